#include "ground/planner/cache.hpp"

#include <cstdio>
#include <filesystem>
#include <stdexcept>

namespace rocksteady::ground::planner {

std::string cache_path(const PlanProblem& problem, const std::string& dir) {
  std::string name;
  for (const char c : problem.case_name) {
    const bool keep = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                      c == '_' || c == '-';
    name += keep ? c : '_';
  }
  if (name.empty()) name = "plan";
  char hash[20];
  std::snprintf(hash, sizeof hash, "%016llx",
                static_cast<unsigned long long>(problem_hash(problem)));
  return (std::filesystem::path(dir) / (name + "-" + hash + ".yaml")).string();
}

CachedPlan plan_cached(const PlanProblem& problem, const std::string& dir) {
  CachedPlan c;
  c.path = cache_path(problem, dir);
  std::error_code ec;
  if (std::filesystem::exists(c.path, ec)) {
    LoadResult loaded = load_trajectory_file(c.path, problem.model);
    if (loaded.ok && loaded.file.problem_hash == problem_hash(problem)) {
      c.ok = true;
      c.from_cache = true;
      c.file = std::move(loaded.file);
      return c;
    }
    c.note = loaded.ok ? c.path + ": problem hash differs; re-planned"
                       : "not reused (" + loaded.error + "); re-planned";
  }
  const PlanResult result = plan(problem);
  if (!result.ok) {
    c.error = problem.case_name + ": " + result.error;
    return c;
  }
  try {
    std::filesystem::create_directories(dir);
    write_trajectory_file(c.path, problem, result);
  } catch (const std::exception& e) {
    c.error = e.what();
    return c;
  }
  LoadResult written = load_trajectory_file(c.path, problem.model);  // what the flight side gets
  if (!written.ok) {
    c.error = "written file does not load back: " + written.error;
    return c;
  }
  c.ok = true;
  c.file = std::move(written.file);
  return c;
}

}  // namespace rocksteady::ground::planner
