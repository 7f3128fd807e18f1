// Plan-once cache: the campaign plans each case once and reuses the file while the problem (model
// and settings) is unchanged. The key is problem_hash(problem); the file name carries it.
#pragma once

#include <string>

#include "ground/planner/trajectory_file.hpp"

namespace rocksteady::ground::planner {

struct CachedPlan {
  bool ok{false};
  std::string error;     // why no plan is available (solver failure, I/O)
  bool from_cache{false};
  std::string path;      // the trajectory file
  std::string note;      // e.g. why an existing file was not reused
  TrajectoryFile file;   // the plan as stored (what the flight side gets)
};

// "<dir>/<case>-<16 hex digits of problem_hash>.yaml" (case name reduced to [A-Za-z0-9_-]).
std::string cache_path(const PlanProblem& problem, const std::string& dir);

// Returns the cached plan when a valid file for exactly this problem exists; otherwise plans, and
// writes the file only if the plan converged and verified.
CachedPlan plan_cached(const PlanProblem& problem, const std::string& dir);

}  // namespace rocksteady::ground::planner
