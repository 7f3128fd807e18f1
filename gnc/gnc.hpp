// The GNC component: one call per tick, estimator -> mode manager -> reference -> law -> allocator.
// Static allocation, no exceptions, no I/O: inputs and outputs are plain structs.
#pragma once

#include <cstdint>

#include "gnc/allocation/allocator.hpp"
#include "gnc/control/laws.hpp"
#include "gnc/estimation/state_filter.hpp"
#include "gnc/guidance/references.hpp"
#include "gnc/guidance/trajectory.hpp"
#include "gnc/guidance/trajectory_buffers.hpp"
#include "gnc/io.hpp"  // SensorSample, GncCommands, GncOutput: what step() takes and gives
#include "gnc/mode/mode_manager.hpp"
#include "gnc/params.hpp"
#include "gnc/types.hpp"

namespace rocksteady::gnc {

class Gnc {
 public:
  // Validates and installs the parameters, resets all state. Not for use inside a tick.
  ParamCheck init(const GncParams& params);
  // Activate a validated parameter table at a tick boundary, keeping the estimate, mode and fuel.
  ParamCheck set_params(const GncParams& params);
  const GncParams& params() const { return params_; }

  // Would a request for `to` be accepted now? (the ground-command validator asks before acking)
  TransitionCheck check_mode_request(Mode to) const;
  // Load (copy) a validated trajectory for TRACK. While TRACK is active the table is staged in the
  // standby buffer and becomes active at the next tick boundary (event kTrajectorySwitched, the
  // reference re-synchronised to the estimate), or is refused there if stale (kTrajectoryStale);
  // a second load while one is staged is refused (kBusyTracking).
  TrajectoryError load_trajectory(const TrajectoryTable& table);
  const TrajectoryBuffers& trajectories() const { return trajectories_; }

  void step(const SensorSample& sample, const GncCommands& commands, GncOutput& out);

  Mode mode() const { return modes_.mode(); }
  const StateFilter& estimator() const { return filter_; }

 private:
  void configure_components();

  GncParams params_{};
  StateFilter filter_{};
  ModeManager modes_{};
  References refs_{};
  ControlLaws laws_{};
  Allocator alloc_{};
  TrajectoryBuffers trajectories_{};  // double buffer: active + standby (switch at a tick boundary)
  double fuel_kg_{0.0};
  std::uint32_t tick_{0};
  std::uint32_t sensor_rejects_{0};
  double last_good_t_{0.0};  // time of the last sample with both sensors valid
  bool have_time_{false};
  Vec3 last_torque_{Vec3::Zero()};  // torque achieved on the previous tick (estimator prediction)
  bool last_saturated_{false};
};

}  // namespace rocksteady::gnc
