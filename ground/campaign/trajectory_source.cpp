#include "ground/campaign/trajectory_source.hpp"

#include <chrono>
#include <cstdio>
#include <exception>

#ifdef ROCKSTEADY_HAVE_PLANNER
#include "ground/planner/planner.hpp"
#endif

namespace rocksteady::campaign {

#ifdef ROCKSTEADY_HAVE_PLANNER
namespace {

// ground/planner's fuel-optimal solution of Eq. (44) for the flight software's model.
class PlannerSource final : public TrajectorySource {
 public:
  PlanOutcome plan(const PlanRequest& r) override {
    const auto start = std::chrono::steady_clock::now();
    PlanOutcome out;
    namespace pl = ground::planner;
    pl::PlanProblem problem;
    problem.case_name = r.setup != nullptr ? r.setup->case_name : "custom";
    problem.model.j_hat = gnc::total_inertia(r.model.mass_hat);
    problem.model.b_hat = gnc::torque_matrix(r.model.rcs, r.model.mass_hat.r_so_bcm);
    problem.model.u_max = r.model.rcs.u_max;
    problem.model.eps_trans = r.model.guidance.eps_trans;
    problem.model.omega_init = r.omega_init;
    try {
      const pl::PlanResult res = pl::plan(problem);
      if (!res.ok) {
        out.note = "no reference: planner failed: " + res.error;
      } else {
        out.table = std::make_shared<const gnc::TrajectoryTable>(pl::to_table(res.samples));
        char buf[160];
        std::snprintf(buf, sizeof buf, "plan: %d nodes, t_f %.0f s, planned fuel %.3f kg",
                      res.nodes, res.t_final, res.fuel_kg);
        out.note = buf;
      }
    } catch (const std::exception& e) {
      out.note = std::string("no reference: planner error: ") + e.what();
    }
    out.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return out;
  }
  std::string name() const override { return "ground/planner (Eq. 44)"; }
};

}  // namespace

std::unique_ptr<TrajectorySource> make_default_trajectory_source() {
  return std::make_unique<PlannerSource>();
}
bool have_planner() { return true; }
#else
std::unique_ptr<TrajectorySource> make_default_trajectory_source() {
  return std::make_unique<NoTrajectorySource>();
}
bool have_planner() { return false; }
#endif

}  // namespace rocksteady::campaign
