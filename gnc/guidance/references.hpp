// Desired attitude trajectories (SPEC §3): the D+PD-based reference (Eq. 51) as the DETUMBLE and
// HOLD phases, the constant-attitude hold, and the fuel-optimal reference (Eqs. 45-48) for TRACK.
#pragma once

#include "gnc/guidance/trajectory.hpp"
#include "gnc/io.hpp"
#include "gnc/math/rotation.hpp"
#include "gnc/types.hpp"

namespace rocksteady::gnc {

struct GuidanceParams {
  double omega_switch{5e-4};  // rad/s: D+PD-based switch (51), fuel-optimal augmentation (46)-(48)
  double k_qd{1e-4};          // 1/s, Eq. (46)-(48)
  Vec3 q_final{Vec3::Zero()};  // MRP, the commanded final attitude (ground can change it)
  // [Rocksteady choice] period of the TRACK reference reset from the current estimate; 0: only at
  // activation.
  double track_reset_period_s{0.0};
  // [Rocksteady choice] acquisition slew. 0: the study's Eqs. (46)-(48). > 0: once the plan is
  // over and |omega_hat| <= omega_switch, the TRACK reference turns from where it is to q_final
  // about the eigenaxis, rest to rest, in slew_s seconds: a trapezoidal rate with ramps of
  // slew_ramp_s (at most slew_s / 2). Eq. (47)'s exponential starts
  // at its highest rate, 4 k_qd |q_d - q_final| / (1 + |.|^2), and a rest-to-rest turn costs about
  // 2 J omega_peak of torque impulse, so the coast at the slowest rate that still arrives in
  // slew_s costs the least. No augmentation (46)-(48) while the plan runs.
  double slew_s{0.0};
  double slew_ramp_s{1000.0};
  // [Rocksteady choice] momentum tracking (gnc/control/laws.hpp momentum_torque). 0: the law
  // tracks the plan's rates (Eq. 45). > 0: while the plan runs, TRACK flies the plan's inertial
  // angular momentum h_d = R_d J_hat omega_d instead, with this feedback gain (1/s): the plan's
  // torque turned into the body frame plus k (h_d - R J_hat omega_hat), no gyroscopic term.
  double track_momentum_k{0.0};
  double eps_trans{0.5 * 2.0 * 3.14159265358979323846 / 60.0};  // 0.5 rpm in rad/s (SPEC §5)
};

struct ReferenceSample {
  ReferencePhase phase{ReferencePhase::kNone};
  // q_d, qdot_d, qddot_d (MRP), expressed in the set of the current estimate.
  mrp::WithRates q{Vec3::Zero(), Vec3::Zero(), Vec3::Zero()};
  // kTrack: the plan's omega_d and omega_d_dot at this tick (body frame of q_d).
  Vec3 plan_omega{Vec3::Zero()};
  Vec3 plan_omega_dot{Vec3::Zero()};
  bool rate_only() const { return phase == ReferencePhase::kDamping; }
};

class References {
 public:
  void configure(const GuidanceParams& g, double dt);
  void set_target(const Vec3& q_final) { q_final_ = mrp::normalize(q_final); }
  const Vec3& target() const { return q_final_; }

  // Restart the TRACK reference from the current estimate: q_d <- q_hat and the plan's clock
  // re-synchronised to the sample whose omega_d is nearest omega_hat.
  void reset_track(double t, const Vec3& q_hat, const Vec3& omega_hat, const TrajectoryTable& traj);

  // One tick. `entered` is true on the first tick spent in the current mode.
  ReferenceSample update(Mode mode, bool entered, double t, const Vec3& q_hat,
                         const Vec3& omega_hat, const TrajectoryTable& traj);

  double plan_time(double t) const { return t - t0_; }
  bool augmented() const { return augmented_; }
  bool slewing() const { return slewing_; }
  // The acquisition slew's eigenaxis (the reference frame at the slew's start), angle (rad) and
  // coast rate (rad/s); zero before a slew starts.
  const Vec3& slew_axis() const { return slew_axis_; }
  double slew_angle() const { return slew_angle_; }
  double slew_rate() const { return slew_rate_; }

 private:
  Vec3 track_rate(const TrajectoryTable& traj, double t, const Vec3& q_d) const;
  bool plan_over(const TrajectoryTable& traj, double t) const;
  void start_slew(double t);
  mrp::WithRates slew_reference(double t) const;

  GuidanceParams g_{};
  double dt_{0.1};
  Vec3 q_final_{Vec3::Zero()};
  // TRACK state
  Vec3 q_d_{Vec3::Zero()};
  double t0_{0.0};          // wall time that corresponds to plan time 0
  double t_prev_{0.0};
  double t_last_reset_{0.0};
  bool augmented_{false};
  // Acquisition slew state (slew_s > 0)
  bool slewing_{false};
  double slew_t0_{0.0};
  double slew_duration_{0.0};
  double slew_ramp_{0.0};
  Vec3 slew_q0_{Vec3::Zero()};
  Vec3 slew_axis_{Vec3::Zero()};
  double slew_angle_{0.0};
  double slew_rate_{0.0};
};

}  // namespace rocksteady::gnc
