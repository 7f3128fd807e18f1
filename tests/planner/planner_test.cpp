// The planner against independent truths: the spherical-body closed form, an independently simulated
// rate-damping law (fuel upper bound), an independent open-loop propagation, and failure handling.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <array>
#include <cmath>
#include <filesystem>
#include <limits>
#include <thread>
#include <vector>

#include "ground/planner/cache.hpp"
#include "ground/planner/planner.hpp"

namespace rocksteady::ground::planner {
namespace {

constexpr double kIspG0 = 287.0 * 9.8;  // SPEC Eq. (54)

Vec3 rate_derivative(const PlanModel& m, const Vec3& omega, const Vec8& u) {
  const Vec3 h = m.j_hat * omega;
  return m.j_hat.inverse() * (h.cross(omega) + m.b_hat * u);  // Eq. (41), written again here
}

// min ||v||_1 subject to B v = h, by enumerating the vertices of the LP: every basic solution uses
// three channels; solve each non-singular 3x3 system and keep the smallest 1-norm.
Vec8 l1_minimum(const Mat38& b, const Vec3& h) {
  Vec8 best = Vec8::Zero();
  double best_norm = std::numeric_limits<double>::infinity();
  for (int i = 0; i < 8; ++i) {
    for (int j = i + 1; j < 8; ++j) {
      for (int k = j + 1; k < 8; ++k) {
        Mat3 sub;
        sub << b.col(i), b.col(j), b.col(k);
        if (std::abs(sub.determinant()) < 1e-9 * std::pow(b.norm(), 3)) continue;
        const Vec3 s = sub.lu().solve(h);
        if (s.lpNorm<1>() < best_norm) {
          best_norm = s.lpNorm<1>();
          best = Vec8::Zero();
          best[i] = s[0];
          best[j] = s[1];
          best[k] = s[2];
        }
      }
    }
  }
  return best;
}

// Fuel of the rate-damping law u_c = -K_d omega (Eq. 49) with the pseudo-inverse allocation (Eq. 53,
// scaled into the box), simulated with RK4 on the same model until |omega| <= 1e-5 rad/s.
double rate_damping_fuel(const PlanModel& m) {
  const Eigen::Matrix<double, 8, 3> b_pinv =
      m.b_hat.transpose() * (m.b_hat * m.b_hat.transpose()).inverse();
  const auto control = [&](const Vec3& omega) -> Vec8 {
    Vec8 u = b_pinv * (-1e4 * omega);
    const double peak = u.cwiseAbs().maxCoeff();
    if (peak > m.u_max) u *= m.u_max / peak;
    return u;
  };
  Vec3 omega = m.omega_init;
  double cost = 0.0;
  const double dt = 0.5;
  for (double t = 0.0; t < 1e5 && omega.norm() > 1e-5; t += dt) {
    const Vec8 u = control(omega);  // zero-order hold over the step
    const Vec3 k1 = rate_derivative(m, omega, u);
    const Vec3 k2 = rate_derivative(m, omega + 0.5 * dt * k1, u);
    const Vec3 k3 = rate_derivative(m, omega + 0.5 * dt * k2, u);
    const Vec3 k4 = rate_derivative(m, omega + dt * k3, u);
    omega += dt / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4);
    cost += u.lpNorm<1>() * dt;
  }
  EXPECT_LE(omega.norm(), 1e-5) << "rate damping did not reach rest";
  return cost / kIspG0;
}

class Case1Plan : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    problem_ = new PlanProblem();
    problem_->case_name = "case1";
    problem_->model = study_case_model(200.0, 0.0, 0.0);
    result_ = new PlanResult(plan(*problem_));
  }
  static void TearDownTestSuite() {
    delete problem_;
    delete result_;
  }
  static PlanProblem* problem_;
  static PlanResult* result_;
};
PlanProblem* Case1Plan::problem_ = nullptr;
PlanResult* Case1Plan::result_ = nullptr;

