#include "ground/campaign/trajectory_source.hpp"

#include <chrono>
#include <cstdio>
#include <exception>
#include <string>
#include <utility>

#ifdef ROCKSTEADY_HAVE_PLANNER
#include "ground/planner/cache.hpp"
#include "ground/planner/planner.hpp"
#endif

namespace rocksteady::campaign {

#ifdef ROCKSTEADY_HAVE_PLANNER
namespace {

// ground/planner's fuel-optimal solution of Eq. (44) for the flight software's model.
class PlannerSource final : public TrajectorySource {
 public:
  explicit PlannerSource(std::string cache_dir) : cache_dir_(std::move(cache_dir)) {}
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
    if (r.study_horizon) problem.settings.t_final_max = pl::kStudyHorizon;
    try {
      if (!cache_dir_.empty()) {
        // Plan once per model and case: the cache file is keyed by the problem's hash, and it is
        // re-validated (checksums, model) when reused.
        const pl::CachedPlan c = pl::plan_cached(problem, cache_dir_);
        if (!c.ok) {
          out.note = "no reference: planner failed: " + c.error;
        } else {
          out.table = std::make_shared<const gnc::TrajectoryTable>(c.file.to_table());
          char buf[200];
          std::snprintf(buf, sizeof buf, "plan%s: t_f %.0f s, planned fuel %.3f kg",
                        c.from_cache ? " (cached)" : "", c.file.t_final, c.file.fuel_kg);
          out.note = buf;
        }
        out.wall_s =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        return out;
      }
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

 private:
  std::string cache_dir_;
};

}  // namespace

std::unique_ptr<TrajectorySource> make_default_trajectory_source(const std::string& cache_dir) {
  return std::make_unique<PlannerSource>(cache_dir);
}
bool have_planner() { return true; }
#else
std::unique_ptr<TrajectorySource> make_default_trajectory_source(const std::string&) {
  return std::make_unique<NoTrajectorySource>();
}
bool have_planner() { return false; }
#endif

}  // namespace rocksteady::campaign
