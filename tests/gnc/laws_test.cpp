// Each control law in closed loop with a test-only rigid-body propagator and a perfect model.
// Scaled-down body (J ~ 10 kg m^2) so that a run of many time constants takes milliseconds.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <functional>

#include "gnc/control/laws.hpp"
#include "gnc/math/rotation.hpp"
#include "gnc/params.hpp"
#include "rigid_body.hpp"

namespace rocksteady::gnc {
namespace {

Mat3 test_inertia() {
  Mat3 j;
  j << 10.0, 1.0, 0.5,  //
      1.0, 12.0, -0.3,  //
      0.5, -0.3, 15.0;
  return j;
}

double lambda_max(const Mat3& m) {
  Eigen::SelfAdjointEigenSolver<Mat3> es(m);
  return es.eigenvalues().maxCoeff();
}
double lambda_min(const Mat3& m) {
  Eigen::SelfAdjointEigenSolver<Mat3> es(m);
  return es.eigenvalues().minCoeff();
}

// A smooth MRP reference with analytic derivatives.
mrp::WithRates tracking_reference(double t) {
  mrp::WithRates r;
  r.q = Vec3(0.2 * std::sin(0.3 * t), 0.1 * std::sin(0.5 * t), 0.15 * std::cos(0.4 * t));
  r.q_dot = Vec3(0.06 * std::cos(0.3 * t), 0.05 * std::cos(0.5 * t), -0.06 * std::sin(0.4 * t));
  r.q_ddot =
      Vec3(-0.018 * std::sin(0.3 * t), -0.025 * std::sin(0.5 * t), -0.024 * std::cos(0.4 * t));
  return r;
}

ReferenceSample track_sample(double t, const Vec3& q) {
  ReferenceSample s;
  s.phase = ReferencePhase::kTrack;
  s.q = mrp::same_set_as(tracking_reference(t), q);
  return s;
}

ReferenceSample hold_sample(const Vec3& target, const Vec3& q) {
  ReferenceSample s;
  s.phase = ReferencePhase::kHold;
  s.q = mrp::same_set_as({target, Vec3::Zero(), Vec3::Zero()}, q);
  return s;
}

GncParams test_params(double k, double lambda) {
  GncParams p;
  p.dt = 1e-3;
  for (TrackingGains* g : {&p.ntcl, &p.el, &p.feedforward}) {
    g->k = k * Mat3::Identity();
    g->lambda = lambda * Mat3::Identity();
  }
  p.el.k = 16.0 * k * Mat3::Identity();  // Z'KZ >= K/16: the same worst-case rate as the others
  p.integral.k = k * Mat3::Identity();
  p.integral.lambda = lambda * Mat3::Identity();
  p.integral.k_i = 1.0 * Mat3::Identity();
  p.integral.integral_limit_nm = 10.0;
  p.adaptive.k = k * Mat3::Identity();
  p.adaptive.lambda = lambda * Mat3::Identity();
  p.adaptive.gamma = 200.0;
  p.so3.k = k * Mat3::Identity();
  p.so3.lambda = 4 * lambda * Mat3::Identity();
  p.dpd.k_d = 8.0 * Mat3::Identity();
  p.dpd.k_p = 4.0;
  return p;
}

struct Trace {
  std::vector<double> t, s_j;  // sqrt(s' J s)
  Vec3 final_q_err{Vec3::Zero()};
  Vec3 final_w_err{Vec3::Zero()};
};

// Runs law `law` with reference `ref_fn` for `duration` s at p.dt, the torque held over each step.
Trace run(ControlLaws& laws, LawId law, const GncParams& p, test::RigidBody& body, double duration,
          const std::function<ReferenceSample(double, const Vec3&)>& ref_fn,
          const Vec3& disturbance = Vec3::Zero(),
          const std::function<void(const ControlLaws&)>& each_step = nullptr) {
  Trace tr;
  const int n = static_cast<int>(duration / p.dt);
  for (int i = 0; i <= n; ++i) {
    const double t = i * p.dt;
    const Vec3 q = body.mrp();
    LawInput in{body.omega, q, ref_fn(t, q), false};
    RateReference rr;
    const Vec3 u = laws.compute(law, in, rr);
    const Vec3 s = body.omega - rr.omega_r;
    tr.t.push_back(t);
    tr.s_j.push_back(std::sqrt(s.dot(body.j * s)));
    if (each_step) each_step(laws);
    if (i == n) {
      tr.final_q_err = q - in.ref.q.q;
      tr.final_w_err = body.omega - mrp::z_inverse(in.ref.q.q) * in.ref.q.q_dot;
      break;
    }
    body.step(p.dt, u + disturbance);
  }
  return tr;
}

test::RigidBody tumbling_body() {
  test::RigidBody b;
  b.j = test_inertia();
  b.omega = Vec3(0.5, -0.3, 0.4);
  b.beta = test::axis_angle(Vec3(1, 1, -1), 0.8);
  return b;
}

// Theorem 1: with a perfect model, s = omega - omega_r contracts: sqrt(s'Js) decays at least as
// exp(-lambda_min(K_eff)/lambda_max(J) t). The theorem is for continuous time; the torque held over
// each 1 ms step leaves an O(dt) floor (~1e-4 here), so the bound is checked down to 1e-3 of s(0).
void expect_contraction(const Trace& tr, double rate) {
  int checked = 0;
  for (size_t i = 0; i < tr.t.size(); i += 50) {
    const double bound = tr.s_j[0] * std::exp(-rate * tr.t[i]);
    if (bound < 1e-3 * tr.s_j[0]) break;
    EXPECT_LE(tr.s_j[i], bound * (1.0 + 2e-3) + 1e-9) << "t = " << tr.t[i];
    ++checked;
  }
  EXPECT_GT(checked, 100);
  EXPECT_LT(tr.s_j.back(), 1e-3 * tr.s_j.front());  // and it did decay
}

class NtclFamily : public ::testing::TestWithParam<LawId> {};

TEST_P(NtclFamily, ConvergesAtLeastAtContractionRateWithPerfectModel) {
  const double k = 5.0, lambda = 0.5;
  const GncParams p = test_params(k, lambda);
  ControlLaws laws;
  laws.configure(law_gains(p), test_inertia(), p.dt);
  laws.reset_state();
  test::RigidBody body = tumbling_body();
  const Trace tr = run(laws, GetParam(), p, body, 40.0, track_sample);
  // Eq. (17): Z'K_l Z = k_l (1+|q|^2)^2/16 I >= k_l/16 I, and the test sets k_l = 16 k.
  const double k_eff = k;
  expect_contraction(tr, k_eff / lambda_max(test_inertia()));
  EXPECT_LT(tr.final_q_err.norm(), 1e-4);
  EXPECT_LT(tr.final_w_err.norm(), 1e-4);
}

TEST(NtclDiscreteFloor, HalvingTheStepHalvesTheResidual) {
  // The residual left by the zero-order hold is O(dt): it is the discretisation, not the law.
  double residual[2];
  for (int k = 0; k < 2; ++k) {
    GncParams p = test_params(5.0, 0.5);
    p.dt = k == 0 ? 2e-3 : 1e-3;
    ControlLaws laws;
    laws.configure(law_gains(p), test_inertia(), p.dt);
    laws.reset_state();
    test::RigidBody body = tumbling_body();
    const Trace tr = run(laws, LawId::kNtcl, p, body, 40.0, track_sample);
    residual[k] = *std::max_element(tr.s_j.end() - 2000 / (k + 1), tr.s_j.end());
  }
  EXPECT_NEAR(residual[0] / residual[1], 2.0, 0.2);
}

INSTANTIATE_TEST_SUITE_P(Laws, NtclFamily,
                         ::testing::Values(LawId::kNtcl, LawId::kNtclEl, LawId::kFeedforward),
                         [](const auto& param_info) { return std::string(to_string(param_info.param)); });

TEST(IntegralNtcl, RejectsConstantDisturbanceTorque) {
  const GncParams p = test_params(5.0, 0.5);
  const Vec3 d(0.3, -0.2, 0.25);
  const Vec3 target(0.1, -0.05, 0.2);
  auto hold = [&](double, const Vec3& q) { return hold_sample(target, q); };

  ControlLaws plain;
  plain.configure(law_gains(p), test_inertia(), p.dt);
  plain.reset_state();
  test::RigidBody b1 = tumbling_body();
  const Trace without = run(plain, LawId::kNtcl, p, b1, 150.0, hold, d);

  ControlLaws integral;
  integral.configure(law_gains(p), test_inertia(), p.dt);
  integral.reset_state();
  test::RigidBody b2 = tumbling_body();
  const Trace with = run(integral, LawId::kIntegral, p, b2, 150.0, hold, d);

  EXPECT_GT(without.final_q_err.norm(), 1e-2);  // the disturbance does push the plain law off
  EXPECT_LT(with.final_q_err.norm(), 1e-5);     // Theorem 2: the integral law rejects it
  EXPECT_LT(with.final_w_err.norm(), 1e-6);
  // At rest J wdot = 0 = u + d with u = -integral: the integrator ends holding exactly d.
  EXPECT_LT((integral.integral() - d).norm(), 1e-4);
}

TEST(IntegralNtcl, AntiWindupFreezesIntegratorWhileSaturated) {
  GncParams p = test_params(5.0, 0.5);
  ControlLaws laws;
  laws.configure(law_gains(p), test_inertia(), p.dt);
  laws.reset_state();
  LawInput in{Vec3(0.1, 0.2, -0.1), Vec3::Zero(), hold_sample(Vec3::Zero(), Vec3::Zero()), true};
  RateReference rr;
  for (int i = 0; i < 100; ++i) laws.compute(LawId::kIntegral, in, rr);
  EXPECT_EQ(laws.integral().norm(), 0.0);
  in.saturated_last = false;
  for (int i = 0; i < 1000000; ++i) laws.compute(LawId::kIntegral, in, rr);
  EXPECT_LE(laws.integral().lpNorm<Eigen::Infinity>(), p.integral.integral_limit_nm);
  EXPECT_NEAR(laws.integral().lpNorm<Eigen::Infinity>(), p.integral.integral_limit_nm, 1e-12);
}

TEST(So3Ntcl, ConvergesFrom170Degrees) {
  const GncParams p = test_params(5.0, 0.5);
  ControlLaws laws;
  laws.configure(law_gains(p), test_inertia(), p.dt);
  laws.reset_state();
  test::RigidBody body;
  body.j = test_inertia();
  body.beta = test::axis_angle(Vec3(0.3, -1, 0.6), 170.0 * M_PI / 180.0);
  auto angle = [](const test::RigidBody& b) { return 2 * std::acos(std::min(1.0, std::fabs(b.beta.w()))); };
  EXPECT_NEAR(angle(body) * 180 / M_PI, 170.0, 1e-9);
  auto hold = [&](double, const Vec3& q) { return hold_sample(Vec3::Zero(), q); };
  run(laws, LawId::kSo3, p, body, 80.0, hold);
  EXPECT_LT(angle(body), 1e-5);
  EXPECT_LT(body.omega.norm(), 1e-5);
}

TEST(AdaptiveNtcl, StaysBoundedAndKeepsInertiaPositiveDefinite) {
  const GncParams p = test_params(5.0, 0.5);
  const Mat3 j_true = test_inertia();
  Mat3 j_hat = 1.4 * j_true;  // 40 % model error
  j_hat(0, 1) = j_hat(1, 0) = -2.0;
  ControlLaws laws;
  laws.configure(law_gains(p), j_hat, p.dt);
  laws.reset_state();
  Eigen::SelfAdjointEigenSolver<Mat3> es(j_hat);
  const double lo = p.adaptive.eig_floor_ratio * es.eigenvalues().minCoeff();
  const double hi = p.adaptive.eig_ceiling_ratio * es.eigenvalues().maxCoeff();
  double min_eig = 1e300, max_eig = 0.0;
  auto watch = [&](const ControlLaws& l) {
    const Mat3 ja = params_to_inertia(l.a_hat());
    min_eig = std::min(min_eig, lambda_min(ja));
    max_eig = std::max(max_eig, lambda_max(ja));
  };
  test::RigidBody body = tumbling_body();
  const Trace tr = run(laws, LawId::kAdaptive, p, body, 120.0, track_sample, Vec3::Zero(), watch);
  EXPECT_GE(min_eig, lo * (1 - 1e-9));
  EXPECT_LE(max_eig, hi * (1 + 1e-9));
  EXPECT_GT(min_eig, 0.0);
  for (double v : tr.s_j) EXPECT_LE(v, 2.0 * tr.s_j.front());  // bounded
  EXPECT_LT(tr.final_q_err.norm(), 1e-3);                        // and still tracks
  EXPECT_LT(tr.s_j.back(), 1e-2 * tr.s_j.front());
}

TEST(AdaptiveNtcl, ProjectionIsANearestPointMapIntoTheEigenvalueBox) {
  Mat3 j;
  j << 5.0, 4.0, 0.0,  //
      4.0, 5.0, 0.0,   //
      0.0, 0.0, -3.0;  // eigenvalues 9, 1, -3
  const Mat3 pj = project_inertia(j, 2.0, 8.0);
  Eigen::SelfAdjointEigenSolver<Mat3> es(pj);
  EXPECT_NEAR(es.eigenvalues()[0], 2.0, 1e-12);
  EXPECT_NEAR(es.eigenvalues()[1], 2.0, 1e-12);
  EXPECT_NEAR(es.eigenvalues()[2], 8.0, 1e-12);
  EXPECT_LT((project_inertia(pj, 2.0, 8.0) - pj).norm(), 1e-12);  // idempotent
  const Mat3 inside = test_inertia();
  EXPECT_LT((project_inertia(inside, 1.0, 100.0) - inside).norm(), 1e-12);
  // Regressor identity: Y a = J w_r_dot - S(J w) w_r.
  const Vec3 w(0.1, -0.4, 0.3), wr(0.2, 0.1, -0.5), wrd(-0.3, 0.6, 0.05);
  const Vec3 lhs = regressor(w, wr, wrd) * inertia_to_params(inside);
  EXPECT_LT((lhs - (inside * wrd - skew(inside * w) * wr)).norm(), 1e-13);
}

TEST(Dpd, DampsThenHoldsTargetAttitude) {
  const GncParams p = test_params(5.0, 0.5);
  ControlLaws laws;
  laws.configure(law_gains(p), test_inertia(), p.dt);
  laws.reset_state();
  test::RigidBody body = tumbling_body();
  ReferenceSample damp;
  damp.phase = ReferencePhase::kDamping;
  run(laws, LawId::kDpd, p, body, 20.0, [&](double, const Vec3&) { return damp; });
  EXPECT_LT(body.omega.norm(), 0.5 * 1e-2);  // Eq. (49) removed the tumble
  const Vec3 target(0.1, 0.2, -0.1);
  run(laws, LawId::kDpd, p, body, 80.0, [&](double, const Vec3& q) { return hold_sample(target, q); });
  EXPECT_LT((body.mrp() - target).norm(), 1e-5);  // Eq. (50) holds the target
}

TEST(RateReference, AnalyticDerivativeMatchesFiniteDifference) {
  // Along a smooth attitude path q(t) (from an omega(t) profile), compare omega_r_dot with
  // central differences of omega_r for both the MRP (Eq. 9) and SO(3) (Eq. 37) references.
  const Mat3 lambda = Vec3(0.5, 0.7, 0.9).asDiagonal();
  auto omega_at = [](double t) { return Vec3(0.2 * std::cos(t), -0.3 + 0.1 * t, 0.25 * std::sin(2 * t)); };
  // Propagate q with a fine RK4 so q(t+-h) are accurate.
  auto q_at = [&](double t_end) {
    Vec3 q(0.1, -0.2, 0.3);
    const int n = 20000;
    const double h = t_end / n;
    for (int i = 0; i < n; ++i) {
      const double t = i * h;
      const Vec3 k1 = mrp::rate(q, omega_at(t));
      const Vec3 k2 = mrp::rate(q + 0.5 * h * k1, omega_at(t + 0.5 * h));
      const Vec3 k3 = mrp::rate(q + 0.5 * h * k2, omega_at(t + 0.5 * h));
      const Vec3 k4 = mrp::rate(q + h * k3, omega_at(t + h));
      q += (h / 6) * (k1 + 2 * k2 + 2 * k3 + k4);
    }
    return q;
  };
  const double t = 1.3, h = 1e-4;
  const Vec3 qm = q_at(t - h), q0 = q_at(t), qp = q_at(t + h);
  for (bool so3 : {false, true}) {
    auto rr = [&](double tt, const Vec3& q) {
      const ReferenceSample ref = track_sample(tt, q);
      return so3 ? so3_rate_reference(q, omega_at(tt), ref, lambda)
                 : mrp_rate_reference(q, omega_at(tt), ref, lambda);
    };
    const Vec3 fd = (rr(t + h, qp).omega_r - rr(t - h, qm).omega_r) / (2 * h);
    EXPECT_LT((rr(t, q0).omega_r_dot - fd).norm(), 1e-7) << (so3 ? "so3" : "mrp");
  }
}

}  // namespace
}  // namespace rocksteady::gnc
