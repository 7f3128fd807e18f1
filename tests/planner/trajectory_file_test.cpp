// The trajectory file: round trip, and rejection (with a reason) of tampered or malformed files.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "ground/planner/trajectory_file.hpp"

namespace rocksteady::ground::planner {
namespace {

// A real case-1 plan on a coarse grid (no refinement check) keeps these tests fast.
class TrajectoryFileTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    problem_ = new PlanProblem();
    problem_->case_name = "file-test";
    problem_->model = study_case_model(200.0, 0.0, 0.0);
    problem_->settings.nodes = 51;
    problem_->settings.verify_refinement = false;
    result_ = new PlanResult(plan(*problem_));
  }
  static void TearDownTestSuite() {
    delete problem_;
    delete result_;
  }
  void SetUp() override { ASSERT_TRUE(result_->ok) << result_->error; }

  static std::string text() { return format_trajectory_file(*problem_, *result_); }
  // Replaces the checksum line with the CRC of the (edited) body: an edit that "fixes" the CRC.
  static std::string with_fresh_crc(const std::string& edited) {
    const std::size_t line = edited.rfind("\nchecksum: ") + 1;
    const std::string body = edited.substr(0, line);
    char crc[32];
    std::snprintf(crc, sizeof crc, "checksum: \"0x%08x\"\n", crc32(body));
    return body + crc;
  }
  static std::string replace_once(std::string s, const std::string& from, const std::string& to) {
    const std::size_t at = s.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    if (at != std::string::npos) s.replace(at, from.size(), to);
    return s;
  }
  static LoadResult parse(const std::string& t) {
    return parse_trajectory_file(t, "plan.yaml", problem_->model);
  }
  static void expect_rejected(const std::string& t, const std::string& reason) {
    const LoadResult r = parse(t);
    EXPECT_FALSE(r.ok);
    EXPECT_EQ(r.error.rfind("plan.yaml: ", 0), 0u) << r.error;
    EXPECT_NE(r.error.find(reason), std::string::npos) << r.error;
  }

  static PlanProblem* problem_;
  static PlanResult* result_;
};
PlanProblem* TrajectoryFileTest::problem_ = nullptr;
PlanResult* TrajectoryFileTest::result_ = nullptr;

TEST_F(TrajectoryFileTest, RoundTripIsExact) {
  const std::filesystem::path path = std::filesystem::path(::testing::TempDir()) / "round_trip.yaml";
  write_trajectory_file(path.string(), *problem_, *result_);
  const LoadResult r = load_trajectory_file(path.string(), problem_->model);
  ASSERT_TRUE(r.ok) << r.error;
  const TrajectoryFile& f = r.file;
  EXPECT_EQ(f.case_name, "file-test");
  EXPECT_EQ(f.version, kTrajectoryFileVersion);
  EXPECT_EQ(f.model.j_hat, problem_->model.j_hat);
  EXPECT_EQ(f.model.b_hat, problem_->model.b_hat);
  EXPECT_EQ(f.model.omega_init, problem_->model.omega_init);
  EXPECT_EQ(f.settings.nodes, 51);
  EXPECT_EQ(f.settings.refinement_check, problem_->settings.refinement_check);
  EXPECT_EQ(f.problem_hash, problem_hash(*problem_));
  EXPECT_EQ(f.fuel_kg, result_->fuel_kg);
  EXPECT_EQ(f.t_final, result_->t_final);
  EXPECT_EQ(f.iterations, result_->iterations);
  ASSERT_EQ(f.samples.size(), result_->samples.size());
  for (std::size_t i = 0; i < f.samples.size(); ++i) {
    EXPECT_EQ(f.samples[i].t, result_->samples[i].t);
    EXPECT_EQ(f.samples[i].omega_d, result_->samples[i].omega_d);
    EXPECT_EQ(f.samples[i].omega_d_dot, result_->samples[i].omega_d_dot);
    EXPECT_EQ(f.samples[i].u_d, result_->samples[i].u_d);
  }
  const gnc::TrajectoryTable table = f.to_table();
  EXPECT_EQ(table.checksum, to_table(result_->samples).checksum);
  EXPECT_EQ(table.checksum, gnc::trajectory_checksum(table));
  EXPECT_EQ(gnc::validate_trajectory(table, problem_->model.eps_trans), gnc::TrajectoryError::kOk);
}

TEST_F(TrajectoryFileTest, RefusesToWriteAFailedPlanAndLeavesNoFile) {
  PlanResult failed = *result_;
  failed.ok = false;
  failed.error = "IPOPT did not converge";
  const std::filesystem::path path = std::filesystem::path(::testing::TempDir()) / "failed.yaml";
  std::filesystem::remove(path);
  EXPECT_THROW(write_trajectory_file(path.string(), *problem_, failed), std::runtime_error);
  EXPECT_FALSE(std::filesystem::exists(path));
}

TEST_F(TrajectoryFileTest, RejectsAnyEditWithoutAMatchingChecksum) {
  const std::string t = text();
  const std::size_t at = t.find("  - [");
  std::string edited = t;
  edited[at + 10] = edited[at + 10] == '1' ? '2' : '1';  // one digit of a sample
  expect_rejected(edited, "checksum mismatch");
  expect_rejected(replace_once(t, "fuel_kg: ", "fuel_kg: 1"), "checksum mismatch");
}