TEST_F(Case1Plan, ConvergesAndVerifiesItself) {
  const PlanResult& r = *result_;
  ASSERT_TRUE(r.ok) << r.error;
  EXPECT_TRUE(r.verification.passed) << r.verification.failure;
  EXPECT_TRUE(r.verification.refinement_checked);
  EXPECT_LT(r.verification.refinement_change, 0.01);
  EXPECT_GT(r.iterations, 0);
  EXPECT_EQ(r.nodes, kDefaultNodes);
  EXPECT_EQ(r.samples.size(), static_cast<std::size_t>(2 * kDefaultNodes - 1));
  EXPECT_NEAR(r.fuel_kg, r.cost_ns / kIspG0, 1e-9 * r.fuel_kg);
}

TEST_F(Case1Plan, MeetsBoundsAndBoundaryConditions) {
  const PlanResult& r = *result_;
  ASSERT_TRUE(r.ok) << r.error;
  const PlanModel& m = problem_->model;
  EXPECT_EQ(r.samples.front().t, 0.0);
  EXPECT_EQ(r.samples.front().omega_d, m.omega_init);   // Eq. (43)
  EXPECT_EQ(r.samples.back().omega_d, Vec3::Zero());    // Eq. (43)
  EXPECT_DOUBLE_EQ(r.samples.back().t, r.t_final);
  for (const PlanSample& s : r.samples) {
    EXPECT_LE(s.omega_d.norm(), m.eps_trans * (1 + 1e-12));
    EXPECT_LE(s.u_d.cwiseAbs().maxCoeff(), m.u_max * (1 + 1e-12));
    EXPECT_LT((s.omega_d_dot - rate_derivative(m, s.omega_d, s.u_d)).norm(), 1e-15);
  }
  EXPECT_GE(r.t_final, r.t_final_min * (1 - 1e-12));
  EXPECT_LE(r.t_final, r.t_final_max * (1 + 1e-12));
  // No plan can be shorter than |H0| / (u_max sum |B_i|) (|H| only changes through the thrusters).
  double torque_bound = 0.0;
  for (int i = 0; i < 8; ++i) torque_bound += m.b_hat.col(i).norm() * m.u_max;
  EXPECT_GE(r.t_final, (m.j_hat * m.omega_init).norm() / torque_bound);
}

TEST_F(Case1Plan, OpenLoopPropagationReproducesTheRatesAndEndsAtRest) {
  // Independent propagation: RK4 with the controls interpolated quadratically through each
  // interval's node, midpoint and node values; 64 steps per interval.
  const PlanResult& r = *result_;
  ASSERT_TRUE(r.ok) << r.error;
  const PlanModel& m = problem_->model;
  Vec3 omega = m.omega_init;
  double worst = 0.0;
  for (std::size_t a = 0; a + 2 < r.samples.size(); a += 2) {
    const double t0 = r.samples[a].t;
    const double h = r.samples[a + 2].t - t0;
    const auto u = [&](double t) -> Vec8 {
      const double s = (t - t0) / h;
      return 2 * (s - 0.5) * (s - 1) * r.samples[a].u_d - 4 * s * (s - 1) * r.samples[a + 1].u_d +
             2 * s * (s - 0.5) * r.samples[a + 2].u_d;
    };
    const int steps = 64;
    const double dt = h / steps;
    for (int k = 0; k < steps; ++k) {
      const double t = t0 + k * dt;
      const Vec3 k1 = rate_derivative(m, omega, u(t));
      const Vec3 k2 = rate_derivative(m, omega + 0.5 * dt * k1, u(t + dt / 2));
      const Vec3 k3 = rate_derivative(m, omega + 0.5 * dt * k2, u(t + dt / 2));
      const Vec3 k4 = rate_derivative(m, omega + dt * k3, u(t + dt));
      omega += dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
    }
    worst = std::max(worst, (omega - r.samples[a + 2].omega_d).norm());
  }
  EXPECT_LT(worst, 1e-3 * m.omega_init.norm());
  EXPECT_LT(omega.norm(), 1e-3 * m.omega_init.norm());
}

