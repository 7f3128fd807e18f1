// The study's state filter (SPEC §6): predict through the model (J_hat, MRP kinematics, last
// commanded torque), then add K times the innovation, K = 1 - exp(-omega_c T_s). With perfect
// sensors the estimate is the measurement (pass-through).
#pragma once

#include <cstdint>

#include "gnc/types.hpp"

namespace rocksteady::gnc {

enum class EstimatorKind : std::uint8_t {
  kPassThrough = 0,  // perfect sensors: the estimate is the measurement
  kFilter = 1,       // SPEC §6
  kMekf = 2,         // multiplicative EKF with gyro bias (gnc/estimation/mekf.hpp)
};
inline constexpr int kEstimatorKindCount = 3;

struct EstimatorParams {  // SPEC §6
  EstimatorKind kind{EstimatorKind::kPassThrough};
  double omega_c{0.02 * 3.14159265358979323846};  // rad/s
  int predict_substeps{1};                         // RK4 steps per tick in the prediction
  // Sample acceptance: a gyro rate above this, or a star-tracker quaternion whose norm is off by
  // more than the tolerance, is rejected (counted, and the model carries the estimate).
  double gyro_max_rate{1.0};          // rad/s
  double quat_norm_tolerance{0.01};
};

struct Measurement {
  Vec3 omega{Vec3::Zero()};  // gyro, rad/s
  Vec3 q{Vec3::Zero()};      // star tracker, MRP
  bool omega_valid{false};
  bool q_valid{false};
};

class StateFilter {
 public:
  void configure(const EstimatorParams& p, const Mat3& j_hat, double dt);
  // Forget the estimate: the next valid measurement initialises it.
  void reset() { initialised_ = false; }
  // One tick: torque = body torque commanded on the previous tick (B_hat u).
  void update(const Measurement& m, const Vec3& torque);

  bool initialised() const { return initialised_; }
  const Vec3& omega() const { return omega_; }
  const Vec3& q() const { return q_; }
  double gain() const { return gain_; }

  // Model propagation used by the prediction (RK4 of Eq. 2 with J_hat and Eq. 4), exposed for
  // tests.
  void predict(Vec3& q, Vec3& omega, const Vec3& torque) const;

 private:
  EstimatorParams p_{};
  Mat3 j_hat_{Mat3::Identity()};
  Mat3 j_hat_inv_{Mat3::Identity()};
  double dt_{0.1};
  double gain_{1.0};
  bool initialised_{false};
  Vec3 omega_{Vec3::Zero()};
  Vec3 q_{Vec3::Zero()};
};

}  // namespace rocksteady::gnc
