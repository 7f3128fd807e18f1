// A scaled-down spacecraft for component-level tests: the same code paths as the study's vehicle,
// with time constants of seconds instead of hours.
#pragma once

#include <cmath>

#include "gnc/gnc.hpp"
#include "gnc/math/rotation.hpp"
#include "rigid_body.hpp"

namespace rocksteady::test {

inline gnc::GncParams small_vehicle_params() {
  gnc::GncParams p;
  p.dt = 0.05;
  p.mass_hat.m_sc = 20.0;
  p.mass_hat.r_scm_so = gnc::Vec3(0, 0, 0.3);
  p.mass_hat.j_sc = gnc::Vec3(1.0, 1.0, 0.5).asDiagonal();
  p.mass_hat.j_ast << 10.0, 1.0, 0.5, 1.0, 12.0, -0.3, 0.5, -0.3, 15.0;
  p.mass_hat.r_so_bcm = gnc::Vec3(0.01, -0.02, 0.4);
  p.rcs = gnc::study_rcs_layout(2.0, 0.5, 0.3);
  for (gnc::TrackingGains* g : {&p.ntcl, &p.el, &p.feedforward}) {
    g->k = 4.0 * gnc::Mat3::Identity();
    g->lambda = 0.3 * gnc::Mat3::Identity();
  }
  p.integral.k = 4.0 * gnc::Mat3::Identity();
  p.integral.lambda = 0.3 * gnc::Mat3::Identity();
  p.integral.k_i = 0.5 * gnc::Mat3::Identity();
  p.integral.integral_limit_nm = 1.0;
  p.adaptive.k = 4.0 * gnc::Mat3::Identity();
  p.adaptive.lambda = 0.3 * gnc::Mat3::Identity();
  p.adaptive.gamma = 100.0;
  p.so3.k = 4.0 * gnc::Mat3::Identity();
  p.so3.lambda = 1.2 * gnc::Mat3::Identity();
  p.dpd.k_d = 6.0 * gnc::Mat3::Identity();
  p.dpd.k_p = 3.0;
  p.guidance.omega_switch = 0.02;
  p.guidance.eps_trans = 1.0;
  p.guidance.k_qd = 0.03;  // 10x below Lambda, as in the study (k_qd = 1e-4, Lambda = 1e-3)
  p.estimator.omega_c = 2.0;
  p.estimator.gyro_max_rate = 5.0;
  p.mode.sensor_timeout_s = 0.5;
  return p;
}

// MRP -> quaternion (scalar last) and -> rotation matrix through the plant's algebra, written out
// here so that a test's truth shares no code with gnc/math.
inline V4 mrp_to_quat(const V3& q) {
  const double n = q.squaredNorm();
  V4 b;
  b.head<3>() = 2.0 * q / (1.0 + n);
  b.w() = (1.0 - n) / (1.0 + n);
  return b;
}
inline M3 mrp_to_dcm(const V3& q) { return quat_to_matrix(mrp_to_quat(q)); }

// A despin plan for the small vehicle: omega_d decays linearly to rest over `duration`.
inline void linear_despin_table(const gnc::Vec3& omega0, double duration, gnc::TrajectoryTable& t) {
  t.count = 101;
  for (int i = 0; i < t.count; ++i) {
    const double s = static_cast<double>(i) / (t.count - 1);
    t.samples[i].t = s * duration;
    t.samples[i].omega_d = (1.0 - s) * omega0;
    t.samples[i].omega_d_dot = -omega0 / duration;
  }
  t.samples[t.count - 1].omega_d_dot.setZero();
  t.checksum = gnc::trajectory_checksum(t);
}

// Truth + flight core in lockstep, ideal sensors, the thrusters applied through the true B.
struct SmallLoop {
  gnc::Gnc gnc;
  RigidBody body;
  gnc::Mat38 b_true;
  double t{0.0};
  gnc::GncOutput out{};

  explicit SmallLoop(const gnc::GncParams& p) {
    body.j = gnc::total_inertia(p.mass_hat);
    b_true = gnc::torque_matrix(p.rcs, p.mass_hat.r_so_bcm);
    body.omega = gnc::Vec3(0.3, -0.2, 0.25);
    body.beta = axis_angle(gnc::Vec3(1, 0.5, -0.2), 0.9);
  }
  gnc::SensorSample sample() const {
    gnc::SensorSample s;
    s.t = t;
    s.gyro_rate = body.omega;
    s.gyro_valid = true;
    s.star_quat = body.beta;
    s.star_valid = true;
    return s;
  }
  void tick(const gnc::GncCommands& c = {}) {
    gnc.step(sample(), c, out);
    body.step(gnc.params().dt, b_true * out.command.force);
    t += gnc.params().dt;
  }
};

}  // namespace rocksteady::test