TEST_F(Case1Plan, UsesLessFuelThanPseudoInverseRateDamping) {
  const PlanResult& r = *result_;
  ASSERT_TRUE(r.ok) << r.error;
  const double damping = rate_damping_fuel(problem_->model);
  RecordProperty("planned_fuel_kg", std::to_string(r.fuel_kg));
  RecordProperty("rate_damping_fuel_kg", std::to_string(damping));
  EXPECT_LT(r.fuel_kg, damping);
}

TEST_F(Case1Plan, TableValidatesAndInterpolatesThroughTheSamples) {
  const PlanResult& r = *result_;
  ASSERT_TRUE(r.ok) << r.error;
  const gnc::TrajectoryTable table = to_table(r.samples);
  EXPECT_EQ(gnc::validate_trajectory(table, problem_->model.eps_trans), gnc::TrajectoryError::kOk);
  for (std::size_t i = 0; i < r.samples.size(); i += 7) {
    const gnc::TrajectoryPoint p = gnc::interpolate(table, r.samples[i].t);
    EXPECT_LT((p.omega_d - r.samples[i].omega_d).norm(), 1e-12);
  }
  // Between samples the on-board cubic Hermite stays close to the dynamics' own motion.
  EXPECT_LT(r.verification.propagation_error, 1e-3 * problem_->model.omega_init.norm());
}

TEST(Planner, SphericalBodyFuelMatchesTheClosedForm) {
  // No gyroscopic coupling: the body-frame momentum only changes through the thrusters, so the
  // least fuel is min ||v||_1 s.t. B v = -H0 over the total impulse v, divided by I_sp g0.
  PlanProblem p;
  p.case_name = "spherical";
  p.model = study_case_model(200.0, 0.0, 0.0);
  p.model.j_hat = 3e7 * Mat3::Identity();
  const Vec3 h0 = p.model.j_hat * p.model.omega_init;
  const Vec8 v = l1_minimum(p.model.b_hat, -h0);
  ASSERT_LT((p.model.b_hat * v + h0).norm(), 1e-6 * h0.norm());
  const double closed_form = h0.norm() * l1_minimum(p.model.b_hat, -h0 / h0.norm()).lpNorm<1>() / kIspG0;
  EXPECT_NEAR(closed_form, v.lpNorm<1>() / kIspG0, 1e-9 * closed_form);
  // The constant-rate burn of that impulse takes max|v_i| / u_max: leave room for it.
  p.settings.t_final_max = 2.0 * v.cwiseAbs().maxCoeff() / p.model.u_max;
  p.settings.nodes = 41;
  const PlanResult r = plan(p);
  ASSERT_TRUE(r.ok) << r.error;
  EXPECT_NEAR(r.fuel_kg, closed_form, 0.01 * closed_form);
  EXPECT_GE(r.fuel_kg, closed_form * (1 - 1e-6));  // it is a lower bound for every transcription
}

TEST(Planner, PlansFromConcurrentThreadsEqualTheSerialPlan) {
  // The campaign's workers re-plan at the same time (ntcl+replan with --jobs 2): IPOPT with
  // sequential MUMPS is process-global, so plan() serialises the solves. Every concurrent plan must
  // be the serial plan, bit for bit (and the process must survive).
  PlanProblem p;
  p.case_name = "concurrent";
  p.model = study_case_model(200.0, 0.0, 0.0);
  p.settings.t_final_max = 600.0;
  p.settings.nodes = 41;
  const PlanResult serial = plan(p);
  ASSERT_TRUE(serial.ok) << serial.error;
  constexpr int kThreads = 3;
  std::vector<PlanResult> results(kThreads);
  std::vector<std::thread> pool;
  for (int i = 0; i < kThreads; ++i) {
    pool.emplace_back([&p, &results, i]() { results[i] = plan(p); });
  }
  for (std::thread& t : pool) t.join();
  for (int i = 0; i < kThreads; ++i) {
    ASSERT_TRUE(results[i].ok) << results[i].error;
    EXPECT_EQ(results[i].fuel_kg, serial.fuel_kg) << i;
    ASSERT_EQ(results[i].samples.size(), serial.samples.size()) << i;
    for (std::size_t k = 0; k < serial.samples.size(); ++k) {
      EXPECT_EQ(results[i].samples[k].omega_d, serial.samples[k].omega_d) << i << " " << k;
    }
  }
}

