// LCM back end, bus half: the HAL ports over LCM for processor-in-the-loop runs.
// Subscribe with the raw-buffer handler and feed LcmSensorSource::on_message(): a malformed packet is
// counted and dropped, never thrown through LCM's dispatcher (ENVIRONMENT.md). Example:
//   LcmSensorSource sensors;
//   bus.subscribe(channels::kSensors, &LcmSensorSource::handle, &sensors);
#pragma once

#include <cstdint>

#include <lcm/lcm-cpp.hpp>

#include "hal/lcm/codec.hpp"
#include "hal/ports.hpp"

namespace rocksteady::hal::wire {

class LcmSensorSource final : public SensorSource {
 public:
  // Raw bytes of one RS_SENSORS message. Returns true if it was accepted.
  bool on_message(const void* buf, int len);
  // Signature of lcm::LCM::subscribe's raw-buffer handler.
  void handle(const lcm::ReceiveBuffer* rbuf, const std::string& /*channel*/) {
    on_message(rbuf->data, static_cast<int>(rbuf->data_size));
  }

  // The newest accepted frame, if any arrived since the last poll. A frame whose seq is not newer
  // than the last one delivered is dropped (counted in out_of_order()).
  bool poll(RawSensors& out) override;
  // Forget the last seq (a restarted plant counts from 0 again).
  void reset() {
    fresh_ = false;
    last_seq_ = -1;
  }

  const RxCounters& counters() const { return counters_; }
  std::uint64_t out_of_order() const { return out_of_order_; }

 private:
  rocksteady::sensor_frame_t scratch_{};
  RawSensors latest_{};
  bool fresh_{false};
  std::int64_t last_seq_{-1};
  RxCounters counters_{};
  std::uint64_t out_of_order_{0};
};

class LcmThrusterSink final : public ThrusterSink {
 public:
  // `bank` converts the outputs back to channel forces for the message; both must outlive the sink.
  LcmThrusterSink(lcm::LCM& bus, const ThrusterBank& bank) : bus_(bus), bank_(bank) {}
  void write(const ThrusterOutputs& outputs, std::int64_t seq, double t) override;
  std::uint64_t publish_errors() const { return publish_errors_; }

 private:
  lcm::LCM& bus_;
  const ThrusterBank& bank_;
  std::uint64_t publish_errors_{0};
};

}  // namespace rocksteady::hal::wire
