// The Gnc component: parameter validation, modes, trajectory handling, estimator, closed loop.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include "gnc/gnc.hpp"
#include "gnc_harness.hpp"

namespace rocksteady::gnc {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// ---------------------------------------------------------------- parameter validation
TEST(ParamValidation, StudyParametersAreValid) {
  for (double u_max : {200.0, 1000.0}) {
    const ParamCheck c = validate(study_gnc_params(u_max));
    EXPECT_TRUE(c.ok) << c.field << ": " << c.reason;
  }
}

struct BadCase {
  const char* name;
  void (*mutate)(GncParams&);
  const char* field;
  const char* reason_contains;
};

const BadCase kBadCases[] = {
    {"NonPositiveDefiniteInertia", [](GncParams& p) { p.mass_hat.j_ast(2, 2) = -1e7; },
     "mass_hat.j_ast", "positive definite"},
    {"AsymmetricInertia", [](GncParams& p) { p.mass_hat.j_ast(0, 1) += 1e6; }, "mass_hat.j_ast",
     "symmetric"},
    {"NonPositiveDefiniteGain", [](GncParams& p) { p.ntcl.k(1, 1) = 0.0; }, "ntcl.K",
     "positive definite"},
    {"NegativeIntegralGain", [](GncParams& p) { p.integral.k_i = -Mat3::Identity(); },
     "integral.K_I", "positive definite"},
    {"NonFiniteGain", [](GncParams& p) { p.so3.lambda(0, 0) = kNaN; }, "so3.Lambda", "non-finite"},
    {"NonFiniteOffset", [](GncParams& p) { p.mass_hat.r_so_bcm.x() = kNaN; },
     "mass_hat.r_so_bcm", "non-finite"},
    {"RankDeficientB",
     [](GncParams& p) {
       for (auto& d : p.rcs.channel_direction) d = Vec3(0, 0, 1);
     },
     "rcs", "rank-deficient"},
    {"NonUnitThrusterDirection", [](GncParams& p) { p.rcs.channel_direction[3] *= 2.0; },
     "rcs.channel_direction", "unit"},
    {"ZeroUmax", [](GncParams& p) { p.rcs.u_max = 0.0; }, "rcs.u_max", "positive"},
    {"NonPositiveRate", [](GncParams& p) { p.dt = 0.0; }, "dt", "positive"},
    {"SwitchAboveEnvelope", [](GncParams& p) { p.guidance.omega_switch = 1.0; },
     "guidance.omega_switch", "eps_trans"},
    {"NegativeResetPeriod", [](GncParams& p) { p.guidance.track_reset_period_s = -1.0; },
     "guidance.track_reset_period", ">= 0"},
    {"NegativeSlew", [](GncParams& p) { p.guidance.slew_s = -1.0; }, "guidance.slew", ">= 0"},
    {"ZeroSlewRamp", [](GncParams& p) { p.guidance.slew_ramp_s = 0.0; }, "guidance.slew_ramp",
     "positive"},
    {"NegativeMomentumGain", [](GncParams& p) { p.guidance.track_momentum_k = -1e-3; },
     "guidance.track_momentum_k", ">= 0"},
    {"NonFiniteMomentumGain", [](GncParams& p) { p.guidance.track_momentum_k = std::nan(""); },
     "guidance.track_momentum_k", ">= 0"},
    {"FilterCutoffAboveNyquist", [](GncParams& p) { p.estimator.omega_c = 100.0; },
     "estimator.omega_c", "Nyquist"},
    {"SensorTimeoutBelowPeriod", [](GncParams& p) { p.mode.sensor_timeout_s = 0.01; },
     "mode.sensor_timeout", "period"},
    {"BootIntoTrack", [](GncParams& p) { p.mode.initial = Mode::kTrack; }, "mode.initial",
     "TRACK"},
    {"ProjectionFloorAboveOne", [](GncParams& p) { p.adaptive.eig_floor_ratio = 1.5; },
     "adaptive.eig_floor_ratio", "(0, 1)"},
};

class BadParams : public ::testing::TestWithParam<BadCase> {};

TEST_P(BadParams, AreRejectedWithFieldAndReason) {
  GncParams p = study_gnc_params(200.0);
  GetParam().mutate(p);
  const ParamCheck c = validate(p);
  EXPECT_FALSE(c.ok);
  EXPECT_STREQ(c.field, GetParam().field);
  EXPECT_NE(std::string(c.reason).find(GetParam().reason_contains), std::string::npos) << c.reason;
  Gnc g;
  EXPECT_FALSE(g.init(p).ok);  // and the component refuses it
}

INSTANTIATE_TEST_SUITE_P(Classes, BadParams, ::testing::ValuesIn(kBadCases),
                         [](const auto& param_info) { return std::string(param_info.param.name); });

// ---------------------------------------------------------------- mode manager
TEST(ModeManager, TransitionTable) {
  TransitionContext ok{true, true, LawId::kNtcl};
  const Mode all[] = {Mode::kIdle, Mode::kDetumble, Mode::kHold, Mode::kTrack, Mode::kSafe};
  for (Mode from : all) {
    for (Mode to : all) {
      const TransitionCheck c = check_transition(from, to, ok);
      if (from == to) {
        EXPECT_EQ(c, TransitionCheck::kSameMode);
      } else if (from == Mode::kSafe && (to == Mode::kHold || to == Mode::kTrack)) {
        EXPECT_EQ(c, TransitionCheck::kNotAllowed);  // SAFE is left through IDLE or DETUMBLE only
      } else {
        EXPECT_EQ(c, TransitionCheck::kOk) << to_string(from) << "->" << to_string(to);
      }
    }
  }
  EXPECT_EQ(check_transition(Mode::kIdle, Mode::kTrack, {true, false, LawId::kNtcl}),
            TransitionCheck::kNoTrajectory);
  EXPECT_EQ(check_transition(Mode::kIdle, Mode::kTrack, {true, true, LawId::kDpd}),
            TransitionCheck::kLawCannotTrack);
  EXPECT_EQ(check_transition(Mode::kIdle, Mode::kDetumble, {false, true, LawId::kNtcl}),
            TransitionCheck::kNoEstimate);
}

TEST(GncModes, RequestAppliedAtTickStartAndAutoHoldAtOmegaSwitch) {
  test::SmallLoop loop(test::small_vehicle_params());
  ASSERT_TRUE(loop.gnc.init(test::small_vehicle_params()).ok);
  loop.tick();
  EXPECT_EQ(loop.out.telemetry.mode, Mode::kIdle);
  EXPECT_FALSE(loop.out.command.enabled);
  EXPECT_EQ(loop.out.command.force.norm(), 0.0);

  GncCommands c;
  c.has_mode_request = true;
  c.mode_request = Mode::kDetumble;
  loop.tick(c);
  EXPECT_EQ(loop.out.telemetry.mode, Mode::kDetumble);  // the same tick's output already obeys it
  ASSERT_EQ(loop.out.events.count, 1);
  EXPECT_EQ(loop.out.events.items[0].id, EventId::kModeChanged);
  EXPECT_TRUE(loop.out.command.enabled);
  EXPECT_GT(loop.out.command.force.norm(), 0.0);

  bool auto_hold_seen = false;
  for (int i = 0; i < 4000 && !auto_hold_seen; ++i) {
    loop.tick();
    for (int e = 0; e < loop.out.events.count; ++e) {
      if (loop.out.events.items[e].id == EventId::kAutoHold) {
        auto_hold_seen = true;
        EXPECT_LE(loop.out.telemetry.omega_hat.norm(), 0.02);
      }
    }
  }
  EXPECT_TRUE(auto_hold_seen);
  EXPECT_EQ(loop.gnc.mode(), Mode::kHold);

  // A request the table refuses is reported and changes nothing.
  c.mode_request = Mode::kHold;
  loop.tick(c);
  ASSERT_GE(loop.out.events.count, 1);
  EXPECT_EQ(loop.out.events.items[0].id, EventId::kRequestRejected);
  EXPECT_EQ(loop.out.events.items[0].reason, TransitionCheck::kSameMode);
  EXPECT_EQ(loop.gnc.mode(), Mode::kHold);
}

TEST(GncModes, LostSensorsSendToSafeWithThrustersOff) {
  const GncParams p = test::small_vehicle_params();
  test::SmallLoop loop(p);
  ASSERT_TRUE(loop.gnc.init(p).ok);
  GncCommands c;
  c.has_mode_request = true;
  c.mode_request = Mode::kDetumble;
  loop.tick(c);
  ASSERT_EQ(loop.gnc.mode(), Mode::kDetumble);
  SensorSample s = loop.sample();
  s.gyro_valid = false;
  s.star_valid = false;
  bool safe_event = false;
  for (int i = 0; i < 20; ++i) {
    s.t += p.dt;
    loop.gnc.step(s, {}, loop.out);
    for (int e = 0; e < loop.out.events.count; ++e) {
      safe_event |= loop.out.events.items[e].id == EventId::kSensorTimeout;
    }
    if (s.t - loop.t < p.mode.sensor_timeout_s - 1e-9) {
      EXPECT_EQ(loop.gnc.mode(), Mode::kDetumble);  // the model carries the estimate meanwhile
    }
  }
  EXPECT_TRUE(safe_event);
  EXPECT_EQ(loop.gnc.mode(), Mode::kSafe);
  EXPECT_FALSE(loop.out.command.enabled);
  EXPECT_EQ(loop.out.command.force.norm(), 0.0);
  // Ground recovers through IDLE once sensors are back.
  s = loop.sample();
  s.t = 10.0;
  c.mode_request = Mode::kIdle;
  loop.gnc.step(s, c, loop.out);
  EXPECT_EQ(loop.gnc.mode(), Mode::kIdle);
}

TEST(GncModes, NonFiniteAndOutOfRangeSamplesAreRejectedAndCounted) {
  const GncParams p = test::small_vehicle_params();
  test::SmallLoop loop(p);
  ASSERT_TRUE(loop.gnc.init(p).ok);
  loop.tick();
  const Vec3 w_before = loop.out.telemetry.omega_hat;
  SensorSample s = loop.sample();
  s.t += p.dt;
  s.gyro_rate = Vec3(kNaN, 0, 0);
  s.star_quat = Vec4(0, 0, 0, 3.0);  // not a unit quaternion
  loop.gnc.step(s, {}, loop.out);
  EXPECT_EQ(loop.out.telemetry.sensor_rejects, 1u);
  EXPECT_TRUE(loop.out.telemetry.omega_hat.allFinite());
  EXPECT_LT((loop.out.telemetry.omega_hat - w_before).norm(), 1e-2);  // model-carried, not NaN
  s.gyro_rate = Vec3(100.0, 0, 0);  // above gyro_max_rate
  s.star_quat = loop.body.beta;
  loop.gnc.step(s, {}, loop.out);
  EXPECT_EQ(loop.out.telemetry.sensor_rejects, 2u);
  EXPECT_LT(loop.out.telemetry.omega_hat.norm(), 1.0);
}

// ---------------------------------------------------------------- trajectories
TEST(Trajectory, ValidationNamesEachDefect) {
  TrajectoryTable t;
  test::linear_despin_table(Vec3(0.3, -0.2, 0.25), 50.0, t);
  EXPECT_EQ(validate_trajectory(t, 1.0), TrajectoryError::kOk);
  TrajectoryTable bad = t;
  bad.samples[10].omega_d.x() += 1e-9;  // tampered
  EXPECT_EQ(validate_trajectory(bad, 1.0), TrajectoryError::kBadChecksum);
  bad = t;
  bad.samples[5].t = bad.samples[4].t;
  bad.checksum = trajectory_checksum(bad);
  EXPECT_EQ(validate_trajectory(bad, 1.0), TrajectoryError::kTimeNotMonotonic);
  bad = t;
  bad.samples[3].omega_d_dot.y() = kNaN;
  bad.checksum = trajectory_checksum(bad);
  EXPECT_EQ(validate_trajectory(bad, 1.0), TrajectoryError::kNonFinite);
  EXPECT_EQ(validate_trajectory(t, 0.1), TrajectoryError::kRateAboveBound);
  bad = t;
  bad.count = 1;
  EXPECT_EQ(validate_trajectory(bad, 1.0), TrajectoryError::kTooFewSamples);
  bad = t;
  bad.samples[bad.count - 1].omega_d = Vec3(1e-3, 0, 0);
  bad.checksum = trajectory_checksum(bad);
  EXPECT_EQ(validate_trajectory(bad, 1.0), TrajectoryError::kNotAtRestAtEnd);
}

TEST(Trajectory, HermiteInterpolationIsExactForCubicsAndConsistent) {
  // omega_d(t) = a + b t + c t^2 + d t^3 per axis is reproduced exactly by cubic Hermite.
  auto f = [](double t) { return Vec3(1 - 0.2 * t + 0.03 * t * t - 0.001 * t * t * t, 0.5 * t, -t * t * 0.01); };
  auto fd = [](double t) { return Vec3(-0.2 + 0.06 * t - 0.003 * t * t, 0.5, -0.02 * t); };
  TrajectoryTable tab;
  tab.count = 7;
  const double knots[] = {0.0, 0.5, 1.7, 2.0, 4.1, 6.0, 9.0};
  for (int i = 0; i < tab.count; ++i) {
    tab.samples[i].t = knots[i];
    tab.samples[i].omega_d = f(knots[i]);
    tab.samples[i].omega_d_dot = fd(knots[i]);
  }
  for (double t = 0.05; t < 9.0; t += 0.37) {
    const TrajectoryPoint p = interpolate(tab, t);
    EXPECT_LT((p.omega_d - f(t)).norm(), 1e-12) << t;
    EXPECT_LT((p.omega_d_dot - fd(t)).norm(), 1e-11) << t;
  }
  EXPECT_LT((interpolate(tab, 20.0).omega_d - f(9.0)).norm(), 1e-15);
  EXPECT_EQ(interpolate(tab, 20.0).omega_d_dot.norm(), 0.0);
}

// ---------------------------------------------------------------- estimator
TEST(StateFilter, PassThroughIsTheMeasurement) {
  StateFilter f;
  EstimatorParams ep;
  ep.kind = EstimatorKind::kPassThrough;
  f.configure(ep, Mat3::Identity() * 10.0, 0.1);
  Measurement m{Vec3(0.1, 0.2, 0.3), Vec3(0.05, 0.0, -0.1), true, true};
  f.update(m, Vec3::Zero());
  m.omega = Vec3(-0.4, 0.1, 0.0);
  m.q = Vec3(0.2, 0.1, 0.0);
  f.update(m, Vec3(1, 2, 3));
  EXPECT_EQ(f.omega(), m.omega);
  EXPECT_EQ(f.q(), m.q);
}

TEST(StateFilter, PerfectModelMakesAFirstOrderLowPassOfTheInnovation) {
  // Body at rest, measurement with a constant rate bias b: with a perfect model the estimate's
  // error after n ticks is (1-K)^n of the initial one, K = 1 - exp(-omega_c T_s) (SPEC §6).
  EstimatorParams ep;
  ep.kind = EstimatorKind::kFilter;
  ep.omega_c = 0.02 * M_PI;
  const double dt = 0.1;
  StateFilter f;
  f.configure(ep, Vec3(10, 20, 30).asDiagonal(), dt);
  EXPECT_NEAR(f.gain(), 1 - std::exp(-ep.omega_c * dt), 1e-15);
  f.update({Vec3::Zero(), Vec3::Zero(), true, true}, Vec3::Zero());  // initialise at the truth
  const Vec3 step(0, 0, 1e-7);  // a tiny attitude step: far below gyroscopic effects
  for (int n = 1; n <= 200; ++n) {
    f.update({Vec3::Zero(), step, true, true}, Vec3::Zero());
    const double expected = 1.0 - std::pow(1.0 - f.gain(), n);
    EXPECT_NEAR(f.q().z() / step.z(), expected, 1e-9) << n;
  }
}

TEST(StateFilter, PredictionFollowsTheModelBetweenSamples) {
  // With no valid measurement, the filter carries the state through the model (Eq. 2 + Eq. 4):
  // compare with the independent quaternion propagator.
  EstimatorParams ep;
  ep.kind = EstimatorKind::kFilter;
  ep.predict_substeps = 4;
  const Mat3 j = Vec3(10, 20, 30).asDiagonal();
  StateFilter f;
  f.configure(ep, j, 0.1);
  test::RigidBody body;
  body.j = j;
  body.omega = Vec3(0.2, -0.1, 0.3);
  body.beta = test::axis_angle(Vec3(0, 1, 1), 0.5);
  f.update({body.omega, body.mrp(), true, true}, Vec3::Zero());
  const Vec3 torque(0.5, -0.2, 0.1);
  for (int i = 0; i < 100; ++i) {
    f.update({}, torque);
    for (int k = 0; k < 40; ++k) body.step(0.0025, torque);
  }
  EXPECT_LT((f.omega() - body.omega).norm(), 1e-7);
  EXPECT_LT((mrp::to_dcm(f.q()) - test::quat_to_matrix(body.beta)).norm(), 1e-6);
}

// ---------------------------------------------------------------- closed loop through Gnc::step
class GncClosedLoop : public ::testing::TestWithParam<LawId> {};

TEST_P(GncClosedLoop, DetumblesHoldsTargetAndTracksAPlan) {
  GncParams p = test::small_vehicle_params();
  p.law = GetParam();
  p.guidance.q_final = Vec3(0.1, -0.1, 0.05);
  test::SmallLoop loop(p);
  ASSERT_TRUE(loop.gnc.init(p).ok);
  GncCommands c;
  c.has_mode_request = true;
  c.mode_request = Mode::kDetumble;
  loop.tick(c);
  for (int i = 0; i < 20000; ++i) loop.tick();  // 1000 s
  EXPECT_EQ(loop.gnc.mode(), Mode::kHold);
  EXPECT_LT((loop.body.mrp() - p.guidance.q_final).norm(), 1e-3) << to_string(GetParam());
  EXPECT_LT(loop.body.omega.norm(), 1e-4);
  EXPECT_GT(loop.out.telemetry.fuel_kg, 0.0);

  if (GetParam() == LawId::kDpd) return;  // D+PD cannot track (TRACK is rejected for it)
  // Spin up again (gently: the gyroscopic torque must stay within the small RCS), then TRACK a
  // linear despin plan; the augmentation brings q to q_final.
  loop.body.omega = Vec3(0.06, -0.04, 0.05);
  TrajectoryTable tab;
  test::linear_despin_table(loop.body.omega, 60.0, tab);
  ASSERT_EQ(loop.gnc.load_trajectory(tab), TrajectoryError::kOk);
  c.mode_request = Mode::kTrack;
  const double t_entry = loop.t;  // plan time 0: omega_hat equals the plan's first sample
  loop.tick(c);
  ASSERT_EQ(loop.gnc.mode(), Mode::kTrack);
  double max_dev = 0.0;
  for (int i = 0; i < 1200; ++i) {  // the 60 s plan: omega follows omega_d
    loop.tick();
    const Vec3 wd = interpolate(tab, loop.t - t_entry).omega_d;
    if (loop.out.telemetry.phase == ReferencePhase::kTrack) {
      max_dev = std::max(max_dev, (loop.body.omega - wd).norm());
    }
  }
  EXPECT_LT(max_dev, 0.1 * 0.0877);  // within 10 % of the initial rate
  for (int i = 0; i < 12000; ++i) loop.tick();
  EXPECT_EQ(loop.out.telemetry.phase, ReferencePhase::kTrackAugmented);
  EXPECT_LT((loop.body.mrp() - p.guidance.q_final).norm(), 2e-3) << to_string(GetParam());
  EXPECT_LT(loop.body.omega.norm(), 1e-3);
}

INSTANTIATE_TEST_SUITE_P(AllLaws, GncClosedLoop,
                         ::testing::Values(LawId::kNtcl, LawId::kNtclEl, LawId::kIntegral,
                                           LawId::kAdaptive, LawId::kSo3, LawId::kDpd,
                                           LawId::kFeedforward),
                         [](const auto& param_info) { return std::string(to_string(param_info.param)); });

}  // namespace
}  // namespace rocksteady::gnc
