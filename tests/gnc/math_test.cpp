// Attitude math against independent truth: closed forms, finite differences, quaternion kinematics.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "gnc/math/rotation.hpp"
#include "rigid_body.hpp"

namespace rocksteady::gnc {
namespace {

std::vector<Vec3> sample_mrps(int n, double max_norm, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Vec3> out;
  while (static_cast<int>(out.size()) < n) {
    Vec3 q(u(rng), u(rng), u(rng));
    if (q.norm() <= max_norm) out.push_back(q);
  }
  return out;
}

TEST(Skew, CrossProductAndVee) {
  const Vec3 a(0.3, -1.2, 2.0), b(-0.7, 0.4, 1.1);
  EXPECT_LT((skew(a) * b - a.cross(b)).norm(), 1e-15);
  EXPECT_LT((vee(skew(a)) - a).norm(), 1e-15);
}

TEST(Mrp, ZTimesClosedFormInverseIsIdentity) {
  for (const Vec3& q : sample_mrps(200, 1.0, 1)) {
    EXPECT_LT((mrp::z_matrix(q) * mrp::z_inverse(q) - Mat3::Identity()).norm(), 1e-13);
    EXPECT_LT((mrp::z_inverse(q) - mrp::z_matrix(q).inverse()).norm(), 1e-11);
  }
}

TEST(Mrp, ZdotMatchesCentralFiniteDifference) {
  const double h = 1e-6;
  for (const Vec3& q0 : sample_mrps(50, 0.9, 2)) {
    const Vec3 qd(0.02, -0.05, 0.03);
    const Mat3 fd = (mrp::z_matrix(q0 + h * qd) - mrp::z_matrix(q0 - h * qd)) / (2 * h);
    EXPECT_LT((mrp::z_dot(q0, qd) - fd).norm(), 1e-9);
  }
}

TEST(Mrp, KinematicsMatchQuaternionKinematicsForTumblingBody) {
  // Torque-free tumbling body, propagated in quaternions (truth) and, from the same omega(t), in MRPs.
  test::RigidBody body;
  body.j = Vec3(10.0, 20.0, 30.0).asDiagonal();
  body.omega = Vec3(0.3, 0.1, -0.5);
  body.beta = test::axis_angle(Vec3(1, 2, 3), 0.4);
  Vec3 q = body.mrp();
  const double h = 1e-3;
  for (int i = 0; i < 60000; ++i) {  // 60 s, several full turns (the shadow switch happens)
    const Vec3 w0 = body.omega;
    const Vec3 q0 = q;
    test::RigidBody half = body;
    half.step(0.5 * h, Vec3::Zero());
    const Vec3 wm = half.omega;
    body.step(h, Vec3::Zero());
    const Vec3 w1 = body.omega;
    const Vec3 k1 = mrp::rate(q0, w0);
    const Vec3 k2 = mrp::rate(q0 + 0.5 * h * k1, wm);
    const Vec3 k3 = mrp::rate(q0 + 0.5 * h * k2, wm);
    const Vec3 k4 = mrp::rate(q0 + h * k3, w1);
    q = mrp::normalize(q0 + (h / 6) * (k1 + 2 * k2 + 2 * k3 + k4));
  }
  // Compare rotations (both sets describe the same attitude).
  const Mat3 r_truth = test::quat_to_matrix(body.beta);
  EXPECT_LT((mrp::to_dcm(q) - r_truth).norm(), 1e-8);
}

TEST(Mrp, ShadowSwitchPreservesRotation) {
  for (const Vec3& q : sample_mrps(100, 1.0, 3)) {
    if (q.norm() < 0.05) continue;
    const Vec3 s = mrp::shadow(q);
    EXPECT_LT((mrp::to_dcm(s) - mrp::to_dcm(q)).norm(), 1e-12);
    EXPECT_GE(s.norm(), 1.0 - 1e-12);
    EXPECT_LE(mrp::normalize(s).norm(), 1.0 + 1e-12);
    EXPECT_LT((mrp::normalize(s) - q).norm(), 1e-12);
  }
}

TEST(Mrp, ShadowWithRatesMatchesFiniteDifference) {
  // A smooth MRP path q(t); its shadow path s(t) differentiated numerically.
  auto path = [](double t) { return Vec3(0.6 * std::sin(t), 0.3 * std::cos(2 * t), 0.2 + 0.1 * t); };
  auto path_d = [](double t) { return Vec3(0.6 * std::cos(t), -0.6 * std::sin(2 * t), 0.1); };
  auto path_dd = [](double t) { return Vec3(-0.6 * std::sin(t), -1.2 * std::cos(2 * t), 0.0); };
  const double t = 0.7, h = 1e-5;
  const mrp::WithRates s = mrp::shadow_with_rates({path(t), path_d(t), path_dd(t)});
  const Vec3 sp = mrp::shadow(path(t + h)), sm = mrp::shadow(path(t - h));
  EXPECT_LT((s.q - mrp::shadow(path(t))).norm(), 1e-14);
  EXPECT_LT((s.q_dot - (sp - sm) / (2 * h)).norm(), 1e-7);
  const Vec3 s0 = mrp::shadow(path(t));
  EXPECT_LT((s.q_ddot - (sp - 2 * s0 + sm) / (h * h)).norm(), 1e-3);
}

TEST(Conversions, RoundTrip) {
  for (const Vec3& q : sample_mrps(100, 1.0, 4)) {
    const Vec4 b = mrp::to_quaternion(q);
    EXPECT_NEAR(b.norm(), 1.0, 1e-14);
    EXPECT_LT((mrp::from_quaternion(b) - q).norm(), 1e-12);
    EXPECT_LT((mrp::from_dcm(mrp::to_dcm(q)) - q).norm(), 1e-10);
    // Quaternion and MRP give the same matrix; the test model's matrix is independent code.
    EXPECT_LT((quat::to_dcm(b) - test::quat_to_matrix(b)).norm(), 1e-13);
    EXPECT_LT((mrp::to_dcm(q) - test::quat_to_matrix(b)).norm(), 1e-12);
    const Vec4 back = quat::from_dcm(quat::to_dcm(b));
    EXPECT_LT((back - b).norm(), 1e-12);
  }
}

TEST(Conversions, CompositionMatchesMatrixProduct) {
  const auto qs = sample_mrps(40, 1.0, 5);
  for (size_t i = 0; i + 1 < qs.size(); i += 2) {
    const Vec3 q12 = mrp::compose(qs[i], qs[i + 1]);
    EXPECT_LT((mrp::to_dcm(q12) - mrp::to_dcm(qs[i]) * mrp::to_dcm(qs[i + 1])).norm(), 1e-12);
    const Vec3 rel = mrp::relative(qs[i], qs[i + 1]);
    EXPECT_LT((mrp::to_dcm(rel) - mrp::to_dcm(qs[i + 1]).transpose() * mrp::to_dcm(qs[i])).norm(),
              1e-12);
  }
}

TEST(Quaternion, RateIsEquationThree) {
  const Vec4 b = test::axis_angle(Vec3(0.2, -1, 0.4), 1.1);
  const Vec3 w(0.1, 0.2, -0.3);
  EXPECT_LT((quat::rate(b, w) - test::quat_derivative(b, w)).norm(), 1e-15);
  // beta_dot = 1/2 beta (x) [w; 0]
  const Vec4 wq(w.x(), w.y(), w.z(), 0.0);
  EXPECT_LT((quat::rate(b, w) - 0.5 * quat::multiply(b, wq)).norm(), 1e-15);
}

TEST(So3, ErrorTermsMatchClosedFormsAndFiniteDifferences) {
  // Small rotation: e_R ~ theta/2, E ~ I/2 (Eqs. 35-36).
  const Vec3 axis = Vec3(1, -2, 0.5).normalized();
  const Mat3 r = test::quat_to_matrix(test::axis_angle(axis, 1e-4));
  const Vec3 e = so3::attitude_error(r, Mat3::Identity());
  EXPECT_LT((e - 0.5e-4 * axis).norm(), 1e-10);
  EXPECT_LT((so3::e_matrix(r, Mat3::Identity()) - 0.5 * Mat3::Identity()).norm(), 1e-4);
  // Exact: Q - Q' = 2 sin(theta) S(n), tr Q = 1 + 2 cos(theta), so
  // e_R = sin(theta) / sqrt(2 + 2 cos theta) n.
  const double th = 2.5;
  const Mat3 r2 = test::quat_to_matrix(test::axis_angle(axis, th));
  EXPECT_LT((so3::attitude_error(r2, Mat3::Identity()) -
             std::sin(th) / std::sqrt(2 + 2 * std::cos(th)) * axis)
                .norm(),
            1e-12);
  // Rates along R(t) = R0 exp(S(w) t), R_d(t) = exp(S(wd) t): Qdot = Q S(e_omega).
  const Vec3 w(0.3, -0.2, 0.5), wd(-0.1, 0.4, 0.2);
  auto rot = [](const Vec3& v, double t) {
    const double a = v.norm() * t;
    return test::quat_to_matrix(test::axis_angle(v, a));
  };
  const Mat3 r0 = test::quat_to_matrix(test::axis_angle(Vec3(0.3, 0.1, 1), 1.2));
  auto r_at = [&](double t) -> Mat3 { return r0 * rot(w, t); };
  auto rd_at = [&](double t) -> Mat3 { return rot(wd, t); };
  const double t = 0.8, h = 1e-6;
  const Mat3 rt = r_at(t), rdt = rd_at(t);
  const Vec3 e_omega = w - rt.transpose() * rdt * wd;
  const so3::ErrorRates er = so3::error_with_rates(rt, rdt, e_omega);
  const Vec3 fd_e = (so3::attitude_error(r_at(t + h), rd_at(t + h)) -
                     so3::attitude_error(r_at(t - h), rd_at(t - h))) /
                    (2 * h);
  const Mat3 fd_E =
      (so3::e_matrix(r_at(t + h), rd_at(t + h)) - so3::e_matrix(r_at(t - h), rd_at(t - h))) /
      (2 * h);
  EXPECT_LT((er.e_r_dot - fd_e).norm(), 1e-8);
  EXPECT_LT((er.e_dot - fd_E).norm(), 1e-8);
  // The known identity e_R_dot = E e_omega.
  EXPECT_LT((er.e_r_dot - er.e * e_omega).norm(), 1e-12);
}

}  // namespace
}  // namespace rocksteady::gnc
