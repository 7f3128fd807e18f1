// Control laws (SPEC §2). Each returns the commanded body torque u_c. Free functions for the
// stateless math; ControlLaws holds the state of the integral and adaptive laws.
#pragma once

#include "gnc/guidance/references.hpp"
#include "gnc/io.hpp"
#include "gnc/types.hpp"

namespace rocksteady::gnc {

struct TrackingGains {  // K (N m s) and Lambda (1/s) of Eqs. (9), (17), feed-forward law
  Mat3 k{1e4 * Mat3::Identity()};
  Mat3 lambda{1e-3 * Mat3::Identity()};
};

struct IntegralGains {  // Eq. (19)
  Mat3 k{1e4 * Mat3::Identity()};
  Mat3 lambda{1e-3 * Mat3::Identity()};
  // [Rocksteady choice] K_I: the study gives no value. K_I = 1 N m/(rad) puts the integral
  // corner (K_I/K = 1e-4 1/s) a factor ~3 below the contraction rate lambda_min(K)/lambda_max(J).
  Mat3 k_i{1.0 * Mat3::Identity()};
  // [Rocksteady choice] anti-windup: |integral| clamped per axis, frozen while the allocator
  // saturates.
  double integral_limit_nm{500.0};
};

struct AdaptiveGains {  // Eq. (34)
  Mat3 k{1e4 * Mat3::Identity()};
  Mat3 lambda{1e-3 * Mat3::Identity()};
  double gamma{1e12};
  // [Rocksteady choice] projection set: the eigenvalues of J(a_hat) stay within
  // [floor_ratio * lambda_min(J_hat0), ceiling_ratio * lambda_max(J_hat0)].
  double eig_floor_ratio{0.5};
  double eig_ceiling_ratio{2.0};
};

struct So3Gains {  // Eq. (37)
  Mat3 k{1e4 * Mat3::Identity()};
  // [Rocksteady choice] Lambda_e = 4 Lambda_r: near the goal e_R ~ theta/2 and E ~ I/2, so this
  // gives the MRP law's small-angle attitude bandwidth (q ~ theta/4, Z ~ I/4).
  Mat3 lambda{4e-3 * Mat3::Identity()};
};

struct DpdGains {  // Eqs. (49)-(50)
  Mat3 k_d{1e4 * Mat3::Identity()};
  double k_p{10.0};
};

// The gains of every law (GncParams holds them under the same names).
struct LawGains {
  TrackingGains ntcl{};
  TrackingGains el{};
  TrackingGains feedforward{};
  IntegralGains integral{};
  AdaptiveGains adaptive{};
  So3Gains so3{};
  DpdGains dpd{};
};

// omega_r and its analytic time derivative.
struct RateReference {
  Vec3 omega_r{Vec3::Zero()};
  Vec3 omega_r_dot{Vec3::Zero()};
};

// Eq. (9): omega_r = Z(q)^-1 qdot_d + Z(q)^-1 Lambda (q_d - q); omega_r_dot from qdot = Z(q) omega,
// qdot_d, qddot_d and d/dt Z^-1 = -Z^-1 Zdot Z^-1. In the damping phase omega_r = 0 (Eq. 51).
RateReference mrp_rate_reference(const Vec3& q, const Vec3& omega, const ReferenceSample& ref,
                                 const Mat3& lambda);

// Eq. (37): omega_r = R' R_d omega_d - Lambda_e E' e_R, with analytic omega_r_dot.
// R_d, omega_d, omega_d_dot are derived from the MRP reference.
RateReference so3_rate_reference(const Vec3& q, const Vec3& omega, const ReferenceSample& ref,
                                 const Mat3& lambda);

// Eq. (9): u_c = J w_r_dot - S(J w) w_r - K (w - w_r).
Vec3 ntcl_torque(const Mat3& j_hat, const Mat3& k, const Vec3& omega, const RateReference& r);
// Eq. (17): u_c = J w_r_dot - S(J w) w_r - Z(q)' K Z(q) (w - w_r).
Vec3 el_torque(const Mat3& j_hat, const Mat3& k, const Vec3& q, const Vec3& omega,
               const RateReference& r);
// Feed-forward cancellation (comparison): u_c = J w_r_dot - S(J w) w - K (w - w_r).
Vec3 feedforward_torque(const Mat3& j_hat, const Mat3& k, const Vec3& omega,
                        const RateReference& r);
// Eqs. (49)-(50): -K_d w while damping; -k_p beta_err,v - K_d w when holding an attitude.
Vec3 dpd_torque(const DpdGains& g, const Vec3& omega, const Vec3& q, const ReferenceSample& ref);

// [Rocksteady choice] momentum tracking of a plan (GuidanceParams::track_momentum_k). The plan
// (Eq. 44, made for J_hat) gives the body rate omega_d(t), omega_d_dot(t) and, through Eq. (45), the
// attitude R_d(t) it expects; its inertial angular momentum is h_d = R_d J_hat omega_d and
// h_d' = R_d tau_d with tau_d = J_hat omega_d_dot + omega_d x J_hat omega_d. The true momentum
// obeys h' = R u whatever the inertia, so
//   u = dR tau_d + k (dR J_hat omega_d - J_hat omega),  dR = R' R_d,
// drives h to h_d at rate k with no gyroscopic term: where J_hat is off, the body turns away from
// R_d (its free motion differs), but no thrust is spent holding it on the plan's rates. The NTCL
// (Eq. 9) instead fires S(J_hat omega) omega_r for every rate the body takes off the plan.
// Writes omega_r = J_hat^-1 dR J_hat omega_d (the rate that carries h_d) and its derivative
// J_hat^-1 (dR tau_d - omega x dR J_hat omega_d) for telemetry.
Vec3 momentum_torque(const Mat3& j_hat, const Mat3& j_hat_inv, double k, const Vec3& q,
                     const Vec3& omega, const ReferenceSample& ref, RateReference& rr);

// Regressor of Eq. (34): Y(w, w_r, w_r_dot) a = J w_r_dot - S(J w) w_r, with
// a = [Jxx, Jyy, Jzz, Jxy, Jxz, Jyz].
Mat36 regressor(const Vec3& omega, const Vec3& omega_r, const Vec3& omega_r_dot);
Vec6 inertia_to_params(const Mat3& j);
Mat3 params_to_inertia(const Vec6& a);
// The adaptive law's projection: the nearest (Frobenius) symmetric matrix whose eigenvalues lie in
// [lo, hi]. The set is convex and bounded, and every member is positive definite.
Mat3 project_inertia(const Mat3& j, double lo, double hi);

struct LawInput {
  Vec3 omega{Vec3::Zero()};
  Vec3 q{Vec3::Zero()};
  ReferenceSample ref{};
  bool saturated_last{false};  // allocator saturated on the previous tick (anti-windup)
};

class ControlLaws {
 public:
  void configure(const LawGains& g, const Mat3& j_hat, double dt);
  void reset_state();  // integral to zero, a_hat to J_hat
  // One tick of law `law`. Writes omega_r for telemetry.
  Vec3 compute(LawId law, const LawInput& in, RateReference& rr);

  const Vec3& integral() const { return integral_; }
  const Vec6& a_hat() const { return a_hat_; }
  const Mat3& j_hat() const { return j_hat_; }
  const Mat3& j_hat_inverse() const { return j_hat_inv_; }

 private:
  LawGains g_{};
  Mat3 j_hat_{Mat3::Identity()};
  Mat3 j_hat_inv_{Mat3::Identity()};
  double dt_{0.1};
  double eig_lo_{0.0};
  double eig_hi_{0.0};
  Vec3 integral_{Vec3::Zero()};
  Vec6 a_hat_{Vec6::Zero()};
};

}  // namespace rocksteady::gnc
