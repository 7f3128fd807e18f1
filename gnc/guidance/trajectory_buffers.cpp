#include "gnc/guidance/trajectory_buffers.hpp"

namespace rocksteady::gnc {

TrajectoryError TrajectoryBuffers::load(const TrajectoryTable& table, double eps_trans,
                                        bool tracking) {
  const TrajectoryError e = validate_trajectory(table, eps_trans);
  if (e != TrajectoryError::kOk) return e;
  if (tracking && valid_ && pending_) return TrajectoryError::kBusyTracking;
  const int standby = 1 - active_;
  tables_[standby] = table;
  if (tracking && valid_) {
    pending_ = true;  // swapped at the next tick boundary
  } else {
    active_ = standby;
    valid_ = true;
    pending_ = false;
  }
  return TrajectoryError::kOk;
}

SwitchOutcome TrajectoryBuffers::switch_at_boundary(const Vec3& omega_hat, double stale_tolerance) {
  if (!pending_) return SwitchOutcome::kNone;
  pending_ = false;
  const TrajectoryTable& staged = tables_[1 - active_];
  double nearest = -1.0;
  for (int i = 0; i < staged.count; ++i) {
    const double d = (staged.samples[i].omega_d - omega_hat).norm();
    if (nearest < 0.0 || d < nearest) nearest = d;
  }
  if (!(nearest >= 0.0 && nearest <= stale_tolerance)) return SwitchOutcome::kRefusedStale;
  active_ = 1 - active_;
  return SwitchOutcome::kSwitched;
}

void TrajectoryBuffers::clear() {
  valid_ = false;
  pending_ = false;
}

}  // namespace rocksteady::gnc
