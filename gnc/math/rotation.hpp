// Attitude math of the flight core: skew/vee, MRP (SPEC Eqs. 3-5), quaternions, rotation matrices.
// Conventions: q is the MRP of F_B in F_I; R maps body-frame vectors to inertial (R = C_IB), so
// Rdot = R S(omega) (Eq. 5). Quaternions are [beta_v; beta4] (scalar last), same attitude as R.
#pragma once

#include "gnc/types.hpp"

namespace rocksteady::gnc {

// S(v): cross-product matrix, S(a) b = a x b.
Mat3 skew(const Vec3& v);
// vee: inverse of skew for the skew-symmetric part of M, vee(S(v)) = v.
Vec3 vee(const Mat3& m);

namespace mrp {

// Eq. (4): Z(q) = 1/2 [ ((1 - q'q)/2) I + q q' + S(q) ],  qdot = Z(q) omega.
Mat3 z_matrix(const Vec3& q);
// Closed-form inverse: Z^-1 = 4 [ (1 - q'q) I - 2 S(q) + 2 q q' ] / (1 + q'q)^2.
Mat3 z_inverse(const Vec3& q);
// Zdot = dZ/dt along qdot: 1/2 [ -(q'qdot) I + qdot q' + q qdot' + S(qdot) ].
Mat3 z_dot(const Vec3& q, const Vec3& q_dot);
// Eq. (4) kinematics.
inline Vec3 rate(const Vec3& q, const Vec3& omega) { return z_matrix(q) * omega; }

// Shadow set of an MRP: -q / (q'q). Same rotation, the other of the two MRP sets.
Vec3 shadow(const Vec3& q);
// [Rocksteady choice] keep |q| <= 1: switch to the shadow set when |q| > 1.
Vec3 normalize(const Vec3& q);
// A reference MRP with its first two time derivatives carried into the shadow set
// (s = -q/n, n = q'q; sdot and sddot by the chain rule).
struct WithRates {
  Vec3 q;
  Vec3 q_dot;
  Vec3 q_ddot;
};
WithRates shadow_with_rates(const WithRates& in);
// Express reference `ref` in the MRP set closest to `q` (SPEC §1: compare in the same set).
WithRates same_set_as(const WithRates& ref, const Vec3& q);

// The representation of q (q or its shadow) nearest to `to`.
Vec3 nearest_set(const Vec3& q, const Vec3& to);

// Composition: attitude of C relative to A given B-rel-A (q1) and C-rel-B (q2), MRP addition rule.
Vec3 compose(const Vec3& q1, const Vec3& q2);
// Relative attitude of B relative to R, both given relative to the same frame: q_BR.
Vec3 relative(const Vec3& q_b, const Vec3& q_r);

Vec4 to_quaternion(const Vec3& q);
Vec3 from_quaternion(const Vec4& beta);  // always the |q| <= 1 set
Mat3 to_dcm(const Vec3& q);              // R = C_IB
Vec3 from_dcm(const Mat3& r);

}  // namespace mrp

namespace quat {

// Hamilton product, scalar last: (a (x) b) corresponds to R(a) R(b).
Vec4 multiply(const Vec4& a, const Vec4& b);
inline Vec4 conjugate(const Vec4& b) { return Vec4(-b.x(), -b.y(), -b.z(), b.w()); }
inline Vec4 identity() { return Vec4(0.0, 0.0, 0.0, 1.0); }
// Eq. (3): beta_v dot = 1/2 (beta4 omega + beta_v x omega), beta4 dot = -1/2 beta_v' omega.
Vec4 rate(const Vec4& beta, const Vec3& omega);
Mat3 to_dcm(const Vec4& beta);  // R = C_IB
Vec4 from_dcm(const Mat3& r);   // Shepperd's method, beta4 >= 0
// Error quaternion of `beta` relative to `beta_target`, short way (beta4 >= 0).
Vec4 error(const Vec4& beta, const Vec4& beta_target);

}  // namespace quat

namespace so3 {

// Eqs. (35)-(36). Q = R_d' R.
// e_R = 1 / (2 sqrt(1 + tr Q)) vee(Q - Q').
Vec3 attitude_error(const Mat3& r, const Mat3& r_d);
// E(R, R_d) = 1 / (2 sqrt(1 + tr Q)) ( tr(R' R_d) I - R' R_d + 2 e_R e_R' ).
Mat3 e_matrix(const Mat3& r, const Mat3& r_d);
// Time derivatives of e_R and E given e_omega = omega - Q' omega_d (Qdot = Q S(e_omega)).
struct ErrorRates {
  Vec3 e_r;
  Mat3 e;
  Vec3 e_r_dot;
  Mat3 e_dot;
};
ErrorRates error_with_rates(const Mat3& r, const Mat3& r_d, const Vec3& e_omega);

}  // namespace so3

}  // namespace rocksteady::gnc
