// The re-planner on synthetic telemetry (case 1's flight table): the first plan starts from the rate
// predicted for the switch and is handed over no earlier than t + latency; a plan the flight
// refuses leaves the previous reference; a re-plan from a mid-despin state verifies and starts on
// the plan being flown.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <utility>

#include "gnc/estimation/identifier.hpp"
#include "gnc/guidance/trajectory.hpp"
#include "gnc/io.hpp"
#include "gnc/model/mass_properties.hpp"
#include "gnc/model/rcs.hpp"
#include "ground/planner/planner.hpp"
#include "ground/planner/replanner.hpp"
#include "rigid_body.hpp"

namespace rocksteady::ground::planner {
namespace {

gnc::GncParams case1_table() {
  gnc::GncParams p;
  p.dt = 0.1;
  p.mass_hat = gnc::study_true_mass_properties();
  p.rcs = gnc::study_rcs_layout(200.0);
  return p;
}

gnc::GncTelemetry tlm(double t, gnc::Mode mode, const Vec3& omega) {
  gnc::GncTelemetry tl;
  tl.t = t;
  tl.mode = mode;
  tl.omega_hat = omega;
  return tl;
}

ReplanPolicy policy(double latency) {
  ReplanPolicy p;
  p.first_plan_s = 10.0;
  p.first_plan_max_s = 10.0;  // no identification here: plan with the table at 10 s
  p.latency_s = latency;
  p.period_s = 60.0;
  p.min_interval_s = 30.0;
  p.error_fraction = 0.0;
  p.on_model_update = false;
  p.on_identified = false;
  p.early_plan_s = 0.0;
  p.refuted_max_s = 0.0;
  return p;
}

TEST(Replanner, FirstPlanStartsAtTheRatePredictedForTheSwitchAndWaitsForTheLatency) {
  const gnc::GncParams table = case1_table();
  const double latency = 20.0;
  Replanner rp(table, policy(latency));
  // A torque-free tumble (no torque applied: the prediction is Euler's equations alone). The
  // telemetry follows an independent rigid body (the plant's RK4, tests/common/rigid_body.hpp).
  rocksteady::test::RigidBody body;
  body.j = gnc::total_inertia(table.mass_hat);
  body.omega = Vec3(0.01, 0.02, 0.03);
  std::optional<Delivery> d;
  double t = 0.0;
  Vec3 omega_at_switch = Vec3::Zero();
  for (int k = 0; k < 400 && !d; ++k) {
    t = k * table.dt;
    d = rp.update(tlm(t, gnc::Mode::kDetumble, body.omega));
    body.step(table.dt, Vec3::Zero());
  }
  ASSERT_TRUE(d.has_value());
  ASSERT_EQ(rp.records().size(), 1u);
  const ReplanRecord& r = rp.records().front();
  ASSERT_TRUE(r.ok) << r.error;
  EXPECT_NEAR(r.t_state, 10.0, 1e-9);
  EXPECT_EQ(r.trigger, ReplanTrigger::kFirst);
  EXPECT_GE(t, r.t_state + latency - 1e-9);  // not before t + latency
  EXPECT_LT(t, r.t_state + latency + table.dt);
  EXPECT_TRUE(d->first);
  // The switch happens one tick after the delivery: the body's rate then (the body has been
  // stepped to t + dt already) is the plan's first sample, to the model's integration error.
  omega_at_switch = body.omega;
  const Vec3 first = d->table->samples[0].omega_d;
  EXPECT_LT((first - omega_at_switch).norm(), 1e-6 * omega_at_switch.norm());
  // Without the prediction the plan would start 20 s of tumble away (about 7 degrees of rotation
  // of the rate vector): the check above is not vacuous.
  rocksteady::test::RigidBody back;
  back.j = body.j;
  back.omega = Vec3(0.01, 0.02, 0.03);
  for (int k = 0; k < 100; ++k) back.step(table.dt, Vec3::Zero());  // the rate at t_state
  EXPECT_GT((first - back.omega).norm(), 1e-3 * omega_at_switch.norm());
  // The table is what the flight validates.
  EXPECT_EQ(gnc::validate_trajectory(*d->table, table.guidance.eps_trans),
            gnc::TrajectoryError::kOk);
}

TEST(Replanner, RePlanWhileTrackingStartsOnThePlanVerifiesAndARefusalKeepsThePreviousPlan) {
  const gnc::GncParams table = case1_table();
  Replanner rp(table, policy(0.0));
  // Fly the first plan exactly (the telemetry is the plan's own rate): TRACK after the delivery.
  std::optional<Delivery> first;
  double t = 0.0;
  Vec3 w(0.01, 0.02, 0.03);
  for (int k = 0; k <= 100 && !first; ++k) {
    t = k * table.dt;
    first = rp.update(tlm(t, gnc::Mode::kDetumble, w));
  }
  ASSERT_TRUE(first.has_value());
  const double t_switch = t + table.dt;
  std::optional<Delivery> second;
  const gnc::TrajectoryTable& plan1 = *first->table;
  for (int k = 1; k < 2000 && !second; ++k) {
    t = t_switch + (k - 1) * table.dt;
    w = gnc::interpolate(plan1, t - t_switch).omega_d;
    second = rp.update(tlm(t, gnc::Mode::kTrack, w));
  }
  ASSERT_TRUE(second.has_value());
  ASSERT_EQ(rp.records().size(), 2u);
  const ReplanRecord r2 = rp.records()[1];  // a copy: more records come
  ASSERT_TRUE(r2.ok) << r2.error;
  EXPECT_EQ(r2.trigger, ReplanTrigger::kPeriodic);
  EXPECT_NEAR(r2.t_state, 10.0 + 60.0, 0.2);
  EXPECT_FALSE(second->first);
  // A minute of the despin is done: the re-plan from there costs less than the first plan.
  EXPECT_LT(r2.fuel_kg, rp.records()[0].fuel_kg);
  EXPECT_GT(r2.fuel_kg, 0.5 * rp.records()[0].fuel_kg);
  // It starts where the first plan is at the switch.
  const Vec3 on_plan1 = gnc::interpolate(plan1, t + table.dt - t_switch).omega_d;
  EXPECT_LT((second->table->samples[0].omega_d - on_plan1).norm(), 1e-6 * on_plan1.norm());

  // The flight refuses it (stale at the boundary): the first plan stays the reference, so the
  // tracking-error check keeps measuring against it and the re-planner keeps tracking.
  rp.refused("trajectory_stale at the switch");
  EXPECT_TRUE(rp.tracking());
  EXPECT_FALSE(rp.records()[1].ok);
  EXPECT_NE(rp.records()[1].error.find("stale"), std::string::npos);
  EXPECT_EQ(rp.plans_delivered(), 1);
  // The next plan comes no sooner than min_interval after the refused one.
  std::optional<Delivery> third;
  const double t_refused = t;
  for (int k = 1; k < 2000 && !third; ++k) {
    t = t_refused + k * table.dt;
    w = gnc::interpolate(plan1, t - t_switch).omega_d;
    third = rp.update(tlm(t, gnc::Mode::kTrack, w));
  }
  ASSERT_TRUE(third.has_value());
  EXPECT_GE(rp.records().back().t_state, r2.t_state + policy(0.0).min_interval_s - 1e-9);
  EXPECT_TRUE(rp.records().back().ok) << rp.records().back().error;
}

// With momentum tracking (guidance.track_momentum_k) the flight holds the plan's inertial momentum
// and lets the attitude drift off the plan's: its rate is then J_hat^-1 dR J_hat omega_d, dR the
// turn from the plan's attitude (telemetry q_d) to the body's (q_hat). The tracking-error trigger
// measures against that rate: a body 30 degrees off the plan's attitude and on the plan's momentum
// asks for no re-plan, where the same telemetry with the law on the plan's rates does.
TEST(Replanner, WithMomentumTrackingTheTrackingErrorIsAgainstTheRateThatCarriesThePlansMomentum) {
  for (const double k : {0.0, 1e-3}) {
    gnc::GncParams table = case1_table();
    table.guidance.track_momentum_k = k;
    ReplanPolicy pol = policy(0.0);
    pol.error_fraction = 0.1;
    pol.period_s = 0.0;
    Replanner rp(table, pol);
    std::optional<Delivery> first;
    double t = 0.0;
    const Vec3 w0(0.01, 0.02, 0.03);
    for (int j = 0; j <= 100 && !first; ++j) {
      t = j * table.dt;
      first = rp.update(tlm(t, gnc::Mode::kDetumble, w0));
    }
    ASSERT_TRUE(first.has_value());
    const double t_switch = t + table.dt;
    const gnc::TrajectoryTable& plan = *first->table;
    // The body 30 degrees about a fixed axis off the plan's attitude (q_d = 0), through the
    // plant's quaternion algebra.
    const double angle = std::acos(-1.0) / 6.0;
    const Eigen::Vector4d b = rocksteady::test::axis_angle(Vec3(1.0, -2.0, 0.5), angle);
    const gnc::Mat3 dr = rocksteady::test::quat_to_matrix(b).transpose();
    const gnc::Mat3 j = gnc::total_inertia(table.mass_hat);
    for (int i = 1; i <= 1000; ++i) {  // 100 s on the plan's momentum
      // The switch's tick starts the plan at the body's attitude (q_d <- q_hat, dR = I) and
      // re-synchronises both plan clocks; the body is off the plan's attitude from then on.
      const gnc::Mat3 turn = i == 1 ? gnc::Mat3::Identity() : dr;
      t = t_switch + (i - 1) * table.dt;
      gnc::GncTelemetry tl =
          tlm(t, gnc::Mode::kTrack,
              j.inverse() * (turn * (j * gnc::interpolate(plan, t - t_switch).omega_d)));
      tl.phase = gnc::ReferencePhase::kTrack;
      tl.q_d = Vec3::Zero();
      tl.q_hat = i == 1 ? Vec3::Zero() : Vec3(rocksteady::test::quat_to_mrp(b));
      rp.update(tl);
    }
    if (k > 0.0) {
      EXPECT_EQ(rp.records().size(), 1u);  // the first plan only
    } else {
      ASSERT_GE(rp.records().size(), 2u);  // and again each min_interval_s: the error stays
      EXPECT_EQ(rp.records()[1].trigger, ReplanTrigger::kTrackingError);
      // as soon as min_interval_s after the first plan allows
      EXPECT_NEAR(rp.records()[1].t_state, rp.records()[0].t_state + pol.min_interval_s, 0.15);
    }
  }
}

// The automatic horizon (ReplanPolicy::horizon_factor <= 0): 16 shortest despins when the flight
// tracks the plan's momentum, 8 on the law's rates; a policy's own factor wins. The same tumble's
// first plan reaches the planner with it: twice the final time (the despin's least fuel falls with
// the horizon, so the plan uses all of it) and less fuel.
TEST(Replanner, TheAutomaticHorizonIsTwiceAsLongWhenTheFlightTracksThePlansMomentum) {
  const auto first_plan = [](double momentum_k, double factor) {
    gnc::GncParams table = case1_table();
    table.guidance.track_momentum_k = momentum_k;
    ReplanPolicy pol = policy(0.0);
    pol.horizon_factor = factor;
    Replanner rp(table, pol);
    std::optional<Delivery> d;
    for (int j = 0; j <= 100 && !d; ++j) {
      d = rp.update(tlm(j * table.dt, gnc::Mode::kDetumble, Vec3(0.01, 0.02, 0.03)));
    }
    EXPECT_TRUE(d.has_value());
    EXPECT_EQ(rp.records().size(), 1u);
    return std::make_pair(rp.horizon_factor(), rp.records().front());
  };
  ASSERT_LE(ReplanPolicy{}.horizon_factor, 0.0);  // automatic by default
  const auto [f_rates, rates] = first_plan(0.0, 0.0);
  const auto [f_momentum, momentum] = first_plan(1e-3, 0.0);
  EXPECT_EQ(f_rates, kHorizonFactor);
  EXPECT_EQ(f_momentum, kMomentumHorizonFactor);
  EXPECT_EQ(first_plan(1e-3, 12.0).first, 12.0);
  ASSERT_TRUE(rates.ok) << rates.error;
  ASSERT_TRUE(momentum.ok) << momentum.error;
  // Both plans start from the same predicted rate, so the same shortest despin.
  EXPECT_NEAR(momentum.t_final / rates.t_final, kMomentumHorizonFactor / kHorizonFactor, 0.02);
  EXPECT_LT(momentum.fuel_kg, rates.fuel_kg);
}

// An identifier report around the table's J_tot and r_SO/BCM, offset by `dj` (inertia parameter
// i, kg m^2) and `dr` (offset component i, m), with 1 sigma `sj` and `sr` on every component.
gnc::EstimationTelemetry report(const gnc::GncParams& table, double sj, double sr, int ij = 0,
                                double dj = 0.0, int ir = 0, double dr = 0.0) {
  gnc::EstimationTelemetry e;
  e.identifying = true;
  e.windows = 5;
  e.j = gnc::inertia_params(gnc::total_inertia(table.mass_hat));
  e.j(ij) += dj;
  e.j_sigma = gnc::Vec6::Constant(sj);
  e.r = table.mass_hat.r_so_bcm;
  e.r(ir) += dr;
  e.r_sigma = gnc::Vec3::Constant(sr);
  return e;
}

TEST(Replanner, APrioriModelConfirmedOnlyWithinItsSigmasAndWithSmallSigmas) {
  const gnc::GncParams table = case1_table();
  // |J_tot| as a 6-vector, computed here from the mass properties (Eq. 1).
  const gnc::Mat3 j = gnc::total_inertia(table.mass_hat);
  const double j_norm = std::sqrt(j(0, 0) * j(0, 0) + j(1, 1) * j(1, 1) + j(2, 2) * j(2, 2) +
                                  j(0, 1) * j(0, 1) + j(0, 2) * j(0, 2) + j(1, 2) * j(1, 2));
  const double sj = 1e-3 * j_norm;  // well inside the 1 % bound
  const double sr = 0.01;
  // At the table's values: confirmed.
  EXPECT_TRUE(apriori_confirmed(table, report(table, sj, sr), 3.0, 0.01, 0.05));
  // Every inertia component and every offset component: 2.9 sigma away confirms, 3.1 does not.
  for (int i = 0; i < 6; ++i) {
    EXPECT_TRUE(apriori_confirmed(table, report(table, sj, sr, i, 2.9 * sj), 3.0, 0.01, 0.05)) << i;
    EXPECT_FALSE(apriori_confirmed(table, report(table, sj, sr, i, -3.1 * sj), 3.0, 0.01, 0.05))
        << i;
  }
  for (int i = 0; i < 3; ++i) {
    EXPECT_TRUE(apriori_confirmed(table, report(table, sj, sr, 0, 0.0, i, -2.9 * sr), 3.0, 0.01,
                                  0.05)) << i;
    EXPECT_FALSE(apriori_confirmed(table, report(table, sj, sr, 0, 0.0, i, 3.1 * sr), 3.0, 0.01,
                                   0.05)) << i;
  }
  // Agreement that means nothing (a 1 sigma above the bounds) does not confirm.
  EXPECT_FALSE(apriori_confirmed(table, report(table, 0.011 * j_norm, sr), 3.0, 0.01, 0.05));
  EXPECT_FALSE(apriori_confirmed(table, report(table, sj, 0.06), 3.0, 0.01, 0.05));
  // No window yet, identification off, or a non-finite report: not confirmed.
  gnc::EstimationTelemetry e = report(table, sj, sr);
  e.windows = 0;
  EXPECT_FALSE(apriori_confirmed(table, e, 3.0, 0.01, 0.05));
  e = report(table, sj, sr);
  e.identifying = false;
  EXPECT_FALSE(apriori_confirmed(table, e, 3.0, 0.01, 0.05));
  e = report(table, sj, sr);
  e.j_sigma(3) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(apriori_confirmed(table, e, 3.0, 0.01, 0.05));
}

TEST(Replanner, EarlyPlanForTheAPrioriModelOnlyOnceTheIdentifierConfirmsIt) {
  const gnc::GncParams table = case1_table();
  ReplanPolicy pol = policy(0.0);
  pol.first_plan_s = 100.0;
  pol.first_plan_max_s = 100.0;
  pol.early_plan_s = 5.0;
  const gnc::Mat3 j = gnc::total_inertia(table.mass_hat);
  const double sj = 1e-4 * j.norm();
  // An identifier that disagrees (5 sigma on Jxx) until 20 s, then agrees: the plan comes at the
  // first telemetry that agrees, for the table's model, long before first_plan_s.
  Replanner rp(table, pol);
  const Vec3 w(0.01, 0.02, 0.03);
  std::optional<Delivery> d;
  double t = 0.0;
  for (int k = 0; k < 1000 && !d; ++k) {
    t = k * table.dt;
    gnc::GncTelemetry tl = tlm(t, gnc::Mode::kDetumble, w);
    tl.est = report(table, sj, 0.01, 0, t < 20.0 - 1e-9 ? 5.0 * sj : 0.0);
    d = rp.update(tl);
  }
  ASSERT_TRUE(d.has_value());
  ASSERT_EQ(rp.records().size(), 1u);
  const ReplanRecord& r = rp.records().front();
  ASSERT_TRUE(r.ok) << r.error;
  EXPECT_EQ(r.trigger, ReplanTrigger::kEarly);
  EXPECT_STREQ(to_string(r.trigger), "early");
  EXPECT_NEAR(r.t_state, 20.0, 1e-9);
  EXPECT_FALSE(r.identified);
  EXPECT_TRUE(d->first);

  // Before early_plan_s nothing is planned even when confirmed; a disagreeing identifier waits for
  // first_plan_s (and then plans for the table: no confident model).
  Replanner wait(table, pol);
  std::optional<Delivery> d2;
  for (int k = 0; k < 2000 && !d2; ++k) {
    t = k * table.dt;
    gnc::GncTelemetry tl = tlm(t, gnc::Mode::kDetumble, w);
    tl.est = report(table, sj, 0.01, 2, t < 4.0 ? 0.0 : 5.0 * sj);
    d2 = wait.update(tl);
  }
  ASSERT_TRUE(d2.has_value());
  EXPECT_EQ(wait.records().front().trigger, ReplanTrigger::kFirst);
  EXPECT_NEAR(wait.records().front().t_state, 100.0, 1e-9);

  // A confirmation that comes after first_plan_s, with no confident model and first_plan_max_s
  // still ahead, plans then (early) instead of waiting for first_plan_max_s.
  ReplanPolicy late_pol = pol;
  late_pol.first_plan_s = 30.0;
  late_pol.first_plan_max_s = 100.0;
  late_pol.refuted_max_s = 0.0;
  Replanner late(table, late_pol);
  std::optional<Delivery> d3;
  for (int k = 0; k < 2000 && !d3; ++k) {
    t = k * table.dt;
    gnc::GncTelemetry tl = tlm(t, gnc::Mode::kDetumble, w);
    // 1 sigma 3 % of |J| (not confirmed) until 60 s, then 0.01 % and agreeing.
    const double s = t < 60.0 - 1e-9 ? 300.0 * sj : sj;
    tl.est = report(table, s, 0.01, 0, 0.0);
    d3 = late.update(tl);
  }
  ASSERT_TRUE(d3.has_value());
  ASSERT_EQ(late.records().size(), 1u);
  EXPECT_EQ(late.records().front().trigger, ReplanTrigger::kEarly);
  EXPECT_NEAR(late.records().front().t_state, 60.0, 1e-9);
}

TEST(Replanner, ARefutedAPrioriModelIsNotPlannedForUntilRefutedMax) {
  const gnc::GncParams table = case1_table();
  ReplanPolicy pol = policy(0.0);
  pol.first_plan_s = 50.0;
  pol.first_plan_max_s = 50.0;
  pol.refuted_max_s = 120.0;
  const gnc::Mat3 j = gnc::total_inertia(table.mass_hat);
  const double sj = 0.05 * j.norm();  // never confident, never confirmed (1 sigma above 2 %)
  const Vec3 w(0.01, 0.02, 0.03);
  auto fly = [&](double dj) {
    Replanner rp(table, pol);
    for (int k = 0; k < 2000; ++k) {
      gnc::GncTelemetry tl = tlm(k * table.dt, gnc::Mode::kDetumble, w);
      tl.est = report(table, sj, 0.5, 1, dj);
      if (rp.update(tl)) break;
    }
    return rp.records();
  };
  // The estimate agrees with the table (within 3 sigma): planned for the table at first_plan_max.
  const auto agree = fly(2.0 * sj);
  ASSERT_EQ(agree.size(), 1u);
  EXPECT_TRUE(agree[0].ok) << agree[0].error;
  EXPECT_NEAR(agree[0].t_state, 50.0, 1e-9);
  // It refutes it (Jyy 4 sigma away): no plan for a model known to be wrong until refuted_max.
  const auto refute = fly(4.0 * sj);
  ASSERT_EQ(refute.size(), 1u);
  EXPECT_TRUE(refute[0].ok) << refute[0].error;
  EXPECT_NEAR(refute[0].t_state, 120.0, 1e-9);
  EXPECT_EQ(refute[0].trigger, ReplanTrigger::kFirst);
  EXPECT_FALSE(refute[0].identified);
}

// adopt_wait_s: a confident identified model that refutes the flight's active model (here Jxx
// 10 sigma = 0.5 % of |J| from the table) is planned for only once the flight has adopted it (the
// adoption count in the telemetry), so that the NTCL tracks the plan with the plan's model; if no
// adoption comes, at most adopt_wait_s after the model became confident. A model the flight's
// table already agrees with is planned for at once.
TEST(Replanner, AConfidentModelTheFlightDoesNotFlyYetIsPlannedForAfterItsAdoption) {
  const gnc::GncParams table = case1_table();
  ReplanPolicy pol = policy(0.0);
  pol.first_plan_s = 10.0;
  pol.first_plan_max_s = 200.0;  // the identified model decides the first plan's time
  pol.adopt_wait_s = 60.0;
  const gnc::Mat3 j = gnc::total_inertia(table.mass_hat);
  const double sj = 5e-4 * j.norm();
  const Vec3 w(0.01, 0.02, 0.03);
  // Confident from 20 s; adopted by the flight at `t_adopt` (< 0: never).
  auto fly = [&](double dj, double t_adopt) {
    Replanner rp(table, pol);
    for (int k = 0; k < 3000; ++k) {
      const double t = k * table.dt;
      gnc::GncTelemetry tl = tlm(t, gnc::Mode::kDetumble, w);
      tl.est = report(table, sj, 0.01, 0, dj);
      tl.est.inertia_confident = t >= 20.0 - 1e-9;
      tl.est.offset_confident = tl.est.inertia_confident;
      tl.est.adoptions = (t_adopt >= 0.0 && t >= t_adopt - 1e-9) ? 1u : 0u;
      if (rp.update(tl)) break;
    }
    return rp.records();
  };
  const auto adopted = fly(10.0 * sj, 35.0);
  ASSERT_EQ(adopted.size(), 1u);
  EXPECT_TRUE(adopted[0].ok) << adopted[0].error;
  EXPECT_TRUE(adopted[0].identified);
  EXPECT_NEAR(adopted[0].t_state, 35.0, 1e-9);  // at the adoption, not at confidence (20 s)
  const auto never = fly(10.0 * sj, -1.0);
  ASSERT_EQ(never.size(), 1u);
  EXPECT_NEAR(never[0].t_state, 80.0, 1e-9);  // confident at 20 s + adopt_wait_s
  const auto agrees = fly(1.0 * sj, -1.0);   // within 3 sigma of the table: nothing to wait for
  ASSERT_EQ(agrees.size(), 1u);
  EXPECT_NEAR(agrees[0].t_state, 20.0, 1e-9);
  pol.adopt_wait_s = 0.0;  // off: planned at confidence
  const auto off = fly(10.0 * sj, 35.0);
  ASSERT_EQ(off.size(), 1u);
  EXPECT_NEAR(off[0].t_state, 20.0, 1e-9);
}

// adopt_settle_tau: with noisy sensors the flight's rate estimate is predicted with its model and
// pulled towards the gyro at the rate stage's cutoff omega_c, so after an adoption it relaxes to
// the new model's value as exp(-omega_c t); no plan is made for adopt_settle_tau / omega_c after
// it. The SPEC §6 filter's omega_c and the MEKF's rate stage each set their own wait; with the
// measurement as the estimate (noise-free sensors) there is nothing to wait for.
TEST(Replanner, AfterAnAdoptionNoPlanIsMadeUntilTheRateStageHasSettled) {
  const Vec3 w(0.01, 0.02, 0.03);
  const auto first_plan = [&](const gnc::GncParams& table, double tau) {
    ReplanPolicy pol = policy(0.0);
    pol.first_plan_s = 10.0;
    pol.first_plan_max_s = 200.0;
    pol.adopt_wait_s = 60.0;
    pol.adopt_settle_tau = tau;
    const double sj = 5e-4 * gnc::total_inertia(table.mass_hat).norm();
    Replanner rp(table, pol);
    for (int k = 0; k < 3000; ++k) {
      const double t = k * table.dt;
      gnc::GncTelemetry tl = tlm(t, gnc::Mode::kDetumble, w);
      tl.est = report(table, sj, 0.01, 0, 10.0 * sj);  // refutes the table: waits for adoption
      tl.est.inertia_confident = t >= 20.0 - 1e-9;
      tl.est.offset_confident = tl.est.inertia_confident;
      tl.est.adoptions = t >= 35.0 - 1e-9 ? 1u : 0u;
      if (rp.update(tl)) break;
    }
    EXPECT_EQ(rp.records().size(), 1u);
    return rp.records().empty() ? -1.0 : rp.records().front().t_state;
  };
  gnc::GncParams filter = case1_table();
  filter.estimator.kind = gnc::EstimatorKind::kFilter;  // omega_c = 0.02 pi rad/s
  const double settle = 3.0 / filter.estimator.omega_c;  // 47.7 s
  // The first telemetry tick at or after the adoption + the settling time.
  EXPECT_NEAR(first_plan(filter, 3.0), std::ceil((35.0 + settle) / filter.dt) * filter.dt, 1e-6);
  gnc::GncParams mekf = case1_table();
  mekf.estimator.kind = gnc::EstimatorKind::kMekf;
  mekf.mekf.rate_cutoff = 0.1;  // 30 s
  EXPECT_NEAR(first_plan(mekf, 3.0), 65.0, 1e-6);
  mekf.mekf.rate_cutoff = 0.0;  // the MEKF's rate is the bias-corrected gyro: no rate stage
  EXPECT_NEAR(first_plan(mekf, 3.0), 35.0, 1e-9);
  EXPECT_NEAR(first_plan(case1_table(), 3.0), 35.0, 1e-9);  // the measurement is the estimate
  EXPECT_NEAR(first_plan(filter, 0.0), 35.0, 1e-9);         // off
}

}  // namespace
}  // namespace rocksteady::ground::planner
