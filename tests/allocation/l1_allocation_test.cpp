// Fuel-optimal allocation, Eq. (52), against an independent truth: a brute-force enumeration of the
// LP's vertices (3 free channels, the other 5 at -u_max, 0 or +u_max). Also: the same torque as the
// rescaled pseudoinverse, Eq. (53), never more |u|_1, saturation, zero torque, parameter validation
// and the Gnc wiring.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <Eigen/LU>

#include "gnc/allocation/allocator.hpp"
#include "gnc/allocation/l1_allocation.hpp"
#include "gnc/gnc.hpp"
#include "gnc/model/mass_properties.hpp"
#include "gnc/model/rcs.hpp"
#include "gnc/params.hpp"

namespace {

using namespace rocksteady::gnc;

// Independent truth. Split u by sign orthant: on each piece Eq. (52) is a linear program whose
// optimum lies at a vertex, where at least 5 of the 8 channels sit on one of -u_max, 0, +u_max
// and the rest solve B u = tau with independent columns (extendable to 3 independent columns since
// rank B = 3). Enumerate C(8,3) * 3^5 = 13608 candidates, keep the feasible ones, take the least
// |u|_1.
struct BruteForce {
  double l1{std::numeric_limits<double>::infinity()};
  Vec8 u{Vec8::Zero()};
  int feasible{0};
};

BruteForce brute_force_l1(const Mat38& b, double u_max, const Vec3& tau) {
  BruteForce best;
  const double tol = 1e-12 * u_max;
  for (int i = 0; i < 8; ++i) {
    for (int j = i + 1; j < 8; ++j) {
      for (int k = j + 1; k < 8; ++k) {
        Mat3 bf;
        bf << b.col(i), b.col(j), b.col(k);
        const Eigen::FullPivLU<Mat3> lu(bf);
        if (lu.rank() < 3) continue;
        int others[5];
        int n = 0;
        for (int c = 0; c < 8; ++c) {
          if (c != i && c != j && c != k) others[n++] = c;
        }
        for (int code = 0; code < 243; ++code) {
          Vec8 u = Vec8::Zero();
          int rest = code;
          for (int c : others) {
            u(c) = static_cast<double>(rest % 3 - 1) * u_max;
            rest /= 3;
          }
          const Vec3 uf = lu.solve(tau - b * u);
          if (!uf.allFinite() || uf.lpNorm<Eigen::Infinity>() > u_max + tol) continue;
          u(i) = uf(0);
          u(j) = uf(1);
          u(k) = uf(2);
          // Guard against nearly singular triples: the candidate must really produce tau.
          if ((b * u - tau).norm() > 1e-10 * (tau.norm() + u_max * b.norm())) continue;
          ++best.feasible;
          if (u.lpNorm<1>() < best.l1) {
            best.l1 = u.lpNorm<1>();
            best.u = u;
          }
        }
      }
    }
  }
  return best;
}

struct Geometry {
  std::string name;
  Mat38 b;
  double u_max;
};

Mat38 study_b(const Vec3& com_error) {
  return torque_matrix(study_rcs_layout(200.0), study_true_mass_properties().r_so_bcm + com_error);
}

std::vector<Geometry> geometries() {
  std::vector<Geometry> g;
  g.push_back({"study", study_b(Vec3::Zero()), 200.0});
  // B_hat from a wrong centre of mass (the flight software's estimate): less symmetry.
  g.push_back({"study_com_error", study_b(Vec3(0.3, -0.2, 0.5)), 200.0});
  g.push_back({"small_umax", study_b(Vec3(-0.1, 0.05, 0.0)), 20.0});
  std::mt19937 rng(52);
  std::normal_distribution<double> n(0.0, 2.0);
  for (int s = 0; s < 2; ++s) {
    Mat38 b;
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 8; ++c) b(r, c) = n(rng);
    }
    g.push_back({"random" + std::to_string(s), b, 50.0 + 100.0 * s});
  }
  return g;
}

