// The flight computer (fsw::FlightComputer: HAL devices + executive + commanding + uplink +
// gnc::Gnc) behind the campaign's FlightSide interface, driven only through the harness's ports
// (PlantBinding). The start mode and the trajectory arrive as ground commands and uplink chunks (the
// bus library's chunking, mapped by the flight side's bus mapping), as in flight.
#pragma once

#include <cstdint>
#include <initializer_list>
#include <memory>
#include <string>

#include "fsw/computer/flight_computer.hpp"
#include "fsw/executive/clock.hpp"
#include "ground/campaign/flight_side.hpp"

namespace rocksteady::campaign {

class FswFlightSide final : public FlightSide {
 public:
  void setup(const FlightSetup& setup, hal::SensorSource& sensors,
             hal::ThrusterSink& thrusters) override;
  void step() override;
  const gnc::GncOutput& output() const override { return computer_->core_output(); }
  std::string name() const override { return "fsw::FlightComputer"; }
  const fsw::FlightComputer& computer() const { return *computer_; }
  bool uplink_plan(const gnc::TrajectoryTable& table, std::int32_t upload_id, bool enter_track,
                   gnc::LawId law, std::string& why) override;
  int trajectory_switches() const override { return switches_; }
  int trajectory_refusals() const override { return refusals_; }

 private:
  void command(fsw::Opcode op, std::initializer_list<double> args);
  fsw::CommandAck try_command(fsw::Opcode op, std::initializer_list<double> args);

  std::unique_ptr<fsw::FlightComputer> computer_;  // large (two trajectory tables): once, on the heap
  fsw::FakeClock clock_{};  // lockstep: the plant owns time; execution-time statistics read 0
  gnc::Mode start_mode_{gnc::Mode::kDetumble};
  bool have_trajectory_{false};
  std::int64_t seq_{0};
  int ticks_{0};
  bool started_{false};
  int switches_{0};
  int refusals_{0};
};

}  // namespace rocksteady::campaign
