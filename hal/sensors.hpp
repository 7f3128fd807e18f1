// Gyro and StarTracker: raw readings in the sensor's own frame, with timestamps and validity, turned
// into body-frame values for gnc::SensorSample through the sensor-to-body alignment (configuration).
// A reading is usable only if the device flagged it valid, its values are finite, it is not older
// than `max_age_s` at the tick, and its timestamp advanced since the last usable reading (a frozen
// sensor repeats itself). No heap, no exceptions.
#pragma once

#include <cstdint>

#include "gnc/gnc.hpp"
#include "gnc/types.hpp"

namespace rocksteady::hal {

struct GyroReading {
  double t{0.0};                          // s, sample time
  gnc::Vec3 rate{gnc::Vec3::Zero()};      // rad/s, in the gyro frame
  bool valid{false};                      // device's own validity flag
};

struct StarTrackerReading {
  double t{0.0};                            // s, sample time
  gnc::Vec4 quat{0.0, 0.0, 0.0, 1.0};       // attitude of the tracker frame in F_I, scalar last
  bool valid{false};
};

// One sensor frame as the back ends deliver it.
struct RawSensors {
  std::int64_t seq{-1};  // frame number (echoed by the thruster command in lockstep)
  double t{0.0};         // s, frame time
  GyroReading gyro{};
  StarTrackerReading star{};
};

struct SensorConfig {
  // C_BS: maps sensor-frame vectors to the body frame (v_B = C_BS v_S). Must be a rotation.
  gnc::Mat3 body_from_sensor{gnc::Mat3::Identity()};
  double max_age_s{0.5};  // a reading older than this at the tick is stale
};

enum class SensorConfigError : std::uint8_t { kOk = 0, kNotARotation, kBadMaxAge };
const char* to_string(SensorConfigError e);
SensorConfigError validate(const SensorConfig& config);

// Why the last reading was not usable.
enum class ReadingStatus : std::uint8_t {
  kOk = 0,
  kDeviceInvalid,   // the device said so
  kNonFinite,
  kStale,           // older than max_age_s at the tick, or from the future
  kNotAdvancing,    // same or older timestamp than the last usable reading
  kNotConfigured,
};

struct BodyRate {
  double t{0.0};
  gnc::Vec3 rate{gnc::Vec3::Zero()};  // rad/s in F_B
  bool valid{false};
  ReadingStatus status{ReadingStatus::kNotConfigured};
};

struct BodyAttitude {
  double t{0.0};
  gnc::Vec4 quat{0.0, 0.0, 0.0, 1.0};  // attitude of F_B in F_I, scalar last
  bool valid{false};
  ReadingStatus status{ReadingStatus::kNotConfigured};
};

class Gyro {
 public:
  SensorConfigError configure(const SensorConfig& config);
  void reset() { have_last_ = false; }
  // omega_B = C_BS omega_S.
  BodyRate read(const GyroReading& r, double t_tick);
  std::uint32_t rejects() const { return rejects_; }

 private:
  SensorConfig config_{};
  bool configured_{false};
  bool have_last_{false};
  double last_t_{0.0};
  std::uint32_t rejects_{0};
};

class StarTracker {
 public:
  SensorConfigError configure(const SensorConfig& config);
  void reset() { have_last_ = false; }
  // R_IB = R_IS C_SB, i.e. beta_IB = beta_IS (x) beta_SB with beta_SB the conjugate of C_BS's.
  BodyAttitude read(const StarTrackerReading& r, double t_tick);
  std::uint32_t rejects() const { return rejects_; }

 private:
  SensorConfig config_{};
  gnc::Vec4 beta_sb_{0.0, 0.0, 0.0, 1.0};
  bool configured_{false};
  bool have_last_{false};
  double last_t_{0.0};
  std::uint32_t rejects_{0};
};

// The flight core's input: t is the tick time; each sensor's validity is its reading's.
gnc::SensorSample make_sample(double t_tick, const BodyRate& gyro, const BodyAttitude& star);

}  // namespace rocksteady::hal
