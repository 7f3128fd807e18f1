#include "gnc/fdi/fault_detector.hpp"
#include "gnc/fdi/jet_check.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>

namespace rocksteady::gnc {
namespace {

// (F13) The LLR of "a jet lost a fraction a of its thrust", a in (0, 1] fitted, from its stuck-off
// LLR and energy E = sum |S~|^2 / var over some windows: with SR = LLR + E / 2, the maximum over a
// of a SR - a^2 E / 2 is SR^2 / (2 E) for SR < E, and the stuck-off LLR (a = 1) beyond.
double fitted_loss_llr(double llr_off, double e) {
  const double sr = llr_off + 0.5 * e;
  if (!(sr > 0.0) || !(e > 0.0)) return 0.0;
  return sr >= e ? llr_off : sr * sr / (2.0 * e);
}

}  // namespace

Check validate(const FaultDetectorParams& p) {
  auto bad = [](const char* field, const char* reason) { return Check{false, field, reason}; };
  if (p.window_ticks < 4 || p.window_ticks > 1000) {
    return bad("fdi.window_ticks", "must be in [4, 1000]");
  }
  if (!finite_non_negative(p.gyro_sigma)) return bad("fdi.gyro_sigma", "must be >= 0 and finite");
  if (!finite_non_negative(p.disturbance_sigma)) {
    return bad("fdi.disturbance_sigma", "must be >= 0 and finite");
  }
  if (!finite_non_negative(p.model_rel_floor)) {
    return bad("fdi.model_rel_floor", "must be >= 0 and finite");
  }
  if (!finite_positive(p.confirm_llr)) return bad("fdi.confirm_llr", "must be positive");
  if (!finite_non_negative(p.margin_llr)) return bad("fdi.margin_llr", "must be >= 0");
  if (!finite_positive(p.suspect_chi2)) return bad("fdi.suspect_chi2", "must be positive");
  if (p.detect_early_ticks < 0 || p.detect_early_ticks > 1000) {
    return bad("fdi.detect_early_ticks", "must be in [0, 1000]");
  }
  if (!finite_positive(p.detect_early_chi2)) {
    return bad("fdi.detect_early_chi2", "must be positive");
  }
  if (!finite_non_negative(p.min_signature)) return bad("fdi.min_signature", "must be >= 0");
  if (!finite_non_negative(p.model_sigmas)) return bad("fdi.model_sigmas", "must be >= 0");
  if (p.probe_after_windows < 0 || p.probe_after_windows > 1000) {
    return bad("fdi.probe_after_windows", "must be in [0, 1000]");
  }
  if (p.probe_windows < 0 || p.probe_windows > 1000) {
    return bad("fdi.probe_windows", "must be in [0, 1000]");
  }
  if (p.probe_window_ticks != 0 && (p.probe_window_ticks < 4 || p.probe_window_ticks > 1000)) {
    return bad("fdi.probe_window_ticks", "must be 0 or in [4, 1000]");
  }
  {  // (F61)
    const BalanceTestParams& b = p.balance;
    if (!finite_non_negative(b.kick_rad_s)) return bad("fdi.balance.kick_rad_s", "must be >= 0");
    if (!finite_positive(b.force_n)) return bad("fdi.balance.force_n", "must be positive");
    if (b.quiet_ticks < 1 || b.quiet_ticks > 10000) {
      return bad("fdi.balance.quiet_ticks", "must be in [1, 10000]");
    }
    if (b.max_fire_ticks < 1 || b.max_fire_ticks > 10000) {
      return bad("fdi.balance.max_fire_ticks", "must be in [1, 10000]");
    }
    if (!finite_non_negative(b.interval_s)) return bad("fdi.balance.interval_s", "must be >= 0");
    if (!finite_positive(b.chi2_bound)) return bad("fdi.balance.chi2_bound", "must be positive");
    if (!finite_positive(b.min_snr)) return bad("fdi.balance.min_snr", "must be positive");
    if (!finite_positive(b.total_sigmas) || !finite_positive(b.partial_sigmas) ||
        b.partial_sigmas < b.total_sigmas) {
      return bad("fdi.balance.partial_sigmas", "must be positive and >= total_sigmas");
    }
    if (!finite_non_negative(b.min_loss) || !(b.min_loss < 1.0)) {
      return bad("fdi.balance.min_loss", "must be in [0, 1)");
    }
    if (b.max_tests < 1 || b.max_tests > 1000) {
      return bad("fdi.balance.max_tests", "must be in [1, 1000]");
    }
  }
  if (!(p.probe_short_min_llr >= 0.0) || !std::isfinite(p.probe_short_min_llr)) {
    return bad("fdi.probe_short_min_llr", "must be finite and >= 0");
  }
  if (!(p.probe_start_llr >= 0.0) || !std::isfinite(p.probe_start_llr) ||
      (p.probe_start_llr > 0.0 && !(p.probe_start_llr < p.confirm_llr))) {
    return bad("fdi.probe_start_llr", "must be 0 or in (0, confirm_llr)");  // (F52)
  }
  if (!finite_positive(p.identified_zero_chi2)) {
    return bad("fdi.identified_zero_chi2", "must be positive");
  }
  if (!finite_positive(p.identified_match_chi2)) {
    return bad("fdi.identified_match_chi2", "must be positive");
  }
  if (!finite_non_negative(p.identified_margin_chi2)) {
    return bad("fdi.identified_margin_chi2", "must be >= 0");
  }
  if (p.identified_windows < 1 || p.identified_windows > 1000) {
    return bad("fdi.identified_windows", "must be in [1, 1000]");
  }
  if (!(p.degraded_min_loss >= 0.0 && p.degraded_min_loss < 1.0)) {
    return bad("fdi.degraded_min_loss", "must be in [0, 1)");
  }
  if (!finite_non_negative(p.check_llr)) return bad("fdi.check_llr", "must be >= 0 and finite");
  if (!finite_positive(p.check_force_n)) return bad("fdi.check_force_n", "must be positive");
  if (p.check_windows < 1 || p.check_windows > 1000) {
    return bad("fdi.check_windows", "must be in [1, 1000]");
  }
  if (!finite_non_negative(p.check_interval_s)) {
    return bad("fdi.check_interval_s", "must be >= 0 and finite");
  }
  if (!finite_positive(p.check_fit_chi2)) return bad("fdi.check_fit_chi2", "must be positive");
  if (!finite_positive(p.check_max_model_error)) {
    return bad("fdi.check_max_model_error", "must be positive");
  }
  if (!(p.check_min_llr >= 0.0) || !std::isfinite(p.check_min_llr)) {
    return bad("fdi.check_min_llr", "must not be negative");
  }
  if (!finite_non_negative(p.survey_interval_s)) {
    return bad("fdi.survey_interval_s", "must be >= 0 and finite");
  }
  if (!finite_positive(p.survey_energy)) return bad("fdi.survey_energy", "must be positive");
  if (!finite_non_negative(p.after_fault_max_j_rel)) {
    return bad("fdi.after_fault_max_j_rel", "must be >= 0 and finite");  // (F59)
  }
  if (!finite_non_negative(p.total_loss_sigmas)) {
    return bad("fdi.total_loss_sigmas", "must be >= 0 and finite");  // (F58)
  }
  if (!finite_non_negative(p.survey_loss_llr)) {
    return bad("fdi.survey_loss_llr", "must be >= 0 and finite");  // (F57)
  }
  if (!finite_non_negative(p.survey_max_kick_rad_s)) {
    return bad("fdi.survey_max_kick_rad_s", "must be >= 0 and finite");
  }
  if (p.survey_max_windows < 1 || p.survey_max_windows > 1000) {
    return bad("fdi.survey_max_windows", "must be in [1, 1000]");
  }
  if (p.check_long_ticks != 0 && (p.check_long_ticks < 4 || p.check_long_ticks > 1000)) {
    return bad("fdi.check_long_ticks", "must be 0 or in [4, 1000]");
  }
  if (!finite_positive(p.check_long_energy)) {
    return bad("fdi.check_long_energy", "must be positive");
  }
  if (!finite_positive(p.check_long_evidence_energy)) {
    return bad("fdi.check_long_evidence_energy", "must be positive");
  }
  if (!(p.check_long_reach >= 0.0 && p.check_long_reach <= 0.95)) {
    return bad("fdi.check_long_reach", "must be in [0, 0.95]");
  }
  return Check{};
}

double check_normal_chi2(const Vec3& b, const Vec3& slope, double stt, double var) {
  const double bb = b.squaredNorm();
  if (!(bb > 0.0) || !(stt > 0.0) || !(var > 0.0)) return 0.0;
  const double bs = b.dot(slope);
  return std::fmax(0.0, slope.squaredNorm() - bs * bs / bb) * stt / var;
}

void FaultDetector::configure(const FaultDetectorParams& p, const RcsLayout& rcs, double u_max,
                              double dt) {
  p_ = p;
  u_max_ = u_max;
  dt_ = dt;
  for (int c = 0; c < kChannels; ++c) {
    for (int s = 0; s < 2; ++s) {
      const auto i = static_cast<std::size_t>(2 * c + s);
      pos_[i] = rcs.pod_position[rcs.channel_pod[c]];
      dir_[i] = s == 0 ? rcs.channel_direction[c] : Vec3(-rcs.channel_direction[c]);
      pod_[i] = rcs.channel_pod[c];
    }
  }
  st_ = FaultDetectorStatus{};
  factor_.fill(1.0);
  check_force_ = p_.check_force_n;
  // (F48) The least kick by which one window shows a total loss at survey_energy (F6's ramp
  // energy over n samples, the gyro's noise sigma_g).
  const double nw = static_cast<double>(p_.window_ticks);
  survey_noisy_ = p_.survey_noise_kick && p_.survey_max_kick_rad_s > 0.0 &&
                  nw * p_.gyro_sigma * std::sqrt(12.0 * p_.survey_energy / (nw * (nw * nw - 1.0))) >
                      p_.survey_max_kick_rad_s;
  // (F61) The balance test, with the detector's per-sample gyro noise (F28's centred form).
  balance_.configure(p_.balance, dt_, u_max_, p_.gyro_sigma, p_.disturbance_sigma);
  reset_scores();
  // Before set_model: nothing suspected, the model is taken (F7).
  suspecting_ = false;
  deg_suspecting_ = false;
  FaultModel m;
  m.j = Mat3::Identity();
  set_model(m);
  reset();
}


void FaultDetector::reset_scores() {
  score_.fill(0.0);
  deg_cusum_.fill(0.0);
  deg_sr_.fill(0.0);
  deg_e_.fill(0.0);
  pool_llr_.fill(0.0);
  pool_energy_.fill(0.0);
}

void FaultDetector::reset_episode() {
  // The sums are not cleared (about 3 kB: 1.3 k Cortex-M7 instructions): a new epoch makes every
  // entry stale; a stale entry reads as zero, and its first window of the episode writes it
  // afresh. (A 32-bit epoch, at most one restart per window of 0.5 s, wraps after 68 years.)
  ++episode_epoch_;
  ambiguous_windows_ = 0;
  st_.ambiguous_with = -1;
}

void FaultDetector::restart_episode_with_window() {
  // (F25) A new episode of the window being evaluated alone: its scores (steps 1 and 2) are
  // already in the old episode's sums, so the new one takes them from the window's own values;
  // its cross sums come next (evaluate_cross), on the new epoch's fresh rows.
  reset_episode();
  for (std::size_t k = 0; k < static_cast<std::size_t>(kHypotheses); ++k) {
    hyp_epoch_[k] = episode_epoch_;
    lambda_[k] = window_llr_[k];
    info_[k] = window_info_[k];
  }
  ++st_.episode_restarts;
}

void FaultDetector::cancel_evaluation() {
  // A declaration or a clearance changes what is predicted: the window being evaluated and the
  // one open (partly predicted without it) are dropped; the next valid sample starts afresh. A
  // staged model is taken on the next update.
  eval_phase_ = 0;
  partial_loss_pending_ = false;
  have_start_ = false;
  restart_window_ = false;
}

void FaultDetector::reset() {
  valve_open_ = {{true, true, true, true}};
  have_start_ = false;
  last_suspicious_ = false;
  n_ = 0;
  cancel_evaluation();
  reset_scores();
  suspecting_ = false;
  deg_suspecting_ = false;
  reset_episode();
  probe_left_ = 0;
  end_probe_verdict();
  reset_probe_llr();
  end_sweep();
  sweep_llr_.fill(0.0);
  sweep_llr_off_.fill(0.0);
  end_check();
  last_check_.fill(0);
  check_backoff_.fill(0);
  survey_e_.fill(0.0);
  survey_from_.fill(st_.windows);
  loss_survey_at_.fill(0);
  st_.unverified = 0;
  check_prev_ = -1;
  quiet_var_ = 0.0;
  eval_unfit_ = false;
  eval_slope_.setZero();
  eval_stt_ = 0.0;
  const std::uint16_t on = st_.confirmed_on;
  const std::uint16_t off = st_.confirmed_off;
  const std::uint16_t degraded = st_.confirmed_degraded;
  st_ = FaultDetectorStatus{};
  st_.confirmed_on = on;
  st_.confirmed_off = off;
  st_.confirmed_degraded = degraded;
}

void FaultDetector::set_model(const FaultModel& m) {
  // (F7) While a hypothesis is suspected, the model it is tested against is held: the identifier
  // is fitting the unmodelled fault into J, r and k, and a model that has absorbed part of the
  // fault moves the signatures of the other hypotheses towards it.
  if (suspecting()) {
    ++st_.models_held;
    return;
  }
  // (F10) The closed window under evaluation is scored with the model its prediction used; a
  // new one waits for the end of the evaluation (a copy, no heap).
  if (eval_phase_ != 0) {
    staged_ = m;
    model_staged_ = true;
    return;
  }
  apply_model(m);
}

void FaultDetector::apply_model(const FaultModel& m) {
  m_ = m;
  r_sigma_ = std::sqrt(std::fmax(0.0, m.r_cov.diagonal().maxCoeff()));
  j_inv_ = m.j.inverse();
  // Spectral norms of J and J^-1 from J's eigenvalues (symmetric 3x3, fixed size: no heap).
  const Eigen::SelfAdjointEigenSolver<Mat3> eig(0.5 * (m.j + m.j.transpose()), Eigen::EigenvaluesOnly);
  const double lo = eig.eigenvalues().minCoeff();
  const double hi = eig.eigenvalues().maxCoeff();
  j_norm_ = hi;
  j_inv_norm_ = lo > 0.0 ? 1.0 / lo : j_inv_.norm();
  for (int i = 0; i < kThrusters; ++i) {
    const auto k = static_cast<std::size_t>(i);
    // (F1): the rate change per newton-second of thruster i.
    b_[k] = j_inv_ * (m.k(i) * (pos_[k] + m.r).cross(dir_[k]));
    b_norm_[k] = b_[k].norm();
  }
}

void FaultDetector::declare(int thruster, FaultKind kind, double factor) {
  if (thruster < 0 || thruster >= kThrusters) return;
  const auto bit = static_cast<std::uint16_t>(1u << thruster);
  st_.confirmed_on = static_cast<std::uint16_t>(st_.confirmed_on & ~bit);
  st_.confirmed_off = static_cast<std::uint16_t>(st_.confirmed_off & ~bit);
  st_.confirmed_degraded = static_cast<std::uint16_t>(st_.confirmed_degraded & ~bit);
  factor_[static_cast<std::size_t>(thruster)] = 1.0;
  if (kind == FaultKind::kStuckOn) st_.confirmed_on |= bit;
  if (kind == FaultKind::kStuckOff) st_.confirmed_off |= bit;
  if (kind == FaultKind::kDegraded && factor > 0.0 && factor < 1.0) {
    st_.confirmed_degraded |= bit;
    factor_[static_cast<std::size_t>(thruster)] = factor;
  }
  cancel_evaluation();  // that window was scored without the fault in the model
  if (balance_.active()) {  // (F61) a test flown against the model before it
    balance_.abort();
    ++st_.balance_aborted;
  }
  st_.balance_channel = -1;
  reset_scores();
  suspecting_ = false;
  deg_suspecting_ = false;
  reset_episode();
  probe_left_ = 0;
  end_probe_verdict();
  reset_probe_llr();
  end_sweep();
  sweep_llr_.fill(0.0);
  sweep_llr_off_.fill(0.0);
  st_.probe_pod = -1;
  end_check();
}

void FaultDetector::carry_counts(const FaultDetectorStatus& b) {
  st_.balance_tests += b.balance_tests;  // (F61)
  st_.balance_confirmations += b.balance_confirmations;
  st_.balance_inconclusive += b.balance_inconclusive;
  st_.balance_aborted += b.balance_aborted;
  st_.suspicions += b.suspicions;
  st_.models_held += b.models_held;
  st_.probes += b.probes;
  st_.episode_restarts += b.episode_restarts;
  st_.identified_confirmations += b.identified_confirmations;
  st_.sweeps += b.sweeps;
  st_.sweep_confirmations += b.sweep_confirmations;
  st_.degraded_confirmations += b.degraded_confirmations;
  st_.checks += b.checks;
  st_.checks_unfit += b.checks_unfit;
  st_.surveys += b.surveys;
  st_.survey_ratings += b.survey_ratings;
  st_.survey_kick_refusals += b.survey_kick_refusals;
  st_.evidence_kick_refusals += b.evidence_kick_refusals;
  st_.survey_noise_refusals += b.survey_noise_refusals;
  st_.long_checks += b.long_checks;
  st_.long_checks_dropped += b.long_checks_dropped;
  st_.long_checks_capped += b.long_checks_capped;
  st_.early_detections += b.early_detections;
  st_.onset_restarts += b.onset_restarts;
  st_.probe_whole_windows += b.probe_whole_windows;
  st_.elsewhere_verdicts += b.elsewhere_verdicts;
}

void FaultDetector::clear(int thruster) {
  identified_confirm_ = -1;
  st_.identified_best = -1;
  st_.identified_streak = 0;
  if (thruster < 0) {
    st_.confirmed_on = 0;
    st_.confirmed_off = 0;
    st_.confirmed_degraded = 0;
    factor_.fill(1.0);
  } else if (thruster < kThrusters) {
    const auto bit = static_cast<std::uint16_t>(1u << thruster);
    st_.confirmed_on = static_cast<std::uint16_t>(st_.confirmed_on & ~bit);
    st_.confirmed_off = static_cast<std::uint16_t>(st_.confirmed_off & ~bit);
    st_.confirmed_degraded = static_cast<std::uint16_t>(st_.confirmed_degraded & ~bit);
    factor_[static_cast<std::size_t>(thruster)] = 1.0;
  }
  cancel_evaluation();
  reset_scores();
  suspecting_ = false;
  deg_suspecting_ = false;
  reset_episode();
  probe_left_ = 0;
  end_check();
  end_probe_verdict();
  reset_probe_llr();
  end_sweep();
  sweep_llr_.fill(0.0);
  sweep_llr_off_.fill(0.0);
  st_.probe_pod = -1;
}

void FaultDetector::identified_evidence(const StuckOnEvidence& e) {
  if (!p_.enabled || !p_.identified_isolation) return;
  // (F14): the best-matching thruster not already latched, and the runner-up.
  int best = -1;
  double c1 = 1e300;  // its chi-square
  double c2 = 1e300;  // the runner-up's
  for (int i = 0; i < kThrusters; ++i) {
    if ((((st_.confirmed_on | st_.confirmed_off) >> i) & 1u) != 0) continue;
    const double c = e.chi2_jet[static_cast<std::size_t>(i)];
    if (!(c >= 0.0)) continue;  // NaN or negative: no evidence
    if (c < c1) {
      c2 = c1;
      c1 = c;
      best = i;
    } else if (c < c2) {
      c2 = c;
    }
  }
  const bool pass = e.fitted && best >= 0 && e.chi2_zero > p_.identified_zero_chi2 &&
                    e.chi2_column[static_cast<std::size_t>(best)] > p_.identified_zero_chi2 &&
                    c1 < p_.identified_match_chi2 && c2 - c1 > p_.identified_margin_chi2;
  if (!e.fitted) return;  // a gated or refused window neither adds nor breaks a streak
  if (!pass) {
    st_.identified_best = -1;
    st_.identified_streak = 0;
    // (F17) The fault torque stands out from zero, but no jet matches it yet (the model has not
    // converged around it): sweep the pods, the one of the best-matching jet first.
    if (p_.identified_sweep && e.chi2_zero > p_.identified_zero_chi2 && !sweeping() &&
        probe_left_ == 0 && !verdict_pending_ && st_.confirmed_on == 0) {
      std::array<double, kPods> pod_best{};
      pod_best.fill(1e300);
      for (int i = 0; i < kThrusters; ++i) {
        const double c = e.chi2_jet[static_cast<std::size_t>(i)];
        const auto q = static_cast<std::size_t>(pod_[static_cast<std::size_t>(i)]);
        if (c >= 0.0 && c < pod_best[q]) pod_best[q] = c;
      }
      for (int q = 0; q < kPods; ++q) sweep_order_[static_cast<std::size_t>(q)] = q;
      for (int a = 1; a < kPods; ++a) {  // insertion sort of four
        for (int b = a; b > 0; --b) {
          const auto x = static_cast<std::size_t>(sweep_order_[static_cast<std::size_t>(b)]);
          const auto y = static_cast<std::size_t>(sweep_order_[static_cast<std::size_t>(b - 1)]);
          if (pod_best[x] >= pod_best[y]) break;
          std::swap(sweep_order_[static_cast<std::size_t>(b)],
                    sweep_order_[static_cast<std::size_t>(b - 1)]);
        }
      }
      sweep_next_ = 0;
      sweep_pod_ = -1;
      sweep_left_ = 0;
      sweep_reading_ = false;
      ++st_.sweeps;
    }
    return;
  }
  st_.identified_streak = best == st_.identified_best ? st_.identified_streak + 1 : 1;
  st_.identified_best = best;
  if (st_.identified_streak >= p_.identified_windows) identified_confirm_ = best;
}

FaultEvents FaultDetector::update(const FaultDetectorInput& in) {
  pending_ = FaultEvents{};
  if (!p_.enabled) return pending_;
  survey_allowed_ = in.survey_allowed;
  valve_open_ = in.valve_open;
  // (F18) A jet latched degraded delivers its factor of what is commanded: everything (the
  // prediction, the hypotheses' ramps, the sweep's delivered thrust) sees the delivered thrust.
  if (st_.confirmed_degraded == 0) return step(in);
  scaled_ = in;
  for (int i = 0; i < kThrusters; ++i) scaled_.thrust(i) *= factor_[static_cast<std::size_t>(i)];
  return step(scaled_);
}

FaultEvents FaultDetector::step(const FaultDetectorInput& in) {
  if (identified_confirm_ >= 0) {
    // (F14) The identifier isolated a stuck-on jet: the same latch and event as (F6).
    const int thruster = identified_confirm_;
    identified_confirm_ = -1;
    st_.identified_best = -1;
    st_.identified_streak = 0;
    if (((st_.confirmed_on >> thruster) & 1u) == 0) {
      declare(thruster, FaultKind::kStuckOn);
      ++st_.identified_confirmations;
      pending_.confirmed = true;
      pending_.thruster = thruster;
      pending_.kind = FaultKind::kStuckOn;
    }
  }
  // (F10) One step of the closed window's evaluation per tick, whatever this tick's data; a model
  // that arrived meanwhile is taken once it is done (before this tick's sample, like any other).
  if (eval_phase_ != 0) {
    // (F61) The third step is idle without a leader past the confirmation level (no blocking
    // scan): a balance test's fit takes it (heavy_step_next() counts it there).
    const bool fit_here = eval_phase_ == 3 && !(st_.best_llr > p_.confirm_llr) &&
                          balance_.evaluate_pending();
    evaluate_step();
    if (fit_here) balance_verdict(balance_.finish());
  } else {
    if (partial_loss_pending_) {
      evaluate_partial_losses();  // (F18)
    } else if (balance_.evaluate_pending()) {
      balance_verdict(balance_.finish());  // (F61) the fit of a test whose last sample is in
    }
    if (model_staged_) {
      model_staged_ = false;
      set_model(staged_);
    }
  }
  balance_clock_s_ += dt_;
  if (!in.omega_valid || !in.thrust_valid || !in.omega.allFinite() || !in.thrust.allFinite()) {
    if (balance_.flying()) {  // (F61) a gap breaks the test too (not one whose samples are in)
      balance_.abort();
      ++st_.balance_aborted;
      st_.balance_channel = -1;
    }
    have_start_ = false;  // a gap breaks the window; the next valid sample starts another
    return pending_;
  }
  if (!have_start_ || restart_window_) {
    // (F27) At a pod's closure the window restarts on this sample: every interval of the new
    // window is flown with the valve as the test set it. (F46) That window is the test's length.
    const bool test_start = restart_window_ && probe_left_ > 0 && !sweeping();
    // (F49) A long check's window starts here; a long check whose window a gap or a declaration
    // broke ends (the rest of it would be flown unscored).
    const bool long_start = restart_window_ && long_start_;
    if (check_long_n_ > 0 && !long_start) end_check();
    restart_window_ = false;
    long_start_ = false;
    if (balance_.flying()) {  // (F61) an unpredicted sample: the test is dropped
      balance_.abort();
      ++st_.balance_aborted;
      st_.balance_channel = -1;
    }
    start_window(in.omega);
    if (long_start) {
      window_len_ = check_long_n_;
    } else if (test_start && p_.probe_window_ticks > 0 && probe_short_) {
      window_len_ = p_.probe_window_ticks;
    }
    return pending_;
  }
  // (F2): the interval ending now, with the thrust commanded over it and the mid-interval rate.
  const Vec3 w = 0.5 * (omega_prev_ + in.omega);
  const Vec3 gyro = j_inv_ * w.cross(m_.j * w);
  Vec3 thrust_rate = Vec3::Zero();
  for (int i = 0; i < kThrusters; ++i) {
    const auto k = static_cast<std::size_t>(i);
    const bool open = in.valve_open[static_cast<std::size_t>(pod_[k])];
    if (!open) continue;
    const bool latched_on = ((st_.confirmed_on >> i) & 1u) != 0;
    const bool latched_off = ((st_.confirmed_off >> i) & 1u) != 0;
    // A confirmed fault is part of the model: stuck-on fires at u_max until its valve closes,
    // stuck-off produces nothing whatever is commanded.
    const double f = latched_on ? u_max_ : latched_off ? 0.0 : in.thrust(i);
    thrust_rate += b_[k] * f;
  }
  predicted_ += (thrust_rate - gyro) * dt_;
  WindowSums& acc = win_[static_cast<std::size_t>(acc_)];
  // (F61) This interval was flown under a balance test: its sample, and the window is the test's.
  if (balance_.flying()) {
    acc.balance = true;
    balance_update(in, thrust_rate, gyro);
  }
  // Model-uncertainty scale (F5): the thrust term, and the gyroscopic term's sensitivity to J,
  // |J^-1 (w x dJ w)| + |dJ^-1 (w x J w)| <= 2 ||J^-1|| ||dJ|| |w|^2 (not |J^-1 (w x J w)|, which
  // vanishes near a principal axis while its error does not).
  const double thrust_norm = thrust_rate.norm();
  acc.motion += (thrust_norm + 2.0 * j_inv_norm_ * j_norm_ * w.squaredNorm()) * dt_;
  // (the relative 1 sigma multiplies this: ||dJ||_2 = rel ||J||_2)
  acc.thrust_motion += thrust_norm * dt_;
  // (F35) Each jet's torque magnitude, where it can differ from their net: on the updates whose
  // thrust a check commanded (the thrust of this update was commanded while check_prev_ ran).
  double gross_rate = thrust_norm;
  if (check_prev_ >= 0) {
    gross_rate = 0.0;
    for (int i = 0; i < kThrusters; ++i) {
      const auto k = static_cast<std::size_t>(i);
      if (!in.valve_open[static_cast<std::size_t>(pod_[k])]) continue;
      const bool latched_on = ((st_.confirmed_on >> i) & 1u) != 0;
      const bool latched_off = ((st_.confirmed_off >> i) & 1u) != 0;
      gross_rate += b_norm_[k] * (latched_on ? u_max_ : latched_off ? 0.0 : in.thrust(i));
    }
  }
  acc.gross_motion += gross_rate * dt_;
  acc.force_impulse += in.thrust.sum() * dt_;
  ++n_;
  const Vec3 r = in.omega - omega_start_ - predicted_;  // (F3) residual of sample j
  if (n_ == 1) {
    accumulate<true>(acc, in, r);
  } else {
    accumulate<false>(acc, in, r);
  }
  // (F33) The window so far, from detect_early_ticks samples until its last (which the closed
  // window's evaluation reads), once per window.
  if (p_.detect_early_ticks > 0 && n_ >= p_.detect_early_ticks && n_ < window_len_ &&
      !acc.early_suspected && !acc.balance && early_chi2(acc, static_cast<double>(n_)) > p_.detect_early_chi2) {
    acc.early_suspected = true;
    ++st_.suspicions;
    ++st_.early_detections;
    pending_.suspected = true;
    pending_.early = true;
    // (F45) The onset window (F21: the first suspicious window after a quiet one, no test or check
    // under way) ends here and is dropped: the fault began within it, so the window starting on
    // this sample is filled by it. The previous window's evaluation is past its first step (which
    // reads last_suspicious_), since that step runs on the update after it closed.
    if (p_.onset_restart && p_.skip_onset_window && !last_suspicious_ && probe_left_ == 0 &&
        !verdict_pending_ && !sweeping() && acc.check_jet < 0 && st_.check_jet < 0) {
      ++st_.onset_restarts;
      last_suspicious_ = true;  // the dropped window was the onset: the next one is scored
      check_prev_ = st_.check_jet;
      start_window(in.omega);
      return pending_;
    }
  }
  // (F49) A long check's window showing motion off the checked jet's signature: another fault
  // (a jet stuck on) started within it. The check ends and its window is dropped, as (F45) drops
  // an onset window, so that the bank decides the fault on windows of its own length. Tested on
  // every update of the window past the early test's level (its first crossing can come while the
  // part off the signature is still small).
  if (check_long_n_ > 0 && st_.check_jet >= 0 && p_.detect_early_ticks > 0 &&
      n_ >= p_.detect_early_ticks && n_ < window_len_) {
    const double nn = static_cast<double>(n_);
    const double var = window_var(acc, nn);
    const double stt = acc.sum_tt - acc.sum_t * acc.sum_t / nn;
    const Vec3 str = acc.sum_tr - acc.sum_t * (acc.sum_r / nn);
    const Vec3 slope = stt > 0.0 ? Vec3(str / stt) : Vec3::Zero();
    if (stt > 0.0 && slope.squaredNorm() * stt / var > p_.detect_early_chi2 &&
        check_normal_chi2(b_[static_cast<std::size_t>(st_.check_jet)], slope, stt, var) >
            p_.check_fit_chi2) {
      ++st_.long_checks_dropped;
      end_check();
      last_suspicious_ = true;  // the next window, filled by the fault, is scored (F21)
      check_prev_ = -1;         // the thrust commanded after this update carries no check
      start_window(in.omega);
      return pending_;
    }
  }
  // (F61) A balance test may start on this sample.
  if (!balance_.active()) balance_start(in);
  // (F19) The thrust of this update was commanded while the check of the previous one ran.
  if (check_prev_ >= 0) acc.check_jet = check_prev_;
  check_prev_ = st_.check_jet;
  omega_prev_ = in.omega;
  if (n_ >= window_len_) {
    // (F49) A long check ends with its window: the thrust commanded after this update is the
    // next window's, without the check.
    const bool long_end = check_long_n_ > 0 && st_.check_jet >= 0;
    close_window();
    start_window(in.omega);  // the window's last sample starts the next one
    if (long_end) {
      end_check();
      check_prev_ = -1;
    }
  }
  return pending_;
}

template <bool kFirst>
void FaultDetector::accumulate(WindowSums& w, const FaultDetectorInput& in, const Vec3& r) {
  // A window's first sample assigns every sum (the set was last used two windows ago).
  const double t = static_cast<double>(n_);
  if (kFirst) {
    w.sum_r = r;
    w.sum_t = t;
    w.sum_tt = t * t;
    w.sum_tr = t * r;
  } else {
    w.sum_r += r;
    w.sum_t += t;
    w.sum_tt += t * t;
    w.sum_tr += t * r;
  }
  // (F4) signatures: stuck-on adds (u_max - f) of its thrust, stuck-off removes f; both only
  // while the pod's valve is open (a closed pod produces nothing under any hypothesis). The
  // increments first, then the sums over all hypotheses in loops of one array each (the compiler
  // runs them two hypotheses at a time; every sum is the same number as one hypothesis at a time).
  std::array<double, kHypotheses> step{};
  for (int i = 0; i < kThrusters; ++i) {
    const auto k = static_cast<std::size_t>(i);
    if (in.valve_open[static_cast<std::size_t>(pod_[k])]) {
      const double f = in.thrust(i);
      step[k] = (u_max_ - f) * dt_;
      step[k + static_cast<std::size_t>(kThrusters)] = -f * dt_;
    }
  }
  const double rx = r.x(), ry = r.y(), rz = r.z();
  if (kFirst) {
    for (std::size_t h = 0; h < step.size(); ++h) {
      const double c = step[h];
      w.c[h] = c;
      w.sum_c[h] = c;
      w.sum_cc[h] = c * c;
      w.sum_crx[h] = c * rx;
      w.sum_cry[h] = c * ry;
      w.sum_crz[h] = c * rz;
    }
  } else {
    for (std::size_t h = 0; h < step.size(); ++h) {
      const double c = (w.c[h] += step[h]);
      w.sum_c[h] += c;
      w.sum_cc[h] += c * c;
      w.sum_crx[h] += c * rx;
      w.sum_cry[h] += c * ry;
      w.sum_crz[h] += c * rz;
    }
  }
  // (F8) cross sums of the basis ramps (the hypotheses' pairs follow from them).
  std::array<double, kBasis> x{};
  for (int i = 0; i < kThrusters; ++i) {
    x[static_cast<std::size_t>(i)] = w.c[static_cast<std::size_t>(i + kThrusters)];
  }
  for (int q = 0; q < kPods; ++q) {
    const auto pq = static_cast<std::size_t>(q);
    const double open = in.valve_open[pq] ? dt_ : 0.0;
    if (kFirst) {
      w.tp[pq] = open;
      w.sum_tp[pq] = open;
    } else {
      w.tp[pq] += open;
      w.sum_tp[pq] += w.tp[pq];
    }
    x[static_cast<std::size_t>(kThrusters + q)] = w.tp[pq];
  }
  if (kFirst) w.live = 0;
  std::size_t idx = 0;
  for (std::size_t a = 0; a < x.size(); ++a) {
    const double xa = x[a];
    const std::uint32_t bit = 1u << a;
    if (xa == 0.0) {  // ramp a still zero: nothing to add (its row is not live yet, or adds 0)
      idx += x.size() - a;
      continue;
    }
    if ((w.live & bit) == 0) {  // ramp a starts: its row is assigned (no clearing needed)
      w.live |= bit;
      for (std::size_t b = a; b < x.size(); ++b) w.sum_xx[idx++] = xa * x[b];
    } else {
      for (std::size_t b = a; b < x.size(); ++b) w.sum_xx[idx++] += xa * x[b];
    }
  }
}

void FaultDetector::start_window(const Vec3& omega) {
  have_start_ = true;
  n_ = 0;
  window_len_ = p_.window_ticks;
  omega_start_ = omega;
  omega_prev_ = omega;
  predicted_.setZero();
  WindowSums& w = win_[static_cast<std::size_t>(acc_)];
  w.motion = 0.0;
  w.force_impulse = 0.0;
  w.thrust_motion = 0.0;
  w.gross_motion = 0.0;
  w.live = 0;
  w.check_jet = -1;
  w.early_suspected = false;
  w.balance = false;
}

void FaultDetector::close_window() {
  // (F10) The closed set is evaluated over the next kEvaluationSteps updates while the other set
  // accumulates the next window. An evaluation still running (a window shorter than the steps:
  // not with window_ticks >= 4) is finished first, and so is the partial-loss step (F18).
  while (eval_phase_ != 0) evaluate_step();
  if (partial_loss_pending_) evaluate_partial_losses();  // (F18), before step 2 rewrites its input
  win_[static_cast<std::size_t>(acc_)].n = n_;
  acc_ ^= 1;
  eval_phase_ = 1;
}

void FaultDetector::evaluate_step() {
  const WindowSums& w = win_[static_cast<std::size_t>(acc_ ^ 1)];
  switch (eval_phase_) {
    case 1:
      evaluate_noise(w);
      evaluate_scores(w, 0, kThrusters);
      eval_phase_ = 2;
      break;
    case 2: {
      evaluate_scores(w, kThrusters, kHypotheses);
      const int was_best = st_.best;
      const bool was_suspecting = suspecting_;
      rank_hypotheses();
      // (F25) A suspicion that starts with a new leader starts a new episode with this window:
      // (F8)'s sums then hold the windows since the fault showed, not hours of healthy flight
      // (in HOLD an idle jet's stuck-off score can stay above zero for the rest of the flight,
      // and the episode used to restart only with every score at zero). A leader that was
      // already leading keeps the evidence it gathered below the suspicion level.
      // (F38) So does a suspicion whose leader's episode sum trails its score by more than
      // margin_llr: its CUSUM restarted after the episode did (the change came later), and the
      // episode holds the healthy windows before it (in HOLD no window is suspicious, so the
      // episode can hold hours, a jet's healthy checks among them).
      const bool stale = p_.episode_restart_stale && st_.best >= 0 &&
                         lambda(static_cast<std::size_t>(st_.best)) < st_.best_llr - p_.margin_llr;
      // (F41) ... and so does a new leader, while suspecting, whose episode sum trails its score
      // by more than margin_llr: the episode began with a window that showed the fault (a
      // suspicion, with another leader) but that this leader's fault did not fill. A jet stuck on
      // one tick before a window closed leaves that window a one-tick ramp, and against it the
      // jet's hypothesis (the whole window's ramp) loses almost its next window's gain: (F8) then
      // reads the leader's lead over every alternative through that one window.
      // Only a leader whose whole score is this window's (its CUSUM was at zero before it): the
      // episode restarted with this window is then exactly the leader's run of evidence.
      const bool fresh_leader =
          st_.best >= 0 &&
          st_.best_llr <= window_llr_[static_cast<std::size_t>(st_.best)] + p_.margin_llr;
      const bool new_stale_leader = p_.episode_restart_leader && suspecting_ && was_suspecting &&
                                    st_.best != was_best && stale && fresh_leader;
      if (p_.episode_restart && suspecting_ &&
          ((!was_suspecting && (st_.best != was_best || stale)) || new_stale_leader)) {
        restart_episode_with_window();
      }
      evaluate_cross(w);
      // (F10) A leader past the confirmation level is checked against every alternative (F8)
      // before the decision, the scan split over this step and the next (the Cortex-M7 tick
      // budget: 6.6 k instructions for the 31 alternatives; the decision that starts an isolation
      // test also re-solves the allocation with a pod closed). Nothing it reads changes before
      // the decision: a model that arrives is held, and a declaration cancels the evaluation.
      block_scan_ = BlockingScan{};
      if (st_.best >= 0 && st_.best_llr > p_.confirm_llr &&
          st_.best_llr - st_.runner_up_llr > p_.margin_llr) {
        block_scan_.h = st_.best;
        blocking_scan(st_.best, 0, kScanSplit, block_scan_);
      }
      eval_phase_ = 3;
      break;
    }
    case 3:
      if (block_scan_.h >= 0) blocking_scan(block_scan_.h, kScanSplit, kHypotheses, block_scan_);
      eval_phase_ = 4;
      break;
    default:
      eval_phase_ = 0;
      // (F18) The partial-loss step follows the decision, on the next update that carries no
      // evaluation step (a declaration in the decision cancels it).
      partial_loss_pending_ = p_.degraded_min_loss > 0.0;
      decide();
      update_check();
      break;
  }
}

double FaultDetector::window_var(const WindowSums& w, double n, bool gross) const {
  // (F5) noise of a residual sample: the gyro (start and sample), the disturbance over the window,
  // and the model's relative uncertainty times the motion it predicts.
  const double rel = std::fmax(p_.model_rel_floor, m_.j_rel_sigma);
  const double j_inv_f = j_inv_.norm();
  const double dist = p_.disturbance_sigma * j_inv_f * n * dt_;
  // (F35) gross: each jet's torque is in error by its own share, whatever their net.
  const double thrust_motion = gross ? w.gross_motion : w.thrust_motion;
  const double motion = w.motion - w.thrust_motion + thrust_motion;
  // (F22) With the floor on the thrust's term only: rel of the thrust's motion, the identifier's
  // own 1 sigma of the gyroscopic term's bound (the rest of the motion).
  const double model = p_.model_floor_gyroscopic
                           ? rel * motion
                           : rel * thrust_motion + m_.j_rel_sigma * (motion - thrust_motion);
  // The centre of mass and the strengths as uncertain as the identifier says: a torque error of
  // r_sigma times the jets' force, and k_sigma times their torque.
  const double offset = r_sigma_ * j_inv_f * w.force_impulse;
  const double strength = m_.k_sigma * thrust_motion;
  const double gyro_var = (p_.centred_gyro_noise ? 1.0 : 2.0) * p_.gyro_sigma * p_.gyro_sigma;
  return gyro_var + dist * dist + model * model + offset * offset + strength * strength + 1e-30;
}

double FaultDetector::early_chi2(const WindowSums& w, double n) const {
  // (F33) The slope test of evaluate_noise on the samples flown so far.
  const double stt = w.sum_tt - w.sum_t * w.sum_t / n;
  if (!(stt > 0.0)) return 0.0;
  const Vec3 str = w.sum_tr - w.sum_t * (w.sum_r / n);
  return str.squaredNorm() / (stt * window_var(w, n));
}

void FaultDetector::evaluate_noise(const WindowSums& w) {
  const double n = static_cast<double>(w.n);
  const double var = window_var(w, n);
  eval_var_ = var;
  if (w.check_jet < 0) quiet_var_ = var;  // (F24) the noise of a window without a check
  st_.noise_sigma = std::sqrt(var);
  // The unknown offset (the start sample's own noise) is removed: mean-centred sums.
  const Vec3 r_mean = w.sum_r / n;
  // Slope test (no fault): least-squares rate of change of the residual, chi-square with 3 dof.
  const double stt = w.sum_tt - w.sum_t * w.sum_t / n;
  const Vec3 str = w.sum_tr - w.sum_t * r_mean;
  const Vec3 slope = stt > 0.0 ? Vec3(str / stt) : Vec3::Zero();
  st_.residual = slope * n;  // rate change over the window that the model does not explain
  st_.chi2 = stt > 0.0 ? slope.squaredNorm() * stt / var : 0.0;
  // (F61) A window flown under a balance test holds the test's firings, which the model predicts
  // with its own error: the test decides them, the bank neither scores nor suspects it.
  eval_balance_ = w.balance;
  if (w.balance) st_.chi2 = 0.0;
  // (F21) A fault that starts inside a window is in it for part of its samples only, whereas every
  // signature (F4) spans the whole window: a jet whose signature matches the truncated ramp (a
  // weaker one of another pod, nearly parallel) can fit it better than the faulty jet and carry
  // that lead into the next windows. So the first window that shows a fault is not scored.
  const bool suspicious = st_.chi2 > p_.suspect_chi2;
  eval_onset_ = p_.skip_onset_window && suspicious && !last_suspicious_ && probe_left_ == 0 &&
                !verdict_pending_ && !sweeping() && w.check_jet < 0;
  last_suspicious_ = suspicious;
  // (F19) A window flown with a jet check: its unexplained rate change must lie along the checked
  // jet's signature b_i (a jet that produced less than commanded: -a b_i f); the part normal to
  // b_i is a model error the check exposed, not the jet.
  eval_unfit_ = false;
  eval_slope_ = slope;  // (F31) what a check about to start must explain
  eval_stt_ = stt;
  if (w.check_jet >= 0) {
    const Vec3& b = b_[static_cast<std::size_t>(w.check_jet)];
    if (check_normal_chi2(b, slope, stt, var) > p_.check_fit_chi2) {
      ++st_.checks_unfit;
      if (p_.check_score_unfit) {
        // (F35) Scored, with the model's error of every jet the check fired.
        eval_var_ = window_var(w, n, true);
      } else {
        eval_unfit_ = true;
      }
    }
  }
  ++st_.windows;
  eval_open_fraction_ =
      probe_tested_pod_ >= 0 ? w.tp[static_cast<std::size_t>(probe_tested_pod_)] / (n * dt_) : 1.0;
  if (sweeping()) {
    // (F17) The window's unexplained angular acceleration (the residual's slope), the gyro's share
    // of its variance, each jet's mean excess thrust and each pod's open fraction.
    const double t_win = n * dt_;
    eval_accel_ = slope / dt_;
    eval_accel_var_ = stt > 0.0 ? p_.gyro_sigma * p_.gyro_sigma / (stt * dt_ * dt_) : 1e300;
    for (int i = 0; i < kThrusters; ++i) {
      const auto k = static_cast<std::size_t>(i);
      eval_excess_[k] = w.c[k] / t_win;
    }
    for (int q = 0; q < kPods; ++q) {
      const auto pq = static_cast<std::size_t>(q);
      eval_open_[pq] = w.tp[pq] / t_win;
    }
  }
}

void FaultDetector::evaluate_scores(const WindowSums& w, int first, int last) {
  // (F6) sequential log-likelihood ratios, CUSUM with exoneration at zero; (F8) the episode's
  // unfloored sums, every window, observable or not (their differences are exact pairwise LLRs).
  const double n = static_cast<double>(w.n);
  const double var = eval_var_;
  const Vec3 r_mean = w.sum_r / n;
  if (eval_unfit_ || eval_onset_ || eval_balance_) {  // (F19) a check that exposed a model error; (F21) an onset; (F61)
    for (int h = first; h < last; ++h) {
      const auto k = static_cast<std::size_t>(h);
      window_llr_[k] = 0.0;
      window_info_[k] = 0.0;
      if (h >= kThrusters) window_energy_[k - static_cast<std::size_t>(kThrusters)] = 0.0;
    }
    return;
  }
  for (int h = first; h < last; ++h) {
    const auto k = static_cast<std::size_t>(h);
    const int thruster = h % kThrusters;
    const bool latched = (((st_.confirmed_on | st_.confirmed_off) >> thruster) & 1u) != 0;
    if (latched) {
      score_[k] = 0.0;
      pool_llr_[k] = 0.0;
      pool_energy_[k] = 0.0;
      window_llr_[k] = 0.0;
      window_info_[k] = 0.0;
      if (h >= kThrusters) window_energy_[k - static_cast<std::size_t>(kThrusters)] = 0.0;
      continue;
    }
    const Vec3& b = b_[k % static_cast<std::size_t>(kThrusters)];
    sig_[k] = b * w.c[k];
    // Mean-centred sums: sum S~ r~ = b.(sum c r) - (b.r_mean) sum c; sum |S~|^2 = |b|^2 (sum c^2 -
    // (sum c)^2 / n).
    const Vec3 sum_cr(w.sum_crx[k], w.sum_cry[k], w.sum_crz[k]);
    const double sr = b.dot(sum_cr) - b.dot(r_mean) * w.sum_c[k];
    const double cc = w.sum_cc[k] - w.sum_c[k] * w.sum_c[k] / n;
    const double ss = b.squaredNorm() * cc;
    const double llr = (sr - 0.5 * ss) / var;
    window_llr_[k] = llr;
    window_info_[k] = cc / var;
    if (hyp_epoch_[k] != episode_epoch_) {  // the hypothesis's first window of the episode
      hyp_epoch_[k] = episode_epoch_;
      lambda_[k] = 0.0;
      info_[k] = 0.0;
    }
    lambda_[k] += llr;
    info_[k] += window_info_[k];
    const double energy = ss / var;
    if (h >= kThrusters) window_energy_[k - static_cast<std::size_t>(kThrusters)] = energy;  // (F18)
    if (energy >= p_.min_signature) {  // observable in this window alone
      score_[k] = std::fmax(0.0, score_[k] + llr);
    } else if (energy > 0.0) {
      // (F11) Too weak alone (a jet commanded at a few percent of u_max): pooled with the
      // hypothesis's other weak windows until the pool is as observable as one strong window.
      pool_llr_[k] += llr;
      pool_energy_[k] += energy;
      if (pool_energy_[k] >= p_.min_signature) {
        score_[k] = std::fmax(0.0, score_[k] + pool_llr_[k]);
        pool_llr_[k] = 0.0;
        pool_energy_[k] = 0.0;
      }
    }
  }
}

void FaultDetector::rank_hypotheses() {
  int best = -1;
  int runner_up = -1;
  double best_s = 0.0;
  double second = 0.0;
  for (int h = 0; h < kHypotheses; ++h) {
    const auto k = static_cast<std::size_t>(h);
    if (score_[k] > best_s) {
      second = best_s;
      runner_up = best;
      best_s = score_[k];
      best = h;
    } else if (score_[k] > second) {
      second = score_[k];
      runner_up = h;
    }
  }
  st_.best = best;
  st_.best_llr = best_s;
  st_.runner_up_llr = second;
  runner_up_ = runner_up;
  st_.suspected_on = 0;
  st_.suspected_off = 0;
  if (best >= 0 && best_s > 0.5 * p_.confirm_llr) {
    const auto bit = static_cast<std::uint16_t>(1u << (best % kThrusters));
    if (best < kThrusters) {
      st_.suspected_on = bit;
    } else {
      st_.suspected_off = bit;
    }
  }
  suspecting_ = best_s > 0.5 * p_.confirm_llr;
}

void FaultDetector::evaluate_cross(const WindowSums& w) {
  // The episode's mean-centred cross sums of the basis ramps, weighted by the window's 1 / var.
  // A ramp that stayed zero (its row not live) adds nothing: its sums are zero.
  if (eval_unfit_ || eval_onset_) return;  // (F19), (F21) not scored
  const double n = static_cast<double>(w.n);
  std::array<double, kBasis> sx{};
  for (int i = 0; i < kThrusters; ++i) {
    sx[static_cast<std::size_t>(i)] = w.sum_c[static_cast<std::size_t>(i + kThrusters)];
  }
  for (int q = 0; q < kPods; ++q) {
    sx[static_cast<std::size_t>(kThrusters + q)] = w.sum_tp[static_cast<std::size_t>(q)];
  }
  const double inv_var = 1.0 / eval_var_;
  std::size_t idx = 0;
  for (std::size_t a = 0; a < sx.size(); ++a) {
    if ((w.live & (1u << a)) == 0) {
      idx += sx.size() - a;
      continue;
    }
    const double sa = sx[a] / n;
    const bool fresh = row_epoch_[a] != episode_epoch_;  // the row's first window of the episode
    row_epoch_[a] = episode_epoch_;
    for (std::size_t b = a; b < sx.size(); ++b, ++idx) {
      const double v = (w.sum_xx[idx] - sa * sx[b]) * inv_var;
      cross_xx_[idx] = fresh ? v : cross_xx_[idx] + v;
    }
  }
}

void FaultDetector::decide() {
  const int best = st_.best;
  const double best_s = st_.best_llr;
  const double second = st_.runner_up_llr;
  const int runner_up = runner_up_;
  if (st_.chi2 > p_.suspect_chi2 && !win_[static_cast<std::size_t>(acc_ ^ 1)].early_suspected) {
    ++st_.suspicions;  // (F33) not again for a window whose suspicion was raised early
    pending_.suspected = true;
  }
  // An isolation test runs its course; the valve reopens after it unless a confirmation closes it.
  // The windows that follow are flown with the valve open again (F9): a stuck-on jet on the tested
  // pod fires whatever is commanded and its signature returns, whereas a stuck-off alternative
  // shows only where its jet is commanded. So no new test starts before probe_after_windows
  // windows have been seen with the valve open.
  if (sweeping() && sweep_step()) return;
  bool probe_ended = false;
  if (probe_left_ > 0 || (verdict_pending_ && eval_open_fraction_ >= 0.5)) {
    // (F16) Every window of the test, and the reopened one that reads it, adds its LLRs.
    for (std::size_t h = 0; h < probe_llr_.size(); ++h) probe_llr_[h] += window_llr_[h];
    for (std::size_t i = 0; i < probe_energy_.size(); ++i) probe_energy_[i] += window_energy_[i];
  }
  if (probe_left_ > 0) {
    // (F15) A window flown with the tested pod closed throughout.
    if (eval_open_fraction_ <= 0.0) {
      ++probe_closed_;
      for (std::size_t h = 0; h < closed_llr_.size(); ++h) closed_llr_[h] += window_llr_[h];
      for (std::size_t i = 0; i < closed_energy_.size(); ++i) {
        closed_energy_[i] += window_energy_[i];
      }
    }
    if (--probe_left_ == 0) {
      st_.probe_pod = -1;
      ambiguous_windows_ = 0;
      probe_ended = true;
      verdict_pending_ = true;
      // (F32) The verdict on the window before the closure and the closed ones; the confirmation
      // closes the valve on this same update, so the tested pod stays closed.
      int h = p_.probe_read_closed ? closed_probe_verdict() : -1;
      if (!verdict_allowed(h)) h = -1;  // (F52) read again on the reopened window
      if (h >= 0) {
        end_probe_verdict();
        declare(h, FaultKind::kStuckOn);
        pending_.confirmed = true;
        pending_.thruster = h;
        pending_.kind = FaultKind::kStuckOn;
        return;
      }
      // (F40) ... or on the stuck-on jet of another pod that the motion behind the closed valve
      // shows; its pod is closed by the confirmation, the tested one reopens.
      int e = p_.probe_read_elsewhere ? closed_verdict_elsewhere() : -1;
      if (!verdict_allowed(e)) e = -1;  // (F52)
      if (e >= 0) {
        end_probe_verdict();
        ++st_.elsewhere_verdicts;
        declare(e, FaultKind::kStuckOn);
        pending_.confirmed = true;
        pending_.thruster = e;
        pending_.kind = FaultKind::kStuckOn;
        return;
      }
      // (F39) The motion went on with the pod closed: the leader is a stuck-on jet of another pod
      // that the closed windows favour. The next test (of the leader's pod) starts now instead of
      // after the reopened window.
      if (p_.probe_chain && closed_leads_elsewhere()) {
        end_probe_verdict();
        probe_ended = false;
      }
    }
  } else if (verdict_pending_ && eval_open_fraction_ >= 0.5) {
    // (F15) The first window flown mostly with the tested pod open again.
    int h = probe_verdict();
    if (!verdict_allowed(h)) h = -1;  // (F52) the bank goes on, and may test again
    end_probe_verdict();
    if (h >= 0) {
      declare(h, FaultKind::kStuckOn);
      pending_.confirmed = true;
      pending_.thruster = h;
      pending_.kind = FaultKind::kStuckOn;
      return;
    }
  }
  if (best < 0) {
    reset_episode();  // every hypothesis exonerated: the next episode starts afresh
    return;
  }
  // (F52) A stuck-on leader past probe_start_llr but not yet past confirm_llr: tested against its
  // runner-up; nothing is confirmed here.
  const bool early_test = best_s <= p_.confirm_llr && p_.probe_start_llr > 0.0 &&
                          best_s > p_.probe_start_llr && best < kThrusters && runner_up >= 0;
  if (best_s <= p_.confirm_llr && !early_test) {
    ambiguous_windows_ = 0;
    st_.ambiguous_with = -1;
    return;
  }
  // (F6) clearly ahead of the runner-up, and (F8) of every alternative beyond the model's error.
  int blocking = runner_up;
  if (!early_test && best_s - second > p_.margin_llr) {
    if (block_scan_.h == best) {  // the scan of steps 2 and 3
      blocking = block_scan_.worst;
    } else {
      blocking = blocking_alternative(best);
    }
  }
  if (blocking < 0 && best >= kThrusters) blocking = partial_loss_alternative(best);
  // (F59) After a fault, no stuck-off on a model not confident again (held as its own partial
  // loss: no isolation test).
  if (blocking < 0 && best >= kThrusters && after_fault_unconfident()) blocking = best;
  if (blocking < 0 && best < kThrusters && p_.episode_restart) blocking = partial_loss_rival(best);
  if (blocking < 0) {
    const int thruster = best % kThrusters;
    const FaultKind kind = best < kThrusters ? FaultKind::kStuckOn : FaultKind::kStuckOff;
    declare(thruster, kind);
    pending_.confirmed = true;
    pending_.thruster = thruster;
    pending_.kind = kind;
    return;
  }
  // (F9) A fault is evident but the leader cannot be told from `blocking`. When one of the two is
  // a stuck-on jet on a pod the other does not use, closing that pod's valve for a few windows
  // separates them: the stuck-on signature stops there and only there.
  st_.ambiguous_with = blocking;
  const int tb = best % kThrusters;
  const int tg = blocking % kThrusters;
  const int pod_b = pod_[static_cast<std::size_t>(tb)];
  const int pod_g = pod_[static_cast<std::size_t>(tg)];
  int pod = -1;
  if (pod_b != pod_g) {
    if (best < kThrusters) {
      pod = pod_b;
    } else if (blocking < kThrusters) {
      pod = pod_g;
    }
  } else if (best < kThrusters && pod_b == probe_llr_pod_) {
    // (F16) The tests of this pod are under way: their sum (T) decides between the pod's jets
    // from the reopened windows, one more each test.
    pod = pod_b;
  }
  // No test starts while the last one's verdict waits for its window flown mostly with the valve
  // open: with short windows (5 ticks) the first window after the reopening was flown mostly
  // closed, a new test started on it, and the verdict was never read (200 tests in 400 s, HOLD).
  if (pod < 0 || p_.probe_windows == 0 || probe_left_ > 0 || probe_ended || verdict_pending_ ||
      sweeping()) {
    return;
  }
  ++ambiguous_windows_;
  if (probe_left_ == 0 && ambiguous_windows_ >= p_.probe_after_windows) {
    st_.probe_pod = pod;
    if (pod != probe_llr_pod_) {  // (F16) a test of another pod starts its own sum
      probe_llr_.fill(0.0);
      probe_energy_.fill(0.0);
      probe_llr_pod_ = pod;
    }
    probe_left_ = p_.probe_windows;
    ++st_.probes;
    restart_window_ = p_.probe_aligned;  // (F27)
    ambiguous_windows_ = 0;
    end_probe_verdict();
    probe_tested_pod_ = pod;
    probe_early_ = early_test;
    trigger_llr_ = window_llr_;  // (F32)
    if (p_.probe_window_ticks > 0) {  // (F47)
      const double ratio =
          static_cast<double>(p_.probe_window_ticks) / static_cast<double>(p_.window_ticks);
      probe_short_ = p_.probe_short_min_llr <= 0.0 ||
                     window_llr_[static_cast<std::size_t>(best)] * ratio * ratio * ratio >=
                         p_.probe_short_min_llr;
      if (!probe_short_ && p_.probe_window_ticks != p_.window_ticks) ++st_.probe_whole_windows;
    }
    trigger_energy_ = window_energy_;
    closed_llr_.fill(0.0);
    closed_energy_.fill(0.0);
    probe_blocker_ = blocking;
  }
}

bool FaultDetector::sweep_step() {
  // (F17) Pod sweep. Before the model is identified the bank's residual carries the model's error
  // (the gyroscopic term with J off by 10 %: 1e-3 rad/s^2, twenty times an axial jet), but that
  // error changes slowly, whereas closing the pod of a stuck-on jet removes its torque at once.
  // So the test reads the step of the unexplained acceleration a (the residual's slope, commanded
  // thrust predicted on the open pods only): with a_ref the window before the closure, a_c the
  // mean of the m windows flown with the pod closed throughout and a_re the reopened window,
  //   D = (a_ref + a_re) / 2 - a_c        (a drift of the model error linear in time cancels),
  // and jet i of the pod predicts s_i = b_i x_i, x_i = (x_ref,i + x_re,i) / 2 its mean excess thrust
  // u_max - f_i. var D = (var_ref + var_re) / 4 + sum var_c / m^2 (the gyro's share of each
  // window's slope) + sd_i^2 + C_r,i: sd_i = sd_cmd (the commanded thrust's model error, below: it
  // changes only with the delivered thrust g_j, whose step is taken as D's) + (rho + k_sigma)|s_i|
  // (rho the relative 1 sigma of J), and C_r,i = x_i^2 J^-1 [e_i]x P_r [e_i]x^T J^-T the centre of
  // mass's share of the jet's torque (a 3x3 covariance C). Each test adds
  //   L_i = D' C^-1 s_i - s_i' C^-1 s_i / 2
  // to its pod's jets' sums (a jet whose pod showed no step loses s' C^-1 s / 2). The leader of
  // the sixteen sums is confirmed stuck on when the test just read is of its pod, its sum exceeds
  // confirm_llr and every other by margin_llr (and every stuck-off alternative's sum, scored on
  // s = -b_j dg_j, the jet's delivered thrust step), and it fits the step,
  // (D - s_i)' C^-1 (D - s_i) < identified_match_chi2. Otherwise the next pod is tested from this
  // window. After the fourth, the pod whose jet leads every other pod's jets by margin_llr is
  // tested again (at most kSweepRepeats times) until its jets are told apart; otherwise the sweep
  // ends (a later identifier window may start another).
  const int q = sweep_pod_;
  if (q < 0) {
    // The window just evaluated is the reference (its valves as they were): start the next test.
    if (sweep_next_ < kPods) {
      sweep_pod_ = sweep_order_[static_cast<std::size_t>(sweep_next_)];
    } else {
      // Every pod tested once: the pod of the leading sum is tested again while that sum is
      // ahead of every other jet's by margin_llr (its step seen, the jet not yet decided), at
      // most kSweepRepeats times; otherwise the sweep ends.
      const SweepLeader leader = sweep_leader();
      const int lead = leader.jet;
      const double l1 = leader.first;
      const bool pod_ahead = lead >= 0 && l1 > 0.0 && sweep_next_ < kPods + kSweepRepeats &&
                             [&] {
                               // ahead of every jet of the other pods by margin_llr
                               const int ql = pod_[static_cast<std::size_t>(lead)];
                               for (int i = 0; i < kThrusters; ++i) {
                                 const auto k = static_cast<std::size_t>(i);
                                 if (pod_[k] == ql) continue;
                                 if (l1 - sweep_llr_[k] <= p_.margin_llr) return false;
                               }
                               return true;
                             }();
      if (!pod_ahead) {
        end_sweep();
        return false;
      }
      sweep_pod_ = pod_[static_cast<std::size_t>(lead)];
    }
    ++sweep_next_;
    sweep_ref_ = eval_accel_;
    sweep_ref_excess_ = eval_excess_;
    for (int i = 0; i < kThrusters; ++i) {
      const auto k = static_cast<std::size_t>(i);
      sweep_ref_force_[k] =
          u_max_ * eval_open_[static_cast<std::size_t>(pod_[k])] - eval_excess_[k];
      sweep_closed_force_[k] = 0.0;
    }
    sweep_ref_var_ = eval_accel_var_;
    sweep_closed_var_ = 0.0;
    sweep_closed_sum_.setZero();
    sweep_closed_ = 0;
    sweep_left_ = p_.probe_windows > 0 ? p_.probe_windows : 1;
    sweep_reading_ = false;
    st_.probe_pod = sweep_pod_;
    restart_window_ = p_.probe_aligned;  // (F27)
    ++st_.probes;
    return false;
  }
  const auto pq = static_cast<std::size_t>(q);
  if (sweep_left_ > 0) {
    if (eval_open_[pq] <= 0.0) {  // flown with the pod closed throughout
      sweep_closed_sum_ += eval_accel_;
      sweep_closed_var_ += eval_accel_var_;
      for (int i = 0; i < kThrusters; ++i) {
        const auto k = static_cast<std::size_t>(i);
        sweep_closed_force_[k] +=
            u_max_ * eval_open_[static_cast<std::size_t>(pod_[k])] - eval_excess_[k];
      }
      ++sweep_closed_;
    }
    if (--sweep_left_ == 0) {
      st_.probe_pod = -1;
      sweep_reading_ = true;
    }
    return false;
  }
  if (!sweep_reading_ || eval_open_[pq] < 0.5) return false;  // wait for the reopened window
  sweep_reading_ = false;
  sweep_pod_ = -1;  // the reopened window is the next test's reference
  if (sweep_closed_ == 0) return false;
  const double m = static_cast<double>(sweep_closed_);
  const Vec3 d = 0.5 * (sweep_ref_ + eval_accel_) - sweep_closed_sum_ / m;
  // var_g: (1/4)(var ref + var re) + (1/m^2) sum var closed.
  const double var_gyro =
      0.25 * (sweep_ref_var_ + eval_accel_var_) + sweep_closed_var_ / (m * m);
  // The commanded thrust's model error changes between the windows only with the delivered thrust
  // (the closure moves the pod's share to the other pods): per jet the delivered mean thrust
  // g = (u_max t_open - c) / T, its step dg taken as D's. An error dr of the centre of mass adds
  // J^-1 (dr x F) with F = sum dg_j e_j the net force step, an error of J^-1 rho |sum b_j dg_j|,
  // the strengths k_sigma |b_j| dg_j each (independent).
  const double rho = std::fmax(p_.model_rel_floor, m_.j_rel_sigma);
  Vec3 net_force = Vec3::Zero();
  Vec3 torque_step = Vec3::Zero();
  double strength_var = 0.0;
  std::array<double, kThrusters> step{};  // each jet's delivered thrust step, as D's
  for (int i = 0; i < kThrusters; ++i) {
    const auto k = static_cast<std::size_t>(i);
    const auto pk = static_cast<std::size_t>(pod_[k]);
    const double g_re = u_max_ * eval_open_[pk] - eval_excess_[k];
    const double dg = 0.5 * (sweep_ref_force_[k] + g_re) - sweep_closed_force_[k] / m;
    step[k] = dg;
    net_force += dg * dir_[k];
    torque_step += dg * b_[k];
    const double sk = m_.k_sigma * b_[k].norm() * dg;
    strength_var += sk * sk;
  }
  const double sd_cmd = r_sigma_ * j_inv_norm_ * net_force.norm() + rho * torque_step.norm() +
                        std::sqrt(strength_var);
  // Stuck-off alternatives: jet j producing nothing leaves D = -b_j dg_j (its delivered thrust
  // step: all of it for a jet of the tested pod, the reallocation's share for the others), scored
  // the same way for every jet whose step is at least 1 N; their sums only block (a stuck-off jet
  // is the bank's to confirm, where it is commanded).
  for (int i = 0; i < kThrusters; ++i) {
    const auto k = static_cast<std::size_t>(i);
    if ((((st_.confirmed_on | st_.confirmed_off) >> i) & 1u) != 0) continue;
    if (std::fabs(step[k]) < 1.0) continue;
    const Vec3 si = -b_[k] * step[k];
    const double sd = sd_cmd + (rho + m_.k_sigma) * si.norm();
    Mat3 ex;
    ex << 0.0, -dir_[k].z(), dir_[k].y(), dir_[k].z(), 0.0, -dir_[k].x(), -dir_[k].y(),
        dir_[k].x(), 0.0;
    const Mat3 jm = j_inv_ * ex * (m_.k(i) * step[k]);
    const Mat3 cov = jm * m_.r_cov * jm.transpose() +
                     Mat3::Identity() * (var_gyro + sd * sd + 1e-30);
    const Eigen::LDLT<Mat3> ldlt(cov);
    const Vec3 ci_s = ldlt.solve(si);
    sweep_llr_off_[k] += d.dot(ci_s) - 0.5 * si.dot(ci_s);
  }
  double off_best = -1e300;
  for (int i = 0; i < kThrusters; ++i) {
    if ((((st_.confirmed_on | st_.confirmed_off) >> i) & 1u) != 0) continue;
    off_best = std::fmax(off_best, sweep_llr_off_[static_cast<std::size_t>(i)]);
  }
  int best_fit_jet = -1;
  double fit_of_best = 1e300;
  for (int i = 0; i < kThrusters; ++i) {
    const auto k = static_cast<std::size_t>(i);
    if (pod_[k] != q) continue;
    if ((((st_.confirmed_on | st_.confirmed_off) >> i) & 1u) != 0) continue;
    const double x = 0.5 * (sweep_ref_excess_[k] + eval_excess_[k]);
    const Vec3 si = b_[k] * x;
    // The jet's own torque as uncertain as the model: J and k relatively (isotropic), and the
    // centre of mass through its covariance, J^-1 k x (dr x e_i): J^-1 [e_i]x P_r [e_i]x^T J^-T x^2
    // (mostly about the axis of least inertia, as every jet's signature is).
    const double sd = sd_cmd + (rho + m_.k_sigma) * si.norm();
    Mat3 ex;
    ex << 0.0, -dir_[k].z(), dir_[k].y(), dir_[k].z(), 0.0, -dir_[k].x(), -dir_[k].y(),
        dir_[k].x(), 0.0;
    const Mat3 jm = j_inv_ * ex * (m_.k(i) * x);
    const Mat3 cov = jm * m_.r_cov * jm.transpose() +
                     Mat3::Identity() * (var_gyro + sd * sd + 1e-30);
    const Eigen::LDLT<Mat3> ldlt(cov);
    const Vec3 ci_s = ldlt.solve(si);
    const Vec3 ci_ds = ldlt.solve(Vec3(d - si));
    const double l = d.dot(ci_s) - 0.5 * si.dot(ci_s);
    sweep_llr_[k] += l;
    const double fit = (d - si).dot(ci_ds);
    if (best_fit_jet < 0 || sweep_llr_[k] > sweep_llr_[static_cast<std::size_t>(best_fit_jet)]) {
      best_fit_jet = i;
      fit_of_best = fit;
    }
  }
  // The sweeps' sums (every test of every pod adds its jets' L): the leader over all sixteen.
  const SweepLeader leader = sweep_leader();
  const int best = leader.jet;
  const double best_l = leader.first;
  const double second = leader.second;
  if (best < 0 || best != best_fit_jet || best_l <= p_.confirm_llr ||
      fit_of_best >= p_.identified_match_chi2 || best_l - second <= p_.margin_llr ||
      best_l - off_best <= p_.margin_llr) {
    return false;  // the next pod is tested from this window
  }
  end_sweep();
  declare(best, FaultKind::kStuckOn);
  ++st_.sweep_confirmations;
  pending_.confirmed = true;
  pending_.thruster = best;
  pending_.kind = FaultKind::kStuckOn;
  return true;
}

FaultDetector::SweepLeader FaultDetector::sweep_leader() const {
  // (F17) The leading and second sums over the jets not yet latched.
  SweepLeader r;
  for (int i = 0; i < kThrusters; ++i) {
    if ((((st_.confirmed_on | st_.confirmed_off) >> i) & 1u) != 0) continue;
    const double l = sweep_llr_[static_cast<std::size_t>(i)];
    if (l > r.first) {
      r.second = r.first;
      r.first = l;
      r.jet = i;
    } else if (l > r.second) {
      r.second = l;
    }
  }
  return r;
}

int FaultDetector::tested_pod_leader(const std::array<double, kHypotheses>& llr,
                                     double& best_llr) const {
  // (F15) The hypothesis a test's summed LLR names: a stuck-on jet of the tested pod, ahead of
  // zero and of every other hypothesis by margin_llr; -1 otherwise.
  int best = -1;
  double second = -1e300;
  best_llr = -1e300;
  for (int h = 0; h < kHypotheses; ++h) {
    const double l = llr[static_cast<std::size_t>(h)];
    if (l > best_llr) {
      second = best_llr;
      best_llr = l;
      best = h;
    } else if (l > second) {
      second = l;
    }
  }
  if (best < 0 || best >= kThrusters || pod_[static_cast<std::size_t>(best)] != probe_tested_pod_) {
    return -1;
  }
  if (best_llr <= p_.margin_llr || best_llr - second <= p_.margin_llr) return -1;
  return best;
}

int FaultDetector::probe_verdict() const {
  // (F15) The unexplained motion followed the tested pod's valve: gone in every window flown with
  // the valve closed (at least one), back in the first window with it open. A stuck-off jet shows
  // only where it is commanded, not where a valve is, so the motion is a stuck-on jet of that pod:
  // the one whose signature explains the reopened window best, ahead of every other hypothesis
  // (any pod, any kind) by margin_llr in that window alone.
  // (F16) "Ahead" is read on the LLR summed over the tests' windows (closed and reopened), not on
  // the reopened window alone: in that window an axial jet and its mirror on the opposite pod
  // (2 r_xy x e_z apart) explain the motion equally, whereas in the closed windows the mirror,
  // behind an open valve, would have fired and did not (LLR -E/2 each).
  // The test's likelihood already says whether the closed windows were quiet and the reopened one
  // not (a stuck-on jet of the tested pod gains only in open windows; every other hypothesis is
  // scored on the closed ones too), so no per-window chi-square bound is asked: a weak jet (a few
  // sigma per window in cases 6-7) is decided over several consecutive tests of its pod. At least
  // one window must have been flown with the pod closed throughout.
  if (probe_closed_ == 0) return -1;
  double best_llr = 0.0;
  const int best = tested_pod_leader(probe_llr_, best_llr);
  if (best < 0) return -1;
  if (p_.probe_partial_rival) {
    // (F29) A jet that lost part of its thrust leaves that part of its stuck-off signature, which
    // no hypothesis of the bank explains at full amplitude: over the test's windows its fitted
    // loss (F13) may explain the motion as well as the tested pod's stuck-on jet (a jet at half
    // strength read as a stuck-on jet of another pod on a one-window test).
    for (int i = 0; i < kThrusters; ++i) {
      if ((((st_.confirmed_on | st_.confirmed_off) >> i) & 1u) != 0) continue;
      const auto k = static_cast<std::size_t>(i);
      const double partial =
          fitted_loss_llr(probe_llr_[k + static_cast<std::size_t>(kThrusters)], probe_energy_[k]);
      if (best_llr - partial <= p_.margin_llr) return -1;
    }
  }
  return best;
}

bool FaultDetector::closed_leads_elsewhere() const {
  // (F39) The bank's leader after the closed windows is a stuck-on jet of another pod, and the
  // closed windows alone favour it: above zero (a jet of another pod fired on while the tested
  // one was closed) and above every stuck-on jet of the tested pod. Under a stuck-on jet of the
  // tested pod the closed windows are quiet: its hypothesis gains nothing there (it predicts no
  // torque behind the closed valve, as no fault does) and every jet of another pod loses E / 2.
  if (probe_closed_ == 0 || probe_tested_pod_ < 0) return false;
  const int h = st_.best;
  if (h < 0 || h >= kThrusters || pod_[static_cast<std::size_t>(h)] == probe_tested_pod_) {
    return false;
  }
  const double lh = closed_llr_[static_cast<std::size_t>(h)];
  if (!(lh > 0.0)) return false;
  for (int g = 0; g < kThrusters; ++g) {
    if (pod_[static_cast<std::size_t>(g)] != probe_tested_pod_) continue;
    if ((((st_.confirmed_on | st_.confirmed_off) >> g) & 1u) != 0) continue;
    if (closed_llr_[static_cast<std::size_t>(g)] >= lh) return false;
  }
  return true;
}

int FaultDetector::closed_probe_verdict() const {
  // (F32) Read when the test's closed windows end. The window that started the test showed the
  // motion (the leader, a stuck-on jet of the tested pod, ahead of everything beyond its own pod
  // only within the model's error); in every window flown with the pod closed throughout it was
  // gone. A stuck-on jet of another pod, behind its open valve, would have gone on firing there
  // (LLR -E/2 per quiet window); a stuck-off jet shows only where it is commanded. So the sum over
  // the start window and the closed ones is read as (F15) reads its own, with two conditions of
  // its own: the alternative that blocked the leader is contradicted by the closed windows (it is
  // on another pod, or no closure could have told them apart), and so is every alternative the
  // start window alone cannot tell from the leader by margin_llr. Anything else waits for the
  // reopened window (F15).
  if (probe_closed_ == 0 || probe_tested_pod_ < 0) return -1;
  std::array<double, kHypotheses> sum{};
  for (std::size_t k = 0; k < sum.size(); ++k) sum[k] = trigger_llr_[k] + closed_llr_[k];
  double best_llr = 0.0;
  const int best = tested_pod_leader(sum, best_llr);
  if (best < 0) return -1;
  const auto contradicted = [this](int g) {
    return closed_llr_[static_cast<std::size_t>(g)] < -p_.margin_llr;
  };
  if (probe_blocker_ < 0 || !contradicted(probe_blocker_)) return -1;
  const double lead_start = trigger_llr_[static_cast<std::size_t>(best)];
  for (int g = 0; g < kHypotheses; ++g) {
    if (g == best) continue;
    const int tg = g % kThrusters;
    if ((((st_.confirmed_on | st_.confirmed_off) >> tg) & 1u) != 0) continue;
    if (g < kThrusters && pod_[static_cast<std::size_t>(tg)] == probe_tested_pod_) continue;
    const double lead = lead_start - trigger_llr_[static_cast<std::size_t>(g)];
    if (lead <= p_.margin_llr && !contradicted(g)) return -1;
  }
  if (!beats_closed_partial_losses(best_llr)) return -1;  // (F29) over the same windows
  return best;
}

bool FaultDetector::beats_closed_partial_losses(double llr) const {
  // (F29) A verdict read on the start window and the closed ones beats, over the same windows,
  // every unlatched jet's fitted partial loss (F13) by margin_llr.
  if (!p_.probe_partial_rival) return true;
  for (int i = 0; i < kThrusters; ++i) {
    if ((((st_.confirmed_on | st_.confirmed_off) >> i) & 1u) != 0) continue;
    const auto k = static_cast<std::size_t>(i);
    const auto ko = k + static_cast<std::size_t>(kThrusters);
    const double partial = fitted_loss_llr(trigger_llr_[ko] + closed_llr_[ko],
                                           trigger_energy_[k] + closed_energy_[k]);
    if (llr - partial <= p_.margin_llr) return false;
  }
  return true;
}

int FaultDetector::closed_verdict_elsewhere() const {
  // (F40) Read when the test's closed windows end and (F32) named no jet of the tested pod. The
  // motion went on behind the closed valve: every hypothesis of the tested pod predicts nothing
  // there (a stuck-on jet behind a closed valve has no signature, F4, and its stuck-off or partial
  // loss is not commanded), so the closed windows' LLR of a stuck-on jet h of another pod, which
  // fires through its open valve whatever is commanded, is its lead over all of them. The start
  // window could not tell h from the tested pod's jet (the mirror pair of F8: an axial jet and the
  // opposite pod's, 2 r_xy x e_z apart); the closed windows can, on the physics, not on the model's
  // fine print. h is named when
  //   - over the start window and the closed ones it leads every hypothesis by margin_llr;
  //   - on the closed windows alone it leads every hypothesis of the tested pod by margin_llr;
  //   - every other alternative (another open pod, any kind) is told from h by the start window
  //     alone (its lead there above margin_llr) or contradicted by the closed windows (their LLR
  //     below -margin_llr), as (F32) asks of the tested pod's jet;
  //   - with (F29), it beats every jet's fitted partial loss over the same windows.
  // The closed windows compare h with another open pod's jet on the model, so a pair the start
  // window could not separate is not separated here either.
  if (probe_closed_ == 0 || probe_tested_pod_ < 0) return -1;
  std::array<double, kHypotheses> sum{};
  for (std::size_t k = 0; k < sum.size(); ++k) sum[k] = trigger_llr_[k] + closed_llr_[k];
  int h = -1;
  double best_llr = -1e300;
  double second = -1e300;
  for (int g = 0; g < kHypotheses; ++g) {
    if ((((st_.confirmed_on | st_.confirmed_off) >> (g % kThrusters)) & 1u) != 0) continue;
    const double l = sum[static_cast<std::size_t>(g)];
    if (l > best_llr) {
      second = best_llr;
      best_llr = l;
      h = g;
    } else if (l > second) {
      second = l;
    }
  }
  if (h < 0 || h >= kThrusters || pod_[static_cast<std::size_t>(h)] == probe_tested_pod_) return -1;
  if (best_llr <= p_.margin_llr || best_llr - second <= p_.margin_llr) return -1;
  const double closed_h = closed_llr_[static_cast<std::size_t>(h)];
  const double start_h = trigger_llr_[static_cast<std::size_t>(h)];
  for (int g = 0; g < kHypotheses; ++g) {
    if (g == h) continue;
    const int tg = g % kThrusters;
    if ((((st_.confirmed_on | st_.confirmed_off) >> tg) & 1u) != 0) continue;
    const auto kg = static_cast<std::size_t>(g);
    if (pod_[static_cast<std::size_t>(tg)] == probe_tested_pod_) {
      if (closed_h - closed_llr_[kg] <= p_.margin_llr) return -1;
    } else if (start_h - trigger_llr_[kg] <= p_.margin_llr && closed_llr_[kg] >= -p_.margin_llr) {
      return -1;
    }
  }
  if (!beats_closed_partial_losses(best_llr)) return -1;  // (F29) over the same windows
  return h;
}

double FaultDetector::cross(int h, int g) const {
  // c_h = alpha_h x_{16+pod} + x_i, alpha = u_max for stuck-on and 0 for stuck-off (F4).
  const auto at = [this](int a, int b) {
    const int row = a <= b ? a : b;
    if (row_epoch_[static_cast<std::size_t>(row)] != episode_epoch_) return 0.0;  // stale
    return cross_xx_[static_cast<std::size_t>(a <= b ? basis_index(a, b) : basis_index(b, a))];
  };
  const int ih = h % kThrusters;
  const int ig = g % kThrusters;
  const int ph = kThrusters + pod_[static_cast<std::size_t>(ih)];
  const int pg = kThrusters + pod_[static_cast<std::size_t>(ig)];
  const double ah = h < kThrusters ? u_max_ : 0.0;
  const double ag = g < kThrusters ? u_max_ : 0.0;
  return ah * ag * at(ph, pg) + ah * at(ph, ig) + ag * at(ih, pg) + at(ih, ig);
}

double FaultDetector::partial_loss_energy(int g) const {
  const auto k = static_cast<std::size_t>(g);
  return b_[k % static_cast<std::size_t>(kThrusters)].squaredNorm() * info(k);
}

double FaultDetector::total_loss_floor(int i) const {
  // (F23) A jet that produces nothing leaves the residual of its whole signature b_i c, known to
  // the model's relative error eps_i only (strength, inertia, centre of mass): the fitted loss of
  // a dead jet scatters below 1 by up to model_sigmas eps_i, and under a long firing (HOLD's
  // steady command, E in the 1e5s) even a few percent gains far more than margin_llr over the
  // total loss. A fitted loss at or above this floor is a total loss. The gap is capped at
  // kMaxTotalLossGap, so that a half-strength jet (the dispersions' degraded 0.5) stays a partial
  // loss whatever the model's error.
  const double gap = std::fmin(p_.model_sigmas * signature_rel_error(i), kMaxTotalLossGap);
  return 1.0 - std::fmax(gap, 0.0);
}

bool FaultDetector::partial_not_total(int i, double sr, double e) const {
  // (F13, F18, F23) The episode's or segment's sums SR, E of thruster i's partial-loss fit say a
  // partial loss, not a total one, when the fitted loss a = SR / E lies below the total-loss
  // floor and the fit gains more than margin_llr over a loss at the floor:
  // (a SR - a^2 E / 2) - (f SR - f^2 E / 2) = E (f - a)^2 / 2.
  if (!(e > 0.0)) return false;
  const double a = sr / e;
  const double floor = total_loss_floor(i);
  return a < floor && 0.5 * e * (floor - a) * (floor - a) > p_.margin_llr;
}

bool FaultDetector::after_fault_unconfident() const {
  return p_.after_fault_max_j_rel > 0.0 &&
         (st_.confirmed_on | st_.confirmed_off | st_.confirmed_degraded) != 0 &&
         !(m_.j_rel_sigma <= p_.after_fault_max_j_rel);
}

bool FaultDetector::below_total_loss(int i, double sr, double e) const {
  // (F58) The fitted loss a = SR / E has the fit's own 1 sigma 1 / sqrt(E) (E is the information
  // of a); a loss more than total_loss_sigmas of that below the floor is not a dead jet's.
  if (!(p_.total_loss_sigmas > 0.0) || !(e > 0.0)) return false;
  return sr / e < total_loss_floor(i) - p_.total_loss_sigmas / std::sqrt(e);
}

double FaultDetector::partial_loss_llr(int g) const {
  // (F13) The episode's LLR of "thruster g lost a fraction a of its thrust", a in (0, 1] fitted:
  // with SR = sum S~.r~ / var = Lambda + E / 2 and E = sum |S~|^2 / var = |b|^2 A, the maximum
  // over a of a SR - a^2 E / 2 is SR^2 / (2 E) for SR < E, and Lambda (a = 1) beyond.
  return fitted_loss_llr(lambda(static_cast<std::size_t>(g)), partial_loss_energy(g));
}

int FaultDetector::partial_loss_alternative(int h) const {
  // (F13) A stuck-off leader must beat, by margin_llr, a partial loss of thrust of every other
  // jet (a degraded jet explains its residual exactly with its own a < 1, and only that much of
  // a smaller, nearly parallel signature of another jet), and its own amplitude must be that of
  // a jet that produces nothing: its fitted a may not gain margin_llr over a loss at the (F23)
  // total-loss floor (1 when model_sigmas is 0), nor lie (F58) total_loss_sigmas of its own
  // 1 sigma below that floor.
  const double lh = lambda(static_cast<std::size_t>(h));
  const double eh = partial_loss_energy(h);
  if (partial_not_total(h % kThrusters, lh + 0.5 * eh, eh)) return h;
  if (below_total_loss(h % kThrusters, lh + 0.5 * eh, eh)) return h;
  return partial_loss_rival(h);
}

int FaultDetector::partial_loss_rival(int h) const {
  // (F13) The jet other than h's whose partial loss of thrust h does not beat by margin_llr, or
  // -1. (F25) A stuck-on leader must pass it too: a jet at half strength leaves half its stuck-off
  // signature, which no hypothesis of the bank explains at full amplitude, and a stuck-on jet
  // whose signature is nearly anti-parallel (another pod, a similar ramp under the despin's
  // steady firing) can lead the bank; over the episode since the fault showed, the partial loss
  // explains it exactly (the former, hours-long episode held the stuck-on leader by accident).
  const double lh = lambda(static_cast<std::size_t>(h));
  for (int g = kThrusters; g < kHypotheses; ++g) {
    if (g == h) continue;
    if ((((st_.confirmed_on | st_.confirmed_off) >> (g - kThrusters)) & 1u) != 0) continue;
    if (lh - partial_loss_llr(g) <= p_.margin_llr) return g;
  }
  return -1;
}

void FaultDetector::evaluate_partial_losses() {
  // (F18) After a window's decision, on the next update free of evaluation steps (F10), or at the
  // next window's close: each jet's partial-loss CUSUM at the design loss
  // a_c = 2 x degraded_min_loss (any loss above degraded_min_loss drifts it up, a healthy jet
  // down), from the window's stuck-off LLR and energy (step 2):
  //   sum S~.r~ / var = llr + E / 2,   C_g <- max(0, C_g + a_c SR_w - a_c^2 E_w / 2),
  // and the sums of the segment since C_g was last zero. A partial loss past half the
  // confirmation level is suspected (F7: the model is held and the identifier does not fit it).
  partial_loss_pending_ = false;
  const double ac = std::fmin(1.0, 2.0 * p_.degraded_min_loss);
  const std::uint16_t latched = static_cast<std::uint16_t>(st_.confirmed_on | st_.confirmed_off);
  deg_suspecting_ = false;
  for (int i = 0; i < kThrusters; ++i) {
    const auto g = static_cast<std::size_t>(i);
    if (((latched >> i) & 1u) != 0) {
      deg_cusum_[g] = 0.0;
      deg_sr_[g] = 0.0;
      deg_e_[g] = 0.0;
      continue;
    }
    const double ev = window_energy_[g];
    const double srv = window_llr_[g + static_cast<std::size_t>(kThrusters)] + 0.5 * ev;
    deg_cusum_[g] += ac * srv - 0.5 * ac * ac * ev;
    if (deg_cusum_[g] <= 0.0) {
      deg_cusum_[g] = 0.0;
      deg_sr_[g] = 0.0;
      deg_e_[g] = 0.0;
      continue;
    }
    deg_sr_[g] += srv;
    deg_e_[g] += ev;
    if (degraded_llr(i) > 0.5 * p_.confirm_llr) deg_suspecting_ = true;
  }
  if (!deg_suspecting_ || probe_left_ > 0 || verdict_pending_ || sweeping()) return;
  if (after_fault_unconfident()) return;  // (F59)
  double loss = 0.0;
  const int g = degraded_candidate(loss);
  if (g < 0) return;
  // The fitted loss's 1 sigma is 1 / sqrt(E_g) (the LLR is quadratic in it with curvature E_g),
  // in units of the factor it multiplies.
  const double before = factor_[static_cast<std::size_t>(g)];
  const double factor = before * (1.0 - loss);
  const double sigma = before / std::sqrt(deg_e_[static_cast<std::size_t>(g)]);
  declare(g, FaultKind::kDegraded, factor);
  ++st_.degraded_confirmations;
  pending_.confirmed = true;
  pending_.thruster = g;
  pending_.kind = FaultKind::kDegraded;
  pending_.factor = factor;
  pending_.factor_sigma = sigma;
}

void FaultDetector::update_check() {
  // (F19) Jet check. A stuck-off or partly failed jet shows only through what it is commanded,
  // and the despin asks most jets for a few newtons (F11): their evidence grows over hundreds of
  // seconds. Once a jet's stuck-off score or partial-loss CUSUM (F18) reaches check_llr, the
  // flight fires it at check_force_n for check_windows windows in the null space of the channels'
  // torques (the Gnc; the detector's model with F42, check_move): no torque on the model. Its
  // stuck-off signature then has the energy of a firm firing:
  // a healthy jet loses about half of it from each hypothesis (exonerated within a window), a
  // failed one gains it (confirmed by F6 / F13 / F18 as before). Nothing here decides anything.
  const bool suspicious = st_.chi2 > p_.suspect_chi2;  // the window just evaluated
  update_survey();
  if (check_left_ > 0) {
    if (--check_left_ == 0) end_check();
    return;
  }
  if (balance_.active()) return;  // (F61) no check during a balance test
  if (!(p_.check_llr > 0.0) || pending_.confirmed || probe_left_ > 0 || verdict_pending_ ||
      sweeping() || after_fault_unconfident()) {  // (F59) no check whose verdict would wait
    return;
  }
  // (F34) A check is for evidence that builds up over many windows of weak firing; a window above
  // the no-fault bound is an evident fault, which the bank and the isolation test decide. A jet
  // stuck on makes its channel partner's stuck-off score jump in that window (the same direction),
  // and a check of the partner then fires against the stuck jet. A check starts on a quiet window.
  if (p_.check_quiet_start && suspicious) return;
  // A stuck-on leader is the isolation test's (F9): no jet check meanwhile.
  if (st_.best >= 0 && st_.best < kThrusters && st_.best_llr > 0.5 * p_.confirm_llr) return;
  const std::uint16_t latched = static_cast<std::uint16_t>(st_.confirmed_on | st_.confirmed_off);
  const double window_s = static_cast<double>(p_.window_ticks) * dt_;
  const auto interval =
      static_cast<std::uint32_t>(std::ceil(p_.check_interval_s / window_s));
  int jet = -1;
  double evidence = p_.check_llr;
  // (F49) Long checks: the evidence scan gates on the model's error only; the chosen jet's force
  // is then sized (one null-space move a decision).
  const bool long_checks = long_mode();
  const auto gated = [&](int g) {
    return signature_rel_error(g) <= p_.check_max_model_error &&
           (long_checks || !(p_.check_min_llr > 0.0) || expected_check_llr(g) >= p_.check_min_llr);
  };
  if (p_.check_blocker && st_.best >= kThrusters && st_.best_llr > p_.confirm_llr &&
      st_.ambiguous_with >= kThrusters) {
    // (F37) The stuck-off jet that blocks a stuck-off leader is checked, evidence or not.
    const int g = st_.ambiguous_with - kThrusters;
    const auto k = static_cast<std::size_t>(g);
    if (((latched >> g) & 1u) == 0 &&
        (last_check_[k] == 0 ||
         st_.windows + 1 - last_check_[k] >= (interval << check_backoff_[k])) &&
        gated(g)) {
      jet = g;
      evidence = 1e300;  // no evidence outranks it
    }
  }
  for (int i = 0; i < kThrusters; ++i) {
    if (((latched >> i) & 1u) != 0) continue;
    const auto k = static_cast<std::size_t>(i);
    // A jet checked before waits the interval, doubled for each earlier check of it (at most 4x):
    // a healthy jet whose evidence builds up again under unmodelled firing is not fired every
    // interval; a jet checked and confirmed is latched and out of the scan.
    if (last_check_[k] != 0 && st_.windows + 1 - last_check_[k] < (interval << check_backoff_[k])) {
      continue;
    }
    const double e = std::fmax(score_[k + static_cast<std::size_t>(kThrusters)], deg_cusum_[k]);
    if (e < evidence) continue;
    // (F31) After a suspicious window, only a jet whose signature the window's unexplained motion
    // lies along (the fit of a check window, F19): motion normal to it is another fault's, which
    // a check of this jet would only keep the bank from scoring.
    if (p_.check_fit_on_suspicion && suspicious &&
        check_normal_chi2(b_[k], eval_slope_, eval_stt_, eval_var_) > p_.check_fit_chi2) {
      continue;
    }
    if (gated(i)) {
      evidence = e;
      jet = i;
    }
  }
  int windows = p_.check_windows;
  double force = p_.check_force_n;
  bool capped = false;
  // (F56) After a confirmed fault, an evidence check within the kick bound of a survey's only.
  const bool kick_gated = p_.check_kick_after_fault && p_.survey_max_kick_rad_s > 0.0 &&
                          (latched | st_.confirmed_degraded) != 0;
  if (jet >= 0 && !long_checks && kick_gated) {
    double kick_rate = 0.0;
    const double e = expected_check_energy(jet, &kick_rate);
    if (!(e > 0.0) || 3.0 * kick_rate * static_cast<double>(windows) * window_s >
                          p_.survey_max_kick_rad_s) {
      ++st_.evidence_kick_refusals;
      last_check_[static_cast<std::size_t>(jet)] = st_.windows + 1;  // due one interval from now
      jet = -1;
    }
  }
  if (jet >= 0 && long_checks) {
    force = long_check_force(jet, p_.check_long_evidence_energy, kick_gated, &capped);
    if (!(force > 0.0)) {
      if (kick_gated) ++st_.evidence_kick_refusals;
      capped = false;
      // No long check of it within the gates: due again one interval from now (not a check).
      last_check_[static_cast<std::size_t>(jet)] = st_.windows + 1;
      jet = -1;
    }
  }
  if (jet < 0) {
    jet = survey_candidate(windows);
    if (jet < 0) return;
    if (long_checks) force = candidate_force_;
    ++st_.surveys;
    const auto ks = static_cast<std::size_t>(jet);
    survey_e_[ks] = 0.0;  // its survey clock restarts with the check (verified or not)
    survey_from_[ks] = st_.windows;
    st_.unverified = static_cast<std::uint16_t>(st_.unverified & ~(1u << jet));
  }
  st_.check_jet = jet;
  check_left_ = windows;
  check_force_ = force;
  if (long_checks) {
    // (F49) One window of check_long_ticks samples, from the next one on: the window under way
    // is dropped, as an aligned test's (F27).
    check_left_ = 1;
    check_long_n_ = p_.check_long_ticks;
    long_start_ = true;
    restart_window_ = true;
    ++st_.long_checks;
    if (capped) ++st_.long_checks_capped;
  }
  const auto kj = static_cast<std::size_t>(jet);
  if (last_check_[kj] != 0 && check_backoff_[kj] < 2) ++check_backoff_[kj];
  last_check_[kj] = st_.windows + 1;
  ++st_.checks;
}

double FaultDetector::signature_rel_error(int i) const {
  // (F18, F19) The model's relative 1 sigma of thruster i's signature b_i = J^-1 k_i (p_i + r) x e_i:
  // strength, inertia, and the centre of mass against the jet's arm.
  const auto k = static_cast<std::size_t>(i);
  const double arm = (pos_[k] + m_.r).cross(dir_[k]).norm();
  const double kk = std::fabs(m_.k(i));
  return (kk > 0.0 ? m_.k_sigma / kk : 1.0) + m_.j_rel_sigma + (arm > 0.0 ? r_sigma_ / arm : 1.0);
}

void FaultDetector::update_survey() {
  // (F36) The stuck-off energy E of each jet's last window (F6: a total loss of the jet would
  // have added E / 2 to its score on average) summed since the jet was last verified. A jet whose
  // sum reaches survey_energy is verified: had it failed, the bank would have seen it. A jet the
  // window commanded (E > 0) and that is not verified yet is marked unverified.
  if (!(p_.survey_interval_s > 0.0)) return;
  const std::uint16_t latched = static_cast<std::uint16_t>(st_.confirmed_on | st_.confirmed_off);
  for (int i = 0; i < kThrusters; ++i) {
    const auto k = static_cast<std::size_t>(i);
    const auto bit = static_cast<std::uint16_t>(1u << i);
    if ((latched & bit) != 0) {
      survey_e_[k] = 0.0;
      survey_from_[k] = st_.windows;
      st_.unverified = static_cast<std::uint16_t>(st_.unverified & ~bit);
      continue;
    }
    const double e = window_energy_[k];
    if (!(e > 0.0)) continue;
    survey_e_[k] += e;
    // (F57) ... and whose partial-loss evidence is not between survey_loss_llr and check_llr (past
    // check_llr the evidence checks, F19, answer it).
    const bool loss_evidence = survey_loss_evidence(k);
    if (survey_e_[k] >= p_.survey_energy && !loss_evidence) {
      survey_e_[k] = 0.0;
      survey_from_[k] = st_.windows;
      st_.unverified = static_cast<std::uint16_t>(st_.unverified & ~bit);
    } else {
      st_.unverified = static_cast<std::uint16_t>(st_.unverified | bit);
    }
  }
}

bool FaultDetector::survey_loss_evidence(std::size_t k) const {
  // (F57) Partial-loss evidence that no evidence check answers yet.
  return p_.survey_loss_llr > 0.0 && deg_cusum_[k] >= p_.survey_loss_llr &&
         deg_cusum_[k] < p_.check_llr;
}

int FaultDetector::survey_candidate(int& windows) {
  // (F36) Of the jets unverified for survey_interval_s, the one unverified longest (the first such
  // on a tie), its check sized so that its expected energy reaches survey_energy. Only that jet is
  // rated against the check gates (F19 model error, F24 expected LLR), one jet per decision (the
  // rating is a null-space move of B; rating every due jet on each decision took the decision's
  // tick over the Cortex-M7 budget): a jet that fails them is rated again check_interval_s later,
  // so the next decision rates the next jet.
  if (!(p_.survey_interval_s > 0.0) || st_.unverified == 0 || !survey_allowed_) return -1;
  const double window_s = static_cast<double>(p_.window_ticks) * dt_;
  const auto interval = static_cast<std::uint32_t>(std::ceil(p_.survey_interval_s / window_s));
  // (F57) A jet unverified for its partial-loss evidence is due after check_interval_s, at most
  // once per survey interval (a healthy jet whose model is a few percent off keeps some evidence,
  // and a survey every check interval would build it up).
  const auto loss_interval = std::min(
      interval, static_cast<std::uint32_t>(std::ceil(p_.check_interval_s / window_s)));
  int jet = -1;
  std::uint32_t oldest = 0;
  for (int i = 0; i < kThrusters; ++i) {
    if (((st_.unverified >> i) & 1u) == 0) continue;
    const auto k = static_cast<std::size_t>(i);
    const std::uint32_t age = st_.windows - survey_from_[k];
    const bool loss = survey_loss_evidence(k) &&
                      (loss_survey_at_[k] == 0 || st_.windows + 1 - loss_survey_at_[k] >= interval);
    if (age < (loss ? loss_interval : interval) || (jet >= 0 && age <= oldest)) continue;
    jet = i;
    oldest = age;
  }
  if (jet < 0) return -1;
  const auto kj = static_cast<std::size_t>(jet);
  const bool loss_due = st_.windows - survey_from_[kj] < interval;  // (F57) due to its evidence only
  ++st_.survey_ratings;
  // (F57) A survey due to partial-loss evidence C is sized to resolve it: at the CUSUM's design
  // loss a_c a healthy jet's C drifts down by a_c^2 E / 2, so the energy E = 2 C / a_c^2 takes it
  // back to zero, and a jet at half strength gains (a_c / 2 - a_c^2 / 2) E = 4 C at a_c 0.2
  // (past check_llr from C >= check_llr / 5: its evidence checks follow). Where the check's gates
  // do not allow that energy, it is sized as any survey.
  const double ac = std::fmin(1.0, 2.0 * p_.degraded_min_loss);
  const double loss_energy =
      loss_due && ac > 0.0 ? 2.0 * deg_cusum_[kj] / (ac * ac) : 0.0;
  if (long_mode()) {
    // (F49) A long check, where (F48) would refuse: its force sized to check_long_energy.
    const bool fit = signature_rel_error(jet) <= p_.check_max_model_error;
    candidate_force_ = fit && loss_energy > p_.check_long_energy
                           ? long_check_force(jet, loss_energy, true)
                           : 0.0;
    if (!(candidate_force_ > 0.0) && fit) {
      candidate_force_ = long_check_force(jet, p_.check_long_energy, true);
    }
    if (candidate_force_ > 0.0) {
      windows = 1;
      if (loss_due) loss_survey_at_[kj] = st_.windows + 1;  // (F57) the survey starts now
      return jet;
    }
    ++st_.survey_kick_refusals;
    const auto retry = std::min(
        interval, static_cast<std::uint32_t>(std::ceil(p_.check_interval_s / window_s)));
    survey_from_[kj] = st_.windows - (interval - retry);
    return -1;
  }
  const bool noisy = survey_noisy_;  // (F48)
  if (noisy) ++st_.survey_noise_refusals;
  double kick_rate = 0.0;
  const double e = signature_rel_error(jet) > p_.check_max_model_error
                       ? 0.0
                       : expected_check_energy(jet, &kick_rate);
  const int lo = p_.check_windows;
  const int hi = std::max(lo, p_.survey_max_windows);
  const double need = e > 0.0 ? std::ceil(p_.survey_energy / e) : 0.0;
  int n = need >= static_cast<double>(hi) ? hi : std::max(lo, static_cast<int>(need));
  if (loss_energy > p_.survey_energy && e > 0.0) {
    // (F57) ... in up to survey_max_windows windows, and no more than the kick bound allows.
    int m = static_cast<int>(std::fmin(std::ceil(loss_energy / e), static_cast<double>(hi)));
    if (p_.survey_max_kick_rad_s > 0.0 && kick_rate > 0.0) {
      m = std::min(m, static_cast<int>(p_.survey_max_kick_rad_s / (3.0 * kick_rate * window_s)));
    }
    n = std::max(n, m);
  }
  // (F44) 3 sigma of the rate the check may put on the body, over its n windows.
  const bool kicks = p_.survey_max_kick_rad_s > 0.0 &&
                     3.0 * kick_rate * static_cast<double>(n) * window_s > p_.survey_max_kick_rad_s;
  if (kicks) ++st_.survey_kick_refusals;
  if (!(e > 0.0) || kicks || noisy ||
      (p_.check_min_llr > 0.0 && 0.5 * e * static_cast<double>(n) < p_.check_min_llr)) {
    // Not checkable now: due again one check interval from now.
    const auto retry = std::min(
        interval, static_cast<std::uint32_t>(std::ceil(p_.check_interval_s / window_s)));
    survey_from_[kj] = st_.windows - (interval - retry);
    return -1;
  }
  windows = n;
  if (loss_due) loss_survey_at_[kj] = st_.windows + 1;  // (F57) the survey starts now
  return jet;
}

bool FaultDetector::check_move(int c, Vec8& du) const {
  Mat38 b = Mat38::Zero();
  for (int q = 0; q < kChannels; ++q) {
    const auto kq = static_cast<std::size_t>(2 * q);
    b.col(q) = (pos_[kq] + m_.r).cross(dir_[kq]);
  }
  return jet_check_move(b, c, du, held_channels());
}

std::uint8_t FaultDetector::held_channels() const {
  const auto latched = static_cast<unsigned>(st_.confirmed_on | st_.confirmed_off);
  std::uint8_t held = 0;
  for (int q = 0; q < kChannels; ++q) {
    const bool open = valve_open_[static_cast<std::size_t>(pod_[static_cast<std::size_t>(2 * q)])];
    if (!open || ((latched >> (2 * q)) & 3u) != 0) held = static_cast<std::uint8_t>(held | (1u << q));
  }
  return held;
}

double FaultDetector::expected_check_llr(int i) const {
  return 0.5 * expected_check_energy(i) * static_cast<double>(p_.check_windows);
}

double FaultDetector::expected_check_energy(int i, double* kick_rate) const {
  // (F24) A check fires thruster i at f = check_force_n, compensated in the null space of the
  // channels' torque matrix B (Gnc::apply_jet_check: du = e_c - B^T (B B^T)^-1 B e_c, scaled to
  // move channel c by f), so every channel fires: the check's force is f_tot = f sum |du| / |du_c|.
  // Under "i stuck off" the residual ramps as b_i f t over each window of n samples, whose
  // mean-centred energy is |b_i f dt|^2 n (n^2 - 1) / 12 / var (F6: a healthy jet's check loses
  // half of it from that hypothesis), with var the window's (F5) noise: that of the last window
  // flown without a check, plus the centre of mass against the check's force,
  // (r_sigma ||J^-1|| f_tot T)^2. (The check adds nothing to the thrust term: B du = 0.)
  const auto k = static_cast<std::size_t>(i);
  const int c = i / 2;
  Vec8 du;
  if (!check_move(c, du)) return 0.0;  // channel c has no null-space move: no check
  const double sum = du.cwiseAbs().sum();
  const double own = du(c);
  const double n = static_cast<double>(p_.window_ticks);
  const double f = p_.check_force_n;
  const double offset = r_sigma_ * j_inv_.norm() * f * (sum / own) * n * dt_;
  if (kick_rate != nullptr) *kick_rate = (f / own) * move_kick_rate(du);
  const double var = quiet_var_ + offset * offset + 1e-30;
  const double step = b_[k].norm() * f * dt_;
  return step * step * n * (n * n - 1.0) / 12.0 / var;
}

double FaultDetector::move_kick_rate(const Vec8& du) const {
  // (F44) The torque the model's error leaves of the move, per unit of du: the centre of mass's
  // covariance against the net force F (tau = dr x F: S(F) R S(F)^T) and each fired jet's
  // strength 1 sigma against its torque (independent); through J^-1, the rate's covariance
  // per second of the check, and its root-mean-square magnitude, per unit of du.
  Vec3 force = Vec3::Zero();
  Mat3 torque_cov = Mat3::Zero();
  for (int q = 0; q < kChannels; ++q) {
    const auto kq = static_cast<std::size_t>(2 * q);
    force += du(q) * dir_[kq];
    const Vec3 tq = (m_.k_sigma * du(q)) * (pos_[kq] + m_.r).cross(dir_[kq]);
    torque_cov += tq * tq.transpose();
  }
  Mat3 sf;
  sf << 0.0, -force.z(), force.y(), force.z(), 0.0, -force.x(), -force.y(), force.x(), 0.0;
  torque_cov += sf * m_.r_cov * sf.transpose();
  const Mat3 rate_cov = j_inv_ * torque_cov * j_inv_.transpose();
  return std::sqrt(std::fmax(rate_cov.trace(), 0.0));
}

double FaultDetector::loss_rel_error(int i) const {
  // (F51) A loss a of thruster i is fitted along its signature b_i = J^-1 k_i (p_i + r) x e_i: a
  // model error db biases it by db . b_i / |b_i|^2. Strength: k_sigma / |k_i|; inertia:
  // j_rel_sigma (|J^-1 dJ| bounds it, as in signature_rel_error). The centre of mass: the jet
  // alone errs by J^-1 k_i (dr x e_i), whose share along b_i is dr . (k_i e_i x J^-T b_i) / |b_i|^2;
  // its check (F19) fires the move du, of net force F = sum du_q e_q per unit of du_c, whose error
  // J^-1 (dr x F) / du_c along b_i is dr . (F x J^-T b_i) / (du_c |b_i|^2). Each 1 sigma is
  // sqrt(v^T R_r v); the larger of the two.
  const auto k = static_cast<std::size_t>(i);
  const double bb = b_[k].squaredNorm();
  const double kk = std::fabs(m_.k(i));
  if (!(bb > 0.0) || !(kk > 0.0)) return 1.0;
  const Vec3 jb = j_inv_.transpose() * b_[k];
  const Vec3 alone = (m_.k(i) / bb) * dir_[k].cross(jb);
  double r_var = alone.dot(m_.r_cov * alone);
  Vec8 du;
  const int c = i / 2;
  if (check_move(c, du) && du(c) > 0.0) {
    Vec3 force = Vec3::Zero();
    for (int q = 0; q < kChannels; ++q) force += du(q) * dir_[static_cast<std::size_t>(2 * q)];
    const Vec3 move = force.cross(jb) / (du(c) * bb);
    r_var = std::fmax(r_var, move.dot(m_.r_cov * move));
  }
  return m_.k_sigma / kk + m_.j_rel_sigma + std::sqrt(std::fmax(r_var, 0.0));
}

double FaultDetector::long_check_force(int i, double energy, bool kick_gates,
                                       bool* capped) const {
  // (F49) One window of N samples through which "i stuck off" ramps the residual by b_i f dt a
  // sample has the energy s^2 f^2 g / (q + a^2 f^2): s = |b_i| dt, g = N (N^2 - 1) / 12 (F24's
  // ramp), q the noise of a quiet window of N samples (the gyro's share as is, the rest of the
  // last quiet window's grown with the window's length, as F5's terms grow) and a f the centre
  // of mass's 1 sigma against the check's force over the window (F24). The least f with the
  // energy asked, 0 when none reaches it, or when that f exceeds check_force_n, or (kick_gates) a
  // dead jet's kick (b_i f N dt) or 3 sigma of the model's (F44) exceeds survey_max_kick_rad_s.
  const auto k = static_cast<std::size_t>(i);
  const int c = i / 2;
  Vec8 du;
  if (!check_move(c, du)) return 0.0;
  const double own = du(c);
  if (!(own > 0.0)) return 0.0;
  const double nn = static_cast<double>(p_.check_long_ticks);
  const double nw = static_cast<double>(p_.window_ticks);
  const double t = nn * dt_;
  const double gyro_var = (p_.centred_gyro_noise ? 1.0 : 2.0) * p_.gyro_sigma * p_.gyro_sigma;
  const double grow = nn / nw;
  const double q = gyro_var + std::fmax(0.0, quiet_var_ - gyro_var) * grow * grow + 1e-30;
  const double a = r_sigma_ * j_inv_.norm() * (du.cwiseAbs().sum() / own) * t;
  const double s = b_[k].norm() * dt_;
  const double g = nn * (nn * nn - 1.0) / 12.0;
  // (F50) The energy no force exceeds is s^2 g / a^2. An energy beyond check_long_reach of it is
  // flown at that fraction, at a force within the kick bounds of a survey check (F44): the check
  // then answers evidence with less than its energy, and is flown again; when that energy is
  // below check_long_energy it is not flown.
  if (capped != nullptr && p_.check_long_reach > 0.0 && a > 0.0 &&
      energy > p_.check_long_reach * s * s * g / (a * a)) {
    const double et = p_.check_long_reach * s * s * g / (a * a);
    double f = std::sqrt(et * q / (s * s * g - et * a * a));
    if (p_.survey_max_kick_rad_s > 0.0) {
      f = std::fmin(f, p_.survey_max_kick_rad_s / (b_[k].norm() * t));
      const double model_kick = 3.0 * move_kick_rate(du) / own * t;
      if (model_kick > 0.0) f = std::fmin(f, p_.survey_max_kick_rad_s / model_kick);
    }
    if (!(f <= p_.check_force_n)) return 0.0;
    if (!(s * s * f * f * g / (q + a * a * f * f) >= p_.check_long_energy)) return 0.0;
    *capped = true;
    return f;
  }
  const double et = energy;
  const double den = s * s * g - et * a * a;
  if (!(den > 0.0)) return 0.0;
  const double f = std::sqrt(et * q / den);
  if (!(f <= p_.check_force_n)) return 0.0;
  if (kick_gates && p_.survey_max_kick_rad_s > 0.0) {
    if (b_[k].norm() * f * t > p_.survey_max_kick_rad_s) return 0.0;
    if (3.0 * (f / own) * move_kick_rate(du) * t > p_.survey_max_kick_rad_s) return 0.0;
  }
  return f;
}

double FaultDetector::degraded_llr(int g) const {
  // (F18) The segment's LLR of "thruster g lost a fraction a of its thrust", a in (0, 1] fitted:
  // max_a (a SR - a^2 E / 2) = SR^2 / (2 E) for SR < E, SR - E / 2 (a = 1) beyond.
  const auto k = static_cast<std::size_t>(g);
  const double sr = deg_sr_[k];
  const double e = deg_e_[k];
  if (sr <= 0.0 || e <= 0.0) return 0.0;
  return sr >= e ? sr - 0.5 * e : sr * sr / (2.0 * e);
}

int FaultDetector::degraded_candidate(double& loss) const {
  // (F18) Each jet's partial-loss CUSUM (scored in step 2 at the design loss 2 x
  // degraded_min_loss, so that any loss above degraded_min_loss drifts it up and a healthy jet
  // drifts it down) keeps the sums SR_g, E_g of the windows since it was last zero. On them the
  // jet's fitted loss is a = SR_g / E_g and its LLR Gamma_g = SR_g^2 / (2 E_g). The leading g is
  // confirmed degraded when
  //   Gamma_g > confirm_llr,
  //   a >= degraded_min_loss + model_sigmas eps_g, with eps_g the model's relative error of g's
  //     signature (strength, inertia, and the centre of mass against g's arm): a model error
  //     alone does not make a loss,
  //   Gamma_g - (SR_g - E_g / 2) > margin_llr: a partial loss, not a total one (a = 1, the
  //     stuck-off that (F6)/(F13) decide),
  //   Gamma_g leads every other jet's Gamma and every stuck-on / stuck-off score by margin_llr,
  //   the runner-up h's fit is further from the data than the model's error can turn the two
  //   signatures: arccos sqrt(Gamma_h / Gamma_g) > model_sigmas (eps_g + eps_h). Twin jets
  //   (opposite pods, the same direction) have nearly parallel signatures, and a model a few
  //   percent off orders them either way; a check (F19) of either, which fires it alone, moves
  //   them apart. (model_sigmas = 0 takes the model as exact, as in F8.)
  const std::uint16_t latched = static_cast<std::uint16_t>(st_.confirmed_on | st_.confirmed_off);
  int g = -1;
  int runner = -1;
  double gamma_g = 0.0;
  double second = 0.0;
  for (int i = 0; i < kThrusters; ++i) {
    if (((latched >> i) & 1u) != 0) continue;
    const double gi = degraded_llr(i);
    if (gi > gamma_g) {
      second = gamma_g;
      runner = g;
      gamma_g = gi;
      g = i;
    } else if (gi > second) {
      second = gi;
      runner = i;
    }
  }
  if (g < 0 || gamma_g <= p_.confirm_llr || gamma_g - second <= p_.margin_llr) return -1;
  const auto kg = static_cast<std::size_t>(g);
  const double a = deg_sr_[kg] / deg_e_[kg];
  const double eps = signature_rel_error(g);
  const double loss_eps = p_.degraded_loss_projection ? loss_rel_error(g) : eps;  // (F51)
  if (a >= 1.0 || a < p_.degraded_min_loss + p_.model_sigmas * loss_eps) return -1;
  // Twin jets: the runner-up explains the data to cos^2 theta = Gamma_h / Gamma_g of what g
  // does. Each signature's direction is known to its relative error, so the model's error can
  // turn either one by up to model_sigmas eps: g is decided only when theta exceeds both turns.
  if (runner >= 0 && second > 0.0 && p_.model_sigmas > 0.0) {
    const double turn = p_.model_sigmas * (eps + signature_rel_error(runner));
    if (turn >= 1.5707963267948966 || std::sqrt(second / gamma_g) >= std::cos(turn)) return -1;
  }
  if (!partial_not_total(g, deg_sr_[kg], deg_e_[kg])) return -1;
  for (int h = 0; h < kHypotheses; ++h) {
    if (gamma_g - score_[static_cast<std::size_t>(h)] <= p_.margin_llr) return -1;
  }
  loss = a;
  return g;
}

void FaultDetector::blocking_scan(int h, int g_begin, int g_end, BlockingScan& scan) const {
  // (F8) Under h, the model's error d of h's signature b_i (constant over the episode) gives the
  // pairwise LLR Lambda_h - Lambda_g the bias V . d with V = b_h A_h - b_g C_hg. Its variance,
  // from the identifier's: strength (d = b dk / k), centre of mass (d = J^-1 k dr x e_i) and
  // inertia (d = -J^-1 dJ b, |V . d| <= |J^-1 V| ||dJ|| |b|).
  const auto kh = static_cast<std::size_t>(h);
  const auto ih = kh % static_cast<std::size_t>(kThrusters);
  const Vec3& bh = b_[ih];
  const double kk = m_.k(static_cast<int>(ih));
  const double rel_k = kk != 0.0 ? m_.k_sigma / std::fabs(kk) : 0.0;
  const double dj = m_.j_rel_sigma * m_.j.norm() * bh.norm();
  for (int g = g_begin; g < g_end; ++g) {
    if (g == h) continue;
    const auto kg = static_cast<std::size_t>(g);
    const int tg = g % kThrusters;
    if ((((st_.confirmed_on | st_.confirmed_off) >> tg) & 1u) != 0) continue;
    const Vec3& bg = b_[kg % static_cast<std::size_t>(kThrusters)];
    const double c = cross(h, g);
    const Vec3 v = bh * info(kh) - bg * c;
    const Vec3 w = j_inv_.transpose() * v;
    const Vec3 wxe = kk * w.cross(dir_[ih]);
    const double vk = rel_k * v.dot(bh);
    const double vj = dj * w.norm();
    const double sd = std::sqrt(vk * vk + wxe.dot(m_.r_cov * wxe) + vj * vj);
    const double lead = lambda(kh) - lambda(kg) - p_.model_sigmas * sd;
    if (lead <= p_.margin_llr && (scan.worst < 0 || lead < scan.worst_lead)) {
      scan.worst = g;
      scan.worst_lead = lead;
    }
  }
}

int FaultDetector::blocking_alternative(int h) const {
  BlockingScan scan;
  blocking_scan(h, 0, kHypotheses, scan);
  return scan.worst;
}

}  // namespace rocksteady::gnc