TEST_F(TrajectoryFileTest, RejectsEditedSamplesEvenWithARecomputedChecksum) {
  // Change omega_d of the second sample; the content CRC is recomputed, the table checksum is not.
  const std::string t = text();
  const std::size_t second = t.find("  - [", t.find("  - [") + 1);
  const std::size_t comma = t.find(", ", second);
  std::string edited = t;
  edited.insert(comma + 2, "0.001+");  // not a number
  expect_rejected(with_fresh_crc(edited), "not a number");
  edited = t;
  edited.insert(comma + 2, "1");  // a different, still valid number
  expect_rejected(with_fresh_crc(edited), "table checksum mismatch");
}

TEST_F(TrajectoryFileTest, RejectsAPlanForAnotherModel) {
  const PlanModel other = study_case_model(200.0, 1e5, 0.01);  // case 2's estimate
  const LoadResult r = parse_trajectory_file(text(), "plan.yaml", other);
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.error.find("different model"), std::string::npos) << r.error;
  EXPECT_NE(r.error.find("j_hat"), std::string::npos) << r.error;
  PlanModel other_u = problem_->model;
  other_u.u_max = 1000.0;
  const LoadResult ru = parse_trajectory_file(text(), "plan.yaml", other_u);
  EXPECT_FALSE(ru.ok);
  EXPECT_NE(ru.error.find("u_max"), std::string::npos) << ru.error;
}

TEST_F(TrajectoryFileTest, RejectsMalformedFilesWithAReason) {
  const std::string t = text();
  expect_rejected(t.substr(0, t.size() / 2), "no checksum line");
  expect_rejected("", "no checksum line");
  expect_rejected(replace_once(t, "\nchecksum: \"0x", "\nchecksum: \"zz"), "malformed checksum");
  expect_rejected(with_fresh_crc(replace_once(t, "version: 1", "version: 7")), "unsupported version 7");
  expect_rejected(with_fresh_crc(replace_once(t, "format: rocksteady-trajectory", "format: other")),
                  "format");
  expect_rejected(with_fresh_crc(replace_once(t, "  u_max: ", "  u_maximum: ")), "model.u_max");
  expect_rejected(with_fresh_crc(replace_once(t, "model:", "model: [\n")), "malformed");
  expect_rejected(with_fresh_crc(replace_once(t, "refinement_check: coarsen", "refinement_check: half")),
                  "planner.refinement_check: \"half\" is not coarsen or bisect");
  // A sample row with a missing value.
  const std::size_t row = t.find("  - [");
  const std::size_t last_comma = t.rfind(", ", t.find('\n', row));
  std::string short_row = t;
  short_row.erase(last_comma, t.find(']', row) - last_comma);
  expect_rejected(with_fresh_crc(short_row), "list of 15 numbers");
  // One sample fewer than the grid has.
  std::string dropped = t;
  dropped.erase(row, t.find('\n', row) + 1 - row);
  expect_rejected(with_fresh_crc(dropped), "does not match");
}

// A file written before the coarsening check has no refinement_check key: its plan was checked by
// bisection, which it loads as, and the problem hash then tells it from a coarsening-checked plan.
TEST_F(TrajectoryFileTest, AFileWithoutTheGridCheckMethodLoadsAsBisected) {
  const std::string t = text();
  const std::size_t at = t.find("  refinement_check: coarsen\n");
  ASSERT_NE(at, std::string::npos);
  std::string older = t;
  older.erase(at, std::string("  refinement_check: coarsen\n").size());
  const LoadResult r = parse(with_fresh_crc(older));
  ASSERT_TRUE(r.ok) << r.error;
  EXPECT_EQ(r.file.settings.refinement_check, PlanSettings::RefinementCheck::kBisect);
  PlanProblem bisected = *problem_;
  bisected.settings.refinement_check = PlanSettings::RefinementCheck::kBisect;
  EXPECT_NE(problem_hash(bisected), problem_hash(*problem_));
}

TEST_F(TrajectoryFileTest, RejectsSamplesThatNoLongerSolveTheDynamics) {
  // A consistent forgery: every control scaled down, table and content checksums recomputed.
  // Only the re-verification against the model can notice.
  PlanResult forged = *result_;
  for (PlanSample& s : forged.samples) s.u_d *= 0.9;
  for (PlanSample& s : forged.samples) {
    const Vec3 h = problem_->model.j_hat * s.omega_d;
    s.omega_d_dot = problem_->model.j_hat.inverse() * (h.cross(s.omega_d) + problem_->model.b_hat * s.u_d);
  }
  expect_rejected(format_trajectory_file(*problem_, forged), "samples fail verification");
}

TEST(TrajectoryFile, MissingFileIsAnErrorNamingIt) {
  const LoadResult r = load_trajectory_file("no/such/plan.yaml", study_case_model(200.0, 0.0, 0.0));
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.error.find("no/such/plan.yaml"), std::string::npos);
  EXPECT_NE(r.error.find("cannot open"), std::string::npos);
}

TEST(TrajectoryFile, Crc32MatchesTheStandardCheckValue) {
  EXPECT_EQ(crc32("123456789"), 0xCBF43926u);  // CRC-32/ISO-HDLC check value
}

}  // namespace
}  // namespace rocksteady::ground::planner
