// The flight software as the closed-loop runner sees it: one call per GNC tick with the sensor
// sample, returning the thruster command and telemetry. The default adapter wraps gnc::Gnc; the full
// flight application (executive + commanding + Gnc) can stand in for it without touching the runner.
#pragma once

#include <memory>
#include <string>

#include "gnc/gnc.hpp"

namespace rocksteady::campaign {

struct FlightSetup {
  gnc::GncParams params{};                        // validated parameters, law included
  gnc::Mode start_mode{gnc::Mode::kDetumble};     // requested on the first tick (boot is IDLE)
  const gnc::TrajectoryTable* trajectory{nullptr};  // uplinked before the first tick (TRACK)
};

class FlightSide {
 public:
  virtual ~FlightSide() = default;
  // Before the first tick. Throws std::runtime_error when the flight side rejects the setup.
  virtual void setup(const FlightSetup& setup) = 0;
  // One GNC tick.
  virtual void step(const gnc::SensorSample& sample, gnc::GncOutput& out) = 0;
  virtual std::string name() const = 0;
};

// gnc::Gnc behind the FlightSide interface. It commands start_mode until the core has entered it
// once (the core boots in IDLE and needs one valid sample first); after that, only the core's own
// transitions (e.g. DETUMBLE -> HOLD) change the mode.
class GncFlightSide final : public FlightSide {
 public:
  GncFlightSide();
  void setup(const FlightSetup& setup) override;
  void step(const gnc::SensorSample& sample, gnc::GncOutput& out) override;
  std::string name() const override { return "gnc::Gnc"; }
  const gnc::Gnc& core() const { return *gnc_; }

 private:
  std::unique_ptr<gnc::Gnc> gnc_;  // large (the trajectory table): on the heap, ground side
  gnc::Mode start_mode_{gnc::Mode::kDetumble};
  bool started_{false};
  int attempts_{0};
};

}  // namespace rocksteady::campaign
