// Fault dispersions: the thruster x kind x onset x case grid covers every combination once, a random
// plan stays in range and is a pure function of the draw, bad `faults:` entries name file, key and
// reason, and a drawn fault reaches the plant (read back) and changes the flight.
#include <gtest/gtest.h>

#include <filesystem>
#include <set>
#include <tuple>

#include "ground/campaign/fsw_flight_side.hpp"
#include "ground/dispersion/draw.hpp"
#include "tests/dispersion/test_util.hpp"

namespace rocksteady::dispersion {
namespace {

class NoPlanner final : public campaign::TrajectorySource {
 public:
  campaign::PlanOutcome plan(const campaign::PlanRequest&) override {
    return {nullptr, "no reference: test planner refuses", 0.0};
  }
  std::string name() const override { return "test"; }
};

std::string fault_spec(const std::string& plan, int draws) {
  return "name: f\n"
         "draws: " + std::to_string(draws) + "\n"
         "master_seed: 3\n"
         "sampling: random\n"
         "duration_s: 60.0\n"
         "strategies: [ntcl+dpd_ref]\n"
         "faults:\n"
         "  thrusters: [3, 12]\n"
         "  kinds: [stuck_on, stuck_off, degraded]\n"
         "  degraded_factor: 0.25\n"
         "  onsets_s: [5, 20]\n"
         "  cases: [" + test::source("configs/cases/case1.yaml") + ", " +
         test::source("configs/cases/case5.yaml") + "]\n"
         "  plan: " + plan + "\n";
}

struct Fixture {
  config::MissionConfig mission = config::load_mission(test::source("configs/mission.yaml"));
  config::GncConfig gnc = config::load_gnc(test::source("configs/gnc.yaml"));
};

TEST(FaultDispersion, GridCoversEveryThrusterKindOnsetAndCaseOnce) {
  Fixture f;
  const DispersionSpec spec = load_spec(test::write_temp("grid.yaml", fault_spec("grid", 24)));
  ASSERT_TRUE(spec.faults.enabled);
  EXPECT_EQ(spec.faults.grid_size(), 24u);
  EXPECT_EQ(spec.faults.case_numbers, (std::vector<int>{1, 5}));
  const Sampler sampler(spec, f.mission);
  std::set<std::tuple<int, int, double, int>> seen;
  for (int i = 0; i < 24; ++i) {
    const DrawParams d = sampler.draw(i);
    ASSERT_TRUE(d.has_fault);
    EXPECT_TRUE(d.error.empty());
    EXPECT_EQ(d.fault.factor, d.fault.kind == plant::FaultKind::kDegraded ? 0.25 : 1.0);
    seen.insert({d.fault.thruster, static_cast<int>(d.fault.kind), d.fault.onset_s, d.case_number});
    // Draw 24 + i repeats draw i.
    const DrawParams again = sampler.draw(24 + i);
    EXPECT_EQ(again.fault.thruster, d.fault.thruster);
    EXPECT_EQ(again.case_file, d.case_file);
  }
  std::set<std::tuple<int, int, double, int>> expected;
  for (int t : {3, 12})
    for (int k : {2, 1, 3})
      for (double o : {5.0, 20.0})
        for (int c : {1, 5}) expected.insert({t, k, o, c});
  EXPECT_EQ(seen, expected);
}

TEST(FaultDispersion, RandomPlanStaysInRangeAndIsAPureFunctionOfTheDraw) {
  Fixture f;
  const DispersionSpec spec = load_spec(test::write_temp("random.yaml", fault_spec("random", 200)));
  const Sampler a(spec, f.mission), b(spec, f.mission);
  std::set<int> thrusters, kinds, cases;
  for (int i = 0; i < 200; ++i) {
    const DrawParams d = a.draw(i);
    const DrawParams e = b.draw(i);
    EXPECT_EQ(d.fault.thruster, e.fault.thruster);
    EXPECT_EQ(d.fault.kind, e.fault.kind);
    EXPECT_EQ(d.fault.onset_s, e.fault.onset_s);
    EXPECT_EQ(d.case_file, e.case_file);
    thrusters.insert(d.fault.thruster);
    kinds.insert(static_cast<int>(d.fault.kind));
    cases.insert(d.case_number);
    EXPECT_TRUE(d.fault.onset_s == 5.0 || d.fault.onset_s == 20.0);
  }
  EXPECT_EQ(thrusters, (std::set<int>{3, 12}));
  EXPECT_EQ(kinds, (std::set<int>{1, 2, 3}));
  EXPECT_EQ(cases, (std::set<int>{1, 5}));
}

TEST(FaultDispersion, BadFaultEntriesNameFileKeyAndReason) {
  struct Bad {
    std::string from, to, key, reason;
  };
  const Bad bad[] = {
      {"thrusters: [3, 12]", "thrusters: [3, 16]", "faults.thrusters", "[0, 15]"},
      {"thrusters: [3, 12]", "thrusters: some", "faults.thrusters", "'all'"},
      {"kinds: [stuck_on, stuck_off, degraded]", "kinds: [stuck]", "faults.kinds", "stuck_off"},
      {"degraded_factor: 0.25", "degraded_factor: 1.0", "faults.degraded_factor", "(0, 1)"},
      {"onsets_s: [5, 20]", "onsets_s: [-5]", "faults.onsets_s", ">= 0"},
      {"plan: grid", "plan: sometimes", "faults.plan", "grid or random"},
      {"plan: grid", "plan: grid\n  extra: 1", "faults.extra", "unknown key"},
      {"cases: [", "cases: [/nonexistent/case9.yaml, ", "faults.cases", "cannot read file"},
  };
  for (const Bad& b : bad) {
    const std::string path =
        test::write_temp("bad.yaml", test::replace_line(fault_spec("grid", 4), b.from, b.to));
    try {
      load_spec(path);
      ADD_FAILURE() << "accepted " << b.to;
    } catch (const config::ConfigError& e) {
      EXPECT_EQ(e.file(), path);
      EXPECT_EQ(e.key(), b.key) << e.what();
      EXPECT_NE(std::string(e.what()).find(b.reason), std::string::npos) << e.what();
    }
  }
  // Cases fly their own parameters: a parameters section beside them is an error.
  const std::string both = test::write_temp("both.yaml", fault_spec("grid", 4) + "parameters: {}\n");
  try {
    load_spec(both);
    ADD_FAILURE() << "accepted parameters with faults.cases";
  } catch (const config::ConfigError& e) {
    EXPECT_EQ(e.key(), "parameters");
  }
  // Without cases, faults combine with the dispersed parameters.
  const std::string with_params = test::write_temp(
      "params.yaml", test::base_spec() + "faults:\n  thrusters: all\n  kinds: [stuck_on]\n"
                                         "  onsets_s: [10]\n");
  const DispersionSpec s = load_spec(with_params);
  EXPECT_EQ(s.faults.grid_size(), 16u);
  EXPECT_TRUE(s.faults.case_files.empty());
}

TEST(FaultDispersion, TheDrawnFaultReachesThePlantAndChangesTheFlight) {
  Fixture f;
  const DispersionSpec spec = load_spec(test::write_temp("fly.yaml", fault_spec("grid", 24)));
  const Sampler sampler(spec, f.mission);
  NoPlanner planner;
  // Draw 0: thruster 3 stuck on at 5 s in case 1.
  const DrawResult r = fly_draw(f.mission, f.gnc, spec, sampler, 0, planner);
  ASSERT_EQ(r.sampled.fault.thruster, 3);
  ASSERT_EQ(r.sampled.fault.kind, plant::FaultKind::kStuckOn);
  ASSERT_EQ(r.sampled.case_number, 1);
  ASSERT_TRUE(r.flown.has_value());
  EXPECT_EQ(r.flown->faults, "thruster 3 stuck_on at 5 s");
  ASSERT_EQ(r.runs.size(), 1u);
  EXPECT_EQ(r.runs[0].status, "ok");
  // The same case without the fault, through the campaign runner.
  config::RunSetup healthy = config::load_case_run(f.mission, f.gnc, test::source("configs/cases/case1.yaml"));
  campaign::FswFlightSide side;
  campaign::RunOptions opt;
  opt.duration_s = 60.0;
  opt.log_interval_s = 0.0;
  const campaign::RunResult h = campaign::run_closed_loop(healthy, spec.strategies[0], side, nullptr, opt);
  EXPECT_EQ(h.faults, "none");
  ASSERT_TRUE(r.runs[0].total_fuel_kg.has_value());
  // 55 s of a stuck-on 200 N thruster that the flight software does not know about: more propellant.
  EXPECT_GT(*r.runs[0].total_fuel_kg, h.total_fuel_kg);
  // The JSON round trip keeps the fault.
  const DrawResult back = draw_from_json(to_json(r));
  EXPECT_EQ(back.sampled.fault.thruster, 3);
  EXPECT_EQ(back.sampled.fault.kind, plant::FaultKind::kStuckOn);
  EXPECT_EQ(back.sampled.case_file, r.sampled.case_file);
  EXPECT_EQ(back.flown->faults, r.flown->faults);
}

// The fault-free reference of a case: the case as its draws fly it, without their fault, so the
// draws' fuel penalty is the fault's alone.
TEST(FaultDispersion, TheReferenceFliesTheCaseWithoutTheFault) {
  Fixture f;
  const DispersionSpec spec = load_spec(test::write_temp("ref.yaml", fault_spec("grid", 24)));
  const Sampler sampler(spec, f.mission);
  NoPlanner planner;
  const std::optional<DrawParams> p = reference_params(spec, sampler, 0);
  ASSERT_TRUE(p.has_value());
  EXPECT_FALSE(p->has_fault);
  EXPECT_EQ(p->case_number, 1);
  EXPECT_EQ(p->case_file, spec.faults.case_files[0]);
  EXPECT_EQ(reference_params(spec, sampler, 1)->case_number, 5);
  EXPECT_FALSE(reference_params(spec, sampler, 2).has_value());
  const DrawResult ref = fly_reference(f.mission, f.gnc, spec, *p, planner);
  ASSERT_TRUE(ref.flown.has_value());
  EXPECT_EQ(ref.flown->faults, "none");
  ASSERT_EQ(ref.runs.size(), 1u);
  ASSERT_TRUE(ref.runs[0].total_fuel_kg.has_value());
  // The same case through the campaign runner, independently: the same fuel to the bit.
  config::RunSetup healthy =
      config::load_case_run(f.mission, f.gnc, test::source("configs/cases/case1.yaml"));
  campaign::FswFlightSide side;
  campaign::RunOptions opt;
  opt.duration_s = spec.duration_s;
  const campaign::RunResult h =
      campaign::run_closed_loop(healthy, spec.strategies[0], side, nullptr, opt);
  EXPECT_EQ(*ref.runs[0].total_fuel_kg, h.total_fuel_kg);
  // Draw 0 (thruster 3 stuck on at 5 s in case 1) costs more than its reference.
  const DrawResult faulty = fly_draw(f.mission, f.gnc, spec, sampler, 0, planner);
  EXPECT_GT(*faulty.runs[0].total_fuel_kg, *ref.runs[0].total_fuel_kg);
  // Stored and read back as a draw file is.
  const std::string root =
      (std::filesystem::path(test::write_temp("ref.yaml", fault_spec("grid", 24))).parent_path() /
       "refdir")
          .string();
  write_reference(root, ref);
  const std::optional<DrawResult> back = read_reference(root, 1);
  ASSERT_TRUE(back.has_value());
  EXPECT_EQ(to_json(*back, false), to_json(ref, false));
  EXPECT_FALSE(read_reference(root, 5).has_value());
}

}  // namespace
}  // namespace rocksteady::dispersion
