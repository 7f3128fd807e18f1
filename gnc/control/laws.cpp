#include "gnc/control/laws.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Eigenvalues>

#include "gnc/math/rotation.hpp"

namespace rocksteady::gnc {

RateReference mrp_rate_reference(const Vec3& q, const Vec3& omega, const ReferenceSample& ref,
                                 const Mat3& lambda) {
  RateReference r;
  if (ref.rate_only()) {
    return r;  // Eq. (51) phase 1: omega_r = 0, omega_r_dot = 0
  }
  const Mat3 z_inv = mrp::z_inverse(q);
  const Vec3 q_dot = mrp::z_matrix(q) * omega;  // Eq. (4)
  const Vec3 v = ref.q.q_dot + lambda * (ref.q.q - q);
  const Vec3 v_dot = ref.q.q_ddot + lambda * (ref.q.q_dot - q_dot);
  r.omega_r = z_inv * v;  // Eq. (9)
  // d/dt Z^-1 = -Z^-1 Zdot Z^-1
  r.omega_r_dot = -z_inv * (mrp::z_dot(q, q_dot) * r.omega_r) + z_inv * v_dot;
  return r;
}

RateReference so3_rate_reference(const Vec3& q, const Vec3& omega, const ReferenceSample& ref,
                                 const Mat3& lambda) {
  RateReference r;
  if (ref.rate_only()) {
    return r;
  }
  const Mat3 rot = mrp::to_dcm(q);
  const Mat3 rot_d = mrp::to_dcm(ref.q.q);
  // omega_d = vee(R_d' R_d_dot) from the MRP reference: omega_d = Z(q_d)^-1 qdot_d.
  const Mat3 zd_inv = mrp::z_inverse(ref.q.q);
  const Vec3 omega_d = zd_inv * ref.q.q_dot;
  const Vec3 omega_d_dot =
      zd_inv * (ref.q.q_ddot - mrp::z_dot(ref.q.q, ref.q.q_dot) * omega_d);
  const Mat3 qt = rot.transpose() * rot_d;  // R' R_d
  const Vec3 e_omega = omega - qt * omega_d;  // Eq. (35)
  const so3::ErrorRates e = so3::error_with_rates(rot, rot_d, e_omega);
  r.omega_r = qt * omega_d - lambda * e.e.transpose() * e.e_r;  // Eq. (37)
  // d/dt (R' R_d omega_d) = -S(omega) R' R_d omega_d + R' R_d omega_d_dot
  r.omega_r_dot = -skew(omega) * (qt * omega_d) + qt * omega_d_dot -
                  lambda * (e.e_dot.transpose() * e.e_r + e.e.transpose() * e.e_r_dot);
  return r;
}

Vec3 ntcl_torque(const Mat3& j_hat, const Mat3& k, const Vec3& omega, const RateReference& r) {
  // Eq. (9)
  return j_hat * r.omega_r_dot - skew(j_hat * omega) * r.omega_r - k * (omega - r.omega_r);
}

Vec3 momentum_torque(const Mat3& j_hat, const Mat3& j_hat_inv, double k, const Vec3& q,
                     const Vec3& omega, const ReferenceSample& ref, RateReference& rr) {
  const Mat3 dr = mrp::to_dcm(q).transpose() * mrp::to_dcm(ref.q.q);  // R' R_d
  const Vec3 h_plan = j_hat * ref.plan_omega;
  const Vec3 tau_plan = j_hat * ref.plan_omega_dot + ref.plan_omega.cross(h_plan);
  const Vec3 h_d = dr * h_plan;  // the plan's momentum in today's body frame
  const Vec3 tau_d = dr * tau_plan;
  rr.omega_r = j_hat_inv * h_d;
  rr.omega_r_dot = j_hat_inv * (tau_d - omega.cross(h_d));
  return tau_d + k * (h_d - j_hat * omega);
}

Vec3 el_torque(const Mat3& j_hat, const Mat3& k, const Vec3& q, const Vec3& omega,
               const RateReference& r) {
  const Mat3 z = mrp::z_matrix(q);
  // Eq. (17)
  return j_hat * r.omega_r_dot - skew(j_hat * omega) * r.omega_r -
         z.transpose() * k * z * (omega - r.omega_r);
}

Vec3 feedforward_torque(const Mat3& j_hat, const Mat3& k, const Vec3& omega,
                        const RateReference& r) {
  // Eq. (9) with omega in place of omega_r in the gyroscopic term: cancels S(J w) w exactly.
  return j_hat * r.omega_r_dot - skew(j_hat * omega) * omega - k * (omega - r.omega_r);
}

Vec3 dpd_torque(const DpdGains& g, const Vec3& omega, const Vec3& q, const ReferenceSample& ref) {
  if (ref.phase != ReferencePhase::kHold) {
    return -g.k_d * omega;  // Eq. (49): rate damping
  }
  const Vec4 beta_err = quat::error(mrp::to_quaternion(q), mrp::to_quaternion(ref.q.q));
  return -g.k_p * beta_err.head<3>() - g.k_d * omega;  // Eq. (50)
}

namespace {
// L(v) a = J v for a = [Jxx, Jyy, Jzz, Jxy, Jxz, Jyz].
Mat36 inertia_product_matrix(const Vec3& v) {
  Mat36 l;
  l << v.x(), 0.0, 0.0, v.y(), v.z(), 0.0,  //
      0.0, v.y(), 0.0, v.x(), 0.0, v.z(),   //
      0.0, 0.0, v.z(), 0.0, v.x(), v.y();
  return l;
}
}  // namespace

Mat36 regressor(const Vec3& omega, const Vec3& omega_r, const Vec3& omega_r_dot) {
  // J w_r_dot - S(J w) w_r = J w_r_dot + S(w_r) J w
  return inertia_product_matrix(omega_r_dot) + skew(omega_r) * inertia_product_matrix(omega);
}

Vec6 inertia_to_params(const Mat3& j) {
  Vec6 a;
  a << j(0, 0), j(1, 1), j(2, 2), j(0, 1), j(0, 2), j(1, 2);
  return a;
}

Mat3 params_to_inertia(const Vec6& a) {
  Mat3 j;
  j << a[0], a[3], a[4],  //
      a[3], a[1], a[5],   //
      a[4], a[5], a[2];
  return j;
}

Mat3 project_inertia(const Mat3& j, double lo, double hi) {
  const Mat3 sym = 0.5 * (j + j.transpose());
  // Fast path: closed-form eigenvalues; most ticks the estimate is well inside the set.
  Eigen::SelfAdjointEigenSolver<Mat3> es;
  es.computeDirect(sym, Eigen::EigenvaluesOnly);
  const double margin = 1e-6 * hi;
  if (es.eigenvalues().minCoeff() >= lo + margin && es.eigenvalues().maxCoeff() <= hi - margin) {
    return sym;
  }
  // Iterative (QR) solver: accurate eigenvectors even for repeated eigenvalues; fixed-size, no heap.
  es.compute(sym, Eigen::ComputeEigenvectors);
  Vec3 lam = es.eigenvalues();
  for (int i = 0; i < 3; ++i) lam[i] = std::clamp(lam[i], lo, hi);
  const Mat3& v = es.eigenvectors();
  return v * lam.asDiagonal() * v.transpose();
}

void ControlLaws::configure(const LawGains& g, const Mat3& j_hat, double dt) {
  g_ = g;
  j_hat_ = j_hat;
  j_hat_inv_ = j_hat.inverse();
  dt_ = dt;
  Eigen::SelfAdjointEigenSolver<Mat3> es;
  es.computeDirect(j_hat, Eigen::EigenvaluesOnly);
  eig_lo_ = g.adaptive.eig_floor_ratio * es.eigenvalues().minCoeff();
  eig_hi_ = g.adaptive.eig_ceiling_ratio * es.eigenvalues().maxCoeff();
}

void ControlLaws::reset_state() {
  integral_.setZero();
  a_hat_ = inertia_to_params(j_hat_);  // a_hat(0) from J_hat_tot (Eq. 34)
}

Vec3 ControlLaws::compute(LawId law, const LawInput& in, RateReference& rr) {
  switch (law) {
    case LawId::kNtcl:
      rr = mrp_rate_reference(in.q, in.omega, in.ref, g_.ntcl.lambda);
      return ntcl_torque(j_hat_, g_.ntcl.k, in.omega, rr);
    case LawId::kNtclEl:
      rr = mrp_rate_reference(in.q, in.omega, in.ref, g_.el.lambda);
      return el_torque(j_hat_, g_.el.k, in.q, in.omega, rr);
    case LawId::kFeedforward:
      rr = mrp_rate_reference(in.q, in.omega, in.ref, g_.feedforward.lambda);
      return feedforward_torque(j_hat_, g_.feedforward.k, in.omega, rr);
    case LawId::kIntegral: {
      rr = mrp_rate_reference(in.q, in.omega, in.ref, g_.integral.lambda);
      const Vec3 s = in.omega - rr.omega_r;
      // Eq. (19) with anti-windup: conditional integration (frozen while the allocator saturates)
      // and a per-axis clamp.
      if (!in.saturated_last) {
        integral_ += dt_ * (g_.integral.k_i * s);
        const double lim = g_.integral.integral_limit_nm;
        for (int i = 0; i < 3; ++i) integral_[i] = std::clamp(integral_[i], -lim, lim);
      }
      return ntcl_torque(j_hat_, g_.integral.k, in.omega, rr) - integral_;
    }
    case LawId::kAdaptive: {
      rr = mrp_rate_reference(in.q, in.omega, in.ref, g_.adaptive.lambda);
      const Vec3 s = in.omega - rr.omega_r;
      const Mat36 y = regressor(in.omega, rr.omega_r, rr.omega_r_dot);
      const Vec3 u = y * a_hat_ - g_.adaptive.k * s;  // Eq. (34)
      // a_hat_dot = -Gamma Proj(a_hat, Y' s): Euler step, then projection onto the convex set.
      const Vec6 a_next = a_hat_ - dt_ * g_.adaptive.gamma * (y.transpose() * s);
      a_hat_ = inertia_to_params(project_inertia(params_to_inertia(a_next), eig_lo_, eig_hi_));
      return u;
    }
    case LawId::kSo3:
      rr = so3_rate_reference(in.q, in.omega, in.ref, g_.so3.lambda);
      return ntcl_torque(j_hat_, g_.so3.k, in.omega, rr);  // Eq. (37)
    case LawId::kDpd:
      rr = RateReference{};
      return dpd_torque(g_.dpd, in.omega, in.q, in.ref);
  }
  rr = RateReference{};
  return Vec3::Zero();
}

}  // namespace rocksteady::gnc
