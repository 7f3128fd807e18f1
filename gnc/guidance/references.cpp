#include "gnc/guidance/references.hpp"

#include <cmath>

namespace rocksteady::gnc {

void References::configure(const GuidanceParams& g, double dt) {
  g_ = g;
  dt_ = dt;
  q_final_ = mrp::normalize(g.q_final);
}

void References::reset_track(double t, const Vec3& q_hat, const Vec3& omega_hat,
                             const TrajectoryTable& traj) {
  q_d_ = q_hat;
  // Re-synchronise the plan clock: the sample with omega_d nearest the estimate.
  int best = 0;
  double best_d2 = (traj.samples[0].omega_d - omega_hat).squaredNorm();
  for (int i = 1; i < traj.count; ++i) {
    const double d2 = (traj.samples[i].omega_d - omega_hat).squaredNorm();
    if (d2 < best_d2) {
      best_d2 = d2;
      best = i;
    }
  }
  t0_ = t - (traj.count > 0 ? traj.samples[best].t : 0.0);
  t_prev_ = t;
  t_last_reset_ = t;
}

Vec3 References::track_rate(const TrajectoryTable& traj, double t, const Vec3& q_d) const {
  const Vec3 omega_d = interpolate(traj, t - t0_).omega_d;
  Vec3 q_dot = mrp::z_matrix(q_d) * omega_d;  // Eq. (45)
  if (augmented_) {
    q_dot -= g_.k_qd * (q_d - q_final_);  // Eq. (47)
  }
  return q_dot;
}

ReferenceSample References::update(Mode mode, bool entered, double t, const Vec3& q_hat,
                                   const Vec3& omega_hat, const TrajectoryTable& traj) {
  ReferenceSample s;
  switch (mode) {
    case Mode::kIdle:
    case Mode::kSafe:
      s.phase = ReferencePhase::kNone;
      s.q.q = q_hat;
      return s;
    case Mode::kDetumble:
      s.phase = ReferencePhase::kDamping;  // Eq. (51), phase 1
      s.q.q = q_hat;
      return s;
    case Mode::kHold:
      s.phase = ReferencePhase::kHold;  // Eq. (51), phase 2
      s.q = mrp::same_set_as({q_final_, Vec3::Zero(), Vec3::Zero()}, q_hat);
      return s;
    case Mode::kTrack:
      break;
  }

  if (entered) {
    augmented_ = false;
    reset_track(t, q_hat, omega_hat, traj);
  } else if (g_.track_reset_period_s > 0.0 && t - t_last_reset_ >= g_.track_reset_period_s) {
    reset_track(t, q_hat, omega_hat, traj);
  } else {
    // Propagate q_d from the previous tick to t (RK4 on Eq. 45 / 47).
    const double h = t - t_prev_;
    if (h > 0.0) {
      const Vec3 k1 = track_rate(traj, t_prev_, q_d_);
      const Vec3 k2 = track_rate(traj, t_prev_ + 0.5 * h, q_d_ + 0.5 * h * k1);
      const Vec3 k3 = track_rate(traj, t_prev_ + 0.5 * h, q_d_ + 0.5 * h * k2);
      const Vec3 k4 = track_rate(traj, t, q_d_ + h * k3);
      q_d_ = mrp::normalize(q_d_ + (h / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4));
    }
    t_prev_ = t;
  }
  if (!augmented_ && omega_hat.norm() <= g_.omega_switch) {
    augmented_ = true;  // latched until TRACK is re-entered
  }

  const TrajectoryPoint p = interpolate(traj, t - t0_);
  const Mat3 z = mrp::z_matrix(q_d_);
  mrp::WithRates r;
  r.q = q_d_;
  if (!augmented_) {
    s.phase = ReferencePhase::kTrack;
    r.q_dot = z * p.omega_d;                                              // Eq. (45)
    r.q_ddot = mrp::z_dot(q_d_, r.q_dot) * p.omega_d + z * p.omega_d_dot;  // Eq. (45)
  } else {
    s.phase = ReferencePhase::kTrackAugmented;
    r.q_dot = z * p.omega_d - g_.k_qd * (q_d_ - q_final_);                  // Eq. (47)
    r.q_ddot = mrp::z_dot(q_d_, r.q_dot) * p.omega_d + z * p.omega_d_dot -  // Eq. (48)
               g_.k_qd * r.q_dot;
  }
  s.q = mrp::same_set_as(r, q_hat);
  return s;
}

}  // namespace rocksteady::gnc
