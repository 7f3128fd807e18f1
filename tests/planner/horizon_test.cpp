// The planner at longer horizons (SPEC Eq. 44): validity of the plan against an independent
// propagation, self-verification, and the fuel's monotonicity in the horizon (a plan that reaches
// rest at T extends to T' > T by resting, so the optimum at T' never costs more).
#include <gtest/gtest.h>

#include <cmath>

#include "gnc/guidance/trajectory_buffers.hpp"
#include "gnc/model/mass_properties.hpp"
#include "gnc/model/rcs.hpp"
#include "ground/planner/planner.hpp"
#include "ground/planner/trajectory_file.hpp"

namespace rocksteady::ground::planner {
namespace {

constexpr double kShort = 1390.0;  // about the default horizon of case 1
constexpr double kLong = 2780.0;

// int |u|_1 dt by Simpson on every interval (nodes and midpoints), written here from the samples.
double simpson_cost(const std::vector<PlanSample>& s) {
  double c = 0.0;
  for (std::size_t a = 0; a + 2 < s.size(); a += 2) {
    const double h = s[a + 2].t - s[a].t;
    c += h / 6.0 *
         (s[a].u_d.cwiseAbs().sum() + 4.0 * s[a + 1].u_d.cwiseAbs().sum() +
          s[a + 2].u_d.cwiseAbs().sum());
  }
  return c;
}

struct Plans {
  PlanModel model = study_case_model(200.0, 0.0, 0.0);
  PlanResult short_plan;
  PlanResult long_plan;
  Plans() {
    PlanProblem p;
    p.model = model;
    p.settings.t_final_max = kShort;
    short_plan = plan(p);
    p.settings.t_final_max = kLong;
    long_plan = plan(p);
  }
};

const Plans& plans() {
  static const Plans p;
  return p;
}

TEST(PlannerHorizon, LongerPlanVerifiesItselfIncludingTheRefinedGrid) {
  const PlanResult& r = plans().long_plan;
  ASSERT_TRUE(r.ok) << r.error;
  EXPECT_TRUE(r.verification.passed) << r.verification.failure;
  EXPECT_TRUE(r.verification.refinement_checked);
  EXPECT_LT(r.verification.refinement_change, 0.01);
  EXPECT_DOUBLE_EQ(r.t_final, kLong);
  EXPECT_EQ(r.samples.size(), static_cast<std::size_t>(2 * r.nodes - 1));
  // The automatic grid: one node every kUniformStep seconds at least.
  EXPECT_LE(kLong / (r.nodes - 1), kUniformStep);
}

// Eq. (41) written out here (not the planner's helper), integrated with RK4 at 64 steps per
// interval under the piecewise-quadratic control through each interval's three samples. Returns the
// largest distance to the plan's nodes; `final_rate` is the open-loop rate at the end.
double open_loop_error(const PlanModel& m, const std::vector<PlanSample>& samples,
                       double& final_rate) {
  const Mat3 j_inv = m.j_hat.inverse();
  const auto f = [&](const Vec3& w, const Vec8& u) -> Vec3 {
    return j_inv * ((m.j_hat * w).cross(w) + m.b_hat * u);
  };
  Vec3 w = m.omega_init;
  double worst = 0.0;
  for (std::size_t a = 0; a + 2 < samples.size(); a += 2) {
    const PlanSample& s0 = samples[a];
    const PlanSample& s1 = samples[a + 1];
    const PlanSample& s2 = samples[a + 2];
    const double h = s2.t - s0.t;
    EXPECT_NEAR(s1.t, s0.t + 0.5 * h, 1e-9 * h);  // the midpoint sample is the midpoint
    const auto u = [&](double t) -> Vec8 {
      const double x = (t - s0.t) / h;
      return 2.0 * (x - 0.5) * (x - 1.0) * s0.u_d - 4.0 * x * (x - 1.0) * s1.u_d +
             2.0 * x * (x - 0.5) * s2.u_d;
    };
    constexpr int kSteps = 64;
    const double dt = h / kSteps;
    for (int k = 0; k < kSteps; ++k) {
      const double t = s0.t + k * dt;
      const Vec3 k1 = f(w, u(t));
      const Vec3 k2 = f(w + 0.5 * dt * k1, u(t + 0.5 * dt));
      const Vec3 k3 = f(w + 0.5 * dt * k2, u(t + 0.5 * dt));
      const Vec3 k4 = f(w + dt * k3, u(t + dt));
      w += dt / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
    }
    worst = std::max(worst, (w - s2.omega_d).norm());
  }
  final_rate = w.norm();
  return worst;
}

TEST(PlannerHorizon, PlanSatisfiesTheDynamicsAgainstAnIndependentRk4Propagation) {
  const PlanModel& m = plans().model;
  const PlanResult& r = plans().long_plan;
  ASSERT_TRUE(r.ok) << r.error;
  double final_rate = 0.0;
  const double worst = open_loop_error(m, r.samples, final_rate);
  const double tol = 1e-3 * m.omega_init.norm();  // the planner's own limit (propagation_limit)
  EXPECT_LT(worst, tol);
  EXPECT_LT(final_rate, tol);  // and the open-loop motion ends near rest
}

TEST(PlannerHorizon, LongerHorizonNeverCostsMoreThanTheShorterPlanExtendedByRest) {
  const Plans& p = plans();
  ASSERT_TRUE(p.short_plan.ok) << p.short_plan.error;
  ASSERT_TRUE(p.long_plan.ok) << p.long_plan.error;
  // The short plan, extended by rest (omega_d = 0, u_d = 0 satisfy Eq. 41 and the bounds exactly)
  // to the long horizon, is a feasible plan for it and costs what the short plan costs...
  const Verification v = verify_samples(p.model, p.short_plan.samples, 1e-3);
  EXPECT_TRUE(v.passed) << v.failure;
  EXPECT_EQ(p.short_plan.samples.back().omega_d, Vec3::Zero());
  const double extended_fuel = simpson_cost(p.short_plan.samples) / (kIsp * kG0);
  EXPECT_NEAR(extended_fuel, p.short_plan.fuel_kg, 1e-6 * p.short_plan.fuel_kg);
  // ... so the optimum at the long horizon costs no more (up to the refinement tolerance).
  EXPECT_LE(p.long_plan.fuel_kg, extended_fuel * (1.0 + 1e-3));
  // Its reported fuel is the Simpson integral of its own samples (Eq. 54).
  EXPECT_NEAR(p.long_plan.fuel_kg, simpson_cost(p.long_plan.samples) / (kIsp * kG0),
              1e-6 * p.long_plan.fuel_kg);
}

TEST(PlannerHorizon, TumbleFollowingGridVerifiesWithFewerSamplesAndTheSameFuel) {
  PlanProblem p;
  p.model = plans().model;
  p.settings.t_final_max = kShort;
  p.settings.tumble_grid = true;
  const PlanResult r = plan(p);
  ASSERT_TRUE(r.ok) << r.error;
  EXPECT_TRUE(r.verification.passed);
  EXPECT_TRUE(r.verification.refinement_checked);
  // The grid is not uniform, and the intervals are shorter where the body turns faster.
  const PlanResult& uniform = plans().short_plan;
  ASSERT_TRUE(uniform.ok);
  EXPECT_LT(r.samples.size(), uniform.samples.size());
  EXPECT_NEAR(r.fuel_kg, uniform.fuel_kg, 0.005 * uniform.fuel_kg);
  double min_h = 1e300, max_h = 0.0;
  for (std::size_t a = 0; a + 2 < r.samples.size(); a += 2) {
    const double h = r.samples[a + 2].t - r.samples[a].t;
    min_h = std::min(min_h, h);
    max_h = std::max(max_h, h);
  }
  EXPECT_GT(max_h, 1.2 * min_h);
}

}  // namespace
}  // namespace rocksteady::ground::planner

