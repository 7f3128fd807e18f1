// The GNC component: one call per tick, estimator -> identifier -> mode manager -> reference ->
// law -> allocator (DESIGN.md "One tick as data").
// Static allocation, no exceptions, no I/O: inputs and outputs are plain structs.
#pragma once

#include <cstdint>

#include "gnc/allocation/allocator.hpp"
#include "gnc/control/laws.hpp"
#include "gnc/estimation/identifier.hpp"
#include "gnc/estimation/mekf.hpp"
#include "gnc/estimation/state_filter.hpp"
#include "gnc/fdi/fault_detector.hpp"
#include "gnc/guidance/references.hpp"
#include "gnc/guidance/trajectory.hpp"
#include "gnc/guidance/trajectory_buffers.hpp"
#include "gnc/io.hpp"  // SensorSample, GncCommands, GncOutput: what step() takes and gives
#include "gnc/mode/mode_manager.hpp"
#include "gnc/params.hpp"
#include "gnc/types.hpp"

namespace rocksteady::gnc {

struct IdentifiedModel {
  Mat3 j{Mat3::Identity()};  // J_tot, kg m^2
  Vec3 r{Vec3::Zero()};      // r_SO/BCM, m
  Vec16 k{Vec16::Ones()};    // thruster strengths
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
  // Load (copy) a validated trajectory for TRACK. While TRACK is active the table is staged in the
  // standby buffer and becomes active at the next tick boundary (event kTrajectorySwitched, the
  // reference re-synchronised to the estimate), or is refused there if stale (kTrajectoryStale);
  // a second load while one is staged is refused (kBusyTracking).
  TrajectoryError load_trajectory(const TrajectoryTable& table);
  const TrajectoryBuffers& trajectories() const { return trajectories_; }

  void step(const SensorSample& sample, const GncCommands& commands, GncOutput& out);

  // The identified model, if confident: J_tot, r_SO/BCM, and the strengths of the thrusters the
  // data have pinned (the table's for the others). kOk: it differs from the active table.
  ModelCandidate identified_model(IdentifiedModel& out) const;
  // The table that would fly the identified model now (the active table with J_tot, r_SO/BCM and
  // the confident thruster strengths replaced, validated). kOk writes `out`; otherwise why not.
  ModelCandidate model_candidate(GncParams& out) const;

  bool estimate_ready() const;  // the active estimator has a state
  Mode mode() const { return modes_.mode(); }
  const StateFilter& estimator() const { return filter_; }
  const Mekf& mekf() const { return mekf_; }
  const Identifier& identifier() const { return ident_; }
  const FaultDetector& fault_detector() const { return fdi_; }
  const std::array<bool, kPods>& valve_open() const { return valve_open_; }
  // The valves as commanded this tick: valve_open() with the detector's isolation test applied
  // (gnc/fdi/README.md (F9)).
  std::array<bool, kPods> commanded_valves() const;
  std::uint32_t model_adoptions() const { return adoptions_; }
  // The identification excitation (gnc/estimation/README.md §I.6) and what it did this tick.
  const IdentificationExcitation& excitation() const { return excite_; }
  const ExcitationStatus& excitation_status() const { return excite_status_; }
  // (gnc/fdi/README.md F19) The jet fired for the detector's jet check this tick (-1 none).
  int jet_check() const { return check_jet_; }

 private:
  // (F19) Adds the detector's jet check to the allocated forces u: the thruster's channel pushed
  // by the check force (on its half), the others moving so that B_hat's torque is unchanged.
  void apply_jet_check(const AllocatorLimits& lim, Vec8& u);
  void configure_components();
  bool excitation_on() const;  // identification and its excitation both enabled
  // Validate and install; declared_change: a table from outside (the identifier re-inflates).
  ParamCheck apply_params(const GncParams& params, bool declared_change);
  // Beyond the confidence bounds, or (adopt_sigmas > 0) beyond that many of the estimate's 1 sigma.
  bool differs(const GncParams& p, const IdentifiedModel& m) const;
  void adopt_model(double t, ModeEvents& events);  // automatic policy, at the tick boundary
  void fill_estimation_telemetry(GncTelemetry& tl) const;
  void refresh_fault_model();
  void release_fault_model();  // (F12) the detector takes the identifier's next model
  void apply_fault_overrides(const GncCommands& commands, ModeEvents& events);
  void detect_faults(const Vec3& omega, bool omega_valid, ModeEvents& events);
  AllocatorLimits allocation_limits() const;

  GncParams params_{};
  StateFilter filter_{};
  Mekf mekf_{};
  Identifier ident_{};
  IdentificationExcitation excite_{};
  ExcitationStatus excite_status_{};
  bool excite_quiet_{false};  // this tick neither latches a window nor carries a detector step
  FaultDetector fdi_{};
  std::array<bool, kPods> valve_open_{{true, true, true, true}};  // commanded this tick
  std::array<bool, kPods> last_valve_{{true, true, true, true}};  // over the previous tick
  bool isolation_inhibited_{false};
  int probe_pod_{-1};  // pod closed for the detector's isolation test this tick, -1 none
  int check_jet_{-1};    // (F19) thruster fired for a jet check this tick, -1 none
  int check_event_{-1};  // ... the one last reported by an event
  int check_move_jet_{-1};  // (F42) the check whose move check_move_ holds, -1 none
  bool check_move_ok_{false};      // ... whether that check has a move
  Vec8 check_move_{Vec8::Zero()};  // ... the move, unscaled, latched when the check starts
  bool reduced_reported_{false};
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
  Vec8 last_force_{Vec8::Zero()};
  Vec3 id_bias_{Vec3::Zero()};  // MEKF gyro bias latched for the identifier's current window  // physical channel forces commanded on the previous tick
  double last_adoption_t_{0.0};
  bool adopted_once_{false};
  std::uint32_t adoptions_{0};
  ModelCandidate candidate_status_{ModelCandidate::kDisabled};
  std::uint32_t candidate_windows_{0};
  bool fault_model_stale_{false};  // a window closed: refresh the detector's model
  // A fault was confirmed: the identifier is re-inflated on the next tick, before its update
  // (the confirmation tick carries the valve and the reallocation; the Cortex-M7 budget).
  bool reinflate_pending_{false};
  bool restart_after_confirmation_{false};  // (F12) the pending re-inflation restarts the identifier
  // (gnc/fdi/README.md (F12)) The model last given to the detector, and the one it keeps while
  // the identifier re-converges after its innovation gate re-inflated J, r and k (I18).
  FaultModel fault_model_given_{};
  bool fault_model_held_{false};
  std::uint32_t gate_reinflations_seen_{0};
  std::uint32_t fault_torque_scored_{0};  // (F14) identifier fault-torque scores passed on
  GncParams candidate_{};  // scratch for the automatic adoption (too large for a tick's stack)
};

}  // namespace rocksteady::gnc
