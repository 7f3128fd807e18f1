// The MEKF against an independent truth (tests/common rigid body, tests/estimation sensors).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Cholesky>

#include "estimation_truth.hpp"
#include "gnc/estimation/mekf.hpp"
#include "gnc/math/rotation.hpp"

namespace rocksteady::gnc {
namespace {

using test::attitude_error;
using test::chi2_quantile;
using test::RigidBody;
using test::SensorNoise;
using test::Sensors;

constexpr double kDt = 0.1;

MekfConfig config_for(const SensorNoise& n) {
  MekfConfig c;
  c.dt = kDt;
  c.gyro_arw = n.gyro_arw;
  c.gyro_bias_rw = n.gyro_bias_rw;
  c.star_sigma = n.star_sigma;
  c.init_attitude_sigma = 3.0 * n.star_sigma;
  c.init_bias_sigma = 1e-3;
  return c;
}

MekfInput input(double t, const Vec3& gyro, const Vec4& star) {
  MekfInput in;
  in.t = t;
  in.gyro_rate = gyro;
  in.gyro_valid = true;
  in.star_quat = star;
  in.star_valid = true;
  return in;
}

// A seeded run: a body tumbling torque-free (so the rate changes within each tick), sensors with
// the configured noise, the filter following. Calls `each(k, filter, truth, sensors)` per tick.
template <typename F>
void run(const SensorNoise& noise, const MekfConfig& c, unsigned long long seed, int ticks,
         const Vec3& bias0, F each) {
  RigidBody body;
  body.j = Vec3(3.0e7, 3.5e7, 4.0e7).asDiagonal();
  body.omega = Vec3(2e-3, -1e-3, 1.5e-3);
  body.beta = test::axis_angle(Vec3(1, 2, 3), 0.7);
  Sensors s(noise, kDt, seed, bias0);
  Mekf f;
  f.configure(c);
  for (int k = 0; k < ticks; ++k) {
    if (k > 0) {
      body.step(kDt, Vec3::Zero());
      s.step_bias();
    }
    f.update(input(k * kDt, s.gyro(body.omega), s.star(body.beta)));
    each(k, f, body, s);
  }
}

TEST(MekfConfig, DefaultsAreValid) {
  EXPECT_TRUE(validate(MekfConfig{}).ok);
}

TEST(MekfConfig, NamesTheFirstBadField) {
  struct Case {
    void (*mutate)(MekfConfig&);
    const char* field;
  };
  const Case cases[] = {
      {[](MekfConfig& c) { c.dt = 0.0; }, "dt"},
      {[](MekfConfig& c) { c.gyro_arw = -1.0; }, "gyro_arw"},
      {[](MekfConfig& c) { c.gyro_bias_rw = std::nan(""); }, "gyro_bias_rw"},
      {[](MekfConfig& c) { c.star_sigma = 0.0; }, "star_sigma"},
      {[](MekfConfig& c) { c.model_sigma = -1.0; }, "model_sigma"},
      {[](MekfConfig& c) { c.gyro_arw = 0.0; }, "gyro_arw"},  // no attitude process noise
      {[](MekfConfig& c) { c.init_attitude_sigma = 0.0; }, "init_attitude_sigma"},
      {[](MekfConfig& c) { c.init_bias_sigma = -1.0; }, "init_bias_sigma"},
      {[](MekfConfig& c) { c.init_bias.x() = INFINITY; }, "init_bias"},
      {[](MekfConfig& c) { c.gate_chi2 = 0.0; }, "gate_chi2"},
      {[](MekfConfig& c) { c.max_consecutive_rejects = 0; }, "max_consecutive_rejects"},
      {[](MekfConfig& c) { c.gyro_max_rate = 0.0; }, "gyro_max_rate"},
      {[](MekfConfig& c) { c.quat_norm_tolerance = 1.0; }, "quat_norm_tolerance"},
      {[](MekfConfig& c) { c.rate_cutoff = -0.1; }, "rate_cutoff"},
      {[](MekfConfig& c) { c.rate_cutoff = INFINITY; }, "rate_cutoff"},
  };
  for (const Case& cs : cases) {
    MekfConfig c;
    cs.mutate(c);
    const MekfConfigCheck r = validate(c);
    EXPECT_FALSE(r.ok) << cs.field;
    EXPECT_EQ(std::string(r.field), cs.field);
    EXPECT_GT(std::string(r.reason).size(), 0u);
  }
}

TEST(Mekf, TransitionIsTheMatrixExponentialOfTheErrorDynamics) {
  // F = [[-S(w), -I], [0, 0]]; Phi = exp(F dt) by a 40-term Taylor series.
  for (const Vec3& w : {Vec3(0.3, -0.2, 0.5), Vec3(1e-5, 2e-5, -1e-5), Vec3::Zero().eval()}) {
    for (double dt : {0.1, 2.0}) {
      Mat6 f = Mat6::Zero();
      Mat3 s;
      s << 0, -w.z(), w.y(), w.z(), 0, -w.x(), -w.y(), w.x(), 0;
      f.topLeftCorner<3, 3>() = -s;
      f.topRightCorner<3, 3>() = -Mat3::Identity();
      Mat6 term = Mat6::Identity(), sum = Mat6::Identity();
      for (int n = 1; n < 40; ++n) {
        term = term * f * dt / n;
        sum += term;
      }
      EXPECT_LT((Mekf::transition(w, dt) - sum).norm(), 1e-12 * (1.0 + sum.norm()))
          << w.transpose() << " dt " << dt;
    }
  }
}

TEST(Mekf, InitialisesFromTheFirstSampleAndOutputsTheSameMrpSetAsTheStateFilter) {
  Mekf f;
  f.configure(MekfConfig{});
  MekfInput in = input(0.0, Vec3(1e-3, 2e-3, 3e-3), test::axis_angle(Vec3(0, 0, 1), 3.0));
  in.star_valid = false;
  f.update(in);
  EXPECT_FALSE(f.initialised());
  in.star_valid = true;
  f.update(in);
  ASSERT_TRUE(f.initialised());
  // 3 rad about z: the |q| <= 1 MRP is tan(3/4) z (the other set, -cot(3/4) z, has |q| > 1).
  EXPECT_NEAR(f.q().z(), std::tan(3.0 / 4.0), 1e-12);
  EXPECT_LE(f.q().norm(), 1.0);
  EXPECT_LT((f.omega() - Vec3(1e-3, 2e-3, 3e-3)).norm(), 1e-15);
}

TEST(Mekf, NeesWithinChiSquareBoundsOverSeededRuns) {
  // M independent runs; at each checked time the sum over runs of the 6-state NEES is chi-square
  // with 6M dof when the filter is consistent. Checked at 50 times: the sum must lie in the
  // two-sided 95 % band at (nearly) all of them, and the average NEES per state must be ~1.
  SensorNoise n;
  n.gyro_arw = 1e-5;
  n.gyro_bias_rw = 1e-7;
  n.star_sigma = 1e-3;
  MekfConfig c = config_for(n);
  c.init_bias_sigma = 1e-4;
  const int runs = 30, ticks = 3000, every = 60, first = 60;
  const int checks = (ticks - first) / every;
  std::vector<double> sum(checks, 0.0), sum_att(checks, 0.0);
  for (int m = 0; m < runs; ++m) {
    std::mt19937_64 init(1000 + m);
    std::normal_distribution<double> g(0.0, 1.0);
    const Vec3 bias0 = 1e-4 * Vec3(g(init), g(init), g(init));  // drawn from the filter's prior
    run(n, c, 77 + m, ticks, bias0,
        [&](int k, const Mekf& f, const RigidBody& b, const Sensors& s) {
          if (k < first || (k - first) % every != 0 || (k - first) / every >= checks) return;
          const int i = (k - first) / every;
          Vec6 e;
          e.head<3>() = attitude_error(f.quaternion(), b.beta);
          e.tail<3>() = s.bias() - f.bias();
          sum[i] += e.dot(f.covariance().ldlt().solve(e));
          const Vec3 ea = e.head<3>();
          sum_att[i] += ea.dot(f.covariance().topLeftCorner<3, 3>().ldlt().solve(ea));
        });
  }
  const double lo = chi2_quantile(6.0 * runs, -1.96), hi = chi2_quantile(6.0 * runs, 1.96);
  const double lo3 = chi2_quantile(3.0 * runs, -1.96), hi3 = chi2_quantile(3.0 * runs, 1.96);
  int inside = 0, inside_att = 0;
  double mean = 0.0, mean_att = 0.0;
  for (int i = 0; i < checks; ++i) {
    inside += sum[i] > lo && sum[i] < hi;
    inside_att += sum_att[i] > lo3 && sum_att[i] < hi3;
    mean += sum[i] / (6.0 * runs * checks);
    mean_att += sum_att[i] / (3.0 * runs * checks);
  }
  std::printf(
      "NEES per state %.3f (attitude %.3f); inside the 95%% band at %d and %d of %d times\n", mean,
      mean_att, inside, inside_att, checks);
  EXPECT_GE(inside, static_cast<int>(0.85 * checks));
  EXPECT_GE(inside_att, static_cast<int>(0.85 * checks));
  EXPECT_NEAR(mean, 1.0, 0.15);
  EXPECT_NEAR(mean_att, 1.0, 0.15);
}

TEST(Mekf, CovarianceStaysSymmetricPositiveDefinite) {
  SensorNoise n;
  n.gyro_arw = 1e-6;
  n.gyro_bias_rw = 1e-9;
  n.star_sigma = 1e-4;
  MekfConfig c = config_for(n);
  c.init_bias_sigma = 1e-2;  // a large initial uncertainty: the hard case for the update
  int bad = 0;
  run(n, c, 5, 5000, Vec3(3e-3, -2e-3, 1e-3),
      [&](int, const Mekf& f, const RigidBody&, const Sensors&) {
        const Mat6& p = f.covariance();
        if ((p - p.transpose()).norm() != 0.0) ++bad;
        if (Eigen::LLT<Mat6>(p).info() != Eigen::Success) ++bad;
        if (p.diagonal().minCoeff() <= 0.0) ++bad;
      });
  EXPECT_EQ(bad, 0);
}

// The filter's covariance recursion (3x3 block forms of Phi P Phi' + Q and of the Joseph update)
// against the dense 6x6 formulas written out here, tick by tick on a seeded tumbling run with a
// large initial bias uncertainty (full cross-covariances).
TEST(Mekf, BlockCovarianceRecursionEqualsTheDenseFormulas) {
  SensorNoise n;
  n.gyro_arw = 1e-6;
  n.gyro_bias_rw = 1e-9;
  n.star_sigma = 1e-4;
  MekfConfig c = config_for(n);
  c.init_bias_sigma = 1e-2;
  RigidBody body;
  body.j = Vec3(3.0e7, 3.5e7, 4.0e7).asDiagonal();
  body.omega = Vec3(2e-2, -1e-2, 1.5e-2);
  body.beta = test::axis_angle(Vec3(1, 2, 3), 0.7);
  Sensors sensors(n, kDt, 11, Vec3(3e-3, -2e-3, 1e-3));
  Mekf f;
  f.configure(c);
  Vec3 last_gyro = Vec3::Zero();
  int compared = 0;
  double worst = 0.0;
  for (int k = 0; k < 600; ++k) {
    if (k > 0) {
      body.step(kDt, Vec3::Zero());
      sensors.step_bias();
    }
    const Vec3 gyro = sensors.gyro(body.omega);
    const Vec4 star = sensors.star(body.beta);
    const bool was_initialised = f.initialised();
    const Mat6 p0 = f.covariance();
    const Vec3 b0 = f.bias();
    const std::uint32_t gated0 = f.counters().gated;
    f.update(input(k * kDt, gyro, star));
    if (was_initialised && f.counters().gated == gated0) {
      const Mat6 phi = Mekf::transition(0.5 * (last_gyro + gyro) - b0, kDt);
      const Mat6 pm = phi * p0 * phi.transpose() + f.process_noise();
      const double r = c.star_sigma * c.star_sigma;
      const Mat3 s_mat = pm.topLeftCorner<3, 3>() + r * Mat3::Identity();
      const Eigen::Matrix<double, 6, 3> kg = pm.leftCols<3>() * s_mat.inverse();
      Mat6 ikh = Mat6::Identity();
      ikh.leftCols<3>() -= kg;
      const Mat6 pp = ikh * pm * ikh.transpose() + r * kg * kg.transpose();
      const double err = (f.covariance() - pp).norm() / pp.norm();
      worst = std::max(worst, err);
      ++compared;
    }
    last_gyro = gyro;
  }
  EXPECT_GT(compared, 550);
  EXPECT_LT(worst, 1e-9);
}

TEST(Mekf, BiasConvergesToTheTruth) {
  SensorNoise n;
  n.gyro_arw = 1e-6;  // case 5: P(dw) = 1e-12
  n.gyro_bias_rw = 0.0;
  n.star_sigma = 4.0 * std::sqrt(1e-8 / kDt);  // case 5: P(dq) = 1e-8, dtheta = 4 dq
  MekfConfig c = config_for(n);
  c.gyro_bias_rw = 1e-10;
  const Vec3 bias(5e-5, -3e-5, 2e-5);  // ~10 deg/h
  Vec3 err0 = Vec3::Zero(), err = Vec3::Zero(), sigma = Vec3::Zero(), sigma0 = Vec3::Zero();
  run(n, c, 11, 18000, bias, [&](int k, const Mekf& f, const RigidBody&, const Sensors& s) {
    if (k == 0) {
      err0 = s.bias() - f.bias();
      sigma0 = f.bias_sigma();
    }
    err = s.bias() - f.bias();
    sigma = f.bias_sigma();
  });
  EXPECT_GT(err0.norm(), 5e-5);
  for (int a = 0; a < 3; ++a) {
    EXPECT_LT(std::fabs(err(a)), 3.0 * sigma(a)) << "axis " << a;
    EXPECT_LT(sigma(a), 0.01 * sigma0(a));
  }
  EXPECT_LT(err.norm(), 0.05 * bias.norm());
}

TEST(Mekf, GateRejectsAnOutlierAndCountsIt) {
  SensorNoise n;
  n.gyro_arw = 1e-6;
  n.star_sigma = 1e-4;
  Mekf f;
  f.configure(config_for(n));
  RigidBody body;
  body.omega = Vec3(1e-3, 0, 0);
  Sensors s(n, kDt, 3, Vec3::Zero());
  int k = 0;
  for (; k < 600; ++k) {
    if (k > 0) body.step(kDt, Vec3::Zero());
    f.update(input(k * kDt, s.gyro(body.omega), s.star(body.beta)));
  }
  const MekfCounters before = f.counters();
  const double err_before = attitude_error(f.quaternion(), body.beta).norm();
  // One star sample 2 degrees off.
  body.step(kDt, Vec3::Zero());
  const Vec4 outlier = test::qmul(body.beta, test::axis_angle(Vec3(1, -1, 0), 2.0 * M_PI / 180));
  f.update(input(k * kDt, s.gyro(body.omega), outlier));
  ++k;
  EXPECT_EQ(f.counters().gated, before.gated + 1);
  EXPECT_EQ(f.counters().updates, before.updates);
  EXPECT_GT(f.innovation_chi2(), 16.27);
  EXPECT_LT(attitude_error(f.quaternion(), body.beta).norm(), err_before + 5e-5);
  // The next good sample is used.
  body.step(kDt, Vec3::Zero());
  f.update(input(k * kDt, s.gyro(body.omega), s.star(body.beta)));
  EXPECT_EQ(f.counters().updates, before.updates + 1);
  EXPECT_EQ(f.counters().gated, before.gated + 1);
}

TEST(Mekf, APersistentJumpReinitialisesAfterTheConfiguredRejections) {
  SensorNoise n;
  n.star_sigma = 1e-4;
  MekfConfig c = config_for(n);
  c.max_consecutive_rejects = 5;
  Mekf f;
  f.configure(c);
  Sensors s(n, kDt, 4, Vec3::Zero());
  const Vec4 truth = test::axis_angle(Vec3(0, 1, 0), 0.3);
  for (int k = 0; k < 300; ++k) f.update(input(k * kDt, s.gyro(Vec3::Zero()), s.star(truth)));
  const Vec4 moved = test::qmul(truth, test::axis_angle(Vec3(0, 0, 1), 0.2));
  for (int k = 300; k < 305; ++k) f.update(input(k * kDt, s.gyro(Vec3::Zero()), s.star(moved)));
  EXPECT_EQ(f.counters().reinitialised, 1u);
  EXPECT_LT(attitude_error(f.quaternion(), moved).norm(), 1e-3);
}

TEST(Mekf, AHeldStarSampleIsNotUsedTwiceAndBadInputIsCounted) {
  Mekf f;
  f.configure(MekfConfig{});
  const Vec4 b = test::axis_angle(Vec3(1, 0, 0), 0.1);
  f.update(input(0.0, Vec3::Zero(), b));
  f.update(input(0.1, Vec3::Zero(), b));
  EXPECT_EQ(f.counters().updates, 1u);
  f.update(input(0.1, Vec3::Zero(), b));  // same sample time
  EXPECT_EQ(f.counters().updates, 1u);
  MekfInput bad = input(0.2, Vec3(5.0, 0, 0), 2.0 * b);  // rate too high, quaternion not unit
  f.update(bad);
  EXPECT_EQ(f.counters().rejected_input, 1u);
  EXPECT_EQ(f.counters().updates, 1u);
  EXPECT_LT(f.omega().norm(), 1e-15);  // the last good gyro sample is held
}


// (M8) The rate stage on a torque-free tumble with the true J: the estimate is the model's
// prediction pulled towards the bias-corrected gyro with gain K = 1 - exp(-w_r dt). Its error is
// then the gyro's white noise through a first-order filter, whose variance ratio is K / (2 - K)
// (closed form of y_k = (1 - K) y_{k-1} + K x_k with white x), against 1 for the raw gyro; the
// bias error passes at unit gain in both, so the bias is known here (zero).
TEST(Mekf, RateStageFiltersTheGyroNoiseToTheFirstOrderClosedForm) {
  SensorNoise n;
  n.gyro_arw = 1e-5;  // per-sample sigma 3.2e-5 rad/s, as study cases 6-7
  n.star_sigma = 1e-4;
  const Mat3 j = Vec3(3.0e7, 3.5e7, 4.0e7).asDiagonal();
  double var_raw = 0.0, var_stage = 0.0;
  int count = 0;
  double gain = 0.0;
  for (double cutoff : {0.0, 0.02 * 3.141592653589793}) {
    MekfConfig c = config_for(n);
    c.init_bias_sigma = 1e-9;  // the bias is known: the rate error is the white noise alone
    c.rate_cutoff = cutoff;
    ASSERT_TRUE(validate(c).ok);
    RigidBody body;
    body.j = j;
    body.omega = Vec3(2e-2, -1e-2, 1.5e-2);
    body.beta = test::axis_angle(Vec3(1, 2, 3), 0.7);
    Sensors sensors(n, kDt, 77, Vec3::Zero());
    Mekf f;
    f.configure(c);
    f.set_rate_model(j);
    double sum = 0.0;
    int samples = 0;
    for (int k = 0; k < 20000; ++k) {
      if (k > 0) body.step(kDt, Vec3::Zero());
      f.update(input(k * kDt, sensors.gyro(body.omega), sensors.star(body.beta)));
      if (k >= 2000) {  // after the stage's transient (time constant 16 s)
        sum += (f.omega() - body.omega).squaredNorm() / 3.0;
        ++samples;
      }
    }
    (cutoff > 0.0 ? var_stage : var_raw) = sum / samples;
    count = samples;
    gain = 1.0 - std::exp(-cutoff * kDt);
  }
  const double white = n.gyro_arw * n.gyro_arw / kDt;
  // The raw output carries the per-sample variance (3 x 18000 samples: within 3 %).
  EXPECT_NEAR(var_raw / white, 1.0, 0.03) << count;
  // The stage: K / (2 - K) = 3.1e-3 of it, an 18x smaller sigma. The filtered errors are
  // correlated over ~1/K samples, so 18000 of them are ~110 independent ones: within 25 %.
  const double expected = gain / (2.0 - gain);
  EXPECT_NEAR(var_stage / white / expected, 1.0, 0.25)
      << "stage " << var_stage << " expected " << expected * white;
}

// (M8) With the stage on, a missing gyro sample is carried by the model (Eq. 2 with the torque
// commanded), not by the held sample: a body under a known constant torque. The attitude is
// propagated with that rate too, so the star tracker keeps agreeing with it (nothing gated).
TEST(Mekf, RateStageCarriesAMissingGyroSampleThroughTheModel) {
  SensorNoise n;
  n.gyro_arw = 1e-9;
  n.star_sigma = 1e-6;
  MekfConfig c = config_for(n);
  c.init_bias_sigma = 1e-9;  // the bias is known: the stage's model alone carries the rate
  c.rate_cutoff = 0.5;
  const Mat3 j = Vec3(3.0e7, 3.5e7, 4.0e7).asDiagonal();
  RigidBody body;
  body.j = j;
  body.omega = Vec3(1e-3, 0.0, 0.0);
  body.beta = quat::identity();
  const Vec3 torque(0.0, 300.0, -200.0);
  Sensors sensors(n, kDt, 5, Vec3::Zero());
  Mekf f;
  f.configure(c);
  f.set_rate_model(j);
  for (int k = 0; k < 400; ++k) {
    if (k > 0) body.step(kDt, torque);
    MekfInput in = input(k * kDt, sensors.gyro(body.omega), sensors.star(body.beta));
    in.torque = torque;
    if (k >= 300) in.gyro_valid = false;  // the last 10 s without a gyro
    f.update(in);
  }
  // 10 s of 300 N m on 3.5e7 kg m^2 is 8.6e-5 rad/s: the held sample would be that far off.
  EXPECT_LT((f.omega() - body.omega).norm(), 1e-6) << (f.omega() - body.omega).transpose();
  EXPECT_EQ(f.counters().gated, 0u);
  EXPECT_EQ(f.counters().reinitialised, 0u);
}

// A running filter re-configured (a new parameter table re-configures every component) keeps its
// estimate and covariance; reset() forgets them.
TEST(Mekf, ReconfiguringARunningFilterKeepsItsEstimate) {
  SensorNoise n;
  const MekfConfig c = config_for(n);
  Mekf kept;
  run(n, c, 11, 600, Vec3(2e-5, -1e-5, 3e-5), [&](int, const Mekf& f, const RigidBody&, const Sensors&) {
    kept = f;
  });
  ASSERT_TRUE(kept.initialised());
  const Vec3 bias = kept.bias();
  const Mat6 p = kept.covariance();
  kept.configure(c);
  EXPECT_TRUE(kept.initialised());
  EXPECT_EQ(kept.bias(), bias);
  EXPECT_EQ(kept.covariance(), p);
  kept.reset();
  EXPECT_FALSE(kept.initialised());
}

TEST(Mekf, HoldAttitudeErrorMatchesFarrenkopfSteadyState) {
  // Case 5 noise (SPEC §5) with a small bias random walk, body at rest (HOLD).
  SensorNoise n;
  n.gyro_arw = std::sqrt(1e-12);
  n.gyro_bias_rw = 1e-9;
  n.star_sigma = 4.0 * std::sqrt(1e-8 / kDt);
  MekfConfig c = config_for(n);
  const double analytic =
      test::farrenkopf_post_update_sigma(n.gyro_arw, n.gyro_bias_rw, n.star_sigma, kDt);
  Mekf f;
  f.configure(c);
  Sensors s(n, kDt, 21, Vec3(1e-6, -2e-6, 0.5e-6));
  const Vec4 truth = test::axis_angle(Vec3(0.3, -0.2, 1.0), 0.4);
  double sq = 0.0;
  int count = 0;
  const int ticks = 60000;
  for (int k = 0; k < ticks; ++k) {
    s.step_bias();
    f.update(input(k * kDt, s.gyro(Vec3::Zero()), s.star(truth)));
    if (k >= 20000) {
      sq += attitude_error(f.quaternion(), truth).squaredNorm();
      ++count;
    }
  }
  const double empirical = std::sqrt(sq / (3.0 * count));
  const double reported = f.attitude_sigma().mean();
  std::printf("HOLD attitude sigma: empirical %.4g rad, filter %.4g rad, Farrenkopf %.4g rad\n",
              empirical, reported, analytic);
  EXPECT_NEAR(reported, analytic, 0.01 * analytic);
  EXPECT_NEAR(empirical, analytic, 0.25 * analytic);
}

}  // namespace
}  // namespace rocksteady::gnc
