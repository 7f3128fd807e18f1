// (F61) Channel balance test. Equations in balance_test.hpp and gnc/fdi/README.md (F61).
#include "gnc/fdi/balance_test.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Cholesky>

namespace rocksteady::gnc {

void ChannelBalanceTest::configure(const BalanceTestParams& p, double dt, double u_max,
                                   double gyro_sigma, double disturbance_sigma) {
  p_ = p;
  dt_ = dt;
  u_max_ = u_max;
  gyro_var_ = gyro_sigma * gyro_sigma;
  dist_sigma_ = disturbance_sigma;
  // The quiet segments: as many samples as put each half's kick at 1.5 min_snr of its 1 sigma
  // (a level difference of two segments of q samples: sigma_g sqrt(2 / q)), at least 10, at most
  // quiet_ticks.
  const double z = p_.kick_rad_s > 0.0 ? 1.5 * p_.min_snr * gyro_sigma / p_.kick_rad_s : 0.0;
  quiet_ = static_cast<int>(std::fmin(std::fmax(std::ceil(2.0 * z * z), 10.0),
                                      static_cast<double>(std::max(p_.quiet_ticks, 1))));
  reset();
}

void ChannelBalanceTest::reset() {
  channel_ = -1;
  pending_ = false;
  command_ = 0.0;
  k_ = 0;
  info_.fill(ChannelInfo{});
  round_open_ = false;
  round_end_s_ = -1e300;
}

bool ChannelBalanceTest::start(double now_s, std::uint8_t usable, const Vec3& omega,
                               const std::array<double, kChannels>& b_plus_norm,
                               double j_inv_norm, double model_rel) {
  if (!enabled() || active()) return false;
  if (!round_open_) {
    if (now_s - round_end_s_ < p_.interval_s) return false;
    info_.fill(ChannelInfo{});
    round_open_ = true;
  }
  int c = -1;
  bool remaining = false;
  for (int j = 0; j < kChannels; ++j) {
    if (info_[static_cast<std::size_t>(j)].done) continue;
    remaining = true;
    if (((usable >> j) & 1u) != 0 && b_plus_norm[static_cast<std::size_t>(j)] > 0.0) {
      c = j;
      break;
    }
  }
  if (c < 0) {
    if (!remaining) {  // every channel decided: the round ends, the next one an interval later
      round_open_ = false;
      round_end_s_ = now_s;
    }
    return false;
  }
  const double force = std::fmin(p_.force_n, u_max_);
  const double measured = info_[static_cast<std::size_t>(c)].response;
  const double per_ns = measured > 0.0 ? measured : b_plus_norm[static_cast<std::size_t>(c)];
  const double ticks = p_.kick_rad_s / (per_ns * force * dt_);
  n_fire_ = static_cast<int>(std::fmin(std::fmax(std::ceil(ticks), 1.0),
                                       static_cast<double>(std::max(p_.max_fire_ticks, 1))));
  channel_ = c;
  k_ = 0;
  j_inv_norm_ = j_inv_norm;
  model_rel_ = model_rel;
  omega_start_ = omega;
  predicted_.setZero();
  motion_ = 0.0;
  i_plus_ = i_minus_ = 0.0;
  n_ = s1_ = s2_ = s11_ = s22_ = s12_ = 0.0;
  sr_.setZero();
  s1r_.setZero();
  s2r_.setZero();
  sp_.setZero();
  s1p_.setZero();
  s2p_.setZero();
  srr_ = 0.0;
  next_command();
  return true;
}

bool ChannelBalanceTest::quiet_enough(double other_rate) const {
  // (F61c) The flight drifts free during a test (Gnc): not while it turns the body by more than
  // the test's kick over the test's quiet samples.
  const double t = 3.0 * static_cast<double>(quiet_) * dt_;
  return other_rate * t <= p_.kick_rad_s;
}

void ChannelBalanceTest::next_command() {
  // The interval after sample k_ (1-based k_ + 1): quiet, "+", quiet, "-", quiet.
  const int j = k_ + 1;
  const int q = quiet_;
  const double force = std::fmin(p_.force_n, u_max_);
  if (j > q && j <= q + n_fire_) {
    command_ = force;
  } else if (j > 2 * q + n_fire_ && j <= 2 * q + 2 * n_fire_) {
    command_ = -force;
  } else {
    command_ = 0.0;
  }
}

void ChannelBalanceTest::abort() {
  if (!active()) return;
  channel_ = -1;
  command_ = 0.0;
  pending_ = false;
}

BalanceVerdict ChannelBalanceTest::sample(const Vec3& omega, const Vec3& predicted_other,
                                          const Vec3& other_thrust, double f_plus,
                                          double f_minus) {
  dropped_ = false;
  if (!active() || pending_) return BalanceVerdict{};
  ++k_;
  predicted_ += predicted_other;
  motion_ += other_thrust.norm();
  i_plus_ += f_plus * dt_;
  i_minus_ += f_minus * dt_;
  // (F61a) the residual of sample k and the sums of its fit.
  const Vec3 r = omega - omega_start_ - predicted_;
  // (F61d) Beyond what the test's own firings can do.
  if (r.lpNorm<Eigen::Infinity>() > kAbortKicks * p_.kick_rad_s + 5.0 * std::sqrt(2.0 * gyro_var_)) {
    abort();
    dropped_ = true;
    return BalanceVerdict{};
  }
  n_ += 1.0;
  s1_ += i_plus_;
  s2_ += i_minus_;
  s11_ += i_plus_ * i_plus_;
  s22_ += i_minus_ * i_minus_;
  s12_ += i_plus_ * i_minus_;
  sr_ += r;
  srr_ += r.squaredNorm();
  s1r_ += i_plus_ * r;
  s2r_ += i_minus_ * r;
  sp_ += predicted_;
  s1p_ += i_plus_ * predicted_;
  s2p_ += i_minus_ * predicted_;
  if (k_ < test_ticks()) {
    next_command();
    return BalanceVerdict{};
  }
  command_ = 0.0;
  pending_ = true;
  return BalanceVerdict{};
}

BalanceVerdict ChannelBalanceTest::finish() {
  if (!pending_ || !active()) return BalanceVerdict{};
  pending_ = false;
  return evaluate();
}

BalanceVerdict ChannelBalanceTest::evaluate() {
  BalanceVerdict v;
  v.channel = channel_;
  ChannelInfo& ci = info_[static_cast<std::size_t>(channel_)];
  channel_ = -1;
  // The noise of a sample: the gyro's and the disturbance over the test (F5's terms; the model's
  // error is the bias of F61c).
  const double t = n_ * dt_;
  const double dist = dist_sigma_ * j_inv_norm_ * t;
  const double var = gyro_var_ + dist * dist + 1e-30;
  // (F61e) the fit's residual: sum |r|^2 less what offset and the two responses explain, per axis
  // b' M^-1 b with M the regressors' normal matrix.
  Mat3 m;
  m << n_, s1_, s2_, s1_, s11_, s12_, s2_, s12_, s22_;
  const Eigen::LDLT<Mat3> ldlt(m);
  double explained = 0.0;
  for (int a = 0; a < 3; ++a) {
    const Vec3 b(sr_(a), s1r_(a), s2r_(a));
    explained += b.dot(ldlt.solve(b));
  }
  const double dof = 3.0 * (n_ - 3.0);
  const double fit_chi2 = std::fmax(srr_ - explained, 0.0) / var;
  const bool fits = ldlt.info() == Eigen::Success && dof > 0.0 &&
                    fit_chi2 <= dof + 5.0 * std::sqrt(2.0 * dof);
  // (F61a) the offset eliminated; the information summed over the channel's tests.
  ci.a00 += (s11_ - s1_ * s1_ / n_) / var;
  ci.a01 += (s12_ - s1_ * s2_ / n_) / var;
  ci.a11 += (s22_ - s2_ * s2_ / n_) / var;
  ci.y0 += (s1r_ - s1_ * (sr_ / n_)) / var;
  ci.y1 += (s2r_ - s2_ * (sr_ / n_)) / var;
  ci.yb0 += model_rel_ * (s1p_ - s1_ * (sp_ / n_)) / var;  // (F61c)
  ci.yb1 += model_rel_ * (s2p_ - s2_ * (sp_ / n_)) / var;
  ++ci.tests;
  const double det = ci.a00 * ci.a11 - ci.a01 * ci.a01;
  v.outcome = BalanceOutcome::kInconclusive;
  if (det > 0.0 && std::isfinite(det)) {
    const double i00 = ci.a11 / det, i11 = ci.a00 / det, i01 = -ci.a01 / det;
    const Vec3 g_plus = i00 * ci.y0 + i01 * ci.y1;
    const Vec3 g_minus = i01 * ci.y0 + i11 * ci.y1;
    const double var_sum = std::fmax(i00 + i11 + 2.0 * i01, 1e-300);
    // (F61c) the model's bias on each half's response and on their sum.
    const Vec3 bias_plus = i00 * ci.yb0 + i01 * ci.yb1;
    const Vec3 bias_minus = i01 * ci.yb0 + i11 * ci.yb1;
    const double bias_sum = kBiasSigmas * (bias_plus + bias_minus).norm();
    const double excess = std::fmax((g_plus + g_minus).norm() - bias_sum, 0.0);
    v.chi2 = excess * excess / var_sum;
    const Vec3 diff = g_plus - g_minus;
    const double dn = diff.norm();
    if (dn > 0.0 && std::isfinite(dn)) {
      const Vec3 u = diff / dn;
      const double s_plus = g_plus.dot(u);
      const double s_minus = -g_minus.dot(u);
      const bool minus_weaker = s_minus < s_plus;
      const double s_s = minus_weaker ? s_plus : s_minus;
      const double s_w = minus_weaker ? s_minus : s_plus;
      const double var_s = minus_weaker ? i00 : i11;
      const double var_w = minus_weaker ? i11 : i00;
      const double bias_s = kBiasSigmas * (minus_weaker ? bias_plus : bias_minus).norm();
      const double bias_w = kBiasSigmas * (minus_weaker ? bias_minus : bias_plus).norm();
      const double sig_w = std::sqrt(std::fmax(var_w, 0.0));
      const double rho = std::fmin(std::fmax(s_w / s_s, 0.0), 1.0);
      v.ratio = rho;
      if (s_s > 3.0 * std::sqrt(std::fmax(var_s, 0.0))) ci.response = s_s;
      // (F61c) Clean: the model's bias, and the other jets' whole motion over this test (one of
      // them may be the faulty jet, which the model predicts as healthy), each within a fraction
      // of min_loss of the kick.
      const double kick = s_s * std::fmax(i_plus_, i_minus_);
      const bool clean = fits && bias_sum <= 0.5 * p_.min_loss * s_s && motion_ <= 0.25 * p_.min_loss * kick;
      if (clean && s_s - bias_s >= p_.min_snr * std::sqrt(std::fmax(var_s, 0.0))) {
        if (v.chi2 < p_.chi2_bound || 1.0 - rho < p_.min_loss) {
          v.outcome = BalanceOutcome::kBalanced;
        } else if (s_w < p_.total_sigmas * sig_w + bias_w && rho < kMaxTotalRatio) {
          v.outcome = BalanceOutcome::kFault;
          v.kind = FaultKind::kStuckOff;
        } else if (s_w - bias_w >= p_.partial_sigmas * sig_w) {
          v.outcome = BalanceOutcome::kFault;
          v.kind = FaultKind::kDegraded;
          v.factor = rho;
          v.factor_sigma = std::sqrt(std::fmax(var_w + rho * rho * var_s, 0.0)) / s_s;
        }
      }
      if (v.outcome == BalanceOutcome::kFault) v.thruster = 2 * v.channel + (minus_weaker ? 1 : 0);
    }
  }
  if (v.outcome == BalanceOutcome::kInconclusive && ci.tests < p_.max_tests) {
    return v;  // the channel is tested again, its information kept
  }
  ci.done = true;
  return v;
}

}  // namespace rocksteady::gnc
