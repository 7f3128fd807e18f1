#include "ground/campaign/flight_side.hpp"

#include <stdexcept>

namespace rocksteady::campaign {

GncFlightSide::GncFlightSide() : gnc_(std::make_unique<gnc::Gnc>()) {}

void GncFlightSide::setup(const FlightSetup& s) {
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

void GncFlightSide::step(const gnc::SensorSample& sample, gnc::GncOutput& out) {
  gnc::GncCommands cmd;
  if (!started_) {
    cmd.has_mode_request = true;
    cmd.mode_request = start_mode_;
  }
  gnc_->step(sample, cmd, out);
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
