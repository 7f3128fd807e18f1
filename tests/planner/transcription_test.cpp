// The transcription's derivatives against central finite differences, and its pattern's shape.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <random>
#include <set>
#include <utility>

#include "ground/planner/planner.hpp"
#include "ground/planner/transcription.hpp"

namespace rocksteady::ground::planner {
namespace {

HermiteSimpsonNlp make_nlp(int nodes, std::vector<double> grid = {}) {
  const PlanModel m = study_case_model(200.0, 1e6, 0.1);
  TranscriptionModel tm;
  tm.j_hat = m.j_hat;
  tm.b_hat = m.b_hat;
  tm.u_max = m.u_max;
  tm.eps_trans = m.eps_trans;
  tm.omega_init = m.omega_init;
  tm.nodes = nodes;
  tm.grid = std::move(grid);
  tm.t_final_min = 500.0;
  tm.t_final_max = 1500.0;
  return HermiteSimpsonNlp(tm);
}

// A generic point: rates of order one (scaled), controls inside (0, 1), tau inside its bounds.
std::vector<double> random_point(const HermiteSimpsonNlp& nlp, std::mt19937& rng) {
  std::uniform_real_distribution<double> w(-0.8, 0.8);
  std::uniform_real_distribution<double> u(0.05, 0.95);
  std::vector<double> x(nlp.num_variables());
  for (int j = 0; j < nlp.num_points(); ++j) {
    for (int c = 0; c < 3; ++c) x[nlp.w_index(j) + c] = w(rng);
    for (int c = 0; c < 16; ++c) x[nlp.p_index(j) + c] = u(rng);
  }
  x[nlp.tau_index()] = 1.1;
  return x;
}

Eigen::MatrixXd dense(const SparsityPattern& p, const std::vector<double>& v, int rows, int cols) {
  Eigen::MatrixXd m = Eigen::MatrixXd::Zero(rows, cols);
  for (std::size_t k = 0; k < v.size(); ++k) m(p.rows[k], p.cols[k]) += v[k];
  return m;
}

Eigen::MatrixXd constraint_jacobian(const HermiteSimpsonNlp& nlp, const std::vector<double>& x) {
  std::vector<double> v(nlp.jacobian_pattern().rows.size());
  nlp.jacobian_values(x.data(), v.data());
  return dense(nlp.jacobian_pattern(), v, nlp.num_constraints(), nlp.num_variables());
}

// Gradient of the Lagrangian sigma f + lambda' g from the analytic first derivatives.
Eigen::VectorXd lagrangian_gradient(const HermiteSimpsonNlp& nlp, const std::vector<double>& x,
                                    double sigma, const Eigen::VectorXd& lambda) {
  Eigen::VectorXd grad(nlp.num_variables());
  nlp.objective_gradient(x.data(), grad.data());
  return sigma * grad + constraint_jacobian(nlp, x).transpose() * lambda;
}

TEST(Transcription, ObjectiveGradientMatchesFiniteDifferences) {
  const HermiteSimpsonNlp nlp = make_nlp(4);
  std::mt19937 rng(1);
  std::vector<double> x = random_point(nlp, rng);
  std::vector<double> grad(nlp.num_variables());
  nlp.objective_gradient(x.data(), grad.data());
  const double step = 1e-6;
  for (int i = 0; i < nlp.num_variables(); ++i) {
    std::vector<double> xp = x, xm = x;
    xp[i] += step;
    xm[i] -= step;
    const double fd = (nlp.objective(xp.data()) - nlp.objective(xm.data())) / (2 * step);
    EXPECT_NEAR(grad[i], fd, 1e-8 * (1.0 + std::abs(fd))) << "variable " << i;
  }
}

TEST(Transcription, ConstraintJacobianMatchesFiniteDifferencesAndPattern) {
  const HermiteSimpsonNlp nlp = make_nlp(4);
  std::mt19937 rng(2);
  const std::vector<double> x = random_point(nlp, rng);
  const Eigen::MatrixXd jac = constraint_jacobian(nlp, x);
  const int m = nlp.num_constraints();
  const double step = 1e-6;
  Eigen::MatrixXd fd(m, nlp.num_variables());
  for (int i = 0; i < nlp.num_variables(); ++i) {
    std::vector<double> xp = x, xm = x;
    xp[i] += step;
    xm[i] -= step;
    Eigen::VectorXd gp(m), gm(m);
    nlp.constraints(xp.data(), gp.data());
    nlp.constraints(xm.data(), gm.data());
    fd.col(i) = (gp - gm) / (2 * step);
  }
  // Entry by entry: this also catches a derivative missing from the pattern (analytic 0, FD not).
  for (int r = 0; r < m; ++r) {
    for (int c = 0; c < nlp.num_variables(); ++c) {
      ASSERT_NEAR(jac(r, c), fd(r, c), 1e-7 * (1.0 + std::abs(fd(r, c)))) << "row " << r << " col " << c;
    }
  }
  EXPECT_GT(jac.cwiseAbs().maxCoeff(), 0.1);
}

TEST(Transcription, LagrangianHessianMatchesFiniteDifferencesOfTheGradient) {
  const HermiteSimpsonNlp nlp = make_nlp(4);
  std::mt19937 rng(3);
  const std::vector<double> x = random_point(nlp, rng);
  std::normal_distribution<double> normal(0.0, 1.0);
  Eigen::VectorXd lambda(nlp.num_constraints());
  for (int i = 0; i < lambda.size(); ++i) lambda[i] = normal(rng);
  const double sigma = 0.7;

  const SparsityPattern& p = nlp.hessian_pattern();
  std::vector<double> v(p.rows.size());
  nlp.hessian_values(x.data(), sigma, lambda.data(), v.data());
  const int n = nlp.num_variables();
  const Eigen::MatrixXd lower = dense(p, v, n, n);
  Eigen::MatrixXd hess = lower + lower.transpose();
  hess.diagonal() = lower.diagonal();

  const double step = 1e-6;
  Eigen::MatrixXd fd(n, n);
  for (int i = 0; i < n; ++i) {
    std::vector<double> xp = x, xm = x;
    xp[i] += step;
    xm[i] -= step;
    fd.col(i) = (lagrangian_gradient(nlp, xp, sigma, lambda) -
                 lagrangian_gradient(nlp, xm, sigma, lambda)) / (2 * step);
  }
  for (int r = 0; r < n; ++r) {
    for (int c = 0; c < n; ++c) {
      ASSERT_NEAR(hess(r, c), fd(r, c), 1e-6 * (1.0 + std::abs(fd(r, c)))) << "row " << r << " col " << c;
    }
  }
  EXPECT_GT(hess.cwiseAbs().maxCoeff(), 0.1);
}

TEST(Transcription, PatternsAreLowerTriangularWithoutDuplicates) {
  const HermiteSimpsonNlp nlp = make_nlp(6);
  const SparsityPattern& h = nlp.hessian_pattern();
  std::set<std::pair<int, int>> seen;
  for (std::size_t k = 0; k < h.rows.size(); ++k) {
    EXPECT_GE(h.rows[k], h.cols[k]);
    EXPECT_TRUE(seen.insert({h.rows[k], h.cols[k]}).second) << "duplicate Hessian entry";
  }
  const SparsityPattern& j = nlp.jacobian_pattern();
  seen.clear();
  for (std::size_t k = 0; k < j.rows.size(); ++k) {
    EXPECT_TRUE(seen.insert({j.rows[k], j.cols[k]}).second) << "duplicate Jacobian entry";
    EXPECT_LT(j.rows[k], nlp.num_constraints());
    EXPECT_LT(j.cols[k], nlp.num_variables());
  }
}

TEST(Transcription, DefectsVanishOnAnExactTorqueFreeMotionOfASphericalBody) {
  // Spherical inertia and zero thrust: omega is constant, so every defect is exactly zero.
  TranscriptionModel tm;
  tm.j_hat = 2e7 * Mat3::Identity();
  tm.b_hat = study_case_model(200.0, 0.0, 0.0).b_hat;
  tm.omega_init = Vec3(0.01, -0.02, 0.005);
  tm.nodes = 5;
  tm.t_final_min = tm.t_final_max = 100.0;
  const HermiteSimpsonNlp nlp(tm);
  std::vector<double> x(nlp.num_variables(), 0.0);
  for (int j = 0; j < nlp.num_points(); ++j) nlp.set_point(x.data(), j, tm.omega_init, Vec8::Zero());
  nlp.set_t_final(x.data(), 100.0);
  std::vector<double> g(nlp.num_constraints());
  nlp.constraints(x.data(), g.data());
  for (int i = 0; i < 6 * (tm.nodes - 1); ++i) EXPECT_NEAR(g[i], 0.0, 1e-15);
}

TEST(Transcription, NonUniformGridDerivativesMatchFiniteDifferences) {
  // The same finite-difference checks on an uneven grid (interval lengths 0.1, 0.5, 0.15, 0.25).
  const HermiteSimpsonNlp nlp = make_nlp(5, {0.0, 0.1, 0.6, 0.75, 1.0});
  std::mt19937 rng(7);
  std::vector<double> x = random_point(nlp, rng);
  std::vector<double> grad(nlp.num_variables());
  nlp.objective_gradient(x.data(), grad.data());
  const Eigen::MatrixXd jac = constraint_jacobian(nlp, x);
  Eigen::VectorXd lambda = Eigen::VectorXd::Random(nlp.num_constraints());
  std::vector<double> hv(nlp.hessian_pattern().rows.size());
  nlp.hessian_values(x.data(), 0.7, lambda.data(), hv.data());
  Eigen::MatrixXd hess = dense(nlp.hessian_pattern(), hv, nlp.num_variables(), nlp.num_variables());
  hess = Eigen::MatrixXd(hess.selfadjointView<Eigen::Lower>());
  const double step = 1e-6;
  for (int i = 0; i < nlp.num_variables(); ++i) {
    std::vector<double> xp = x, xm = x;
    xp[i] += step;
    xm[i] -= step;
    const double fd = (nlp.objective(xp.data()) - nlp.objective(xm.data())) / (2 * step);
    EXPECT_NEAR(grad[i], fd, 1e-8 * (1.0 + std::abs(fd))) << "gradient, variable " << i;
    std::vector<double> gp(nlp.num_constraints()), gm(nlp.num_constraints());
    nlp.constraints(xp.data(), gp.data());
    nlp.constraints(xm.data(), gm.data());
    for (int r = 0; r < nlp.num_constraints(); ++r) {
      const double fdj = (gp[r] - gm[r]) / (2 * step);
      EXPECT_NEAR(jac(r, i), fdj, 1e-6 * (1.0 + std::abs(fdj))) << "jacobian " << r << "," << i;
    }
    const Eigen::VectorXd lp = lagrangian_gradient(nlp, xp, 0.7, lambda);
    const Eigen::VectorXd lm = lagrangian_gradient(nlp, xm, 0.7, lambda);
    const Eigen::VectorXd fdh = (lp - lm) / (2 * step);
    for (int r = 0; r < nlp.num_variables(); ++r) {
      EXPECT_NEAR(hess(r, i), fdh[r], 1e-5 * (1.0 + std::abs(fdh[r]))) << "hessian " << r << "," << i;
    }
  }
}

TEST(Transcription, NonUniformGridIsExactForAConstantTorqueOnASphericalBody) {
  // Spherical inertia, constant thrust: omega(t) = omega0 + J^-1 B u t is linear, which
  // Hermite-Simpson reproduces exactly on any grid; the cost is |u|_1 t_f exactly.
  TranscriptionModel tm;
  tm.j_hat = 2e7 * Mat3::Identity();
  tm.b_hat = study_case_model(200.0, 0.0, 0.0).b_hat;
  tm.omega_init = Vec3(0.01, -0.02, 0.005);
  tm.nodes = 4;
  tm.grid = {0.0, 0.05, 0.7, 1.0};
  tm.t_final_min = tm.t_final_max = 300.0;
  const HermiteSimpsonNlp nlp(tm);
  Vec8 u;
  u << 50, -20, 0, 10, -5, 0, 30, -40;
  const Vec3 accel = tm.j_hat.inverse() * tm.b_hat * u;
  std::vector<double> x(nlp.num_variables(), 0.0);
  for (int j = 0; j < nlp.num_points(); ++j) {
    const double t = 300.0 * nlp.point_fraction(j);
    nlp.set_point(x.data(), j, tm.omega_init + accel * t, u);
  }
  EXPECT_DOUBLE_EQ(nlp.point_fraction(3), 0.375);  // midpoint of [0.05, 0.7]
  nlp.set_t_final(x.data(), 300.0);
  std::vector<double> g(nlp.num_constraints());
  nlp.constraints(x.data(), g.data());
  for (int i = 0; i < 6 * (tm.nodes - 1); ++i) EXPECT_NEAR(g[i], 0.0, 1e-15) << "defect row " << i;
  EXPECT_NEAR(nlp.cost_scale() * nlp.objective(x.data()), u.cwiseAbs().sum() * 300.0, 1e-9);
}

}  // namespace
}  // namespace rocksteady::ground::planner
