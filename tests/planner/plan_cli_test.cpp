// rocksteady-plan as a user runs it: from a directory without configs, `--case N` finds the
// configuration next to the program; a missing case, a bad $ROCKSTEADY_CONFIG_DIR and a bad option
// are usage/configuration errors (exit 2) whose message names what the user typed; --help states
// the exit convention.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace {

namespace fs = std::filesystem;

struct Outcome {
  int code{-1};
  std::string out, err;
};

class PlanCli : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string tmpl = (fs::temp_directory_path() / "rs-plan-cli-XXXXXX").string();
    ASSERT_NE(mkdtemp(tmpl.data()), nullptr);
    dir_ = tmpl;
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  Outcome plan(const std::string& args, const std::string& env = "") {
    const std::string out = (dir_ / "out.txt").string();
    const std::string err = (dir_ / "err.txt").string();
    const std::string cmd = "cd '" + dir_.string() + "' && env -u ROCKSTEADY_CONFIG_DIR " + env +
                            " '" + ROCKSTEADY_PLAN_EXE + "' " + args + " >'" + out + "' 2>'" + err +
                            "'";
    const int status = std::system(cmd.c_str());
    Outcome r;
    r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    r.out = read(out);
    r.err = read(err);
    return r;
  }
  static std::string read(const std::string& p) {
    std::ifstream in(p);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
  }
  fs::path dir_;
};

TEST_F(PlanCli, CaseNumberFindsTheConfigsFromAnyDirectory) {
  ASSERT_FALSE(fs::exists(dir_ / "configs"));
  const Outcome r = plan("--case 1 --nodes 51 --no-refinement -o plan.yaml");
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(fs::exists(dir_ / "plan.yaml"));
  EXPECT_NE(read((dir_ / "plan.yaml").string()).find("case1"), std::string::npos);
}

TEST_F(PlanCli, AMissingCaseIsAConfigurationErrorNamingTheOption) {
  const Outcome r = plan("--case 9 -o plan.yaml");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--case 9: no case file"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("(cases here: 1..7)"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "plan.yaml"));
}

TEST_F(PlanCli, ABadConfigDirIsNamed) {
  const Outcome r = plan("--case 1 -o plan.yaml", "ROCKSTEADY_CONFIG_DIR=/no/such/dir");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("ROCKSTEADY_CONFIG_DIR=/no/such/dir"), std::string::npos) << r.err;
  const Outcome d = plan("--case 1 --config-dir /no/such/dir -o plan.yaml");
  EXPECT_EQ(d.code, 2);
  EXPECT_NE(d.err.find("--config-dir /no/such/dir"), std::string::npos) << d.err;
}

TEST_F(PlanCli, UsageErrorsExitTwoAndHelpStatesTheConvention) {
  const Outcome bad = plan("--nodes 2 -o plan.yaml");
  EXPECT_EQ(bad.code, 2);
  EXPECT_NE(bad.err.find("--nodes"), std::string::npos) << bad.err;
  EXPECT_EQ(plan("--no-such-option").code, 2);
  const Outcome help = plan("--help");
  EXPECT_EQ(help.code, 0);
  EXPECT_NE(help.out.find("Exit status: 0 planned"), std::string::npos) << help.out;
  EXPECT_NE(help.out.find("2 usage or configuration error"), std::string::npos) << help.out;
}

}  // namespace

namespace {

TEST_F(PlanCli, StudyHorizonAndAnExplicitFinalTimeTogetherAreAUsageError) {
  const Outcome r = plan("--study-horizon --t-final-max 2000 -o x.yaml");
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("--study-horizon and --t-final-max"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "x.yaml"));
}

}  // namespace
