// Momentum tracking of a plan (guidance.track_momentum_k, gnc/control/laws.hpp momentum_torque):
// TRACK flies the plan's inertial angular momentum h_d = R_d J_hat omega_d instead of its body
// rates. Truth here is the plant's quaternion algebra and rigid body (tests/common/rigid_body.hpp,
// no gnc/math code) and finite differences.
#include <gtest/gtest.h>

#include <cmath>

#include "gnc/control/laws.hpp"
#include "gnc/guidance/references.hpp"
#include "gnc_harness.hpp"

namespace rocksteady::gnc {
namespace {

using test::M3;
using test::V3;
using test::V4;

M3 dcm(const V3& q) { return test::mrp_to_dcm(q); }
using test::mrp_to_quat;

M3 sym(double a, double b, double c, double d, double e, double f) {
  M3 m;
  m << a, d, e, d, b, f, e, f, c;
  return m;
}

ReferenceSample plan_sample(const V3& q_d, const V3& w_d, const V3& w_d_dot) {
  ReferenceSample s;
  s.phase = ReferencePhase::kTrack;
  s.q.q = q_d;
  s.plan_omega = w_d;
  s.plan_omega_dot = w_d_dot;
  return s;
}

// The torque: with the body's momentum on the plan's (J_hat omega = R' R_d J_hat omega_d) it is
// the plan's torque J_hat omega_d' + omega_d x J_hat omega_d turned from the plan's body frame into
// today's, whatever the two attitudes; off it, k times the momentum error is added. The rate it
// reports carries h_d (J_hat omega_r = R' R_d J_hat omega_d) and its derivative matches the finite
// difference of that rate as the body turns at omega and the plan runs.
TEST(MomentumTracking, ThePlansTorqueTurnedIntoTheBodyFramePlusTheMomentumError) {
  const M3 j = sym(10.0, 12.0, 15.0, 1.0, 0.5, -0.3);
  const M3 j_inv = j.inverse();
  const V3 q(0.3, -0.2, 0.1), q_d(-0.1, 0.4, 0.25);
  const V3 w_d(0.2, -0.1, 0.3), w_d_dot(-0.01, 0.02, 0.005);
  const M3 dr = dcm(q).transpose() * dcm(q_d);
  const V3 tau_plan = j * w_d_dot + w_d.cross(j * w_d);
  const V3 w_on = j_inv * (dr * (j * w_d));
  RateReference rr;
  const double k = 0.7;
  const Vec3 u_on = momentum_torque(j, j_inv, k, q, w_on, plan_sample(q_d, w_d, w_d_dot), rr);
  EXPECT_LT((u_on - dr * tau_plan).norm(), 1e-12 * tau_plan.norm());
  EXPECT_LT((j * rr.omega_r - dr * (j * w_d)).norm(), 1e-12);

  const V3 w_off = w_on + V3(0.05, -0.02, 0.01);
  const Vec3 u_off = momentum_torque(j, j_inv, k, q, w_off, plan_sample(q_d, w_d, w_d_dot), rr);
  EXPECT_LT((u_off - (dr * tau_plan + k * (dr * (j * w_d) - j * w_off))).norm(), 1e-12);

  // omega_r' along the motion: q turns at w_off (the plant's quaternion rate), q_d at w_d, and the
  // plan's rate moves at w_d_dot; central differences of omega_r.
  const double h = 1e-5;
  const auto omega_r_at = [&](double s) {
    V4 b = mrp_to_quat(q), b_d = mrp_to_quat(q_d);
    b += s * test::quat_derivative(b, w_off);
    b_d += s * test::quat_derivative(b_d, w_d);
    b.normalize();
    b_d.normalize();
    RateReference r;
    momentum_torque(j, j_inv, k, test::quat_to_mrp(b), w_off,
                    plan_sample(test::quat_to_mrp(b_d), w_d + s * w_d_dot, w_d_dot), r);
    return V3(r.omega_r);
  };
  const V3 fd = (omega_r_at(h) - omega_r_at(-h)) / (2.0 * h);
  momentum_torque(j, j_inv, k, q, w_off, plan_sample(q_d, w_d, w_d_dot), rr);
  EXPECT_LT((fd - rr.omega_r_dot).norm(), 1e-7 * rr.omega_r_dot.norm());
}

// The acquisition phases start from where the body is: momentum tracking lets the attitude go off
// the plan's q_d, so the slew after the plan (and, without one, Eqs. 46-48) restart q_d from the
// estimate; the plan's rates reach the law in kTrack.
TEST(MomentumTracking, TheSlewAfterThePlanStartsFromTheEstimate) {
  const double dt = 0.05;
  const Vec3 w0(0.06, -0.04, 0.05);
  TrajectoryTable tab;
  test::linear_despin_table(w0, 60.0, tab);
  GuidanceParams g;
  g.omega_switch = 0.02;
  g.k_qd = 0.03;
  g.q_final = Vec3(0.1, -0.2, 0.3);
  g.slew_s = 300.0;
  g.slew_ramp_s = 30.0;
  g.track_momentum_k = 0.1;
  References refs;
  refs.configure(g, dt);
  ReferenceSample s = refs.update(Mode::kTrack, true, 0.0, Vec3::Zero(), w0, tab);
  ASSERT_EQ(s.phase, ReferencePhase::kTrack);
  EXPECT_LT((s.plan_omega - w0).norm(), 1e-15);
  EXPECT_LT((s.plan_omega_dot + w0 / 60.0).norm(), 1e-15);
  for (int k = 1; k * dt < 60.0 - 1e-9; ++k) {
    s = refs.update(Mode::kTrack, false, k * dt, Vec3::Zero(), interpolate(tab, k * dt).omega_d,
                    tab);
  }
  EXPECT_GT(s.q.q.norm(), 0.05);  // the plan's attitude has moved; the body (q_hat = 0) has not
  const Vec3 q_hat(-0.3, 0.1, 0.2);
  s = refs.update(Mode::kTrack, false, 61.0, q_hat, Vec3(0.001, 0.0, 0.0), tab);
  ASSERT_EQ(s.phase, ReferencePhase::kTrackSlew);
  EXPECT_LT((s.q.q - q_hat).norm(), 1e-12);  // no step: the turn starts at the estimate
  const M3 rel = dcm(q_hat).transpose() * dcm(g.q_final);
  EXPECT_NEAR(refs.slew_angle(), std::acos(0.5 * (rel.trace() - 1.0)), 1e-9);
}

// Closed loop through Gnc::step (the small vehicle, ideal sensors): the body's inertia is ~10 % off
// the model the plan was made for. The NTCL holds the body on the plan's rates and pays for the
// gyroscopic difference; momentum tracking flies the plan's inertial momentum, which the true
// body follows whatever its inertia (h' = R u). Truth: the inertial momentum R J omega of the
// rigid body against the plan's, R_d J_hat omega_d with R_d integrated from the plan's rates by
// the plant's quaternion algebra from the attitude at the start.
TEST(MomentumTracking, AWrongInertiaCostsTheNtclFuelThatMomentumTrackingDoesNotSpend) {
  double fuel[2] = {0.0, 0.0};
  double h_err_max[2] = {0.0, 0.0};
  double h_end[2] = {0.0, 0.0};
  int track_ticks[2] = {0, 0};
  const Vec3 w0(0.3, -0.2, 0.25);
  const double plan_s = 80.0;
  M3 j_hat_model = M3::Identity(), loop_j_true = M3::Identity();
  for (int run = 0; run < 2; ++run) {
    GncParams p = test::small_vehicle_params();
    p.law = LawId::kNtcl;
    p.guidance.omega_switch = 1e-3;  // the whole plan in kTrack
    p.guidance.track_momentum_k = run == 1 ? 0.2 : 0.0;
    test::SmallLoop loop(p);
    const M3 j_hat = loop.body.j;
    loop.body.j = j_hat + 0.2 * j_hat.norm() * M3(V3(-0.3, 0.3, 0.15).asDiagonal());
    j_hat_model = j_hat;
    loop_j_true = loop.body.j;
    loop.body.omega = w0;
    ASSERT_TRUE(loop.gnc.init(p).ok);
    TrajectoryTable tab;
    test::linear_despin_table(w0, plan_s, tab);
    ASSERT_EQ(loop.gnc.load_trajectory(tab), TrajectoryError::kOk);
    GncCommands c;
    c.has_mode_request = true;
    c.mode_request = Mode::kTrack;
    V4 beta_d = loop.body.beta;  // the plan's attitude, from the body's at TRACK's first tick
    loop.tick(c);
    ASSERT_EQ(loop.gnc.mode(), Mode::kTrack);
    const double t0 = loop.t - p.dt;
    const V3 h_start = test::quat_to_matrix(beta_d) * (j_hat * w0);
    while (loop.t < t0 + plan_s - 1e-9) {
      // RK4 of the plan's attitude over the tick (its rate is the table's, Hermite-exact here).
      const double ta = loop.t - t0;
      const auto wd = [&](double s) { return V3(interpolate(tab, s).omega_d); };
      const double hh = p.dt;
      const V4 k1 = test::quat_derivative(beta_d, wd(ta));
      const V4 k2 = test::quat_derivative(beta_d + 0.5 * hh * k1, wd(ta + 0.5 * hh));
      const V4 k3 = test::quat_derivative(beta_d + 0.5 * hh * k2, wd(ta + 0.5 * hh));
      const V4 k4 = test::quat_derivative(beta_d + hh * k3, wd(ta + hh));
      beta_d = (beta_d + hh / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)).normalized();
      loop.tick();
      const V3 h_true = test::quat_to_matrix(loop.body.beta) * (loop.body.j * loop.body.omega);
      const V3 h_plan = test::quat_to_matrix(beta_d) * (j_hat * wd(loop.t - t0));
      h_err_max[run] = std::fmax(h_err_max[run], (h_true - h_plan).norm() / h_start.norm());
      track_ticks[run] += loop.out.telemetry.phase == ReferencePhase::kTrack ? 1 : 0;
    }
    fuel[run] = loop.out.telemetry.fuel_kg;
    h_end[run] = (loop.body.j * loop.body.omega).norm() / h_start.norm();
    EXPECT_GT(track_ticks[run], 0.99 * plan_s / p.dt) << run;  // the plan flown in kTrack
  }
  // Momentum tracking: the true momentum stays as near the plan's as it starts (the plan's h_d(0)
  // is J_hat omega_0, 9 % off J omega_0), and the despin ends with little momentum left.
  const double h_err0 = ((loop_j_true - j_hat_model) * w0).norm() / (j_hat_model * w0).norm();
  EXPECT_LT(h_err_max[1], 1.05 * h_err0);
  EXPECT_LT(h_end[1], 0.01);
  // The NTCL holds the rates instead: the momentum goes further off the plan, and it costs fuel
  // (measured: 24 % more).
  EXPECT_GT(h_err_max[0], 1.1 * h_err0);
  EXPECT_LT(fuel[1], 0.85 * fuel[0]);
  std::printf("fuel NTCL %.4g momentum %.4g kg; |h - h_d|max / |h0| %.3f %.3f; |h_end| / |h0| "
              "%.3f %.3f\n",
              fuel[0], fuel[1], h_err_max[0], h_err_max[1], h_end[0], h_end[1]);
}

}  // namespace
}  // namespace rocksteady::gnc
