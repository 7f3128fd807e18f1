// Flight-board stub back end: compiles without LCM or any OS service. Until the board's drivers exist
// it reports device-invalid readings (so the flight core goes through its sensor-timeout path) and
// records what it was asked to fire. Tests can inject readings.
#pragma once

#include <cstdint>

#include "hal/ports.hpp"

namespace rocksteady::hal {

class FlightBoardStub final : public SensorSource, public ThrusterSink {
 public:
  // Frame time advances by `period_s` per poll.
  explicit FlightBoardStub(double period_s = 0.1) : period_s_(period_s) {}

  bool poll(RawSensors& out) override;
  void write(const ThrusterOutputs& outputs, std::int64_t seq, double t) override;

  // Test hook: the next poll returns these readings (frame time and seq still come from the stub).
  void inject(const GyroReading& gyro, const StarTrackerReading& star);

  std::int64_t frames() const { return next_seq_; }
  std::uint64_t writes() const { return writes_; }
  const ThrusterOutputs& last_outputs() const { return last_; }
  std::int64_t last_seq() const { return last_seq_; }
  double last_t() const { return last_t_; }

 private:
  double period_s_;
  std::int64_t next_seq_{0};
  bool injected_{false};
  GyroReading gyro_{};
  StarTrackerReading star_{};
  ThrusterOutputs last_{};
  std::int64_t last_seq_{-1};
  double last_t_{0.0};
  std::uint64_t writes_{0};
};

}  // namespace rocksteady::hal