namespace rocksteady::gnc {

void FaultDetector::balance_update(const FaultDetectorInput& in, const Vec3& thrust_rate,
                                   const Vec3& gyro) {
  // (F61a) The other jets' motion, as the model predicts it: the channel's own halves are the
  // test's regressors, whatever the model says of them.
  const int c = balance_.channel();
  const auto kp = static_cast<std::size_t>(2 * c);
  const auto km = kp + 1;
  if (!in.valve_open[static_cast<std::size_t>(pod_[kp])] ||
      (((st_.confirmed_on | st_.confirmed_off | st_.confirmed_degraded) >> (2 * c)) & 3u) != 0) {
    balance_.abort();
    ++st_.balance_aborted;
    st_.balance_channel = -1;
    return;
  }
  const double fp = in.thrust(static_cast<Eigen::Index>(kp));
  const double fm = in.thrust(static_cast<Eigen::Index>(km));
  const Vec3 other_thrust = (thrust_rate - b_[kp] * fp - b_[km] * fm) * dt_;
  balance_.sample(in.omega, other_thrust - gyro * dt_, other_thrust, fp, fm);
  if (balance_.dropped_on_motion()) {
    // (F61d) The body moved beyond the test: the window restarts on the next sample and is scored
    // (the motion began before it, as F45's onset window).
    ++st_.balance_aborted;
    st_.balance_channel = -1;
    restart_window_ = true;
    last_suspicious_ = true;
  }
}

void FaultDetector::balance_verdict(const BalanceVerdict& v) {
  st_.balance_channel = balance_.channel();
  if (v.outcome == BalanceOutcome::kNone) return;
  st_.balance_chi2 = v.chi2;
  st_.balance_ratio = v.ratio;
  if (v.outcome == BalanceOutcome::kInconclusive && balance_.info(v.channel).done) {
    ++st_.balance_inconclusive;
  }
  if (v.outcome != BalanceOutcome::kFault) return;
  const auto bit = 1u << v.thruster;
  if (((st_.confirmed_on | st_.confirmed_off | st_.confirmed_degraded) & bit) != 0) return;
  declare(v.thruster, v.kind, v.factor);
  ++st_.balance_confirmations;
  if (v.kind == FaultKind::kDegraded) ++st_.degraded_confirmations;
  pending_.confirmed = true;
  pending_.thruster = v.thruster;
  pending_.kind = v.kind;
  pending_.factor = v.kind == FaultKind::kDegraded ? v.factor : 0.0;
  pending_.factor_sigma = v.kind == FaultKind::kDegraded ? v.factor_sigma : 0.0;
}

void FaultDetector::balance_start(const FaultDetectorInput& in) {
  // (F61) In HOLD (the GNC's balance_allowed), with nothing else under way: no isolation test,
  // sweep, check or confirmation. A channel is usable with both halves unlatched and its pod open.
  // A stuck-on leader is the isolation test's (F9), as for a check; a stuck-off or partial-loss
  // suspicion that the bank cannot decide (a model that absorbed the fault) is the balance test's.
  const bool stuck_on_leader =
      st_.best >= 0 && st_.best < kThrusters && st_.best_llr > 0.5 * p_.confirm_llr;
  // Nor after a window above the no-fault bound (the bank's evidence first; F61d sets it when a
  // test is dropped on the body's motion), and only once the bank has scored a window flown
  // without a test since the last one: between two tests it sees the body under control.
  const WindowSums& closed = win_[static_cast<std::size_t>(acc_ ^ 1)];
  if (!balance_.enabled() || !in.balance_allowed || stuck_on_leader || last_suspicious_ ||
      closed.balance || win_[static_cast<std::size_t>(acc_)].balance ||
      probe_left_ > 0 ||
      verdict_pending_ || sweeping() || st_.check_jet >= 0 || check_left_ > 0 ||
      st_.probe_pod >= 0 || pending_.confirmed || eval_phase_ != 0) {
    return;
  }
  const std::uint16_t latched =
      static_cast<std::uint16_t>(st_.confirmed_on | st_.confirmed_off | st_.confirmed_degraded);
  std::uint8_t usable = 0;
  std::array<double, kChannels> b_plus{};
  for (int c = 0; c < kChannels; ++c) {
    const auto k = static_cast<std::size_t>(2 * c);
    b_plus[static_cast<std::size_t>(c)] = b_norm_[k];
    if (((latched >> (2 * c)) & 3u) == 0 && in.valve_open[static_cast<std::size_t>(pod_[k])]) {
      usable = static_cast<std::uint8_t>(usable | (1u << c));
    }
  }
  const double rel = std::fmax(p_.model_rel_floor, m_.j_rel_sigma);
  // (F61c) Not on a busy flight: the motion of the last window closed, on the model.
  const WindowSums& last = win_[static_cast<std::size_t>(acc_ ^ 1)];
  const double rate = last.n > 0 ? last.thrust_motion / (static_cast<double>(last.n) * dt_) : 1e300;
  if (!balance_.quiet_enough(rate)) return;
  if (balance_.start(balance_clock_s_, usable, in.omega, b_plus, j_inv_.norm(), rel)) {
    ++st_.balance_tests;
    st_.balance_channel = balance_.channel();
  }
}

}  // namespace rocksteady::gnc
