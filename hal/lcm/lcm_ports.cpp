#include "hal/lcm/lcm_ports.hpp"

#include "hal/lcm/convert.hpp"

namespace rocksteady::hal::wire {

bool LcmSensorSource::on_message(const void* buf, int len) {
  if (!safe_decode(buf, len, scratch_, &counters_)) return false;
  if (scratch_.seq <= last_seq_) {
    ++out_of_order_;
    return false;
  }
  latest_ = to_raw(scratch_);
  last_seq_ = scratch_.seq;
  fresh_ = true;
  return true;
}

bool LcmSensorSource::poll(RawSensors& out) {
  if (!fresh_) return false;
  out = latest_;
  fresh_ = false;
  return true;
}

void LcmThrusterSink::write(const ThrusterOutputs& outputs, std::int64_t seq, double t) {
  const rocksteady::thruster_cmd_t msg = to_message(outputs, bank_.channel_forces(outputs), seq, t);
  if (bus_.publish(channels::kThrusterCmd, &msg) != 0) ++publish_errors_;
}

}  // namespace rocksteady::hal::wire
