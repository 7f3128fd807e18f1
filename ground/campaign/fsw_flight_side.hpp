// The flight application (fsw::FlightApp: executive + commanding + uplink + gnc::Gnc) behind the
// campaign's FlightSide interface, bound to the plant through the in-process HAL: the plant's sensor
// readings go through hal::Gyro / hal::StarTracker, the commanded channel forces through
// hal::ThrusterBank to the 16 physical thrusters and back to the channel forces the plant applies.
// The start mode and the trajectory arrive as ground commands and uplink chunks, as in flight.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "fsw/app/flight_app.hpp"
#include "fsw/executive/clock.hpp"
#include "ground/campaign/flight_side.hpp"
#include "hal/sensors.hpp"
#include "hal/thruster_bank.hpp"

namespace rocksteady::campaign {

class FswFlightSide final : public FlightSide {
 public:
  FswFlightSide();
  void setup(const FlightSetup& setup) override;
  void step(const gnc::SensorSample& sample, gnc::GncOutput& out) override;
  std::string name() const override { return "fsw::FlightApp"; }
  const fsw::FlightApp& app() const { return *app_; }

 private:
  void command(fsw::Opcode op, std::initializer_list<double> args);

  std::unique_ptr<fsw::FlightApp> app_;  // large (two trajectory tables): once, on the heap
  fsw::FakeClock clock_{};  // lockstep: the plant owns time; execution-time statistics read 0
  hal::Gyro gyro_{};
  hal::StarTracker star_{};
  hal::ThrusterBank bank_{};
  fsw::Outputs outputs_{};
  gnc::Mode start_mode_{gnc::Mode::kDetumble};
  const gnc::TrajectoryTable* trajectory_{nullptr};
  std::int64_t seq_{0};
  int ticks_{0};
  bool started_{false};
};

}  // namespace rocksteady::campaign
