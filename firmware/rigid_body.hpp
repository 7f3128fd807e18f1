// The firmware's built-in plant: one rigid body, Eq. (2) J w' = (J w) x w + tau, with quaternion
// kinematics, Eq. (3), integrated by classical RK4 with the torque held over the step. Independent of
// gnc/math (its own quaternion algebra), so the loop is closed against a separately written model.
// Header-only and allocation-free: used by the bare-metal image and by the aarch64 tick benchmark.
// Why a copy of the one truth model (ground/plant/attitude.*, which the plant and the gnc/fsw tests
// share): the bare-metal image builds only gnc/ and firmware/ for a freestanding target (no ground
// code, no out-of-line library), so it keeps this self-contained header.
#pragma once

#include <cmath>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <Eigen/LU>

namespace rocksteady::firmware {

class RigidBody {
 public:
  using V3 = Eigen::Vector3d;
  using V4 = Eigen::Vector4d;  // quaternion [x y z w], scalar last: attitude of F_B in F_I
  using M3 = Eigen::Matrix3d;

  RigidBody(const M3& j, const V4& beta, const V3& omega)
      : j_(j), j_inv_(j.inverse()), beta_(beta.normalized()), omega_(omega) {}

  // Quaternion of a modified-Rodrigues-parameter vector: beta_v = 2 p / (1 + p'p),
  // beta4 = (1 - p'p) / (1 + p'p).
  static V4 quaternion_from_mrp(const V3& p) {
    const double n = p.squaredNorm();
    V4 b;
    b.head<3>() = 2.0 * p / (1.0 + n);
    b.w() = (1.0 - n) / (1.0 + n);
    return b;
  }

  // One RK4 step of length h with body torque `tau` (N m) held constant.
  void step(double h, const V3& tau) {
    const V4 b0 = beta_;
    const V3 w0 = omega_;
    const V4 kb1 = beta_dot(b0, w0);
    const V3 kw1 = omega_dot(w0, tau);
    const V4 b1 = b0 + 0.5 * h * kb1;
    const V3 w1 = w0 + 0.5 * h * kw1;
    const V4 kb2 = beta_dot(b1, w1);
    const V3 kw2 = omega_dot(w1, tau);
    const V4 b2 = b0 + 0.5 * h * kb2;
    const V3 w2 = w0 + 0.5 * h * kw2;
    const V4 kb3 = beta_dot(b2, w2);
    const V3 kw3 = omega_dot(w2, tau);
    const V4 b3 = b0 + h * kb3;
    const V3 w3 = w0 + h * kw3;
    const V4 kb4 = beta_dot(b3, w3);
    const V3 kw4 = omega_dot(w3, tau);
    beta_ = (b0 + (h / 6.0) * (kb1 + 2.0 * kb2 + 2.0 * kb3 + kb4)).normalized();
    omega_ = w0 + (h / 6.0) * (kw1 + 2.0 * kw2 + 2.0 * kw3 + kw4);
  }

  const V4& beta() const { return beta_; }
  const V3& omega() const { return omega_; }
  // Rotational kinetic energy 1/2 w' J w (J).
  double kinetic_energy() const { return 0.5 * omega_.dot(j_ * omega_); }

 private:
  // Eq. (3): beta_v' = 1/2 (beta4 w + beta_v x w), beta4' = -1/2 beta_v' w.
  static V4 beta_dot(const V4& b, const V3& w) {
    const V3 v = b.head<3>();
    V4 d;
    d.head<3>() = 0.5 * (b.w() * w + v.cross(w));
    d.w() = -0.5 * v.dot(w);
    return d;
  }
  // Eq. (2).
  V3 omega_dot(const V3& w, const V3& tau) const { return j_inv_ * ((j_ * w).cross(w) + tau); }

  M3 j_;
  M3 j_inv_;
  V4 beta_;
  V3 omega_;
};

}  // namespace rocksteady::firmware