// The grid-convergence check (PlanSettings::refinement_check): the default re-solves the plan on
// every other node. Its fuel is that of the same problem planned on its own on that grid, and a
// plan on a grid too coarse to resolve the despin is refused by it, with the reason.
TEST(PlannerGridCheck, CoarseningReSolvesOnEveryOtherNodeAndRefusesAnUnresolvedGrid) {
  PlanProblem p;
  p.model = study_case_model(200.0, 0.0, 0.0);
  p.settings.t_final_max = 1390.0;
  p.settings.nodes = 101;
  const PlanResult r = plan(p);
  ASSERT_TRUE(r.ok) << r.error;
  ASSERT_TRUE(r.verification.refinement_checked);
  EXPECT_EQ(r.verification.refined_nodes, 51);
  // The same problem on 51 nodes, planned cold and without a check of its own.
  PlanProblem coarse = p;
  coarse.settings.nodes = 51;
  coarse.settings.verify_refinement = false;
  coarse.settings.propagation_limit = 1.0;  // its open-loop error is not what is compared here
  const PlanResult c = plan(coarse);
  ASSERT_TRUE(c.ok) << c.error;
  EXPECT_NEAR(r.verification.refined_fuel_kg, c.fuel_kg, 1e-4 * c.fuel_kg);
  EXPECT_NEAR(r.verification.refinement_change, std::abs(c.fuel_kg - r.fuel_kg) / r.fuel_kg, 1e-4);
  // Bisection, the other check, re-solves on 201 nodes.
  PlanProblem bisect = p;
  bisect.settings.refinement_check = PlanSettings::RefinementCheck::kBisect;
  const PlanResult b = plan(bisect);
  ASSERT_TRUE(b.ok) << b.error;
  EXPECT_EQ(b.verification.refined_nodes, 201);
  EXPECT_EQ(b.fuel_kg, r.fuel_kg);  // the check does not change the plan
  // A grid of 9 nodes (174 s intervals, about one turn of the body each) does not resolve the
  // despin: halving it again changes the fuel by more than the limit.
  PlanProblem unresolved = p;
  unresolved.settings.nodes = 9;
  unresolved.settings.propagation_limit = 1.0;
  const PlanResult u = plan(unresolved);
  EXPECT_FALSE(u.ok);
  EXPECT_NE(u.error.find("grid coarsening (9 -> 5 nodes) changes the fuel by"), std::string::npos)
      << u.error;
  EXPECT_GT(u.verification.refinement_change, p.settings.refinement_limit);
}

TEST(Planner, InfeasibleHorizonIsAClearErrorAndWritesNoFile) {
  PlanProblem p;
  p.case_name = "too-short";
  p.model = study_case_model(200.0, 0.0, 0.0);
  double t_min = 0.0, t_max = 0.0;
  resolve_final_time_bounds(p.model, p.settings, t_min, t_max);
  p.settings.t_final_max = 0.5 * t_max / kHorizonFactor;  // half the shortest possible despin
  p.settings.nodes = 21;
  p.settings.max_iterations = 300;
  const std::filesystem::path dir =
      std::filesystem::path(::testing::TempDir()) / "planner_infeasible_cache";
  std::filesystem::remove_all(dir);
  const CachedPlan c = plan_cached(p, dir.string());
  EXPECT_FALSE(c.ok);
  EXPECT_NE(c.error.find("too-short"), std::string::npos) << c.error;
  EXPECT_NE(c.error.find("IPOPT"), std::string::npos) << c.error;
  EXPECT_FALSE(std::filesystem::exists(c.path));
}