// Requests: random directions with magnitudes from well inside to far outside the pinv envelope,
// and structured ones (axes, single channel columns, sums of two columns) where ties and
// degeneracy are the rule.
std::vector<Vec3> requests(const Mat38& b, double u_max, unsigned seed) {
  std::vector<Vec3> r;
  std::mt19937 rng(seed);
  std::normal_distribution<double> n(0.0, 1.0);
  std::uniform_real_distribution<double> mag(-2.5, 0.7);  // log10 of the fraction of capacity
  const double cap = u_max * b.norm();
  for (int i = 0; i < 110; ++i) {
    const Vec3 d = Vec3(n(rng), n(rng), n(rng)).normalized();
    r.push_back(d * cap * std::pow(10.0, mag(rng)));
  }
  for (int a = 0; a < 3; ++a) {
    for (double s : {-1.0, 1.0}) {
      for (double f : {0.05, 0.4, 3.0}) r.push_back(s * f * cap * Vec3::Unit(a));
    }
  }
  for (int c = 0; c < 8; ++c) {
    r.push_back(0.5 * u_max * b.col(c));
    r.push_back(u_max * b.col(c) - 0.7 * u_max * b.col((c + 3) % 8));
  }
  return r;
}

class L1VsBruteForce : public ::testing::TestWithParam<Geometry> {};

TEST_P(L1VsBruteForce, OptimalFeasibleSameTorqueAndNeverMoreFuelThanPseudoinverse) {
  const Geometry& g = GetParam();
  Allocator pinv;
  Allocator l1;
  ASSERT_TRUE(pinv.configure(g.b, g.u_max));
  ASSERT_TRUE(l1.configure(g.b, g.u_max, AllocatorKind::kL1));
  EXPECT_EQ(l1.kind(), AllocatorKind::kL1);
  int saturated = 0;
  int strictly_better = 0;
  int max_iterations = 0;
  for (const Vec3& uc : requests(g.b, g.u_max, 11)) {
    Vec8 up, ul;
    AllocatorStatus sp, sl;
    pinv.allocate(uc, up, sp);
    l1.allocate(uc, ul, sl);
    const Vec3 target = sp.scale * uc;  // the torque the rescaled pseudoinverse achieves
    ASSERT_FALSE(sl.l1_fallback) << uc.transpose();
    max_iterations = std::max(max_iterations, static_cast<int>(sl.l1_iterations));
    // (1) B u = target torque.
    EXPECT_LE((g.b * ul - target).norm(), 1e-9 * target.norm()) << uc.transpose();
    // (2) |u_i| <= u_max.
    EXPECT_LE(ul.lpNorm<Eigen::Infinity>(), g.u_max);
    // (3) |u|_1 is the optimum of the vertex enumeration.
    const BruteForce truth = brute_force_l1(g.b, g.u_max, target);
    ASSERT_GT(truth.feasible, 0);
    EXPECT_NEAR(ul.lpNorm<1>(), truth.l1, 1e-9 * truth.l1) << uc.transpose();
    // (4) never more fuel than the pseudoinverse.
    EXPECT_LE(ul.lpNorm<1>(), up.lpNorm<1>() * (1.0 + 1e-12));
    if (ul.lpNorm<1>() < 0.999 * up.lpNorm<1>()) ++strictly_better;
    // The status reports what was achieved, and the pinv's saturation and scale.
    EXPECT_LE((sl.torque_achieved - g.b * ul).norm(), 1e-12 * (1.0 + target.norm()));
    EXPECT_EQ(sl.saturated, sp.saturated);
    EXPECT_EQ(sl.scale, sp.scale);
    EXPECT_EQ(sl.torque_requested, uc);
    if (sp.saturated) ++saturated;
  }
  // The sample covers saturation, and the LP does buy fuel back.
  EXPECT_GT(saturated, 10);
  EXPECT_GT(strictly_better, 50);
  EXPECT_LT(max_iterations, L1Allocation::kMaxIterations);
  std::printf("[ %s ] max simplex iterations %d (cap %d)\n", g.name.c_str(), max_iterations,
              L1Allocation::kMaxIterations);
}

// The anti-cycling rule on its own: Bland's pricing throughout reaches the same optimum.
TEST_P(L1VsBruteForce, BlandPricingAloneReachesTheOptimum) {
  const Geometry& g = GetParam();
  L1Allocation bland;
  ASSERT_TRUE(bland.configure(g.b, g.u_max, L1Allocation::Pricing::kBland));
  int max_iterations = 0;
  for (const Vec3& tau : requests(g.b, g.u_max, 12)) {
    // A torque every allocation can reach: the pseudoinverse's, rescaled to u_max if needed.
    const Vec8 pinv_u = g.b.transpose() * (g.b * g.b.transpose()).ldlt().solve(tau);
    const double peak = pinv_u.lpNorm<Eigen::Infinity>();
    const Vec3 target = peak > g.u_max ? Vec3(tau * (g.u_max / peak)) : tau;
    const L1Solution s = bland.solve(target);
    ASSERT_TRUE(s.ok) << tau.transpose();
    max_iterations = std::max(max_iterations, static_cast<int>(s.iterations));
    EXPECT_LE((g.b * s.u - target).norm(), 1e-9 * target.norm());
    EXPECT_LE(s.u.lpNorm<Eigen::Infinity>(), g.u_max);
    const BruteForce truth = brute_force_l1(g.b, g.u_max, target);
    EXPECT_NEAR(s.u.lpNorm<1>(), truth.l1, 1e-9 * truth.l1) << tau.transpose();
  }
  EXPECT_LT(max_iterations, L1Allocation::kMaxIterations);
  std::printf("[ %s ] Bland's rule alone: max simplex iterations %d\n", g.name.c_str(),
              max_iterations);
}

