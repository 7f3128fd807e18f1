// The in-process harness's port pair: the plant (ground/plant) bound to the HAL's two ports, so the
// flight computer flies it exactly as it flies the plant process over LCM or a board's devices. One
// sensor frame per control period (the plant's device readings, numbered by period); the thrusters
// last written are held over the next period (zero-order hold) when the harness advances the plant.
#pragma once

#include <cstdint>

#include "ground/plant/plant.hpp"
#include "hal/ports.hpp"

namespace rocksteady::campaign {

class PlantBinding final : public hal::SensorSource, public hal::ThrusterSink {
 public:
  explicit PlantBinding(plant::Plant& plant) : plant_(plant) {}

  // The plant's frame for the current period, once per period.
  bool poll(hal::RawSensors& out) override;
  // Hands the firing (and the latch-valve commands) to the plant's valve driver, which holds it for
  // the next advance().
  void write(const hal::ThrusterOutputs& outputs, std::int64_t seq, double t) override;

  // One control period of the plant with the thrusters last written (all off before any write; all
  // off as well once the plant's command timeout, if set, has passed without a write).
  void advance() { plant_.advance(); }

  const hal::ThrusterOutputs& thrusters() const { return thrusters_; }
  // The signed channel forces of that firing, by the plant's own wiring.
  plant::Vec8 channel_forces() const { return plant::Plant::channel_forces(thrusters_); }
  std::int64_t last_seq() const { return last_seq_; }
  std::uint64_t writes() const { return writes_; }

 private:
  plant::Plant& plant_;
  bool polled_{false};
  std::uint64_t polled_tick_{0};
  hal::ThrusterOutputs thrusters_{};
  std::int64_t last_seq_{-1};
  std::uint64_t writes_{0};
};

}  // namespace rocksteady::campaign
