// The plant's own attitude math, written independently of gnc/math so that a wrong formula in the
// flight core cannot hide in the truth model (DESIGN.md).
// Quaternion beta = [beta_v; beta4] (scalar last) of F_B in F_I; R = C_IB maps body vectors to
// inertial ones, Rdot = R S(omega) (SPEC Eq. 5).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace rocksteady::plant {

using Vec3 = Eigen::Vector3d;
using Vec4 = Eigen::Vector4d;
using Mat3 = Eigen::Matrix3d;

namespace att {

// S(v) b = v x b.
Mat3 cross_matrix(const Vec3& v);
// SPEC Eq. (3): beta_v dot = 1/2 (beta4 omega + beta_v x omega), beta4 dot = -1/2 beta_v' omega.
Vec4 quat_rate(const Vec4& beta, const Vec3& omega);
// R = C_IB = (beta4^2 - beta_v'beta_v) I + 2 beta_v beta_v' + 2 beta4 S(beta_v).
Mat3 quat_to_matrix(const Vec4& beta);
// Unit quaternion of R (largest-component method), beta4 >= 0.
Vec4 matrix_to_quat(const Mat3& r);
// MRP of beta, shadow-normalised: the sign of beta is chosen with beta4 >= 0, so |q| <= 1.
Vec3 quat_to_mrp(const Vec4& beta);
// Unit quaternion of an MRP: beta4 = (1 - q'q)/(1 + q'q), beta_v = 2 q/(1 + q'q); sign fixed so
// beta4 >= 0.
Vec4 mrp_to_quat(const Vec3& q);
// Rotation by angle |v| about v/|v| (Rodrigues' formula): exp(S(v)).
Mat3 rotation_exp(const Vec3& v);

// One classical RK4 step of length h of SPEC Eq. (2), J w' = (J w) x w + tau, and Eq. (3), with the
// torque held over the step (zero-order hold); beta is renormalised after the step. The plant and
// the flight-side tests' truth model (tests/common/rigid_body.hpp) both integrate with this.
void rk4_step(const Mat3& j, const Mat3& j_inv, const Vec3& torque, double h, Vec4& beta,
              Vec3& omega);

}  // namespace att
}  // namespace rocksteady::plant
