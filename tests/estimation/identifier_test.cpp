// Mass-property identification against an independent truth (tests/common rigid body driven by
// sixteen thrusters with strength factors, tests/estimation/identification_truth.hpp).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "estimation_truth.hpp"
#include "gnc/estimation/identifier.hpp"
#include "gnc/model/mass_properties.hpp"
#include "gnc/model/rcs.hpp"
#include "identification_truth.hpp"

namespace rocksteady::gnc {
namespace {

using test::TruthRun;
using test::TruthSetup;

constexpr double kDt = 0.1;

Mat3 study_j() {
  return total_inertia(study_true_mass_properties());
}

// Truth strengths 1 + delta with sum(delta) = 0 (the common scale is anchored, §I.4).
Vec16 spread_strengths() {
  Vec16 k;
  for (int i = 0; i < kThrusters; ++i)
    k(i) = 1.0 + 0.04 * ((i % 2 == 0) ? 1.0 : -1.0) * ((i / 2) % 3 == 0 ? 1.0 : 0.5);
  k.array() -= k.mean() - 1.0;
  return k;
}

IdentifierConfig config_with_priors(const Mat3& j0, const Vec3& r0) {
  IdentifierConfig c;
  c.dt = kDt;
  c.window_s = 20.0;
  c.rcs = study_rcs_layout(200.0);
  c.j0 = j0;
  c.r0 = r0;
  return c;
}

// Channel forces: each channel a seeded piecewise-constant level in [-u, u], a new level every
// `hold` seconds (rich excitation).
struct RandomFiring {
  explicit RandomFiring(unsigned long long seed, double u = 200.0, double hold = 7.0)
      : rng(seed), u_max(u), hold_s(hold) {}
  test::V8 operator()(double t, const test::V3&) {
    if (t >= next - 1e-9) {
      for (int c = 0; c < 8; ++c) level(c) = u_max * uni(rng);
      next += hold_s;
    }
    return level;
  }
  std::mt19937_64 rng;
  std::uniform_real_distribution<double> uni{-1.0, 1.0};
  double u_max, hold_s, next{0.0};
  test::V8 level{test::V8::Zero()};
};

IdentifierInput id_input(const test::V3& omega, const test::V8& force) {
  IdentifierInput in;
  in.omega = omega;
  in.omega_valid = true;
  in.force = force;
  return in;
}

double j_error(const Identifier& id, const Mat3& j) {
  return (id.estimate().j - j).norm() / j.norm();
}
double k_error(const Identifier& id, const Vec16& k) {
  return (id.estimate().k - k).cwiseAbs().maxCoeff();
}

TEST(IdentifierConfig, DefaultsAreValidAndTheFirstBadFieldIsNamed) {
  IdentifierConfig ok = config_with_priors(study_j(), Vec3::Zero());
  EXPECT_TRUE(validate(ok).ok);
  struct Case {
    void (*mutate)(IdentifierConfig&);
    const char* field;
  };
  const Case cases[] = {
      {[](IdentifierConfig& c) { c.dt = -0.1; }, "dt"},
      {[](IdentifierConfig& c) { c.window_s = 2.05; }, "window_s"},
      {[](IdentifierConfig& c) { c.window_s = 0.3; }, "window_s"},
      {[](IdentifierConfig& c) { c.rcs.channel_direction[3] = Vec3(0, 0, 2); },
       "rcs.channel_direction"},
      {[](IdentifierConfig& c) { c.rcs.channel_pod[1] = 7; }, "rcs.channel_pod"},
      {[](IdentifierConfig& c) { c.j0(0, 0) = -1.0; }, "j0"},
      {[](IdentifierConfig& c) { c.j0(0, 1) += 1e6; }, "j0"},
      {[](IdentifierConfig& c) { c.r0.x() = NAN; }, "r0"},
      {[](IdentifierConfig& c) { c.k_prior_sigma = 0.0; }, "k_prior_sigma"},
      {[](IdentifierConfig& c) { c.torque_floor = 0.0; }, "torque_floor"},
      {[](IdentifierConfig& c) { c.j_forget_s = 5.0; }, "j_forget_s"},
      {[](IdentifierConfig& c) { c.min_inertia_information = -1.0; }, "min_inertia_information"},
      {[](IdentifierConfig& c) { c.min_offset_information = NAN; }, "min_offset_information"},
      {[](IdentifierConfig& c) { c.guard_halvings = -1; }, "guard_halvings"},
      {[](IdentifierConfig& c) { c.guard_halvings = 11; }, "guard_halvings"},
      {[](IdentifierConfig& c) { c.k_max = 0.0; }, "k_min"},
      {[](IdentifierConfig& c) { c.unobservable_ratio = 1.0; }, "unobservable_ratio"},
      {[](IdentifierConfig& c) { c.r_confident = 0.0; }, "r_confident"},
      {[](IdentifierConfig& c) { c.early_window_s = 12.05; }, "early_window_s"},
      {[](IdentifierConfig& c) { c.early_window_s = 30.0; }, "early_window_s"},
      {[](IdentifierConfig& c) { c.early_span_s = -1.0; }, "early_span_s"},
  };
  for (const Case& cs : cases) {
    IdentifierConfig c = ok;
    cs.mutate(c);
    const IdentifierConfigCheck r = validate(c);
    EXPECT_FALSE(r.ok) << cs.field;
    EXPECT_EQ(std::string(r.field), cs.field);
    EXPECT_GT(std::string(r.reason).size(), 0u);
  }
}

TEST(Identifier, InertiaParametersAndRegressorAgree) {
  const Mat3 j = study_j();
  const Vec3 v(0.3, -1.2, 2.0);
  EXPECT_LT((inertia_matrix(inertia_params(j)) - j).norm(), 1e-9 * j.norm());
  EXPECT_LT((inertia_regressor(v) * inertia_params(j) - j * v).norm(), 1e-9 * (j * v).norm());
}

TEST(Identifier, ThrusterGeometryMatchesTheTorqueMatrix) {
  // sum over the + thrusters of (p + r) x e equals B (SPEC §4) column by column.
  const RcsLayout l = study_rcs_layout(200.0);
  const Vec3 r(0.1, -0.2, 3.5);
  const Mat38 b = torque_matrix(l, r);
  for (int c = 0; c < kChannels; ++c) {
    const Vec3 plus = (thruster_position(l, 2 * c) + r).cross(thruster_direction(l, 2 * c));
    const Vec3 minus =
        (thruster_position(l, 2 * c + 1) + r).cross(thruster_direction(l, 2 * c + 1));
    EXPECT_LT((plus - b.col(c)).norm(), 1e-12);
    EXPECT_LT((minus + b.col(c)).norm(), 1e-12);
  }
}

TEST(Identifier, RecoversInertiaOffsetAndStrengthsToTheNoiseFloor) {
  // Noise-free synthetic trajectory from the study's initial rate, known J, r, k; priors off by
  // the case-4 errors (||dJ|| = 1e7 kg m^2, ||dr|| = 1 m).
  TruthSetup s;
  s.j = study_j();
  s.r = study_true_mass_properties().r_so_bcm;
  s.k = spread_strengths();
  const Mat3 dj = 1e7 * Vec3(-1.0, 1.0, 0.5).asDiagonal();
  const Vec3 dr = Vec3(1, 1, 1).normalized();
  Identifier id;
  IdentifierConfig c = config_with_priors(s.j - dj, s.r - dr);
  ASSERT_TRUE(validate(c).ok);
  id.configure(c);
  EXPECT_GT(j_error(id, s.j), 0.2);
  TruthRun truth(s);
  RandomFiring fire(5);
  truth.run(static_cast<int>(3000.0 / kDt), fire,
            [&](double, const test::V3& w, const test::V8& f) { id.update(id_input(w, f)); });
  const double ej = j_error(id, s.j), er = (id.estimate().r - s.r).norm(), ek = k_error(id, s.k);
  std::printf("noise-free 3000 s: |dJ|/|J| %.3g, |dr| %.3g m, max|dk| %.3g\n", ej, er, ek);
  // Without noise what is left is the window quadrature (trapezoid, O(dt^2)) and the
  // information not yet gathered on the strengths; the common scale is anchored (mean k = 1).
  EXPECT_LT(ej, 2e-4);
  EXPECT_LT(er, 2e-3);
  EXPECT_LT(ek, 4e-3);
  EXPECT_EQ(id.counters().inertia_refused, 0u);
  EXPECT_EQ(id.observability().offset_unobservable, 0);
  EXPECT_FALSE(id.observability().inertia_scale_unobservable);
  EXPECT_TRUE(id.observability().thrust_scale_anchored);
}

// (I15) The thrust scale is held by a perfect pseudo-measurement: after every step the mean strength
// of the reference thrusters is the mean of k0 and its variance c'Pc is zero (to rounding), however
// the anchor is spread over blocks (its P c is summed over two, the Cortex-M7 budget). Checked on
// the tick each step's report comes out, over a 1500 s flight with a strength spread.
TEST(Identifier, TheThrustScaleAnchorHoldsTheMeanStrengthExactlyAfterEveryStep) {
  TruthSetup s;
  s.j = study_j();
  s.r = study_true_mass_properties().r_so_bcm;
  s.k = spread_strengths();
  Identifier id;
  IdentifierConfig c = config_with_priors(s.j, s.r);
  id.configure(c);
  TruthRun truth(s);
  RandomFiring fire(3);
  const double k0_mean = c.k0.mean();
  std::uint32_t steps_seen = id.counters().windows;
  int checked = 0;
  double worst_mean = 0.0, worst_var = 0.0;
  truth.run(static_cast<int>(1500.0 / kDt), fire,
            [&](double, const test::V3& w, const test::V8& f) {
              id.update(id_input(w, f));
              if (id.counters().windows == steps_seen || id.stepping()) return;
              steps_seen = id.counters().windows;  // this window's step has just finished
              ++checked;
              worst_mean = std::fmax(worst_mean, std::fabs(id.estimate().k.mean() - k0_mean));
              const MatId& p = id.joint_covariance();
              const double cpc =
                  p.block<kThrusters, kThrusters>(kIdK, kIdK).sum() / (kThrusters * kThrusters);
              const double vk = c.k_prior_sigma * c.k_prior_sigma;
              worst_var = std::fmax(worst_var, std::fabs(cpc) / vk);
            });
  std::printf("%d steps: |mean k - mean k0| at most %.3g, c'Pc at most %.3g of the prior\n", checked,
              worst_mean, worst_var);
  EXPECT_GT(checked, 50);
  EXPECT_LT(worst_mean, 1e-12);
  EXPECT_LT(worst_var, 1e-10);
}

// The joint step is spread over ticks in row blocks (the Cortex-M7 budget), and the executive may
// withhold ticks from it (the fault detector's window close). Neither changes a number: with every
// third tick withheld the estimates and covariances after each window's step are bit for bit those
// of the run that never withholds, the step always finishes inside its window, and the
// covariances stay exactly symmetric.
TEST(Identifier, WithheldTicksDelayTheStepButChangeNoNumber) {
  TruthSetup s;
  s.j = study_j();
  s.r = study_true_mass_properties().r_so_bcm;
  s.k = spread_strengths();
  const Mat3 dj = 1e7 * Vec3(-1.0, 1.0, 0.5).asDiagonal();
  const IdentifierConfig c = config_with_priors(s.j - dj, s.r - Vec3(0.5, 0.5, 0.5));
  ASSERT_TRUE(validate(c).ok);
  Identifier every, withheld;
  every.configure(c);
  withheld.configure(c);
  TruthRun truth(s);
  RandomFiring fire(9);
  const int n = static_cast<int>(std::lround(c.window_s / kDt));
  int tick = 0, compared = 0, asymmetric = 0;
  truth.run(static_cast<int>(600.0 / kDt), fire, [&](double, const test::V3& w, const test::V8& f) {
    every.update(id_input(w, f));
    withheld.update(id_input(w, f), tick % 3 != 0);
    ++tick;
    // Just before the next window closes both have finished the previous window's step.
    if (tick % n == n - 1 && every.counters().windows > 0) {
      ++compared;
      EXPECT_EQ(every.counters().windows, withheld.counters().windows);
      EXPECT_TRUE(every.estimate().j == withheld.estimate().j) << tick;
      EXPECT_TRUE(every.estimate().r == withheld.estimate().r) << tick;
      EXPECT_TRUE(every.estimate().k == withheld.estimate().k) << tick;
      EXPECT_TRUE(every.inertia_covariance() == withheld.inertia_covariance()) << tick;
      EXPECT_TRUE(every.offset_covariance() == withheld.offset_covariance()) << tick;
      EXPECT_TRUE(every.strength_covariance() == withheld.strength_covariance()) << tick;
      const Mat16& pk = every.strength_covariance();
      if (!(pk == pk.transpose()) ||
          !(every.inertia_covariance() == every.inertia_covariance().transpose())) {
        ++asymmetric;
      }
    }
  });
  EXPECT_GE(compared, 25);
  EXPECT_EQ(asymmetric, 0);
  EXPECT_GT(every.counters().inertia_updates, 20u);
  EXPECT_LT(j_error(every, s.j), 1e-3);  // and the spread step still identifies
}

TEST(Identifier, WithNoiseTheErrorsAreConsistentWithTheReportedSigma) {
  TruthSetup s;
  s.j = study_j();
  s.r = study_true_mass_properties().r_so_bcm;
  s.k = spread_strengths();
  s.disturbance_sigma = 1.0 / std::sqrt(3.0);
  s.gyro_sigma = std::sqrt(1e-10 / kDt);  // case 7 gyro noise
  s.seed = 9;
  IdentifierConfig c = config_with_priors(s.j - 1e7 * Mat3(Vec3(-1, 1, 0.5).asDiagonal()),
                                          s.r - Vec3(1, 1, 1).normalized());
  c.gyro_sigma = s.gyro_sigma;
  Identifier id;
  id.configure(c);
  TruthRun truth(s);
  RandomFiring fire(6);
  truth.run(static_cast<int>(1200.0 / kDt), fire,
            [&](double, const test::V3& w, const test::V8& f) { id.update(id_input(w, f)); });
  const IdentifierEstimate& e = id.estimate();
  const Vec6 dj = inertia_params(e.j) - inertia_params(s.j);
  const Vec3 dr = e.r - s.r;
  std::printf("noisy 1200 s: |dJ|/|J| %.3g, |dr| %.3g m, max|dk| %.3g\n", j_error(id, s.j),
              dr.norm(), k_error(id, s.k));
  double nees_j = dj.dot(id.inertia_covariance().ldlt().solve(dj));
  double nees_r = dr.dot(id.offset_covariance().ldlt().solve(dr));
  std::printf("normalised errors: J %.3g (6 dof), r %.3g (3 dof)\n", nees_j, nees_r);
  EXPECT_LT(j_error(id, s.j), 0.01);
  // Consistency (loose, one run): below the chi-square 0.999 quantile.
  EXPECT_LT(nees_j, test::chi2_quantile(6, 3.09));
  EXPECT_LT(nees_r, test::chi2_quantile(3, 3.09));
}

// (I17) A constant gyro bias, drawn per run (norm up to 5e-5 rad/s, the identification dispersion's
// range), with case-7 gyro noise and the 1 N m disturbance, from case-4 priors. Over 24 seeded runs
// the normalised estimation error squared with the full reported covariance, summed over the runs,
// lies inside the two-sided 95 % chi-square band of 24 x dof for J (6), r (3) and b (3). The
// identifier that takes the rate as unbiased (gyro_bias_sigma = 0) fails the same test.
struct BiasedRunNees {
  double j{0.0}, r{0.0}, b{0.0}, j_rel_max{0.0};
};
BiasedRunNees biased_run_nees(double bias_sigma, bool estimated, int runs) {
  BiasedRunNees out;
  std::mt19937_64 rng(2024);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  for (int run = 0; run < runs; ++run) {
    TruthSetup s;
    s.j = study_j();
    s.r = study_true_mass_properties().r_so_bcm;
    s.k = spread_strengths();
    s.disturbance_sigma = 1.0 / std::sqrt(3.0);
    s.gyro_sigma = std::sqrt(1e-10 / kDt);  // case 7
    s.seed = 100 + static_cast<unsigned long long>(run);
    s.disturbance_phase_s = kDt * std::floor(1.0 + 98.0 * uni(rng));  // random hold phase
    const Vec3 dir = Vec3(normal(rng), normal(rng), normal(rng)).normalized();
    s.gyro_bias = 5e-5 * uni(rng) * dir;
    s.omega0 = 0.04 * Vec3(normal(rng), normal(rng), normal(rng)).normalized();
    IdentifierConfig c = config_with_priors(s.j - 1e7 * Mat3(Vec3(-1, 1, 0.5).asDiagonal()),
                                            s.r - Vec3(1, 1, 1).normalized());
    c.gyro_sigma = s.gyro_sigma;
    c.gyro_bias_sigma = bias_sigma;
    c.gyro_bias_estimated = estimated;
    c.second_order_noise = true;
    Identifier id;
    id.configure(c);
    TruthRun truth(s);
    RandomFiring fire(200 + static_cast<unsigned long long>(run));
    truth.run(static_cast<int>(1200.0 / kDt), fire,
              [&](double, const test::V3& w, const test::V8& f) { id.update(id_input(w, f)); });
    const IdentifierEstimate& e = id.estimate();
    const Vec6 dj = inertia_params(e.j) - inertia_params(s.j);
    const Vec3 dr = e.r - s.r;
    out.j += dj.dot(id.inertia_covariance().ldlt().solve(dj));
    out.r += dr.dot(id.offset_covariance().ldlt().solve(dr));
    if (bias_sigma > 0.0 && estimated) {
      const Vec3 db = e.gyro_bias - s.gyro_bias;
      out.b += db.dot(id.bias_covariance().ldlt().solve(db));
    }
    out.j_rel_max = std::fmax(out.j_rel_max, j_error(id, s.j));
  }
  return out;
}

TEST(Identifier, WithAGyroBiasTheNormalisedErrorsStayInsideTheChiSquareBand) {
  constexpr int kRuns = 24;
  const auto in_band = [](double sum, int dof) {
    return sum >= test::chi2_quantile(dof, -1.96) && sum <= test::chi2_quantile(dof, 1.96);
  };
  const BiasedRunNees with = biased_run_nees(3e-5, true, kRuns);
  std::printf("bias estimated: mean NEES J %.2f (6), r %.2f (3), b %.2f (3); worst |dJ|/|J| %.2g\n",
              with.j / kRuns, with.r / kRuns, with.b / kRuns, with.j_rel_max);
  // Estimated (not the flight's default): under this firing the bias and r are nearly
  // confounded, and how much of the bias the 24 runs resolve depends on the last bits of the
  // arithmetic (x86-64: mean NEES J 6.3, b 3.4; the same runs built for aarch64: 4.3, 1.8). The
  // reported covariance is never overconfident (the upper bound, what the fault detector relies
  // on); the two-sided band is asserted for the default, the considered bias, below.
  const auto not_overconfident = [](double sum, int dof) {
    return sum <= test::chi2_quantile(dof, 1.96);
  };
  EXPECT_TRUE(not_overconfident(with.j, 6 * kRuns)) << with.j;
  EXPECT_TRUE(in_band(with.r, 3 * kRuns)) << with.r;
  EXPECT_TRUE(not_overconfident(with.b, 3 * kRuns)) << with.b;
  const BiasedRunNees consider = biased_run_nees(3e-5, false, kRuns);
  std::printf("bias considered: mean NEES J %.2f (6), r %.2f (3); worst |dJ|/|J| %.2g\n",
              consider.j / kRuns, consider.r / kRuns, consider.j_rel_max);
  EXPECT_TRUE(in_band(consider.j, 6 * kRuns)) << consider.j;
  EXPECT_TRUE(in_band(consider.r, 3 * kRuns)) << consider.r;
  const BiasedRunNees without = biased_run_nees(0.0, false, kRuns);
  std::printf("bias ignored: mean NEES J %.2f (6), r %.2f (3); worst |dJ|/|J| %.2g\n",
              without.j / kRuns, without.r / kRuns, without.j_rel_max);
  EXPECT_FALSE(in_band(without.j, 6 * kRuns) && in_band(without.r, 3 * kRuns));
}

// (I29) The anchor (I15) holds the mean strength of the reference thrusters at the mean of k0, but
// the true thrusters are calibrated only to sigma_k each: their mean is off by sigma_k / sqrt(16),
// and J with it (the data never show the common scale of J and k). Over 48 runs whose true
// strengths are drawn from the prior (not re-centred), flown with the flight's settings, the
// normalised error of J with the reported (marginal) covariance, summed over the runs, lies in the
// two-sided 95 % chi-square band, and k's with its marginal covariance is not above it; with the
// covariance conditional on the scale (what the covariance accessors give, and what a prediction
// of the motion needs) J's sum is far above it.
TEST(Identifier, TheReportedSigmaCarriesTheThrustScalesCalibration) {
  constexpr int kRuns = 48;
  constexpr double kSigmaK = 0.01;
  const auto in_band = [](double sum, int dof) {
    return sum >= test::chi2_quantile(dof, -1.96) && sum <= test::chi2_quantile(dof, 1.96);
  };
  std::mt19937_64 rng(29);
  std::normal_distribution<double> normal(0.0, 1.0);
  double nees_marginal = 0.0, nees_conditional = 0.0, nees_k = 0.0, scale_err2 = 0.0;
  for (int run = 0; run < kRuns; ++run) {
    TruthSetup s;
    s.j = study_j();
    s.r = study_true_mass_properties().r_so_bcm;
    for (int i = 0; i < kThrusters; ++i) s.k(i) = 1.0 + kSigmaK * normal(rng);
    s.disturbance_sigma = 1.0 / std::sqrt(3.0);
    s.seed = 300 + static_cast<unsigned long long>(run);
    s.omega0 = 0.04 * Vec3(normal(rng), normal(rng), normal(rng)).normalized();
    IdentifierConfig c = config_with_priors(s.j - 1e6 * Mat3(Vec3(-1, 1, 0.5).asDiagonal()),
                                            s.r - 0.3 * Vec3(1, 1, 1).normalized());
    c.k_prior_sigma = kSigmaK;
    c.j_forget_s = 0.0;  // the flight's settings (gnc.yaml): forgetting would inflate P
    c.r_forget_s = 0.0;
    c.second_order_noise = true;
    Identifier id;
    id.configure(c);
    TruthRun truth(s);
    RandomFiring fire(400 + static_cast<unsigned long long>(run));
    truth.run(static_cast<int>(600.0 / kDt), fire,
              [&](double, const test::V3& w, const test::V8& f) { id.update(id_input(w, f)); });
    const IdentifierEstimate& e = id.estimate();
    ASSERT_DOUBLE_EQ(e.thrust_scale_sigma, kSigmaK / 4.0);  // sixteen reference thrusters, k0 = 1
    const Vec6 dj = inertia_params(e.j) - inertia_params(s.j);
    const Mat6 marginal = unpack_upper<6>(e.j_cov);
    // The marginal is the conditional plus the scale's rank-one term, entry by entry.
    const Vec6 a = inertia_params(e.j);
    const Mat6 expected =
        id.inertia_covariance() + e.thrust_scale_sigma * e.thrust_scale_sigma * a * a.transpose();
    EXPECT_LT((marginal - expected).cwiseAbs().maxCoeff(), 1e-9 * expected.cwiseAbs().maxCoeff());
    for (int i = 0; i < 6; ++i) EXPECT_DOUBLE_EQ(e.j_sigma(i), std::sqrt(marginal(i, i)));
    nees_marginal += dj.dot(marginal.ldlt().solve(dj));
    nees_conditional += dj.dot(id.inertia_covariance().ldlt().solve(dj));
    // k's errors are mostly the one scale error too: its marginal covariance, written here from
    // (I29), with the reported 1 sigma its diagonal.
    const Mat16 k_marginal = id.strength_covariance() +
                             e.thrust_scale_sigma * e.thrust_scale_sigma * e.k * e.k.transpose();
    for (int i = 0; i < kThrusters; ++i) EXPECT_DOUBLE_EQ(e.k_sigma(i), std::sqrt(k_marginal(i, i)));
    const Vec16 dk = e.k - s.k;
    nees_k += dk.dot(k_marginal.ldlt().solve(dk));
    const double eps = s.k.mean() - 1.0;
    scale_err2 += eps * eps;
  }
  std::printf("%d runs: sum NEES J %.1f marginal, %.1f conditional (band %.1f-%.1f); k %.1f (band "
              "%.1f-%.1f); rms mean-strength error %.3g (sigma %.3g)\n",
              kRuns, nees_marginal, nees_conditional, test::chi2_quantile(6 * kRuns, -1.96),
              test::chi2_quantile(6 * kRuns, 1.96), nees_k,
              test::chi2_quantile(kThrusters * kRuns, -1.96),
              test::chi2_quantile(kThrusters * kRuns, 1.96), std::sqrt(scale_err2 / kRuns),
              kSigmaK / 4.0);
  EXPECT_TRUE(in_band(nees_marginal, 6 * kRuns)) << nees_marginal;
  // k: never over-confident (its ratios come out slightly pessimistic in this rig, about 0.85 of
  // the dof, as do J's with the second-order term); the conditional k covariance is singular
  // along the scale and cannot be scored at all.
  EXPECT_LE(nees_k, test::chi2_quantile(kThrusters * kRuns, 1.96)) << nees_k;
  EXPECT_GT(nees_k, 0.5 * kThrusters * kRuns) << nees_k;
  EXPECT_GT(nees_conditional, test::chi2_quantile(6 * kRuns, 1.96));
}

// (I29) A thruster declared changed leaves the reference set: the scale is then the calibration
// of the fifteen others. Without the anchor the k prior holds the scale in the covariance itself,
// and nothing is added.
TEST(Identifier, TheThrustScalesSigmaFollowsTheReferenceSet) {
  IdentifierConfig c = config_with_priors(study_j(), study_true_mass_properties().r_so_bcm);
  c.k_prior_sigma = 0.02;
  Identifier id;
  id.configure(c);
  TruthSetup s;
  s.j = study_j();
  s.r = study_true_mass_properties().r_so_bcm;
  TruthRun truth(s);
  RandomFiring fire(31);
  const auto fly = [&](double seconds) {
    truth.run(static_cast<int>(seconds / kDt), fire,
              [&](double, const test::V3& w, const test::V8& f) { id.update(id_input(w, f)); });
  };
  fly(45.0);
  EXPECT_DOUBLE_EQ(id.estimate().thrust_scale_sigma, 0.02 / 4.0);
  id.reinflate_thruster(5);
  fly(45.0);
  EXPECT_DOUBLE_EQ(id.estimate().thrust_scale_sigma, 0.02 / std::sqrt(15.0));
  c.anchor_thrust_scale = false;
  Identifier unanchored;
  unanchored.configure(c);
  TruthRun truth2(s);
  RandomFiring fire2(31);
  truth2.run(static_cast<int>(45.0 / kDt), fire2, [&](double, const test::V3& w, const test::V8& f) {
    unanchored.update(id_input(w, f));
  });
  EXPECT_EQ(unanchored.estimate().thrust_scale_sigma, 0.0);
  const Vec6 sd = unanchored.inertia_covariance().diagonal().cwiseSqrt();
  for (int i = 0; i < 6; ++i) EXPECT_DOUBLE_EQ(unanchored.estimate().j_sigma(i), sd(i));
}

// (I30) Early windows: the windows that close within early_span_s (60 s) are early_window_s (12 s)
// long, the rest window_s; identified_s() is their sum; every window's step ends before the next
// window closes, the short ones included. From the case-4 prior errors with the same firings, the
// five early steps leave J closer at 60 s than the two of 20 s windows.
TEST(Identifier, EarlyWindowsAreShorterOnlyOverTheirSpan) {
  TruthSetup s;
  s.j = study_j();
  s.r = study_true_mass_properties().r_so_bcm;
  s.k = spread_strengths();
  IdentifierConfig c = config_with_priors(s.j - 1e7 * Mat3(Vec3(-1, 1, 0.5).asDiagonal()),
                                          s.r - Vec3(1, 1, 1).normalized());
  c.second_order_noise = true;
  c.guard_halvings = 3;
  IdentifierConfig early = c;
  early.early_window_s = 12.0;
  early.early_span_s = 60.0;
  ASSERT_TRUE(validate(early).ok);
  Identifier plain, id;
  plain.configure(c);
  id.configure(early);
  TruthRun truth(s);
  RandomFiring fire(12);
  std::vector<double> lengths;
  double sum = 0.0;
  int overrun = 0;
  bool stepping_before = false;
  double j60_plain = 0.0, j60_early = 0.0;
  int tick = 0;
  truth.run(static_cast<int>(200.0 / kDt), fire, [&](double, const test::V3& w, const test::V8& f) {
    const std::uint32_t before = id.counters().windows;
    stepping_before = id.stepping();
    plain.update(id_input(w, f));
    id.update(id_input(w, f));
    ++tick;
    if (id.counters().windows != before) {
      if (stepping_before && before > 0) ++overrun;
      lengths.push_back(id.latched_window_s());
      sum += id.latched_window_s();
      EXPECT_NEAR(id.identified_s(), sum, 1e-9);
    }
    if (tick == 600) {
      j60_plain = j_error(plain, s.j);
      j60_early = j_error(id, s.j);
    }
  });
  ASSERT_GE(lengths.size(), 8u);
  for (std::size_t i = 0; i < lengths.size(); ++i) {
    EXPECT_NEAR(lengths[i], i < 5 ? 12.0 : 20.0, 1e-9) << i;
  }
  EXPECT_EQ(overrun, 0);
  std::printf("J at 60 s: %.3g with 20 s windows, %.3g with five early 12 s windows\n", j60_plain,
              j60_early);
  EXPECT_LT(j60_early, j60_plain);
  EXPECT_LT(j_error(id, s.j), 1e-3);
}

// (I18) A thruster that stops delivering (an unmodelled fault) after the model is identified: the
// windows it spoils do not fit the model within S. Each is refused and counted, and leaves the
// estimate and the covariance exactly as they were (a refused update never shrinks the
// covariance); after gate_reinflate_after such windows in a row J, r and k go back to their prior
// covariance. Without the gate the same data move r-hat by centimetres while the reported 1 sigma
// stays at millimetres.
// restart_at (gnc/fdi/README.md F12, after a confirmed fault): right after reinflate_all, J, r and k
// start again from the given model with its uncertainty, each block at most the prior's, their
// cross-covariances cleared, the rate bias's block kept; without a re-inflation just before, it
// does nothing. Then the windows that follow move the estimate from there.
TEST(Identifier, ARestartAfterAReinflationTakesTheGivenModelAndItsUncertainty) {
  TruthSetup s;
  s.j = study_j();
  s.r = study_true_mass_properties().r_so_bcm;
  IdentifierConfig c = config_with_priors(s.j, s.r);
  Identifier id;
  id.configure(c);
  TruthRun truth(s);
  RandomFiring fire(7);
  truth.run(static_cast<int>(200.0 / kDt), fire,
            [&](double, const test::V3& w, const test::V8& f) { id.update(id_input(w, f)); });
  ASSERT_GT(id.counters().windows, 5u);
  Mat3 j = s.j;
  j(0, 1) += 1e5;
  j(1, 0) += 1e5;
  const Vec3 r = s.r + Vec3(0.01, -0.02, 0.03);
  Vec16 k = Vec16::Ones();
  k(3) = 0.7;
  Mat3 r_cov;
  r_cov << 4e-4, 1e-5, 0.0, 1e-5, 9e-4, 0.0, 0.0, 0.0, 1e-4;
  // Without a re-inflation first: nothing changes.
  const Mat3 j_was = id.estimate().j;
  id.restart_at(j, 1e4, r, r_cov, k, 1e-3);
  EXPECT_TRUE(id.estimate().j == j_was);
  const Mat3 p_bb = id.joint_covariance().block<3, 3>(kIdB, kIdB);
  id.reinflate_all();
  id.restart_at(j, 1e4, r, r_cov, k, 1e-3);
  EXPECT_LT((id.estimate().j - j).norm(), 1e-9 * j.norm());
  EXPECT_TRUE(id.estimate().r == r);
  EXPECT_TRUE(id.estimate().k == k);
  EXPECT_TRUE(id.inertia_covariance() == Mat6(1e8 * Mat6::Identity()));
  EXPECT_TRUE(id.offset_covariance() == r_cov);
  EXPECT_TRUE(id.strength_covariance() == Mat16(1e-6 * Mat16::Identity()));
  const MatId& p = id.joint_covariance();
  EXPECT_TRUE(Mat6(p.block<6, 6>(0, 0)) == Mat6(1e8 * Mat6::Identity()));
  EXPECT_TRUE(Mat3(p.block<3, 3>(kIdR, kIdR)) == r_cov);
  EXPECT_TRUE(Mat16(p.block<16, 16>(kIdK, kIdK)) == Mat16(1e-6 * Mat16::Identity()));
  const double cross_terms = p.block<6, 3>(0, kIdR).norm() + p.block<6, 16>(0, kIdK).norm() +
                             p.block<3, 16>(kIdR, kIdK).norm();
  EXPECT_EQ(cross_terms, 0.0);
  EXPECT_TRUE(Mat3(p.block<3, 3>(kIdB, kIdB)) == p_bb);
  // Uncertainties above the prior are the prior's.
  id.reinflate_all();
  id.restart_at(j, 1e9, r, 1e3 * Mat3::Identity(), k, 1.0);
  const double vj = c.j_prior_sigma * c.j_prior_sigma;
  const double vr = c.r_prior_sigma * c.r_prior_sigma;
  const double vk = c.k_prior_sigma * c.k_prior_sigma;
  EXPECT_TRUE(id.inertia_covariance() == Mat6(vj * Mat6::Identity()));
  EXPECT_TRUE(id.offset_covariance() == Mat3(vr * Mat3::Identity()));
  EXPECT_TRUE(id.strength_covariance() == Mat16(vk * Mat16::Identity()));
  // The next windows start from the given model.
  const std::uint32_t w0 = id.counters().windows;
  truth.run(static_cast<int>(60.0 / kDt), fire,
            [&](double, const test::V3& w, const test::V8& f) { id.update(id_input(w, f)); });
  EXPECT_GT(id.counters().windows, w0);
  EXPECT_LT((id.estimate().k - k).cwiseAbs().maxCoeff(), 0.35);  // moved from k, towards 1
  EXPECT_GT((id.estimate().k - k).cwiseAbs().maxCoeff(), 0.0);
}

TEST(Identifier, AnUpdateRefusedByTheInnovationGateLeavesEstimateAndCovarianceAlone) {
  TruthSetup s;
  s.j = study_j();
  s.r = study_true_mass_properties().r_so_bcm;
  s.disturbance_sigma = 1.0 / std::sqrt(3.0);
  s.disturbance_phase_s = 3.0;
  s.gyro_sigma = std::sqrt(1e-12 / kDt);
  IdentifierConfig c = config_with_priors(s.j, s.r);
  c.gyro_sigma = s.gyro_sigma;
  c.anchor_thrust_scale = false;  // nothing but the gate acts on a refused window
  c.gate_chi2 = 16.27;
  c.gate_reinflate_after = 3;
  const double t_fault = 600.0;
  for (bool gate : {true, false}) {
    IdentifierConfig ci = c;
    if (!gate) ci.gate_chi2 = 0.0;
    Identifier id;
    id.configure(ci);
    TruthRun truth(s);
    RandomFiring fire(31);
    Mat6 pj_before = Mat6::Zero();
    Mat3 pr_before = Mat3::Zero();
    Vec3 r_before = Vec3::Zero();
    Mat3 j_before = Mat3::Zero();
    std::uint32_t gated_seen = 0;
    int checked = 0, reinflated = 0, at_prior = 0;
    bool prior_pending = false;
    double r_move = 0.0, r_sigma_fault = 0.0;
    truth.run(static_cast<int>(700.0 / kDt), fire,
              [&](double t, const test::V3& w, const test::V8& f) {
                if (std::fabs(t - t_fault) < 1e-6) {
                  truth.set_strength(2, 0.0);  // thruster 2 (pod 1 tangential +) dead
                  truth.set_strength(3, 0.0);
                  r_before = id.estimate().r;
                  r_sigma_fault = id.estimate().r_sigma.maxCoeff();
                }
                if (id.counters().windows_gated == gated_seen) {
                  pj_before = id.inertia_covariance();
                  pr_before = id.offset_covariance();
                  j_before = id.estimate().j;
                }
                id.update(id_input(w, f));
                if (id.counters().windows_gated != gated_seen) {
                  // This window's step has just ended refused: nothing moved (a re-inflation the
                  // refusal asks for comes on the next blocks, below).
                  gated_seen = id.counters().windows_gated;
                  ++checked;
                  EXPECT_TRUE(id.inertia_covariance() == pj_before) << t;
                  EXPECT_TRUE(id.offset_covariance() == pr_before) << t;
                  EXPECT_TRUE(id.estimate().j == j_before) << t;
                }
                if (id.counters().gate_reinflations > static_cast<std::uint32_t>(reinflated)) {
                  // Too many refusals in a row: J and r go back to their prior covariance (as
                  // published once the step's blocks end, before the next window closes).
                  ++reinflated;
                  prior_pending = true;
                }
                if (prior_pending &&
                    id.inertia_covariance() ==
                        Mat6(ci.j_prior_sigma * ci.j_prior_sigma * Mat6::Identity()) &&
                    id.offset_covariance() ==
                        Mat3(ci.r_prior_sigma * ci.r_prior_sigma * Mat3::Identity())) {
                  prior_pending = false;
                  ++at_prior;
                }
                if (t > t_fault) r_move = std::fmax(r_move, (id.estimate().r - r_before).norm());
              });
    const Vec3 z = (id.estimate().r - s.r).cwiseQuotient(id.estimate().r_sigma);
    std::printf(
        "gate %d: windows gated %u, re-inflations %u, r moved %.3g m (1 sigma %.3g m "
        "at the fault); at 700 s |r_hat - r| %.3g m, largest |error| / sigma %.3g\n",
        gate, id.counters().windows_gated, id.counters().gate_reinflations, r_move, r_sigma_fault,
        (id.estimate().r - s.r).norm(), z.cwiseAbs().maxCoeff());
    if (gate) {
      EXPECT_GE(checked, 2);
      EXPECT_GE(reinflated, 1);
      EXPECT_EQ(at_prior, reinflated);
      EXPECT_GE(id.counters().reinflations, 1u);
      // What the unmodelled fault did to r-hat is covered by the reported 1 sigma.
      EXPECT_LT(z.cwiseAbs().maxCoeff(), 3.0);
    } else {
      EXPECT_EQ(id.counters().windows_gated, 0u);
      EXPECT_GT(r_move, 5.0 * r_sigma_fault);  // the overconfidence the gate prevents
      EXPECT_GT(z.cwiseAbs().maxCoeff(), 10.0);
    }
  }
}

// (I17) With b a consider parameter, a new bias correction upstream (the MEKF's) sets b's
// covariance to the given 1 sigma, clears its cross terms and keeps b-hat at zero, but only once
// the closed window's step (which used the old rate) is done.
// (I22)-(I23): thruster 4 (pod 1, tangential "+") stuck on from the first tick, the others fired
// at up to 30 N (the despin commands 5-15 N) and the channel's other half against it, with the
// firing
// the identifier is told about being the commanded one. From far priors (J 4·10^6 kg m^2 and r
// 0.4 m off), with the fault torque d in the state, the model converges around the jet: d-hat
// carries its torque, matches thruster 4's column within chi-square(3) 0.999 and no other column
// (the margin F14 asks for), and stands far from zero; the innovation gate stops refusing.
// Without d, the gate refuses window after window and re-inflates.
TEST(Identifier, AJetStuckOnFromTheStartIsFittedAsTheFaultTorqueAndMatchesOnlyItsColumn) {
  constexpr int kJet = 4;
  TruthSetup s;
  s.j = study_j();
  s.r = study_true_mass_properties().r_so_bcm;
  s.disturbance_sigma = 1.0 / std::sqrt(3.0);
  s.gyro_sigma = std::sqrt(1e-12 / kDt);
  Mat3 j0 = s.j;
  j0(0, 0) += 4e6;
  j0(1, 2) += 1e6;
  j0(2, 1) += 1e6;
  IdentifierConfig c = config_with_priors(j0, s.r + Vec3(0.3, -0.2, 0.2));
  c.gyro_sigma = s.gyro_sigma;
  c.k_prior_sigma = 0.01;
  c.second_order_noise = true;
  c.gate_chi2 = 16.27;
  c.gate_reinflate_after = 3;
  // The model's column of the jet (p_i + r) x e_i u_max, written out from SPEC §4: pod 1 at
  // 135 degrees, radius 2.5 m, height 3 m; the "+" tangential direction.
  const double th = M_PI / 4 + M_PI / 2;
  const Vec3 pos(2.5 * std::cos(th), 2.5 * std::sin(th), 3.0);
  const Vec3 dir(-std::sin(th), std::cos(th), 0.0);
  const Vec3 column = (pos + s.r).cross(dir) * 200.0;
  for (bool with_d : {true, false}) {
    IdentifierConfig ci = c;
    ci.fault_torque_sigma = with_d ? 3000.0 : 0.0;
    Identifier id;
    id.configure(ci);
    TruthRun truth(s);
    RandomFiring fire(77, 30.0);  // small commands, as the despin gives (5-15 N)
    test::V8 commanded = test::V8::Zero();
    truth.run(
        static_cast<int>(1500.0 / kDt),
        [&](double t, const test::V3& w) {
          commanded = fire(t, w);
          // As in the loop, the controller fires the channel's other half against the stuck jet
          // (here at 170-230 N), so the body is not spun up.
          commanded(kJet / 2) = -200.0 + commanded(kJet / 2);
          test::V8 applied = commanded;  // channel 2's "+" jet at u_max whatever is commanded
          applied(kJet / 2) = 200.0 + std::fmin(commanded(kJet / 2), 0.0);
          return applied;
        },
        [&](double, const test::V3& w, const test::V8&) { id.update(id_input(w, commanded)); });
    const IdentifierFaultTorque& ft = id.fault_torque();
    if (!with_d) {
      EXPECT_EQ(ft.scored, 0u);
      EXPECT_GT(id.counters().gate_reinflations, 3u) << "without d the jet breaks the model";
      continue;
    }
    std::printf(
        "d-hat (%.1f %.1f %.1f) N m, column (%.1f %.1f %.1f) N m; chi2 zero %.3g, own %.3g; "
        "gated %u, re-inflations %u\n",
        ft.d(0), ft.d(1), ft.d(2), column(0), column(1), column(2), ft.chi2_zero,
        ft.chi2_jet[kJet], id.counters().windows_gated, id.counters().gate_reinflations);
    EXPECT_GT(ft.scored, 60u);
    EXPECT_TRUE(ft.fitted);
    EXPECT_LT((ft.d - column).norm(), 0.05 * column.norm());
    EXPECT_GT(ft.chi2_zero, 100.0);
    EXPECT_LT(ft.chi2_jet[kJet], 16.27);
    for (int i = 0; i < kThrusters; ++i) {
      if (i != kJet) {
        EXPECT_GT(ft.chi2_jet[i] - ft.chi2_jet[kJet], 25.0) << "thruster " << i;
      }
    }
  }
}

// The study vehicle under rich firing with a quiet gyro, from r 0.4 m off, with the flight's
// strength prior, second-order term and innovation gate: the fault torque's settling (I24).
struct SettlingSetup {
  TruthSetup truth;
  IdentifierConfig config;
};
SettlingSetup settling_setup() {
  SettlingSetup out;
  TruthSetup& s = out.truth;
  s.j = study_j();
  s.r = study_true_mass_properties().r_so_bcm;
  s.disturbance_sigma = 1.0 / std::sqrt(3.0);
  s.gyro_sigma = std::sqrt(1e-12 / kDt);
  IdentifierConfig& c = out.config;
  c = config_with_priors(s.j, s.r + Vec3(0.3, -0.2, 0.2));
  c.gyro_sigma = s.gyro_sigma;
  c.k_prior_sigma = 0.01;
  c.second_order_noise = true;
  c.gate_chi2 = 16.27;
  return out;
}

// (I24): without a fault, d-hat stays consistent with zero and is settled there (the
// pseudo-measurement d = 0); the information it held returns to J and r, whose 1 sigma end
// within 25 % of an identifier that never had d (the detector's noise (F5) is built from them),
// with estimates as close to the truth. (Under this rich firing d is barely confounded: unsettled,
// r's 1 sigma is 3 % larger. Under the despin's firing the difference cost the detector its
// axial isolations at 3000 s in cases 6-7: gnc/fdi/README.md (F14).)
TEST(Identifier, AHealthyFaultTorqueIsSettledAtZeroAndGivesItsInformationBack) {
  const SettlingSetup setup = settling_setup();
  const TruthSetup& s = setup.truth;
  IdentifierConfig c = setup.config;
  struct Result {
    double r_sigma, j_sigma, r_err;
    bool held;
    std::uint32_t settles;
  };
  auto fly = [&](double fault_sigma) {
    IdentifierConfig ci = c;
    ci.fault_torque_sigma = fault_sigma;
    Identifier id;
    id.configure(ci);
    TruthRun truth(s);
    RandomFiring fire(5);
    truth.run(static_cast<int>(1500.0 / kDt), fire,
              [&](double, const test::V3& w, const test::V8& f) { id.update(id_input(w, f)); });
    return Result{id.estimate().r_sigma.maxCoeff(), id.estimate().j_sigma.maxCoeff(),
                  (id.estimate().r - s.r).norm(), id.fault_torque().held_zero,
                  id.counters().fault_torque_settles};
  };
  const Result without = fly(0.0);
  const Result with = fly(3000.0);
  std::printf("r 1 sigma %.3g m (no d %.3g m), J 1 sigma %.3g (no d %.3g), |r error| %.3g m "
              "(no d %.3g m), settled %d\n",
              with.r_sigma, without.r_sigma, with.j_sigma, without.j_sigma, with.r_err,
              without.r_err, with.held);
  EXPECT_TRUE(with.held);
  // Settled once: d held at zero is out of the state and is not settled again on every quiet
  // window (75 windows here; the settling's row blocks are tick budget spent for nothing).
  EXPECT_EQ(with.settles, 1U);
  EXPECT_EQ(without.settles, 0U);
  EXPECT_LT(with.r_sigma, 1.25 * without.r_sigma);
  EXPECT_LT(with.j_sigma, 1.25 * without.j_sigma);
  EXPECT_LT(with.r_err, 3.0 * with.r_sigma + without.r_err);
}

// reinflate_all computes only the block it keeps of the step under way (the rate bias b's, and
// d's when settled at zero, I24): the Cortex-M7 tick of a confirmed fault. It must leave what
// re-inflating the groups one by one leaves (each of which finishes every pending row block of
// the whole matrix first), to rounding: checked on every third tick of a flight that goes
// through joint steps, anchors and the settling of d, with d live and with d settled.
namespace {
// Largest |a_ij - b_ij| / sqrt(b_ii b_jj) (0 where both are 0): the difference in units of the
// entries' own scale, so a cross term is not judged against a large prior elsewhere.
double scaled_difference(const MatId& a, const MatId& b) {
  double worst = 0.0;
  for (int i = 0; i < kIdParams; ++i) {
    for (int j = 0; j < kIdParams; ++j) {
      const double diff = std::fabs(a(i, j) - b(i, j));
      if (diff == 0.0) continue;
      const double scale = std::sqrt(std::fabs(b(i, i) * b(j, j)));
      worst = std::fmax(worst, scale > 0.0 ? diff / scale : 1.0);
    }
  }
  return worst;
}
}  // namespace

TEST(Identifier, ReinflatingEverythingAtOnceEqualsGroupByGroupOnEveryTickOfAStep) {
  const SettlingSetup setup = settling_setup();
  const TruthSetup& s = setup.truth;
  IdentifierConfig c = setup.config;
  c.fault_torque_sigma = 3000.0;
  c.gyro_bias_sigma = 1e-5;
  c.gyro_bias_estimated = true;  // b in the state: the joint step updates its rows too
  Identifier id;
  id.configure(c);
  TruthRun truth(s);
  RandomFiring fire(5);
  int compared = 0, with_d_settled = 0, flown_on = 0;
  double worst = 0.0, worst_flown = 0.0;
  int worst_tick = -1;
  bool exact_elsewhere = true;
  int tick = 0;
  truth.run(static_cast<int>(1500.0 / kDt), fire,
            [&](double, const test::V3& w, const test::V8& f) {
              id.update(id_input(w, f));
              ++tick;
              if (tick % 3 != 0) return;  // every third tick: every row-block phase is hit
              Identifier at_once = id;
              Identifier by_group = id;
              const bool settled = id.fault_torque_held_zero();
              at_once.reinflate_all();
              by_group.reinflate_inertia();
              by_group.reinflate_offset();
              for (int i = 0; i < kThrusters; ++i) by_group.reinflate_thruster(i);
              if (!settled) by_group.reinflate_fault_torque();
              ++compared;
              with_d_settled += settled ? 1 : 0;
              const double diff =
                  scaled_difference(at_once.joint_covariance(), by_group.joint_covariance());
              if (diff > worst) {
                worst = diff;
                worst_tick = tick;
              }
              // The re-inflated groups are their priors, exactly.
              exact_elsewhere =
                  exact_elsewhere &&
                  (at_once.inertia_covariance().array() == by_group.inertia_covariance().array())
                      .all() &&
                  (at_once.offset_covariance().array() == by_group.offset_covariance().array())
                      .all() &&
                  (at_once.strength_covariance().array() ==
                   by_group.strength_covariance().array()).all() &&
                  at_once.fault_torque_held_zero() == by_group.fault_torque_held_zero();
              // And both fly on alike (the pending phase, the dropped gain).
              if (tick % 999 == 0) {
                ++flown_on;
                for (int k = 0; k < 400; ++k) {
                  const test::V3 wk = w + 1e-6 * k * test::V3(1.0, -0.5, 0.25);
                  at_once.update(id_input(wk, f));
                  by_group.update(id_input(wk, f));
                }
                worst_flown = std::fmax(worst_flown, scaled_difference(at_once.joint_covariance(),
                                                                       by_group.joint_covariance()));
                EXPECT_LT((at_once.estimate().j - by_group.estimate().j).norm(),
                          1e-9 * by_group.estimate().j.norm())
                    << "tick " << tick;
              }
            });
  std::printf("%d ticks compared (%d with d settled): largest scaled difference %.3g (tick %d), "
              "%.3g after 400 more ticks\n",
              compared, with_d_settled, worst, worst_tick, worst_flown);
  EXPECT_LT(worst, 1e-14) << "tick " << worst_tick;  // rounding: 2e-16 measured
  EXPECT_LT(worst_flown, 1e-9);
  EXPECT_TRUE(exact_elsewhere);
  EXPECT_GT(flown_on, 10);
  EXPECT_GT(with_d_settled, 100) << "the flight must settle d to test both branches";
  EXPECT_LT(with_d_settled, compared - 100);
  EXPECT_EQ(id.counters().fault_torque_settles, 1U);
}

TEST(Identifier, AConsideredRateBiasTakesTheGivenSigmaAfterTheStep) {
  TruthSetup s;
  s.j = study_j();
  s.r = study_true_mass_properties().r_so_bcm;
  IdentifierConfig c = config_with_priors(s.j, s.r);
  c.gyro_bias_sigma = 3e-5;
  Identifier id;
  id.configure(c);
  EXPECT_NEAR(id.bias_covariance()(0, 0), 9e-10, 1e-22);
  TruthRun truth(s);
  RandomFiring fire(4);
  const int n = static_cast<int>(std::lround(c.window_s / kDt));
  int tick = 0;
  bool asked = false, checked_pending = false;
  const Vec3 sigma(1e-6, 2e-6, 3e-6);
  truth.run(3 * n, fire, [&](double, const test::V3& w, const test::V8& f) {
    id.update(id_input(w, f));
    ++tick;
    if (!asked && id.counters().windows == 1) {  // the first window has just closed
      asked = true;
      id.consider_rate_bias(sigma);
      EXPECT_NEAR(id.bias_covariance()(0, 0), 9e-10, 1e-22);  // its step still runs
      checked_pending = true;
    }
  });
  ASSERT_TRUE(checked_pending);
  // Two more windows' steps ran with the new covariance: b was never fitted (no gain), so its
  // covariance is what was given, with no cross terms beyond what those steps created.
  EXPECT_TRUE(id.estimate().gyro_bias.isZero());
  for (int a = 0; a < 3; ++a) EXPECT_NEAR(id.bias_covariance()(a, a), sigma(a) * sigma(a), 1e-24);
}

// (I21) against a brute-force double sum over a fine grid, random phase: the closed form and the
// Simpson branch.
TEST(Identifier, HeldDisturbanceFactorMatchesTheDoubleIntegral) {
  for (const auto& tt : {std::pair<double, double>{20.0, 10.0},
                         {60.0, 10.0},
                         {20.0, 15.0},
                         {20.0, 40.0},
                         {8.0, 1.0}}) {
    const double t_w = tt.first, tau = tt.second;
    const int n = 800;
    const double dt = t_w / n;
    double sum = 0.0;
    for (int i = 0; i < n; ++i) {
      const double ti = (i + 0.5) * dt, wi = 1.0 - std::fabs(2.0 * ti / t_w - 1.0);
      for (int j = 0; j < n; ++j) {
        const double tj = (j + 0.5) * dt, wj = 1.0 - std::fabs(2.0 * tj / t_w - 1.0);
        const double u = std::fabs(ti - tj);
        if (u < tau) sum += wi * wj * (1.0 - u / tau);
      }
    }
    sum *= dt * dt;
    EXPECT_NEAR(held_disturbance_factor(t_w, tau), sum, 1e-4 * sum) << t_w << " " << tau;
  }
}

// Couples only: every firing pattern has zero net force, so r cannot show (I10).
test::V8 pure_couples(double t, const test::V3&) {
  test::V8 u = test::V8::Zero();
  const double a = 150.0 * std::sin(0.05 * t), b = 150.0 * std::cos(0.031 * t);
  const double c = 100.0 * std::sin(0.017 * t + 1.0);
  for (int k = 0; k < 4; ++k) u(2 * k) = c;  // tangential, all the same: pure z couple
  u(1) = a;                                  // axial, pod 0 against pod 2
  u(5) = -a;
  u(3) = b;  // pod 1 against pod 3
  u(7) = -b;
  return u;
}

TEST(Identifier, PureCouplesLeaveTheOffsetReportedUnobservableNotEstimated) {
  TruthSetup s;
  s.j = study_j();
  s.r = study_true_mass_properties().r_so_bcm;
  const Vec3 r0 = s.r - Vec3(0.3, -0.2, 0.5);
  Identifier id;
  id.configure(config_with_priors(s.j, r0));
  TruthRun truth(s);
  truth.run(static_cast<int>(600.0 / kDt), pure_couples,
            [&](double, const test::V3& w, const test::V8& f) { id.update(id_input(w, f)); });
  EXPECT_GT(id.counters().windows, 20u);
  EXPECT_EQ(id.observability().offset_unobservable, 3);
  EXPECT_EQ(id.counters().offset_updates, 0u);
  // Not invented: nothing is learned along unobservable directions (round-off of the joint
  // update's scale anchoring only, below a nanometre).
  EXPECT_LT((id.estimate().r - r0).norm(), 1e-9) << (id.estimate().r - r0).transpose();
  EXPECT_FALSE(id.estimate().offset_confident);
  EXPECT_GT(id.estimate().r_sigma.minCoeff(), 0.9 * 1.0);  // still the prior's 1 m
  // The inertia is still identified from the couples.
  EXPECT_LT(j_error(id, s.j), 1e-3);
}

TEST(Identifier, ANetForceAlongZLeavesOnlyTheZOffsetUnobservable) {
  TruthSetup s;
  s.j = study_j();
  s.r = study_true_mass_properties().r_so_bcm;
  const Vec3 r0 = s.r - Vec3(0.3, -0.2, 0.5);
  Identifier id;
  id.configure(config_with_priors(s.j, r0));
  TruthRun truth(s);
  auto axial_plus_couples = [](double t, const test::V3& w) {
    test::V8 u = pure_couples(t, w);
    for (int k = 0; k < 4; ++k) u(2 * k + 1) += 40.0 + 30.0 * std::sin(0.02 * t + k);
    return u;
  };
  truth.run(static_cast<int>(600.0 / kDt), axial_plus_couples,
            [&](double, const test::V3& w, const test::V8& f) { id.update(id_input(w, f)); });
  ASSERT_EQ(id.observability().offset_unobservable, 1);
  EXPECT_GT(std::fabs(id.observability().offset_directions[0].z()), 0.999);
  EXPECT_NEAR(id.estimate().r.x(), s.r.x(), 5e-3);
  EXPECT_NEAR(id.estimate().r.y(), s.r.y(), 5e-3);
  // z stays at the prior: reported, not estimated.
  EXPECT_NEAR(id.estimate().r.z(), r0.z(), 0.02 * std::fabs(s.r.z() - r0.z()));
}

TEST(Identifier, TorqueFreeMotionGivesRatiosButNotTheInertiaScale) {
  TruthSetup s;
  s.j = study_j();
  const Mat3 j0 = 1.3 * s.j;  // right ratios, wrong scale
  Identifier id;
  id.configure(config_with_priors(j0, Vec3::Zero()));
  TruthRun truth(s);
  truth.run(
      static_cast<int>(300.0 / kDt),
      [](double, const test::V3&) { return test::V8::Zero().eval(); },
      [&](double, const test::V3& w, const test::V8& f) { id.update(id_input(w, f)); });
  EXPECT_GT(id.counters().inertia_updates, 0u);
  EXPECT_FALSE(id.excitation().inertia_scale);
  EXPECT_TRUE(id.excitation().inertia_motion);
  EXPECT_TRUE(id.observability().inertia_scale_unobservable);
  EXPECT_FALSE(id.estimate().inertia_confident);
  // The scale is not invented: it stays where the prior put it (the ratios were already right).
  EXPECT_NEAR(id.estimate().j.norm() / s.j.norm(), 1.3, 1e-3);
}

TEST(Identifier, AnInertiaUpdateThatWouldNotBePositiveDefiniteIsRefused) {
  // Commands reported with the wrong sign: the data say J is negative definite.
  TruthSetup s;
  s.j = study_j();
  s.r = study_true_mass_properties().r_so_bcm;
  s.omega0 = Vec3(1e-3, -1e-3, 5e-4);
  Identifier id;
  IdentifierConfig c = config_with_priors(s.j, s.r);
  c.j_prior_sigma = 1e8;
  id.configure(c);
  TruthRun truth(s);
  RandomFiring fire(8, 500.0);
  truth.run(static_cast<int>(300.0 / kDt), fire,
            [&](double, const test::V3& w, const test::V8& f) { id.update(id_input(w, -f)); });
  EXPECT_GT(id.counters().inertia_refused, 0u);
  EXPECT_EQ(Eigen::LLT<Mat3>(id.estimate().j).info(), Eigen::Success);
}

// (I28) A prior that is positive definite but outside the triangle inequality of the principal
// moments (a table validated for definiteness only, as identification-quiet.yaml's draw 176):
// the strict guard refuses every step that does not reach the inequality at once, so the first
// window is lost under the D+PD firings; with I28 a step may move J back towards it, never further
// out. Independent truth: the synthetic rigid body's J; the inequality from the eigenvalues here.
TEST(Identifier, APriorOutsideTheTriangleInequalityMovesBackWithI28) {
  TruthSetup s;
  s.j = study_j();
  s.r = study_true_mass_properties().r_so_bcm;
  s.k = spread_strengths();
  s.disturbance_sigma = 1.0 / std::sqrt(3.0);
  s.seed = 28;
  // Shrink the smallest principal moment and grow the largest by 6e6 kg m^2 each.


  const double kShrink = 5e6, kGrow = 2e7;
  Eigen::SelfAdjointEigenSolver<Mat3> es(s.j);
  const Mat3 v = es.eigenvectors();
  const Mat3 j0 = s.j - kShrink * v.col(0) * v.col(0).transpose() + kGrow * v.col(2) * v.col(2).transpose();
  Eigen::SelfAdjointEigenSolver<Mat3> e0(j0);
  ASSERT_GT(e0.eigenvalues()(0), 0.0);
  ASSERT_LT(e0.eigenvalues()(0) + e0.eigenvalues()(1), e0.eigenvalues()(2)) << "the prior must break it";
  struct Outcome {
    double j_at_50{0.0}, j_at_300{0.0}, nees{0.0};
    std::uint32_t refused{0}, damped{0};
    bool physical{false};
  };
  auto fly = [&](int halvings) {
    IdentifierConfig c = config_with_priors(j0, s.r);
    c.guard_halvings = halvings;
    Identifier id;
    id.configure(c);
    TruthRun truth(s);
    // The D+PD despin's firings (Eq. 49, the pseudoinverse of Eq. 53 on the true table): torque
    // along -omega only, as the flight's first minute.
    const Mat38 b = torque_matrix(study_rcs_layout(200.0), s.r);
    const Mat83 pinv = b.transpose() * (b * b.transpose()).inverse();
    auto fire = [&](double, const test::V3& w) { return test::V8(pinv * (-1e4 * w)); };
    Outcome o;
    int tick = 0;
    truth.run(static_cast<int>(300.0 / kDt), fire, [&](double, const test::V3& w, const test::V8& f) {
      id.update(id_input(w, f));
      if (++tick == static_cast<int>(50.0 / kDt)) {
        o.j_at_50 = j_error(id, s.j);
        o.refused = id.counters().inertia_refused;
      }
    });
    o.j_at_300 = j_error(id, s.j);
    o.damped = id.counters().damped_steps;
    const Vec6 dj = inertia_params(id.estimate().j) - inertia_params(s.j);
    o.nees = dj.dot(id.inertia_covariance().ldlt().solve(dj));
    Eigen::SelfAdjointEigenSolver<Mat3> ej(id.estimate().j);
    o.physical = ej.eigenvalues()(0) > 0.0 && ej.eigenvalues()(0) + ej.eigenvalues()(1) >= ej.eigenvalues()(2);
    return o;
  };
  const Outcome strict = fly(0);
  const Outcome i28 = fly(3);
  std::printf("prior outside the inequality: J at 50 s %.3g (strict, %u refused) -> %.3g (I28, %u refused); "
              "at 300 s %.3g -> %.3g, NEES %.2f; damped steps %u\n",
              strict.j_at_50, strict.refused, i28.j_at_50, i28.refused, strict.j_at_300, i28.j_at_300,
              i28.nees, i28.damped);
  EXPECT_GE(strict.refused, 1u) << "the strict guard loses the first windows";
  EXPECT_GT(strict.j_at_50, 0.2) << "... and J is still far off at 50 s (prior " << (j0 - s.j).norm() / s.j.norm() << ")";
  EXPECT_EQ(i28.refused, 0u);
  EXPECT_LT(i28.j_at_50, 0.5 * strict.j_at_50);
  EXPECT_LT(i28.j_at_300, 0.01);
  EXPECT_LT(i28.nees, test::chi2_quantile(6, 3.09));
  EXPECT_TRUE(i28.physical) << "the estimate has come back inside the inequality";
}

// (I28) A step the guards refuse is halved: with the commands' sign reported wrong, the data say J
// is negative definite. The strict guard refuses those steps; with halvings a step is applied
// only at a fraction the guards accept, J stays positive definite, and no step pushes it out of
// the triangle inequality it met.
TEST(Identifier, AStepTheGuardsRefuseIsHalvedUntilTheyAcceptIt) {
  TruthSetup s;
  s.j = study_j();
  s.r = study_true_mass_properties().r_so_bcm;
  s.omega0 = Vec3(1e-3, -1e-3, 5e-4);
  for (const int halvings : {0, 3}) {
    Identifier id;
    IdentifierConfig c = config_with_priors(s.j, s.r);
    c.j_prior_sigma = 1e8;
    c.guard_halvings = halvings;
    id.configure(c);
    TruthRun truth(s);
    RandomFiring fire(8, 500.0);
    bool always_physical = true;
    truth.run(static_cast<int>(300.0 / kDt), fire, [&](double, const test::V3& w, const test::V8& f) {
      id.update(id_input(w, -f));
      Eigen::SelfAdjointEigenSolver<Mat3> e(id.estimate().j);
      const Vec3 m = e.eigenvalues();
      always_physical = always_physical && m(0) > 0.0 && m(0) + m(1) >= m(2);
    });
    EXPECT_TRUE(always_physical) << halvings;
    if (halvings == 0) {
      EXPECT_EQ(id.counters().damped_steps, 0u);
      EXPECT_GT(id.counters().inertia_refused, 0u);
    } else {
      EXPECT_GT(id.counters().damped_steps, 0u) << "refused " << id.counters().inertia_refused;
    }
  }
}

TEST(Identifier, ReinflationLetsAStrengthEstimateFollowADeclaredFault) {
  TruthSetup s;
  s.j = study_j();
  s.r = study_true_mass_properties().r_so_bcm;
  for (bool declare : {false, true}) {
    Identifier id;
    id.configure(config_with_priors(s.j, s.r));
    TruthRun truth(s);
    RandomFiring fire(12);
    double t_fault = 600.0;
    truth.run(static_cast<int>(1200.0 / kDt), fire,
              [&](double t, const test::V3& w, const test::V8& f) {
                if (std::fabs(t - t_fault) < 1e-6) {
                  truth.set_strength(6, 0.5);  // thruster 6 (pod 1 tangential +) at half thrust
                  if (declare) id.reinflate_thruster(6);
                }
                id.update(id_input(w, f));
              });
    std::printf("declared %d: k6 %.4f\n", declare, id.estimate().k(6));
    if (declare) {
      EXPECT_NEAR(id.estimate().k(6), 0.5, 0.02);
      EXPECT_EQ(id.counters().reinflations, 1u);
    } else {
      EXPECT_GT(std::fabs(id.estimate().k(6) - 0.5), 0.05);  // without it the old data dominate
    }
  }
}

// ---- (I20): the closed forms against their definitions ----

// S(v) x = v x x, written out here.
Mat3 skew(const Vec3& v) {
  Mat3 s;
  s << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return s;
}

Mat3 random_spd3(std::mt19937_64& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  Mat3 a;
  for (int i = 0; i < 9; ++i) a(i) = n(rng);
  return a * a.transpose() + 0.1 * Mat3::Identity();
}

// (I20) cov(a x b) = E[S(a) B S(a)'] for a ~ N(0, A): the explicit sum over A's entries of
// S(e_k) B S(e_l)', and a Monte Carlo estimate.
TEST(IdentifierMath, TheCrossProductCovarianceIsTheSumOverItsEntries) {
  std::mt19937_64 rng(41);
  for (int trial = 0; trial < 5; ++trial) {
    const Mat3 a = random_spd3(rng), b = random_spd3(rng);
    Mat3 sum = Mat3::Zero();
    for (int k = 0; k < 3; ++k) {
      for (int l = 0; l < 3; ++l) sum += a(k, l) * skew(Vec3::Unit(k)) * b * skew(Vec3::Unit(l)).transpose();
    }
    const Mat3 c = cross_product_covariance(a, b);
    EXPECT_LT((c - sum).norm(), 1e-12 * sum.norm());
    EXPECT_LT((cross_product_covariance(b, a) - c).norm(), 1e-12 * sum.norm());  // a x b = -b x a
  }
  // Monte Carlo with independent draws (200 000 samples: 1 % on the entries).
  const Mat3 a = random_spd3(rng), b = random_spd3(rng);
  const Eigen::LLT<Mat3> la(a), lb(b);
  std::normal_distribution<double> n(0.0, 1.0);
  Mat3 mc = Mat3::Zero();
  constexpr int kSamples = 200000;
  for (int i = 0; i < kSamples; ++i) {
    const Vec3 x = la.matrixL() * Vec3(n(rng), n(rng), n(rng));
    const Vec3 y = lb.matrixL() * Vec3(n(rng), n(rng), n(rng));
    const Vec3 z = x.cross(y);
    mc += z * z.transpose();
  }
  mc /= kSamples;
  const Mat3 c = cross_product_covariance(a, b);
  EXPECT_LT((mc - c).norm(), 0.03 * c.norm());
}

// (I20) sum_kl P_b(k, l) B_k P_a B_l' with B_k = S(m) L(e_k) + S(e_k) L(m) formed directly.
TEST(IdentifierMath, TheBilinearBiasCovarianceIsTheSumOverItsEntries) {
  std::mt19937_64 rng(42);
  std::normal_distribution<double> n(0.0, 1.0);
  for (int trial = 0; trial < 5; ++trial) {
    Mat6 g;
    for (int i = 0; i < 36; ++i) g(i) = n(rng);
    const Mat6 p_a = g * g.transpose() + Mat6::Identity();
    const Mat3 p_b = random_spd3(rng);
    const Vec3 m(n(rng), n(rng), n(rng));
    Mat36 b[3];
    for (int k = 0; k < 3; ++k) {
      b[k] = skew(m) * inertia_regressor(Vec3::Unit(k)) + skew(Vec3::Unit(k)) * inertia_regressor(m);
    }
    Mat3 sum = Mat3::Zero();
    for (int k = 0; k < 3; ++k) {
      for (int l = 0; l < 3; ++l) sum += p_b(k, l) * b[k] * p_a * b[l].transpose();
    }
    Mat36 bpa[3];
    bias_jacobian_times(m, p_a, bpa);
    for (int k = 0; k < 3; ++k) EXPECT_LT((bpa[k] - b[k] * p_a).norm(), 1e-12 * (b[k] * p_a).norm());
    EXPECT_LT((bilinear_bias_covariance(m, bpa, p_b) - sum).norm(), 1e-12 * sum.norm());
  }
}

TEST(Identifier, ADiscardedWindowIsCountedAndLeavesTheEstimateAlone) {
  Identifier id;
  id.configure(config_with_priors(study_j(), Vec3::Zero()));
  for (int k = 0; k < 50; ++k)
    id.update(id_input(Vec3(0.01, 0.02, 0.03), test::V8::Constant(10.0)));
  IdentifierInput bad = id_input(Vec3(0.01, 0.02, 0.03), test::V8::Zero());
  bad.omega_valid = false;
  id.update(bad);
  EXPECT_EQ(id.counters().windows_discarded, 1u);
  EXPECT_EQ(id.counters().windows, 0u);
  EXPECT_EQ(id.estimate().j, study_j());
}

}  // namespace
}  // namespace rocksteady::gnc

