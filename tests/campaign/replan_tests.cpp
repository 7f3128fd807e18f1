// The re-planning strategy in the in-process closed loop (plant + flight application): the
// re-planner plans from the flight's telemetry in simulated time and uplinks through the flight
// software's chunked uplink and LOAD_TRAJECTORY; the flight switches tables at tick boundaries.
#include <cmath>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "ground/campaign/fsw_flight_side.hpp"
#include "ground/campaign/runner.hpp"
#include "ground/campaign/strategy.hpp"
#include "ground/campaign/trajectory_source.hpp"
#include "ground/config/config.hpp"
#include "ground/planner/planner.hpp"

namespace rocksteady::campaign {
namespace {

const std::string kConfigs = std::string(ROCKSTEADY_SOURCE_DIR) + "/configs";

config::RunSetup case1() {
  return config::load_run(kConfigs + "/mission.yaml", kConfigs + "/gnc.yaml",
                          kConfigs + "/cases/case1.yaml");
}

// A short, fast policy: the first plan after 100 s on the D+PD reference, then a re-plan every
// 200 s (each plan takes ~1 s of CPU).
ReplanOptions fast_policy(double latency_s) {
  ReplanOptions o;
  o.latency_s = latency_s;
  o.first_plan_s = 100.0;
  o.first_plan_max_s = 100.0;
  o.period_s = 200.0;
  o.min_interval_s = 100.0;
  o.error_fraction = 0.0;  // periodic only: a predictable number of plans
  o.on_model_update = false;
  o.on_identified = false;
  o.early_plan_s = 0.0;    // the first plan at 100 s exactly, for the table
  o.refuted_max_s = 0.0;
  return o;
}

RunResult fly(const config::RunSetup& s, const ReplanOptions& policy, double duration,
              double log_interval, const std::string& strategy = "ntcl+replan") {
  FswFlightSide flight;
  RunOptions opt;
  opt.duration_s = duration;
  opt.log_interval_s = log_interval;
  opt.replan = policy;
  return run_closed_loop(s, *parse_strategy(strategy), flight, nullptr, opt);
}

TEST(ReplanStrategy, NameParsesWithIdentificationImplied) {
  const auto s = parse_strategy("ntcl+replan");
  ASSERT_TRUE(s.has_value());
  EXPECT_TRUE(s->replans());
  EXPECT_FALSE(s->needs_trajectory());  // nothing is planned before the run
  EXPECT_TRUE(s->identify);
  EXPECT_EQ(s->law, gnc::LawId::kNtcl);
  EXPECT_TRUE(parse_strategy("ntcl+replan:id").has_value());
  EXPECT_TRUE(parse_strategy("ntcl+replan:mekf").has_value());
  EXPECT_FALSE(parse_strategy("ntcl+replan:id:id").has_value());
  EXPECT_FALSE(parse_strategy("dpd+replan").has_value());  // D+PD cannot track
  // ":idx": identification with its excitation (gnc/estimation/README.md §I.6); one of the two.
  const auto x = parse_strategy("dpd:idx");
  ASSERT_TRUE(x.has_value());
  EXPECT_TRUE(x->identify);
  EXPECT_TRUE(x->excite);
  EXPECT_FALSE(parse_strategy("dpd:id")->excite);
  EXPECT_FALSE(parse_strategy("dpd:id:idx").has_value());
}

// The latency: every plan made from the telemetry at t reaches the flight no earlier than
// t + latency, and the flight's own mode telemetry (not the re-planner's bookkeeping) shows TRACK
// starting only after the first plan's delivery. Later plans are switched in during TRACK through
// the flight software (trajectory_switched), none refused.
TEST(ReplanStrategy, PlansAreActivatedNoEarlierThanTheLatencyAndSwitchedInDuringTrack) {
  ASSERT_TRUE(have_planner());
  const config::RunSetup s = case1();
  const double latency = 30.0;
  const RunResult r = fly(s, fast_policy(latency), 800.0, 0.1);
  ASSERT_EQ(r.status, RunStatus::kOk) << r.note;
  const ReplanReport& rep = r.replan;
  ASSERT_TRUE(rep.enabled);
  ASSERT_GE(rep.events.size(), 3u) << r.note;
  EXPECT_EQ(rep.failed, 0) << r.note;
  EXPECT_EQ(rep.delivered, static_cast<int>(rep.events.size()));
  for (const ReplanEvent& e : rep.events) {
    ASSERT_TRUE(e.ok) << e.error;
    EXPECT_GE(e.t_delivered_s, e.t_state_s + latency - 1e-9);
    EXPECT_LE(e.t_delivered_s, e.t_state_s + latency + s.truth.control_period_s + 1e-9);
    EXPECT_GT(e.planned_fuel_kg, 0.0);
  }
  EXPECT_EQ(rep.events.front().trigger, "first");
  EXPECT_NEAR(rep.events.front().t_state_s, 100.0, s.truth.control_period_s);
  // Every plan after the first was switched in while tracking, and none was stale.
  EXPECT_EQ(rep.switched, rep.delivered - 1);
  EXPECT_EQ(rep.refused, 0);
  // The flight's telemetry: DETUMBLE (the D+PD reference) until the first delivery, then TRACK.
  double first_track = -1.0;
  for (const TimeRow& row : r.series) {
    if (row.mode == gnc::Mode::kTrack) {
      first_track = row.t;
      break;
    }
    if (row.t > 1.0) {
      EXPECT_EQ(row.mode, gnc::Mode::kDetumble) << row.t;
    }
  }
  ASSERT_GT(first_track, 0.0);
  EXPECT_GE(first_track, rep.events.front().t_state_s + latency);
  EXPECT_EQ(r.final_mode, "TRACK");
  // The re-plans despin: the true rate fell while tracking.
  EXPECT_LT(r.final_rate_rad_s, 0.8 * s.truth.omega0.norm());
}

// In simulated time the re-planner is deterministic: the same run twice gives the same plans,
// bit for bit, and the same fuel.
TEST(ReplanStrategy, RunIsDeterministic) {
  ASSERT_TRUE(have_planner());
  const config::RunSetup s = case1();
  const RunResult a = fly(s, fast_policy(10.0), 500.0, 0.0);
  const RunResult b = fly(s, fast_policy(10.0), 500.0, 0.0);
  ASSERT_EQ(a.status, RunStatus::kOk) << a.note;
  ASSERT_EQ(b.status, RunStatus::kOk) << b.note;
  ASSERT_GE(a.replan.events.size(), 2u);
  ASSERT_EQ(a.replan.events.size(), b.replan.events.size());
  for (std::size_t i = 0; i < a.replan.events.size(); ++i) {
    EXPECT_EQ(a.replan.events[i].t_state_s, b.replan.events[i].t_state_s);
    EXPECT_EQ(a.replan.events[i].t_delivered_s, b.replan.events[i].t_delivered_s);
    EXPECT_EQ(a.replan.events[i].planned_fuel_kg, b.replan.events[i].planned_fuel_kg);
    EXPECT_EQ(a.replan.events[i].iterations, b.replan.events[i].iterations);
  }
  EXPECT_EQ(a.total_fuel_kg, b.total_fuel_kg);
  EXPECT_EQ(a.final_rate_rad_s, b.final_rate_rad_s);
  EXPECT_EQ(a.ticks, b.ticks);
}

// Case 2's a-priori model is 0.2 % of |J| off, inside the flight's fixed confidence bounds (1 %):
// the identifier resolves it within 300 s, and with the replan strategies' adopt_sigmas the flight
// adopts it (so its NTCL tracks the plan with the model the plan is for); without, it never does.
TEST(ReplanStrategy, FlightAdoptsAResolvedSmallModelErrorWithAdoptSigmas) {
  ASSERT_TRUE(have_planner());
  const config::RunSetup s = config::load_run(kConfigs + "/mission.yaml", kConfigs + "/gnc.yaml",
                                              kConfigs + "/cases/case2.yaml");
  ReplanOptions on;  // the defaults
  ASSERT_GT(on.adopt_sigmas, 0.0);
  // The identification excited by plans over 8 shortest despins (gnc.yaml's pseudoinverse): the
  // slower despin of the automatic 16 resolves the 0.2 % later than 500 s.
  on.horizon_factor = ground::planner::kHorizonFactor;
  ReplanOptions off = on;
  off.adopt_sigmas = 0.0;
  const RunResult a = fly(s, on, 500.0, 0.0);
  const RunResult b = fly(s, off, 500.0, 0.0);
  ASSERT_EQ(a.status, RunStatus::kOk) << a.note;
  ASSERT_EQ(b.status, RunStatus::kOk) << b.note;
  EXPECT_GE(a.estimation.model_adoptions, 1u);
  EXPECT_EQ(b.estimation.model_adoptions, 0u);
}

// Case 7 (noisy gyro, J_hat 1e7 kg m^2 and r_hat 1 m off) on the D+PD reference with the MEKF: the
// identifier's inertia becomes confident, its offset does not reach the flight's 5 cm bound, so
// by 1000 s nothing is adopted and no plan is made (the refuted a-priori model is waited out).
// With the replan strategies' offset bound at 1 m (--replan-offset-confident) the flight adopts the
// identified model and the first plan, for it, follows before 1000 s, after the rate stage has
// settled on the adopted model (adopt_settle_tau: no plan within 3 / omega_c of the adoption).
TEST(ReplanStrategy, AWiderOffsetBoundAdoptsAndPlansForTheIdentifiedModelInCase7) {
  ASSERT_TRUE(have_planner());
  const config::RunSetup s = config::load_run(kConfigs + "/mission.yaml", kConfigs + "/gnc.yaml",
                                              kConfigs + "/cases/case7.yaml");
  const auto fly7 = [&](double offset_confident_m, double settle_tau = 3.0) {
    FswFlightSide flight;
    RunOptions opt;
    opt.duration_s = 1000.0;
    opt.log_interval_s = 0.0;
    opt.replan.offset_confident_m = offset_confident_m;
    opt.replan.adopt_settle_tau = settle_tau;
    return run_closed_loop(s, *parse_strategy("ntcl+replan:mekf"), flight, nullptr, opt);
  };
  const RunResult flight_bound = fly7(0.0);
  const RunResult wide = fly7(1.0);
  ASSERT_EQ(flight_bound.status, RunStatus::kOk) << flight_bound.note;
  ASSERT_EQ(wide.status, RunStatus::kOk) << wide.note;
  EXPECT_EQ(flight_bound.estimation.model_adoptions, 0u);
  EXPECT_TRUE(flight_bound.replan.events.empty());
  ASSERT_GE(wide.estimation.model_adoptions, 1u);
  ASSERT_FALSE(wide.replan.events.empty());
  const ReplanEvent& first = wide.replan.events.front();
  EXPECT_TRUE(first.ok) << first.error;
  EXPECT_TRUE(first.identified);
  EXPECT_LT(first.t_state_s, 1000.0);
  // Without the settle the plan is made at the adoption (the flight is the same until then): the
  // settle moves it by 3 time constants of the MEKF's rate stage, to the next telemetry sample.
  const RunResult at_adoption = fly7(1.0, 0.0);
  ASSERT_FALSE(at_adoption.replan.events.empty());
  const double settle = 3.0 / s.flight.mekf.rate_cutoff;
  EXPECT_GE(first.t_state_s - at_adoption.replan.events.front().t_state_s, settle - 1e-6);
  EXPECT_LT(first.t_state_s - at_adoption.replan.events.front().t_state_s, settle + 0.2);
}

// The replan strategies' acquisition slew (ReplanOptions::slew_s -> the flight's guidance.slew_s):
// once the despin is over the flight turns to q_final at the slew's coast, below the SPEC §7 rate
// goal (10^-4 rad/s) for the whole turn, where Eqs. (46)-(48) (slew_s 0: gnc.yaml's own) start at
// their highest rate, above the goal in case 1.
TEST(ReplanStrategy, TheAcquisitionSlewTurnsBelowTheRateGoalWhereTheExponentialDoesNot) {
  ASSERT_TRUE(have_planner());
  const config::RunSetup s = case1();
  ASSERT_EQ(s.flight.guidance.slew_s, 0.0);  // gnc.yaml: the study's (46)-(48)
  const auto peak_after_despin = [&](double slew_s) {
    FswFlightSide flight;
    RunOptions opt;
    opt.duration_s = 5000.0;
    opt.log_interval_s = 10.0;
    opt.replan.slew_s = slew_s;
    opt.replan.horizon_factor = ground::planner::kHorizonFactor;  // the despin over by ~2500 s
    const RunResult r = run_closed_loop(s, *parse_strategy("ntcl+replan"), flight, nullptr, opt);
    EXPECT_EQ(r.status, RunStatus::kOk) << r.note;
    EXPECT_FALSE(r.replan.events.empty());
    if (r.replan.events.empty()) return 0.0;
    const ReplanEvent& last = r.replan.events.back();
    const double plan_end = last.t_delivered_s + last.t_final_s;  // the last plan flown
    EXPECT_LT(plan_end, 4000.0);
    double peak = 0.0;
    for (const TimeRow& row : r.series) {
      if (row.t > plan_end) peak = std::fmax(peak, row.omega.norm());
    }
    return peak;
  };
  ASSERT_EQ(ReplanOptions{}.slew_s, 40000.0);
  EXPECT_LT(peak_after_despin(ReplanOptions{}.slew_s), 1e-4);
  EXPECT_GT(peak_after_despin(0.0), 1e-4);
}

// Momentum tracking (ReplanOptions::momentum_k -> the flight's guidance.track_momentum_k), case 7
// with the MEKF: the first plan is made for the identified model at ~830 s, still ~1 % off. The
// NTCL on the plan's rates then fires the gyroscopic difference S(J_hat omega) omega_r for every
// rate the body takes off the plan; flying the plan's inertial momentum does not (gnc/control/
// laws.hpp momentum_torque). Same flight and the same plan; 600 s of it later the NTCL has spent
// several kg more (measured with gnc.yaml's pseudoinverse allocator: 61.6 against 54.0 kg in all,
// each with one later re-plan).
TEST(ReplanStrategy, MomentumTrackingFliesCase7sFirstPlanForLessFuelThanTheNtcl) {
  ASSERT_TRUE(have_planner());
  const config::RunSetup s = config::load_run(kConfigs + "/mission.yaml", kConfigs + "/gnc.yaml",
                                              kConfigs + "/cases/case7.yaml");
  ASSERT_EQ(s.flight.guidance.track_momentum_k, 0.0);  // gnc.yaml: the study's law on the rates
  const auto fly7 = [&](double momentum_k) {
    ReplanOptions o;
    o.momentum_k = momentum_k;
    o.horizon_factor = ground::planner::kHorizonFactor;  // the same plan for both
    return fly(s, o, 1430.0, 0.0, "ntcl+replan:mekf");
  };
  const RunResult ntcl = fly7(0.0);
  const RunResult momentum = fly7(ReplanOptions{}.momentum_k);
  ASSERT_GT(ReplanOptions{}.momentum_k, 0.0);
  for (const RunResult* r : {&ntcl, &momentum}) {
    ASSERT_EQ(r->status, RunStatus::kOk) << r->note;
    ASSERT_GE(r->replan.delivered, 1);
    EXPECT_TRUE(r->replan.events.front().identified);
    EXPECT_LT(r->replan.events.front().t_delivered_s, 900.0);
  }
  EXPECT_DOUBLE_EQ(ntcl.replan.events.front().planned_fuel_kg,
                   momentum.replan.events.front().planned_fuel_kg);  // the same plan
  EXPECT_LT(momentum.total_fuel_kg, ntcl.total_fuel_kg - 3.0);
  std::printf("case 7 by 1430 s: NTCL %.2f kg (%d plans), momentum %.2f kg (%d plans)\n",
              ntcl.total_fuel_kg, ntcl.replan.delivered, momentum.total_fuel_kg,
              momentum.replan.delivered);
}

// The replan strategies' horizon: with momentum tracking (their default) the re-planner plans over
// 16 shortest despins (ground/planner/planner.hpp kMomentumHorizonFactor) instead of 8. Case 7
// with the MEKF and the L1 allocator (as the README's results): the same identification, the first
// plan at ~830 s for the same model; the longer plans despin for less fuel, flown as planned
// (measured over 10^5 s: 91.35 against 92.55 kg at t_omega,conv, 92.86 against 94.35 kg in all).
TEST(ReplanStrategy, WithMomentumTrackingTheLongerHorizonDespinsCase7ForLessFuel) {
  ASSERT_TRUE(have_planner());
  config::RunSetup s = config::load_run(kConfigs + "/mission.yaml", kConfigs + "/gnc.yaml",
                                        kConfigs + "/cases/case7.yaml");
  s.flight.allocator = gnc::AllocatorKind::kL1;
  ASSERT_LE(ReplanOptions{}.horizon_factor, 0.0);  // the re-planner's automatic horizon
  ASSERT_GT(ReplanOptions{}.momentum_k, 0.0);
  const auto fly7 = [&](double horizon_factor) {
    ReplanOptions o;
    o.horizon_factor = horizon_factor;
    // 6500 s: both despins over (16 despins: by ~5700 s).
    return fly(s, o, 6500.0, 0.0, "ntcl+replan:mekf");
  };
  const RunResult eight = fly7(ground::planner::kHorizonFactor);
  const RunResult automatic = fly7(0.0);
  for (const RunResult* r : {&eight, &automatic}) {
    ASSERT_EQ(r->status, RunStatus::kOk) << r->note;
    ASSERT_FALSE(r->replan.events.empty());
    EXPECT_TRUE(r->replan.events.front().identified);
    ASSERT_TRUE(r->t_omega_conv_s.has_value());  // despun
  }
  EXPECT_NEAR(automatic.replan.events.front().t_state_s, eight.replan.events.front().t_state_s,
              1e-6);
  // The longer plan: twice the final time, less fuel planned from the same state.
  EXPECT_GT(automatic.replan.events.front().t_final_s,
            1.8 * eight.replan.events.front().t_final_s);
  EXPECT_LT(automatic.replan.events.front().planned_fuel_kg,
            eight.replan.events.front().planned_fuel_kg);
  EXPECT_GT(*automatic.t_omega_conv_s, *eight.t_omega_conv_s);
  EXPECT_LT(automatic.total_fuel_kg, eight.total_fuel_kg - 0.5);
  std::printf("case 7 by 6500 s: %.2f kg over 8 despins (despun at %.0f s), %.2f kg over 16 "
              "(at %.0f s)\n",
              eight.total_fuel_kg, *eight.t_omega_conv_s, automatic.total_fuel_kg,
              *automatic.t_omega_conv_s);
}

// The bare flight core has no uplink: the replan strategy says so instead of flying half a plan.
TEST(ReplanStrategy, CoreOnlyFlightSideRefusesTheUplinkAndTheRunSaysWhy) {
  ASSERT_TRUE(have_planner());
  const config::RunSetup s = case1();
  GncFlightSide core;
  RunOptions opt;
  opt.duration_s = 150.0;
  opt.log_interval_s = 0.0;
  opt.replan = fast_policy(10.0);
  const RunResult r = run_closed_loop(s, *parse_strategy("ntcl+replan"), core, nullptr, opt);
  ASSERT_EQ(r.status, RunStatus::kOk);
  EXPECT_EQ(r.replan.delivered, 0);
  EXPECT_GE(r.replan.failed, 1);
  EXPECT_NE(r.note.find("re-planning needs the flight application"), std::string::npos) << r.note;
  EXPECT_EQ(r.final_mode, "DETUMBLE");
}

}  // namespace
}  // namespace rocksteady::campaign
