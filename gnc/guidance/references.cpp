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
  slewing_ = false;  // a new plan (or a restart) flies its own despin first
  slew_angle_ = 0.0;
  slew_rate_ = 0.0;
  slew_axis_.setZero();
}

bool References::plan_over(const TrajectoryTable& traj, double t) const {
  return traj.count <= 0 || t - t0_ >= traj.samples[traj.count - 1].t;
}

// The rotation that takes the reference from q_d to q_final, in the reference frame at the start:
// R_final = R_0 Rot(e, theta), delta = beta_0* (x) beta_final (short way, theta <= pi). Along it,
// R_d(t) = R_0 Rot(e, theta(t)) gives R_d' = R_d S(e theta'), so omega_d = e theta' in the
// reference frame, a fixed axis.
void References::start_slew(double t) {
  slewing_ = true;
  slew_t0_ = t;
  slew_q0_ = q_d_;
  slew_duration_ = g_.slew_s;
  slew_ramp_ = std::fmin(g_.slew_ramp_s, 0.5 * g_.slew_s);
  const Vec4 delta = quat::error(mrp::to_quaternion(q_final_), mrp::to_quaternion(slew_q0_));
  const double s = delta.head<3>().norm();
  slew_angle_ = 2.0 * std::atan2(s, delta.w());
  slew_axis_ = s > 0.0 ? Vec3(delta.head<3>() / s) : Vec3::UnitX();
  // Trapezoid: ramps of slew_ramp_ at +-a, coast at w_c; area w_c (T - t_a) = theta.
  slew_rate_ = slew_angle_ / (slew_duration_ - slew_ramp_);
}

mrp::WithRates References::slew_reference(double t) const {
  const double tau = t - slew_t0_;
  const double T = slew_duration_;
  const double ta = slew_ramp_;
  const double wc = slew_rate_;
  const double a = wc / ta;
  double th = slew_angle_, th_dot = 0.0, th_ddot = 0.0;
  if (tau <= 0.0) {
    th = 0.0;
  } else if (tau < ta) {
    th = 0.5 * a * tau * tau;
    th_dot = a * tau;
    th_ddot = a;
  } else if (tau < T - ta) {
    th = 0.5 * wc * ta + wc * (tau - ta);
    th_dot = wc;
  } else if (tau < T) {
    const double left = T - tau;
    th = slew_angle_ - 0.5 * a * left * left;
    th_dot = a * left;
    th_ddot = -a;
  }
  mrp::WithRates r;
  r.q = mrp::normalize(mrp::compose(slew_q0_, slew_axis_ * std::tan(0.25 * th)));
  const Vec3 omega = slew_axis_ * th_dot;
  const Vec3 omega_dot = slew_axis_ * th_ddot;
  const Mat3 z = mrp::z_matrix(r.q);
  r.q_dot = z * omega;                                                // Eq. (45)
  r.q_ddot = mrp::z_dot(r.q, r.q_dot) * omega + z * omega_dot;        // Eq. (45)
  return r;
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

  const bool slew = g_.slew_s > 0.0;
  if (entered) {
    augmented_ = false;
    reset_track(t, q_hat, omega_hat, traj);
  } else if (slewing_) {
    // The slew is closed form from its start: nothing accumulates, nothing to reset.
    t_prev_ = t;
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
  // Momentum tracking lets the attitude go where the body takes it: the attitude phases after
  // the plan start from the estimate, not from the plan's q_d.
  const bool momentum = g_.track_momentum_k > 0.0;
  if (slew) {
    if (!slewing_ && plan_over(traj, t) && omega_hat.norm() <= g_.omega_switch) {
      if (momentum) q_d_ = q_hat;
      start_slew(t);
    }
    if (slewing_) {
      const mrp::WithRates r = slew_reference(t);
      q_d_ = r.q;
      s.phase = ReferencePhase::kTrackSlew;
      s.q = mrp::same_set_as(r, q_hat);
      return s;
    }
  } else if (!augmented_ && omega_hat.norm() <= g_.omega_switch) {
    augmented_ = true;  // latched until TRACK is re-entered
    if (momentum) q_d_ = q_hat;
  }

  const TrajectoryPoint p = interpolate(traj, t - t0_);
  const Mat3 z = mrp::z_matrix(q_d_);
  mrp::WithRates r;
  r.q = q_d_;
  if (!augmented_) {
    s.phase = ReferencePhase::kTrack;
    s.plan_omega = p.omega_d;
    s.plan_omega_dot = p.omega_d_dot;
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
