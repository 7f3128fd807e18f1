#include "gnc/estimation/identifier.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include "gnc/check.hpp"
#include "gnc/math/rotation.hpp"

namespace rocksteady::gnc {

namespace {

// Weighted recursive least squares with a vector measurement (I7): Phi theta = y + v,
// cov(v) = R (the window noise plus what the other groups' uncertainty contributes).
template <int N>
void rls_update(Eigen::Matrix<double, N, 1>& theta, Eigen::Matrix<double, N, N>& p,
                const Eigen::Matrix<double, 3, N>& phi, const Vec3& y, const Mat3& r) {
  const Eigen::Matrix<double, N, 3> p_phi_t = p * phi.transpose();
  const Mat3 s = r + phi * p_phi_t;
  const Eigen::LDLT<Mat3> ldlt(s);
  if (ldlt.info() != Eigen::Success || !ldlt.isPositive()) return;
  const Eigen::Matrix<double, N, 3> k = ldlt.solve(p_phi_t.transpose()).transpose();
  theta += k * (y - phi * theta);
  p.noalias() -= k * p_phi_t.transpose();
  p = 0.5 * (p + p.transpose()).eval();
}

// Exponential forgetting over one window (I8): P <- P / lambda, lambda = exp(-T / tau), capped so
// no variance exceeds its prior (no covariance wind-up while a direction is not excited).
template <int N>
void forget(Eigen::Matrix<double, N, N>& p, double window_s, double tau_s, double prior_var) {
  if (tau_s <= 0.0) return;
  p *= std::exp(window_s / tau_s);
  const double worst = p.diagonal().maxCoeff();
  if (worst > prior_var) p *= prior_var / worst;
}

}  // namespace

Vec6 inertia_params(const Mat3& j) {
  Vec6 a;
  a << j(0, 0), j(1, 1), j(2, 2), j(0, 1), j(0, 2), j(1, 2);
  return a;
}

Mat3 inertia_matrix(const Vec6& a) {
  Mat3 j;
  j << a(0), a(3), a(4),  //
      a(3), a(1), a(5),   //
      a(4), a(5), a(2);
  return j;
}

Mat36 inertia_regressor(const Vec3& v) {
  // (I1): J v = L(v) a, a = [Jxx Jyy Jzz Jxy Jxz Jyz].
  Mat36 l;
  l << v.x(), 0.0, 0.0, v.y(), v.z(), 0.0,  //
      0.0, v.y(), 0.0, v.x(), 0.0, v.z(),   //
      0.0, 0.0, v.z(), 0.0, v.x(), v.y();
  return l;
}

Mat3 cross_product_covariance(const Mat3& a, const Mat3& b) {
  // E[S(a) B S(a)'] entry (i, j) = sum eps_ipk eps_jql A_pq B_kl, which for symmetric A and B
  // is the closed form below (I20).
  const double ta = a.trace(), tb = b.trace();
  const Mat3 ab = a * b;
  Mat3 out = ab + ab.transpose() - ta * b - tb * a;
  out.diagonal().array() += ta * tb - ab.trace();
  return out;
}

void bias_jacobian_times(const Vec3& m, const Mat6& p_a, Mat36 (&out)[3]) {
  // Row r of L(e_k) selects parameter kSel[k][r] (I1): J e_1 = (Jxx, Jxy, Jxz), and so on.
  static constexpr int kSel[3][3] = {{0, 3, 4}, {3, 1, 5}, {4, 5, 2}};
  const Mat36 lmp = inertia_regressor(m) * p_a;  // L(m) P_a
  const Mat3 sm = skew(m);
  for (int k = 0; k < 3; ++k) {
    Mat36 lep;
    for (int r = 0; r < 3; ++r) lep.row(r) = p_a.row(kSel[k][r]);
    out[k].noalias() = sm * lep;
    out[k].noalias() += skew(Vec3::Unit(k)) * lmp;
  }
}

Mat3 bilinear_bias_covariance(const Vec3& m, const Mat36 (&bpa)[3], const Mat3& p_b) {
  // sum_kl P_b(k, l) (B_k P_a) B_l' = sum_k (B_k P_a) D_k',  D_k = sum_l P_b(k, l) B_l.
  const Mat3 sm = skew(m);
  const Mat36 lm = inertia_regressor(m);
  Mat36 b[3];
  for (int l = 0; l < 3; ++l) b[l] = sm * inertia_regressor(Vec3::Unit(l)) + skew(Vec3::Unit(l)) * lm;
  Mat3 out = Mat3::Zero();
  for (int k = 0; k < 3; ++k) {
    const Mat36 dk = p_b(k, 0) * b[0] + p_b(k, 1) * b[1] + p_b(k, 2) * b[2];
    out.noalias() += bpa[k] * dk.transpose();
  }
  return out;
}

Vec3 thruster_direction(const RcsLayout& l, int i) {
  const Vec3& d = l.channel_direction[i / 2];
  return (i % 2 == 0) ? d : Vec3(-d);
}

Vec3 thruster_position(const RcsLayout& l, int i) {
  return l.pod_position[l.channel_pod[i / 2]];
}

double held_disturbance_factor(double window_s, double hold_s) {
  // R_w(u) for the triangle of half-width h = T/2 (a piecewise cubic):
  //   2h/3 - u^2/h + u^3/(2h^2) on [0, h],  (2h - u)^3/(6h^2) on [h, 2h], 0 beyond.
  // For hold <= T/2 the integral is closed: T hold/3 - hold^3/(3T) + hold^4/(5T^2) (I21);
  // beyond, Simpson's rule on [0, min(hold, T)] (breakpoint at h on a node).
  const double t = window_s;
  const double tau = hold_s;
  if (tau <= 0.5 * t)
    return t * tau / 3.0 - tau * tau * tau / (3.0 * t) + tau * tau * tau * tau / (5.0 * t * t);
  const double h = 0.5 * t;
  const auto r_w = [h](double u) {
    if (u <= h) return 2.0 * h / 3.0 - u * u / h + u * u * u / (2.0 * h * h);
    if (u <= 2.0 * h) return (2.0 * h - u) * (2.0 * h - u) * (2.0 * h - u) / (6.0 * h * h);
    return 0.0;
  };
  const auto f = [&](double u) { return (1.0 - u / tau) * r_w(u); };
  // Two Simpson pieces, [0, h] and [h, min(tau, 2h)], 200 intervals each.
  const auto simpson = [&](double a, double b) {
    constexpr int kN = 200;
    const double dx = (b - a) / kN;
    double acc = f(a) + f(b);
    for (int i = 1; i < kN; ++i) acc += (i % 2 == 1 ? 4.0 : 2.0) * f(a + i * dx);
    return acc * dx / 3.0;
  };
  return 2.0 * (simpson(0.0, h) + simpson(h, std::fmin(tau, 2.0 * h)));
}

IdentifierConfigCheck validate(const IdentifierConfig& c) {
  auto bad = [](const char* field, const char* reason) {
    return IdentifierConfigCheck{false, field, reason};
  };
  if (!finite_positive(c.dt)) return bad("dt", "must be positive and finite");
  if (!finite_positive(c.window_s)) return bad("window_s", "must be positive and finite");
  const double ticks = c.window_s / c.dt;
  const long n = std::lround(ticks);
  if (std::fabs(ticks - static_cast<double>(n)) > 1e-6 || n < 8 || n % 2 != 0 || n > 1000000) {
    return bad("window_s", "must be an even number of ticks, at least 8");
  }
  if (!(std::isfinite(c.early_window_s) && c.early_window_s >= 0.0)) {
    return bad("early_window_s", "must be >= 0 and finite");
  }
  if (!(std::isfinite(c.early_span_s) && c.early_span_s >= 0.0)) {
    return bad("early_span_s", "must be >= 0 and finite");
  }
  if (c.early_window_s > 0.0) {
    const double et = c.early_window_s / c.dt;
    if (std::fabs(et - std::round(et)) > 1e-6 || std::lround(et) % 2 != 0 || std::lround(et) < 8) {
      return bad("early_window_s", "must be an even number of ticks, at least 8");
    }
    if (c.early_window_s > c.window_s) return bad("early_window_s", "must not exceed window_s");
  }
  for (int ch = 0; ch < kChannels; ++ch) {
    if (!c.rcs.channel_direction[ch].allFinite() ||
        std::fabs(c.rcs.channel_direction[ch].norm() - 1.0) > 1e-6) {
      return bad("rcs.channel_direction", "not a unit vector");
    }
    if (c.rcs.channel_pod[ch] < 0 || c.rcs.channel_pod[ch] >= kPods) {
      return bad("rcs.channel_pod", "pod index out of range");
    }
  }
  for (int k = 0; k < kPods; ++k) {
    if (!c.rcs.pod_position[k].allFinite()) return bad("rcs.pod_position", "non-finite value");
  }
  if (!c.j0.allFinite() || (c.j0 - c.j0.transpose()).norm() > 1e-9 * (1.0 + c.j0.norm()) ||
      Eigen::LLT<Mat3>(c.j0).info() != Eigen::Success) {
    return bad("j0", "not symmetric positive definite");
  }
  if (!c.r0.allFinite()) return bad("r0", "non-finite value");
  if (!c.k0.allFinite()) return bad("k0", "non-finite value");
  if (!finite_positive(c.j_prior_sigma)) return bad("j_prior_sigma", "must be positive and finite");
  if (!finite_positive(c.r_prior_sigma)) return bad("r_prior_sigma", "must be positive and finite");
  if (!finite_positive(c.k_prior_sigma)) return bad("k_prior_sigma", "must be positive and finite");
  if (!finite_non_negative(c.gyro_sigma)) return bad("gyro_sigma", "must be >= 0 and finite");
  if (!finite_non_negative(c.gyro_bias_sigma)) {
    return bad("gyro_bias_sigma", "must be >= 0 and finite");
  }
  if (!finite_non_negative(c.gate_chi2)) return bad("gate_chi2", "must be >= 0 (0: no gate)");
  if (c.gate_reinflate_after < 1) return bad("gate_reinflate_after", "must be >= 1");
  if (!finite_non_negative(c.fault_torque_sigma)) {
    return bad("fault_torque_sigma", "must be >= 0 and finite (0: no fault torque state)");
  }
  if (c.fault_torque_sigma > 0.0 && c.mode != IdentifierMode::kJoint) {
    return bad("fault_torque_sigma", "the fault torque state (I22) needs the joint mode");
  }
  if (!finite_non_negative(c.disturbance_sigma)) {
    return bad("disturbance_sigma", "must be >= 0 and finite");
  }
  if (!finite_positive(c.disturbance_corr_s)) {
    return bad("disturbance_corr_s", "must be positive and finite");
  }
  if (!finite_positive(c.torque_floor)) return bad("torque_floor", "must be positive and finite");
  if (!finite_non_negative(c.j_forget_s))
    return bad("j_forget_s", "must be >= 0 (0: no forgetting)");
  if (!finite_non_negative(c.r_forget_s))
    return bad("r_forget_s", "must be >= 0 (0: no forgetting)");
  if (!finite_non_negative(c.k_forget_s))
    return bad("k_forget_s", "must be >= 0 (0: no forgetting)");
  if ((c.j_forget_s > 0.0 && c.j_forget_s < c.window_s) ||
      (c.r_forget_s > 0.0 && c.r_forget_s < c.window_s) ||
      (c.k_forget_s > 0.0 && c.k_forget_s < c.window_s)) {
    return bad("j_forget_s", "a forgetting time shorter than one window forgets everything");
  }
  if (!finite_non_negative(c.min_torque_impulse)) return bad("min_torque_impulse", "must be >= 0");
  if (!finite_non_negative(c.min_force_impulse)) return bad("min_force_impulse", "must be >= 0");
  if (!finite_non_negative(c.min_snr)) return bad("min_snr", "must be >= 0");
  if (!finite_non_negative(c.min_inertia_information)) {
    return bad("min_inertia_information", "must be >= 0 (0: off)");
  }
  if (!finite_non_negative(c.min_offset_information)) {
    return bad("min_offset_information", "must be >= 0 (0: off)");
  }
  if (c.guard_halvings < 0 || c.guard_halvings > 10) return bad("guard_halvings", "must be in [0, 10]");
  if (!finite_non_negative(c.min_thruster_impulse)) {
    return bad("min_thruster_impulse", "must be >= 0");
  }
  if (!finite_positive(c.r_max_offset)) return bad("r_max_offset", "must be positive and finite");
  if (!std::isfinite(c.k_min) || !std::isfinite(c.k_max) || c.k_min < 0.0 || c.k_max <= c.k_min) {
    return bad("k_min", "need 0 <= k_min < k_max");
  }
  if (!(c.unobservable_ratio > 0.0 && c.unobservable_ratio < 1.0)) {
    return bad("unobservable_ratio", "must be in (0, 1)");
  }
  if (!finite_positive(c.j_confident_rel)) return bad("j_confident_rel", "must be positive");
  if (!finite_positive(c.r_confident)) return bad("r_confident", "must be positive");
  if (!finite_positive(c.k_confident)) return bad("k_confident", "must be positive");
  return {};
}

void Identifier::configure(const IdentifierConfig& c) {
  c_ = c;
  n_full_ = static_cast<int>(std::lround(c.window_s / c.dt));
  n_early_ = c.early_window_s > 0.0 && c.early_span_s > 0.0
                 ? static_cast<int>(std::lround(c.early_window_s / c.dt))
                 : 0;
  n_ = n_full_;
  dist_factor_ = held_disturbance_factor(c.window_s, c.disturbance_corr_s);
  dist_factor_early_ =
      n_early_ > 0 ? held_disturbance_factor(c.early_window_s, c.disturbance_corr_s) : 0.0;
  const int n_min = n_early_ > 0 ? n_early_ : n_full_;  // validate: early_window_s <= window_s
  // Ticks of one joint step: linearisation, the second-order term (3), the information gate
  // (I26), gain rows, gain, a gate re-inflation (4), apply, covariance rows, finish, strengths
  // and report. Smallest blocks that let the step end well before the next window closes.
  const auto ticks_for = [](int g, int r) {
    return 1 + 3 + 1 + (kIdParams + g - 1) / g + 1 + 4 + 1 + (kIdParams + r - 1) / r +
           (kIdParams + kSymmetriseRowsPerTick - 1) / kSymmetriseRowsPerTick + 1 + 1 +
           (kIdParams + kAnchorRowsPerTick - 1) / kAnchorRowsPerTick + 1 +
           (kThrusters + kFaultJetsPerTick - 1) / kFaultJetsPerTick +
           2 + (kIdParams + kSettleRowsPerTick - 1) / kSettleRowsPerTick;
  };
  gain_rows_per_tick_ = 4;
  cov_rows_per_tick_ = 1;
  // (4/5 of the window: ticks withheld for other periodic work must not make the step overrun.)
  while (ticks_for(gain_rows_per_tick_, cov_rows_per_tick_) > (n_min - 1) * 4 / 5 &&
         cov_rows_per_tick_ < kIdParams) {
    cov_rows_per_tick_ = std::min(kIdParams, 2 * cov_rows_per_tick_);
    gain_rows_per_tick_ = std::min(kIdParams, 2 * gain_rows_per_tick_);
  }
  for (int i = 0; i < kThrusters; ++i) {
    e_[i] = thruster_direction(c.rcs, i);
    p_pos_[i] = thruster_position(c.rcs, i);
    p_cross_e_[i] = p_pos_[i].cross(e_[i]);
  }
  reset();
}

void Identifier::reset() {
  a_ = inertia_params(c_.j0);
  r_ = c_.r0;
  k_ = c_.k0;
  p_j_ = c_.j_prior_sigma * c_.j_prior_sigma * Mat6::Identity();
  p_r_ = c_.r_prior_sigma * c_.r_prior_sigma * Mat3::Identity();
  p_k_ = c_.k_prior_sigma * c_.k_prior_sigma * Mat16::Identity();
  b_.setZero();
  p_b_ = c_.gyro_bias_sigma * c_.gyro_bias_sigma * Mat3::Identity();
  bias_shift_.setZero();
  bias_consider_pending_ = false;
  gated_in_row_ = 0;
  gate_reinflation_due_ = 0;
  innovation_chi2_ = 0.0;
  fill_pending_ = false;
  p_all_.setZero();
  p_all_.topLeftCorner<6, 6>() = p_j_;
  p_all_.block<3, 3>(kIdR, kIdR) = p_r_;
  p_all_.block<kThrusters, kThrusters>(kIdK, kIdK) = p_k_;
  p_all_.block<3, 3>(kIdB, kIdB) = p_b_;
  d_.setZero();
  p_all_.block<3, 3>(kIdD, kIdD) =
      c_.fault_torque_sigma * c_.fault_torque_sigma * Mat3::Identity();
  ft_ = IdentifierFaultTorque{};
  ft_.d_cov = p_all_.block<3, 3>(kIdD, kIdD);
  fault_jet_next_ = 0;
  settle_streak_ = 0;
  d_held_zero_ = false;
  settle_ = SettleStep{};
  reference_.fill(true);
  joint_ = JointStep{};
  anchor_ = AnchorStep{};
  acc_ = Window{};
  latched_ = Window{};
  sample_ = -1;
  identified_s_ = 0.0;
  n_ = window_ticks_next();
  phase_ = Phase::kIdle;
  latched_noise_ = 1.0;
  latched_r_ = Mat3::Identity();
  residual_cov_ = Mat3::Identity();
  exc_ = IdentifierExcitation{};
  obs_ = IdentifierObservability{};
  counters_ = IdentifierCounters{};
  est_ = IdentifierEstimate{};
  report();
}

namespace {
// Back to the prior for parameters [first, first + n) of a covariance: cross terms cleared.
template <int N>
void reinflate_block(Eigen::Matrix<double, N, N>& p, int first, int n, double var) {
  p.middleRows(first, n).setZero();
  p.middleCols(first, n).setZero();
  for (int i = first; i < first + n; ++i) p(i, i) = var;
}
}  // namespace

void Identifier::reinflate_inertia() {
  complete_reinflation();
  joint_finish_covariance();
  finish_anchor();
  finish_settle();
  joint_.pending = false;  // a gain from the old covariance is dropped
  joint_.started = false;
  const double v = c_.j_prior_sigma * c_.j_prior_sigma;
  reinflate_block<6>(p_j_, 0, 6, v);
  reinflate_block<kIdParams>(p_all_, 0, 6, v);
  ++counters_.reinflations;
}

void Identifier::reinflate_offset() {
  complete_reinflation();
  joint_finish_covariance();
  finish_anchor();
  finish_settle();
  joint_.pending = false;  // a gain from the old covariance is dropped
  joint_.started = false;
  const double v = c_.r_prior_sigma * c_.r_prior_sigma;
  reinflate_block<3>(p_r_, 0, 3, v);
  reinflate_block<kIdParams>(p_all_, 6, 3, v);
  ++counters_.reinflations;
}

void Identifier::reinflate_thruster(int i) {
  complete_reinflation();
  if (i < 0 || i >= kThrusters) return;
  joint_finish_covariance();
  finish_anchor();
  finish_settle();
  joint_.pending = false;
  joint_.started = false;
  const double v = c_.k_prior_sigma * c_.k_prior_sigma;
  reinflate_block<kThrusters>(p_k_, i, 1, v);
  reinflate_block<kIdParams>(p_all_, kIdK + i, 1, v);
  reference_[i] = false;  // a changed thruster no longer defines the thrust scale
  ++counters_.reinflations;
}

void Identifier::reinflate_all() {
  // The same covariance as reinflate_inertia, reinflate_offset, reinflate_thruster(0..15) and
  // (unless d was settled at zero, I24) reinflate_fault_torque in turn (to rounding), on one
  // tick of the Cortex-M7 budget. Those finish every pending block of rows first (the joint
  // step's covariance rows, the anchor's, the settling's: up to 40 k instructions when a
  // confirmation lands while a step is under way), and then clear every row but the rate bias
  // b's (and d's when settled). Each entry's update reads only that entry and the step's
  // factors, so only the kept block is computed here; the rest is about to be the prior.
  complete_reinflation();
  anchor_scale_finish();  // a scale anchor begun on the last block ends as it would have
  const bool d_live = !d_held_zero_;
  std::array<bool, kIdParams> kept{};
  for (int a = 0; a < 3; ++a) {
    kept[static_cast<std::size_t>(kIdB + a)] = true;
    kept[static_cast<std::size_t>(kIdD + a)] = !d_live;
  }
  finish_kept_rows(kept);
  gate_reinflation_due_ = 0;  // this re-inflation covers the gate's (I18)
  joint_.pending = false;  // a gain from the old covariance is dropped
  joint_.started = false;
  // The joint covariance itself is rewritten on the identifier's next free tick
  // (complete_reinflation: 7.7 kB to clear, 3.5 k Cortex-M7 instructions that made the tick after
  // a confirmation 21.4 k in DETUMBLE); nothing reads it before, and whatever would, completes it
  // first.
  fill_.p_bb = p_all_.block<3, 3>(kIdB, kIdB);
  fill_.p_bd = p_all_.block<3, 3>(kIdB, kIdD);
  fill_.p_dd = p_all_.block<3, 3>(kIdD, kIdD);
  fill_.d_live = d_live;
  fill_pending_ = true;
  const double vj = c_.j_prior_sigma * c_.j_prior_sigma;
  const double vr = c_.r_prior_sigma * c_.r_prior_sigma;
  const double vk = c_.k_prior_sigma * c_.k_prior_sigma;
  fill_.vj = vj;
  fill_.p_r = vr * Mat3::Identity();
  fill_.vk = vk;
  if (d_live) {
    // (I22) d too: a fault the detector isolated changes the constant torque; its estimate is
    // kept as the starting point. A d settled at zero was never in the fault and stays out.
    d_held_zero_ = false;
    settle_streak_ = 0;
  }
  p_j_ = vj * Mat6::Identity();
  p_r_ = vr * Mat3::Identity();
  p_k_ = vk * Mat16::Identity();
  reference_.fill(false);  // no thruster defines the thrust scale any more
  ++counters_.reinflations;
}

void Identifier::restart_at(const Mat3& j, double j_sigma, const Vec3& r, const Mat3& r_cov,
                            const Vec16& k, double k_sigma) {
  if (!fill_pending_) return;  // only right after reinflate_all
  const double vj = c_.j_prior_sigma * c_.j_prior_sigma;
  const double vr = c_.r_prior_sigma * c_.r_prior_sigma;
  const double vk = c_.k_prior_sigma * c_.k_prior_sigma;
  a_ = inertia_params(j);
  r_ = r;
  k_ = k;
  fill_.vj = std::fmin(vj, j_sigma * j_sigma);
  fill_.p_r = 0.5 * (r_cov + r_cov.transpose());
  if (!(fill_.p_r.trace() <= 3.0 * vr)) fill_.p_r = vr * Mat3::Identity();
  fill_.vk = std::fmin(vk, k_sigma * k_sigma);
  p_j_ = fill_.vj * Mat6::Identity();
  p_r_ = fill_.p_r;
  p_k_ = fill_.vk * Mat16::Identity();
  est_.j = inertia_matrix(a_);
  est_.r = r_;
  est_.k = k_;
}

void Identifier::complete_reinflation() {
  if (!fill_pending_) return;
  fill_pending_ = false;
  p_all_.setZero();
  for (int i = 0; i < 6; ++i) p_all_(i, i) = fill_.vj;
  p_all_.block<3, 3>(kIdR, kIdR) = fill_.p_r;
  for (int i = 0; i < kThrusters; ++i) p_all_(kIdK + i, kIdK + i) = fill_.vk;
  p_all_.block<3, 3>(kIdB, kIdB) = fill_.p_bb;
  if (fill_.d_live) {
    const double vd = c_.fault_torque_sigma * c_.fault_torque_sigma;
    for (int i = 0; i < 3; ++i) p_all_(kIdD + i, kIdD + i) = vd;
  } else {
    p_all_.block<3, 3>(kIdB, kIdD) = fill_.p_bd;
    p_all_.block<3, 3>(kIdD, kIdB) = fill_.p_bd.transpose();
    p_all_.block<3, 3>(kIdD, kIdD) = fill_.p_dd;
  }
}

const MatId& Identifier::joint_covariance() {
  complete_reinflation();
  return p_all_;
}

void Identifier::finish_kept_rows(const std::array<bool, kIdParams>& kept) {
  // What joint_finish_covariance, finish_anchor and finish_settle would leave in the block of the
  // kept rows and columns; every other entry is about to be cleared and is not computed. Each
  // update of entry (i, j) reads only entry (i, j) and the step's factors.
  std::array<int, kIdParams> idx{};
  int n = 0;
  for (int i = 0; i < kIdParams; ++i) {
    if (kept[static_cast<std::size_t>(i)]) idx[static_cast<std::size_t>(n++)] = i;
  }
  if (joint_.rows_pending) {
    joint_.rows_pending = false;
    // joint_covariance_rows, entry by entry (equal to its row form up to rounding).
    const VecId& d = joint_.d;
    const bool full_form = !exc_.offset || !c_.gyro_bias_estimated;
    for (int a = 0; a < n; ++a) {
      const int i = idx[static_cast<std::size_t>(a)];
      if (i < joint_.cov_rows) continue;  // this row is done
      const Vec3 ks = joint_.k.row(i) * joint_.s;
      for (int b = 0; b < n; ++b) {
        const int j = idx[static_cast<std::size_t>(b)];
        double v = d(i) * (p_all_(i, j) * d(j));
        v -= joint_.k.row(i).dot(joint_.p_ht.row(j));
        if (full_form) {
          v -= joint_.p_ht.row(i).dot(joint_.k.row(j));
          v += ks.dot(joint_.k.row(j).transpose());
        }
        p_all_(i, j) = v;
      }
    }
    joint_.cov_rows = kIdParams;
    for (int a = 0; a < n; ++a) {  // symmetrise_rows on the kept pairs
      const int i = idx[static_cast<std::size_t>(a)];
      if (i < joint_.sym_rows) continue;
      for (int b = a + 1; b < n; ++b) {
        const int j = idx[static_cast<std::size_t>(b)];
        const double v = 0.5 * (p_all_(i, j) + p_all_(j, i));
        p_all_(i, j) = v;
        p_all_(j, i) = v;
      }
    }
    joint_.sym_rows = kIdParams;
    // The cap of joint_finish_covariance, on the kept block, in the same order.
    for (int a = 0; a < n; ++a) {
      const int i = idx[static_cast<std::size_t>(a)];
      const double cap = i < kIdD ? c_.gyro_bias_sigma * c_.gyro_bias_sigma
                                  : c_.fault_torque_sigma * c_.fault_torque_sigma;
      if (p_all_(i, i) > cap) {
        const double f = std::sqrt(cap / p_all_(i, i));
        for (int b = 0; b < n; ++b) p_all_(i, idx[static_cast<std::size_t>(b)]) *= f;
        for (int b = 0; b < n; ++b) p_all_(idx[static_cast<std::size_t>(b)], i) *= f;
      }
    }
  }
  // The anchor's and the settling's rank-deficient terms: entry (i, j) of a row not yet done loses
  // term(min(i, j), max(i, j)) (anchor_rows, settle_rows).
  const auto subtract_kept = [&](int rows_done, auto term) {
    for (int a = 0; a < n; ++a) {
      const int i = idx[static_cast<std::size_t>(a)];
      if (i < rows_done) continue;
      for (int b = 0; b < n; ++b) {
        const int j = idx[static_cast<std::size_t>(b)];
        p_all_(i, j) -= i < j ? term(i, j) : term(j, i);
      }
    }
  };
  if (anchor_.pending) {
    anchor_.pending = false;
    subtract_kept(anchor_.rows, [this](int lo, int hi) { return anchor_.g(lo) * anchor_.pc(hi); });
    anchor_.rows = kIdParams;
  }
  if (settle_.pending) {
    settle_.pending = false;
    subtract_kept(settle_.rows, [this](int lo, int hi) {
      return settle_.g.row(lo).dot(settle_.pd.row(hi));
    });
    settle_.rows = kIdParams;
    p_all_.middleRows<3>(kIdD).setZero();
    p_all_.middleCols<3>(kIdD).setZero();
    p_b_ = p_all_.block<3, 3>(kIdB, kIdB);  // sync_blocks (the other blocks are re-inflated)
  }
}

void Identifier::reinflate_fault_torque() {
  complete_reinflation();
  // (I22) A declared change (a confirmed fault, its valve closed) changes the constant torque
  // too: d goes back to its prior covariance; the estimate is kept as the starting point.
  joint_finish_covariance();
  finish_anchor();
  finish_settle();
  joint_.pending = false;
  joint_.started = false;
  finish_settle();
  reinflate_block<kIdParams>(p_all_, kIdD, 3, c_.fault_torque_sigma * c_.fault_torque_sigma);
  d_held_zero_ = false;
  settle_streak_ = 0;
  ++counters_.reinflations;
}

void Identifier::shift_rate_bias(const Vec3& delta) {
  if (!delta.allFinite()) return;
  bias_shift_ += delta;
  if (phase_ == Phase::kIdle) apply_bias_changes();  // no step on a window with the old rate
}

void Identifier::consider_rate_bias(const Vec3& sigma) {
  if (!sigma.allFinite() || (sigma.array() < 0.0).any()) return;
  bias_consider_sigma_ = sigma;
  bias_consider_pending_ = true;
  if (phase_ == Phase::kIdle) apply_bias_changes();
}

void Identifier::apply_bias_changes() {
  complete_reinflation();
  b_ -= bias_shift_;
  bias_shift_.setZero();
  if (bias_consider_pending_ && c_.mode == IdentifierMode::kJoint) {
    bias_consider_pending_ = false;
    b_.setZero();
    p_all_.middleRows<3>(kIdB).setZero();
    p_all_.middleCols<3>(kIdB).setZero();
    for (int a = 0; a < 3; ++a) {
      const double v = bias_consider_sigma_(a) * bias_consider_sigma_(a);
      p_all_(kIdB + a, kIdB + a) = std::fmin(v, c_.gyro_bias_sigma * c_.gyro_bias_sigma);
    }
    p_b_ = p_all_.block<3, 3>(kIdB, kIdB);
  }
  est_.gyro_bias = b_;
  est_.gyro_bias_sigma = p_b_.diagonal().cwiseMax(0.0).cwiseSqrt();
}

void Identifier::sync_blocks() {
  p_j_ = p_all_.topLeftCorner<6, 6>();
  p_r_ = p_all_.block<3, 3>(kIdR, kIdR);
  p_k_ = p_all_.block<kThrusters, kThrusters>(kIdK, kIdK);
  p_b_ = p_all_.block<3, 3>(kIdB, kIdB);
}

Mat3 Identifier::bias_jacobian() const {
  // (I17): sum_i w_i dt [S(omega_i) J - S(J omega_i)] = S(m) J - S(J m), m = sum_i w_i dt omega_i.
  const Mat3 j = inertia_matrix(a_);
  return skew(latched_.m) * j - skew(j * latched_.m);
}

void Identifier::joint_gain() {
  // (I13): e(x) = A_J a - sum_i k_i [(p_i + r) x e_i] ∫ w F_i dt = noise, linearised at the
  // estimate: H = [A_J, S(F_hat), -Phi_k(r_hat), -G], one extended-RLS step on all 28
  // parameters (with the rate bias b of I17).
  // The gain is formed over several ticks (joint_gain, then joint_gain_rows per block of rows),
  // the update applied on one (joint_apply) and the covariance updated over several
  // (joint_covariance_step), so no tick carries more than a block of the 28-parameter step.
  joint_.pending = false;
  joint_.started = false;
  window_fitted_ = false;
  const Vec3 force = net_force_impulse();
  const Mat316 phi_k = strength_regressor();
  const Vec3 tau = phi_k * k_;
  // (I17): the rate carries a bias b: e = A_J a - G(a) b - tau, G(a) b = [S(m) L(b) + S(b) L(m)] a.
  const Mat3 g = bias_jacobian();
  // (I22): a constant torque d adds W d, W = ∫ w dt.
  joint_.e0 = latched_.a_j * a_ - g * b_ - tau - latched_.weight * d_;
  exc_.inertia_motion = latched_.a_j.norm() * a_.norm() >= torque_threshold();
  exc_.inertia_scale = tau.norm() >= torque_threshold();
  exc_.offset = force.norm() >= c_.min_force_impulse;
  joint_.any_thruster = false;
  for (int i = 0; i < kThrusters; ++i) {
    exc_.thruster[i] = latched_.impulse(i) >= c_.min_thruster_impulse;
    joint_.any_thruster = joint_.any_thruster || exc_.thruster[i];
  }
  if (!exc_.inertia_motion && !exc_.inertia_scale) return;
  Eigen::Matrix<double, 3, kIdParams> h;
  h.leftCols<6>() = latched_.a_j - skew(latched_.m) * inertia_regressor(b_) -
                    skew(b_) * inertia_regressor(latched_.m);
  h.middleCols<3>(kIdR) = skew(force);
  h.middleCols<kThrusters>(kIdK) = -phi_k;
  h.middleCols<3>(kIdB) = -g;
  h.middleCols<3>(kIdD) = -latched_.weight * Mat3::Identity();

  // (I26) decided on the first block of gain rows (information_gate), a tick of its own.
  exc_.inertia_informative = true;
  exc_.inertia_information = 0.0;
  exc_.offset_informative = true;
  joint_.inertia_held = false;
  joint_.offset_held = false;
  joint_.damped = false;
  joint_.gated = false;

  // Forgetting per group (I8): P_f = D P D, D = diag(lambda_g^-1/2) on the excited groups.
  VecId& d = joint_.d;
  d.setOnes();
  if (exc_.inertia_scale && c_.j_forget_s > 0.0) {
    d.head<6>().setConstant(std::exp(0.5 * latched_.length_s / c_.j_forget_s));
  }
  if (exc_.offset && c_.r_forget_s > 0.0) {
    d.segment<3>(6).setConstant(std::exp(0.5 * latched_.length_s / c_.r_forget_s));
  }
  if (joint_.any_thruster && c_.k_forget_s > 0.0) {
    d.segment<kThrusters>(kIdK).setConstant(std::exp(0.5 * latched_.length_s / c_.k_forget_s));
  }
  // (I20) on the next ticks (second_order_step), one part per tick.
  joint_.second_order.setZero();
  joint_.second_order_part = 0;
  // P_f H' = D P D H' without forming P_f, a block of rows per tick (joint_gain_rows).
  joint_.h = h;
  joint_.dht = d.asDiagonal() * h.transpose();
  joint_.gain_rows = 0;
  joint_.started = true;
}

bool Identifier::information_gate() {
  // (I26) What the window would teach J, against what J already knows:
  //   nu_J = tr(R^-1 H_a P_a H_a'),  nu_r = tr(R^-1 S(F) P_r S(F)'),
  // R the window's noise (I19). Below min_*_information the group is a consider parameter in
  // this window: no gain (joint_gain_rows), no forgetting (its rows of D and D H' put back to
  // one here, before any row of P H' is formed), its covariance carried (the full form).
  joint_.gated = true;
  if (!(c_.min_inertia_information > 0.0) && !(c_.min_offset_information > 0.0)) return false;
  const Eigen::LDLT<Mat3> r_ldlt(latched_r_);
  if (r_ldlt.info() != Eigen::Success) return true;
  const Mat3 r_inv = r_ldlt.solve(Mat3::Identity());
  if (c_.min_inertia_information > 0.0) {
    const Mat36 ha = joint_.h.leftCols<6>();
    const Mat3 m = ha * p_all_.topLeftCorner<6, 6>() * ha.transpose();
    exc_.inertia_information = r_inv.cwiseProduct(m).sum();  // tr(R^-1 M), both symmetric
    exc_.inertia_informative = exc_.inertia_information >= c_.min_inertia_information;
    joint_.inertia_held = !exc_.inertia_informative;
    if (joint_.inertia_held) {
      joint_.d.head<6>().setOnes();
      joint_.dht.topRows<6>() = ha.transpose();
    }
  }
  if (c_.min_offset_information > 0.0 && exc_.offset) {
    const Mat3 sf = joint_.h.middleCols<3>(kIdR);  // S(F_hat)
    const Mat3 m = sf * p_all_.block<3, 3>(kIdR, kIdR) * sf.transpose();
    exc_.offset_informative = r_inv.cwiseProduct(m).sum() >= c_.min_offset_information;
    joint_.offset_held = !exc_.offset_informative;
    if (joint_.offset_held) {
      joint_.d.segment<3>(kIdR).setOnes();
      joint_.dht.middleRows<3>(kIdR) = sf.transpose();
    }
  }
  return true;
}

bool Identifier::joint_gain_rows() {
  if (!joint_.started) return true;
  // (I26) on a tick of its own before the first row block (none when both gates are off).
  if (!joint_.gated && information_gate()) return false;
  const int first = joint_.gain_rows;
  if (first < kIdParams) {
    const int n = std::min(gain_rows_per_tick_, kIdParams - first);
    for (int i = first; i < first + n; ++i) {
      Vec3 acc = Vec3::Zero();  // row i of P times D H' (a plain loop: no GEMM packing per row)
      for (int j = 0; j < kIdParams; ++j) acc += p_all_(i, j) * joint_.dht.row(j).transpose();
      joint_.p_ht.row(i) = joint_.d(i) * acc.transpose();
    }
    joint_.gain_rows = first + n;
    return false;
  }
  // Every row done: S and the gain on a tick of their own.
  joint_.started = false;
  joint_.s = latched_r_ + joint_.second_order + joint_.h.lazyProduct(joint_.p_ht);
  residual_cov_ = joint_.s;
  const Eigen::LDLT<Mat3> ldlt(joint_.s);
  if (ldlt.info() != Eigen::Success || !ldlt.isPositive()) return true;
  // K = P H' S^-1 with S^-1 from the 3x3 factorisation (a 28 x 3 times 3 x 3 product, no
  // blocked triangular solve over 28 right-hand sides).
  const Mat3 s_inv = ldlt.solve(Mat3::Identity());
  // (I18) innovation gate: a window the model cannot explain within S is refused, estimate and
  // covariance untouched; too many in a row re-inflate J, r and k.
  innovation_chi2_ = joint_.e0.dot(s_inv * joint_.e0);
  if (c_.gate_chi2 > 0.0 && innovation_chi2_ > c_.gate_chi2) {
    ++counters_.windows_gated;
    if (++gated_in_row_ >= c_.gate_reinflate_after) {
      gated_in_row_ = 0;
      gate_reinflation_due_ = 1;  // on the next blocks (gate_reinflate)
    }
    return true;
  }
  gated_in_row_ = 0;
  joint_.k = joint_.p_ht.lazyProduct(s_inv);
  if (joint_.inertia_held) joint_.k.topRows<6>().setZero();  // (I26)
  // Without a net force r is not estimated (I10): it stays a consider parameter, gain zero.
  if (!exc_.offset || joint_.offset_held) joint_.k.middleRows<3>(kIdR).setZero();
  // (I17) b as a consider parameter: no gain, its covariance kept (Schmidt).
  if (!c_.gyro_bias_estimated) joint_.k.middleRows<3>(kIdB).setZero();
  joint_.pending = true;
  return true;
}

bool Identifier::gate_reinflate() {
  // (I18) Too many refused windows in a row: J, r, k and d back to their prior covariance. On the
  // blocks after the refusal, at most eight rows and columns per block, not on the gain's own tick
  // (the Cortex-M7 tick budget: all at once on the gain's tick it was 25.6 k instructions, on a
  // tick of its own 22.8 k). Until the last part the covariance is the one the refused step left
  // untouched; the step's later blocks and the published copies (sync_blocks) come after it.
  constexpr int kHalf = kThrusters / 2;
  switch (gate_reinflation_due_) {
    case 1:
      reinflate_block<kIdParams>(p_all_, kIdJ, 6, c_.j_prior_sigma * c_.j_prior_sigma);
      break;
    case 2:
      reinflate_block<kIdParams>(p_all_, kIdR, 3, c_.r_prior_sigma * c_.r_prior_sigma);
      reinflate_block<kIdParams>(p_all_, kIdD, 3, c_.fault_torque_sigma * c_.fault_torque_sigma);
      break;
    case 3:
      reinflate_block<kIdParams>(p_all_, kIdK, kHalf, c_.k_prior_sigma * c_.k_prior_sigma);
      break;
    case 4:
      reinflate_block<kIdParams>(p_all_, kIdK + kHalf, kHalf, c_.k_prior_sigma * c_.k_prior_sigma);
      gate_reinflation_due_ = 0;
      d_held_zero_ = false;
      settle_streak_ = 0;
      ++counters_.reinflations;
      ++counters_.gate_reinflations;
      return true;
    default:
      return false;
  }
  ++gate_reinflation_due_;
  return true;
}

void Identifier::joint_apply() {
  if (!joint_.pending) return;
  joint_.pending = false;
  VecId x0;
  x0 << a_, r_, k_, b_, d_;
  const VecId step = joint_.k * joint_.e0;
  // Guards (I14): J positive definite and physical, r within bounds; else the update is refused
  // and the covariance left as it was. (I28) Before refusing, the gain is halved up to
  // guard_halvings times and the first fraction the guards accept is applied; and the triangle
  // inequality m0 + m1 >= m2 of the principal moments is asked of the step only as far as the
  // estimate meets it (a prior that is only positive definite may move back, never further out).
  const auto triangle_margin = [](const Mat3& j) {
    Eigen::SelfAdjointEigenSolver<Mat3> es;
    es.computeDirect(j, Eigen::EigenvaluesOnly);
    const Vec3 m = es.eigenvalues();
    return m(0) > 0.0 ? m(0) + m(1) - m(2) : -1e300;
  };
  double floor_margin = 0.0;
  bool floor_known = c_.guard_halvings == 0;  // without I28 the inequality itself is the guard
  VecId x = x0 - step;
  bool physical = false;
  bool r_ok = false;
  double alpha = 1.0;
  for (int halving = 0;; ++halving) {
    const Mat3 j = inertia_matrix(x.head<6>());
    physical = j.allFinite() && Eigen::LLT<Mat3>(j).info() == Eigen::Success;
    if (physical) {
      const double margin = triangle_margin(j);
      if (margin < 0.0 && !floor_known) {
        floor_margin = std::fmin(0.0, triangle_margin(inertia_matrix(x0.head<6>())));
        floor_known = true;
      }
      physical = margin >= floor_margin;
    }
    r_ok = x.segment<3>(kIdR).allFinite() && (x.segment<3>(kIdR) - c_.r0).norm() <= c_.r_max_offset;
    if ((physical && r_ok) || halving >= c_.guard_halvings) break;
    alpha *= 0.5;
    x = x0 - alpha * step;
  }
  if (!physical || !r_ok) {
    if (!physical) ++counters_.inertia_refused;
    if (!r_ok) ++counters_.offset_refused;
    return;
  }
  if (alpha < 1.0) {
    // (I28) The gain actually applied; the covariance rows then take the full form for it.
    joint_.k *= alpha;
    joint_.damped = true;
    ++counters_.damped_steps;
  }
  // The covariance is updated a block of rows per tick from the next tick on (each row needs
  // only its own old row, p_ht, K and S).
  joint_.cov_rows = 0;
  joint_.sym_rows = 0;
  joint_.rows_pending = true;
  a_ = x.head<6>();
  r_ = x.segment<3>(kIdR);
  k_ = x.segment<kThrusters>(kIdK);
  b_ = x.segment<3>(kIdB);
  d_ = x.segment<3>(kIdD);
  for (int i = 0; i < kThrusters; ++i) {
    const double clamped = std::fmin(std::fmax(k_(i), c_.k_min), c_.k_max);
    if (clamped != k_(i)) {
      k_(i) = clamped;
      ++counters_.strength_clamped;
    }
  }
  window_fitted_ = true;
  if (!joint_.inertia_held) ++counters_.inertia_updates;  // (I26) a held J was not updated
  if (exc_.offset && !joint_.offset_held) ++counters_.offset_updates;
  if (joint_.any_thruster) ++counters_.strength_updates;
}

void Identifier::joint_covariance_rows(int first, int n) {
  // P = D P D - K H P_f - (K H P_f)' + K S K' (valid for any gain; with the optimal gain it is
  // D P D - K H P_f). Row i needs only row i of P, so the rows can be done in blocks.
  const VecId& d = joint_.d;
  for (int i = first; i < first + n; ++i) {
    Eigen::Matrix<double, 1, kIdParams> row = d(i) * p_all_.row(i).cwiseProduct(d.transpose());
    row.noalias() -= joint_.k.row(i) * joint_.p_ht.transpose();
    if (!exc_.offset || !c_.gyro_bias_estimated || joint_.inertia_held || joint_.offset_held ||
        joint_.damped) {
      // a gain with zeroed rows, or halved (I28): the full form
      row.noalias() -= joint_.p_ht.row(i) * joint_.k.transpose();
      row.noalias() += (joint_.k.row(i) * joint_.s) * joint_.k.transpose();
    }
    p_all_.row(i) = row;
  }
}

void Identifier::symmetrise_rows(int first, int n) {
  // (P + P')/2 over the pairs (i, j > i) of rows [first, first + n): the same values as the whole
  // matrix at once, in blocks.
  for (int i = first; i < first + n; ++i) {
    for (int j = i + 1; j < kIdParams; ++j) {
      const double v = 0.5 * (p_all_(i, j) + p_all_(j, i));
      p_all_(i, j) = v;
      p_all_(j, i) = v;
    }
  }
}

bool Identifier::joint_covariance_step() {
  if (!joint_.rows_pending) return true;
  if (joint_.cov_rows < kIdParams) {
    const int n = std::min(cov_rows_per_tick_, kIdParams - joint_.cov_rows);
    joint_covariance_rows(joint_.cov_rows, n);
    joint_.cov_rows += n;
    return false;
  }
  if (joint_.sym_rows < kIdParams) {
    const int n = std::min(kSymmetriseRowsPerTick, kIdParams - joint_.sym_rows);
    symmetrise_rows(joint_.sym_rows, n);
    joint_.sym_rows += n;
    return false;
  }
  return true;
}

void Identifier::joint_finish_covariance() {
  if (!joint_.rows_pending) return;
  joint_.rows_pending = false;
  if (joint_.cov_rows < kIdParams) {
    joint_covariance_rows(joint_.cov_rows, kIdParams - joint_.cov_rows);
    joint_.cov_rows = kIdParams;
  }
  if (joint_.sym_rows < kIdParams) {
    symmetrise_rows(joint_.sym_rows, kIdParams - joint_.sym_rows);
    joint_.sym_rows = kIdParams;
  }
  // No variance above its prior (no wind-up while a direction is not excited).
  const double caps[5] = {c_.j_prior_sigma * c_.j_prior_sigma, c_.r_prior_sigma * c_.r_prior_sigma,
                          c_.k_prior_sigma * c_.k_prior_sigma,
                          c_.gyro_bias_sigma * c_.gyro_bias_sigma,
                          c_.fault_torque_sigma * c_.fault_torque_sigma};
  for (int i = 0; i < kIdParams; ++i) {
    const double cap =
        caps[i < kIdR ? 0 : (i < kIdK ? 1 : (i < kIdB ? 2 : (i < kIdD ? 3 : 4)))];
    if (p_all_(i, i) > cap) {
      const double f = std::sqrt(cap / p_all_(i, i));
      p_all_.row(i) *= f;
      p_all_.col(i) *= f;
    }
  }
}

void Identifier::anchor_scale() {
  // (I15): a perfect pseudo-measurement c'x = b, c = mean over the reference thrusters, b = the
  // same mean of k0: x <- x - P c (c'x - b) / (c'P c), P <- P - P c c'P / (c'P c).
  if (!c_.anchor_thrust_scale) return;
  VecId c = VecId::Zero();
  int n = 0;
  double b = 0.0;
  for (int i = 0; i < kThrusters; ++i) {
    if (!reference_[i]) continue;
    c(kIdK + i) = 1.0;
    b += c_.k0(i);
    ++n;
  }
  if (n == 0) return;
  c /= n;
  b /= n;
  if (c_.mode == IdentifierMode::kJoint) {
    // c is sparse (1/n on the reference thrusters): P c sums those columns, the first eight
    // thrusters' here and the rest on the next block (anchor_scale_finish; the Cortex-M7 tick
    // budget: 16 columns and the update on one tick were 3.7 k instructions).
    anchor_.c = c;
    anchor_.b = b;
    anchor_.pc.setZero();
    for (int i = 0; i < kThrusters / 2; ++i) {
      if (reference_[i]) anchor_.pc += p_all_.col(kIdK + i) * c(kIdK + i);
    }
    anchor_.pc_pending = true;
  } else {
    const Vec16 ck = c.segment<kThrusters>(kIdK);
    const Vec16 pc = p_k_ * ck;
    const double cpc = ck.dot(pc);
    if (!(cpc > 0.0)) return;
    k_ -= pc * ((ck.dot(k_) - b) / cpc);
    p_k_.noalias() -= pc * pc.transpose() / cpc;
    p_k_ = 0.5 * (p_k_ + p_k_.transpose()).eval();
  }
}

double Identifier::thrust_scale_sigma() const {
  // (I29) sigma of eps, the relative error of the anchored scale: the calibration's mean error of
  // the n reference thrusters (independent, sigma_k each) over their mean prior strength b.
  if (!c_.anchor_thrust_scale) return 0.0;  // the k prior holds the scale in P itself
  int n = 0;
  double b = 0.0;
  for (int i = 0; i < kThrusters; ++i) {
    if (!reference_[i]) continue;
    b += c_.k0(i);
    ++n;
  }
  if (n == 0 || !(b > 0.0)) return 0.0;
  b /= n;
  return c_.k_prior_sigma / (std::sqrt(static_cast<double>(n)) * b);
}

void Identifier::anchor_scale_finish() {
  if (!anchor_.pc_pending) return;
  anchor_.pc_pending = false;
  const VecId& c = anchor_.c;
  const double b = anchor_.b;
  VecId pc = anchor_.pc;
  for (int i = kThrusters / 2; i < kThrusters; ++i) {
    if (reference_[i]) pc += p_all_.col(kIdK + i) * c(kIdK + i);
  }
  {
    const double cpc = c.dot(pc);
    if (!(cpc > 0.0)) return;
    VecId x;
    x << a_, r_, k_, b_, d_;
    x -= pc * ((c.dot(x) - b) / cpc);
    // P -= P c c'P / (c'P c), a block of rows per tick from the next tick on (anchor_rows).
    anchor_.pc = pc;
    anchor_.g = pc / cpc;
    anchor_.rows = 0;
    anchor_.pending = true;
    a_ = x.head<6>();
    r_ = x.segment<3>(kIdR);
    k_ = x.segment<kThrusters>(kIdK);
    b_ = x.segment<3>(kIdB);
    d_ = x.segment<3>(kIdD);
  }
}

bool Identifier::anchor_rows() {
  if (!anchor_.pending) return true;
  // Element (i, j) loses g(lo) pc(hi), lo = min(i, j): the same product for (j, i), so a
  // symmetric P stays exactly symmetric whichever rows are done first.
  const int first = anchor_.rows;
  const int n = std::min(kAnchorRowsPerTick, kIdParams - first);
  for (int i = first; i < first + n; ++i) {
    for (int j = 0; j < kIdParams; ++j) {
      const int lo = i < j ? i : j;
      const int hi = i < j ? j : i;
      p_all_(i, j) -= anchor_.g(lo) * anchor_.pc(hi);
    }
  }
  anchor_.rows = first + n;
  if (anchor_.rows < kIdParams) return false;
  anchor_.pending = false;
  return true;
}

void Identifier::finish_anchor() {
  anchor_scale_finish();
  while (!anchor_rows()) {
  }
}

double Identifier::sample_weight(int i) const {
  // Triangular modulating window (I2): w(0) = w(T) = 0, w(T/2) = 1.
  return 1.0 - std::fabs(2.0 * i / n_ - 1.0);
}

double Identifier::sample_alpha(int i) const {
  // (I4): coefficient of L(omega_i) in -∫ w' J omega dt with the trapezoid rule on each tick;
  // w' = +2/T on the first half, -2/T on the second; sign s of the interval ending at sample j.
  auto slope_sign = [this](int j) -> double {
    if (j < 1 || j > n_) return 0.0;
    return j <= n_ / 2 ? 1.0 : -1.0;
  };
  return -(slope_sign(i) + slope_sign(i + 1)) / n_;
}

void Identifier::accumulate(const IdentifierInput& in) {
  const double dt = c_.dt;
  if (sample_ >= 0) {
    // The interval ending at this sample, forces held over it (zero-order hold, SPEC §4):
    // ∫ w F_i dt = (w_(j-1) + w_j) / 2 dt F_i, exact for the linear w.
    const int j = sample_ + 1;
    const double wi = 0.5 * (sample_weight(j - 1) + sample_weight(j)) * dt;
    for (int ch = 0; ch < kChannels; ++ch) {
      const double f = in.force(ch);
      if (f > 0.0) {
        acc_.impulse(2 * ch) += wi * f;
      } else if (f < 0.0) {
        acc_.impulse(2 * ch + 1) -= wi * f;
      }
    }
    acc_.weight += wi;
  }
  sample_ += 1;
  const int i = sample_;
  const double alpha = sample_alpha(i);
  const double wdt = sample_weight(i) * dt;
  const Mat36 l = inertia_regressor(in.omega);
  // (I3): A_J += alpha_i L(omega_i) + w_i dt S(omega_i) L(omega_i).
  acc_.a_j += alpha * l + wdt * (skew(in.omega) * l);
  acc_.sum_alpha2 += alpha * alpha;
  acc_.sum_gyro2 += wdt * wdt * in.omega.squaredNorm();
  acc_.m += wdt * in.omega;                                    // (I17)
  acc_.w2 += (wdt * wdt) * (in.omega * in.omega.transpose());  // (I19)
  acc_.n += (alpha * wdt) * in.omega;
}

int Identifier::window_ticks_next() const {
  // (I30) Early windows while one more still closes within early_span_s of identification.
  if (n_early_ > 0 && identified_s_ + n_early_ * c_.dt <= c_.early_span_s + 1e-9) return n_early_;
  return n_full_;
}

void Identifier::finish_step() {
  complete_reinflation();
  for (int guard = 0; phase_ != Phase::kIdle && guard < 4 * kIdParams; ++guard) step_phase();
}

void Identifier::update(const IdentifierInput& in, bool background) {
  // Work on the latched window first: one block per tick (J, gain rows, apply, covariance rows,
  // strengths, report).
  if (background) {
    if (fill_pending_) {
      complete_reinflation();  // the tick's block: the re-inflated covariance (reinflate_all)
    } else {
      step_phase();
    }
  }

  const bool ok = in.omega_valid && in.omega.allFinite() &&
                  (sample_ < 0 || (in.force_valid && in.force.allFinite()));
  if (!ok) {
    if (sample_ > 0) ++counters_.windows_discarded;
    acc_ = Window{};
    sample_ = -1;
    return;
  }
  accumulate(in);
  if (sample_ == n_) {
    finish_step();  // only when ticks were withheld from a window too short for the blocks
    latched_ = acc_;
    latched_.length_s = n_ * c_.dt;
    latched_.dist_factor = n_ == n_full_ ? dist_factor_ : dist_factor_early_;
    identified_s_ += latched_.length_s;
    n_ = window_ticks_next();
    latched_noise_ = window_noise();
    ++counters_.windows;
    // The window's noise matrix (I19) is the step's first block, on a tick of its own: on the
    // closing tick it could meet the fault detector's heavy evaluation steps, which the background
    // blocks avoid (the Cortex-M7 tick budget: 20.8 k instructions in HOLD when they met).
    phase_ = Phase::kNoise;
    // This sample also opens the next window (w = 0 here, so it only enters through alpha_0).
    acc_ = Window{};
    sample_ = -1;
    accumulate(in);
  }
}

void Identifier::step_phase() {
  complete_reinflation();
  switch (phase_) {
    case Phase::kNoise:
      latched_r_ = window_noise_matrix();
      phase_ = Phase::kInertia;
      break;
    case Phase::kInertia:
      if (c_.mode == IdentifierMode::kJoint) {
        joint_gain();
      } else {
        update_inertia();
      }
      phase_ = Phase::kSecondOrder;
      break;
    case Phase::kSecondOrder:
      if (c_.mode != IdentifierMode::kJoint || second_order_step()) phase_ = Phase::kGain;
      break;
    case Phase::kGain:
      if (c_.mode != IdentifierMode::kJoint || joint_gain_rows()) phase_ = Phase::kOffset;
      break;
    case Phase::kOffset:
      if (c_.mode == IdentifierMode::kJoint) {
        if (gate_reinflate()) break;
        joint_apply();
      } else {
        update_offset();
      }
      phase_ = Phase::kApply;
      break;
    case Phase::kApply:
      // Row blocks of the covariance update, then (its own tick) symmetrise and cap.
      if (c_.mode != IdentifierMode::kJoint || joint_covariance_step()) {
        if (c_.mode == IdentifierMode::kJoint) joint_finish_covariance();
        phase_ = Phase::kStrength;
      }
      break;
    case Phase::kStrength:
      if (c_.mode == IdentifierMode::kJoint) {
        anchor_scale();
        phase_ = Phase::kAnchor;
      } else {
        update_strengths();
        phase_ = Phase::kSync;
      }
      break;
    case Phase::kAnchor:
      if (anchor_.pc_pending) {
        anchor_scale_finish();
        break;
      }
      if (anchor_rows()) phase_ = Phase::kSync;
      break;
    case Phase::kSync:
      // A block of its own, before the report (the Cortex-M7 tick budget: together they were
      // 5.1 k instructions, and the tick with the identification excitation 20.8 k).
      if (c_.mode == IdentifierMode::kJoint) sync_blocks();
      // The step used the rate as it was given in its window; a bias shift requested since
      // applies from here on.
      apply_bias_changes();
      phase_ = Phase::kReport;
      break;
    case Phase::kReport:
      report();
      fault_jet_next_ = 0;
      phase_ = c_.fault_torque_sigma > 0.0 ? Phase::kFaultScore : Phase::kIdle;
      break;
    case Phase::kFaultScore: {
      const int n = std::min(kFaultJetsPerTick, kThrusters - fault_jet_next_);
      score_fault_torque(fault_jet_next_, n);
      fault_jet_next_ += n;
      if (fault_jet_next_ >= kThrusters) {
        ++ft_.scored;
        phase_ = Phase::kIdle;
        // (I24) d settled at zero? (Only while d is in the state: once held at zero, d-hat and
        // its covariance are exactly zero and would read as "quiet" on every window.)
        if (ft_.fitted && !d_held_zero_) {
          const double gate = c_.gate_chi2 > 0.0 ? c_.gate_chi2 : 16.27;
          const double settled = 0.1 * c_.fault_torque_sigma;
          const bool quiet = ft_.chi2_zero < gate &&
                             ft_.d_cov.diagonal().maxCoeff() <= settled * settled;
          settle_streak_ = quiet ? settle_streak_ + 1 : 0;
          if (settle_streak_ >= kSettleWindows) {
            settle_streak_ = 0;
            phase_ = Phase::kSettleFactors;  // its own ticks (the Cortex-M7 tick budget)
          }
        }
      }
      break;
    }
    case Phase::kSettleFactors:
      settle_factors();
      phase_ = settle_.factored ? Phase::kSettleStart : Phase::kIdle;
      break;
    case Phase::kSettleStart:
      start_settle();
      phase_ = settle_.pending ? Phase::kSettle : Phase::kIdle;
      break;
    case Phase::kSettle:
      if (settle_rows()) phase_ = Phase::kIdle;
      break;
    case Phase::kIdle:
      break;
  }
}

double Identifier::torque_threshold() const {
  // (I16): a window counts only when its torque impulse stands well above the window noise.
  // Below that, in a closed loop, the commands mostly answer the disturbance and are correlated
  // with it, which biases least squares (the classic closed-loop identification bias).
  return std::fmax(c_.min_torque_impulse, c_.min_snr * std::sqrt(latched_noise_));
}

double Identifier::window_noise() const {
  // (I5): variance of one row of the window equation.
  const double jn = inertia_matrix(a_).norm();
  const double g2 = c_.gyro_sigma * c_.gyro_sigma;
  const double gyro = g2 * jn * jn * (latched_.sum_alpha2 + 4.0 * latched_.sum_gyro2);
  const double t = latched_.length_s;
  const double dist = c_.disturbance_sigma * c_.disturbance_sigma * c_.disturbance_corr_s * t / 3.0;
  const double floor = c_.torque_floor * latched_.weight;
  return gyro + dist + floor * floor;
}

bool Identifier::second_order_step() {
  // (I20): e(x) is bilinear in (k, r) and in (a, b), so linearised at the estimate it leaves
  //   e2 = dr x dF - G(da) db,   dF = sum_i dk_i I_i e_i,   G(da) db = sum_k db_k B_k da,
  //   B_k = S(m) L(e_k) + S(e_k) L(m)   (I17),
  // which the first-order step does not see. While dr, dk (or da, db) are large, early on and
  // from the case-4 priors, it is much larger than the window noise; ignoring it makes the step
  // overconfident and freezes the linearisation error in. Its covariance (the second-order
  // filter's term, the errors taken as independent zero-mean Gaussians) joins S:
  //   cov(dr x dF) = cross_product_covariance(P_r, Q),  Q = Phi_F P_k Phi_F',
  //   cov(G(da) db) = sum_kl P_b,kl B_k P_a B_l'.
  // Three parts on three ticks (the Cortex-M7 tick budget: the whole term on the linearisation's
  // tick made it 30 k instructions): Q and the cross product; B_k P_a; the bias term.
  if (!joint_.started || !c_.second_order_noise) return true;
  const Mat3 p_b = p_all_.block<3, 3>(kIdB, kIdB);
  switch (joint_.second_order_part) {
    case 0: {
      // Q = Phi_F P_k Phi_F' over the thrusters that fired in the window (Phi_F col i = I_i e_i).
      Mat3 q = Mat3::Zero();
      for (int i = 0; i < kThrusters; ++i) {
        const double ii = latched_.impulse(i);
        if (ii == 0.0) continue;
        Vec3 v = Vec3::Zero();  // sum_j P_k(i, j) I_j e_j
        for (int j = 0; j < kThrusters; ++j) {
          const double ij = latched_.impulse(j);
          if (ij != 0.0) v += (p_all_(kIdK + i, kIdK + j) * ij) * e_[j];
        }
        q.noalias() += (ii * e_[i]) * v.transpose();
      }
      joint_.second_order = cross_product_covariance(p_all_.block<3, 3>(kIdR, kIdR), q);
      joint_.second_order_part = 1;
      return false;
    }
    case 1:
      if (p_b.diagonal().maxCoeff() <= 0.0) break;
      bias_jacobian_times(latched_.m, p_all_.topLeftCorner<6, 6>(), joint_.bpa);
      joint_.second_order_part = 2;
      return false;
    default:
      joint_.second_order += bilinear_bias_covariance(latched_.m, joint_.bpa, p_b);
      break;
  }
  joint_.second_order = 0.5 * (joint_.second_order + joint_.second_order.transpose()).eval();
  joint_.second_order_part = 0;
  return true;
}

Mat3 Identifier::window_noise_matrix() const {
  // (I19): the gyro's white noise eta_i enters the window equation through the sample's
  // coefficient C_i = alpha_i J + w_i dt M(omega_i), M(v) = S(v) J - S(J v) (the Jacobian of
  // v x J v), so its covariance is sigma^2 sum_i C_i C_i'. M is linear in omega, so the sum
  // follows from three window moments: sum alpha^2, n = sum alpha w dt omega and
  // W = sum (w dt)^2 omega omega':
  //   sum C C' = (sum alpha^2) J J' + J M(n)' + M(n) J' + sum_kl W_kl M(e_k) M(e_l)'.
  // Plus the disturbance and the floor of (I5), which act alike on every axis.
  const Mat3 j = inertia_matrix(a_);
  const auto m_of = [&j](const Vec3& v) -> Mat3 { return skew(v) * j - skew(j * v); };
  std::array<Mat3, 3> me;
  for (int k = 0; k < 3; ++k) me[static_cast<std::size_t>(k)] = m_of(Vec3::Unit(k));
  const Mat3 mn = m_of(latched_.n);
  Mat3 c = latched_.sum_alpha2 * (j * j.transpose()) + j * mn.transpose() + mn * j.transpose();
  for (int k = 0; k < 3; ++k) {
    for (int l = 0; l < 3; ++l) {
      c.noalias() += latched_.w2(k, l) * (me[static_cast<std::size_t>(k)] *
                                          me[static_cast<std::size_t>(l)].transpose());
    }
  }
  const double g2 = c_.gyro_sigma * c_.gyro_sigma;
  const double dist = c_.disturbance_sigma * c_.disturbance_sigma * latched_.dist_factor;
  const double floor = c_.torque_floor * latched_.weight;
  Mat3 r = g2 * c;
  r = 0.5 * (r + r.transpose()).eval();
  r.diagonal().array() += dist + floor * floor;
  return r;
}

Vec3 Identifier::model_torque_impulse(const Vec16& k, const Vec3& r) const {
  // (I6): ∫ w tau dt = sum_i k_i (p_i + r) x e_i ∫ w F_i dt.
  Vec3 tau = Vec3::Zero();
  Vec3 force = Vec3::Zero();
  for (int i = 0; i < kThrusters; ++i) {
    const double ki = k(i) * latched_.impulse(i);
    if (ki == 0.0) continue;
    tau += ki * p_cross_e_[i];
    force += ki * e_[i];
  }
  return tau + r.cross(force);
}

Vec3 Identifier::net_force_impulse() const {
  Vec3 force = Vec3::Zero();
  for (int i = 0; i < kThrusters; ++i) force += k_(i) * latched_.impulse(i) * e_[i];
  return force;
}

Mat316 Identifier::strength_regressor() const {
  // (I11): column i = [(p_i + r_hat) x e_i] ∫ w F_i dt.
  Mat316 phi;
  for (int i = 0; i < kThrusters; ++i) {
    phi.col(i) = (p_cross_e_[i] + r_.cross(e_[i])) * latched_.impulse(i);
  }
  return phi;
}

// (I7): what each group's own uncertainty adds to the window equation when another group holds it
// at its estimate (the "consider" covariance).
Mat3 Identifier::consider_inertia() const {
  return latched_.a_j * p_j_ * latched_.a_j.transpose();
}

Mat3 Identifier::consider_offset() const {
  const Mat3 s = skew(net_force_impulse());
  return s * p_r_ * s.transpose();
}

Mat3 Identifier::consider_strengths() const {
  const Mat316 phi = strength_regressor();
  return phi * p_k_ * phi.transpose();
}

void Identifier::update_inertia() {
  // (I9): A_J a = ∫ w tau dt with the latest r_hat, k_hat.
  const Vec3 y = model_torque_impulse(k_, r_);
  exc_.inertia_motion = latched_.a_j.norm() * a_.norm() >= torque_threshold();
  exc_.inertia_scale = y.norm() >= torque_threshold();
  if (!exc_.inertia_motion && !exc_.inertia_scale) return;
  const Vec6 a_keep = a_;
  const Mat6 p_keep = p_j_;
  const double prior_var = c_.j_prior_sigma * c_.j_prior_sigma;
  if (exc_.inertia_scale) forget<6>(p_j_, latched_.length_s, c_.j_forget_s, prior_var);
  // The other groups' uncertainty enters as measurement noise (I7).
  const Mat3 r_noise = latched_r_ + consider_offset() + consider_strengths();
  residual_cov_ = r_noise + consider_inertia();
  rls_update<6>(a_, p_j_, latched_.a_j, y, r_noise);
  // Guard: positive definite, principal moments obey the triangle inequality.
  const Mat3 j = inertia_matrix(a_);
  bool physical = j.allFinite() && Eigen::LLT<Mat3>(j).info() == Eigen::Success;
  if (physical) {
    Eigen::SelfAdjointEigenSolver<Mat3> es;
    es.computeDirect(j, Eigen::EigenvaluesOnly);
    const Vec3 m = es.eigenvalues();  // ascending
    physical = m(0) > 0.0 && m(0) + m(1) >= m(2);
  }
  if (!physical) {
    a_ = a_keep;
    p_j_ = p_keep;
    ++counters_.inertia_refused;
    return;
  }
  ++counters_.inertia_updates;
}

void Identifier::update_offset() {
  // (I10): A_J a_hat - sum k_i (p_i x e_i) I_i = r x F = -S(F) r, F = sum k_i e_i I_i.
  Vec3 tau_p = Vec3::Zero();
  Vec3 force = Vec3::Zero();
  for (int i = 0; i < kThrusters; ++i) {
    const double ki = k_(i) * latched_.impulse(i);
    tau_p += ki * p_cross_e_[i];
    force += ki * e_[i];
  }
  exc_.offset = force.norm() >= c_.min_force_impulse;
  if (!exc_.offset) return;
  const Vec3 y = latched_.a_j * a_ - tau_p;
  const Mat3 phi = -skew(force);
  const Vec3 r_keep = r_;
  const Mat3 p_keep = p_r_;
  const Mat3 r_noise = latched_r_ + consider_inertia() + consider_strengths();
  forget<3>(p_r_, latched_.length_s, c_.r_forget_s, c_.r_prior_sigma * c_.r_prior_sigma);
  rls_update<3>(r_, p_r_, phi, y, r_noise);
  if (!r_.allFinite() || (r_ - c_.r0).norm() > c_.r_max_offset) {
    r_ = r_keep;
    p_r_ = p_keep;
    ++counters_.offset_refused;
    return;
  }
  ++counters_.offset_updates;
}

void Identifier::update_strengths() {
  // (I11): A_J a_hat = sum_i k_i [(p_i + r_hat) x e_i] I_i.
  bool any = false;
  for (int i = 0; i < kThrusters; ++i) {
    exc_.thruster[i] = latched_.impulse(i) >= c_.min_thruster_impulse;
    any = any || exc_.thruster[i];
  }
  if (!any) return;
  const Mat316 phi = strength_regressor();
  const Vec3 y = latched_.a_j * a_;
  const Mat3 r_noise = latched_r_ + consider_inertia() + consider_offset();
  forget<kThrusters>(p_k_, latched_.length_s, c_.k_forget_s, c_.k_prior_sigma * c_.k_prior_sigma);
  rls_update<kThrusters>(k_, p_k_, phi, y, r_noise);
  for (int i = 0; i < kThrusters; ++i) {
    const double clamped = std::fmin(std::fmax(k_(i), c_.k_min), c_.k_max);
    if (clamped != k_(i) || !std::isfinite(k_(i))) {
      k_(i) = std::isfinite(k_(i)) ? clamped : c_.k0(i);
      ++counters_.strength_clamped;
    }
  }
  ++counters_.strength_updates;
  anchor_scale();
}

void Identifier::report() {
  // Estimates and 1 sigma.
  // (I29) The covariance is conditional on the thrust scale the anchor (I15) holds; the true mean
  // strength of the reference thrusters is the calibration's, b (1 + eps) with
  // eps ~ N(0, sigma_k^2 / (n b^2)), and the data cannot tell eps (every datum is invariant under
  // (J, k) -> ((1 + eps) J, (1 + eps) k)). The reported 1 sigma of J and k are the marginal ones:
  // var(a_i) + var(eps) a_i^2, var(k_i) + var(eps) k_i^2.
  est_.thrust_scale_sigma = thrust_scale_sigma();
  const double ve = est_.thrust_scale_sigma * est_.thrust_scale_sigma;
  const Mat6 j_marginal = p_j_ + ve * (a_ * a_.transpose());
  est_.j = inertia_matrix(a_);
  est_.j_sigma = j_marginal.diagonal().cwiseMax(0.0).cwiseSqrt();
  est_.j_cov = pack_upper<6>(j_marginal);
  est_.r = r_;
  est_.r_sigma = p_r_.diagonal().cwiseMax(0.0).cwiseSqrt();
  est_.k = k_;
  est_.k_sigma = (p_k_.diagonal() + ve * k_.cwiseAbs2()).cwiseMax(0.0).cwiseSqrt();
  est_.r_cov = pack_upper<3>(p_r_);
  est_.gyro_bias = b_;
  est_.gyro_bias_sigma = p_b_.diagonal().cwiseMax(0.0).cwiseSqrt();

  // Observability (§I.3): directions still near their prior are reported, not estimated.
  const double ratio2 = c_.unobservable_ratio * c_.unobservable_ratio;
  Eigen::SelfAdjointEigenSolver<Mat3> es;
  es.computeDirect(p_r_);
  const double r_var0 = c_.r_prior_sigma * c_.r_prior_sigma;
  obs_.offset_unobservable = 0;
  double r_worst_observed = 0.0;
  for (int d = 2; d >= 0; --d) {  // largest variance first
    if (es.eigenvalues()(d) >= ratio2 * r_var0) {
      obs_.offset_directions[obs_.offset_unobservable++] = es.eigenvectors().col(d);
    } else {
      r_worst_observed =
          std::fmax(r_worst_observed, std::sqrt(std::fmax(es.eigenvalues()(d), 0.0)));
    }
  }
  const double j_var0 = c_.j_prior_sigma * c_.j_prior_sigma;
  const Vec6 u = a_.normalized();
  obs_.inertia_scale_unobservable = u.dot(p_j_ * u) >= ratio2 * j_var0;
  obs_.inertia_unobservable = 0;
  for (int d = 0; d < 6; ++d) {
    if (p_j_(d, d) >= ratio2 * j_var0) ++obs_.inertia_unobservable;
  }
  const double k_var0 = c_.k_prior_sigma * c_.k_prior_sigma;
  for (int i = 0; i < kThrusters; ++i) {
    obs_.thruster_unobservable[i] = p_k_(i, i) >= ratio2 * k_var0;
    est_.thruster_confident[i] =
        !obs_.thruster_unobservable[i] && est_.k_sigma(i) <= c_.k_confident;
  }
  obs_.thrust_scale_anchored = true;

  est_.inertia_confident = !obs_.inertia_scale_unobservable && obs_.inertia_unobservable == 0 &&
                           est_.j_sigma.maxCoeff() <= c_.j_confident_rel * est_.j.norm();
  est_.offset_confident = obs_.offset_unobservable == 0 && r_worst_observed <= c_.r_confident;

  // Residual of the last window with the latest estimates (I12).
  if (latched_.weight > 0.0) {
    const Vec3 res = latched_.a_j * a_ - bias_jacobian() * b_ - model_torque_impulse(k_, r_) -
                     latched_.weight * d_;
    est_.residual_torque = res / latched_.weight;
    // Against the window's innovation covariance before the update (joint: S; concurrent: the
    // inertia group's noise plus its own consider term).
    est_.residual_chi2 = res.dot(residual_cov_.ldlt().solve(res));
  }
}

void Identifier::score_fault_torque(int first, int n) {
  // (I23) d-hat against "thruster i stuck on": t_i = d - u_max k_i (p_i + r) x e_i, linearised in
  // (d, r, k_i): dt/dd = I, dt/dr = u_max k_i S(e_i), dt/dk_i = -u_max (p_i + r) x e_i, and
  // chi2_i = t_i' (M_i P_(d,r,k_i) M_i')^-1 t_i with the joint covariance (cross terms included).
  const Mat3 p_dd = p_all_.block<3, 3>(kIdD, kIdD);
  const Mat3 p_dr = p_all_.block<3, 3>(kIdD, kIdR);
  const Mat3 p_rr = p_all_.block<3, 3>(kIdR, kIdR);
  if (first == 0) {
    ft_.d = d_;
    ft_.d_cov = p_dd;
    ft_.fitted = window_fitted_;
    ft_.held_zero = d_held_zero_;
    const Eigen::LDLT<Mat3> l(p_dd);
    ft_.chi2_zero = l.info() == Eigen::Success && l.isPositive() ? d_.dot(l.solve(d_)) : 0.0;
  }
  const double u_max = c_.rcs.u_max;
  for (int i = first; i < first + n; ++i) {
    const Vec3 arm = (p_pos_[i] + r_).cross(e_[i]);
    const Vec3 t = d_ - u_max * k_(i) * arm;
    const Mat3 a = u_max * k_(i) * skew(e_[i]);  // dt/dr
    const Vec3 c = -u_max * arm;                  // dt/dk_i
    const Vec3 p_dk = p_all_.block<3, 1>(kIdD, kIdK + i);
    const Vec3 p_rk = p_all_.block<3, 1>(kIdR, kIdK + i);
    const double p_kk = p_all_(kIdK + i, kIdK + i);
    const Mat3 ap_rd = a * p_dr.transpose();
    const Vec3 ap_rk = a * p_rk;
    // The column's own covariance (r and k_i), then with d's terms.
    const Mat3 col_cov = a * p_rr * a.transpose() + ap_rk * c.transpose() +
                         c * ap_rk.transpose() + p_kk * (c * c.transpose());
    const Vec3 col = u_max * k_(i) * arm;
    // Along the column's own direction (S(e_i) makes col_cov rank-deficient without k's term):
    // (|col|^2)^2 / col' C col, the squared ratio of its length to its 1 sigma there.
    const double c2 = col.squaredNorm();
    const double var = col.dot(col_cov * col);
    ft_.chi2_column[static_cast<std::size_t>(i)] = var > 0.0 ? c2 * c2 / var : 0.0;
    const Mat3 cov = p_dd + ap_rd + ap_rd.transpose() + col_cov + p_dk * c.transpose() +
                     c * p_dk.transpose();
    const Eigen::LDLT<Mat3> l(cov);
    ft_.chi2_jet[static_cast<std::size_t>(i)] =
        l.info() == Eigen::Success && l.isPositive() ? t.dot(l.solve(t)) : 1e300;
  }
}

void Identifier::settle_factors() {
  // (I24) The perfect pseudo-measurement d = 0: x <- x - P_:d P_dd^-1 d, P <- P - P_:d P_dd^-1 P_d:
  // its factors here, the state on the next tick (start_settle), the covariance a block of rows
  // per tick (settle_rows). Two ticks, not one (the Cortex-M7 tick budget: together 1.5 k
  // instructions, which with the identification excitation made one HOLD tick 20.3 k).
  settle_.factored = false;
  if (d_held_zero_) return;
  const Mat3 p_dd = p_all_.block<3, 3>(kIdD, kIdD);
  const Eigen::LDLT<Mat3> l(p_dd);
  if (l.info() != Eigen::Success || !l.isPositive()) return;
  settle_.pd = p_all_.middleCols<3>(kIdD);
  settle_.g = settle_.pd * l.solve(Mat3::Identity());
  settle_.factored = true;
  settle_.generation = counters_.reinflations;
}

void Identifier::start_settle() {
  // A re-inflation since the factors (a confirmed fault, the gate) changed P: no settling.
  if (!settle_.factored || d_held_zero_ || settle_.generation != counters_.reinflations) return;
  settle_.factored = false;
  VecId x;
  x << a_, r_, k_, b_, d_;
  x -= settle_.g * d_;
  const Mat3 j = inertia_matrix(x.head<6>());
  if (!j.allFinite() || Eigen::LLT<Mat3>(j).info() != Eigen::Success) return;  // (I14)
  a_ = x.head<6>();
  r_ = x.segment<3>(kIdR);
  k_ = x.segment<kThrusters>(kIdK);
  b_ = x.segment<3>(kIdB);
  d_.setZero();
  settle_.rows = 0;
  settle_.pending = true;
  d_held_zero_ = true;
  ++counters_.fault_torque_settles;
}

bool Identifier::settle_rows() {
  if (!settle_.pending) return true;
  // Element (i, j) loses g(lo) . pd(hi), lo = min(i, j): the same product for (j, i), so P stays
  // exactly symmetric whichever rows are done first.
  const int first = settle_.rows;
  const int n = std::min(kSettleRowsPerTick, kIdParams - first);
  for (int i = first; i < first + n; ++i) {
    for (int j = 0; j < kIdParams; ++j) {
      const int lo = i < j ? i : j;
      const int hi = i < j ? j : i;
      p_all_(i, j) -= settle_.g.row(lo).dot(settle_.pd.row(hi));
    }
  }
  settle_.rows = first + n;
  if (settle_.rows < kIdParams) return false;
  settle_.pending = false;
  // d is out of the state: exactly zero rows and columns (no gain, no uncertainty).
  p_all_.middleRows<3>(kIdD).setZero();
  p_all_.middleCols<3>(kIdD).setZero();
  sync_blocks();
  return true;
}

void Identifier::finish_settle() {
  while (!settle_rows()) {
  }
}

}  // namespace rocksteady::gnc
