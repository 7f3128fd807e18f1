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

struct ReadingInput {
  bool configured;
  bool device_valid;
  bool finite;    // the reading's values
  double t;       // the reading's time
  double t_tick;  // the tick it is read at
  double max_age;
};

// Common timestamp / validity rules; updates the "last usable" time on success.
ReadingStatus check_reading(const ReadingInput& in, ReadingClock& clock) {
  if (!in.configured) return ReadingStatus::kNotConfigured;
  if (!in.device_valid) return ReadingStatus::kDeviceInvalid;
  if (!in.finite || !std::isfinite(in.t) || !std::isfinite(in.t_tick)) {
    return ReadingStatus::kNonFinite;
  }
  const double age = in.t_tick - in.t;
  if (age > in.max_age || age < -in.max_age) return ReadingStatus::kStale;
  if (clock.have_last && in.t <= clock.last_t) return ReadingStatus::kNotAdvancing;
  clock.have_last = true;
  clock.last_t = in.t;
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
    clock_ = ReadingClock{};
  }
  return e;
}

ReadingStatus Gyro::read(const GyroReading& r, double t_tick, gnc::SensorSample& out) {
  const ReadingStatus status = check_reading(
      {configured_, r.valid, r.rate.allFinite(), r.t, t_tick, config_.max_age_s}, clock_);
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
    clock_ = ReadingClock{};
  }
  return e;
}

ReadingStatus StarTracker::read(const StarTrackerReading& r, double t_tick,
                                gnc::SensorSample& out) {
  const ReadingStatus status = check_reading(
      {configured_, r.valid, r.quat.allFinite(), r.t, t_tick, config_.max_age_s}, clock_);
  out.star_valid = status == ReadingStatus::kOk;
  if (out.star_valid) {
    out.star_quat = gnc::quat::multiply(r.quat, beta_sb_);
  } else {
    ++rejects_;
  }
  return status;
}

}  // namespace rocksteady::hal
