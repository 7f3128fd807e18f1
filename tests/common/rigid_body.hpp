// Test-only truth model: rigid body, Eq. (2), with its own quaternion kinematics (Eq. 3) and RK4.
// Deliberately shares no code with gnc/math, so a wrong MRP formula cannot hide behind it.
#pragma once

#include <Eigen/Dense>

namespace rocksteady::test {

using V3 = Eigen::Vector3d;
using V4 = Eigen::Vector4d;  // [x y z w], scalar last
using M3 = Eigen::Matrix3d;

inline V4 quat_derivative(const V4& b, const V3& w) {
  const V3 v = b.head<3>();
  V4 d;
  d.head<3>() = 0.5 * (b.w() * w + v.cross(w));
  d.w() = -0.5 * v.dot(w);
  return d;
}

// Body-to-inertial rotation matrix of a scalar-last unit quaternion.
inline M3 quat_to_matrix(const V4& b) {
  const double x = b.x(), y = b.y(), z = b.z(), w = b.w();
  M3 r;
  r << 1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w),  //
      2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w),   //
      2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y);
  return r;
}

// MRP of a quaternion in the |q| <= 1 set: q = beta_v / (1 + beta4), beta4 >= 0.
inline V3 quat_to_mrp(const V4& b) {
  const V4 u = (b.w() < 0 ? V4(-b) : b).normalized();
  return u.head<3>() / (1.0 + u.w());
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

  V3 omega_dot(const V3& w, const V3& torque) const {
    return j.ldlt().solve((j * w).cross(w) + torque);  // Eq. (2)
  }

  // One RK4 step of length h with the torque held constant (zero-order hold).
  void step(double h, const V3& torque) {
    const V3 w0 = omega;
    const V4 b0 = beta;
    const V3 k1w = omega_dot(w0, torque);
    const V4 k1b = quat_derivative(b0, w0);
    const V3 k2w = omega_dot(w0 + 0.5 * h * k1w, torque);
    const V4 k2b = quat_derivative(b0 + 0.5 * h * k1b, w0 + 0.5 * h * k1w);
    const V3 k3w = omega_dot(w0 + 0.5 * h * k2w, torque);
    const V4 k3b = quat_derivative(b0 + 0.5 * h * k2b, w0 + 0.5 * h * k2w);
    const V3 k4w = omega_dot(w0 + h * k3w, torque);
    const V4 k4b = quat_derivative(b0 + h * k3b, w0 + h * k3w);
    omega = w0 + (h / 6) * (k1w + 2 * k2w + 2 * k3w + k4w);
    beta = (b0 + (h / 6) * (k1b + 2 * k2b + 2 * k3b + k4b)).normalized();
  }

  V3 mrp() const { return quat_to_mrp(beta); }
};

}  // namespace rocksteady::test
