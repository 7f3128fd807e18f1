// The study-horizon option: "<law>+fuel_optimal_study" asks the trajectory source for a plan with the
// study's final time, planned once per case next to (not instead of) the default-horizon plan.
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "ground/campaign/campaign.hpp"
#include "ground/campaign/strategy.hpp"
#include "ground/campaign/trajectory_source.hpp"

namespace rocksteady::campaign {
namespace {

const std::string kConfigs = std::string(ROCKSTEADY_SOURCE_DIR) + "/configs";

// Answers "no reference" and records what it was asked.
class RecordingSource final : public TrajectorySource {
 public:
  PlanOutcome plan(const PlanRequest& r) override {
    requests.push_back(r.study_horizon);
    return {nullptr, r.study_horizon ? "asked: study horizon" : "asked: default horizon", 0.0};
  }
  std::string name() const override { return "recording"; }
  std::vector<bool> requests;
};

TEST(StudyHorizon, StrategyNameSelectsTheStudyHorizonPlan) {
  const auto s = parse_strategy("ntcl+fuel_optimal_study");
  ASSERT_TRUE(s.has_value());
  EXPECT_TRUE(s->needs_trajectory());
  EXPECT_EQ(s->horizon, PlanHorizon::kStudy);
  EXPECT_EQ(s->law, gnc::LawId::kNtcl);
  EXPECT_EQ(parse_strategy("ntcl+fuel_optimal")->horizon, PlanHorizon::kDefault);
  EXPECT_FALSE(parse_strategy("ntcl+fuel_optimal_studyx").has_value());
}

TEST(StudyHorizon, CampaignPlansEachHorizonOncePerCaseAndGivesEachStrategyItsOwn) {
  CampaignSpec spec;
  spec.mission_file = kConfigs + "/mission.yaml";
  spec.gnc_file = kConfigs + "/gnc.yaml";
  spec.case_files = {kConfigs + "/cases/case1.yaml"};
  spec.strategies = {*parse_strategy("ntcl+fuel_optimal"), *parse_strategy("el+fuel_optimal_study"),
                     *parse_strategy("ntcl+fuel_optimal_study"), *parse_strategy("dpd")};
  spec.out_dir = ::testing::TempDir() + "/study_horizon";
  spec.duration_s = 50.0;
  spec.write_plots = false;
  spec.write_timeseries = false;
  spec.progress = ProgressMode::kOff;
  RecordingSource source;
  std::ostringstream log;
  const CampaignReport rep = run_campaign(spec, source, log);
  EXPECT_EQ(source.requests, (std::vector<bool>{false, true}));  // one plan per horizon
  ASSERT_EQ(rep.results.size(), 4u);
  EXPECT_NE(rep.results[0].note.find("default horizon"), std::string::npos) << rep.results[0].note;
  EXPECT_NE(rep.results[1].note.find("study horizon"), std::string::npos) << rep.results[1].note;
  EXPECT_NE(rep.results[2].note.find("study horizon"), std::string::npos) << rep.results[2].note;
  EXPECT_EQ(rep.results[3].note.find("horizon"), std::string::npos) << rep.results[3].note;
}

}  // namespace
}  // namespace rocksteady::campaign