INSTANTIATE_TEST_SUITE_P(Geometries, L1VsBruteForce, ::testing::ValuesIn(geometries()),
                         [](const ::testing::TestParamInfo<Geometry>& i) { return i.param.name; });

TEST(L1Allocation, SaturatedRequestKeepsPseudoinverseDirectionAndMagnitude) {
  const Mat38 b = study_b(Vec3(0.1, 0.2, -0.3));
  Allocator pinv, l1;
  ASSERT_TRUE(pinv.configure(b, 200.0));
  ASSERT_TRUE(l1.configure(b, 200.0, AllocatorKind::kL1));
  std::mt19937 rng(5);
  std::normal_distribution<double> n(0.0, 1.0);
  for (int i = 0; i < 100; ++i) {
    const Vec3 uc = Vec3(n(rng), n(rng), n(rng)) * 2e4;  // far outside the envelope
    Vec8 up, ul;
    AllocatorStatus sp, sl;
    pinv.allocate(uc, up, sp);
    l1.allocate(uc, ul, sl);
    ASSERT_TRUE(sp.saturated);
    ASSERT_TRUE(sl.saturated);
    EXPECT_FALSE(sl.l1_fallback);
    const Vec3 achieved = b * ul;
    // Same direction as the request, same magnitude as the pseudoinverse's scaled torque.
    EXPECT_LT(achieved.normalized().cross(uc.normalized()).norm(), 1e-9);
    EXPECT_GT(achieved.dot(uc), 0.0);
    EXPECT_NEAR(achieved.norm(), (b * up).norm(), 1e-9 * achieved.norm());
    EXPECT_NEAR(achieved.norm(), sp.scale * uc.norm(), 1e-9 * achieved.norm());
    EXPECT_LE(ul.lpNorm<Eigen::Infinity>(), 200.0);
    EXPECT_LE(ul.lpNorm<1>(), up.lpNorm<1>() * (1.0 + 1e-12));
  }
}

TEST(L1Allocation, ZeroTorqueGivesZeroForces) {
  Allocator l1;
  ASSERT_TRUE(l1.configure(study_b(Vec3::Zero()), 200.0, AllocatorKind::kL1));
  Vec8 u = Vec8::Constant(1.0);
  AllocatorStatus st;
  l1.allocate(Vec3::Zero(), u, st);
  EXPECT_FALSE(st.l1_fallback);
  for (int i = 0; i < 8; ++i) EXPECT_EQ(u(i), 0.0);
  EXPECT_EQ(st.torque_achieved, Vec3::Zero());
  EXPECT_FALSE(st.saturated);
}

TEST(L1Allocation, SingleChannelTorqueUsesThatChannelWhenItIsCheapest) {
  // Closed form: a torque that one channel produces alone at force f costs |f|; any other
  // combination costs at least as much when the channel's column is not a cheaper combination of
  // the others. Checked against the enumeration, and the LP reaches that cost.
  const Mat38 b = study_b(Vec3::Zero());
  Allocator l1;
  ASSERT_TRUE(l1.configure(b, 200.0, AllocatorKind::kL1));
  for (int c = 0; c < 8; ++c) {
    const Vec3 tau = 120.0 * b.col(c);
    Vec8 u;
    AllocatorStatus st;
    l1.allocate(tau, u, st);
    EXPECT_LE(u.lpNorm<1>(), 120.0 * (1.0 + 1e-12));
    EXPECT_NEAR(u.lpNorm<1>(), brute_force_l1(b, 200.0, tau).l1, 1e-9 * 120.0);
    EXPECT_LE((b * u - tau).norm(), 1e-9 * tau.norm());
  }
}

