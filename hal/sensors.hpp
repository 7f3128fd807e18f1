// Gyro and StarTracker: raw readings (hal/readings.hpp) in the sensor's own frame, with timestamps
// and validity, written straight into the flight core's input gnc::SensorSample in the body frame
// through the sensor-to-body alignment (configuration). The reading checks below are made here and
// nowhere else on the flight path.
// A reading is usable only if the device flagged it valid, its values are finite, it is not older
// than `max_age_s` at the tick, and its timestamp advanced since the last usable reading (a frozen
// sensor repeats itself). No heap, no exceptions.
#pragma once

#include <cstdint>

#include "gnc/io.hpp"
#include "gnc/types.hpp"
#include "hal/readings.hpp"

namespace rocksteady::hal {

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

// The time of the last usable reading (a frozen sensor repeats itself).
struct ReadingClock {
  bool have_last{false};
  double last_t{0.0};
};

class Gyro {
 public:
  SensorConfigError configure(const SensorConfig& config);
  void reset() { clock_ = ReadingClock{}; }
  // omega_B = C_BS omega_S into out.gyro_rate / out.gyro_valid (the rate is left untouched when
  // the reading is not usable). Returns why it was not.
  ReadingStatus read(const GyroReading& r, double t_tick, gnc::SensorSample& out);
  std::uint32_t rejects() const { return rejects_; }

 private:
  SensorConfig config_{};
  bool configured_{false};
  ReadingClock clock_{};
  std::uint32_t rejects_{0};
};

class StarTracker {
 public:
  SensorConfigError configure(const SensorConfig& config);
  void reset() { clock_ = ReadingClock{}; }
  // R_IB = R_IS C_SB, i.e. beta_IB = beta_IS (x) beta_SB with beta_SB the conjugate of C_BS's, into
  // out.star_quat / out.star_valid.
  ReadingStatus read(const StarTrackerReading& r, double t_tick, gnc::SensorSample& out);
  std::uint32_t rejects() const { return rejects_; }

 private:
  SensorConfig config_{};
  gnc::Vec4 beta_sb_{0.0, 0.0, 0.0, 1.0};
  bool configured_{false};
  ReadingClock clock_{};
  std::uint32_t rejects_{0};
};

}  // namespace rocksteady::hal