namespace rocksteady::ground::planner {
namespace {

TEST(Replan, FromAMidDespinStateVerifiesCostsNoMoreThanTheRestAndIsAcceptedOnBoard) {
  // Fly half of the default case-1 plan (open loop, on the estimated model = truth here), then
  // re-plan from the rate reached, warm-started from the rest of the plan, for the same end time.
  const PlanResult& first = plans().short_plan;
  ASSERT_TRUE(first.ok) << first.error;
  const double t_now = 0.5 * kShort;
  const std::vector<PlanSample> rest = remaining_plan(first.samples, t_now);
  ASSERT_GE(rest.size(), 3u);
  ASSERT_EQ(rest.size() % 2, 1u);
  EXPECT_EQ(rest.front().t, 0.0);
  EXPECT_NEAR(rest.back().t, kShort - t_now, 1e-9);
  const Vec3 omega_now = rest.front().omega_d;  // the state the flight would report

  gnc::GncParams active;  // the parameter table the flight flies with: the case-1 estimate
  active.mass_hat = gnc::study_true_mass_properties();
  active.rcs = gnc::study_rcs_layout(200.0);
  PlanProblem p;
  p.model = replan_model(active, omega_now);
  EXPECT_LT((p.model.j_hat - plans().model.j_hat).norm(), 1e-6 * plans().model.j_hat.norm());
  EXPECT_LT((p.model.b_hat - plans().model.b_hat).norm(), 1e-9);
  p.settings.t_final_max = kShort - t_now;
  p.warm_start = &rest;
  const PlanResult re = plan(p);
  ASSERT_TRUE(re.ok) << re.error;
  EXPECT_TRUE(re.verification.passed);
  EXPECT_EQ(re.samples.front().omega_d, omega_now);
  // The rest of the first plan is (up to its first, interpolated interval) a plan for the same
  // problem, so the re-plan's optimum costs no more than it (1 % covers that interval).
  EXPECT_LE(re.fuel_kg, simpson_cost(rest) / (kIsp * kG0) * 1.01);
  // On board: the table validates, and a flight core tracking the first plan accepts it at the
  // boundary (a sample at the current rate: not stale).
  const gnc::TrajectoryTable table = to_table(re.samples);
  EXPECT_EQ(gnc::validate_trajectory(table, p.model.eps_trans), gnc::TrajectoryError::kOk);
  gnc::TrajectoryBuffers buffers;
  ASSERT_EQ(buffers.load(to_table(first.samples), p.model.eps_trans, false), gnc::TrajectoryError::kOk);
  ASSERT_EQ(buffers.load(table, p.model.eps_trans, true), gnc::TrajectoryError::kOk);
  EXPECT_EQ(buffers.switch_at_boundary(omega_now, gnc::stale_tolerance(omega_now)),
            gnc::SwitchOutcome::kSwitched);
}

}  // namespace
}  // namespace rocksteady::ground::planner

