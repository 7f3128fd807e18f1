// Configuration files: the shipped ones load into the SPEC's values; each class of bad file gives a
// ConfigError naming the file, the key and the reason.
#include <stdlib.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>

#include <Eigen/Eigenvalues>
#include <gtest/gtest.h>

#include "ground/config/config.hpp"

namespace rocksteady::config {
namespace {

namespace fs = std::filesystem;

const std::string kConfigs = std::string(ROCKSTEADY_SOURCE_DIR) + "/configs";
const std::string kMission = kConfigs + "/mission.yaml";
const std::string kGnc = kConfigs + "/gnc.yaml";
std::string case_file(int n) { return kConfigs + "/cases/case" + std::to_string(n) + ".yaml"; }

std::string read(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// A temporary copy of a shipped file with one edit applied.
class TempFile {
 public:
  TempFile(const std::string& name, const std::string& text) {
    // mkdtemp: unique across the test processes ctest runs in parallel (a name from the gtest
    // seed, which follows the clock, collided when two started in the same millisecond).
    std::string tmpl = (fs::temp_directory_path() / "rocksteady_config_XXXXXX").string();
    if (::mkdtemp(tmpl.data()) == nullptr) throw std::runtime_error("mkdtemp failed: " + tmpl);
    dir_ = tmpl;
    path_ = (dir_ / name).string();
    std::ofstream(path_) << text;
  }
  ~TempFile() { fs::remove_all(dir_); }
  const std::string& path() const { return path_; }

 private:
  fs::path dir_;
  std::string path_;
};

std::string replaced(const std::string& text, const std::string& from, const std::string& to) {
  const std::size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << "test setup: '" << from << "' not in the shipped file";
  std::string out = text;
  if (at != std::string::npos) out.replace(at, from.size(), to);
  return out;
}

// Runs `load` and checks the error names file, key and reason.
template <typename F>
void expect_error(F load, const std::string& file, const std::string& key,
                  const std::string& reason_part) {
  try {
    load();
    ADD_FAILURE() << "no error for " << key;
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.file(), file) << e.what();
    EXPECT_EQ(e.key(), key) << e.what();
    EXPECT_NE(e.reason().find(reason_part), std::string::npos) << e.what();
    const std::string what = e.what();
    EXPECT_NE(what.find(file), std::string::npos);
    EXPECT_NE(what.find(key), std::string::npos);
  }
}

TEST(ConfigShipped, MissionIsTheStudysTrueSpacecraftAndAsteroid) {
  const MissionConfig m = load_mission(kMission);
  const gnc::MassProperties truth = gnc::study_true_mass_properties();
  EXPECT_LT((m.mass.j_ast - truth.j_ast).norm(), 1e-6);
  EXPECT_LT((m.mass.j_sc - truth.j_sc).norm(), 1e-9);
  EXPECT_LT((m.mass.r_so_bcm - truth.r_so_bcm).norm(), 1e-15);
  EXPECT_LT((m.mass.r_scm_so - truth.r_scm_so).norm(), 1e-15);
  EXPECT_EQ(m.mass.m_sc, truth.m_sc);
  // The RCS layout matches the SPEC §4 layout built by the flight core's model.
  const gnc::RcsLayout ours = rcs_layout(m, 200.0);
  const gnc::RcsLayout study = gnc::study_rcs_layout(200.0);
  EXPECT_LT((gnc::torque_matrix(ours, truth.r_so_bcm) - gnc::torque_matrix(study, truth.r_so_bcm))
                .norm(),
            1e-12);
}

TEST(ConfigShipped, EveryCaseAssemblesWithTable3ErrorsAlongSpecDirections) {
  const double table_dj[] = {0, 1e5, 1e6, 1e7, 0, 0, 1e7};
  const double table_dr[] = {0, 1e-2, 1e-1, 1, 0, 0, 1};
  const double table_pw[] = {0, 0, 0, 0, 1e-12, 1e-10, 1e-10};
  const double table_pq[] = {0, 0, 0, 0, 1e-8, 1e-6, 1e-6};
  const double table_umax[] = {200, 200, 200, 1000, 200, 200, 200};
  for (int n = 1; n <= 7; ++n) {
    SCOPED_TRACE(n);
    const RunSetup s = load_run(kMission, kGnc, case_file(n));
    const int i = n - 1;
    EXPECT_EQ(s.case_number, n);
    EXPECT_EQ(s.duration_s, 1e5);
    // dJ = J_true - J_hat, spectral norm and direction diag(-1, 1, 0.5).
    const Mat3 dj = s.truth.mass.j_ast - s.flight.mass_hat.j_ast;
    const Eigen::SelfAdjointEigenSolver<Mat3> eig(dj);
    EXPECT_NEAR(eig.eigenvalues().cwiseAbs().maxCoeff(), table_dj[i], 1e-6 * (1 + table_dj[i]));
    EXPECT_NEAR(dj(0, 0), -table_dj[i], 1e-6 * (1 + table_dj[i]));
    EXPECT_NEAR(dj(1, 1), table_dj[i], 1e-6 * (1 + table_dj[i]));
    EXPECT_NEAR(dj(2, 2), 0.5 * table_dj[i], 1e-6 * (1 + table_dj[i]));
    const Vec3 dr = s.truth.mass.r_so_bcm - s.flight.mass_hat.r_so_bcm;
    EXPECT_NEAR(dr.norm(), table_dr[i], 1e-12);
    if (table_dr[i] > 0) {
      EXPECT_LT((dr.normalized() - Vec3::Ones().normalized()).norm(), 1e-12);
    }
    EXPECT_EQ(s.truth.sensors.gyro_psd, table_pw[i]);
    EXPECT_EQ(s.truth.sensors.star_psd, table_pq[i]);
    EXPECT_EQ(s.truth.rcs.u_max, table_umax[i]);
    EXPECT_EQ(s.flight.rcs.u_max, table_umax[i]);
    // estimator: auto = filter exactly where the sensors are noisy (SPEC §6).
    EXPECT_EQ(s.flight.estimator.kind, table_pw[i] > 0 ? gnc::EstimatorKind::kFilter
                                                       : gnc::EstimatorKind::kPassThrough);
    EXPECT_TRUE(gnc::validate(s.flight).ok);
    EXPECT_NEAR(s.flight.dt, 0.1, 1e-15);
  }
}

TEST(ConfigShipped, GncIsTable4) {
  const GncConfig g = load_gnc(kGnc);
  const gnc::GncParams d;  // the flight core's defaults are Table 4
  EXPECT_EQ(g.params.ntcl.k, d.ntcl.k);
  EXPECT_EQ(g.params.ntcl.lambda, d.ntcl.lambda);
  EXPECT_EQ(g.params.adaptive.gamma, 1e12);
  EXPECT_EQ(g.params.dpd.k_p, 10.0);
  EXPECT_EQ(g.params.guidance.omega_switch, 5e-4);
  EXPECT_EQ(g.params.guidance.k_qd, 1e-4);
  EXPECT_NEAR(g.params.guidance.eps_trans, d.guidance.eps_trans, 1e-15);
  EXPECT_NEAR(g.params.estimator.omega_c, d.estimator.omega_c, 1e-15);
  EXPECT_EQ(g.estimator, EstimatorChoice::kAuto);
  EXPECT_EQ(g.params.allocator, gnc::AllocatorKind::kPseudoInverse);  // the study's Eq. (53)
}

TEST(ConfigShipped, AllocatorKeyIsOptionalAndSelectsTheL1Allocator) {
  TempFile l1("gnc.yaml", replaced(read(kGnc), "allocator: pinv", "allocator: l1"));
  EXPECT_EQ(load_gnc(l1.path()).params.allocator, gnc::AllocatorKind::kL1);
  EXPECT_EQ(load_run(kMission, l1.path(), case_file(1)).flight.allocator, gnc::AllocatorKind::kL1);
  TempFile absent("gnc.yaml", replaced(read(kGnc), "allocator: pinv", ""));
  EXPECT_EQ(load_gnc(absent.path()).params.allocator, gnc::AllocatorKind::kPseudoInverse);
}

// Momentum tracking (guidance.track_momentum_k): off (the law on the plan's rates) in the shipped
// file and when the key is absent; set, read; negative, the file and key named.
TEST(ConfigShipped, MomentumTrackingIsOptionalAndChecked) {
  const std::string from = read(kGnc).substr(read(kGnc).find("  track_momentum_k: 0.0"));
  const std::string line = from.substr(0, from.find('\n'));
  EXPECT_EQ(load_gnc(kGnc).params.guidance.track_momentum_k, 0.0);
  TempFile absent("gnc.yaml", replaced(read(kGnc), line, ""));
  EXPECT_EQ(load_gnc(absent.path()).params.guidance.track_momentum_k,
            gnc::GncParams{}.guidance.track_momentum_k);
  TempFile set("gnc.yaml", replaced(read(kGnc), line, "  track_momentum_k: 0.001"));
  EXPECT_EQ(load_gnc(set.path()).params.guidance.track_momentum_k, 0.001);
  TempFile bad("gnc.yaml", replaced(read(kGnc), line, "  track_momentum_k: -0.001"));
  expect_error([&] { load_gnc(bad.path()); }, bad.path(), "guidance.track_momentum_k",
               "must not be negative");
}

// The acquisition slew (guidance.slew_s, slew_ramp_s): off (Eqs. 46-48) in the shipped file, the
// defaults when the keys are absent, and a bad value names the file and key.
TEST(ConfigShipped, TheAcquisitionSlewIsOptionalAndChecked) {
  const gnc::GncParams defaults;
  const std::string slew = read(kGnc).substr(read(kGnc).find("  slew_s: 0.0"));
  const std::string slew_line = slew.substr(0, slew.find('\n'));
  const std::string ramp = read(kGnc).substr(read(kGnc).find("  slew_ramp_s: 1000.0"));
  const std::string ramp_line = ramp.substr(0, ramp.find('\n'));
  EXPECT_EQ(load_gnc(kGnc).params.guidance.slew_s, 0.0);
  EXPECT_EQ(load_gnc(kGnc).params.guidance.slew_ramp_s, 1000.0);
  TempFile absent("gnc.yaml", replaced(replaced(read(kGnc), slew_line, ""), ramp_line, ""));
  EXPECT_EQ(load_gnc(absent.path()).params.guidance.slew_s, defaults.guidance.slew_s);
  EXPECT_EQ(load_gnc(absent.path()).params.guidance.slew_ramp_s, defaults.guidance.slew_ramp_s);
  TempFile set("gnc.yaml", replaced(read(kGnc), slew_line, "  slew_s: 40000"));
  EXPECT_EQ(load_gnc(set.path()).params.guidance.slew_s, 40000.0);
  TempFile bad("gnc.yaml", replaced(read(kGnc), slew_line, "  slew_s: -1"));
  expect_error([&] { load_gnc(bad.path()); }, bad.path(), "guidance.slew_s", "must not be negative");
  TempFile bad_ramp("gnc.yaml", replaced(read(kGnc), ramp_line, "  slew_ramp_s: 0"));
  expect_error([&] { load_gnc(bad_ramp.path()); }, bad_ramp.path(), "guidance.slew_ramp_s",
               "must be positive");
}

// The MEKF's rate stage (gnc/estimation/README.md (M8)): on at the SPEC §6 cutoff in the shipped
// file, off (the raw gyro less the bias) when the key is absent, and a negative value is an error.
TEST(ConfigShipped, MekfRateCutoffIsOptionalAndChecked) {
  EXPECT_NEAR(load_gnc(kGnc).params.mekf.rate_cutoff, 0.02 * 3.141592653589793, 1e-15);
  const std::string line = "  rate_cutoff_rad_s: 0.06283185307179587";
  TempFile absent("gnc.yaml", replaced(read(kGnc), line, ""));
  EXPECT_EQ(load_gnc(absent.path()).params.mekf.rate_cutoff, 0.0);
  TempFile bad("gnc.yaml", replaced(read(kGnc), line, "  rate_cutoff_rad_s: -1.0"));
  expect_error([&] { load_gnc(bad.path()); }, bad.path(), "mekf.rate_cutoff_rad_s", "must not be negative");
  // A case with a perfect gyro (cases 1-4) has no noise to filter: the stage is off there.
  EXPECT_EQ(load_run(kMission, kGnc, case_file(4)).flight.mekf.rate_cutoff, 0.0);
  EXPECT_NEAR(load_run(kMission, kGnc, case_file(6)).flight.mekf.rate_cutoff,
              0.02 * 3.141592653589793, 1e-15);
}

// The bare-metal firmware flies gnc::apply_flight_identification_settings (it has no YAML
// reader): the identifier's settings must be the ones gnc.yaml gives, with a noisy gyro (case 6)
// and with the study's perfect one (case 1). Fails when either side changes alone.
TEST(ConfigShipped, TheFirmwaresIdentifierSettingsAreGncYamls) {
  for (const int n : {1, 6}) {
    SCOPED_TRACE("case " + std::to_string(n));
    const RunSetup run = load_run(kMission, kGnc, case_file(n));
    const gnc::IdentificationParams& y = run.flight.identification;
    gnc::GncParams p = gnc::study_gnc_params(200.0);
    gnc::apply_flight_identification_settings(p, y.config.gyro_sigma);
    const gnc::IdentificationParams& f = p.identification;
    EXPECT_EQ(f.config.mode, y.config.mode);
    EXPECT_EQ(f.config.window_s, y.config.window_s);
    EXPECT_EQ(f.config.j_prior_sigma, y.config.j_prior_sigma);
    EXPECT_EQ(f.config.r_prior_sigma, y.config.r_prior_sigma);
    EXPECT_EQ(f.config.k_prior_sigma, y.config.k_prior_sigma);
    EXPECT_EQ(f.config.disturbance_sigma, y.config.disturbance_sigma);
    EXPECT_EQ(f.config.gyro_sigma, y.config.gyro_sigma);
    EXPECT_EQ(f.config.gyro_bias_sigma, y.config.gyro_bias_sigma);
    EXPECT_EQ(f.config.gyro_bias_estimated, y.config.gyro_bias_estimated);
    EXPECT_EQ(f.config.second_order_noise, y.config.second_order_noise);
    EXPECT_EQ(f.config.gate_chi2, y.config.gate_chi2);
    EXPECT_EQ(f.config.gate_reinflate_after, y.config.gate_reinflate_after);
    EXPECT_EQ(f.config.min_inertia_information, y.config.min_inertia_information);
    EXPECT_EQ(f.config.min_offset_information, y.config.min_offset_information);
    EXPECT_EQ(f.config.guard_halvings, y.config.guard_halvings);
    EXPECT_EQ(f.config.early_window_s, y.config.early_window_s);
    EXPECT_EQ(f.config.early_span_s, y.config.early_span_s);
    EXPECT_EQ(f.config.j_forget_s, y.config.j_forget_s);
    EXPECT_EQ(f.config.r_forget_s, y.config.r_forget_s);
    EXPECT_EQ(f.config.j_confident_rel, y.config.j_confident_rel);
    EXPECT_EQ(f.config.r_confident, y.config.r_confident);
    EXPECT_EQ(f.config.k_confident, y.config.k_confident);
    EXPECT_EQ(f.adopt_interval_s, y.adopt_interval_s);
    EXPECT_EQ(f.adopt_sigmas, y.adopt_sigmas);
    EXPECT_EQ(f.mekf_bias_sigma_floor, y.mekf_bias_sigma_floor);
    EXPECT_EQ(f.keep_model_after_fault, y.keep_model_after_fault);
  }
  EXPECT_GT(load_run(kMission, kGnc, case_file(6)).flight.identification.config.gyro_sigma, 0.0);
}

// (I27) keep_model_after_fault: gnc.yaml false (measured, not adopted), true when set, false when
// the key is absent, and a value that is not a boolean names the file and key.
TEST(ConfigShipped, KeepingTheModelAfterAFaultIsReadAndOptional) {
  const std::string line =
      "  keep_model_after_fault: false # (I27) true: after a confirmed fault, restart from the "
      "confident model of the tick before (floored 1 sigma), not from the prior (measured, not "
      "adopted: estimation README I.9)";
  EXPECT_FALSE(load_run(kMission, kGnc, case_file(1)).flight.identification.keep_model_after_fault);
  TempFile on("gnc.yaml", replaced(read(kGnc), line, "  keep_model_after_fault: true"));
  EXPECT_TRUE(load_run(kMission, on.path(), case_file(6)).flight.identification.keep_model_after_fault);
  TempFile absent("gnc.yaml", replaced(read(kGnc), line, ""));
  EXPECT_FALSE(load_gnc(absent.path()).params.identification.keep_model_after_fault);
  TempFile bad("gnc.yaml", replaced(read(kGnc), line, "  keep_model_after_fault: 3"));
  expect_error([&] { load_gnc(bad.path()); }, bad.path(), "identification.keep_model_after_fault",
               "expected true or false");
}

// An optional switch of the detector's section: gnc.yaml names it with `shipped`, which is also
// the detector's default; the other value is read in a quiet case (1) and a noisy one (6); a
// file without the key keeps the default; a value that is not a boolean names the file and key.
void expect_optional_fdi_switch(const std::string& key, bool shipped,
                                bool gnc::FaultDetectorParams::*member) {
  const std::string as_shipped = key + ": " + (shipped ? "true" : "false");
  const std::string flipped = key + ": " + (shipped ? "false" : "true");
  EXPECT_EQ(load_run(kMission, kGnc, case_file(1)).flight.fdi.*member, shipped) << key;
  TempFile other("gnc.yaml", replaced(read(kGnc), as_shipped, flipped));
  EXPECT_EQ(load_run(kMission, other.path(), case_file(1)).flight.fdi.*member, !shipped) << key;
  EXPECT_EQ(load_run(kMission, other.path(), case_file(6)).flight.fdi.*member, !shipped) << key;
  TempFile absent("gnc.yaml", replaced(read(kGnc), "  " + as_shipped, "  #"));
  EXPECT_EQ(load_run(kMission, absent.path(), case_file(1)).flight.fdi.*member, shipped) << key;
  TempFile bad("gnc.yaml", replaced(read(kGnc), as_shipped, key + ": 3"));
  expect_error([&] { load_gnc(bad.path()); }, bad.path(), "fdi." + key, "");
}

TEST(ConfigShipped, TheGyroscopicFloorSwitchIsReadAndOptional) {
  // (F22): true, the floor on both terms of the model's error.
  expect_optional_fdi_switch("model_floor_gyroscopic", true,
                             &gnc::FaultDetectorParams::model_floor_gyroscopic);
}

TEST(ConfigShipped, TheChainedIsolationTestIsReadAndOptional) {
  // (F39): false, measured and not adopted.
  expect_optional_fdi_switch("probe_chain", false, &gnc::FaultDetectorParams::probe_chain);
}

// (F24) The jet checks' information gate: gnc.yaml's value, off (0) when the key is absent, and a
// negative value names the file and key.
// An optional fdi key shipped in gnc.yaml as `line`: `absent` checks a run whose gnc.yaml lacks the
// line, and `bad_line` in its place is refused, naming the file, fdi.<key> and the reason.
template <class Absent>
void expect_optional_fdi_key(const std::string& line, const std::string& key,
                             const std::string& bad_line, const std::string& reason,
                             Absent absent) {
  ASSERT_NE(read(kGnc).find(line), std::string::npos) << key;
  TempFile without("gnc.yaml", replaced(read(kGnc), line, "  #"));
  absent(without.path());
  TempFile bad("gnc.yaml", replaced(read(kGnc), line, bad_line));
  expect_error([&] { load_gnc(bad.path()); }, bad.path(), "fdi." + key, reason);
}

// (X8) The excitation's inertia phase: gnc.yaml's 100 N m per axis, no inertia phase when the key
// is absent, and a negative amplitude names the file and key.
TEST(ConfigShipped, TheExcitationsInertiaPhaseIsReadAndOptional) {
  const std::string line = "    inertia_torque_nm: [100.0, 100.0, 100.0]";
  const std::string text = read(kGnc);
  ASSERT_NE(text.find(line), std::string::npos);
  for (int c : {1, 4, 7}) {
    EXPECT_EQ(load_run(kMission, kGnc, case_file(c)).flight.identification.excitation.inertia_torque_nm,
              gnc::Vec3(100.0, 100.0, 100.0))
        << "case " << c;
  }
  const std::size_t eol = text.find('\n', text.find(line));
  const std::string whole = text.substr(text.find(line), eol - text.find(line));
  TempFile without("gnc.yaml", replaced(text, whole, "    #"));
  EXPECT_EQ(load_run(kMission, without.path(), case_file(4)).flight.identification.excitation.inertia_torque_nm,
            gnc::Vec3::Zero());
  TempFile bad("gnc.yaml", replaced(text, whole, "    inertia_torque_nm: [100.0, -1.0, 100.0]"));
  expect_error([&] { load_gnc(bad.path()); }, bad.path(), "identification.excitation.inertia_torque_nm",
               "must be >= 0");
}

// (I28) The guards' halvings: gnc.yaml's 3, refused as before (0) when the key is absent, and a
// value outside [0, 10] names the file and key.
TEST(ConfigShipped, TheGuardHalvingsAreReadAndOptional) {
  const std::string text = read(kGnc);
  const std::size_t at = text.find("  guard_halvings: 3 ");
  ASSERT_NE(at, std::string::npos);
  const std::string whole = text.substr(at, text.find('\n', at) - at);
  EXPECT_EQ(load_run(kMission, kGnc, case_file(4)).flight.identification.config.guard_halvings, 3);
  TempFile without("gnc.yaml", replaced(text, whole, "  #"));
  EXPECT_EQ(load_run(kMission, without.path(), case_file(4)).flight.identification.config.guard_halvings, 0);
  TempFile bad("gnc.yaml", replaced(text, whole, "  guard_halvings: 11"));
  expect_error([&] { load_gnc(bad.path()); }, bad.path(), "identification.guard_halvings", "must be in [0, 10]");
}

// (I30) The early windows: 12 s over the first 60 s with quiet sensors, none with a noisy gyro,
// none when the keys are absent; one longer than window_s is named with its file and key.
TEST(ConfigShipped, TheEarlyWindowsAreReadOptionalAndQuietSensorsOnly) {
  const std::string text = read(kGnc);
  EXPECT_EQ(load_run(kMission, kGnc, case_file(4)).flight.identification.config.early_window_s, 12.0);
  EXPECT_EQ(load_run(kMission, kGnc, case_file(4)).flight.identification.config.early_span_s, 60.0);
  EXPECT_EQ(load_run(kMission, kGnc, case_file(6)).flight.identification.config.early_window_s, 0.0);
  const std::size_t at = text.find("  window_early_s: 12.0 ");
  ASSERT_NE(at, std::string::npos);
  const std::string whole = text.substr(at, text.find('\n', at) - at);
  const std::size_t at2 = text.find("  window_early_span_s: 60.0");
  ASSERT_NE(at2, std::string::npos);
  const std::string span = text.substr(at2, text.find('\n', at2) - at2);
  TempFile without("gnc.yaml", replaced(replaced(text, whole, "  #"), span, "  #"));
  EXPECT_EQ(load_run(kMission, without.path(), case_file(4)).flight.identification.config.early_window_s, 0.0);
  TempFile bad("gnc.yaml", replaced(text, whole, "  window_early_s: 30.0"));
  expect_error([&] { load_gnc(bad.path()); }, bad.path(), "identification.window_early_s",
               "must not exceed window_s");
}

TEST(ConfigShipped, TheJetCheckInformationGateIsReadAndOptional) {
  EXPECT_EQ(load_run(kMission, kGnc, case_file(1)).flight.fdi.check_min_llr, 5.0);
  EXPECT_EQ(load_run(kMission, kGnc, case_file(6)).flight.fdi.check_min_llr, 5.0);
  expect_optional_fdi_key("  check_min_llr: 5.0", "check_min_llr", "  check_min_llr: -1.0",
                          "must not be negative", [](const std::string& gnc) {
                            EXPECT_EQ(load_run(kMission, gnc, case_file(1)).flight.fdi.check_min_llr,
                                      0.0);
                          });
}

// (F36) The jet survey: every 20 000 s in gnc.yaml (F48), off (0) when the key is absent; its
// energy and its longest check read (the struct's values when absent); bad values named by file
// and key.
TEST(ConfigShipped, TheJetSurveyIsReadOptionalAndOnInGncYaml) {
  EXPECT_EQ(load_run(kMission, kGnc, case_file(1)).flight.fdi.survey_interval_s, 20000.0);
  EXPECT_EQ(load_run(kMission, kGnc, case_file(7)).flight.fdi.survey_interval_s, 20000.0);
  EXPECT_EQ(load_run(kMission, kGnc, case_file(6)).flight.fdi.survey_energy, 10.0);
  EXPECT_EQ(load_run(kMission, kGnc, case_file(6)).flight.fdi.survey_max_windows, 8);
  expect_optional_fdi_key("  survey_interval_s: 20000.0", "survey_interval_s",
                          "  survey_interval_s: -5", "", [](const std::string& gnc) {
                            EXPECT_EQ(load_run(kMission, gnc, case_file(1)).flight.fdi.survey_interval_s,
                                      0.0);
                          });
  // (F44) The survey's kick bound: 5e-5 rad/s in gnc.yaml, off (0) when absent, a negative one named.
  EXPECT_EQ(load_run(kMission, kGnc, case_file(1)).flight.fdi.survey_max_kick_rad_s, 5.0e-5);
  expect_optional_fdi_key("  survey_max_kick_rad_s: 5.0e-5", "survey_max_kick_rad_s",
                          "  survey_max_kick_rad_s: -1e-5", "", [](const std::string& gnc) {
                            EXPECT_EQ(
                                load_run(kMission, gnc, case_file(1)).flight.fdi.survey_max_kick_rad_s,
                                0.0);
                          });
  TempFile other("gnc.yaml", replaced(read(kGnc), "  survey_interval_s: 20000.0", "  survey_interval_s: 300"));
  EXPECT_EQ(load_run(kMission, other.path(), case_file(1)).flight.fdi.survey_interval_s, 300.0);
  expect_optional_fdi_key("  survey_energy: 10.0", "survey_energy", "  survey_energy: 0", "",
                          [](const std::string& gnc) {
                            EXPECT_EQ(load_run(kMission, gnc, case_file(1)).flight.fdi.survey_energy,
                                      gnc::FaultDetectorParams{}.survey_energy);
                          });
  expect_optional_fdi_key("  survey_max_windows: 8", "survey_max_windows",
                          "  survey_max_windows: 0", "must be in [1, 1000]",
                          [](const std::string& gnc) {
                            EXPECT_EQ(load_run(kMission, gnc, case_file(1)).flight.fdi.survey_max_windows,
                                      gnc::FaultDetectorParams{}.survey_max_windows);
                          });
  // (F57) A jet with partial-loss evidence is not verified by its energy: 2.5 in gnc.yaml, off
  // (0) when the key is absent.
  EXPECT_EQ(load_run(kMission, kGnc, case_file(6)).flight.fdi.survey_loss_llr, 2.5);
  expect_optional_fdi_key("  survey_loss_llr: 2.5", "survey_loss_llr", "  survey_loss_llr: -1", "",
                          [](const std::string& gnc) {
                            EXPECT_EQ(load_run(kMission, gnc, case_file(1)).flight.fdi.survey_loss_llr,
                                      0.0);
                          });
}

// (F58) A stuck-off leader this many of its fit's 1 sigma below the total-loss floor is a partial
// loss: 2 in gnc.yaml, off (0) when the key is absent, a negative value named by file and key.
TEST(ConfigShipped, TheTotalLossSigmasAreReadAndOptional) {
  EXPECT_EQ(load_run(kMission, kGnc, case_file(7)).flight.fdi.total_loss_sigmas, 2.0);
  expect_optional_fdi_key("  total_loss_sigmas: 2.0", "total_loss_sigmas", "  total_loss_sigmas: -1",
                          "", [](const std::string& gnc) {
                            EXPECT_EQ(load_run(kMission, gnc, case_file(1)).flight.fdi.total_loss_sigmas,
                                      0.0);
                          });
}

// (F59) After a fault, no further loss confirmed and no check on a model whose inertia is not
// known to this: 0.01 in gnc.yaml (the identifier's confidence bound), off (0) when the key is
// absent, a negative value named by file and key.
TEST(ConfigShipped, TheAfterFaultModelBoundIsReadAndOptional) {
  EXPECT_EQ(load_run(kMission, kGnc, case_file(4)).flight.fdi.after_fault_max_j_rel, 0.01);
  expect_optional_fdi_key("  after_fault_max_j_rel: 0.01", "after_fault_max_j_rel",
                          "  after_fault_max_j_rel: -1", "", [](const std::string& gnc) {
                            EXPECT_EQ(load_run(kMission, gnc, case_file(1)).flight.fdi.after_fault_max_j_rel,
                                      0.0);
                          });
}

// (F49) Long checks where the gyro is too noisy for the survey's: gnc.yaml's 1 000 samples at
// energies 80 (survey) and 320 (evidence), off (0) when the key is absent (the struct's energies),
// bad values named by file and key; (F50) evidence checks at 0.8 of the energy the centre of mass
// caps, off (0) when absent.
TEST(ConfigShipped, TheLongChecksAreReadOptionalAndOnInGncYaml) {
  const auto fd = load_run(kMission, kGnc, case_file(7)).flight.fdi;
  EXPECT_EQ(fd.check_long_ticks, 1000);
  EXPECT_EQ(fd.check_long_energy, 80.0);
  EXPECT_EQ(fd.check_long_evidence_energy, 320.0);
  EXPECT_EQ(fd.check_long_reach, 0.8);  // (F50)
  expect_optional_fdi_key("  check_long_ticks: 1000", "check_long_ticks",
                          "  check_long_ticks: 2", "must be 0 or in [4, 1000]",
                          [](const std::string& gnc) {
                            EXPECT_EQ(load_run(kMission, gnc, case_file(7)).flight.fdi.check_long_ticks, 0);
                          });
  expect_optional_fdi_key("  check_long_energy: 80.0", "check_long_energy",
                          "  check_long_energy: 0", "", [](const std::string& gnc) {
                            EXPECT_EQ(load_run(kMission, gnc, case_file(7)).flight.fdi.check_long_energy,
                                      gnc::FaultDetectorParams{}.check_long_energy);
                          });
  expect_optional_fdi_key("  check_long_evidence_energy: 320.0", "check_long_evidence_energy",
                          "  check_long_evidence_energy: -1", "", [](const std::string& gnc) {
                            EXPECT_EQ(load_run(kMission, gnc, case_file(7))
                                          .flight.fdi.check_long_evidence_energy,
                                      gnc::FaultDetectorParams{}.check_long_evidence_energy);
                          });
  expect_optional_fdi_key("  check_long_reach: 0.8", "check_long_reach",  // (F50), off when absent
                          "  check_long_reach: 1.5", "must be in [0, 0.95]", [](const std::string& gnc) {
                            EXPECT_EQ(load_run(kMission, gnc, case_file(7)).flight.fdi.check_long_reach, 0.0);
                          });
}

// (F33) Early detection: gnc.yaml's 3 samples at chi-square(3) 1 - 1e-7, off (0) when the key is
// absent, and a bad value named by file and key.
TEST(ConfigShipped, EarlyDetectionIsReadAndOptional) {
  EXPECT_EQ(load_run(kMission, kGnc, case_file(1)).flight.fdi.detect_early_ticks, 3);
  EXPECT_EQ(load_run(kMission, kGnc, case_file(6)).flight.fdi.detect_early_chi2, 35.41);
  expect_optional_fdi_key("  detect_early_ticks: 3", "detect_early_ticks",
                          "  detect_early_ticks: -1", "must be in [0, 1000]",
                          [](const std::string& gnc) {
                            EXPECT_EQ(load_run(kMission, gnc, case_file(1)).flight.fdi.detect_early_ticks,
                                      0);
                          });
  expect_optional_fdi_key("  detect_early_chi2: 35.41", "detect_early_chi2",
                          "  detect_early_chi2: -2", "", [](const std::string& gnc) {
                            EXPECT_EQ(load_run(kMission, gnc, case_file(1)).flight.fdi.detect_early_chi2,
                                      gnc::FaultDetectorParams{}.detect_early_chi2);
                          });
}

// (F30) The window sized by the case's gyro noise, against a brute-force count: for each case, the
// weakest jet's acceleration from the table's model, column by column, and the slope statistic's
// sum of squared sample times written out; the window is the first n from `from` (below `to`)
// whose stuck-on ramp stands snr sigma above the gyro, `to` when none does, `from` with a
// noise-free gyro.
int brute_force_window(const gnc::GncParams& p, const CaseConfig& cs, double snr, int from, int to) {
  const double sigma = std::sqrt(cs.gyro_psd / 0.1);
  if (!(sigma > 0.0)) return from;
  const gnc::Mat3 j = gnc::total_inertia(p.mass_hat);
  double a_min = 1e300;
  for (int ch = 0; ch < gnc::kChannels; ++ch) {
    const auto k = static_cast<std::size_t>(ch);
    const gnc::Vec3 arm = p.mass_hat.r_so_bcm +
                          p.rcs.pod_position[static_cast<std::size_t>(p.rcs.channel_pod[k])];
    const gnc::Vec3 b = arm.cross(p.rcs.channel_direction[k]);
    a_min = std::fmin(a_min, j.ldlt().solve(b).norm() * p.rcs.u_max);
  }
  for (int n = from; n < to; ++n) {
    double mean = 0.0;
    for (int t = 1; t <= n; ++t) mean += t;
    mean /= n;
    double stt = 0.0;
    for (int t = 1; t <= n; ++t) stt += (t - mean) * (t - mean);
    if (a_min * 0.1 * std::sqrt(stt) / sigma >= snr) return n;
  }
  return to;
}

// gnc.yaml's value, and the former switch when the key is absent.
TEST(ConfigShipped, TheNoisyWindowIsSizedByTheGyroNoise) {
  const std::string line = "  window_snr: 5.0";
  ASSERT_NE(read(kGnc).find(line), std::string::npos);
  for (int c = 1; c <= 7; ++c) {
    const auto run = load_run(kMission, kGnc, case_file(c));
    const CaseConfig cs = load_case(case_file(c));
    const bool noisy = cs.gyro_psd > 0.0 || cs.star_psd > 0.0;
    // gnc.yaml: window_ticks 10 (quiet sensors), window_noisy_ticks 25.
    const int expect = noisy ? brute_force_window(run.flight, cs, 5.0, 10, 25) : 10;
    EXPECT_EQ(run.flight.fdi.window_ticks, expect) << "case " << c;
  }
  // The study's noisy cases: case 5's gyro (3.2e-6 rad/s a sample) flies the quiet window, cases
  // 6-7 (3.2e-5) a long one.
  EXPECT_EQ(load_run(kMission, kGnc, case_file(5)).flight.fdi.window_ticks, 10);
  EXPECT_GE(load_run(kMission, kGnc, case_file(6)).flight.fdi.window_ticks, 20);
  expect_optional_fdi_key(line, "window_snr", "  window_snr: -1", "", [](const std::string& gnc) {
    EXPECT_EQ(load_run(kMission, gnc, case_file(5)).flight.fdi.window_ticks, 25);
  });
}

// (F46) The isolation test's window: gnc.yaml's 5 samples with quiet sensors; with noisy ones the
// same brute-force count from 5 up to the bank's window. Absent, 0 (the test flies a whole
// window); a value below the evaluation's 4 steps names the file and key.
TEST(ConfigShipped, TheIsolationTestsWindowIsSizedByTheGyroNoise) {
  const std::string line = "  probe_window_ticks: 5";
  ASSERT_NE(read(kGnc).find(line), std::string::npos);
  for (int c = 1; c <= 7; ++c) {
    const auto run = load_run(kMission, kGnc, case_file(c));
    const CaseConfig cs = load_case(case_file(c));
    const bool noisy = cs.gyro_psd > 0.0 || cs.star_psd > 0.0;
    const int expect =
        noisy ? brute_force_window(run.flight, cs, 5.0, 5, run.flight.fdi.window_ticks) : 5;
    EXPECT_EQ(run.flight.fdi.probe_window_ticks, expect) << "case " << c;
    EXPECT_LE(run.flight.fdi.probe_window_ticks, run.flight.fdi.window_ticks) << "case " << c;
    std::printf("case %d: bank window %d, isolation test %d samples\n", c,
                run.flight.fdi.window_ticks, run.flight.fdi.probe_window_ticks);
  }
  // Case 5 tests on a shorter window than its bank's 10 samples; cases 6-7 on about their bank's.
  EXPECT_LT(load_run(kMission, kGnc, case_file(5)).flight.fdi.probe_window_ticks, 10);
  EXPECT_GE(load_run(kMission, kGnc, case_file(7)).flight.fdi.probe_window_ticks, 20);
  expect_optional_fdi_key(line, "probe_window_ticks", "  probe_window_ticks: 3",
                          "must be 0 or in [4, 1000]", [](const std::string& gnc) {
                            EXPECT_EQ(load_run(kMission, gnc, case_file(1)).flight.fdi.probe_window_ticks, 0);
                            EXPECT_EQ(load_run(kMission, gnc, case_file(6)).flight.fdi.probe_window_ticks, 0);
                          });
}

// (F47) The short test's evidence gate: gnc.yaml's 10 in every case, 0 (every test short) when the
// key is absent, a negative one named by file and key.
TEST(ConfigShipped, TheShortIsolationTestsEvidenceGateIsReadAndOptional) {
  for (int c = 1; c <= 7; ++c) {
    EXPECT_EQ(load_run(kMission, kGnc, case_file(c)).flight.fdi.probe_short_min_llr, 10.0)
        << "case " << c;
  }
  expect_optional_fdi_key("  probe_short_min_llr: 10.0", "probe_short_min_llr",
                          "  probe_short_min_llr: -1", "must not be negative",
                          [](const std::string& gnc) {
                            EXPECT_EQ(load_run(kMission, gnc, case_file(1)).flight.fdi.probe_short_min_llr,
                                      0.0);
                          });
}

// (F52) Isolation tests started on a stuck-on leader past 8, below confirm_llr: gnc.yaml's 8, off
// (0) when the key is absent, and a level at or past confirm_llr names the file and key.
TEST(ConfigShipped, TheEarlyIsolationTestsLevelIsReadAndOptional) {
  for (int c = 1; c <= 7; ++c) {
    EXPECT_EQ(load_run(kMission, kGnc, case_file(c)).flight.fdi.probe_start_llr, 8.0)
        << "case " << c;
  }
  expect_optional_fdi_key("  probe_start_llr: 8.0", "probe_start_llr",
                          "  probe_start_llr: 30.0", "below confirm_llr",
                          [](const std::string& gnc) {
                            EXPECT_EQ(load_run(kMission, gnc, case_file(1)).flight.fdi.probe_start_llr,
                                      0.0);
                          });
}

// (F61) The channel balance tests: gnc.yaml's map read into every case's flight parameters, each
// bad value named by file and key, and no tests when the map is absent.
TEST(ConfigShipped, TheChannelBalanceTestsAreReadAndOptional) {
  for (int c = 1; c <= 7; ++c) {
    const gnc::BalanceTestParams& b = load_run(kMission, kGnc, case_file(c)).flight.fdi.balance;
    EXPECT_EQ(b.kick_rad_s, 0.0) << "case " << c;  // off in gnc.yaml (README F61)
    EXPECT_EQ(b.force_n, 100.0);
    EXPECT_EQ(b.quiet_ticks, 300);
    EXPECT_EQ(b.max_fire_ticks, 200);
    EXPECT_EQ(b.interval_s, 20000.0);
    EXPECT_EQ(b.chi2_bound, 30.66);
    EXPECT_EQ(b.min_snr, 10.0);
    EXPECT_EQ(b.total_sigmas, 2.0);
    EXPECT_EQ(b.partial_sigmas, 3.0);
    EXPECT_EQ(b.min_loss, 0.1);
    EXPECT_EQ(b.max_tests, 6);
  }
  const std::string text = read(kGnc);
  const struct {
    const char* line;
    const char* bad;
    const char* key;
    const char* reason;
  } bad_values[] = {
      {"    quiet_ticks: 300", "    quiet_ticks: 0", "fdi.balance.quiet_ticks", "[1, 10000]"},
      {"    min_loss: 0.1", "    min_loss: 1.5", "fdi.balance.min_loss", "below 1"},
      {"    partial_sigmas: 3.0", "    partial_sigmas: 1.0", "fdi.balance.partial_sigmas", "total_sigmas"},
      {"    kick_rad_s: 0.0 ", "    kick_rad_s: -1.0 ", "fdi.balance.kick_rad_s", "negative"},
      {"    max_tests: 6", "    max_tests: 0", "fdi.balance.max_tests", "[1, 1000]"},
  };
  for (const auto& v : bad_values) {
    ASSERT_NE(text.find(v.line), std::string::npos) << v.line;
    TempFile bad("gnc.yaml", replaced(text, v.line, v.bad));
    expect_error([&] { load_gnc(bad.path()); }, bad.path(), v.key, v.reason);
  }
  // Absent: every line of the map commented out, no tests.
  std::string without = text;
  const std::size_t at = without.find("  balance:");
  ASSERT_NE(at, std::string::npos);
  std::size_t pos = at;
  for (int i = 0; i < 12; ++i) {
    without.replace(pos, 2, "#");
    pos = without.find('\n', pos) + 1;
  }
  TempFile absent("gnc.yaml", without);
  EXPECT_EQ(load_run(kMission, absent.path(), case_file(5)).flight.fdi.balance.kick_rad_s, 0.0);
}

// (F27) aligned isolation tests, (F28) the centred gyro noise, (F29) the test's partial-loss rival,
// (F32) the test read on its closed windows, (F34) checks started on quiet windows, (F35) unfit
// check windows scored, (F37) the blocker checked, (F38) the stale episode restarted, (F40)
// another pod's jet named by a test's closed windows, (F41) the episode restarted for a new leader,
// (F21) the onset window not scored, (F45) ended at its early suspicion, (F42) checks in the
// identified model's null space, (F43) the survey in HOLD only and (F48) not where the gyro is
// too noisy, (F51) the loss gate on the signature's error along itself, (F56) evidence checks
// after a fault within the kick bound:
// gnc.yaml true, the former behaviour (false) when a key is absent, and a value that is not a
// boolean names the file and key.
TEST(ConfigShipped, TheAlignedTestTheCentredGyroNoiseAndThePartialRivalAreReadAndOptional) {
  for (const char* key : {"probe_aligned", "centred_gyro_noise", "probe_partial_rival",
                          "probe_read_closed", "check_quiet_start", "check_score_unfit",
                          "check_blocker", "episode_restart_stale", "probe_read_elsewhere",
                          "episode_restart_leader", "skip_onset_window",
                          "check_model_null_space", "survey_hold_only", "onset_restart",
                          "survey_noise_kick", "degraded_loss_projection",
                          "check_kick_after_fault"}) {
    const std::string line = std::string("  ") + key + ": true";
    const auto get = [&](const auto& f) {
      const std::string k = key;
      return k == "probe_aligned"         ? f.probe_aligned
             : k == "centred_gyro_noise"  ? f.centred_gyro_noise
             : k == "probe_partial_rival" ? f.probe_partial_rival
             : k == "probe_read_closed"   ? f.probe_read_closed
             : k == "check_quiet_start"   ? f.check_quiet_start
             : k == "check_blocker"       ? f.check_blocker
             : k == "episode_restart_stale" ? f.episode_restart_stale
             : k == "probe_read_elsewhere" ? f.probe_read_elsewhere
             : k == "check_model_null_space" ? f.check_model_null_space
             : k == "survey_hold_only" ? f.survey_hold_only
             : k == "episode_restart_leader" ? f.episode_restart_leader
             : k == "skip_onset_window"     ? f.skip_onset_window
             : k == "onset_restart"         ? f.onset_restart
             : k == "survey_noise_kick"     ? f.survey_noise_kick
             : k == "degraded_loss_projection" ? f.degraded_loss_projection
             : k == "check_kick_after_fault" ? f.check_kick_after_fault
                                          : f.check_score_unfit;
    };
    EXPECT_TRUE(get(load_run(kMission, kGnc, case_file(1)).flight.fdi)) << key;
    EXPECT_TRUE(get(load_run(kMission, kGnc, case_file(6)).flight.fdi)) << key;
    expect_optional_fdi_key(line, key, std::string("  ") + key + ": 3", "",
                            [&](const std::string& gnc) {
                              EXPECT_FALSE(get(load_run(kMission, gnc, case_file(1)).flight.fdi))
                                  << key;
                            });
  }
}

// (F25) The episode restart: gnc.yaml true, the former episode (false) when the key is absent,
// and a value that is not a boolean names the file and key.
TEST(ConfigShipped, TheEpisodeRestartIsReadAndOptional) {
  const std::string line = "  episode_restart: true";
  ASSERT_NE(read(kGnc).find(line), std::string::npos);
  EXPECT_TRUE(load_run(kMission, kGnc, case_file(1)).flight.fdi.episode_restart);
  EXPECT_TRUE(load_run(kMission, kGnc, case_file(6)).flight.fdi.episode_restart);
  TempFile absent("gnc.yaml", replaced(read(kGnc), line, "  #"));
  EXPECT_FALSE(load_run(kMission, absent.path(), case_file(1)).flight.fdi.episode_restart);
  TempFile bad("gnc.yaml", replaced(read(kGnc), line, "  episode_restart: 3"));
  expect_error([&] { load_gnc(bad.path()); }, bad.path(), "fdi.episode_restart", "");
}

TEST(ConfigErrors, UnreadableFile) {
  const std::string missing = kConfigs + "/cases/no_such_case.yaml";
  expect_error([&] { load_case(missing); }, missing, "", "cannot read file");
}

TEST(ConfigErrors, YamlSyntaxError) {
  TempFile f("case.yaml", read(case_file(1)) + "\nseed: [1, 2\n");
  expect_error([&] { load_case(f.path()); }, f.path(), "", "YAML syntax error");
}

TEST(ConfigErrors, MissingKey) {
  TempFile f("case.yaml", replaced(read(case_file(2)), "u_max_n: 200", ""));
  expect_error([&] { load_case(f.path()); }, f.path(), "u_max_n", "missing required key");
  TempFile g("gnc.yaml", replaced(read(kGnc), "k_p: 10.0", "k_pp: 10.0"));
  expect_error([&] { load_gnc(g.path()); }, g.path(), "laws.dpd.k_p", "missing required key");
}

TEST(ConfigErrors, UnknownKey) {
  TempFile f("mission.yaml", replaced(read(kMission), "  hold_s: 10.0", "  hold_s: 10.0\n  hold_ss: 3"));
  expect_error([&] { load_mission(f.path()); }, f.path(), "disturbance.hold_ss", "unknown key");
  TempFile g("case.yaml", read(case_file(1)) + "u_maxx: 3\n");
  expect_error([&] { load_case(g.path()); }, g.path(), "u_maxx", "unknown key");
}

// The findings: a duplicate key was silently ignored (the first one won), and u_max_n: 1e300 or
// duration_s: 1e300 were accepted. Both are errors naming file, key and reason now.
TEST(ConfigErrors, DuplicateKeyIsAnError) {
  TempFile f("case.yaml", read(case_file(1)) + "u_max_n: 5\n");
  expect_error([&] { load_case(f.path()); }, f.path(), "u_max_n", "duplicate key");
  TempFile g("gnc.yaml", replaced(read(kGnc), "  auto_hold: true", "  auto_hold: true\n  auto_hold: false"));
  expect_error([&] { load_gnc(g.path()); }, g.path(), "modes.auto_hold", "duplicate key");
}

TEST(ConfigErrors, ValuesOutsideTheirPhysicalRangesAreErrors) {
  TempFile f("case.yaml", replaced(read(case_file(2)), "u_max_n: 200", "u_max_n: 1e300"));
  expect_error([&] { load_case(f.path()); }, f.path(), "u_max_n", "physical range");
  TempFile g("case.yaml", read(case_file(1)));
  const std::string text = read(case_file(1));
  const std::size_t at = text.find("duration_s:");
  ASSERT_NE(at, std::string::npos);
  const std::size_t end = text.find('\n', at);
  TempFile h("case.yaml", text.substr(0, at) + "duration_s: 1e300" + text.substr(end));
  expect_error([&] { load_case(h.path()); }, h.path(), "duration_s", "physical range");
  TempFile k("gnc.yaml", replaced(read(kGnc), "sensor_timeout_s: 1.0", "sensor_timeout_s: 1e30"));
  try {
    load_flight_params(kMission, k.path(), case_file(1));
    ADD_FAILURE() << "sensor_timeout_s: 1e30 accepted";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("mode.sensor_timeout"), std::string::npos) << e.what();
  }
}

TEST(ConfigErrors, WrongShape) {
  TempFile f("mission.yaml",
             replaced(read(kMission), "r_so_bcm_m: [-0.0495, -0.0004, 3.5456]", "r_so_bcm_m: [1, 2]"));
  expect_error([&] { load_mission(f.path()); }, f.path(), "asteroid.r_so_bcm_m", "list of 3");
  TempFile g("gnc.yaml", replaced(read(kGnc), "ntcl:        {K: 1.0e4,", "ntcl:        {K: [1, 2],"));
  expect_error([&] { load_gnc(g.path()); }, g.path(), "laws.ntcl.K", "3x3 matrix");
  TempFile h("case.yaml", replaced(read(case_file(1)), "u_max_n: 200", "u_max_n: lots"));
  expect_error([&] { load_case(h.path()); }, h.path(), "u_max_n", "expected a number");
  TempFile k("gnc.yaml", replaced(read(kGnc), "laws:\n", "laws: 3\nold_laws:\n"));
  expect_error([&] { load_gnc(k.path()); }, k.path(), "laws", "expected a mapping");
}

TEST(ConfigErrors, NonPositiveDefiniteInertia) {
  TempFile f("mission.yaml", replaced(read(kMission), "- [ 0.8658e7,", "- [ -0.8658e7,"));
  expect_error([&] { load_mission(f.path()); }, f.path(), "asteroid.inertia_kg_m2",
               "not positive definite");
  TempFile g("mission.yaml", replaced(read(kMission), "[5.584e4, 5.584e4, 1.568e4]",
                                      "[5.584e4, 0.0, 1.568e4]"));
  expect_error([&] { load_mission(g.path()); }, g.path(), "spacecraft.inertia_kg_m2",
               "not positive definite");
  // An error so large that the flight software's estimate J_ast - dJ is not positive definite.
  TempFile h("case.yaml", replaced(read(case_file(4)), "delta_j_ast_norm_kg_m2: 1.0e7",
                                   "delta_j_ast_norm_kg_m2: 1.0e8"));
  expect_error([&] { load_run(kMission, kGnc, h.path()); }, h.path(), "delta_j_ast_norm_kg_m2",
               "not positive definite");
}

TEST(ConfigErrors, NegativeNoisePower) {
  TempFile f("case.yaml", replaced(read(case_file(6)), "gyro_noise_psd_rad2_s2: 1.0e-10",
                                   "gyro_noise_psd_rad2_s2: -1.0e-10"));
  expect_error([&] { load_case(f.path()); }, f.path(), "gyro_noise_psd_rad2_s2", "negative");
  TempFile g("case.yaml", replaced(read(case_file(6)), "star_noise_psd: 1.0e-6",
                                   "star_noise_psd: -1.0e-6"));
  expect_error([&] { load_case(g.path()); }, g.path(), "star_noise_psd", "negative");
}

TEST(ConfigErrors, BadValues) {
  TempFile f("gnc.yaml", replaced(read(kGnc), "estimator: auto", "estimator: kalman"));
  expect_error([&] { load_gnc(f.path()); }, f.path(), "estimator", "auto, passthrough, filter or mekf");
  TempFile a("gnc.yaml", replaced(read(kGnc), "allocator: pinv", "allocator: simplex"));
  expect_error([&] { load_gnc(a.path()); }, a.path(), "allocator", "pinv or l1");
  TempFile g("gnc.yaml", replaced(read(kGnc), "{K_d: 1.0e4, k_p: 10.0}", "{K_d: -1.0e4, k_p: 10.0}"));
  expect_error([&] { load_gnc(g.path()); }, g.path(), "laws.dpd.K_d", "not positive definite");
  TempFile h("case.yaml", replaced(read(case_file(1)), "seed: 1001", "seed: -4"));
  expect_error([&] { load_case(h.path()); }, h.path(), "seed", "non-negative integer");
  // Caught by the flight core's own validation, reported against gnc.yaml.
  TempFile k("gnc.yaml", replaced(read(kGnc), "omega_switch_rad_s: 5.0e-4", "omega_switch_rad_s: 1.0"));
  expect_error([&] { load_run(kMission, k.path(), case_file(1)); }, k.path(),
               "guidance.omega_switch", "below eps_trans");
}

TEST(PlantTruthExtras, AbsentKeysKeepTheStudyTruthAndGivenOnesApply) {
  const RunSetup run = load_run(kMission, kGnc, case_file(5));
  plant::PlantParams t = run.truth;
  apply_plant_truth(YAML::Load("{}"), "x.yaml", t);
  EXPECT_EQ(t.sensors.gyro_bias, Vec3::Zero());
  EXPECT_EQ(t.sensors.gyro_bias_rw, 0.0);
  EXPECT_EQ(t.thruster_strength, plant::Vec16::Ones());
  apply_plant_truth(
      YAML::Load("{gyro_bias_rad_s: [1.0e-5, -2.0e-5, 0], gyro_bias_random_walk: 1.0e-9, "
                 "thruster_strength: [1, 1, 1, 1, 0.5, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 0.9]}"),
      "x.yaml", t);
  EXPECT_EQ(t.sensors.gyro_bias, Vec3(1e-5, -2e-5, 0.0));
  EXPECT_EQ(t.sensors.gyro_bias_rw, 1e-9);
  EXPECT_EQ(t.thruster_strength(4), 0.5);
  EXPECT_EQ(t.thruster_strength(15), 0.9);
  EXPECT_EQ(t.thruster_strength(0), 1.0);
}

TEST(PlantTruthExtras, BadValuesNameFileAndKey) {
  plant::PlantParams t = load_run(kMission, kGnc, case_file(1)).truth;
  expect_error([&] { apply_plant_truth(YAML::Load("{gyro_bias_random_walk: -1}"), "x.yaml", t); },
               "x.yaml", "plant_truth.gyro_bias_random_walk", "negative");
  expect_error([&] { apply_plant_truth(YAML::Load("{thruster_strength: [1, 2]}"), "x.yaml", t); },
               "x.yaml", "plant_truth.thruster_strength", "16");
  expect_error(
      [&] {
        apply_plant_truth(
            YAML::Load("{thruster_strength: [1, 1, 1, 1, -0.5, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1]}"),
            "x.yaml", t);
      },
      "x.yaml", "plant_truth.thruster_strength", ">= 0");
  expect_error([&] { apply_plant_truth(YAML::Load("{gyro_bias: [0, 0, 0]}"), "x.yaml", t); },
               "x.yaml", "plant_truth.gyro_bias", "unknown key");
}


TEST(CaseFaults, AbsentMeansNoFaultAndNoTimeout) {
  for (int n = 1; n <= 7; ++n) {
    const RunSetup s = load_run(kMission, kGnc, case_file(n));
    EXPECT_TRUE(s.truth.faults.empty());
    EXPECT_EQ(s.truth.command_timeout_s, 0.0);
  }
}

TEST(CaseFaults, ListAndTimeoutReachThePlantButNotTheFlightSoftware) {
  TempFile f("case.yaml", read(case_file(5)) +
                              "faults:\n"
                              "  - {thruster: 3, kind: stuck_on, onset_s: 60}\n"
                              "  - {thruster: 9, kind: degraded, onset_s: 5000, factor: 0.5}\n"
                              "  - {thruster: 12, kind: stuck_off}\n"
                              "valve_driver_timeout_s: 1.5\n");
  const RunSetup s = load_run(kMission, kGnc, f.path());
  ASSERT_EQ(s.truth.faults.size(), 3u);
  EXPECT_EQ(s.truth.faults[0].thruster, 3);
  EXPECT_EQ(s.truth.faults[0].kind, plant::FaultKind::kStuckOn);
  EXPECT_EQ(s.truth.faults[0].onset_s, 60.0);
  EXPECT_EQ(s.truth.faults[1].kind, plant::FaultKind::kDegraded);
  EXPECT_EQ(s.truth.faults[1].factor, 0.5);
  EXPECT_EQ(s.truth.faults[2].kind, plant::FaultKind::kStuckOff);
  EXPECT_EQ(s.truth.faults[2].onset_s, 0.0);
  EXPECT_EQ(s.truth.command_timeout_s, 1.5);
  // The flight software's loader accepts the file and its parameters are those of the plain case.
  const gnc::GncParams with = load_flight_params(kMission, kGnc, f.path());
  const gnc::GncParams without = load_flight_params(kMission, kGnc, case_file(5));
  EXPECT_EQ(with.rcs.u_max, without.rcs.u_max);
  EXPECT_EQ(with.mass_hat.j_ast, without.mass_hat.j_ast);
  EXPECT_EQ(with.estimator.kind, without.estimator.kind);
}

TEST(CaseFaults, BadEntriesNameFileKeyAndReason) {
  const std::string base = read(case_file(1));
  struct Bad {
    std::string yaml, key, reason;
  };
  const Bad bad[] = {
      {"faults: {thruster: 3}\n", "faults", "list of faults"},
      {"faults: [3]\n", "faults[0]", "mapping"},
      {"faults:\n  - {thruster: 16, kind: stuck_on}\n", "faults[0].thruster", "[0, 15]"},
      {"faults:\n  - {thruster: 2.5, kind: stuck_on}\n", "faults[0].thruster", "integer"},
      {"faults:\n  - {kind: stuck_on}\n", "faults[0].thruster", "missing required key"},
      {"faults:\n  - {thruster: 1, kind: stuck}\n", "faults[0].kind", "stuck_off, stuck_on or degraded"},
      {"faults:\n  - {thruster: 1, kind: degraded}\n", "faults[0].factor", "missing required key"},
      {"faults:\n  - {thruster: 1, kind: degraded, factor: 1.0}\n", "faults[0].factor", "(0, 1)"},
      {"faults:\n  - {thruster: 1, kind: stuck_on, factor: 0.5}\n", "faults[0].factor", "only a degraded"},
      {"faults:\n  - {thruster: 1, kind: stuck_on, onset_s: -2}\n", "faults[0].onset_s", "negative"},
      {"faults:\n  - {thruster: 1, kind: stuck_on, onsett: 2}\n", "faults[0].onsett", "unknown key"},
      {"faults:\n  - {thruster: 1, kind: stuck_on}\n  - {thruster: 1, kind: stuck_off}\n",
       "faults[1].thruster", "already has a fault"},
      {"valve_driver_timeout_s: -1\n", "valve_driver_timeout_s", "negative"},
  };
  for (const Bad& b : bad) {
    TempFile f("case.yaml", base + b.yaml);
    expect_error([&] { load_run(kMission, kGnc, f.path()); }, f.path(), b.key, b.reason);
  }
}

}  // namespace
}  // namespace rocksteady::config