TEST(L1Allocation, SolverAndAllocatorRejectBadConfiguration) {
  L1Allocation s;
  EXPECT_FALSE(s.configure(Mat38::Zero(), 200.0));
  EXPECT_FALSE(s.configure(study_b(Vec3::Zero()), 0.0));
  EXPECT_FALSE(s.configure(study_b(Vec3::Zero()), std::numeric_limits<double>::infinity()));
  // Unconfigured: never claims a solution.
  EXPECT_FALSE(s.solve(Vec3(1, 2, 3)).ok);
  ASSERT_TRUE(s.configure(study_b(Vec3::Zero()), 200.0));
  EXPECT_FALSE(s.solve(Vec3(std::nan(""), 0, 0)).ok);
  // An unattainable torque: phase 1 cannot drive the artificials to zero.
  EXPECT_FALSE(s.solve(Vec3(1e7, 0, 0)).ok);
  Allocator a;
  EXPECT_FALSE(a.configure(study_b(Vec3::Zero()), 200.0, static_cast<AllocatorKind>(2)));
}

TEST(L1Allocation, StringNames) {
  EXPECT_STREQ(to_string(AllocatorKind::kPseudoInverse), "pinv");
  EXPECT_STREQ(to_string(AllocatorKind::kL1), "l1");
}

TEST(AllocatorParams, DefaultIsPseudoinverseAndUnknownKindIsRejected) {
  GncParams p = study_gnc_params(200.0);
  EXPECT_EQ(p.allocator, AllocatorKind::kPseudoInverse);
  p.allocator = AllocatorKind::kL1;
  EXPECT_TRUE(validate(p).ok);
  p.allocator = static_cast<AllocatorKind>(7);
  const ParamCheck c = validate(p);
  EXPECT_FALSE(c.ok);
  EXPECT_STREQ(c.field, "allocator");
}

// The flight core flies the configured allocator: fed identical samples, a kL1 and a kPseudoInverse
// Gnc request the same torques and achieve the same torques, the kL1 forces are exactly those of a
// separately configured L1 allocator, and the on-board fuel estimate (Eq. 54) is lower.
TEST(AllocatorParams, GncFliesTheConfiguredAllocator) {
  GncParams pp = study_gnc_params(200.0);
  GncParams pl = pp;
  pl.allocator = AllocatorKind::kL1;
  Gnc gp, gl;
  ASSERT_TRUE(gp.init(pp).ok);
  ASSERT_TRUE(gl.init(pl).ok);
  Allocator reference;
  ASSERT_TRUE(reference.configure(torque_matrix(pl.rcs, pl.mass_hat.r_so_bcm), pl.rcs.u_max,
                                  AllocatorKind::kL1));
  GncCommands cmd;
  cmd.has_mode_request = true;
  cmd.mode_request = Mode::kDetumble;
  GncOutput op, ol;
  int active = 0;
  for (int k = 0; k < 200; ++k) {
    SensorSample s;
    s.t = 0.1 * k;
    const double a = 0.01 * k;
    s.gyro_rate = Vec3(0.02 * std::cos(a), -0.015, 0.03 * std::sin(a) + 0.005);
    s.gyro_valid = true;
    s.star_quat = Vec4(0.1 * std::sin(a), 0.05, 0.0, 1.0).normalized();
    s.star_valid = true;
    gp.step(s, cmd, op);
    gl.step(s, cmd, ol);
    cmd = GncCommands{};
    ASSERT_EQ(ol.telemetry.mode, op.telemetry.mode);
    if (!ol.command.enabled) continue;
    ++active;
    const Vec3& uc = ol.telemetry.alloc.torque_requested;
    EXPECT_LE((uc - op.telemetry.alloc.torque_requested).norm(), 1e-9 * uc.norm());
    EXPECT_LE((ol.telemetry.alloc.torque_achieved - op.telemetry.alloc.torque_achieved).norm(),
              1e-9 * uc.norm());
    Vec8 u;
    AllocatorStatus st;
    reference.allocate(uc, u, st);
    EXPECT_EQ(ol.command.force, u);
    EXPECT_FALSE(ol.telemetry.alloc.l1_fallback);
    EXPECT_LE(ol.command.force.lpNorm<1>(), op.command.force.lpNorm<1>() * (1.0 + 1e-12));
  }
  EXPECT_GT(active, 150);
  EXPECT_LT(ol.telemetry.fuel_kg, op.telemetry.fuel_kg);
  std::printf("on-board fuel over %d ticks: pinv %.4f kg, l1 %.4f kg\n", active,
              op.telemetry.fuel_kg, ol.telemetry.fuel_kg);
}

}  // namespace

