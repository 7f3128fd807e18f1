// The flight software as the closed-loop runner sees it: bound to a pair of HAL ports at setup, then
// one call per GNC tick; it reads its sensors and fires its thrusters through the ports only. The
// full flight computer (fsw::FlightComputer: devices + executive + commanding + Gnc) is the default;
// the flight core alone behind the same HAL devices is kept for comparison (--flight core).
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "gnc/gnc.hpp"
#include "hal/ports.hpp"
#include "hal/sensors.hpp"
#include "hal/thruster_bank.hpp"

namespace rocksteady::campaign {

struct FlightSetup {
  gnc::GncParams params{};                        // validated parameters, law included
  gnc::Mode start_mode{gnc::Mode::kDetumble};     // requested on the first tick (boot is IDLE)
  const gnc::TrajectoryTable* trajectory{nullptr};  // uplinked before the first tick (TRACK)
};

class FlightSide {
 public:
  virtual ~FlightSide() = default;
  // Before the first tick; the ports must outlive the run. Throws std::runtime_error when the
  // flight side rejects the setup.
  virtual void setup(const FlightSetup& setup, hal::SensorSource& sensors,
                     hal::ThrusterSink& thrusters) = 0;
  // One GNC tick through the ports.
  virtual void step() = 0;
  // The flight core's output of the last tick (telemetry for the runner's time series).
  virtual const gnc::GncOutput& output() const = 0;
  virtual std::string name() const = 0;

  // A plan from the re-planner, mid-run, through the same path as a ground upload: the chunked
  // uplink, LOAD_TRAJECTORY, and (enter_track, the first plan) SET_LAW law with the fuel-optimal
  // reference, which requests TRACK. Takes effect at the next tick boundary. false with the reason
  // when the flight software refused a chunk or a command (nothing thrown: the run goes on with the
  // plan it had). The default: this flight side cannot take uplinks during a run.
  virtual bool uplink_plan(const gnc::TrajectoryTable& table, std::int32_t upload_id,
                           bool enter_track, gnc::LawId law, std::string& why) {
    (void)table;
    (void)upload_id;
    (void)enter_track;
    (void)law;
    why = "this flight side takes no uplink during a run (re-planning needs the flight application)";
    return false;
  }
  // The flight's verdicts at the tick boundary on plans loaded while tracking (events
  // trajectory_switched / trajectory_stale), counted since setup.
  virtual int trajectory_switches() const { return 0; }
  virtual int trajectory_refusals() const { return 0; }
};

// gnc::Gnc alone behind the same HAL devices (gyro, star tracker, thruster bank; no executive, no
// commanding). It commands start_mode until the core has entered it once (the core boots in IDLE and
// needs one valid sample first); after that, only the core's own transitions change the mode.
class GncFlightSide final : public FlightSide {
 public:
  GncFlightSide();
  void setup(const FlightSetup& setup, hal::SensorSource& sensors,
             hal::ThrusterSink& thrusters) override;
  void step() override;
  const gnc::GncOutput& output() const override { return out_; }
  std::string name() const override { return "gnc::Gnc"; }
  const gnc::Gnc& core() const { return *gnc_; }

 private:
  std::unique_ptr<gnc::Gnc> gnc_;  // large (the trajectory table): on the heap, ground side
  hal::SensorSource* sensors_{nullptr};
  hal::ThrusterSink* thrusters_{nullptr};
  hal::Gyro gyro_{};
  hal::StarTracker star_{};
  hal::ThrusterBank bank_{};
  hal::RawSensors frame_{};
  hal::ThrusterOutputs thruster_out_{};
  gnc::GncOutput out_{};
  gnc::Mode start_mode_{gnc::Mode::kDetumble};
  bool started_{false};
  int attempts_{0};
};

}  // namespace rocksteady::campaign
