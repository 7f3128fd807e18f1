// Test truth model: the plant's rigid body (ground/plant/attitude.hpp): Eq. (2) with quaternion
// kinematics, Eq. (3), integrated by classical RK4 with the torque held over the step, exactly as
// Plant::advance does. It shares no code with gnc/math, so a wrong MRP formula in the flight core
// cannot hide behind it, and the gnc/fsw tests close their loops against the same model as the
// ground plant. (The firmware keeps a freestanding copy, firmware/rigid_body.hpp, for the
// bare-metal image, which builds nothing from ground/.)
#pragma once

#include <cmath>

#include <Eigen/Core>
#include <Eigen/LU>

#include "ground/plant/attitude.hpp"

namespace rocksteady::test {

using V3 = Eigen::Vector3d;
using V4 = Eigen::Vector4d;  // [x y z w], scalar last
using M3 = Eigen::Matrix3d;

// SPEC Eq. (3).
inline V4 quat_derivative(const V4& b, const V3& w) {
  return plant::att::quat_rate(b, w);
}

// Body-to-inertial rotation matrix of a scalar-last unit quaternion.
inline M3 quat_to_matrix(const V4& b) {
  return plant::att::quat_to_matrix(b);
}

// MRP of a quaternion in the |q| <= 1 set: q = beta_v / (1 + beta4), beta4 >= 0.
inline V3 quat_to_mrp(const V4& b) {
  return plant::att::quat_to_mrp(b);
}

inline V4 axis_angle(const V3& axis, double angle) {
  V4 b;
  b.head<3>() = axis.normalized() * std::sin(angle / 2);
  b.w() = std::cos(angle / 2);
  return b;
}

// One RK4 step of length h of Eq. (2), J w' = (J w) x w + tau, and Eq. (3), with the torque held
// (zero-order hold); beta is renormalised after the step. The same step as Plant::advance.
inline void rigid_body_rk4_step(const M3& j, const M3& j_inv, const V3& torque, double h, V4& beta,
                                V3& omega) {
  auto derivative = [&](const V4& b, const V3& w, V4& b_dot, V3& w_dot) {
    b_dot = plant::att::quat_rate(b, w);          // Eq. (3)
    w_dot = j_inv * ((j * w).cross(w) + torque);  // Eq. (2)
  };
  V4 k1b, k2b, k3b, k4b;
  V3 k1w, k2w, k3w, k4w;
  derivative(beta, omega, k1b, k1w);
  derivative(beta + 0.5 * h * k1b, omega + 0.5 * h * k1w, k2b, k2w);
  derivative(beta + 0.5 * h * k2b, omega + 0.5 * h * k2w, k3b, k3w);
  derivative(beta + h * k3b, omega + h * k3w, k4b, k4w);
  beta += (h / 6.0) * (k1b + 2.0 * k2b + 2.0 * k3b + k4b);
  omega += (h / 6.0) * (k1w + 2.0 * k2w + 2.0 * k3w + k4w);
  beta.normalize();
}

struct RigidBody {
  M3 j{M3::Identity()};
  V4 beta{0, 0, 0, 1};
  V3 omega{V3::Zero()};

  // One RK4 step of length h with the torque held constant (zero-order hold).
  void step(double h, const V3& torque) {
    rigid_body_rk4_step(j, j.inverse(), torque, h, beta, omega);
  }

  V3 mrp() const { return quat_to_mrp(beta); }
};

}  // namespace rocksteady::test