TEST(Planner, RejectsInvalidProblems) {
  PlanProblem p;
  p.model = study_case_model(200.0, 0.0, 0.0);
  p.model.omega_init = Vec3(0.1, 0.0, 0.0);  // above eps_trans
  PlanResult r = plan(p);
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.error.find("eps_trans"), std::string::npos) << r.error;
  p.model = study_case_model(200.0, 0.0, 0.0);
  p.model.j_hat(0, 0) = -1.0;
  r = plan(p);
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.error.find("positive definite"), std::string::npos) << r.error;
  p.model = study_case_model(200.0, 0.0, 0.0);
  p.settings.nodes = 600;  // 1199 samples do not fit the on-board table
  r = plan(p);
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.error.find("nodes"), std::string::npos) << r.error;
}

TEST(Planner, StudyCaseModelAppliesTheSpecErrorDirections) {
  const PlanModel truth = study_case_model(200.0, 0.0, 0.0);
  const PlanModel est = study_case_model(1000.0, 1e7, 1.0);
  // J_tot = J_ast + J_sc + m_sc [...](r): the J_ast part moves by -dJ diag(-1, 1, 0.5) exactly,
  // the parallel-axis part by the change of r (SPEC Eq. 1).
  const Vec3 r_true = Vec3(0, 0, 3.0) + Vec3(-0.0495, -0.0004, 3.5456);
  const Vec3 r_hat = r_true - Vec3::Ones() / std::sqrt(3.0);
  const auto parallel = [](const Vec3& r) -> Mat3 {
    return 1.6e4 * (r.squaredNorm() * Mat3::Identity() - r * r.transpose());
  };
  const Mat3 expected = truth.j_hat - 1e7 * Vec3(-1, 1, 0.5).asDiagonal().toDenseMatrix() -
                        parallel(r_true) + parallel(r_hat);
  EXPECT_LT((est.j_hat - expected).norm(), 1e-6 * expected.norm());
  EXPECT_EQ(est.u_max, 1000.0);
  EXPECT_NEAR(est.eps_trans, 0.5 * 2 * 3.14159265358979323846 / 60, 1e-15);
}

TEST(Planner, CacheReturnsTheStoredPlanForTheSameProblemOnly) {
  PlanProblem p;
  p.case_name = "cache/test";
  p.model = study_case_model(200.0, 0.0, 0.0);
  p.model.j_hat = 3e7 * Mat3::Identity();
  p.settings.nodes = 21;
  p.settings.verify_refinement = false;
  const std::filesystem::path dir = std::filesystem::path(::testing::TempDir()) / "planner_cache";
  std::filesystem::remove_all(dir);
  const CachedPlan first = plan_cached(p, dir.string());
  ASSERT_TRUE(first.ok) << first.error;
  EXPECT_FALSE(first.from_cache);
  EXPECT_TRUE(std::filesystem::exists(first.path));
  EXPECT_EQ(std::filesystem::path(first.path).parent_path(), dir);
  const CachedPlan second = plan_cached(p, dir.string());
  ASSERT_TRUE(second.ok) << second.error;
  EXPECT_TRUE(second.from_cache);
  EXPECT_EQ(second.path, first.path);
  EXPECT_EQ(second.file.fuel_kg, first.file.fuel_kg);
  EXPECT_EQ(second.file.to_table().checksum, first.file.to_table().checksum);
  PlanProblem other = p;
  other.settings.nodes = 25;
  EXPECT_NE(cache_path(other, dir.string()), first.path);
  EXPECT_NE(problem_hash(other), problem_hash(p));
}

}  // namespace
}  // namespace rocksteady::ground::planner
