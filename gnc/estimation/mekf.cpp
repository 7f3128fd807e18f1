#include "gnc/estimation/mekf.hpp"

#include <cmath>

#include <Eigen/LU>

#include "gnc/check.hpp"
#include "gnc/math/rotation.hpp"

namespace rocksteady::gnc {

namespace {


// Rotation increment of a body rate held over dt, as a quaternion (scalar last): exact for a
// constant rate, R(t + dt) = R(t) exp(S(omega) dt) (Eq. 5).
Vec4 rotation_increment(const Vec3& omega, double dt) {
  const double w = omega.norm();
  const double half = 0.5 * w * dt;
  // sin(half)/w with its series below 1e-4 rad (error < 1e-17 relative).
  const double s = half < 1e-4 ? 0.5 * dt * (1.0 - half * half / 6.0) : std::sin(half) / w;
  return Vec4(s * omega.x(), s * omega.y(), s * omega.z(), std::cos(half));
}

}  // namespace

MekfConfigCheck validate(const MekfConfig& c) {
  auto bad = [](const char* field, const char* reason) {
    return MekfConfigCheck{false, field, reason};
  };
  if (!finite_positive(c.dt)) return bad("dt", "must be positive and finite");
  if (!finite_non_negative(c.gyro_arw)) return bad("gyro_arw", "must be >= 0 and finite");
  if (!finite_non_negative(c.gyro_bias_rw)) return bad("gyro_bias_rw", "must be >= 0 and finite");
  if (!finite_positive(c.star_sigma)) return bad("star_sigma", "must be positive and finite");
  if (!finite_non_negative(c.model_sigma)) return bad("model_sigma", "must be >= 0 and finite");
  if (!(c.gyro_arw > 0.0 || c.model_sigma > 0.0)) {
    return bad("gyro_arw",
               "gyro_arw or model_sigma must be positive (else P -> 0 and the star "
               "tracker is ignored)");
  }
  if (!finite_positive(c.init_attitude_sigma)) {
    return bad("init_attitude_sigma", "must be positive and finite");
  }
  if (!finite_positive(c.init_bias_sigma))
    return bad("init_bias_sigma", "must be positive and finite");
  if (!c.init_bias.allFinite()) return bad("init_bias", "non-finite value");
  if (!finite_positive(c.gate_chi2)) return bad("gate_chi2", "must be positive and finite");
  if (c.max_consecutive_rejects < 1) return bad("max_consecutive_rejects", "must be >= 1");
  if (!finite_positive(c.gyro_max_rate)) return bad("gyro_max_rate", "must be positive and finite");
  if (!finite_positive(c.quat_norm_tolerance) || c.quat_norm_tolerance >= 1.0) {
    return bad("quat_norm_tolerance", "must be in (0, 1)");
  }
  if (!finite_non_negative(c.rate_cutoff)) return bad("rate_cutoff", "must be >= 0 and finite");
  return {};
}

void Mekf::configure(const MekfConfig& c) {
  c_ = c;
  // Discrete process noise of the [dtheta; db] error state over dt (Farrenkopf's gyro model,
  // Markley & Crassidis 2014 Eq. 6.93, small omega dt), plus the model-uncertainty term.
  const double dt = c.dt;
  const double v2 = c.gyro_arw * c.gyro_arw;
  const double u2 = c.gyro_bias_rw * c.gyro_bias_rw;
  const double m2 = c.model_sigma * c.model_sigma;
  q_.setZero();
  q_.topLeftCorner<3, 3>() = ((v2 + m2) * dt + u2 * dt * dt * dt / 3.0) * Mat3::Identity();
  q_.topRightCorner<3, 3>() = (-0.5 * u2 * dt * dt) * Mat3::Identity();
  q_.bottomLeftCorner<3, 3>() = q_.topRightCorner<3, 3>();
  q_.bottomRightCorner<3, 3>() = (u2 * dt) * Mat3::Identity();
  r_var_ = c.star_sigma * c.star_sigma;
  rate_gain_ = c.rate_cutoff > 0.0 ? 1.0 - std::exp(-c.rate_cutoff * dt) : 1.0;
  // A running filter keeps its estimate (a new parameter table, e.g. an adopted identified
  // model, re-configures every component); reset() forgets it.
  if (!initialised_) reset();
}

void Mekf::set_rate_model(const Mat3& j_hat) {
  j_hat_ = j_hat;
  j_hat_inv_ = j_hat.inverse();
}

void Mekf::reset() {
  initialised_ = false;
  beta_ = quat::identity();
  bias_ = c_.init_bias;
  omega_.setZero();
  last_gyro_.setZero();
  p_.setZero();
  consecutive_rejects_ = 0;
  innovation_.setZero();
  innovation_chi2_ = 0.0;
}

Mat6 Mekf::transition(const Vec3& omega, double dt) {
  // Exact transition of dtheta_dot = -omega x dtheta - db for a constant omega
  // (Markley & Crassidis 2014 Eqs. 6.83-6.85).
  const double w = omega.norm();
  const Mat3 s = skew(omega);
  const Mat3 s2 = s * s;
  double a, b, c;  // sin(w dt)/w, (1 - cos(w dt))/w^2, (w dt - sin(w dt))/w^3
  const double x = w * dt;
  if (x < 1e-3) {
    a = dt * (1.0 - x * x / 6.0);
    b = dt * dt * (0.5 - x * x / 24.0);
    c = dt * dt * dt * (1.0 / 6.0 - x * x / 120.0);
  } else {
    a = std::sin(x) / w;
    b = (1.0 - std::cos(x)) / (w * w);
    c = (x - std::sin(x)) / (w * w * w);
  }
  Mat6 phi = Mat6::Identity();
  phi.topLeftCorner<3, 3>() = Mat3::Identity() - a * s + b * s2;
  phi.topRightCorner<3, 3>() = -(dt * Mat3::Identity() - b * s + c * s2);
  return phi;
}

void Mekf::initialise(const Vec4& beta, const Vec3& gyro) {
  beta_ = beta.w() < 0.0 ? Vec4(-beta.normalized()) : beta.normalized();
  bias_ = c_.init_bias;
  last_gyro_ = gyro;
  omega_ = gyro - bias_;
  p_.setZero();
  p_.topLeftCorner<3, 3>() = c_.init_attitude_sigma * c_.init_attitude_sigma * Mat3::Identity();
  p_.bottomRightCorner<3, 3>() = c_.init_bias_sigma * c_.init_bias_sigma * Mat3::Identity();
  consecutive_rejects_ = 0;
  initialised_ = true;
}

void Mekf::propagate(const Vec3& gyro_mean) {
  // Attitude with the mean of the two gyro samples that bound the tick (trapezoid), bias
  // corrected; covariance P = Phi P Phi' + Q.
  const Vec3 w = gyro_mean - bias_;
  beta_ = quat::multiply(beta_, rotation_increment(w, c_.dt)).normalized();
  const Mat6 phi = transition(w, c_.dt);
  // Phi = [A B; 0 I] (transition), so Phi P Phi' by 3x3 blocks (P21 = P12'):
  //   M1 = A P11 + B P12',  M2 = A P12 + B P22,
  //   P11+ = M1 A' + M2 B',  P12+ = M2,  P22+ = P22;
  // six 3x3 products instead of two 6x6 ones (the Cortex-M7 tick budget).
  const Mat3 a = phi.topLeftCorner<3, 3>();
  const Mat3 b = phi.topRightCorner<3, 3>();
  const Mat3 p11 = p_.topLeftCorner<3, 3>();
  const Mat3 p12 = p_.topRightCorner<3, 3>();
  const Mat3 p22 = p_.bottomRightCorner<3, 3>();
  const Mat3 m1 = a * p11 + b * p12.transpose();
  const Mat3 m2 = a * p12 + b * p22;
  const Mat3 n11 = m1 * a.transpose() + m2 * b.transpose();
  const Mat3 n22 = p22 + q_.bottomRightCorner<3, 3>();
  const Mat3 n12 = m2 + q_.topRightCorner<3, 3>();
  p_.topLeftCorner<3, 3>() = 0.5 * (n11 + n11.transpose()) + q_.topLeftCorner<3, 3>();
  p_.topRightCorner<3, 3>() = n12;
  p_.bottomLeftCorner<3, 3>() = n12.transpose();
  p_.bottomRightCorner<3, 3>() = 0.5 * (n22 + n22.transpose());
}

void Mekf::star_update(const Vec4& beta_meas) {
  // Innovation: the small rotation from the estimate to the measurement, body frame,
  // dbeta = beta_hat^-1 (x) beta_meas, nu = 2 dbeta_v (short way), H = [I 0].
  Vec4 db = quat::multiply(quat::conjugate(beta_), beta_meas);
  if (db.w() < 0.0) db = -db;
  const Vec3 nu = 2.0 * db.head<3>();
  const Mat3 s = p_.topLeftCorner<3, 3>() + r_var_ * Mat3::Identity();
  const Mat3 s_inv = s.inverse();
  innovation_ = nu;
  innovation_chi2_ = nu.dot(s_inv * nu);
  if (!(innovation_chi2_ <= c_.gate_chi2)) {  // also rejects a NaN distance
    ++counters_.gated;
    if (++consecutive_rejects_ >= c_.max_consecutive_rejects) {
      // A persistent jump is the truth moving, not an outlier: start again from the sensor.
      const Vec3 keep_bias = bias_;
      const Mat3 keep_pb = p_.bottomRightCorner<3, 3>();
      initialise(beta_meas, last_gyro_);
      bias_ = keep_bias;
      p_.bottomRightCorner<3, 3>() = keep_pb;
      ++counters_.reinitialised;
    }
    return;
  }
  consecutive_rejects_ = 0;
  ++counters_.updates;
  // K = P H' S^-1; Joseph form P = (I - K H) P (I - K H)' + K R K' keeps P symmetric PD.
  const Eigen::Matrix<double, 6, 3> k = p_.leftCols<3>() * s_inv;
  // With K = [K1; K2] and G = I - K1, I - K H = [G 0; -K2 I], so by 3x3 blocks (P21 = P12'):
  //   P11+ = G P11 G' + r K1 K1'
  //   P12+ = G (P12 - P11 K2') + r K1 K2'
  //   P22+ = K2 P11 K2' - (K2 P12)' - K2 P12 + P22 + r K2 K2'
  const Mat3 k1 = k.topRows<3>();
  const Mat3 k2 = k.bottomRows<3>();
  const Mat3 g = Mat3::Identity() - k1;
  const Mat3 p11 = p_.topLeftCorner<3, 3>();
  const Mat3 p12 = p_.topRightCorner<3, 3>();
  const Mat3 p22 = p_.bottomRightCorner<3, 3>();
  const Mat3 gp11 = g * p11;
  const Mat3 k2p11 = k2 * p11;
  const Mat3 k2p12 = k2 * p12;
  const Mat3 n11 = gp11 * g.transpose() + r_var_ * (k1 * k1.transpose());
  const Mat3 n12 = g * p12 - gp11 * k2.transpose() + r_var_ * (k1 * k2.transpose());
  const Mat3 n22 = k2p11 * k2.transpose() - k2p12.transpose() - k2p12 + p22 +
                   r_var_ * (k2 * k2.transpose());
  p_.topLeftCorner<3, 3>() = 0.5 * (n11 + n11.transpose());
  p_.topRightCorner<3, 3>() = n12;
  p_.bottomLeftCorner<3, 3>() = n12.transpose();
  p_.bottomRightCorner<3, 3>() = 0.5 * (n22 + n22.transpose());
  const Vec6 dx = k * nu;
  // Reset: fold the attitude error into the quaternion, the bias error into the bias.
  const Vec3 dtheta = dx.head<3>();
  beta_ = quat::multiply(beta_, Vec4(0.5 * dtheta.x(), 0.5 * dtheta.y(), 0.5 * dtheta.z(), 1.0))
              .normalized();
  bias_ += dx.tail<3>();
}

void Mekf::update(const MekfInput& in) {
  const bool gyro_ok =
      in.gyro_valid && in.gyro_rate.allFinite() && in.gyro_rate.norm() <= c_.gyro_max_rate;
  const double qn = in.star_quat.norm();
  const bool star_ok =
      in.star_valid && in.star_quat.allFinite() && std::fabs(qn - 1.0) <= c_.quat_norm_tolerance;
  if ((in.gyro_valid && !gyro_ok) || (in.star_valid && !star_ok)) ++counters_.rejected_input;
  if (!initialised_) {
    if (gyro_ok && star_ok) {
      initialise(in.star_quat / qn, in.gyro_rate);
      last_star_t_ = in.t;
    }
    return;
  }
  // (M8) The rate stage's prediction through Eq. (2) with J_hat and the commanded torque (Heun).
  const bool stage = c_.rate_cutoff > 0.0;
  Vec3 predicted = omega_;
  if (stage) {
    auto w_dot = [&](const Vec3& w) -> Vec3 {
      return j_hat_inv_ * ((j_hat_ * w).cross(w) + in.torque);
    };
    const Vec3 k1 = w_dot(omega_);
    const Vec3 k2 = w_dot(omega_ + c_.dt * k1);
    predicted = omega_ + 0.5 * c_.dt * (k1 + k2);
  }
  // A missing gyro sample: the stage's prediction when it runs (as a gyro would read it), else
  // the last sample held.
  const Vec3 gyro = gyro_ok ? in.gyro_rate : (stage ? Vec3(predicted + bias_) : last_gyro_);
  propagate(0.5 * (last_gyro_ + gyro));
  last_gyro_ = gyro;
  if (star_ok && in.t > last_star_t_) {
    last_star_t_ = in.t;
    star_update(in.star_quat / qn);
  }
  const Vec3 measured = last_gyro_ - bias_;
  // (M8) Correct towards the bias-corrected gyro: SPEC §6 step 3 on omega_gyro - b_hat.
  if (stage) {
    omega_ = gyro_ok ? Vec3(predicted + rate_gain_ * (measured - predicted)) : predicted;
  } else {
    omega_ = measured;
  }
}

Vec3 Mekf::q() const {
  return mrp::from_quaternion(beta_);
}

Vec3 Mekf::attitude_sigma() const {
  return p_.topLeftCorner<3, 3>().diagonal().cwiseSqrt();
}

Vec3 Mekf::bias_sigma() const {
  return p_.bottomRightCorner<3, 3>().diagonal().cwiseSqrt();
}

Vec3 Mekf::omega_sigma() const {
  const double white = c_.gyro_arw * c_.gyro_arw / c_.dt;
  return (p_.bottomRightCorner<3, 3>().diagonal().array() + white).sqrt().matrix();
}

}  // namespace rocksteady::gnc
