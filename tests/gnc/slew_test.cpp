// The acquisition slew (gnc/guidance/references.hpp, guidance.slew_s): after the plan, the TRACK
// reference turns rest to rest about the eigenaxis to q_final with a trapezoidal rate.
// Truth here is the plant's quaternion algebra (tests/common/rigid_body.hpp, no gnc/math code)
// and Rodrigues' formula written out, finite differences for the rates.
#include <gtest/gtest.h>

#include <cmath>

#include "gnc/guidance/references.hpp"
#include "gnc/math/rotation.hpp"
#include "gnc_harness.hpp"

namespace rocksteady::gnc {
namespace {

using test::M3;
using test::V3;
using test::V4;

M3 dcm(const V3& q) { return test::mrp_to_dcm(q); }
using test::mrp_to_quat;

M3 rodrigues(const V3& axis, double angle) {
  M3 k;
  k << 0, -axis.z(), axis.y(), axis.z(), 0, -axis.x(), -axis.y(), axis.x(), 0;
  return M3::Identity() + std::sin(angle) * k + (1.0 - std::cos(angle)) * k * k;
}

// The rest-to-rest trapezoid the slew must fly: ramps of ta at +-a, coast at wc, angle th in T.
struct Trapezoid {
  double th, T, ta, wc;
  double angle(double tau) const {
    if (tau <= 0.0) return 0.0;
    if (tau >= T) return th;
    const double a = wc / ta;
    if (tau < ta) return 0.5 * a * tau * tau;
    if (tau > T - ta) return th - 0.5 * a * (T - tau) * (T - tau);
    return 0.5 * wc * ta + wc * (tau - ta);
  }
};

TrajectoryTable rest_table() {
  TrajectoryTable tab;
  tab.count = 1;
  tab.samples[0].t = 0.0;
  tab.samples[0].omega_d.setZero();
  tab.samples[0].omega_d_dot.setZero();
  tab.checksum = trajectory_checksum(tab);
  return tab;
}

GuidanceParams slew_params(double slew_s, double ramp_s) {
  GuidanceParams g;
  g.omega_switch = 0.02;
  g.k_qd = 0.03;
  g.q_final = Vec3(0.1, -0.2, 0.3);
  g.slew_s = slew_s;
  g.slew_ramp_s = ramp_s;
  return g;
}

// The reference's attitude is R_0 Rot(e, theta(t)) with e and the total angle from R_0' R_final
// (the matrix's axis and angle), theta(t) the trapezoid; its rate Z^-1 q_dot is e theta' (a fixed
// eigenaxis); q_ddot is the derivative of q_dot; at the end it is q_final at rest.
TEST(AcquisitionSlew, TheReferenceIsTheEigenaxisTurnToTheTargetRestToRest) {
  const double dt = 0.05;
  const GuidanceParams g = slew_params(400.0, 50.0);
  References refs;
  refs.configure(g, dt);
  const TrajectoryTable tab = rest_table();
  const V3 q0(-0.3, 0.4, 0.2);

  const M3 r0 = dcm(q0);
  const M3 rel = r0.transpose() * dcm(g.q_final);
  const double angle = std::acos(0.5 * (rel.trace() - 1.0));
  const V3 axis = V3(rel(2, 1) - rel(1, 2), rel(0, 2) - rel(2, 0), rel(1, 0) - rel(0, 1)) /
                  (2.0 * std::sin(angle));
  ASSERT_GT(angle, 1.0);  // a large turn, well inside the short way
  const Trapezoid trap{angle, 400.0, 50.0, angle / (400.0 - 50.0)};

  ReferenceSample s = refs.update(Mode::kTrack, true, 0.0, q0, Vec3::Zero(), tab);
  ASSERT_EQ(s.phase, ReferencePhase::kTrackSlew);  // the plan is over and the body at rest
  EXPECT_NEAR(refs.slew_angle(), angle, 1e-9);
  EXPECT_LT((refs.slew_axis() - axis).norm(), 1e-9);
  EXPECT_NEAR(refs.slew_rate(), angle / 350.0, 1e-12);

  double swept = 0.0, peak = 0.0, max_att = 0.0, max_rate = 0.0, max_acc = 0.0;
  Vec3 prev_q_dot = Vec3::Zero();
  double prev_t = 0.0;
  V3 w_prev = V3::Zero();
  for (int k = 1; k <= 9000; ++k) {  // 450 s: the slew and 50 s at rest
    const double t = k * dt;
    s = refs.update(Mode::kTrack, false, t, q0, Vec3::Zero(), tab);
    ASSERT_EQ(s.phase, ReferencePhase::kTrackSlew);
    const M3 expect = r0 * rodrigues(axis, trap.angle(t));
    max_att = std::fmax(max_att, (dcm(s.q.q) - expect).norm());
    const V3 w = mrp::z_inverse(s.q.q) * s.q.q_dot;
    const double th_dot = (trap.angle(t + 1e-3) - trap.angle(t - 1e-3)) / 2e-3;
    if (std::fabs(t - 50.0) > 0.01 && std::fabs(t - 350.0) > 0.01 && t < 399.99) {
      max_rate = std::fmax(max_rate, (w - axis * th_dot).norm());
    }
    if (k > 1) {
      // q_ddot against the central difference of q_dot (away from the ramps' corners).
      const Vec3 fd = (s.q.q_dot - prev_q_dot) / (t - prev_t);
      const bool corner = std::fabs(t - 50.0) < 0.2 || std::fabs(t - 350.0) < 0.2 ||
                          std::fabs(t - 400.0) < 0.2;
      if (!corner) max_acc = std::fmax(max_acc, (fd - s.q.q_ddot).norm());
    }
    swept += 0.5 * (w.norm() + w_prev.norm()) * dt;
    peak = std::fmax(peak, w.norm());
    prev_q_dot = s.q.q_dot;
    prev_t = t;
    w_prev = w;
  }
  EXPECT_LT(max_att, 1e-9);
  EXPECT_LT(max_rate, 1e-9);
  EXPECT_LT(max_acc, 1e-6 * angle / 350.0 / 50.0 * 100.0);
  EXPECT_NEAR(swept, angle, 1e-6);             // the rate integrates to the turn
  EXPECT_NEAR(peak, angle / 350.0, 1e-12);     // the coast: angle / (T - t_ramp)
  EXPECT_LT((dcm(s.q.q) - dcm(g.q_final)).norm(), 1e-12);  // at q_final
  EXPECT_LT(s.q.q_dot.norm(), 1e-15);                      // at rest
  EXPECT_LT(s.q.q_ddot.norm(), 1e-15);
}

// It starts only when the plan is over and |omega_hat| <= omega_switch; until then the plan is
// flown by Eq. (45) alone (no augmentation). With slew_s = 0 the study's Eqs. (46)-(48) act as
// before. A new plan (reset_track) ends a slew under way.
TEST(AcquisitionSlew, StartsOnlyAfterThePlanAndBelowTheSwitchRate) {
  const double dt = 0.05;
  const Vec3 w0(0.06, -0.04, 0.05);
  TrajectoryTable tab;
  test::linear_despin_table(w0, 60.0, tab);
  for (double slew : {0.0, 300.0}) {
    References refs;
    refs.configure(slew_params(slew, 30.0), dt);
    Vec3 q_hat(0.2, 0.1, -0.1);
    ReferenceSample s = refs.update(Mode::kTrack, true, 0.0, q_hat, w0, tab);
    bool augmented_in_plan = false;
    for (int k = 1; k * dt < 60.0 - 1e-9; ++k) {  // the plan, tracked exactly
      const double t = k * dt;
      const Vec3 w = interpolate(tab, t).omega_d;
      s = refs.update(Mode::kTrack, false, t, s.q.q, w, tab);
      augmented_in_plan |= s.phase == ReferencePhase::kTrackAugmented;
      ASSERT_NE(s.phase, ReferencePhase::kTrackSlew) << t;
    }
    // (46)-(48) latch once |omega| <= omega_switch; with the slew the plan stays Eq. (45).
    EXPECT_EQ(augmented_in_plan, slew == 0.0);
    // After the plan, a rate above the switch: no slew yet.
    s = refs.update(Mode::kTrack, false, 61.0, s.q.q, Vec3(0.03, 0.0, 0.0), tab);
    EXPECT_EQ(s.phase, slew == 0.0 ? ReferencePhase::kTrackAugmented : ReferencePhase::kTrack);
    EXPECT_FALSE(refs.slewing());
    s = refs.update(Mode::kTrack, false, 62.0, s.q.q, Vec3(0.01, 0.0, 0.0), tab);
    EXPECT_EQ(s.phase, slew == 0.0 ? ReferencePhase::kTrackAugmented : ReferencePhase::kTrackSlew);
    EXPECT_EQ(refs.slewing(), slew > 0.0);
    if (slew == 0.0) continue;
    EXPECT_GT(refs.slew_angle(), 0.0);
    // A new plan ends it: the plan is flown first.
    refs.reset_track(100.0, s.q.q, w0, tab);
    EXPECT_FALSE(refs.slewing());
    s = refs.update(Mode::kTrack, false, 100.05, s.q.q, w0, tab);
    EXPECT_EQ(s.phase, ReferencePhase::kTrack);
  }
}

// Closed loop through Gnc::step (NTCL, the small vehicle): after a despin plan the slew brings
// the body to q_final with its rate at the slew's coast, and with less fuel than Eqs. (46)-(48)
// over the same time (which start at their highest rate, here 4 k_qd |dq| / (1 + |dq|^2), against
// the slew's coast at angle / (T - t_ramp)).
TEST(AcquisitionSlew, ClosedLoopReachesTheTargetForLessFuelThanTheExponential) {
  double fuel[2] = {0.0, 0.0};
  for (int run = 0; run < 2; ++run) {
    GncParams p = test::small_vehicle_params();
    p.law = LawId::kNtcl;
    p.guidance.q_final = Vec3(0.1, -0.1, 0.05);
    p.guidance.slew_s = run == 1 ? 200.0 : 0.0;
    p.guidance.slew_ramp_s = 10.0;
    test::SmallLoop loop(p);
    loop.body.omega = Vec3(0.06, -0.04, 0.05);
    ASSERT_TRUE(loop.gnc.init(p).ok);
    TrajectoryTable tab;
    test::linear_despin_table(loop.body.omega, 60.0, tab);
    ASSERT_EQ(loop.gnc.load_trajectory(tab), TrajectoryError::kOk);
    GncCommands c;
    c.has_mode_request = true;
    c.mode_request = Mode::kTrack;
    loop.tick(c);
    ASSERT_EQ(loop.gnc.mode(), Mode::kTrack);
    while (loop.t < 61.0) loop.tick();  // the plan
    const V3 q_end = loop.body.mrp();
    const double fuel0 = loop.out.telemetry.fuel_kg;
    double peak = 0.0;
    bool slewed = false;
    while (loop.t < 61.0 + 300.0) {
      loop.tick();
      peak = std::fmax(peak, loop.body.omega.norm());
      slewed |= loop.out.telemetry.phase == ReferencePhase::kTrackSlew;
    }
    EXPECT_EQ(slewed, run == 1);
    EXPECT_LT((dcm(loop.body.mrp()) - dcm(p.guidance.q_final)).norm(), 5e-3) << run;
    EXPECT_LT(loop.body.omega.norm(), 1e-3) << run;
    fuel[run] = loop.out.telemetry.fuel_kg - fuel0;
    if (run == 1) {
      const M3 rel = dcm(q_end).transpose() * dcm(p.guidance.q_final);
      const double angle = std::acos(0.5 * (rel.trace() - 1.0));
      EXPECT_LT(peak, 1.2 * angle / (200.0 - 10.0));
    }
  }
  EXPECT_GT(fuel[0], 0.0);
  EXPECT_LT(fuel[1], 0.7 * fuel[0]);  // measured 0.55
}

}  // namespace
}  // namespace rocksteady::gnc
