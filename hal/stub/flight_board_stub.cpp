#include "hal/stub/flight_board_stub.hpp"

namespace rocksteady::hal {

bool FlightBoardStub::poll(RawSensors& out) {
  out = RawSensors{};
  out.seq = next_seq_;
  out.t = static_cast<double>(next_seq_) * period_s_;
  if (injected_) {
    out.gyro = gyro_;
    out.star = star_;
    injected_ = false;
  } else {
    out.gyro.t = out.t;
    out.gyro.valid = false;
    out.star.t = out.t;
    out.star.valid = false;
  }
  ++next_seq_;
  return true;
}

void FlightBoardStub::write(const ThrusterOutputs& outputs, std::int64_t seq, double t) {
  last_ = outputs;
  last_seq_ = seq;
  last_t_ = t;
  ++writes_;
}

void FlightBoardStub::inject(const GyroReading& gyro, const StarTrackerReading& star) {
  gyro_ = gyro;
  star_ = star;
  injected_ = true;
}

}  // namespace rocksteady::hal
