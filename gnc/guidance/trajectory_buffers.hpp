// Two statically allocated trajectory tables (double buffer). TRACK follows the active one; a
// plan (a re-plan, or the next one) is validated and copied into the standby one while TRACK runs,
// and the two swap at a tick boundary (Gnc::step), never inside a tick: no copy, no heap.
//
// A staged plan is refused at the switch, and the active plan kept, when it is stale: no sample of
// it comes within the tolerance of the current rate estimate, so the reference could not be
// re-synchronised to the estimate (References::reset_track).
#pragma once

#include <array>

#include "gnc/guidance/trajectory.hpp"
#include "gnc/types.hpp"

namespace rocksteady::gnc {

enum class SwitchOutcome : std::uint8_t {
  kNone = 0,   // nothing staged
  kSwitched,   // the staged table is now the active one
  kRefusedStale,  // the staged table was discarded, the active one kept
};

class TrajectoryBuffers {
 public:
  // Validates (validate_trajectory) and copies `table` into the standby buffer. Not tracking (or
  // no table active yet): it becomes the active table at once. Tracking: it waits for the next tick
  // boundary (switch_at_boundary); a second load while one waits is refused with kBusyTracking.
  TrajectoryError load(const TrajectoryTable& table, double eps_trans, bool tracking);

  // At the tick boundary: make a staged table active if one of its samples is within
  // `stale_tolerance` (rad/s) of omega_hat; else discard it and keep the active one.
  SwitchOutcome switch_at_boundary(const Vec3& omega_hat, double stale_tolerance);

  bool valid() const { return valid_; }
  bool switch_pending() const { return pending_; }
  const TrajectoryTable& active() const { return tables_[active_]; }
  int active_index() const { return active_; }  // 0 or 1 (telemetry, tests)
  void clear();

 private:
  std::array<TrajectoryTable, 2> tables_{};
  int active_{0};
  bool valid_{false};
  bool pending_{false};
};

// [Rocksteady choice] a staged plan is stale when none of its samples comes within this fraction of
// |omega_hat| (floored at kStaleFloorRadS) of the estimate at the switch.
inline constexpr double kStaleFraction = 0.2;
inline constexpr double kStaleFloorRadS = 1e-3;
inline double stale_tolerance(const Vec3& omega_hat) {
  const double r = kStaleFraction * omega_hat.norm();
  return r > kStaleFloorRadS ? r : kStaleFloorRadS;
}

}  // namespace rocksteady::gnc
