#include "fsw/computer/flight_computer.hpp"

namespace rocksteady::fsw {

FlightComputerConfig default_computer_config(const FlightConfig& app) {
  FlightComputerConfig c;
  c.app = app;
  c.thrusters = hal::default_thruster_bank_config(app.gnc.rcs.u_max);
  return c;
}

InitResult FlightComputer::init(const FlightComputerConfig& config, const Clock& clock) {
  if (gyro_.configure(config.gyro) != hal::SensorConfigError::kOk) {
    return InitResult{false, "gyro", hal::to_string(hal::validate(config.gyro))};
  }
  if (star_.configure(config.star_tracker) != hal::SensorConfigError::kOk) {
    return InitResult{false, "star_tracker", hal::to_string(hal::validate(config.star_tracker))};
  }
  const hal::BankConfigCheck bc = bank_.configure(config.thrusters, &config.app.gnc.rcs);
  if (!bc.ok()) return InitResult{false, "thrusters", hal::to_string(bc.error)};
  const InitResult r = app_.init(config.app, clock);
  if (!r.ok) return r;
  clock_ = &clock;
  out_ = Outputs{};
  thruster_out_ = hal::ThrusterOutputs{};
  echo_seq_ = 0;
  next_index_ = 0;
  return InitResult{};
}

TickReport FlightComputer::tick(const Tick& tick) {
  TickReport report;
  if (clock_ == nullptr) return report;  // not initialised: nothing is read or commanded
  gnc::SensorSample sample;
  const gnc::SensorSample* frame = nullptr;
  if (sensors_.poll(frame_)) {
    if (frame_.stream_restart) {
      gyro_.reset();
      star_.reset();
    }
    sample.t = frame_.t;
    // A reading with non-finite values (NaN, inf) is a rejected sample: counted in the health's
    // sensor_rejects with the flight core's own rejections.
    std::uint32_t nonfinite = 0;
    nonfinite += gyro_.read(frame_.gyro, frame_.t, sample) == hal::ReadingStatus::kNonFinite ? 1 : 0;
    nonfinite += star_.read(frame_.star, frame_.t, sample) == hal::ReadingStatus::kNonFinite ? 1 : 0;
    if (nonfinite > 0) app_.note_sensor_rejects(nonfinite);
    frame = &sample;
    echo_seq_ = frame_.seq;
    report.frame = true;
  }
  app_.tick(tick, frame, out_);
  next_index_ = tick.index + 1;
  if (out_.gnc_ran) {
    bank_.command(out_.command, thruster_out_);
    thrusters_.write(thruster_out_, echo_seq_, out_.telemetry.t);
  }
  report.gnc_ran = out_.gnc_ran;
  report.housekeeping_ran = out_.housekeeping_ran;
  return report;
}

TickReport FlightComputer::step() {
  if (clock_ == nullptr) return TickReport{};
  return tick(Tick{next_index_, clock_->now_ns(), 0});
}

}  // namespace rocksteady::fsw