namespace rocksteady::gnc {
namespace {

// (I26) A closed-loop despin: a rate damper tau = -K omega_measured (the D of the study's D+PD,
// K = 1e4 N m s) on the pseudoinverse of the true torque matrix, thrust clipped to u_max with the
// direction kept, case-6 gyro noise and the 1 N m held disturbance, from the true model's priors
// (so every error below is what the data did to the estimate). The commands answer the gyro's
// noise and the disturbance, which are in the regressor A_J too; as the rate decays each window
// teaches J less while pulling it as much. J's error after 15 000 s, with and without the gate,
// each run without forgetting (gnc.yaml), against the identifier's own 1 sigma.
struct DespinErrors {
  double j_rel{0.0};        // |J_hat - J| / |J|
  double j_sigma_rel{0.0};  // largest reported 1 sigma of J's parameters / |J|
  double r{0.0};            // |r_hat - r|, m
  double r_nees{0.0};       // with the reported covariance, 3 dof
};
DespinErrors closed_loop_despin(double min_j_information, double min_r_information) {
  TruthSetup s;
  s.j = study_j();
  s.r = study_true_mass_properties().r_so_bcm;
  s.disturbance_sigma = 1.0 / std::sqrt(3.0);
  s.gyro_sigma = std::sqrt(1e-10 / kDt);  // case 6
  s.seed = 61;
  IdentifierConfig c = config_with_priors(s.j, s.r);
  c.window_s = 60.0;  // the flight's window with a noisy gyro
  c.gyro_sigma = s.gyro_sigma;
  c.second_order_noise = true;
  c.j_forget_s = 0.0;
  c.r_forget_s = 0.0;
  c.min_inertia_information = min_j_information;
  c.min_offset_information = min_r_information;
  Identifier id;
  id.configure(c);
  const RcsLayout rcs = study_rcs_layout(200.0);
  const Mat38 b = torque_matrix(rcs, s.r);
  const Eigen::Matrix<double, 8, 3> b_pinv = b.transpose() * (b * b.transpose()).inverse();
  auto damper = [&](double, const test::V3& w) {
    test::V8 u = b_pinv * (-1e4 * w);
    const double peak = u.cwiseAbs().maxCoeff();
    if (peak > 200.0) u *= 200.0 / peak;
    return u;
  };
  TruthRun truth(s);
  truth.run(static_cast<int>(15000.0 / kDt), damper,
            [&](double, const test::V3& w, const test::V8& f) { id.update(id_input(w, f)); });
  DespinErrors e;
  e.j_rel = j_error(id, s.j);
  e.j_sigma_rel = id.inertia_covariance().diagonal().cwiseSqrt().maxCoeff() / s.j.norm();
  const Vec3 dr = id.estimate().r - s.r;
  e.r = dr.norm();
  e.r_nees = dr.dot(id.offset_covariance().ldlt().solve(dr));
  return e;
}

TEST(Identifier, LateWeakWindowsOfAClosedLoopDespinDoNotPullTheInertia) {
  const DespinErrors g = closed_loop_despin(1.0, 0.0);
  const DespinErrors o = closed_loop_despin(0.0, 0.0);
  const double gated = g.j_rel, sigma_gated = g.j_sigma_rel;
  const double open = o.j_rel, sigma_open = o.j_sigma_rel;
  std::printf("15 000 s closed-loop despin, case-6 gyro: |dJ|/|J| gated %.3g (1 sigma %.3g), "
              "every window %.3g (1 sigma %.3g)\n",
              gated, sigma_gated, open, sigma_open);
  // Measured: gated 2.6 % (the early windows' own bias, within its 1 sigma of 1.1 %), every
  // window 16.6 % against a 1 sigma of 1.0 %.
  EXPECT_GT(open, 4.0 * gated);
  // The gated error is within 3 of its largest reported 1 sigma; the ungated one is far outside.
  EXPECT_LT(gated, 3.0 * sigma_gated);
  EXPECT_GT(open, 10.0 * sigma_open);
}

// (I26) for r: the same despin with J gated, r gated as well or not. The damper's net force is
// small and turns with the rate; late windows carry almost nothing about r but the correlated
// noise, and r wanders with them.
TEST(Identifier, LateWeakWindowsOfAClosedLoopDespinDoNotPullTheOffset) {
  const DespinErrors g = closed_loop_despin(1.0, 1.0);
  const DespinErrors o = closed_loop_despin(1.0, 0.0);
  std::printf("15 000 s closed-loop despin, case-6 gyro: |dr| gated %.3g m (NEES %.3g), every "
              "window %.3g m (NEES %.3g)\n",
              g.r, g.r_nees, o.r, o.r_nees);
  // Measured: 0.23 m (NEES 5.0) against 0.54 m (NEES 65).
  EXPECT_LT(2.0 * g.r, o.r);
  EXPECT_LT(g.r_nees, test::chi2_quantile(3, 3.09));
  EXPECT_GT(o.r_nees, test::chi2_quantile(3, 3.09));
}

}  // namespace
}  // namespace rocksteady::gnc
