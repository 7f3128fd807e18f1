// The estimation report of a run (runner.hpp EstimationReport) as JSON, for the campaign's
// results.json and the dispersion tool's per-draw files (written and read back).
#pragma once

#include <nlohmann/json.hpp>

#include "ground/campaign/runner.hpp"

namespace rocksteady::campaign {

nlohmann::json estimation_json(const EstimationReport& e);
nlohmann::json fdi_json(const FdiReport& f);
FdiReport fdi_from_json(const nlohmann::json& j);
// The re-planner's plans; `with_wall` adds each solve's wall time (not part of a reproducible
// result: the dispersion tool's draw files leave it out).
nlohmann::json replan_json(const ReplanReport& r, bool with_wall = true);
// Throws nlohmann::json::exception on a malformed object (the caller names the file).
ReplanReport replan_from_json(const nlohmann::json& j);
// Throws nlohmann::json::exception on a malformed object (the caller names the file).
EstimationReport estimation_from_json(const nlohmann::json& j);

// Chi-square 95 % upper bounds for the normalised errors of IdentificationMark (6 and 3 dof).
inline constexpr double kChi2Dof6P95 = 12.592;
inline constexpr double kChi2Dof3P95 = 7.815;
inline constexpr double kChi2Dof1P95 = 3.841;

}  // namespace rocksteady::campaign
