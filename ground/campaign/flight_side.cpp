#include "ground/campaign/flight_side.hpp"

#include <stdexcept>

namespace rocksteady::campaign {

GncFlightSide::GncFlightSide() : gnc_(std::make_unique<gnc::Gnc>()) {}

void GncFlightSide::setup(const FlightSetup& s, hal::SensorSource& sensors,
                          hal::ThrusterSink& thrusters) {
  sensors_ = &sensors;
  thrusters_ = &thrusters;
  if (gyro_.configure(hal::SensorConfig{}) != hal::SensorConfigError::kOk ||
      star_.configure(hal::SensorConfig{}) != hal::SensorConfigError::kOk ||
      !bank_.configure(hal::default_thruster_bank_config(s.params.rcs.u_max), &s.params.rcs).ok()) {
    throw std::runtime_error("HAL device configuration rejected");
  }
  const gnc::ParamCheck c = gnc_->init(s.params);
  if (!c.ok) {
    throw std::runtime_error(std::string("flight core rejected parameter ") + c.field + ": " +
                             c.reason);
  }
  if (s.trajectory != nullptr) {
    const gnc::TrajectoryError e = gnc_->load_trajectory(*s.trajectory);
    if (e != gnc::TrajectoryError::kOk) {
      throw std::runtime_error(std::string("flight core rejected the trajectory: ") +
                               gnc::to_string(e));
    }
  }
  start_mode_ = s.start_mode;
  started_ = false;
  attempts_ = 0;
}

void GncFlightSide::step() {
  gnc::SensorSample sample;
  if (sensors_->poll(frame_)) {
    sample.t = frame_.t;
    gyro_.read(frame_.gyro, frame_.t, sample);
    star_.read(frame_.star, frame_.t, sample);
  }
  gnc::GncCommands cmd;
  if (!started_) {
    cmd.has_mode_request = true;
    cmd.mode_request = start_mode_;
  }
  gnc_->step(sample, cmd, out_);
  bank_.command(out_.command, thruster_out_);
  thrusters_->write(thruster_out_, frame_.seq, out_.telemetry.t);
  if (!started_) {
    if (gnc_->mode() == start_mode_) {
      started_ = true;
    } else if (++attempts_ > 100) {
      throw std::runtime_error(std::string("flight core did not enter ") +
                               gnc::to_string(start_mode_) + " (still " +
                               gnc::to_string(gnc_->mode()) + ")");
    }
  }
}

}  // namespace rocksteady::campaign
