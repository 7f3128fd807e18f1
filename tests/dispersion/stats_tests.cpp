// Wilson intervals and percentiles against hand-computed values; the summary on synthetic draws.
#include <gtest/gtest.h>

#include <cmath>
#include <map>

#include "ground/dispersion/stats.hpp"

namespace rocksteady::dispersion {
namespace {

TEST(Wilson, HandComputedValues) {
  // 8 of 10, z = 1.959964: centre (0.8 + z^2/20) / (1 + z^2/10) = 0.99207 / 1.38415 = 0.716725;
  // half-width z / 1.38415 * sqrt(0.016 + z^2/400) = 1.41599 * 0.15883 = 0.224904.
  auto w = wilson_interval(8, 10);
  EXPECT_NEAR(w.first, 0.4901625, 1e-6);
  EXPECT_NEAR(w.second, 0.9433178, 1e-6);
  // 0 of 10: [0, z^2 / (n + z^2)] = [0, 3.841459 / 13.841459] = [0, 0.2775328].
  w = wilson_interval(0, 10);
  EXPECT_NEAR(w.first, 0.0, 1e-12);
  EXPECT_NEAR(w.second, 0.2775328, 1e-6);
  // n of n mirrors 0 of n.
  w = wilson_interval(10, 10);
  EXPECT_NEAR(w.first, 1.0 - 0.2775328, 1e-6);
  EXPECT_NEAR(w.second, 1.0, 1e-12);
  // 50 of 100: 0.5 -+ z * sqrt(0.0025 + z^2/40000) / (1 + z^2/100) = 0.5 -+ 0.0961...
  w = wilson_interval(50, 100);
  EXPECT_NEAR(w.first, 0.4038315, 1e-6);
  EXPECT_NEAR(w.second, 0.5961685, 1e-6);
}

TEST(Percentiles, LinearInterpolationBetweenOrderStatistics) {
  // Unsorted input; sorted 1..5. h = 4 p: p5 -> 1.2, p50 -> 3, p95 -> 4.8, p99 -> 4.96.
  const Percentiles p = percentiles({5.0, 1.0, 4.0, 2.0, 3.0});
  EXPECT_EQ(p.n, 5);
  EXPECT_NEAR(*p.p5, 1.2, 1e-12);
  EXPECT_NEAR(*p.p50, 3.0, 1e-12);
  EXPECT_NEAR(*p.p95, 4.8, 1e-12);
  EXPECT_NEAR(*p.p99, 4.96, 1e-12);
  EXPECT_EQ(*percentile({7.0}, 0.99), 7.0);
  EXPECT_FALSE(percentile({}, 0.5).has_value());
  // Two values 10, 20: p25 = 12.5.
  EXPECT_NEAR(*percentile({20.0, 10.0}, 0.25), 12.5, 1e-12);
}

StrategyOutcome ok(const std::string& s, double fuel, bool success) {
  StrategyOutcome o;
  o.strategy = s;
  o.status = "ok";
  o.total_fuel_kg = fuel;
  o.success = success;
  o.t_omega_conv_s = 1000.0 + fuel;
  if (success) o.t_q_conv_s = 2000.0 + fuel;
  return o;
}

TEST(Summary, SuccessWorstAndPairedDifferencesOnSyntheticDraws) {
  DispersionSpec spec;
  spec.name = "syn";
  spec.draws = 4;
  spec.strategies = {*campaign::parse_strategy("ntcl+fuel_optimal"),
                     *campaign::parse_strategy("ntcl+dpd_ref")};
  std::vector<DrawResult> draws(4);
  const double dj[] = {1e3, 1e4, 1e5, 1e6};
  const double fo[] = {80.0, 90.0, 150.0, 300.0};
  const double dpd[] = {100.0, 100.0, 110.0, 120.0};
  for (int i = 0; i < 4; ++i) {
    draws[static_cast<std::size_t>(i)].index = i;
    draws[static_cast<std::size_t>(i)].sampled.delta_j_norm = dj[i];
    draws[static_cast<std::size_t>(i)].runs = {ok("ntcl+fuel_optimal", fo[i], i != 3),
                                               ok("ntcl+dpd_ref", dpd[i], true)};
  }
  draws[2].runs[0].status = "no_plan";
  draws[2].runs[0].success = false;
  draws[2].runs[0].total_fuel_kg.reset();
  const Summary s = summarize(spec, draws);
  ASSERT_EQ(s.strategies.size(), 2u);
  EXPECT_EQ(s.strategies[0].successes, 2);
  EXPECT_EQ(s.strategies[0].no_plan, 1);
  EXPECT_EQ(s.strategies[1].successes, 4);
  // Worst first: the no-plan draw, then the unsuccessful one, then by fuel.
  ASSERT_GE(s.strategies[0].worst.size(), 3u);
  EXPECT_EQ(s.strategies[0].worst[0].draw, 2);
  EXPECT_EQ(s.strategies[0].worst[1].draw, 3);
  EXPECT_EQ(s.strategies[0].worst[2].draw, 1);
  // Paired: draws 0, 1, 3 flew both: differences -20, -10, 180.
  ASSERT_EQ(s.paired.size(), 1u);
  EXPECT_EQ(s.paired[0].n, 3);
  EXPECT_NEAR(s.paired[0].mean_diff_kg, 50.0, 1e-12);
  EXPECT_NEAR(*s.paired[0].diff.p50, -10.0, 1e-12);
  EXPECT_NEAR(s.paired[0].frac_a_less, 2.0 / 3.0, 1e-12);
  // Crossover between the 1e4 bin (-10) and the 1e6 bin (+180).
  ASSERT_EQ(s.crossovers.size(), 1u);
  ASSERT_TRUE(s.crossovers[0].crossover_kg_m2.has_value());
  EXPECT_GT(*s.crossovers[0].crossover_kg_m2, 1e4);
  EXPECT_LT(*s.crossovers[0].crossover_kg_m2, 1e6);
}

// The strengths 600 s after each thruster's first firing, summarised over synthetic draws: worst
// per draw, every pair, within 2 %, chi-square (1 dof) consistency and the confident ones, all
// recounted by hand below.
TEST(Summary, ThrusterStrengthsAfterFirstFiringPerDrawAndPerPair) {
  DispersionSpec spec;
  spec.name = "strengths";
  spec.strategies = {*campaign::parse_strategy("ntcl+dpd_ref:id")};
  auto mark = [](double err, double sigma, bool confident) {
    campaign::StrengthMark m;
    m.first_fired_s = 10.0;
    m.reached = true;
    m.err = err;
    m.sigma = sigma;
    m.confident = confident;
    return m;
  };
  std::vector<DrawResult> draws(3);
  for (int i = 0; i < 3; ++i) {
    draws[static_cast<std::size_t>(i)].index = i;
    StrategyOutcome o = ok("ntcl+dpd_ref:id", 90.0, true);
    o.estimation.identifying = true;
    o.estimation.marks.push_back(campaign::IdentificationMark{60.0, true});
    o.estimation.strengths.resize(16);  // never fired unless set below
    draws[static_cast<std::size_t>(i)].runs = {o};
  }
  auto& s0 = draws[0].runs[0].estimation.strengths;
  s0[0] = mark(0.010, 0.01, true);   // z 1.0: in band, within 2 %
  s0[1] = mark(0.030, 0.01, false);  // z 3.0: out of band, not within
  s0[2].first_fired_s = 3500.0;      // fired, run ended before its mark
  auto& s1 = draws[1].runs[0].estimation.strengths;
  s1[5] = mark(0.005, 0.002, true);  // z 2.5: out (6.25 > 3.841), within
  s1[6] = mark(0.019, 0.01, true);   // z 1.9: in (3.61), within
  // Draw 2: no thruster fired, so it has no worst thruster.
  const Summary s = summarize(spec, draws);
  ASSERT_EQ(s.strategies.size(), 1u);
  const StrengthStats& k = s.strategies[0].strengths;
  EXPECT_EQ(k.draws, 2);
  EXPECT_EQ(k.pairs, 4);
  EXPECT_EQ(k.never_fired, 13 + 14 + 16);
  EXPECT_EQ(k.confident, 3);
  EXPECT_NEAR(k.within_2pct, 3.0 / 4.0, 1e-12);
  EXPECT_NEAR(k.nees_in95, 2.0 / 4.0, 1e-12);
  ASSERT_EQ(k.worst.n, 2);  // 0.030 and 0.019
  EXPECT_NEAR(*k.worst.p50, 0.0245, 1e-12);
  ASSERT_EQ(k.all.n, 4);    // 0.005 0.010 0.019 0.030: p50 (0.010 + 0.019) / 2
  EXPECT_NEAR(*k.all.p50, 0.0145, 1e-12);
  ASSERT_EQ(k.worst_confident.n, 2);  // 0.010 and 0.019
  EXPECT_NEAR(*k.worst_confident.p95, 0.010 + 0.95 * 0.009, 1e-12);
}

// A fault dispersion over two study cases: isolation counted per kind, onset and case against the
// draw's injected fault, latency from onset, fuel penalty against the case's fault-free reference.
TEST(Summary, FaultsCountedAgainstTheInjectedFaultWithThePenaltyAgainstTheReference) {
  DispersionSpec spec;
  spec.name = "faults";
  spec.strategies = {*campaign::parse_strategy("ntcl+dpd_ref")};
  spec.faults.enabled = true;
  spec.faults.kinds = {plant::FaultKind::kStuckOn, plant::FaultKind::kStuckOff};
  spec.faults.onsets_s = {60.0};
  spec.faults.case_numbers = {1, 5};
  spec.faults.case_files = {"case1.yaml", "case5.yaml"};
  struct Row {
    int case_number;
    plant::FaultKind kind;
    int thruster;
    int confirmed_thruster;  // -1 none
    const char* confirmed_kind;
    int confirmations;
    double confirmed_at;
    double fuel;
    bool success;
  };
  const Row rows[] = {
      {1, plant::FaultKind::kStuckOn, 3, 3, "stuck-on", 1, 62.0, 110.0, true},    // isolated, 2 s
      {1, plant::FaultKind::kStuckOn, 4, 5, "stuck-on", 1, 61.0, 120.0, true},    // wrong thruster
      {5, plant::FaultKind::kStuckOn, 6, 6, "stuck-on", 1, 70.0, 130.0, false},   // isolated, 10 s
                                                                                  // (goals met)
      {5, plant::FaultKind::kStuckOn, 7, 7, "stuck-on", 2, 64.0, 140.0, true},    // and another
      {1, plant::FaultKind::kStuckOff, 0, 0, "stuck-on", 1, 90.0, 101.0, true},   // wrong kind
      {5, plant::FaultKind::kStuckOff, 1, -1, "", 0, 0.0, 95.0, true},            // none
  };
  std::vector<DrawResult> draws;
  int i = 0;
  for (const Row& r : rows) {
    DrawResult d;
    d.index = i++;
    d.sampled.case_number = r.case_number;
    d.sampled.has_fault = true;
    d.sampled.fault.kind = r.kind;
    d.sampled.fault.thruster = r.thruster;
    d.sampled.fault.onset_s = 60.0;
    StrategyOutcome o = ok("ntcl+dpd_ref", r.fuel, r.success);
    // Draw 2 met both SPEC §7 goals but left eps_trans on the way: a goal met, not a success.
    if (d.index == 2) o.t_q_conv_s = 3000.0;
    o.fdi.enabled = true;
    o.fdi.confirmations = r.confirmations;
    o.fdi.thruster = r.confirmed_thruster;
    o.fdi.kind = r.confirmed_kind;
    if (r.confirmations > 0) o.fdi.first_confirmation_s = r.confirmed_at;
    // Detection one second before each confirmation (draw 3: never detected); a stuck-on
    // confirmation closes its valve half a second before it (draw 2: before onset, not counted).
    if (r.confirmations > 0 && d.index != 3) o.fdi.fault_detected_s = r.confirmed_at - 1.0;
    if (r.kind == plant::FaultKind::kStuckOn && r.confirmations > 0) {
      o.fdi.valve_closed_s = d.index == 2 ? 50.0 : r.confirmed_at - 0.5;
    }
    d.runs = {o};
    draws.push_back(d);
  }
  std::vector<DrawResult> refs(2);
  refs[0].sampled.case_number = 1;
  refs[0].runs = {ok("ntcl+dpd_ref", 100.0, true)};
  refs[1].sampled.case_number = 5;
  refs[1].runs = {ok("ntcl+dpd_ref", 90.0, true)};
  const Summary s = summarize(spec, draws, refs);
  ASSERT_EQ(s.references.size(), 2u);
  auto group = [&](plant::FaultKind k, int c) -> const FaultGroupStats* {
    for (const FaultGroupStats& g : s.faults) {
      if (g.kind == plant::to_string(k) && g.case_number == c) return &g;
    }
    return nullptr;
  };
  const FaultGroupStats* on = group(plant::FaultKind::kStuckOn, 0);
  ASSERT_NE(on, nullptr);
  EXPECT_EQ(on->runs, 4);
  EXPECT_EQ(on->successes, 3);
  EXPECT_EQ(on->goals_met, 4);
  EXPECT_EQ(on->isolated, 2);
  EXPECT_EQ(on->wrong, 2);
  EXPECT_EQ(on->none, 0);
  EXPECT_NEAR(*on->latency_s.p50, 6.0, 1e-12);  // 2 s and 10 s
  EXPECT_NEAR(*on->latency_max_s, 10.0, 1e-12);
  // Detected in draws 0, 1, 2 (1, 0 and 9 s after onset), and in draw 3 by its confirmation (4 s:
  // no window above the bound), over every run, isolated or not.
  EXPECT_EQ(on->detected, 4);
  EXPECT_NEAR(*on->detection_s.p50, 2.5, 1e-12);
  EXPECT_NEAR(*on->detection_max_s, 9.0, 1e-12);
  // The valve over the isolated runs closed after onset: draw 0 only (1.5 s).
  EXPECT_EQ(on->valve_s.n, 1);
  EXPECT_NEAR(*on->valve_max_s, 1.5, 1e-12);
  // Penalties: 10, 20 (case 1, reference 100) and 40, 50 (case 5, reference 90).
  EXPECT_NEAR(*on->penalty_kg.p50, 30.0, 1e-12);
  EXPECT_NEAR(*on->penalty_max_kg, 50.0, 1e-12);
  const FaultGroupStats* on5 = group(plant::FaultKind::kStuckOn, 5);
  ASSERT_NE(on5, nullptr);
  EXPECT_EQ(on5->runs, 2);
  EXPECT_EQ(on5->isolated, 1);
  EXPECT_EQ(on5->wrong, 1);
  const FaultGroupStats* off = group(plant::FaultKind::kStuckOff, 0);
  ASSERT_NE(off, nullptr);
  EXPECT_EQ(off->isolated, 0);
  EXPECT_EQ(off->wrong, 1);
  EXPECT_EQ(off->none, 1);
  EXPECT_EQ(off->goals_met, 2);
  EXPECT_EQ(off->successes, 2);
  EXPECT_FALSE(off->latency_s.p50.has_value());
  EXPECT_NEAR(*off->penalty_kg.p50, 3.0, 1e-12);  // 1 and 5
  // Without references there is no penalty, and the counts are unchanged.
  const Summary bare = summarize(spec, draws);
  EXPECT_TRUE(bare.references.empty());
  for (const FaultGroupStats& g : bare.faults) {
    EXPECT_EQ(g.penalty_kg.n, 0);
    if (g.kind == "stuck_on" && g.case_number == 0) {
      EXPECT_EQ(g.isolated, 2);
    }
  }
}

// The faulty jet's firing before isolation at full thrust: its commanded impulse over the draw's
// true u_max, over the isolated runs only (a jet asked 300 N s of a 200 N jet fired 1.5 s; 100 N s
// of a 1 000 N jet, 0.1 s), per case and over every case.
TEST(Summary, AStuckOffJetsFiringBeforeIsolationIsItsImpulseAtFullThrust) {
  DispersionSpec spec;
  spec.name = "firing";
  spec.strategies = {*campaign::parse_strategy("ntcl+dpd_ref")};
  spec.faults.enabled = true;
  spec.faults.kinds = {plant::FaultKind::kStuckOff};
  spec.faults.onsets_s = {3000.0};
  spec.faults.case_numbers = {1, 4};
  spec.faults.case_files = {"case1.yaml", "case4.yaml"};
  struct Row {
    int case_number;
    double u_max;
    double impulse;
    bool isolated;
  };
  const Row rows[] = {{1, 200.0, 300.0, true}, {4, 1000.0, 100.0, true}, {1, 200.0, 5000.0, false}};
  std::vector<DrawResult> draws;
  int i = 0;
  for (const Row& r : rows) {
    DrawResult d;
    d.index = i++;
    d.sampled.case_number = r.case_number;
    d.sampled.has_fault = true;
    d.sampled.fault.kind = plant::FaultKind::kStuckOff;
    d.sampled.fault.thruster = 2;
    d.sampled.fault.onset_s = 3000.0;
    d.flown = Readback{};
    d.flown->u_max_true_n = r.u_max;
    StrategyOutcome o = ok("ntcl+dpd_ref", 100.0, true);
    o.fdi.enabled = true;
    o.fdi.fault_first_commanded_s = 3000.0;
    o.fdi.fault_commanded_s = 40.0;
    o.fdi.fault_commanded_impulse_ns = r.impulse;
    if (r.isolated) {
      o.fdi.confirmations = 1;
      o.fdi.thruster = 2;
      o.fdi.kind = "stuck-off";
      o.fdi.first_confirmation_s = 3100.0;
    }
    d.runs = {o};
    draws.push_back(d);
  }
  const Summary s = summarize(spec, draws, {});
  std::map<int, const FaultGroupStats*> by_case;
  for (const FaultGroupStats& g : s.faults) by_case[g.case_number] = &g;
  ASSERT_EQ(by_case.size(), 3u);
  const FaultGroupStats& all = *by_case.at(0);
  EXPECT_EQ(all.isolated, 2);
  EXPECT_EQ(all.firing_to_isolation_s.n, 2);
  EXPECT_NEAR(*all.firing_to_isolation_s.p50, 0.8, 1e-12);
  EXPECT_NEAR(*all.firing_to_isolation_max_s, 1.5, 1e-12);
  EXPECT_NEAR(*all.commanded_to_isolation_max_s, 40.0, 1e-12);  // ticks commanded at any force
  EXPECT_NEAR(*by_case.at(1)->firing_to_isolation_max_s, 1.5, 1e-12);
  EXPECT_NEAR(*by_case.at(4)->firing_to_isolation_s.p50, 0.1, 1e-12);
}

}  // namespace
}  // namespace rocksteady::dispersion
