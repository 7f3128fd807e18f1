// Test-only truth for the estimation tests: independent quaternion algebra, a gyro with white noise
// and a random-walk bias, a star tracker with per-axis attitude noise, and a chi-square quantile.
// Shares no code with gnc/math.
#pragma once

#include <cmath>
#include <random>

#include <Eigen/Dense>

#include "rigid_body.hpp"

namespace rocksteady::test {

// Hamilton product, scalar last, a (x) b <-> R(a) R(b).
inline V4 qmul(const V4& a, const V4& b) {
  const V3 av = a.head<3>(), bv = b.head<3>();
  V4 r;
  r.head<3>() = a.w() * bv + b.w() * av + av.cross(bv);
  r.w() = a.w() * b.w() - av.dot(bv);
  return r;
}
inline V4 qconj(const V4& a) {
  return V4(-a.x(), -a.y(), -a.z(), a.w());
}
// Small rotation vector -> quaternion (exact).
inline V4 rotvec_quat(const V3& v) {
  const double a = v.norm();
  if (a < 1e-15) return V4(0, 0, 0, 1);
  return axis_angle(v / a, a);
}
// Attitude error of `est` relative to `truth` in the body frame, truth = est (x) [e/2; 1]:
// e = 2 vec(est^-1 (x) truth) on the short way (what the MEKF calls dtheta).
inline V3 attitude_error(const V4& est, const V4& truth) {
  V4 d = qmul(qconj(est), truth);
  if (d.w() < 0) d = -d;
  return 2.0 * d.head<3>();
}

// Chi-square quantile (Wilson-Hilferty): accurate to < 1 % for dof >= 3 in the tails used here.
inline double chi2_quantile(double dof, double z) {
  const double a = 2.0 / (9.0 * dof);
  const double c = 1.0 - a + z * std::sqrt(a);
  return dof * c * c * c;
}

struct SensorNoise {
  double gyro_arw{1e-6};     // rad/sqrt(s): per-sample sigma = arw / sqrt(dt)
  double gyro_bias_rw{0.0};  // rad/s^(3/2)
  double star_sigma{1e-3};   // rad per axis
};

// Gyro + star tracker sampled every dt from a truth, seeded.
class Sensors {
 public:
  Sensors(const SensorNoise& n, double dt, unsigned long long seed, const V3& bias0)
      : n_(n), dt_(dt), rng_(seed), bias_(bias0) {}
  V3 gyro(const V3& omega) {
    V3 g = omega + bias_;
    for (int a = 0; a < 3; ++a) g(a) += n_.gyro_arw / std::sqrt(dt_) * normal_(rng_);
    return g;
  }
  V4 star(const V4& beta) {
    V3 e;
    for (int a = 0; a < 3; ++a) e(a) = n_.star_sigma * normal_(rng_);
    V4 m = qmul(beta, rotvec_quat(e));
    return m.w() < 0 ? V4(-m) : m;
  }
  // Advance the bias random walk by dt.
  void step_bias() {
    for (int a = 0; a < 3; ++a) bias_(a) += n_.gyro_bias_rw * std::sqrt(dt_) * normal_(rng_);
  }
  const V3& bias() const { return bias_; }

 private:
  SensorNoise n_;
  double dt_;
  std::mt19937_64 rng_;
  std::normal_distribution<double> normal_{0.0, 1.0};
  V3 bias_;
};

// Per-axis steady state of the attitude/bias filter at rest (Farrenkopf 1978): the fixed point of
// the discrete Riccati recursion for x = [theta, b], written out independently of the MEKF.
inline double farrenkopf_post_update_sigma(double arw, double brw, double star, double dt) {
  double p11 = star * star, p12 = 0.0, p22 = 1e-6;
  for (int it = 0; it < 2000000; ++it) {
    // Predict: Phi = [[1, -dt], [0, 1]], Q of the gyro model.
    const double m11 =
        p11 - 2 * dt * p12 + dt * dt * p22 + arw * arw * dt + brw * brw * dt * dt * dt / 3;
    const double m12 = p12 - dt * p22 - 0.5 * brw * brw * dt * dt;
    const double m22 = p22 + brw * brw * dt;
    // Update with H = [1 0].
    const double s = m11 + star * star;
    const double n11 = m11 - m11 * m11 / s, n12 = m12 - m11 * m12 / s, n22 = m22 - m12 * m12 / s;
    const bool done = std::fabs(n11 - p11) < 1e-16 * p11 && std::fabs(n22 - p22) <= 1e-16 * p22;
    p11 = n11;
    p12 = n12;
    p22 = n22;
    if (done) break;
  }
  return std::sqrt(p11);
}

}  // namespace rocksteady::test