namespace {

// Many requests without the enumeration: never a fallback, always feasible and never above the
// pseudoinverse's |u|_1; the iteration count stays well below the cap (recorded).
TEST(L1Allocation, ManyRequestsNoFallbackAndBoundedIterations) {
  const Mat38 b = study_b(Vec3(0.05, -0.1, 0.2));
  Allocator pinv, l1;
  ASSERT_TRUE(pinv.configure(b, 200.0));
  ASSERT_TRUE(l1.configure(b, 200.0, AllocatorKind::kL1));
  std::mt19937 rng(99);
  std::normal_distribution<double> n(0.0, 1.0);
  std::uniform_real_distribution<double> mag(-3.0, 0.8);
  const double cap = 200.0 * b.norm();
  int max_it = 0;
  long sum_it = 0;
  const int count = 20000;
  for (int i = 0; i < count; ++i) {
    const Vec3 uc = Vec3(n(rng), n(rng), n(rng)).normalized() * cap * std::pow(10.0, mag(rng));
    Vec8 up, ul;
    AllocatorStatus sp, sl;
    pinv.allocate(uc, up, sp);
    l1.allocate(uc, ul, sl);
    ASSERT_FALSE(sl.l1_fallback) << uc.transpose();
    ASSERT_LE((b * ul - sp.scale * uc).norm(), 1e-9 * sp.scale * uc.norm());
    ASSERT_LE(ul.lpNorm<Eigen::Infinity>(), 200.0);
    ASSERT_LE(ul.lpNorm<1>(), up.lpNorm<1>() * (1.0 + 1e-12));
    max_it = std::max(max_it, static_cast<int>(sl.l1_iterations));
    sum_it += sl.l1_iterations;
  }
  EXPECT_LT(max_it, L1Allocation::kMaxIterations);
  std::printf("simplex iterations over %d requests: mean %.2f, max %d (cap %d)\n", count,
              static_cast<double>(sum_it) / count, max_it, L1Allocation::kMaxIterations);
}

}  // namespace

