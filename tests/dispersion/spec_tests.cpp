// The shipped dispersion files load; every class of malformed file is a ConfigError naming the
// file, the dotted key and the reason.
#include <gtest/gtest.h>

#include "config/config_error.hpp"
#include "ground/dispersion/spec.hpp"
#include "tests/dispersion/test_util.hpp"

namespace rocksteady::dispersion {
namespace {

using test::base_spec;
using test::replace_line;

TEST(DispersionFiles, ShippedFilesLoad) {
  const DispersionSpec a = load_spec(test::source("configs/dispersions/study-neighbourhood.yaml"));
  EXPECT_EQ(a.name, "study-neighbourhood");
  EXPECT_EQ(a.draws, 200);
  EXPECT_EQ(a.strategies.size(), 6u);
  EXPECT_EQ(a.delta_j_direction, DirectionKind::kRandomSymmetric);
  const DispersionSpec b = load_spec(test::source("configs/dispersions/prop5-sweep.yaml"));
  EXPECT_EQ(b.delta_j_norm.kind, Scalar::Kind::kLogUniform);
  EXPECT_EQ(b.delta_j_norm.min, 1e3);
  EXPECT_EQ(b.delta_j_norm.max, 1e7);
  EXPECT_EQ(b.dimensions().size(), 1u);
  EXPECT_TRUE(b.override_allocator);
  EXPECT_EQ(b.allocator, gnc::AllocatorKind::kL1);
}

// The re-planning strategy and its policy (optional map `replan`).
TEST(DispersionFiles, ReplanStrategyAndItsPolicyLoad) {
  const std::string text =
      replace_line(replace_line(base_spec(), "[dpd, ntcl+dpd_ref]", "[ntcl+dpd_ref, ntcl+replan]"),
                   "sampling: random",
                   "sampling: random\nreplan: {latency_s: 25, period_s: 0, min_horizon_s: 1400, "
                   "adopt_sigmas: 4, adopt_wait_s: 30, adopt_settle_tau: 2, "
                   "offset_confident_m: 0.25, slew_s: 30000}");
  const DispersionSpec s = load_spec(test::write_temp("replan.yaml", text));
  ASSERT_EQ(s.strategies.size(), 2u);
  EXPECT_TRUE(s.strategies[1].replans());
  EXPECT_TRUE(s.strategies[1].identify);
  EXPECT_EQ(s.replan.latency_s, 25.0);
  EXPECT_EQ(s.replan.period_s, 0.0);
  EXPECT_EQ(s.replan.min_horizon_s, 1400.0);
  EXPECT_EQ(s.replan.adopt_sigmas, 4.0);
  EXPECT_EQ(s.replan.adopt_wait_s, 30.0);
  EXPECT_EQ(s.replan.adopt_settle_tau, 2.0);
  EXPECT_EQ(s.replan.offset_confident_m, 0.25);
  EXPECT_EQ(s.replan.slew_s, 30000.0);
  EXPECT_EQ(s.replan.first_plan_s, campaign::ReplanOptions{}.first_plan_s);  // default kept
}

struct Bad {
  const char* what;
  std::string from, to;
  std::string expect;  // "key: reason" part of the message
};

TEST(DispersionFiles, EachMalformedClassNamesFileKeyAndReason) {
  const std::vector<Bad> cases = {
      {"missing key", "draws: 10\n", "", "draws: missing"},
      {"unknown key", "draws: 10\n", "draws: 10\nwarp: 9\n", "warp"},
      {"unknown distribution", "distribution: uniform, min: 0.0, max: 1.0}",
       "distribution: cauchy, min: 0.0, max: 1.0}",
       "parameters.delta_r_so_bcm_norm_m.distribution: expected fixed, uniform, log_uniform or "
       "normal"},
      {"empty range", "{distribution: uniform, min: 200.0, max: 1000.0}",
       "{distribution: uniform, min: 200.0, max: 200.0}",
       "parameters.u_max_n.max: must be greater than min"},
      {"log-uniform at zero", "min: 1.0e3, max: 1.0e7}", "min: 0.0, max: 1.0e7}",
       "parameters.delta_j_ast_norm_kg_m2.min: a log-uniform distribution needs min > 0"},
      {"negative value", "delta_r_so_bcm_norm_m: {distribution: uniform, min: 0.0, max: 1.0}",
       "delta_r_so_bcm_norm_m: -1.0", "parameters.delta_r_so_bcm_norm_m: must not be negative"},
      {"untruncated normal of a non-negative quantity",
       "mean: 0.577, sigma: 0.15, min: 0.0, max: 1.2}", "mean: 0.577, sigma: 0.15}",
       "parameters.disturbance_sigma_nm.min: this quantity is not negative"},
      {"non-positive sigma", "sigma: 0.15", "sigma: 0.0", "parameters.disturbance_sigma_nm.sigma"},
      {"unknown strategy", "[dpd, ntcl+dpd_ref]", "[dpd, warp+dpd_ref]",
       "strategies: unknown strategy 'warp+dpd_ref'"},
      {"duplicate strategy", "[dpd, ntcl+dpd_ref]", "[dpd, dpd]",
       "strategies: 'dpd' is listed twice"},
      {"empty strategies", "[dpd, ntcl+dpd_ref]", "[]", "strategies: expected a non-empty list"},
      {"bad sampling", "sampling: random", "sampling: sobol",
       "sampling: expected random, latin_hypercube or corners"},
      {"bad direction", "initial_rate_direction: sphere",
       "initial_rate_direction: random_symmetric",
       "parameters.initial_rate_direction: expected mission or sphere"},
      {"bad attitude", "initial_attitude: random_rotation", "initial_attitude: sphere",
       "parameters.initial_attitude: expected mission or random_rotation"},
      {"no draws", "draws: 10", "draws: 0", "draws: must be in [1, 10000000]"},
      {"wrong shape", "u_max_n: {distribution: uniform, min: 200.0, max: 1000.0}",
       "u_max_n: [1, 2]", "parameters.u_max_n: expected a number or a mapping"},
      {"zero u_max", "u_max_n: {distribution: uniform, min: 200.0, max: 1000.0}", "u_max_n: 0.0",
       "parameters.u_max_n: must be positive"},
      {"bad seed", "noise_seed: per_draw", "noise_seed: sometimes", "parameters.noise_seed"},
      {"bad name", "name: t", "name: a b", "name: must be a non-empty word"},
      {"bad allocator", "sampling: random", "sampling: random\nallocator: l2",
       "allocator: expected pinv or l1"},
      {"negative replan latency", "sampling: random", "sampling: random\nreplan: {latency_s: -1}",
       "replan.latency_s: must not be negative"},
      {"unknown replan key", "sampling: random", "sampling: random\nreplan: {latency: 5}",
       "replan.latency"},
      {"first plan deadline before the first plan", "sampling: random",
       "sampling: random\nreplan: {first_plan_s: 500, first_plan_max_s: 100}",
       "replan.first_plan_max_s: must not be below first_plan_s"},
  };
  for (const Bad& b : cases) {
    const std::string text = b.to.empty() && b.what == std::string("missing key")
                                 ? replace_line(base_spec(), b.from, "")
                                 : replace_line(base_spec(), b.from, b.to);
    const std::string path = test::write_temp("bad.yaml", text);
    try {
      load_spec(path);
      ADD_FAILURE() << b.what << ": loaded";
    } catch (const config::ConfigError& e) {
      const std::string msg = e.what();
      EXPECT_EQ(msg.rfind(path + ": ", 0), 0u) << b.what << ": " << msg;
      EXPECT_NE(msg.find(b.expect), std::string::npos) << b.what << ": " << msg;
    }
  }
}

TEST(DispersionFiles, UnreadableAndSyntaxErrors) {
  EXPECT_THROW(load_spec("/nonexistent/x.yaml"), config::ConfigError);
  const std::string path = test::write_temp("syntax.yaml", "name: [unclosed\n");
  EXPECT_THROW(load_spec(path), config::ConfigError);
}

TEST(DispersionFiles, BaseSpecLoads) {
  const DispersionSpec s = load_spec(test::write_temp("ok.yaml", base_spec()));
  EXPECT_EQ(s.dimensions().size(), 7u);
}

}  // namespace
}  // namespace rocksteady::dispersion
