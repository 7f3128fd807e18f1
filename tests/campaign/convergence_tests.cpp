// Figures of merit (SPEC §7) and strategy names.
#include <gtest/gtest.h>

#include "ground/campaign/runner.hpp"
#include "ground/campaign/strategy.hpp"

namespace rocksteady::campaign {
namespace {

TEST(ConvergenceTracker, LeastTimeAfterWhichTheCriterionHoldsForGood) {
  ConvergenceTracker c(1.0);
  // value(t): 5, 0.5 (dips in), 2 (leaves), 0.9, 0.8, 0.7 -> converged from t = 3 on.
  const double values[] = {5, 0.5, 2, 0.9, 0.8, 0.7};
  for (int k = 0; k < 6; ++k) c.add(k, values[k], 10.0 * k);
  ASSERT_TRUE(c.converged());
  EXPECT_EQ(*c.time(), 3.0);
  EXPECT_EQ(*c.fuel_kg(), 30.0);
}

TEST(ConvergenceTracker, NotConvergedWhenTheLastSampleFails) {
  ConvergenceTracker c(1.0);
  c.add(0, 0.1, 0);
  c.add(1, 0.2, 1);
  c.add(2, 1.5, 2);
  EXPECT_FALSE(c.converged());
  EXPECT_FALSE(c.time().has_value());
  EXPECT_FALSE(c.fuel_kg().has_value());
}

TEST(ConvergenceTracker, SatisfiedFromTheStartIsTimeZero) {
  ConvergenceTracker c(1.0);
  for (int k = 0; k < 4; ++k) c.add(k, 1.0, k);  // <= tol counts as met
  EXPECT_EQ(*c.time(), 0.0);
  EXPECT_EQ(*c.fuel_kg(), 0.0);
}

TEST(AttitudeError, ComparesInTheNearestMrpSet) {
  EXPECT_DOUBLE_EQ(attitude_error(Eigen::Vector3d(0.3, 0.4, 0), Eigen::Vector3d::Zero()), 0.5);
  // q_final near the unit sphere and q in its shadow set: the same attitude, error ~ 0.
  const Eigen::Vector3d qf(0.999, 0, 0);
  const Eigen::Vector3d shadow = -qf / qf.squaredNorm();
  EXPECT_LT(attitude_error(shadow, qf), 1e-12);
}

TEST(Strategy, TheStudysSixColumnsAndTheComparisonLaw) {
  const std::vector<std::string> six = {"ntcl+fuel_optimal", "adaptive+fuel_optimal",
                                        "el+fuel_optimal",   "ntcl+dpd_ref",
                                        "adaptive+dpd_ref",  "dpd"};
  EXPECT_EQ(study_strategy_names(), six);
  EXPECT_EQ(all_strategy_names().size(), 8u);
  for (const std::string& n : all_strategy_names()) {
    const auto s = parse_strategy(n);
    ASSERT_TRUE(s.has_value()) << n;
    EXPECT_EQ(s->name, n);
  }
  EXPECT_EQ(parse_strategy("ntcl+dpd_ref")->law, gnc::LawId::kNtcl);
  EXPECT_EQ(parse_strategy("el+fuel_optimal")->law, gnc::LawId::kNtclEl);
  EXPECT_EQ(parse_strategy("adaptive+dpd_ref")->law, gnc::LawId::kAdaptive);
  EXPECT_EQ(parse_strategy("feedforward+dpd_ref")->law, gnc::LawId::kFeedforward);
  EXPECT_EQ(parse_strategy("dpd")->law, gnc::LawId::kDpd);
  EXPECT_FALSE(parse_strategy("dpd")->needs_trajectory());
  EXPECT_TRUE(parse_strategy("ntcl+fuel_optimal")->needs_trajectory());
  EXPECT_FALSE(parse_strategy("dpd+fuel_optimal").has_value());
  EXPECT_FALSE(parse_strategy("ntcl").has_value());
  EXPECT_FALSE(parse_strategy("ntcl+optimal").has_value());
}

}  // namespace
}  // namespace rocksteady::campaign
