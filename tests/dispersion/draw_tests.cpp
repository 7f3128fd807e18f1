// A draw flown through the campaign runner: the parameters read back from the plant and the flight
// application agree with the sampler (dispersions are really applied); a re-flown draw is bit for
// bit the same; the JSON round trip is exact.
#include <gtest/gtest.h>

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

struct Fixture {
  config::MissionConfig mission = config::load_mission(test::source("configs/mission.yaml"));
  config::GncConfig gnc = config::load_gnc(test::source("configs/gnc.yaml"));
  DispersionSpec spec;
  Fixture() {
    std::string t = test::replace_line(test::base_spec(), "strategies: [dpd, ntcl+dpd_ref]",
                                       "strategies: [dpd, ntcl+fuel_optimal]");
    spec = load_spec(test::write_temp("draw.yaml", t));
  }
};

void expect_rel(double a, double b, double tol, const char* what) {
  EXPECT_LE(std::fabs(a - b), tol * std::max(std::fabs(a), std::fabs(b)) + 1e-300)
      << what << " " << a << " " << b;
}

TEST(DrawFlown, ReadBackFromThePlantAndTheFlightSoftwareAgreesWithTheSampler) {
  Fixture f;
  const Sampler sampler(f.spec, f.mission);
  NoPlanner planner;
  for (int i = 0; i < 4; ++i) {
    const DrawResult r = fly_draw(f.mission, f.gnc, f.spec, sampler, i, planner);
    ASSERT_TRUE(r.flown.has_value()) << i;
    const DrawParams& d = r.sampled;
    const Readback& b = *r.flown;
    ASSERT_GT(d.delta_j_norm, 0.0);
    EXPECT_LE((b.delta_j - d.delta_j).norm(), 1e-9 * d.delta_j_norm) << i;
    expect_rel(b.delta_j_norm, d.delta_j_norm, 1e-9, "||dJ||");
    EXPECT_LE((b.delta_r - d.delta_r).norm(), 1e-12) << i;
    EXPECT_LE((b.omega0 - d.omega0).norm(), 1e-15) << i;
    EXPECT_LE((b.mrp0 - d.mrp0).norm(), 1e-12) << i;
    EXPECT_EQ(b.gyro_psd, d.gyro_psd);
    EXPECT_EQ(b.star_psd, d.star_psd);
    EXPECT_EQ(b.disturbance_sigma_nm, d.disturbance_sigma_nm);
    EXPECT_EQ(b.noise_seed, d.noise_seed);
    EXPECT_EQ(b.u_max_true_n, d.u_max_n);
    EXPECT_EQ(b.u_max_flight_n, d.u_max_n);
    EXPECT_EQ(b.allocator, "pinv");  // gnc.yaml's
    // The planner's refusal is a recorded "no plan" with its reason, the other strategy flew.
    ASSERT_EQ(r.runs.size(), 2u);
    EXPECT_EQ(r.runs[0].status, "ok");
    EXPECT_EQ(r.runs[1].status, "no_plan");
    EXPECT_NE(r.runs[1].note.find("test planner refuses"), std::string::npos);
  }
}

TEST(DrawFlown, AllocatorOfTheDispersionFileIsTheOneFlown) {
  Fixture f;
  f.spec.override_allocator = true;
  f.spec.allocator = gnc::AllocatorKind::kL1;
  NoPlanner planner;
  const DrawResult r = fly_draw(f.mission, f.gnc, f.spec, Sampler(f.spec, f.mission), 0, planner);
  ASSERT_TRUE(r.flown.has_value());
  EXPECT_EQ(r.flown->allocator, "l1");
}

TEST(DrawFlown, ReflownDrawIsBitForBitAndJsonRoundTripsExactly) {
  Fixture f;
  const Sampler sampler(f.spec, f.mission);
  NoPlanner planner;
  const DrawResult a = fly_draw(f.mission, f.gnc, f.spec, sampler, 3, planner);
  FlyOptions with_series;
  with_series.log_interval_s = 1.0;  // recording the series must not change the flight
  const DrawResult b =
      fly_draw(f.mission, f.gnc, f.spec, Sampler(f.spec, f.mission), 3, planner, with_series);
  EXPECT_EQ(to_json(a, false), to_json(b, false));
  const DrawResult c = draw_from_json(to_json(a));
  EXPECT_EQ(to_json(c).dump(), to_json(a).dump());
}

// A replan strategy's plans are in its draw file (a re-flown draw says what the re-planner did),
// without the solves' wall times, and read back exactly.
TEST(DrawFlown, ReplanEventsAreWrittenWithoutWallTimesAndReadBack) {
  Fixture f;
  NoPlanner planner;
  DrawResult a = fly_draw(f.mission, f.gnc, f.spec, Sampler(f.spec, f.mission), 3, planner);
  ASSERT_FALSE(a.runs.empty());
  EXPECT_EQ(to_json(a)["result"]["runs"][0].count("replan"), 0u);  // not a replan strategy
  campaign::ReplanReport& rp = a.runs[0].replan;
  rp.enabled = true;
  rp.plans = 2;
  rp.failed = 1;
  rp.delivered = 1;
  rp.switched = 1;
  for (int i = 0; i < 2; ++i) {
    campaign::ReplanEvent e;
    e.trigger = i == 0 ? "first" : "periodic";
    e.t_state_s = 827.9 + 600.0 * i;
    e.t_due_s = e.t_state_s + 10.0;
    e.t_delivered_s = i == 0 ? e.t_due_s : -1.0;
    e.ok = i == 0;
    e.error = i == 0 ? "" : "not verified";
    e.identified = true;
    e.planned_fuel_kg = 65.29 - 15.0 * i;
    e.t_final_s = 2157.27 - 500.0 * i;
    e.nodes = 101 + i;
    e.iterations = 77 + i;
    e.wall_s = 1.25;
    e.upload_id = 10 + i;
    rp.events.push_back(e);
  }
  const nlohmann::json j = to_json(a);
  const nlohmann::json& events = j["result"]["runs"][0]["replan"]["events"];
  ASSERT_EQ(events.size(), 2u);
  EXPECT_EQ(events[0].count("solve_wall_s"), 0u);
  const DrawResult back = draw_from_json(j);
  const campaign::ReplanReport& r = back.runs[0].replan;
  EXPECT_TRUE(r.enabled);
  EXPECT_EQ(r.failed, 1);
  ASSERT_EQ(r.events.size(), 2u);
  EXPECT_EQ(r.events[1].trigger, "periodic");
  EXPECT_EQ(r.events[1].error, "not verified");
  EXPECT_EQ(r.events[1].t_delivered_s, -1.0);
  EXPECT_EQ(r.events[0].planned_fuel_kg, 65.29);
  EXPECT_EQ(r.events[1].upload_id, 11);
  EXPECT_EQ(r.events[0].wall_s, 0.0);  // not written
  EXPECT_EQ(to_json(back).dump(), j.dump());
}

}  // namespace
}  // namespace rocksteady::dispersion
