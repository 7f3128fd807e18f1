// The campaign's hook for "obtain a fuel-optimal trajectory for (case, model)" (SPEC Eq. 44).
// Without the planner the source answers "no reference", and the fuel_optimal runs report that
// instead of numbers.
#pragma once

#include <memory>
#include <optional>
#include <string>

#include "gnc/guidance/trajectory.hpp"
#include "gnc/params.hpp"
#include "ground/config/config.hpp"

namespace rocksteady::campaign {

struct PlanRequest {
  const config::RunSetup* setup{nullptr};  // the case
  gnc::GncParams model{};                   // the flight software's model: J_hat, B_hat, u_max
  gnc::Vec3 omega_init{gnc::Vec3::Zero()};  // the flight software's first rate measurement
  bool study_horizon{false};  // plan with the study's final time (ground/planner kStudyHorizon)
};

struct PlanOutcome {
  std::shared_ptr<const gnc::TrajectoryTable> table;  // null: no reference
  std::string note;                                   // why not, or a summary of the plan
  double wall_s{0.0};
};

class TrajectorySource {
 public:
  virtual ~TrajectorySource() = default;
  virtual PlanOutcome plan(const PlanRequest& request) = 0;
  virtual std::string name() const = 0;
};

// Always "no reference".
class NoTrajectorySource final : public TrajectorySource {
 public:
  PlanOutcome plan(const PlanRequest&) override {
    return {nullptr, "no reference: the fuel-optimal planner is not built into this campaign", 0.0};
  }
  std::string name() const override { return "none"; }
};

// The planner (ground/planner) when this build has it, else NoTrajectorySource. With a cache folder,
// each (model, case) is planned once and the verified trajectory file is reused.
std::unique_ptr<TrajectorySource> make_default_trajectory_source(const std::string& cache_dir = "");
bool have_planner();

}  // namespace rocksteady::campaign
