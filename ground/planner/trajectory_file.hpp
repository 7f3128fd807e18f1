// The reference-trajectory file: a plan as human-readable YAML, with the model and case it was planned
// for, the planner settings and results, the samples (t, omega_d, omega_d_dot, u_d), and a CRC-32 of
// the content. Loading checks the checksum, the format, the model it was planned for (against the
// model the caller expects), and re-verifies the samples; any failure is an error naming the file and
// the reason, never a table.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "ground/planner/planner.hpp"

namespace rocksteady::ground::planner {

inline constexpr int kTrajectoryFileVersion = 1;

struct TrajectoryFile {
  int version{kTrajectoryFileVersion};
  std::string case_name;
  PlanModel model;
  PlanSettings settings;
  std::uint64_t problem_hash{0};
  double fuel_kg{0.0};
  double cost_ns{0.0};
  double t_final{0.0};
  int iterations{0};
  double solve_seconds{0.0};
  std::vector<PlanSample> samples;

  // The flight-side table (t, omega_d, omega_d_dot, checksum).
  gnc::TrajectoryTable to_table() const;
};

// CRC-32 (IEEE 802.3, reflected, as zlib) of a byte string.
std::uint32_t crc32(const std::string& bytes);

// Writes the plan. Refuses (std::runtime_error, no file written) a result that is not ok, and
// writes through a temporary file so a reader never sees half a file.
void write_trajectory_file(const std::string& path, const PlanProblem& problem,
                           const PlanResult& result);
// The text that write_trajectory_file writes (exposed for tests).
std::string format_trajectory_file(const PlanProblem& problem, const PlanResult& result);

struct LoadResult {
  bool ok{false};
  std::string error;  // "<path>: <reason>" when !ok
  TrajectoryFile file;
};

// Loads and checks a file against the model the caller will fly with.
LoadResult load_trajectory_file(const std::string& path, const PlanModel& expected_model);
// Same, from text already in memory (`name` is used in error messages).
LoadResult parse_trajectory_file(const std::string& text, const std::string& name,
                                 const PlanModel& expected_model);

}  // namespace rocksteady::ground::planner
