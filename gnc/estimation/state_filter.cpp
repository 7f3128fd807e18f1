#include "gnc/estimation/state_filter.hpp"

#include <cmath>

#include <Eigen/LU>

#include "gnc/math/rotation.hpp"

namespace rocksteady::gnc {

void StateFilter::configure(const EstimatorParams& p, const Mat3& j_hat, double dt) {
  p_ = p;
  j_hat_ = j_hat;
  j_hat_inv_ = j_hat.inverse();
  dt_ = dt;
  gain_ = 1.0 - std::exp(-p.omega_c * dt);  // SPEC §6, step 3
}

void StateFilter::predict(Vec3& q, Vec3& omega, const Vec3& torque) const {
  // Eq. (2) with J_hat, no disturbance; Eq. (4) kinematics; RK4 with predict_substeps steps.
  const int n = p_.predict_substeps > 0 ? p_.predict_substeps : 1;
  const double h = dt_ / n;
  auto w_dot = [&](const Vec3& w) -> Vec3 { return j_hat_inv_ * ((j_hat_ * w).cross(w) + torque); };
  for (int i = 0; i < n; ++i) {
    const Vec3 k1w = w_dot(omega);
    const Vec3 k1q = mrp::rate(q, omega);
    const Vec3 w2 = omega + 0.5 * h * k1w, q2 = q + 0.5 * h * k1q;
    const Vec3 k2w = w_dot(w2);
    const Vec3 k2q = mrp::rate(q2, w2);
    const Vec3 w3 = omega + 0.5 * h * k2w, q3 = q + 0.5 * h * k2q;
    const Vec3 k3w = w_dot(w3);
    const Vec3 k3q = mrp::rate(q3, w3);
    const Vec3 w4 = omega + h * k3w, q4 = q + h * k3q;
    const Vec3 k4w = w_dot(w4);
    const Vec3 k4q = mrp::rate(q4, w4);
    omega += (h / 6.0) * (k1w + 2.0 * k2w + 2.0 * k3w + k4w);
    q = mrp::normalize(q + (h / 6.0) * (k1q + 2.0 * k2q + 2.0 * k3q + k4q));
  }
}

void StateFilter::update(const Measurement& m, const Vec3& torque) {
  if (!initialised_) {
    if (m.omega_valid && m.q_valid) {
      omega_ = m.omega;
      q_ = mrp::normalize(m.q);
      initialised_ = true;
    }
    return;
  }
  if (p_.kind == EstimatorKind::kPassThrough) {
    // Perfect sensors: the estimate is the measurement; a missing one is carried by the model.
    Vec3 q_pred = q_;
    Vec3 w_pred = omega_;
    if (!(m.omega_valid && m.q_valid)) predict(q_pred, w_pred, torque);
    omega_ = m.omega_valid ? m.omega : w_pred;
    q_ = m.q_valid ? mrp::normalize(m.q) : q_pred;
    return;
  }
  // SPEC §6: 1. predict; 2. innovation (same MRP set); 3. estimate = prediction + K e.
  Vec3 q_pred = q_;
  Vec3 w_pred = omega_;
  predict(q_pred, w_pred, torque);
  if (m.omega_valid) {
    w_pred += gain_ * (m.omega - w_pred);
  }
  if (m.q_valid) {
    const Vec3 q_meas = mrp::nearest_set(m.q, q_pred);  // same set as the prediction
    q_pred += gain_ * (q_meas - q_pred);
  }
  omega_ = w_pred;
  q_ = mrp::normalize(q_pred);
}

}  // namespace rocksteady::gnc
