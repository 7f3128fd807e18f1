// Distributions against closed forms, directions against their known distributions (fixed seeds),
// the positive-definite rejection of J_ast - dJ, and the purity of draws.
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <set>

#include "ground/dispersion/sampler.hpp"
#include "tests/dispersion/test_util.hpp"

namespace rocksteady::dispersion {
namespace {

constexpr double kPi = 3.14159265358979323846;

struct Moments {
  double mean{0.0}, var{0.0}, min{1e300}, max{-1e300};
};
Moments sample(const Scalar& s, int n, std::uint64_t seed) {
  Rng rng(seed);
  double sum = 0.0, sum2 = 0.0;
  Moments m;
  for (int i = 0; i < n; ++i) {
    const double x = s.quantile(rng.uniform());
    sum += x;
    sum2 += x * x;
    m.min = std::min(m.min, x);
    m.max = std::max(m.max, x);
  }
  m.mean = sum / n;
  m.var = sum2 / n - m.mean * m.mean;
  return m;
}

TEST(Distributions, UniformMomentsAndRange) {
  Scalar s;
  s.kind = Scalar::Kind::kUniform;
  s.min = 2.0;
  s.max = 5.0;
  const int n = 200000;
  const Moments m = sample(s, n, 11);
  // Closed forms: mean (a + b) / 2 = 3.5, variance (b - a)^2 / 12 = 0.75.
  EXPECT_NEAR(m.mean, 3.5, 5.0 * std::sqrt(0.75 / n));
  EXPECT_NEAR(m.var, 0.75, 0.01);
  EXPECT_GE(m.min, 2.0);
  EXPECT_LE(m.max, 5.0);
  EXPECT_EQ(s.quantile(0.0), 2.0);
  EXPECT_EQ(s.quantile(1.0), 5.0);
}

TEST(Distributions, LogUniformMomentsAndRange) {
  Scalar s;
  s.kind = Scalar::Kind::kLogUniform;
  s.min = 1.0;
  s.max = std::exp(2.0);
  const int n = 200000;
  const Moments m = sample(s, n, 12);
  // ln X ~ U[0, 2]: E[X] = (e^2 - 1) / 2, E[X^2] = (e^4 - 1) / 4.
  const double mean = (std::exp(2.0) - 1.0) / 2.0;
  const double var = (std::exp(4.0) - 1.0) / 4.0 - mean * mean;
  EXPECT_NEAR(m.mean, mean, 5.0 * std::sqrt(var / n));
  EXPECT_NEAR(m.var, var, 0.02 * var);
  EXPECT_GE(m.min, 1.0);
  EXPECT_LE(m.max, std::exp(2.0));
  // Each decade equally likely: the median is the geometric mean.
  EXPECT_NEAR(s.quantile(0.5), std::exp(1.0), 1e-12);
}

TEST(Distributions, TruncatedNormalMomentsAgainstNumericalIntegration) {
  Scalar s;
  s.kind = Scalar::Kind::kNormal;
  s.mean = 1.0;
  s.sigma = 2.0;
  s.min = 0.0;
  s.max = 4.0;
  // Truth by brute-force integration of the truncated density (Simpson, 20000 intervals).
  const int k = 20000;
  double z = 0.0, m1 = 0.0, m2 = 0.0;
  for (int i = 0; i <= k; ++i) {
    const double x = s.min + (s.max - s.min) * i / k;
    const double w = (i == 0 || i == k) ? 1.0 : (i % 2 == 1 ? 4.0 : 2.0);
    const double f = w * std::exp(-0.5 * (x - s.mean) * (x - s.mean) / (s.sigma * s.sigma));
    z += f;
    m1 += f * x;
    m2 += f * x * x;
  }
  const double mean = m1 / z, var = m2 / z - mean * mean;
  EXPECT_NEAR(s.mean_value(), mean, 1e-9);
  EXPECT_NEAR(s.variance(), var, 1e-9);
  const int n = 200000;
  const Moments m = sample(s, n, 13);
  EXPECT_NEAR(m.mean, mean, 5.0 * std::sqrt(var / n));
  EXPECT_NEAR(m.var, var, 0.02 * var);
  EXPECT_GE(m.min, 0.0);
  EXPECT_LE(m.max, 4.0);
}

TEST(Distributions, NormalQuantileInvertsTheCdf) {
  for (double p : {1e-12, 1e-6, 0.01, 0.02425, 0.2, 0.5, 0.77, 0.975, 0.999999}) {
    EXPECT_NEAR(normal_cdf(normal_quantile(p)), p, 1e-14 + 1e-12 * p) << p;
  }
  EXPECT_NEAR(normal_quantile(0.975), 1.959963984540054, 1e-12);
}

TEST(Directions, SphereIsUniformByChiSquareOnEqualAreaCells) {
  // Fixed seed. Equal-area cells: 10 bands in z (Archimedes) x 12 sectors in longitude.
  Rng rng(2024);
  const int n = 60000, bands = 10, sectors = 12;
  std::vector<int> count(bands * sectors, 0);
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (int i = 0; i < n; ++i) {
    const double u1 = rng.uniform(), u2 = rng.uniform();
    const Vec3 v = sphere_direction(u1, u2);
    ASSERT_NEAR(v.norm(), 1.0, 1e-12);
    sum += v;
    const int b = std::min(bands - 1, static_cast<int>((v.z() + 1.0) / 2.0 * bands));
    double phi = std::atan2(v.y(), v.x());
    if (phi < 0) phi += 2.0 * kPi;
    const int s = std::min(sectors - 1, static_cast<int>(phi / (2.0 * kPi) * sectors));
    ++count[static_cast<std::size_t>(b * sectors + s)];
  }
  const double expected = static_cast<double>(n) / (bands * sectors);
  double chi2 = 0.0;
  for (int c : count) chi2 += (c - expected) * (c - expected) / expected;
  // 119 degrees of freedom: the 99.9 % quantile is 173.0.
  EXPECT_LT(chi2, 173.0);
  // The mean of a uniform direction is 0 (each component has variance 1/3).
  EXPECT_LT(sum.norm() / n, 5.0 / std::sqrt(static_cast<double>(n)));  // |mean| ~ 1/sqrt(n)
}

TEST(Directions, RandomRotationAnglesFollowTheHaarDistribution) {
  // For a uniform rotation, the angle theta has CDF (theta - sin theta) / pi. Kolmogorov-Smirnov.
  Rng rng(77);
  const int n = 20000;
  std::vector<double> angle;
  for (int i = 0; i < n; ++i) {
    const double a = rng.uniform(), b = rng.uniform(), c = rng.uniform();
    const Eigen::Vector4d q = random_rotation(a, b, c);
    ASSERT_NEAR(q.norm(), 1.0, 1e-12);
    angle.push_back(2.0 * std::acos(std::min(1.0, std::fabs(q(3)))));
  }
  std::sort(angle.begin(), angle.end());
  double d = 0.0;
  for (int i = 0; i < n; ++i) {
    const double f =
        (angle[static_cast<std::size_t>(i)] - std::sin(angle[static_cast<std::size_t>(i)])) / kPi;
    d = std::max(d, std::max(std::fabs(f - static_cast<double>(i) / n),
                             std::fabs(f - static_cast<double>(i + 1) / n)));
  }
  EXPECT_LT(d, 1.95 / std::sqrt(static_cast<double>(n)));  // KS 99.9 %
}

TEST(Directions, RandomSymmetricHasUnitSpectralNormAndNoPreferredSign) {
  Rng rng(5);
  double trace_sum = 0.0;
  const int n = 4000;
  for (int i = 0; i < n; ++i) {
    const Mat3 m = random_symmetric_direction(rng);
    ASSERT_TRUE(m.isApprox(m.transpose(), 0.0));
    const Eigen::SelfAdjointEigenSolver<Mat3> es(m);
    ASSERT_NEAR(es.eigenvalues().cwiseAbs().maxCoeff(), 1.0, 1e-12);
    trace_sum += m.trace();
  }
  EXPECT_LT(std::fabs(trace_sum / n), 0.05);
}

config::MissionConfig mission() {
  return config::load_mission(test::source("configs/mission.yaml"));
}

DispersionSpec spec_from(const std::string& text) {
  return load_spec(test::write_temp("s.yaml", text));
}

TEST(PdRejection, EstimatedInertiaAlwaysPositiveDefiniteAndRedrawsCountedExactly) {
  // ||dJ|| = 1e7 kg m^2 exceeds lambda_min(J_ast) ~ 7.9e6: many directions make J_ast - dJ
  // indefinite.
  std::string t = test::replace_line(
      test::base_spec(),
      "delta_j_ast_norm_kg_m2: {distribution: log_uniform, min: 1.0e3, max: 1.0e7}",
      "delta_j_ast_norm_kg_m2: 1.0e7");
  t = test::replace_line(t, "draws: 10", "draws: 300");
  const DispersionSpec s = spec_from(t);
  const config::MissionConfig m = mission();
  const Sampler sampler(s, m);
  int total_redraws = 0;
  for (int i = 0; i < s.draws; ++i) {
    const DrawParams d = sampler.draw(i);
    ASSERT_TRUE(d.error.empty()) << d.error;
    const Mat3 hat = m.mass.j_ast - d.delta_j;
    EXPECT_EQ(Eigen::LLT<Mat3>(hat).info(), Eigen::Success);
    const Eigen::SelfAdjointEigenSolver<Mat3> es(d.delta_j);
    EXPECT_NEAR(es.eigenvalues().cwiseAbs().maxCoeff(), 1e7, 1e-3);
    // Recount independently: replay the draw's matrix stream and test each candidate.
    Rng replay(mix_seed(d.seed, kMatrixStream));
    int rejected = 0;
    for (;;) {
      const Mat3 cand = 1e7 * random_symmetric_direction(replay);
      const Eigen::SelfAdjointEigenSolver<Mat3> e2(m.mass.j_ast - cand);
      if (e2.eigenvalues().minCoeff() > 0.0) {
        EXPECT_TRUE(cand.isApprox(d.delta_j, 0.0));
        break;
      }
      ++rejected;
    }
    EXPECT_EQ(rejected, d.pd_redraws);
    total_redraws += d.pd_redraws;
  }
  EXPECT_GT(total_redraws, 0);
}

TEST(PdRejection, LimitReachedIsARecordedErrorNotACrash) {
  std::string t = test::replace_line(
      test::base_spec(),
      "delta_j_ast_norm_kg_m2: {distribution: log_uniform, min: 1.0e3, max: 1.0e7}",
      "delta_j_ast_norm_kg_m2: 1.0e9\n  max_pd_redraws: 3");
  const DispersionSpec s = spec_from(t);
  const Sampler sampler(s, mission());
  const DrawParams d = sampler.draw(0);
  EXPECT_EQ(d.pd_redraws, 3);
  EXPECT_NE(d.error.find("positive-definite"), std::string::npos) << d.error;
}

bool same(const DrawParams& a, const DrawParams& b) {
  return a.seed == b.seed && a.u == b.u && a.delta_j == b.delta_j && a.delta_r == b.delta_r &&
         a.omega0 == b.omega0 && a.mrp0 == b.mrp0 && a.gyro_psd == b.gyro_psd &&
         a.star_psd == b.star_psd && a.disturbance_sigma_nm == b.disturbance_sigma_nm &&
         a.noise_seed == b.noise_seed && a.u_max_n == b.u_max_n && a.pd_redraws == b.pd_redraws;
}

TEST(Reproducibility, DrawIsAPureFunctionOfMasterSeedAndIndex) {
  for (const char* sampling : {"random", "latin_hypercube", "corners"}) {
    const std::string t = test::replace_line(test::base_spec(), "sampling: random",
                                             std::string("sampling: ") + sampling);
    const DispersionSpec s = spec_from(t);
    const config::MissionConfig m = mission();
    const Sampler a(s, m), b(s, m);
    std::vector<DrawParams> forward;
    for (int i = 0; i < s.draws; ++i) forward.push_back(a.draw(i));
    for (int i = s.draws - 1; i >= 0; --i) {  // another sampler, reverse order
      EXPECT_TRUE(same(b.draw(i), forward[static_cast<std::size_t>(i)])) << sampling << " " << i;
    }
    EXPECT_FALSE(same(forward[0], forward[1]));
    // Another master seed gives other draws.
    DispersionSpec s2 = s;
    s2.master_seed = 8;
    EXPECT_FALSE(same(Sampler(s2, m).draw(3), forward[3])) << sampling;
  }
}

TEST(Sampling, LatinHypercubeHitsEveryStratumOnceInEveryDimension) {
  const std::string t = test::replace_line(
      test::replace_line(test::base_spec(), "sampling: random", "sampling: latin_hypercube"),
      "draws: 10", "draws: 64");
  const DispersionSpec s = spec_from(t);
  const Sampler sampler(s, mission());
  const std::size_t nd = s.dimensions().size();
  ASSERT_EQ(nd, 7u);
  for (std::size_t k = 0; k < nd; ++k) {
    std::set<int> strata;
    for (int i = 0; i < 64; ++i)
      strata.insert(static_cast<int>(std::floor(sampler.coordinates(i)[k] * 64)));
    EXPECT_EQ(strata.size(), 64u) << k;
  }
}

TEST(Sampling, CornersVisitEveryCornerOfTheBoundedBoxFirst) {
  std::string t = test::replace_line(test::base_spec(), "sampling: random", "sampling: corners");
  t = test::replace_line(t, "draws: 10", "draws: 200");
  const DispersionSpec s = spec_from(t);
  const Sampler sampler(s, mission());
  std::set<std::vector<double>> corners;
  for (int i = 0; i < 128; ++i) {  // 7 bounded dimensions: 2^7 corners
    const auto u = sampler.coordinates(i);
    for (double x : u) EXPECT_TRUE(x == 0.0 || x == 1.0);
    corners.insert(u);
  }
  EXPECT_EQ(corners.size(), 128u);
  const DrawParams lo = sampler.draw(0), hi = sampler.draw(127);
  EXPECT_EQ(lo.delta_j_norm, 1e3);
  EXPECT_EQ(hi.delta_j_norm, 1e7);
  EXPECT_EQ(lo.u_max_n, 200.0);
  EXPECT_EQ(hi.u_max_n, 1000.0);
  EXPECT_EQ(hi.disturbance_sigma_nm, 1.2);
  // After the corners: points on a face (at least one coordinate at a bound).
  for (int i = 128; i < 200; ++i) {
    const auto u = sampler.coordinates(i);
    EXPECT_TRUE(std::any_of(u.begin(), u.end(), [](double x) { return x == 0.0 || x == 1.0; }));
  }
}

}  // namespace
}  // namespace rocksteady::dispersion
