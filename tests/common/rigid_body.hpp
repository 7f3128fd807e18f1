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

struct RigidBody {
  M3 j{M3::Identity()};
  V4 beta{0, 0, 0, 1};
  V3 omega{V3::Zero()};

  // One RK4 step of length h with the torque held constant (zero-order hold).
  void step(double h, const V3& torque) {
    plant::att::rk4_step(j, j.inverse(), torque, h, beta, omega);
  }

  V3 mrp() const { return quat_to_mrp(beta); }
};

}  // namespace rocksteady::test
