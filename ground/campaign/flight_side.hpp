// The flight software as the closed-loop runner sees it: bound to a pair of HAL ports at setup, then
// one call per GNC tick; it reads its sensors and fires its thrusters through the ports only. The
// full flight computer (fsw::FlightComputer: devices + executive + commanding + Gnc) is the default;
// the flight core alone behind the same HAL devices is kept for comparison (--flight core).
#pragma once

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
