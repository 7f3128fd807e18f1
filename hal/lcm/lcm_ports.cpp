#include "hal/lcm/lcm_ports.hpp"

#include "lcmtypes/channels.hpp"
#include "wire/convert.hpp"

namespace rocksteady::hal {

bool LcmSensorSource::on_message(const void* buf, int len) {
  if (!wire::safe_decode(buf, len, scratch_, &counters_)) return false;
  ++frames_;
  if (have_seq_ && scratch_.seq < last_seq_) {
    ++restarts_;
    restart_pending_ = true;  // carried by the next frame polled
  }
  if (fresh_) ++superseded_;
  latest_ = wire::to_raw(scratch_);
  latest_.stream_restart = restart_pending_;
  have_seq_ = true;
  last_seq_ = scratch_.seq;
  fresh_ = true;
  return true;
}

bool LcmSensorSource::poll(RawSensors& out) {
  if (!fresh_) return false;
  out = latest_;
  fresh_ = false;
  restart_pending_ = false;
  return true;
}

void LcmThrusterSink::write(const ThrusterOutputs& outputs, std::int64_t seq, double t) {
  const std::lock_guard<std::mutex> lock(mutex_);
  if (off_latched_.load()) {
    ++suppressed_;
    return;
  }
  msg_ = wire::to_message(outputs, channel_forces(wiring_, outputs), seq, t);
  written_ = true;
  publish_locked();
}

void LcmThrusterSink::republish() {
  const std::lock_guard<std::mutex> lock(mutex_);
  if (off_latched_.load()) {
    ++suppressed_;
    return;
  }
  if (written_) publish_locked();
}

void LcmThrusterSink::all_off(std::int64_t seq, double t) {
  const std::lock_guard<std::mutex> lock(mutex_);
  off_latched_.store(true);
  // Disabled, every thruster off, zero force; the latch valves stay as last commanded (reopening a
  // valve that isolates a failed-on thruster would fire it again).
  ThrusterOutputs off{};
  for (int p = 0; p < gnc::kPods; ++p) {
    off.valve_open[static_cast<std::size_t>(p)] = msg_.valve_closed[p] == 0;
  }
  msg_ = wire::to_message(off, channel_forces(wiring_, off), seq, t);
  written_ = true;
  publish_locked();
}

void LcmThrusterSink::publish_locked() {
  const int n = wire::encode(msg_, buf_, static_cast<int>(sizeof buf_));
  if (n < 0 || bus_ == nullptr || lcm_publish(bus_, channels::kThrusterCmd, buf_, static_cast<unsigned int>(n)) != 0) {
    ++publish_errors_;
  }
}

}  // namespace rocksteady::hal
