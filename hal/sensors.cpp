#include "hal/sensors.hpp"

#include <cmath>

#include "gnc/math/rotation.hpp"

namespace rocksteady::hal {

namespace {

bool is_rotation(const gnc::Mat3& r) {
  if (!r.allFinite()) return false;
  const double orth = (r.transpose() * r - gnc::Mat3::Identity()).cwiseAbs().maxCoeff();
  return orth <= 1e-9 && std::fabs(r.determinant() - 1.0) <= 1e-9;
}

// Common timestamp / validity rules; updates the "last usable" time on success.
ReadingStatus check_reading(bool configured, bool device_valid, bool finite, double t, double t_tick,
                            double max_age, bool& have_last, double& last_t) {
  if (!configured) return ReadingStatus::kNotConfigured;
  if (!device_valid) return ReadingStatus::kDeviceInvalid;
  if (!finite || !std::isfinite(t) || !std::isfinite(t_tick)) return ReadingStatus::kNonFinite;
  const double age = t_tick - t;
  if (age > max_age || age < -max_age) return ReadingStatus::kStale;
  if (have_last && t <= last_t) return ReadingStatus::kNotAdvancing;
  have_last = true;
  last_t = t;
  return ReadingStatus::kOk;
}

}  // namespace

const char* to_string(SensorConfigError e) {
  switch (e) {
    case SensorConfigError::kOk: return "ok";
    case SensorConfigError::kNotARotation: return "body_from_sensor is not a rotation matrix";
    case SensorConfigError::kBadMaxAge: return "max_age_s must be finite and positive";
  }
  return "unknown";
}

SensorConfigError validate(const SensorConfig& config) {
  if (!is_rotation(config.body_from_sensor)) return SensorConfigError::kNotARotation;
  if (!std::isfinite(config.max_age_s) || config.max_age_s <= 0.0) {
    return SensorConfigError::kBadMaxAge;
  }
  return SensorConfigError::kOk;
}

SensorConfigError Gyro::configure(const SensorConfig& config) {
  const SensorConfigError e = validate(config);
  if (e == SensorConfigError::kOk) {
    config_ = config;
    configured_ = true;
    have_last_ = false;
  }
  return e;
}

ReadingStatus Gyro::read(const GyroReading& r, double t_tick, gnc::SensorSample& out) {
  const ReadingStatus status = check_reading(configured_, r.valid, r.rate.allFinite(), r.t, t_tick,
                                             config_.max_age_s, have_last_, last_t_);
  out.gyro_valid = status == ReadingStatus::kOk;
  if (out.gyro_valid) {
    out.gyro_rate = config_.body_from_sensor * r.rate;
  } else {
    ++rejects_;
  }
  return status;
}

SensorConfigError StarTracker::configure(const SensorConfig& config) {
  const SensorConfigError e = validate(config);
  if (e == SensorConfigError::kOk) {
    config_ = config;
    // quat::from_dcm(C_BS) is beta_BS; its conjugate is beta_SB.
    beta_sb_ = gnc::quat::conjugate(gnc::quat::from_dcm(config.body_from_sensor));
    configured_ = true;
    have_last_ = false;
  }
  return e;
}

ReadingStatus StarTracker::read(const StarTrackerReading& r, double t_tick,
                                gnc::SensorSample& out) {
  const ReadingStatus status = check_reading(configured_, r.valid, r.quat.allFinite(), r.t, t_tick,
                                             config_.max_age_s, have_last_, last_t_);
  out.star_valid = status == ReadingStatus::kOk;
  if (out.star_valid) {
    out.star_quat = gnc::quat::multiply(r.quat, beta_sb_);
  } else {
    ++rejects_;
  }
  return status;
}

}  // namespace rocksteady::hal
