// Campaign outputs: results.csv header and NC fields, the Markdown table layout, time series, plots.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "ground/campaign/campaign.hpp"
#include "ground/campaign/runner.hpp"

namespace rocksteady::campaign {
namespace {

namespace fs = std::filesystem;
const std::string kConfigs = std::string(ROCKSTEADY_SOURCE_DIR) + "/configs";

std::string slurp(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

std::vector<std::string> lines(const std::string& text) {
  std::vector<std::string> out;
  std::stringstream ss(text);
  std::string l;
  while (std::getline(ss, l)) out.push_back(l);
  return out;
}

// The identification marks' NEES (gnc/estimation README §I.11): e' C^-1 e with the reported
// covariance, packed row by row, against an explicit inverse; J's errors along one direction (the
// thrust scale) are one number, so the per-parameter sum over-counts them six times. A covariance
// that is not positive definite falls back to the 1 sigma form.
TEST(CampaignOutputs, TheNormalisedErrorUsesTheCorrelations) {
  Eigen::Matrix<double, 6, 6> c = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix<double, 6, 1> v, sigma;
  v << 2.0e7, 1.8e7, 3.1e7, -0.4e7, 0.2e7, 0.9e6;  // a J's parameters
  for (int i = 0; i < 6; ++i) c(i, i) = std::pow(1e-3 * (1.0 + 0.3 * i) * 2e7, 2.0);
  for (int i = 0; i < 5; ++i) c(i, i + 1) = c(i + 1, i) = 0.2 * std::sqrt(c(i, i) * c(i + 1, i + 1));
  const double s_eps = 2.5e-3;
  c += s_eps * s_eps * v * v.transpose();
  const Eigen::Matrix<double, 21, 1> packed = gnc::pack_upper<6>(c);
  int k = 0;
  for (int i = 0; i < 6; ++i) {
    for (int j = i; j < 6; ++j) ASSERT_EQ(packed(k++), c(i, j)) << i << " " << j;
  }
  EXPECT_TRUE(gnc::unpack_upper<6>(packed) == c);
  for (int i = 0; i < 6; ++i) sigma(i) = std::sqrt(c(i, i));
  Eigen::Matrix<double, 6, 1> err = 2.0 * s_eps * v;  // a 2 sigma thrust-scale error
  err(1) += 0.5 * std::sqrt(c(1, 1));
  const double expected = err.dot(c.inverse() * err);
  const double got = normalised_error<6>(err, packed, sigma);
  EXPECT_NEAR(got, expected, 1e-9 * expected);
  const double diagonal = err.cwiseQuotient(sigma).squaredNorm();
  std::printf("NEES %.2f with the correlations, %.2f from the 1 sigma alone\n", got, diagonal);
  EXPECT_GT(diagonal, 2.0 * got);
  // Not positive definite (nothing reported yet): the 1 sigma form.
  const Eigen::Matrix<double, 6, 1> zero_cov = Eigen::Matrix<double, 6, 1>::Zero();
  const Eigen::Vector3d e3(0.01, -0.02, 0.03), s3(0.01, 0.01, 0.02);
  EXPECT_DOUBLE_EQ(normalised_error<3>(e3, zero_cov, s3), 1.0 + 4.0 + 2.25);
}

TEST(CampaignOutputs, ResultsCsvHasTheExactHeaderAndEmptyFieldsForNc) {
  RunResult ok;
  ok.case_name = "case1";
  ok.strategy = "dpd";
  ok.t_omega_conv_s = 100.0;
  ok.fuel_at_t_omega_kg = 2.5;
  ok.total_fuel_kg = 3.0;
  ok.max_rate_rad_s = 0.04;  // t_q never converged: NC
  RunResult noref;
  noref.case_name = "case1";
  noref.strategy = "ntcl+fuel_optimal";
  noref.status = RunStatus::kNoReference;
  const fs::path dir = fs::temp_directory_path() / "rocksteady_outputs_csv";
  write_results_csv((dir / "results.csv").string(), {ok, noref});
  const auto l = lines(slurp((dir / "results.csv").string()));
  ASSERT_EQ(l.size(), 3u);
  EXPECT_EQ(l[0],
            "case,strategy,t_omega_conv_s,fuel_at_t_omega_kg,t_q_conv_s,fuel_at_t_q_kg,"
            "total_fuel_kg,max_rate_rad_s");
  EXPECT_EQ(l[1], "case1,dpd,100.0,2.5000,,,3.0000,0.04");
  EXPECT_EQ(l[2], "case1,ntcl+fuel_optimal,,,,,,");
  fs::remove_all(dir);
}

TEST(CampaignOutputs, SmallCampaignWritesTablesSeriesAndPlots) {
  CampaignSpec spec;
  spec.mission_file = kConfigs + "/mission.yaml";
  spec.gnc_file = kConfigs + "/gnc.yaml";
  spec.case_files = {kConfigs + "/cases/case1.yaml", kConfigs + "/cases/case4.yaml"};
  spec.strategies = {*parse_strategy("ntcl+dpd_ref"), *parse_strategy("ntcl+fuel_optimal")};
  const fs::path dir = fs::temp_directory_path() / "rocksteady_outputs_campaign";
  fs::remove_all(dir);
  spec.out_dir = dir.string();
  spec.duration_s = 300.0;  // short: this test is about the files
  spec.log_interval_s = 1.0;
  spec.progress = ProgressMode::kOff;
  NoTrajectorySource none;
  std::ostringstream log;
  const CampaignReport rep = run_campaign(spec, none, log);
  ASSERT_EQ(rep.results.size(), 4u);
  EXPECT_EQ(rep.cases, (std::vector<std::string>{"case1", "case4"}));

  const auto csv = lines(slurp(rep.results_csv));
  ASSERT_EQ(csv.size(), 5u);
  EXPECT_EQ(csv[0], kResultsHeader);
  EXPECT_EQ(csv[1].rfind("case1,ntcl+dpd_ref,", 0), 0u);
  EXPECT_EQ(csv[2], "case1,ntcl+fuel_optimal,,,,,,");  // no reference: no numbers
  EXPECT_EQ(csv[4], "case4,ntcl+fuel_optimal,,,,,,");

  // Markdown: strategies as columns, cases as row groups of the six figures of merit.
  const std::string md = slurp(rep.results_md);
  EXPECT_NE(md.find("| case | figure of merit | `ntcl+dpd_ref` | `ntcl+fuel_optimal` |"),
            std::string::npos);
  EXPECT_NE(md.find("| **case1** | t_ω,conv (s) |"), std::string::npos);
  EXPECT_NE(md.find("| **case4** | t_ω,conv (s) |"), std::string::npos);
  EXPECT_NE(md.find("no ref."), std::string::npos);
  EXPECT_NE(md.find("NC"), std::string::npos);  // 300 s is far too short to converge

  // Per-run time series: 300 s at 1 s plus the final row, every column present.
  const RunResult& r = rep.results[0];
  ASSERT_EQ(r.status, RunStatus::kOk);
  const auto ts = lines(slurp(r.timeseries_path));
  ASSERT_EQ(ts.size(), 1u + 301u);
  EXPECT_EQ(ts[0].rfind("t_s,omega_x,omega_y,omega_z,omega_hat_x", 0), 0u);
  EXPECT_NE(ts[0].find("u7,fuel_kg"), std::string::npos);
  // The first row is the initial state of SPEC §5.
  EXPECT_EQ(ts[1].rfind("0,0.01,0.02,0.03,", 0), 0u);

  // The plot is a PNG made by gnuplot.
  ASSERT_FALSE(r.plot_path.empty()) << r.note;
  std::ifstream png(r.plot_path, std::ios::binary);
  char magic[8] = {};
  png.read(magic, 8);
  EXPECT_EQ(std::string(magic + 1, 3), "PNG");
  EXPECT_EQ(rep.results[1].status, RunStatus::kNoReference);
  EXPECT_TRUE(rep.results[1].timeseries_path.empty());
  fs::remove_all(dir);
}

// A run that identifies and detects faults carries the identifier's errors against the truth and
// the detector's state in its time series; at the marks (60, 300 s) the columns are the marks'
// numbers. A run without those modules has none of the columns.
TEST(CampaignOutputs, TimeSeriesCarriesIdentificationAndFaultDetectionWhenFlown) {
  CampaignSpec spec;
  spec.mission_file = kConfigs + "/mission.yaml";
  spec.gnc_file = kConfigs + "/gnc.yaml";
  spec.case_files = {kConfigs + "/cases/case2.yaml"};
  spec.strategies = {*parse_strategy("ntcl+dpd_ref:id:fdi"), *parse_strategy("ntcl+dpd_ref")};
  const fs::path dir = fs::temp_directory_path() / "rocksteady_outputs_id_series";
  fs::remove_all(dir);
  spec.out_dir = dir.string();
  spec.duration_s = 400.0;
  spec.log_interval_s = 20.0;
  spec.write_plots = false;
  spec.progress = ProgressMode::kOff;
  NoTrajectorySource none;
  std::ostringstream log;
  const CampaignReport rep = run_campaign(spec, none, log);
  ASSERT_EQ(rep.results.size(), 2u);
  const RunResult& id = rep.results[0];
  ASSERT_EQ(id.status, RunStatus::kOk) << id.note;
  const auto ts = lines(slurp(id.timeseries_path));
  ASSERT_GE(ts.size(), 2u);
  const std::string tail =
      ",mode,id_j_rel,id_r_err_m,id_k_max_err,id_j_nees,id_r_nees,id_r_sigma_max_m,"
      "id_windows_gated,id_gate_reinflations,id_windows,id_guard_refusals,id_excited_inertia,"
      "fdi_chi2,fdi_best,fdi_best_llr,fdi_confirmed,"
      "fdi_check_jet";
  ASSERT_GE(ts[0].size(), tail.size());
  EXPECT_EQ(ts[0].substr(ts[0].size() - tail.size()), tail);
  auto fields = [](const std::string& line) {
    std::vector<std::string> f;
    std::stringstream ss(line);
    std::string x;
    while (std::getline(ss, x, ',')) f.push_back(x);
    return f;
  };
  const std::vector<std::string> head = fields(ts[0]);
  auto col = [&](const char* name) {
    const auto it = std::find(head.begin(), head.end(), name);
    return static_cast<std::size_t>(it - head.begin());
  };
  int at_marks = 0;
  long windows = 0, refusals = 0;
  for (std::size_t i = 1; i < ts.size(); ++i) {
    const std::vector<std::string> f = fields(ts[i]);
    ASSERT_EQ(f.size(), head.size()) << "row " << i;
    const double t = std::stod(f[0]);
    // The identifier's counters only grow; the excitation flag is a boolean.
    EXPECT_GE(std::stol(f[col("id_windows")]), windows) << t;
    EXPECT_GE(std::stol(f[col("id_guard_refusals")]), refusals) << t;
    windows = std::stol(f[col("id_windows")]);
    refusals = std::stol(f[col("id_guard_refusals")]);
    EXPECT_TRUE(f[col("id_excited_inertia")] == "0" || f[col("id_excited_inertia")] == "1") << t;
    for (const IdentificationMark& m : id.estimation.marks) {
      if (!m.reached || std::fabs(t - m.t_s) > 1e-6) continue;
      ++at_marks;
      EXPECT_NEAR(std::stod(f[col("id_j_rel")]), m.j_rel, 1e-6 * m.j_rel + 1e-12) << t;
      EXPECT_NEAR(std::stod(f[col("id_r_err_m")]), m.r_err_m, 1e-6 * m.r_err_m + 1e-12) << t;
      EXPECT_NEAR(std::stod(f[col("id_j_nees")]), m.j_nees, 1e-6 * m.j_nees + 1e-12) << t;
      EXPECT_NEAR(std::stod(f[col("id_r_nees")]), m.r_nees, 1e-6 * m.r_nees + 1e-12) << t;
    }
    EXPECT_EQ(f[col("fdi_confirmed")], "0") << t;  // a healthy run
    EXPECT_EQ(f[col("fdi_check_jet")], "-1") << t;
  }
  EXPECT_EQ(at_marks, 2) << "the 60 s and 300 s marks fall on logged rows";
  EXPECT_GT(windows, 0) << "windows closed over the run";
  // Without the modules: the series ends with the mode.
  const auto plain = lines(slurp(rep.results[1].timeseries_path));
  ASSERT_GE(plain.size(), 1u);
  ASSERT_GE(plain[0].size(), 5u);
  EXPECT_EQ(plain[0].substr(plain[0].size() - 5), ",mode");
  EXPECT_EQ(plain[0].find("id_j_rel"), std::string::npos);
  EXPECT_EQ(plain[0].find("fdi_chi2"), std::string::npos);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace rocksteady::campaign
