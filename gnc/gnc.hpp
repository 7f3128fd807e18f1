// The GNC component: one call per tick, estimator -> mode manager -> reference -> law -> allocator.
// Static allocation, no exceptions, no I/O: inputs and outputs are plain structs.
#pragma once

#include <array>
#include <cstdint>

#include "gnc/allocation/allocator.hpp"
#include "gnc/control/laws.hpp"
#include "gnc/estimation/state_filter.hpp"
#include "gnc/guidance/references.hpp"
#include "gnc/guidance/trajectory.hpp"
#include "gnc/mode/mode_manager.hpp"
#include "gnc/params.hpp"
#include "gnc/types.hpp"

namespace rocksteady::gnc {

// What the HAL delivers each tick, already rotated into the body frame.
struct SensorSample {
  double t{0.0};                    // s, sample time
  Vec3 gyro_rate{Vec3::Zero()};     // measured omega, rad/s, F_B
  bool gyro_valid{false};
  Vec4 star_quat{0, 0, 0, 1};       // measured attitude of F_B in F_I, [beta_v; beta4]
  bool star_valid{false};
};

// Requests from the ground (already validated and acknowledged by the flight application); applied
// at the start of the tick.
struct GncCommands {
  bool has_mode_request{false};
  Mode mode_request{Mode::kIdle};
  bool has_target{false};
  Vec3 target_mrp{Vec3::Zero()};
  bool has_law{false};
  LawId law{LawId::kNtcl};
};

struct ThrusterCommand {
  Vec8 force{Vec8::Zero()};  // signed channel forces, N, |u_i| <= u_max
  bool enabled{false};       // false: all thrusters inhibited (IDLE, SAFE)
};

struct GncTelemetry {
  double t{0.0};
  std::uint32_t tick{0};
  Mode mode{Mode::kIdle};
  LawId law{LawId::kNtcl};
  ReferencePhase phase{ReferencePhase::kNone};
  Vec3 omega_hat{Vec3::Zero()};
  Vec3 q_hat{Vec3::Zero()};
  Vec3 q_d{Vec3::Zero()};
  Vec3 omega_r{Vec3::Zero()};
  Vec3 attitude_error{Vec3::Zero()};  // q_hat - q_final (same MRP set)
  AllocatorStatus alloc{};
  double fuel_kg{0.0};                // on-board estimate, Eq. (54)
  std::uint32_t sensor_rejects{0};    // samples rejected (invalid or non-finite)
  bool trajectory_loaded{false};
  Vec6 a_hat{Vec6::Zero()};           // adaptive law's inertia estimate
  Vec3 integral{Vec3::Zero()};        // integral law's state
};

struct GncOutput {
  ThrusterCommand command{};
  GncTelemetry telemetry{};
  ModeEvents events{};  // transitions and faults raised during this tick
};

class Gnc {
 public:
  // Validates and installs the parameters, resets all state. Not for use inside a tick.
  ParamCheck init(const GncParams& params);
  // Activate a validated parameter table at a tick boundary, keeping the estimate, mode and fuel.
  ParamCheck set_params(const GncParams& params);
  const GncParams& params() const { return params_; }

  // Would a request for `to` be accepted now? (the ground-command validator asks before acking)
  TransitionCheck check_mode_request(Mode to) const;
  // Load (copy) a validated trajectory for TRACK. Rejected while TRACK is active.
  TrajectoryError load_trajectory(const TrajectoryTable& table);

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
  TrajectoryTable trajectory_{};
  bool trajectory_valid_{false};
  double fuel_kg_{0.0};
  std::uint32_t tick_{0};
  std::uint32_t sensor_rejects_{0};
  double last_good_t_{0.0};  // time of the last sample with both sensors valid
  bool have_time_{false};
  Vec3 last_torque_{Vec3::Zero()};  // torque achieved on the previous tick (estimator prediction)
  bool last_saturated_{false};
};

}  // namespace rocksteady::gnc
