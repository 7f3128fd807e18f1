// The trajectory an operator uplinks: a planner trajectory file
// (ground/planner/trajectory_file.hpp), checked against the model the flight will fly with before
// any chunk is sent.
#pragma once

#include <string>

#include "ground/planner/trajectory_file.hpp"

namespace rocksteady::ground::cli {

// The model a trajectory file says it was planned for (its "model:" section), for
// `upload-trajectory --file-model`: the file's CRC and the re-verification of its samples still
// run, only the comparison with an independently known model is given up. Throws
// std::runtime_error.
planner::PlanModel file_model(const std::string& text, const std::string& name);

// Reads and checks the file (planner::parse_trajectory_file) against `model`.
planner::LoadResult load_trajectory(const std::string& path, const planner::PlanModel& model);
// Same, against the model recorded in the file itself.
planner::LoadResult load_trajectory_own_model(const std::string& path);

}  // namespace rocksteady::ground::cli
