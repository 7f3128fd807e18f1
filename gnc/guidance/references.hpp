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
  double eps_trans{0.5 * 2.0 * 3.14159265358979323846 / 60.0};  // 0.5 rpm in rad/s (SPEC §5)
};

struct ReferenceSample {
  ReferencePhase phase{ReferencePhase::kNone};
  // q_d, qdot_d, qddot_d (MRP), expressed in the set of the current estimate.
  mrp::WithRates q{Vec3::Zero(), Vec3::Zero(), Vec3::Zero()};
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

 private:
  Vec3 track_rate(const TrajectoryTable& traj, double t, const Vec3& q_d) const;

  GuidanceParams g_{};
  double dt_{0.1};
  Vec3 q_final_{Vec3::Zero()};
  // TRACK state
  Vec3 q_d_{Vec3::Zero()};
  double t0_{0.0};          // wall time that corresponds to plan time 0
  double t_prev_{0.0};
  double t_last_reset_{0.0};
  bool augmented_{false};
};

}  // namespace rocksteady::gnc