namespace rocksteady::ground::planner {
namespace {

TEST(PlannerHorizon, HorizonBeyondTheTablePlannedInFullIsRefusedWithTheReason) {
  PlanProblem p;
  p.model = study_case_model(200.0, 0.0, 0.0);
  p.settings.t_final_max = kStudyHorizon;
  p.settings.active_horizon_max = -1.0;  // the whole horizon on the uniform grid
  const PlanResult r = plan(p);
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.error.find("needs 1761 nodes"), std::string::npos) << r.error;
  EXPECT_NE(r.error.find("holds 512"), std::string::npos) << r.error;
  EXPECT_EQ(r.iterations, 0);  // refused before solving
}

// The study's horizon (44 000 s) with the default settings: a despin over at most the active
// horizon, then rest; checked here against independent computations.
TEST(PlannerHorizon, StudyHorizonPlanDespinsWithinTheActiveHorizonThenRestsAndVerifies) {
  const PlanModel m = study_case_model(200.0, 0.0, 0.0);
  PlanProblem p;
  p.model = m;
  p.settings.t_final_max = kStudyHorizon;
  const PlanResult r = plan(p);
  ASSERT_TRUE(r.ok) << r.error;
  EXPECT_TRUE(r.verification.passed) << r.verification.failure;
  EXPECT_TRUE(r.verification.refinement_checked);  // the despin's own grid-refinement check
  EXPECT_LT(r.verification.refinement_change, 0.01);
  EXPECT_EQ(r.t_final, kStudyHorizon);
  EXPECT_EQ(r.samples.back().t, kStudyHorizon);
  EXPECT_GT(r.t_active, 0.0);
  EXPECT_LE(r.t_active, kActiveHorizon);
  EXPECT_EQ(r.samples.size(), static_cast<std::size_t>(2 * r.nodes - 1));
  // After the despin: at rest, no control (Eq. 41 holds exactly), and the despin ends with u = 0.
  std::size_t after = 0;
  for (const PlanSample& s : r.samples) {
    if (s.t < r.t_active) continue;
    EXPECT_EQ(s.omega_d, Vec3::Zero()) << "t = " << s.t;
    EXPECT_EQ(s.u_d, Vec8::Zero()) << "t = " << s.t;
    EXPECT_EQ(s.omega_d_dot, Vec3::Zero()) << "t = " << s.t;
    ++after;
  }
  EXPECT_EQ(after, 3u);  // the despin's last node, the rest interval's midpoint and end
  // The dynamics by an independent propagation, rest tail included (torque-free motion of the
  // residual rate for 38 000 s stays within the planner's limit).
  double final_rate = 0.0;
  const double worst = open_loop_error(m, r.samples, final_rate);
  EXPECT_LT(worst, 1e-3 * m.omega_init.norm());
  EXPECT_LT(final_rate, 1e-3 * m.omega_init.norm());
  // Fuel: the Simpson integral of its own samples (Eq. 54), and no more than the plan at the
  // automatic horizon (one of the candidates; the longer ones are kept only when cheaper).
  EXPECT_NEAR(r.fuel_kg, simpson_cost(r.samples) / (kIsp * kG0), 1e-6 * r.fuel_kg);
  PlanProblem automatic;
  automatic.model = m;
  const PlanResult a = plan(automatic);
  ASSERT_TRUE(a.ok) << a.error;
  EXPECT_LE(r.fuel_kg, a.fuel_kg);
  // On board: it fits the table, validates, and the reference is exactly at rest in the tail.
  const gnc::TrajectoryTable table = to_table(r.samples);
  EXPECT_EQ(gnc::validate_trajectory(table, m.eps_trans), gnc::TrajectoryError::kOk);
  for (double t : {r.t_active, 0.5 * (r.t_active + kStudyHorizon), kStudyHorizon - 1.0}) {
    const gnc::TrajectoryPoint q = gnc::interpolate(table, t);
    EXPECT_EQ(q.omega_d, Vec3::Zero()) << "t = " << t;
    EXPECT_EQ(q.omega_d_dot, Vec3::Zero()) << "t = " << t;
  }
  // The file round trip re-verifies the whole plan against the model.
  const LoadResult loaded =
      parse_trajectory_file(format_trajectory_file(p, r), "study-horizon", m);
  ASSERT_TRUE(loaded.ok) << loaded.error;
  EXPECT_EQ(loaded.file.to_table().checksum, table.checksum);
}

// Every horizon beyond the active one gets the same despin (the same candidates, solved the same
// way), only the rest is longer; a shorter active horizon (here 2 candidates) bounds the work.
TEST(PlannerHorizon, HorizonsBeyondTheActiveOneShareTheSameDespin) {
  PlanProblem p;
  p.model = study_case_model(200.0, 0.0, 0.0);
  p.settings.active_horizon_max = 2000.0;
  p.settings.t_final_max = 22000.0;
  const PlanResult a = plan(p);
  p.settings.t_final_max = 50000.0;
  const PlanResult b = plan(p);
  ASSERT_TRUE(a.ok) << a.error;
  ASSERT_TRUE(b.ok) << b.error;
  EXPECT_EQ(a.t_active, b.t_active);
  EXPECT_LE(a.t_active, 2000.0);
  EXPECT_EQ(a.fuel_kg, b.fuel_kg);
  ASSERT_EQ(a.samples.size(), b.samples.size());
  for (std::size_t i = 0; i + 2 < a.samples.size(); ++i) {
    EXPECT_EQ(a.samples[i].t, b.samples[i].t);
    EXPECT_EQ(a.samples[i].omega_d, b.samples[i].omega_d);
    EXPECT_EQ(a.samples[i].u_d, b.samples[i].u_d);
  }
  EXPECT_EQ(b.samples.back().t, 50000.0);
  // The despin is the cheaper of the automatic horizon's and 2000 s, both ending with u = 0: it
  // costs no more than the automatic-horizon plan with u_d(t_f) = 0, planned here on its own.
  PlanProblem at_auto;
  at_auto.model = p.model;
  double t_auto_min = 0.0;
  double t_auto = 0.0;
  resolve_final_time_bounds(p.model, PlanSettings{}, t_auto_min, t_auto);
  at_auto.settings.t_final_max = 50000.0;
  at_auto.settings.active_horizon_max = t_auto;  // the automatic horizon alone, then rest
  const PlanResult c = plan(at_auto);
  ASSERT_TRUE(c.ok) << c.error;
  EXPECT_LE(a.fuel_kg, c.fuel_kg);
}

// The candidates of a long horizon solved in worker processes (PlanSettings::jobs) give the plan
// solved one after the other in this process, bit for bit: the workers share nothing, and the
// choice among the candidates does not depend on the order they finish in.
TEST(PlannerHorizon, CandidatesSolvedInWorkerProcessesGiveTheSamePlanAsInProcess) {
  PlanProblem p;
  p.model = study_case_model(200.0, 0.0, 0.0);
  p.settings.active_horizon_max = 3000.0;  // candidates 1 390 s, 3 000 s
  p.settings.t_final_max = 22000.0;
  p.settings.jobs = 1;
  const PlanResult serial = plan(p);
  p.settings.jobs = 2;
  const PlanResult parallel = plan(p);
  ASSERT_TRUE(serial.ok) << serial.error;
  ASSERT_TRUE(parallel.ok) << parallel.error;
  EXPECT_EQ(serial.fuel_kg, parallel.fuel_kg);
  EXPECT_EQ(serial.t_active, parallel.t_active);
  EXPECT_EQ(serial.iterations, parallel.iterations);
  EXPECT_EQ(serial.nodes, parallel.nodes);
  EXPECT_EQ(serial.verification.refined_fuel_kg, parallel.verification.refined_fuel_kg);
  ASSERT_EQ(serial.samples.size(), parallel.samples.size());
  for (std::size_t i = 0; i < serial.samples.size(); ++i) {
    EXPECT_EQ(serial.samples[i].t, parallel.samples[i].t) << i;
    EXPECT_EQ(serial.samples[i].omega_d, parallel.samples[i].omega_d) << i;
    EXPECT_EQ(serial.samples[i].omega_d_dot, parallel.samples[i].omega_d_dot) << i;
    EXPECT_EQ(serial.samples[i].u_d, parallel.samples[i].u_d) << i;
  }
}

}  // namespace
}  // namespace rocksteady::ground::planner
