// The trajectory files upload-trajectory reads: the model recorded in a file is read back exactly,
// a plan is refused against another model and accepted against its own.
#include <gtest/gtest.h>

#include "ground/cli/trajectory_input.hpp"
#include "ground/planner/planner.hpp"
#include "test_util.hpp"

namespace rocksteady::ground::cli {
namespace {

class TrajectoryInput : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    problem_ = new planner::PlanProblem();
    problem_->case_name = "cli-input";
    // A dispersed model (case-3-like), so a nominal model differs from it.
    problem_->model = planner::study_case_model(200.0, 4000.0, 0.05);
    problem_->settings.nodes = 51;
    problem_->settings.verify_refinement = false;
    result_ = new planner::PlanResult(planner::plan(*problem_));
  }
  static void TearDownTestSuite() {
    delete problem_;
    delete result_;
  }
  void SetUp() override {
    ASSERT_TRUE(result_->ok) << result_->error;
    path_ = dir_.file("plan.yaml");
    planner::write_trajectory_file(path_, *problem_, *result_);
  }

  static planner::PlanProblem* problem_;
  static planner::PlanResult* result_;
  test::TempDir dir_;
  std::string path_;
};
planner::PlanProblem* TrajectoryInput::problem_ = nullptr;
planner::PlanResult* TrajectoryInput::result_ = nullptr;

TEST_F(TrajectoryInput, FileModelIsTheModelThePlanWasMadeFor) {
  const planner::PlanModel m = file_model(test::read_file(path_), path_);
  const planner::PlanModel& e = problem_->model;
  EXPECT_EQ(m.j_hat, e.j_hat);
  EXPECT_EQ(m.b_hat, e.b_hat);
  EXPECT_EQ(m.u_max, e.u_max);
  EXPECT_EQ(m.eps_trans, e.eps_trans);
  EXPECT_EQ(m.omega_init, e.omega_init);
}

TEST_F(TrajectoryInput, PlanIsRefusedAgainstAnotherModelAndAcceptedAgainstItsOwn) {
  const planner::LoadResult nominal =
      load_trajectory(path_, planner::study_case_model(200.0, 0.0, 0.0));
  EXPECT_FALSE(nominal.ok);
  EXPECT_NE(nominal.error.find("planned for a different model"), std::string::npos)
      << nominal.error;

  const planner::LoadResult own = load_trajectory_own_model(path_);
  ASSERT_TRUE(own.ok) << own.error;
  EXPECT_EQ(own.file.samples.size(), result_->samples.size());
  const planner::LoadResult same = load_trajectory(path_, problem_->model);
  EXPECT_TRUE(same.ok) << same.error;
}

TEST_F(TrajectoryInput, FileWithoutAModelIsAnErrorNamingTheFile) {
  EXPECT_THROW(file_model("format: something\nsamples: []\n", "x.yaml"), std::runtime_error);
  try {
    file_model("model:\n  j_hat: [1, 2, 3]\n", "x.yaml");
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("x.yaml: model.j_hat has 3 numbers, 9 expected"),
              std::string::npos)
        << e.what();
  }
  const planner::LoadResult missing = load_trajectory_own_model(dir_.file("absent.yaml"));
  EXPECT_FALSE(missing.ok);
  EXPECT_NE(missing.error.find("absent.yaml"), std::string::npos) << missing.error;
}

}  // namespace
}  // namespace rocksteady::ground::cli