namespace {

// Warm start: the same optimum as a cold start (and as the enumeration), from far fewer steps.
// Three torque histories: a slowly turning request (a despin), one whose sign flips every solve
// (HOLD answering noise), and random directions with random per-channel bounds (faults).
TEST(L1Allocation, WarmStartReachesTheColdOptimumFromThePreviousBasisOrItsMirror) {
  const Mat38 b = study_b(Vec3(0.05, -0.1, 0.2));
  const double u_max = 200.0;
  L1Allocation warm, cold;
  ASSERT_TRUE(warm.configure(b, u_max));
  ASSERT_TRUE(cold.configure(b, u_max));
  cold.set_warm_start(false);
  const double cap = u_max * b.norm();
  std::mt19937 rng(7);
  std::normal_distribution<double> n(0.0, 1.0);
  std::uniform_real_distribution<double> uni(0.0, 1.0);

  struct Totals {
    long warm_it{0}, cold_it{0};
    int warm_starts{0}, solves{0};
  };
  auto check = [&](const Vec3& tau, const Vec8& lo, const Vec8& hi, Totals& t, bool brute) {
    const L1Solution w = warm.solve(tau, lo, hi);
    const L1Solution c = cold.solve(tau, lo, hi);
    ASSERT_TRUE(c.ok) << tau.transpose();
    ASSERT_TRUE(w.ok) << tau.transpose();
    EXPECT_FALSE(c.warm);
    ASSERT_NEAR(w.u.lpNorm<1>(), c.u.lpNorm<1>(), 1e-9 * u_max);
    ASSERT_LE((b * w.u - tau).norm(), 1e-9 * (tau.norm() + 1.0));
    for (int i = 0; i < 8; ++i) {
      ASSERT_GE(w.u(i), lo(i) - 1e-9 * u_max);
      ASSERT_LE(w.u(i), hi(i) + 1e-9 * u_max);
    }
    if (brute) {
      const BruteForce bf = brute_force_l1(b, u_max, tau);
      ASSERT_GT(bf.feasible, 0);
      ASSERT_NEAR(w.u.lpNorm<1>(), bf.l1, 1e-7 * u_max);
    }
    t.warm_it += w.iterations;
    t.cold_it += c.iterations;
    t.warm_starts += w.warm ? 1 : 0;
    ++t.solves;
  };
  const Vec8 lo = Vec8::Constant(-u_max);
  const Vec8 hi = Vec8::Constant(u_max);

  // 1. A slowly turning request (1 degree per solve about a tilted axis), within the envelope.
  Totals turning;
  const Eigen::AngleAxisd step(M_PI / 180.0, Vec3(0.3, -0.5, 0.8).normalized());
  Vec3 tau = 0.2 * cap * Vec3(1.0, 0.4, -0.2).normalized();
  for (int k = 0; k < 720; ++k) {
    tau = step * tau;
    check(tau, lo, hi, turning, k % 40 == 0);
  }
  // 2. Alternating sign with a small random wander: the mirrored basis is optimal as it is.
  Totals flipping;
  Vec3 base = 0.05 * cap * Vec3(-0.2, 0.9, 0.4).normalized();
  for (int k = 0; k < 400; ++k) {
    base += 1e-3 * cap * Vec3(n(rng), n(rng), n(rng));
    check((k % 2 == 0 ? 1.0 : -1.0) * base, lo, hi, flipping, k % 40 == 0);
  }
  // 3. Random directions and magnitudes with random asymmetric bounds (some channels out).
  Totals faults;
  for (int k = 0; k < 600; ++k) {
    Vec8 l, h;
    for (int i = 0; i < 8; ++i) {
      const double r = uni(rng);
      l(i) = r < 0.1 ? 0.0 : -u_max * (r < 0.2 ? uni(rng) : 1.0);
      h(i) = r > 0.9 ? 0.0 : u_max * (r > 0.8 ? uni(rng) : 1.0);
    }
    // An attainable torque: one that some allowed forces produce.
    Vec8 f;
    for (int i = 0; i < 8; ++i) f(i) = l(i) + (h(i) - l(i)) * uni(rng);
    check(b * f, l, h, faults, false);
  }
  std::printf("warm starts / solves, mean steps warm vs cold: turning %d/%d %.2f vs %.2f; "
              "flipping %d/%d %.2f vs %.2f; random bounds %d/%d %.2f vs %.2f\n",
              turning.warm_starts, turning.solves, double(turning.warm_it) / turning.solves,
              double(turning.cold_it) / turning.solves, flipping.warm_starts, flipping.solves,
              double(flipping.warm_it) / flipping.solves, double(flipping.cold_it) / flipping.solves,
              faults.warm_starts, faults.solves, double(faults.warm_it) / faults.solves,
              double(faults.cold_it) / faults.solves);
  // Every solve after the first starts warm when the request turns or flips, and takes fewer
  // steps than from u = 0 (a flip needs none: the mirrored basis is already optimal).
  EXPECT_EQ(turning.warm_starts, turning.solves - 1);
  EXPECT_EQ(flipping.warm_starts, flipping.solves);
  EXPECT_LT(turning.warm_it * 3, turning.cold_it);
  EXPECT_LT(flipping.warm_it * 10, flipping.cold_it);
  EXPECT_GT(faults.warm_starts, faults.solves / 2);
  EXPECT_EQ(warm.start_counts().warm + warm.start_counts().cold,
            static_cast<std::uint32_t>(turning.solves + flipping.solves + faults.solves));
  EXPECT_EQ(cold.start_counts().warm, 0u);
}

// The mirrored basis: after solving tau, solving -tau needs no step at all and gives exactly the
// negated forces (the final solution is computed from the basis in ascending order).
TEST(L1Allocation, MirroredWarmStartSolvesTheOppositeTorqueWithoutAStep) {
  const Mat38 b = study_b(Vec3(0.3, -0.2, 0.5));
  L1Allocation l1;
  ASSERT_TRUE(l1.configure(b, 200.0));
  Vec8 f;
  f << 120.0, -40.0, 10.0, 0.0, -150.0, 60.0, 30.0, -90.0;
  const Vec3 tau = b * f;  // attainable
  const L1Solution a = l1.solve(tau);
  const L1Solution m = l1.solve(-tau);
  ASSERT_TRUE(a.ok);
  ASSERT_TRUE(m.ok);
  EXPECT_FALSE(a.warm);
  EXPECT_TRUE(m.warm);
  EXPECT_EQ(m.iterations, 0);
  EXPECT_LE((m.u + a.u).lpNorm<Eigen::Infinity>(), 1e-12 * 200.0);
  // configure() forgets the basis.
  ASSERT_TRUE(l1.configure(b, 200.0));
  EXPECT_FALSE(l1.solve(tau).warm);
}

}  // namespace
