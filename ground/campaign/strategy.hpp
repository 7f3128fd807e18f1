// A strategy = a control law + a desired-trajectory choice, named as the study's results table:
// "<law>+fuel_optimal", "<law>+dpd_ref", and plain "dpd" (the D+PD law, Eqs. 49-50).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "gnc/params.hpp"

namespace rocksteady::campaign {

// kReplan: identify on the D+PD reference first, then plan from the current state with the
// identified model and TRACK, re-planning on a policy (ground/planner/replanner.hpp).
enum class ReferenceKind { kDpdRef, kFuelOptimal, kReplan };

// The fuel-optimal plan's final time: the planner's default (8x the shortest despin), or the study's
// (ground/planner kStudyHorizon, the option "study-horizon": reference name fuel_optimal_study).
enum class PlanHorizon { kDefault = 0, kStudy = 1 };
inline constexpr int kPlanHorizons = 2;

struct Strategy {
  std::string name;
  gnc::LawId law{gnc::LawId::kNtcl};
  ReferenceKind reference{ReferenceKind::kDpdRef};
  PlanHorizon horizon{PlanHorizon::kDefault};
  // Modifiers beyond the study (name suffixes): ":mekf" flies the MEKF instead of the case's
  // estimator; ":id" runs the on-line identification with automatic model adoption; ":idx" the
  // same with the identification excitation (gnc/estimation/README.md §I.6).
  bool mekf{false};
  bool identify{false};
  bool excite{false};
  bool fdi{false};  // ":fdi": thruster fault detection and isolation on
  // A plan before the run (uplinked before the first tick).
  bool needs_trajectory() const { return reference == ReferenceKind::kFuelOptimal; }
  // Plans made during the run by the re-planner, in simulated time.
  bool replans() const { return reference == ReferenceKind::kReplan; }
};

// Laws: ntcl, el, integral, adaptive, so3, feedforward; references: dpd_ref, fuel_optimal,
// fuel_optimal_study (the fuel-optimal plan with the study's horizon), replan (identification on
// the D+PD reference, then on-line fuel-optimal re-planning; implies ":id"); optional suffixes ":mekf",
// ":id" (or ":idx", with the identification excitation) and ":fdi" in any order
// ("ntcl+dpd_ref:mekf:id", "dpd:idx:fdi").
std::optional<Strategy> parse_strategy(const std::string& name);
// The six columns of the study's results table, in its order.
const std::vector<std::string>& study_strategy_names();
// The study's six plus the feed-forward comparison law with both references.
const std::vector<std::string>& all_strategy_names();

}  // namespace rocksteady::campaign
