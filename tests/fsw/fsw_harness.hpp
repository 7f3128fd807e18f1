// Test harness for the flight application: a scaled-down vehicle (time constants of seconds), a
// test-only rigid-body truth (Eqs. 2-3, own RK4, shares no code with gnc/math) and command helpers.
#pragma once

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <memory>
#include <stdexcept>
#include <vector>

#include <Eigen/Dense>

#include "fsw/app/flight_app.hpp"
#include "gnc/guidance/trajectory.hpp"
#include "gnc/params.hpp"
#include "rigid_body.hpp"

namespace rocksteady::fsw::test {

using V3 = Eigen::Vector3d;
using V4 = Eigen::Vector4d;  // scalar last
using M3 = Eigen::Matrix3d;

inline gnc::GncParams small_vehicle_params() {
  gnc::GncParams p;
  p.dt = 0.05;
  p.mass_hat.m_sc = 20.0;
  p.mass_hat.r_scm_so = V3(0, 0, 0.3);
  p.mass_hat.j_sc = V3(1.0, 1.0, 0.5).asDiagonal();
  p.mass_hat.j_ast << 10.0, 1.0, 0.5, 1.0, 12.0, -0.3, 0.5, -0.3, 15.0;
  p.mass_hat.r_so_bcm = V3(0.01, -0.02, 0.4);
  p.rcs = gnc::study_rcs_layout(2.0, 0.5, 0.3);
  for (gnc::TrackingGains* g : {&p.ntcl, &p.el, &p.feedforward}) {
    g->k = 4.0 * M3::Identity();
    g->lambda = 0.3 * M3::Identity();
  }
  p.integral.k = 4.0 * M3::Identity();
  p.integral.lambda = 0.3 * M3::Identity();
  p.integral.k_i = 0.5 * M3::Identity();
  p.integral.integral_limit_nm = 1.0;
  p.adaptive.k = 4.0 * M3::Identity();
  p.adaptive.lambda = 0.3 * M3::Identity();
  p.adaptive.gamma = 100.0;
  p.so3.k = 4.0 * M3::Identity();
  p.so3.lambda = 1.2 * M3::Identity();
  p.dpd.k_d = 6.0 * M3::Identity();
  p.dpd.k_p = 3.0;
  p.guidance.omega_switch = 0.02;
  p.guidance.eps_trans = 1.0;
  p.guidance.k_qd = 0.2;
  p.estimator.omega_c = 2.0;
  p.estimator.gyro_max_rate = 5.0;
  p.mode.sensor_timeout_s = 0.5;
  return p;
}

// 20 Hz base tick = GNC (dt 0.05 s), housekeeping at 1 Hz.
inline FlightConfig small_config() {
  FlightConfig c;
  c.gnc = small_vehicle_params();
  c.executive.base_rate_hz = 20.0;
  c.executive.gnc_divider = 1;
  c.executive.housekeeping_divider = 20;
  c.executive.slip_event_interval_s = 10.0;
  c.sensor_event_interval_s = 10.0;
  c.security.lab_mode = true;  // command authentication has its own tests (auth_test.cpp)
  return c;
}

// Truth: the shared test-only rigid body (Eq. 2, quaternion kinematics Eq. 3, RK4 with zero-order
// hold; tests/common/rigid_body.hpp), with its clock.
struct Truth : rocksteady::test::RigidBody {
  double t{0.0};

  void step(double h, const V3& tau) {
    RigidBody::step(h, tau);
    t += h;
  }

  gnc::SensorSample sample() const {
    gnc::SensorSample s;
    s.t = t;
    s.gyro_rate = omega;
    s.gyro_valid = true;
    s.star_quat = beta;
    s.star_valid = true;
    return s;
  }
};

// The small vehicle's truth (same mass properties as the flight software's estimate) and the
// thrusters applied through the torque matrix of the RCS layout.
struct Loop {
  gnc::GncParams params = small_vehicle_params();
  Truth truth;
  Eigen::Matrix<double, 3, 8> b;

  Loop() {
    truth.j = gnc::total_inertia(params.mass_hat);
    b = gnc::torque_matrix(params.rcs, params.mass_hat.r_so_bcm);
  }
  // One tick: sample, flight application, thrusters held for dt.
  void tick(FlightApp& app, Outputs& out) {
    app.gnc_tick(truth.sample(), out);
    const V3 tau = out.gnc_ran && out.command.enabled ? V3(b * out.command.force) : V3::Zero();
    truth.step(params.dt, tau);
  }
};

inline GroundCommand command(std::int64_t seq, Opcode op, std::initializer_list<double> args = {},
                             std::int32_t source = 1) {
  GroundCommand c;
  c.seq = seq;
  c.source = source;
  c.opcode = static_cast<std::int32_t>(op);
  c.arg_count = static_cast<std::int32_t>(args.size());
  int i = 0;
  for (double a : args) {
    if (i < kMaxCommandArgs) c.args[i] = a;
    ++i;
  }
  return c;
}

inline std::vector<Event> drain(FlightApp& app) {
  std::vector<Event> v;
  Event e;
  while (app.pop_event(e)) v.push_back(e);
  return v;
}

inline int count_events(const std::vector<Event>& v, EventId id) {
  int n = 0;
  for (const Event& e : v) n += e.id == id ? 1 : 0;
  return n;
}

// A despin plan: omega_d decays linearly to rest over `duration` (n samples).
inline void linear_despin_table(const V3& omega0, double duration, int n, gnc::TrajectoryTable& t) {
  t.count = n;
  for (int i = 0; i < n; ++i) {
    const double s = static_cast<double>(i) / (n - 1);
    t.samples[i].t = s * duration;
    t.samples[i].omega_d = (1.0 - s) * omega0;
    t.samples[i].omega_d_dot = -omega0 / duration;
  }
  t.samples[n - 1].omega_d_dot.setZero();
  t.checksum = gnc::trajectory_checksum(t);
}

// Cut a table into uplink chunks of 32 samples.
inline std::vector<TrajectoryChunk> chunks_of(const gnc::TrajectoryTable& t,
                                              std::int32_t upload_id) {
  std::vector<TrajectoryChunk> v;
  const int count = (t.count + kChunkSamples - 1) / kChunkSamples;
  for (int i = 0; i < count; ++i) {
    TrajectoryChunk c;
    c.upload_id = upload_id;
    c.chunk_index = i;
    c.chunk_count = count;
    c.total_samples = t.count;
    c.crc32 = t.checksum;
    c.n = std::min(kChunkSamples, t.count - i * kChunkSamples);
    for (int k = 0; k < c.n; ++k) c.samples[k] = t.samples[i * kChunkSamples + k];
    v.push_back(c);
  }
  return v;
}

}  // namespace rocksteady::fsw::test

namespace rocksteady::fsw::test {

// An initialised application on a fake clock, with a truth loop and a sequence counter.
struct AppFixture {
  FakeClock clock{0};
  std::unique_ptr<FlightApp> app = std::make_unique<FlightApp>();
  Loop loop;
  Outputs out;
  std::int64_t seq = 0;

  explicit AppFixture(const FlightConfig& cfg = small_config()) {
    const InitResult r = app->init(cfg, clock);
    if (!r.ok) throw std::runtime_error(r.field);
  }
  CommandAck send(Opcode op, std::initializer_list<double> args = {}) {
    return app->submit(command(++seq, op, args));
  }
  void ticks(int n) {
    for (int i = 0; i < n; ++i) {
      clock.advance(50000000);
      loop.tick(*app, out);
    }
  }
};

}  // namespace rocksteady::fsw::test
