// Parameter tables: load into the inactive copy, validate the whole copy (first bad field named),
// activate at a tick boundary.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <string>

#include "fsw/params/param_table.hpp"
#include "gnc/param_bounds.hpp"
#include "fsw_harness.hpp"

namespace rocksteady::fsw {
namespace {

using test::AppFixture;
using test::M3;
using test::V3;

double id_arg(ParamId id) {
  return static_cast<double>(static_cast<int>(id));
}

// Written independently of the fsw's own mapping: where each parameter id must land.
struct Field {
  ParamId id;
  std::function<M3*(gnc::GncParams&)> matrix;
  std::function<double*(gnc::GncParams&)> scalar;
};

std::vector<Field> fields() {
  using P = gnc::GncParams;
  auto m = [](ParamId id, std::function<M3*(P&)> f) { return Field{id, std::move(f), nullptr}; };
  auto s = [](ParamId id, std::function<double*(P&)> f) {
    return Field{id, nullptr, std::move(f)};
  };
  return {
      m(ParamId::kNtclK, [](P& p) { return &p.ntcl.k; }),
      m(ParamId::kNtclLambda, [](P& p) { return &p.ntcl.lambda; }),
      m(ParamId::kElK, [](P& p) { return &p.el.k; }),
      m(ParamId::kElLambda, [](P& p) { return &p.el.lambda; }),
      m(ParamId::kFeedforwardK, [](P& p) { return &p.feedforward.k; }),
      m(ParamId::kFeedforwardLambda, [](P& p) { return &p.feedforward.lambda; }),
      m(ParamId::kIntegralK, [](P& p) { return &p.integral.k; }),
      m(ParamId::kIntegralLambda, [](P& p) { return &p.integral.lambda; }),
      m(ParamId::kIntegralKi, [](P& p) { return &p.integral.k_i; }),
      s(ParamId::kIntegralLimit, [](P& p) { return &p.integral.integral_limit_nm; }),
      m(ParamId::kAdaptiveK, [](P& p) { return &p.adaptive.k; }),
      m(ParamId::kAdaptiveLambda, [](P& p) { return &p.adaptive.lambda; }),
      s(ParamId::kAdaptiveGamma, [](P& p) { return &p.adaptive.gamma; }),
      s(ParamId::kAdaptiveEigFloor, [](P& p) { return &p.adaptive.eig_floor_ratio; }),
      s(ParamId::kAdaptiveEigCeiling, [](P& p) { return &p.adaptive.eig_ceiling_ratio; }),
      m(ParamId::kSo3K, [](P& p) { return &p.so3.k; }),
      m(ParamId::kSo3Lambda, [](P& p) { return &p.so3.lambda; }),
      m(ParamId::kDpdKd, [](P& p) { return &p.dpd.k_d; }),
      s(ParamId::kDpdKp, [](P& p) { return &p.dpd.k_p; }),
      s(ParamId::kOmegaSwitch, [](P& p) { return &p.guidance.omega_switch; }),
      s(ParamId::kKqd, [](P& p) { return &p.guidance.k_qd; }),
      s(ParamId::kEpsTrans, [](P& p) { return &p.guidance.eps_trans; }),
      s(ParamId::kTrackResetPeriod, [](P& p) { return &p.guidance.track_reset_period_s; }),
      s(ParamId::kSensorTimeout, [](P& p) { return &p.mode.sensor_timeout_s; }),
      s(ParamId::kGyroMaxRate, [](P& p) { return &p.estimator.gyro_max_rate; }),
      s(ParamId::kQuatNormTolerance, [](P& p) { return &p.estimator.quat_norm_tolerance; }),
      s(ParamId::kEstimatorOmegaC, [](P& p) { return &p.estimator.omega_c; }),
  };
}

TEST(ParamTable, EveryParameterIdLandsInItsField) {
  const gnc::GncParams base = test::small_vehicle_params();
  const auto all = fields();
  ASSERT_EQ(static_cast<int>(all.size()) + 1, kParamCount);  // + the auto_hold flag
  for (const Field& f : all) {
    ParamTable t;
    t.reset(base);
    gnc::GncParams expected = base;
    if (f.matrix) {
      const M3 cur = *f.matrix(expected);
      const V3 d = 1.25 * cur.diagonal();
      ASSERT_TRUE(t.load(static_cast<int>(f.id), d.data(), 3).ok())
          << param_specs()[int(f.id)].name;
      *f.matrix(expected) = d.asDiagonal();
      gnc::GncParams got = t.inactive();
      EXPECT_TRUE(f.matrix(got)->isApprox(*f.matrix(expected), 0.0))
          << param_specs()[int(f.id)].name;
    } else {
      // A value that keeps the table valid: scale towards the valid interior.
      double v = *f.scalar(expected);
      v = f.id == ParamId::kTrackResetPeriod ? 5.0
                                             : (f.id == ParamId::kAdaptiveEigFloor ? 0.4 : 1.1 * v);
      if (f.id == ParamId::kQuatNormTolerance) v = 0.02;
      ASSERT_TRUE(t.load(static_cast<int>(f.id), &v, 1).ok()) << param_specs()[int(f.id)].name;
      *f.scalar(expected) = v;
      gnc::GncParams got = t.inactive();
      EXPECT_EQ(*f.scalar(got), v) << param_specs()[int(f.id)].name;
    }
    EXPECT_TRUE(t.loaded());
    EXPECT_TRUE(gnc::validate(t.inactive()).ok);
  }
  ParamTable t;
  t.reset(base);
  const double off = 0.0;
  ASSERT_TRUE(t.load(static_cast<int>(ParamId::kAutoHold), &off, 1).ok());
  EXPECT_FALSE(t.inactive().mode.auto_hold);
}

TEST(ParamTable, SixValuesLoadASymmetricMatrix) {
  ParamTable t;
  t.reset(test::small_vehicle_params());
  const double v[6] = {5.0, 6.0, 7.0, 0.5, -0.25, 0.125};  // xx yy zz xy xz yz
  ASSERT_TRUE(t.load(static_cast<int>(ParamId::kSo3K), v, 6).ok());
  M3 expected;
  expected << 5.0, 0.5, -0.25, 0.5, 6.0, 0.125, -0.25, 0.125, 7.0;
  EXPECT_TRUE(t.inactive().so3.k.isApprox(expected, 0.0));
}

TEST(ParamTable, InvalidLoadNamesTheFirstBadFieldAndKeepsTheInactiveTable) {
  ParamTable t;
  const gnc::GncParams base = test::small_vehicle_params();
  t.reset(base);
  // Symmetric but indefinite: eigenvalues of [[1,3],[3,1]] are 4 and -2.
  const double indefinite[6] = {1.0, 1.0, 1.0, 3.0, 0.0, 0.0};
  ParamLoadResult r = t.load(static_cast<int>(ParamId::kNtclK), indefinite, 6);
  EXPECT_EQ(r.reason, RejectReason::kInvalidTable);
  EXPECT_STREQ(r.text, "ntcl.K");
  EXPECT_FALSE(t.loaded());
  EXPECT_TRUE(t.inactive().ntcl.k.isApprox(base.ntcl.k, 0.0));
  // omega_switch must stay below eps_trans (1.0 for this vehicle).
  double v = 2.0;
  r = t.load(static_cast<int>(ParamId::kOmegaSwitch), &v, 1);
  EXPECT_STREQ(r.text, "guidance.omega_switch");
  // The sensor timeout must cover at least one GNC period (0.05 s).
  v = 0.01;
  r = t.load(static_cast<int>(ParamId::kSensorTimeout), &v, 1);
  EXPECT_STREQ(r.text, "mode.sensor_timeout");
  v = -3.0;
  r = t.load(static_cast<int>(ParamId::kDpdKp), &v, 1);
  EXPECT_STREQ(r.text, "dpd.k_p");
  EXPECT_FALSE(t.loaded());
  EXPECT_EQ(t.inactive().dpd.k_p, base.dpd.k_p);
}

TEST(ParamTable, CoupledFieldsLoadInAValidOrder) {
  ParamTable t;
  t.reset(test::small_vehicle_params());
  double eps = 0.01;
  double sw = 0.005;
  // eps_trans = 0.01 first would fall below omega_switch = 0.02; lowering omega_switch first keeps
  // the table valid (both values inside their physical ranges, gnc/param_bounds.cpp).
  EXPECT_FALSE(t.load(static_cast<int>(ParamId::kEpsTrans), &eps, 1).ok());
  EXPECT_TRUE(t.load(static_cast<int>(ParamId::kOmegaSwitch), &sw, 1).ok());
  EXPECT_TRUE(t.load(static_cast<int>(ParamId::kEpsTrans), &eps, 1).ok());
}

TEST(ParamTableActivation, TakesEffectAtTheNextTickBoundary) {
  AppFixture f;
  f.ticks(2);
  const double kp_before = f.app->active_params().dpd.k_p;
  ASSERT_TRUE(f.send(Opcode::kParamLoad, {id_arg(ParamId::kDpdKp), 5.0}).accepted);
  ASSERT_TRUE(f.send(Opcode::kParamLoad, {id_arg(ParamId::kNtclK), 2.0, 3.0, 4.0}).accepted);
  EXPECT_EQ(f.app->active_params().dpd.k_p, kp_before);  // loaded, not active
  EXPECT_EQ(f.app->param_table().inactive().dpd.k_p, 5.0);
  EXPECT_TRUE(f.app->health().table_loaded);
  ASSERT_TRUE(f.send(Opcode::kParamActivate).accepted);
  EXPECT_EQ(f.send(Opcode::kParamActivate).reason, RejectReason::kBusy);  // one at a time
  EXPECT_EQ(f.app->active_params().dpd.k_p, kp_before);                   // not before the boundary
  f.ticks(1);
  EXPECT_EQ(f.app->active_params().dpd.k_p, 5.0);
  EXPECT_TRUE(
      f.app->active_params().ntcl.k.isApprox(V3(2.0, 3.0, 4.0).asDiagonal().toDenseMatrix(), 0.0));
  EXPECT_FALSE(f.app->param_table().loaded());
  EXPECT_EQ(f.app->param_table().inactive().dpd.k_p, 5.0);  // inactive := active
  const HealthTelemetry h = f.app->health();
  EXPECT_EQ(h.table_activations, 1u);
  EXPECT_EQ(h.table_loads, 2u);
  const std::vector<Event> ev = test::drain(*f.app);
  EXPECT_EQ(test::count_events(ev, EventId::kTableLoaded), 2);
  EXPECT_EQ(test::count_events(ev, EventId::kTableActivated), 1);
}

TEST(ParamTableActivation, KeepsTheCommandedLawAndTarget) {
  AppFixture f;
  f.ticks(2);
  ASSERT_TRUE(
      f.send(Opcode::kSetLaw, {static_cast<double>(static_cast<int>(gnc::LawId::kSo3))}).accepted);
  ASSERT_TRUE(f.send(Opcode::kSetTarget, {0.1, 0.2, -0.1}).accepted);
  f.ticks(1);
  ASSERT_EQ(f.app->active_params().law, gnc::LawId::kSo3);
  ASSERT_TRUE(f.send(Opcode::kParamLoad, {id_arg(ParamId::kKqd), 0.3}).accepted);
  ASSERT_TRUE(f.send(Opcode::kParamActivate).accepted);
  f.ticks(1);
  EXPECT_EQ(f.app->active_params().guidance.k_qd, 0.3);
  EXPECT_EQ(f.app->active_params().law, gnc::LawId::kSo3);
  // The flight core still holds the commanded target: attitude_error = q_hat - q_final.
  EXPECT_TRUE(
      (f.out.telemetry.q_hat - f.out.telemetry.attitude_error).isApprox(V3(0.1, 0.2, -0.1), 1e-12));
}

TEST(ParamTableActivation, LoadsAfterTheActivateCommandStayInTheInactiveTable) {
  AppFixture f;
  ASSERT_TRUE(f.send(Opcode::kParamLoad, {id_arg(ParamId::kDpdKp), 5.0}).accepted);
  ASSERT_TRUE(f.send(Opcode::kParamActivate).accepted);
  ASSERT_TRUE(f.send(Opcode::kParamLoad, {id_arg(ParamId::kDpdKp), 7.0}).accepted);
  f.ticks(1);
  EXPECT_EQ(f.app->active_params().dpd.k_p, 5.0);  // the table as it was when activated
  EXPECT_TRUE(f.app->param_table().loaded());
  EXPECT_EQ(f.app->param_table().inactive().dpd.k_p, 7.0);
}

TEST(ParamTableActivation, DiscardRestoresTheInactiveTableFromTheActiveOne) {
  AppFixture f;
  const double kp = f.app->active_params().dpd.k_p;
  ASSERT_TRUE(f.send(Opcode::kParamLoad, {id_arg(ParamId::kDpdKp), 5.0}).accepted);
  ASSERT_TRUE(f.send(Opcode::kParamDiscard).accepted);
  EXPECT_FALSE(f.app->param_table().loaded());
  EXPECT_EQ(f.app->param_table().inactive().dpd.k_p, kp);
  EXPECT_EQ(f.send(Opcode::kParamActivate).reason, RejectReason::kNothingToActivate);
}

// read_param is write_param's inverse for every parameter: values written (a symmetric matrix as 6
// values, a scalar, the flag) read back unchanged.
TEST(ParamTable, ReadParamInvertsWriteParamForEveryId) {
  for (int id = 0; id < kParamCount; ++id) {
    gnc::GncParams p = test::small_vehicle_params();
    double in[6] = {11.0 + id, 12.0, 13.0, 0.5, -0.25, 0.125};
    int n = 6;
    if (param_specs()[id].kind == ParamKind::kScalar) n = 1;
    if (param_specs()[id].kind == ParamKind::kFlag) {
      n = 1;
      in[0] = p.mode.auto_hold ? 0.0 : 1.0;  // the other value
    }
    ASSERT_TRUE(write_param(p, id, in, n).ok()) << param_specs()[id].name;
    double out[6] = {};
    ASSERT_EQ(read_param(p, id, out), n) << param_specs()[id].name;
    for (int k = 0; k < n; ++k) EXPECT_EQ(out[k], in[k]) << param_specs()[id].name << " " << k;
  }
  double out[6];
  EXPECT_EQ(read_param(test::small_vehicle_params(), kParamCount, out), 0);
  EXPECT_EQ(read_param(test::small_vehicle_params(), -1, out), 0);
}

// PARAM_DUMP reads the ACTIVE table back at once (not the inactive one with its pending loads).
TEST(ParamTableActivation, DumpReadsTheActiveTableBack) {
  AppFixture f;
  f.ticks(2);
  ASSERT_TRUE(f.send(Opcode::kParamLoad, {id_arg(ParamId::kDpdKp), 5.0}).accepted);
  ASSERT_TRUE(f.send(Opcode::kParamActivate).accepted);
  f.ticks(1);
  ASSERT_TRUE(f.send(Opcode::kParamLoad, {id_arg(ParamId::kDpdKp), 7.0}).accepted);  // inactive only
  ParamDump d;
  EXPECT_FALSE(f.app->take_param_dump(d));
  ASSERT_TRUE(f.send(Opcode::kParamDump).accepted);
  ASSERT_TRUE(f.app->take_param_dump(d));
  EXPECT_FALSE(f.app->take_param_dump(d));  // once per command
  EXPECT_EQ(d.seq, 1u);
  EXPECT_EQ(d.count, kParamCount);
  EXPECT_EQ(d.t, f.app->onboard_time());
  for (int id = 0; id < kParamCount; ++id) {
    double expect[6];
    const int n = read_param(f.app->active_params(), id, expect);
    ASSERT_EQ(d.value_count[id], n);
    for (int k = 0; k < n; ++k) EXPECT_EQ(d.values[id][k], expect[k]);
  }
  EXPECT_EQ(d.values[static_cast<int>(ParamId::kDpdKp)][0], 5.0);
  const std::vector<Event> ev = test::drain(*f.app);
  EXPECT_EQ(test::count_events(ev, EventId::kParamsDumped), 1);
}

// The findings: values that switch protection or control off passed gnc::validate (sign and
// finiteness only). Each is now refused by the physical-range table (gnc/param_bounds.cpp), naming
// the parameter, and the table stays as it was; values inside the ranges still load.
TEST(ParamBounds, ValuesThatSwitchProtectionOrControlOffAreRefused) {
  AppFixture f;
  const double timeout = static_cast<double>(static_cast<int>(ParamId::kSensorTimeout));
  const double ntcl_k = static_cast<double>(static_cast<int>(ParamId::kNtclK));
  const double lambda = static_cast<double>(static_cast<int>(ParamId::kNtclLambda));
  const double gyro = static_cast<double>(static_cast<int>(ParamId::kGyroMaxRate));
  const struct {
    std::initializer_list<double> args;
    const char* field;
  } cases[] = {
      {{timeout, 1e30}, "mode.sensor_timeout"},
      {{timeout, 3600.0}, "mode.sensor_timeout"},
      {{ntcl_k, 1e-300, 1e-300, 1e-300}, "ntcl.K"},
      {{ntcl_k, 1e30, 1e30, 1e30}, "ntcl.K"},
      {{lambda, 1e3, 1e3, 1e3}, "ntcl.Lambda"},
      {{gyro, 1e9}, "estimator.gyro_max_rate"},
  };
  for (const auto& c : cases) {
    const CommandAck a = f.send(Opcode::kParamLoad, c.args);
    EXPECT_EQ(a.reason, RejectReason::kInvalidTable) << c.field;
    EXPECT_STREQ(a.text, c.field);
  }
  EXPECT_FALSE(f.app->param_table().loaded());
  EXPECT_TRUE(f.send(Opcode::kParamLoad, {timeout, 2.0}).accepted);
  EXPECT_TRUE(f.send(Opcode::kParamLoad, {ntcl_k, 8.0, 8.0, 8.0}).accepted);
}

// Every row of the table: a value inside passes gnc::validate's range check, just outside fails,
// naming that row (the table itself, checked independently of the code that applies it).
TEST(ParamBounds, TheTableIsWellFormedAndEveryRowHasAReason) {
  int n = 0;
  const gnc::ParamBound* rows = gnc::param_bounds(n);
  ASSERT_GT(n, 25);
  for (int i = 0; i < n; ++i) {
    EXPECT_LT(rows[i].lo, rows[i].hi) << rows[i].name;
    EXPECT_GT(std::string(rows[i].why).size(), 10u) << rows[i].name;
    EXPECT_EQ(gnc::find_param_bound(rows[i].name), &rows[i]);
    if (rows[i].kind == gnc::BoundKind::kScalar) {
      EXPECT_TRUE(gnc::within_bound(rows[i].name, rows[i].lo));
      EXPECT_TRUE(gnc::within_bound(rows[i].name, rows[i].hi));
      EXPECT_FALSE(gnc::within_bound(rows[i].name, rows[i].hi * 1.01 + 1e-12));
      EXPECT_FALSE(gnc::within_bound(rows[i].name, std::nan("")));
    }
  }
  // The study's and the tests' parameters are inside every range.
  EXPECT_TRUE(gnc::check_bounds(gnc::study_gnc_params(200.0)).ok)
      << gnc::check_bounds(gnc::study_gnc_params(200.0)).field;
  EXPECT_TRUE(gnc::check_bounds(test::small_vehicle_params()).ok)
      << gnc::check_bounds(test::small_vehicle_params()).field;
}

// The finding: PARAM_DISCARD was acknowledged while a pending activation still went through.
TEST(ParamBounds, DiscardIsRefusedWhileAnActivationIsPending) {
  AppFixture f;
  f.ticks(1);
  const double kp = static_cast<double>(static_cast<int>(ParamId::kDpdKp));
  ASSERT_TRUE(f.send(Opcode::kParamLoad, {kp, 4.5}).accepted);
  ASSERT_TRUE(f.send(Opcode::kParamActivate).accepted);
  const CommandAck d = f.send(Opcode::kParamDiscard);
  EXPECT_FALSE(d.accepted);
  EXPECT_EQ(d.reason, RejectReason::kBusy);
  f.ticks(1);
  EXPECT_EQ(f.app->active_params().dpd.k_p, 4.5);  // what the refusal said: it was activated
  // With nothing pending, a discard drops the load as before.
  ASSERT_TRUE(f.send(Opcode::kParamLoad, {kp, 7.0}).accepted);
  EXPECT_TRUE(f.send(Opcode::kParamDiscard).accepted);
  f.ticks(1);
  EXPECT_EQ(f.app->active_params().dpd.k_p, 4.5);
}

}  // namespace
}  // namespace rocksteady::fsw
