// Allocation under failures: per-channel asymmetric bounds [lo_i, hi_i] and a known bias torque.
// Every single-thruster mask (16 stuck off, 16 stuck on with their bias, 16 degraded to half thrust,
// 4 pods behind a closed latch valve) against independent truths: the L1 linear program against a
// brute-force enumeration of its vertices; the pseudoinverse against a separately written least-squares solution (SVD); the
// authority each mask leaves against a Monte Carlo over torque directions. Plus the analysis of the
// three-pod configurations (rank, positive span, authority per axis), printed for the README.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "gnc/allocation/allocator.hpp"
#include "gnc/allocation/l1_allocation.hpp"
#include "gnc/model/mass_properties.hpp"
#include "gnc/model/rcs.hpp"
#include "heap_counter.hpp"

namespace {

using namespace rocksteady::gnc;
constexpr double kUMax = 200.0;

Mat38 study_b() {
  return torque_matrix(study_rcs_layout(kUMax), study_true_mass_properties().r_so_bcm);
}

// One failure case: a physical thruster i (= 2c for channel c's "+", 2c + 1 its "-") stuck off or
// stuck on, or a pod's latch valve closed. Written out from the words of the fault, independently
// of the flight code.
struct Mask {
  std::string name;
  AllocatorLimits limits;
};

std::vector<Mask> single_masks(const Mat38& b) {
  std::vector<Mask> out;
  for (int i = 0; i < 16; ++i) {
    const int c = i / 2;
    const bool plus = i % 2 == 0;
    Mask off{"thruster " + std::to_string(i) + " stuck off", nominal_limits(kUMax)};
    (plus ? off.limits.hi(c) : off.limits.lo(c)) = 0.0;  // that half of the channel is gone
    out.push_back(off);
    Mask on{"thruster " + std::to_string(i) + " stuck on", nominal_limits(kUMax)};
    (plus ? on.limits.hi(c) : on.limits.lo(c)) = 0.0;   // it is already at full thrust
    on.limits.bias = (plus ? 1.0 : -1.0) * kUMax * b.col(c);  // its torque, until the valve closes
    out.push_back(on);
    Mask weak{"thruster " + std::to_string(i) + " degraded x0.5", nominal_limits(kUMax)};
    (plus ? weak.limits.hi(c) : weak.limits.lo(c)) = (plus ? 0.5 : -0.5) * kUMax;
    out.push_back(weak);
  }
  for (int pod = 0; pod < 4; ++pod) {
    Mask closed{"pod " + std::to_string(pod) + " valve closed", nominal_limits(kUMax)};
    for (const int c : {2 * pod, 2 * pod + 1}) closed.limits.lo(c) = closed.limits.hi(c) = 0.0;
    out.push_back(closed);
  }
  return out;
}

// Brute force: at a vertex of min |u|_1 s.t. B u = tau, lo <= u <= hi, at least 5 channels sit at
// lo_i, 0 or hi_i and 3 columns solve for the rest. C(8,3) * 3^5 candidates.
struct BruteForce {
  double l1{std::numeric_limits<double>::infinity()};
  Vec8 u{Vec8::Zero()};
  int feasible{0};
};
BruteForce brute_force(const Mat38& b, const Vec8& lo, const Vec8& hi, const Vec3& tau) {
  BruteForce best;
  const double tol = 1e-9;
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
            const int pick = rest % 3;
            u(c) = pick == 0 ? lo(c) : pick == 1 ? 0.0 : hi(c);
            rest /= 3;
          }
          const Vec3 uf = lu.solve(tau - b * u);
          u(i) = uf(0);
          u(j) = uf(1);
          u(k) = uf(2);
          bool in = uf.allFinite();
          for (int c : {i, j, k}) in = in && u(c) >= lo(c) - tol && u(c) <= hi(c) + tol;
          if (!in || (b * u - tau).norm() > 1e-9 * (tau.norm() + kUMax * b.norm())) continue;
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

Vec8 random_in_box(std::mt19937& rng, const Vec8& lo, const Vec8& hi) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  Vec8 u;
  for (int i = 0; i < 8; ++i) u(i) = lo(i) + unit(rng) * (hi(i) - lo(i));
  return u;
}

TEST(FaultL1, EverySingleThrusterMaskMatchesBruteForceEnumeration) {
  const Mat38 b = study_b();
  L1Allocation lp;
  ASSERT_TRUE(lp.configure(b, kUMax));
  std::mt19937 rng(19);
  int solved = 0, max_iter = 0;
  for (const Mask& m : single_masks(b)) {
    for (int trial = 0; trial < 60; ++trial) {
      // Attainable torques: a random point of the box (interior and, every third trial, pushed to
      // the boundary so the optimum is constrained).
      Vec8 u0 = random_in_box(rng, m.limits.lo, m.limits.hi);
      if (trial % 3 == 0) u0 = u0.cwiseMax(m.limits.lo * 0.95).cwiseMin(m.limits.hi * 0.95) * 1.0;
      const Vec3 tau = b * u0;
      const L1Solution s = lp.solve(tau, m.limits.lo, m.limits.hi);
      const BruteForce bf = brute_force(b, m.limits.lo, m.limits.hi, tau);
      ASSERT_GT(bf.feasible, 0) << m.name;
      ASSERT_TRUE(s.ok) << m.name << " trial " << trial;
      max_iter = std::max(max_iter, static_cast<int>(s.iterations));
      EXPECT_LT((b * s.u - tau).norm(), 1e-7 * (1.0 + tau.norm())) << m.name;
      for (int c = 0; c < 8; ++c) {
        EXPECT_GE(s.u(c), m.limits.lo(c) - 1e-9) << m.name;
        EXPECT_LE(s.u(c), m.limits.hi(c) + 1e-9) << m.name;
      }
      EXPECT_NEAR(s.u.lpNorm<1>(), bf.l1, 1e-7 * (1.0 + bf.l1)) << m.name << " trial " << trial;
      ++solved;
    }
    // Torques out of reach: the LP says so (no certified solution), as the enumeration does.
    const Vec3 far = b * (m.limits.hi + m.limits.lo) * 0.5 + Vec3(1e5, -1e5, 1e5);
    EXPECT_FALSE(lp.solve(far, m.limits.lo, m.limits.hi).ok) << m.name;
    EXPECT_EQ(brute_force(b, m.limits.lo, m.limits.hi, far).feasible, 0) << m.name;
  }
  EXPECT_EQ(solved, 52 * 60);
  EXPECT_LE(max_iter, L1Allocation::kMaxIterations);
  std::printf("L1 under single-thruster masks: %d solves, max %d iterations (cap %d)\n", solved,
              max_iter, L1Allocation::kMaxIterations);
}

// Separately written least squares: the minimum-norm solution of B_S x = tau over a column set S,
// by a singular value decomposition (dynamic sizes: test code only).
Vec8 min_norm_ls(const Mat38& b, const std::vector<int>& cols, const Vec3& tau) {
  Eigen::MatrixXd bs(3, static_cast<int>(cols.size()));
  for (std::size_t k = 0; k < cols.size(); ++k) bs.col(static_cast<int>(k)) = b.col(cols[k]);
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(bs, Eigen::ComputeThinU | Eigen::ComputeThinV);
  svd.setThreshold(1e-9);
  const Eigen::VectorXd x = svd.solve(tau);
  Vec8 u = Vec8::Zero();
  for (std::size_t k = 0; k < cols.size(); ++k) u(cols[k]) = x(static_cast<int>(k));
  return u;
}

TEST(FaultPinv, EveryMaskIsTheMinimumNormSolutionOnItsChannelsAndKeepsDirection) {
  const Mat38 b = study_b();
  Allocator alloc;
  ASSERT_TRUE(alloc.configure(b, kUMax));
  std::mt19937 rng(7);
  std::normal_distribution<double> n(0.0, 1.0);
  int exact = 0, saturated = 0;
  for (const Mask& m : single_masks(b)) {
    for (int trial = 0; trial < 200; ++trial) {
      const double size = trial % 2 == 0 ? 50.0 : 3000.0;  // small (exact) and saturating requests
      const Vec3 u_c = Vec3(n(rng), n(rng), n(rng)) * size + m.limits.bias;
      Vec8 u;
      AllocatorStatus st;
      alloc.allocate(u_c, m.limits, u, st);
      ASSERT_TRUE(u.allFinite()) << m.name;
      EXPECT_EQ(st.rank, 3) << m.name;
      EXPECT_FALSE(st.impossible) << m.name;
      for (int c = 0; c < 8; ++c) {
        EXPECT_GE(u(c), m.limits.lo(c) - 1e-9) << m.name;
        EXPECT_LE(u(c), m.limits.hi(c) + 1e-9) << m.name;
      }
      // The channels used: every two-sided one, and the one-sided ones the allocation kept.
      std::vector<int> s;
      for (int c = 0; c < 8; ++c) {
        const bool two = m.limits.lo(c) < 0.0 && m.limits.hi(c) > 0.0;
        const bool one = (m.limits.lo(c) < 0.0) != (m.limits.hi(c) > 0.0);
        if (two || (one && u(c) != 0.0)) s.push_back(c);
      }
      const Vec3 tau = u_c - m.limits.bias;
      const Vec8 ls = st.scale * min_norm_ls(b, s, tau);
      EXPECT_LT((u - ls).norm(), 1e-8 * (1.0 + ls.norm())) << m.name << " trial " << trial;
      // Achieved = B u + bias; unsaturated it is the request, saturated it keeps the direction of
      // the channels' torque.
      EXPECT_LT((st.torque_achieved - (b * u + m.limits.bias)).norm(), 1e-9 * (1.0 + u_c.norm()));
      EXPECT_LT((st.shortfall - (u_c - st.torque_achieved)).norm(), 1e-9 * (1.0 + u_c.norm()));
      const Vec3 made = b * u;
      if (!st.saturated) {
        EXPECT_LT((made - tau).norm(), 1e-8 * (1.0 + tau.norm())) << m.name;
        ++exact;
      } else {
        EXPECT_LT((made - st.scale * tau).norm(), 1e-8 * (1.0 + tau.norm())) << m.name;
        EXPECT_GT(made.dot(tau), 0.0);
        ++saturated;
      }
      // The two kinds make the same torque; L1 never spends more.
      Allocator l1;
      ASSERT_TRUE(l1.configure(b, kUMax, AllocatorKind::kL1));
      Vec8 v;
      AllocatorStatus sl;
      l1.allocate(u_c, m.limits, v, sl);
      EXPECT_FALSE(sl.l1_fallback) << m.name;
      EXPECT_LT((sl.torque_achieved - st.torque_achieved).norm(), 1e-7 * (1.0 + u_c.norm()));
      EXPECT_LE(v.lpNorm<1>(), u.lpNorm<1>() * (1.0 + 1e-9) + 1e-9);
      for (int c = 0; c < 8; ++c) {
        EXPECT_GE(v(c), m.limits.lo(c) - 1e-9) << m.name;
        EXPECT_LE(v(c), m.limits.hi(c) + 1e-9) << m.name;
      }
    }
  }
  EXPECT_GT(exact, 1000);
  EXPECT_GT(saturated, 1000);
}

TEST(FaultPinv, NominalLimitsAreTheStudysAllocationBitForBit) {
  const Mat38 b = study_b();
  std::mt19937 rng(11);
  std::normal_distribution<double> n(0.0, 1.0);
  for (const AllocatorKind kind : {AllocatorKind::kPseudoInverse, AllocatorKind::kL1}) {
    Allocator a;
    ASSERT_TRUE(a.configure(b, kUMax, kind));
    for (int trial = 0; trial < 500; ++trial) {
      const Vec3 u_c = Vec3(n(rng), n(rng), n(rng)) * (trial % 2 ? 100.0 : 3000.0);
      Vec8 u1, u2, u3;
      AllocatorStatus s1, s2, s3;
      a.allocate(u_c, u1, s1);
      a.allocate(u_c, AllocatorLimits{}, u2, s2);           // +-infinity: the whole channels
      a.allocate(u_c, nominal_limits(kUMax), u3, s3);
      EXPECT_EQ(u1, u2);
      EXPECT_EQ(u1, u3);
      EXPECT_EQ(s1.torque_achieved, s2.torque_achieved);
      EXPECT_EQ(s1.scale, s3.scale);
      EXPECT_EQ(s2.rank, 3);
      EXPECT_FALSE(s2.reduced_authority);
      EXPECT_EQ(s2.active_channels, 8);
    }
  }
}

TEST(FaultPinv, FewerThanThreeDirectionsGiveTheLeastSquaresTorqueAndNoChannelIsImpossible) {
  const Mat38 b = study_b();
  Allocator alloc;
  ASSERT_TRUE(alloc.configure(b, kUMax));
  std::mt19937 rng(5);
  std::normal_distribution<double> n(0.0, 1.0);
  // Two channels left (rank 2): the torque is the projection of the request on their plane.
  AllocatorLimits two = nominal_limits(kUMax);
  for (int c = 0; c < 8; ++c) {
    if (c != 1 && c != 3) two.lo(c) = two.hi(c) = 0.0;
  }
  for (int trial = 0; trial < 100; ++trial) {
    const Vec3 u_c = Vec3(n(rng), n(rng), n(rng)) * 20.0;
    Vec8 u;
    AllocatorStatus st;
    alloc.allocate(u_c, two, u, st);
    EXPECT_EQ(st.rank, 2);
    EXPECT_EQ(st.active_channels, 2);
    EXPECT_TRUE(st.reduced_authority);
    EXPECT_FALSE(st.impossible);
    const Vec8 ls = st.scale * min_norm_ls(b, {1, 3}, u_c);
    EXPECT_LT((u - ls).norm(), 1e-8 * (1.0 + ls.norm()));
    if (!st.saturated) {
      // Least squares: the shortfall is orthogonal to both remaining columns.
      EXPECT_LT(std::fabs(st.shortfall.dot(b.col(1))), 1e-8 * u_c.norm() * b.col(1).norm());
      EXPECT_LT(std::fabs(st.shortfall.dot(b.col(3))), 1e-8 * u_c.norm() * b.col(3).norm());
    }
  }
  // One channel left (rank 1): the torque is the projection of the request on its column, and the
  // pseudoinverse holds no spurious second direction (the closed-form eigenvalues of B_F B_F' put
  // the zero ones near 1e-8 of the largest).
  for (int c = 0; c < 8; ++c) {
    AllocatorLimits one = nominal_limits(kUMax);
    for (int k = 0; k < 8; ++k) {
      if (k != c) one.lo(k) = one.hi(k) = 0.0;
    }
    for (int trial = 0; trial < 20; ++trial) {
      const Vec3 u_c = Vec3(n(rng), n(rng), n(rng)) * 20.0;
      Vec8 u;
      AllocatorStatus st;
      alloc.allocate(u_c, one, u, st);
      EXPECT_EQ(st.rank, 1) << "channel " << c;
      EXPECT_EQ(st.active_channels, 1);
      const Vec8 ls = st.scale * min_norm_ls(b, {c}, u_c);
      EXPECT_LT((u - ls).norm(), 1e-8 * (1.0 + ls.norm())) << "channel " << c;
    }
  }
  // Nothing left: impossible, nothing fired, the bias is all there is.
  AllocatorLimits none = nominal_limits(kUMax);
  none.lo.setZero();
  none.hi.setZero();
  none.bias = Vec3(1, 2, 3);
  Vec8 u;
  AllocatorStatus st;
  alloc.allocate(Vec3(10, 0, 0), none, u, st);
  EXPECT_TRUE(st.impossible);
  EXPECT_TRUE(st.reduced_authority);
  EXPECT_EQ(st.rank, 0);
  EXPECT_EQ(u, Vec8::Zero());
  EXPECT_EQ(st.torque_achieved, Vec3(1, 2, 3));
  // NaN bounds take a channel out; bounds beyond u_max or of the wrong sign are clipped.
  AllocatorLimits odd = nominal_limits(kUMax);
  odd.lo(0) = std::nan("");
  odd.hi(1) = 1e9;
  odd.lo(2) = 50.0;  // a lower bound above zero means zero
  alloc.allocate(Vec3(3000, -2000, 500), odd, u, st);
  EXPECT_EQ(u(0), 0.0);
  EXPECT_LE(u(1), kUMax);
  EXPECT_GE(u(2), 0.0);
  EXPECT_EQ(st.active_channels, 7);
}

// Monte Carlo truth for the positive span: is every direction d attainable (tau = t d, t > 0 small,
// within the bounds)? Checked with the L1 program's feasibility on many directions; a spanning cone
// must pass them all, a non-spanning one fails on some.
bool all_directions_attainable(const Mat38& b, const Vec8& lo, const Vec8& hi, int n) {
  L1Allocation lp;
  if (!lp.configure(b, kUMax)) return false;
  std::mt19937 rng(3);
  std::normal_distribution<double> g(0.0, 1.0);
  for (int k = 0; k < n; ++k) {
    const Vec3 d = Vec3(g(rng), g(rng), g(rng)).normalized();
    if (!lp.solve(1.0 * d, lo, hi).ok) return false;
  }
  return true;
}

TEST(FaultAuthority, RankAndSpanOfEveryMaskAgreeWithMonteCarlo) {
  const Mat38 b = study_b();
  for (const Mask& m : single_masks(b)) {
    const Authority a = authority(b, m.limits.lo, m.limits.hi);
    EXPECT_EQ(a.rank, 3) << m.name;
    EXPECT_EQ(a.spans, all_directions_attainable(b, m.limits.lo, m.limits.hi, 3000)) << m.name;
  }
  // Cones that do not span: every channel one-sided and pushing "+" only.
  Vec8 lo = Vec8::Zero(), hi = Vec8::Constant(kUMax);
  const Authority plus_only = authority(b, lo, hi);
  EXPECT_EQ(plus_only.spans, all_directions_attainable(b, lo, hi, 3000));
  // Three channels, one of them one-sided: rank 3 but only a half-space of torques at best.
  lo = Vec8::Zero();
  hi = Vec8::Zero();
  lo(0) = -kUMax, hi(0) = kUMax, lo(3) = -kUMax, hi(3) = kUMax, hi(5) = kUMax;
  const Authority three = authority(b, lo, hi);
  EXPECT_EQ(three.rank, 3);
  EXPECT_FALSE(three.spans);
  EXPECT_FALSE(all_directions_attainable(b, lo, hi, 3000));
}

// With every active channel two-way the generators are +-B_i, so the cone spans R^3 exactly when
// the rank is 3 (authority() takes that without the pair test): every subset of two-way
// channels, against the Monte Carlo truth.
TEST(FaultAuthority, TwoWayChannelsSpanExactlyWhenTheyHaveRankThree) {
  const Mat38 b = study_b();
  int spanning = 0, not_spanning = 0;
  for (unsigned mask = 1; mask < 256; ++mask) {
    Vec8 lo = Vec8::Zero(), hi = Vec8::Zero();
    for (int c = 0; c < 8; ++c) {
      if ((mask >> c) & 1U) lo(c) = -kUMax, hi(c) = kUMax;
    }
    const Authority a = authority(b, lo, hi);
    const bool truth = all_directions_attainable(b, lo, hi, 400);
    EXPECT_EQ(a.spans, truth) << "channels " << mask;
    EXPECT_EQ(a.spans, a.rank == 3) << "channels " << mask;
    (truth ? spanning : not_spanning) += 1;
  }
  EXPECT_GT(spanning, 0);
  EXPECT_GT(not_spanning, 0);
}

// The rank authority() reports (and the pseudoinverse's free set uses) counts the eigenvalues of
// B_F B_F' above 1e-9 of the largest; a closed-form test takes rank 3 without the
// eigen-decomposition when it is certain. Against the singular values of B_F (SVD, independent):
// every subset of channels of the study's B, and of matrices whose columns lean out of a plane by
// a tilt that puts the smallest eigenvalue at 1e-5 ... 1e-13 of the largest, either side of the
// threshold and of the closed-form test's own bound.
TEST(FaultAuthority, RankOfEveryChannelSubsetAgreesWithTheSingularValues) {
  auto svd_rank = [](const Mat38& m) {
    const Eigen::JacobiSVD<Mat38> svd(m);
    const Vec3 s = svd.singularValues();  // descending
    if (!(s(0) > 0.0)) return 0;
    int r = 0;
    for (int i = 0; i < 3; ++i) r += s(i) * s(i) > 1e-9 * s(0) * s(0) ? 1 : 0;
    return r;
  };
  std::vector<Mat38> matrices{study_b()};
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> angle(0.0, 6.283185307179586);
  for (const double ratio : {1e-5, 1e-7, 3e-9, 1.2e-9, 0.8e-9, 1e-11, 1e-13}) {
    // Columns at random in-plane angles, tilted out of it by +-t: with unit in-plane parts and 8
    // columns, B B' has about 4 in-plane and 8 t^2 out of plane, so t^2 = ratio / 2.
    Mat38 m;
    const double t = std::sqrt(ratio / 2.0);
    for (int c = 0; c < 8; ++c) {
      const double a = angle(rng);
      m.col(c) = 150.0 * Vec3(std::cos(a), std::sin(a), (c % 2 == 0 ? t : -t));
    }
    matrices.push_back(m);
  }
  int full = 0, deficient = 0;
  for (const Mat38& b : matrices) {
    for (unsigned mask = 1; mask < 256; ++mask) {
      Vec8 lo = Vec8::Zero(), hi = Vec8::Zero();
      Mat38 b_f = Mat38::Zero();
      for (int c = 0; c < 8; ++c) {
        if ((mask >> c) & 1U) {
          lo(c) = -kUMax, hi(c) = kUMax;
          b_f.col(c) = b.col(c);
        }
      }
      const int truth = svd_rank(b_f);
      EXPECT_EQ(authority(b, lo, hi).rank, truth) << "channels " << mask;
      (truth == 3 ? full : deficient) += 1;
    }
  }
  EXPECT_GT(full, 0);
  EXPECT_GT(deficient, 0);
}

// Largest t with t d attainable within the bounds (bisection on the L1 program's feasibility).
double max_along(const Mat38& b, const Vec8& lo, const Vec8& hi, const Vec3& d) {
  L1Allocation lp;
  lp.configure(b, kUMax);
  double a = 0.0, z = 1e5;
  for (int k = 0; k < 80; ++k) {
    const double mid = 0.5 * (a + z);
    (lp.solve(mid * d, lo, hi).ok ? a : z) = mid;
  }
  return a;
}

// The three-pod analysis (SPEC §4 geometry, study r_SO/BCM, u_max = 200 N): one pod's valve closed
// leaves six channels; their rank, whether the cone of the 12 one-way thrust torques spans R^3, and
// the largest torque along each body axis before and after.
TEST(FaultAuthority, ThreePodsStillControlEveryAxisWithTheAuthorityPrinted) {
  const Mat38 b = study_b();
  const Vec8 lo = Vec8::Constant(-kUMax), hi = Vec8::Constant(kUMax);
  double full[6];
  for (int k = 0; k < 6; ++k) {
    const Vec3 d = (k % 2 == 0 ? 1.0 : -1.0) * Vec3::Unit(k / 2);
    full[k] = max_along(b, lo, hi, d);
    // An independent bound: the support function sum_i u_max |d' B_i| (attained when no other axis
    // needs cancelling).
    double support = 0.0;
    for (int c = 0; c < 8; ++c) support += kUMax * std::fabs(d.dot(b.col(c)));
    EXPECT_LE(full[k], support * (1.0 + 1e-9));
  }
  std::printf("all four pods: max torque +x %.1f -x %.1f +y %.1f -y %.1f +z %.1f -z %.1f N m\n",
              full[0], full[1], full[2], full[3], full[4], full[5]);
  for (int pod = 0; pod < 4; ++pod) {
    Vec8 l = lo, h = hi;
    for (const int c : {2 * pod, 2 * pod + 1}) l(c) = h(c) = 0.0;
    const Authority a = authority(b, l, h);
    EXPECT_EQ(a.active_channels, 6);
    EXPECT_EQ(a.rank, 3) << "pod " << pod;
    EXPECT_TRUE(a.spans) << "pod " << pod;
    EXPECT_TRUE(all_directions_attainable(b, l, h, 2000)) << "pod " << pod;
    double left[6];
    for (int k = 0; k < 6; ++k) {
      const Vec3 d = (k % 2 == 0 ? 1.0 : -1.0) * Vec3::Unit(k / 2);
      left[k] = max_along(b, l, h, d);
      EXPECT_GT(left[k], 0.0);
      EXPECT_LE(left[k], full[k] * (1.0 + 1e-9));
    }
    std::printf("pod %d closed: rank %d, cone of 12 one-way torques spans R^3: %s; max torque "
                "+x %.1f (%.0f%%) -x %.1f (%.0f%%) +y %.1f (%.0f%%) -y %.1f (%.0f%%) +z %.1f (%.0f%%) "
                "-z %.1f (%.0f%%) N m\n",
                pod, a.rank, a.spans ? "yes" : "no", left[0], 100 * left[0] / full[0], left[1],
                100 * left[1] / full[1], left[2], 100 * left[2] / full[2], left[3],
                100 * left[3] / full[3], left[4], 100 * left[4] / full[4], left[5],
                100 * left[5] / full[5]);
  }
}

TEST(FaultAllocation, AllocateUnderLimitsNeverTouchesTheHeap) {
  const Mat38 b = study_b();
  Allocator l1, pinv;
  ASSERT_TRUE(l1.configure(b, kUMax, AllocatorKind::kL1));
  ASSERT_TRUE(pinv.configure(b, kUMax));
  const std::vector<Mask> masks = single_masks(b);
  std::mt19937 rng(9);
  std::normal_distribution<double> n(0.0, 1.0);
  std::vector<Vec3> requests(300);
  for (Vec3& r : requests) r = Vec3(n(rng), n(rng), n(rng)) * 2000.0;
  Vec8 u;
  AllocatorStatus st;
  double sink = 0.0;
  long counted = 0;
  {
    rocksteady::test::HeapArmed armed;
    for (std::size_t k = 0; k < requests.size(); ++k) {
      const AllocatorLimits& lim = masks[k % masks.size()].limits;
      l1.allocate(requests[k], lim, u, st);
      sink += u.sum();
      pinv.allocate(requests[k], lim, u, st);
      sink += u.sum();
      sink += authority(b, lim.lo, lim.hi).rank;
    }
    counted = rocksteady::test::heap_allocations();
  }
  EXPECT_EQ(counted, 0);
  EXPECT_TRUE(std::isfinite(sink));
}

}  // namespace

// The allocator keeps the authority and the re-derived Eq. (53) of the last limit patterns (the
// Cortex-M7 tick budget). A cache must be invisible: a long-lived allocator fed the masks in an
// interleaved order (more patterns than it keeps, so entries are evicted and recomputed) gives
// bit for bit what a fresh allocator gives for each call, and so after configure() with another
// B_hat (nothing kept from the old one may be used).
TEST(FaultAllocation, KeptAuthorityAndMatricesAreBitIdenticalToAFreshAllocator) {
  const Mat38 b1 = study_b();
  const Mat38 b2 =
      torque_matrix(study_rcs_layout(kUMax), study_true_mass_properties().r_so_bcm + Vec3(0.4, -0.3, 0.2));
  const std::vector<Mask> masks = single_masks(b1);
  for (const AllocatorKind kind : {AllocatorKind::kPseudoInverse, AllocatorKind::kL1}) {
    Allocator kept;
    ASSERT_TRUE(kept.configure(b1, kUMax, kind));
    std::mt19937 rng(11);
    std::normal_distribution<double> n(0.0, 1.0);
    std::uniform_int_distribution<std::size_t> pick(0, masks.size() - 1);
    int compared = 0;
    for (int phase = 0; phase < 2; ++phase) {
      const Mat38& b = phase == 0 ? b1 : b2;
      if (phase == 1) {
        ASSERT_TRUE(kept.configure(b2, kUMax, kind));
      }
      for (int call = 0; call < 600; ++call) {
        // Runs of the same mask (hits) and jumps between masks (misses, evictions).
        std::size_t which = call % 3 == 0 ? pick(rng) : static_cast<std::size_t>(call / 3) % masks.size();
        // The last call before configure() and the first after it fly the same mask, so a kept
        // entry of the old B_hat would be found.
        if ((phase == 0 && call == 599) || (phase == 1 && call == 0)) which = 0;
        const Mask& m = masks[which];
        const Vec3 u_c = Vec3(n(rng), n(rng), n(rng)) * (call % 2 == 0 ? 50.0 : 3000.0);
        Vec8 u_kept, u_fresh;
        AllocatorStatus s_kept, s_fresh;
        kept.allocate(u_c, m.limits, u_kept, s_kept);
        Allocator fresh;
        ASSERT_TRUE(fresh.configure(b, kUMax, kind));
        fresh.allocate(u_c, m.limits, u_fresh, s_fresh);
        if (kind == AllocatorKind::kPseudoInverse) {
          ASSERT_EQ(u_kept, u_fresh) << m.name << " call " << call << " phase " << phase;
        } else {
          // L1: the LP's warm start differs between the two (by design), the optimum does not.
          ASSERT_LT((b * u_kept - b * u_fresh).norm(), 1e-7 * (1.0 + u_c.norm())) << m.name;
          ASSERT_NEAR(u_kept.lpNorm<1>(), u_fresh.lpNorm<1>(), 1e-7 * (1.0 + u_fresh.lpNorm<1>()));
        }
        ASSERT_EQ(s_kept.rank, s_fresh.rank) << m.name;
        ASSERT_EQ(s_kept.active_channels, s_fresh.active_channels) << m.name;
        ASSERT_EQ(s_kept.reduced_authority, s_fresh.reduced_authority) << m.name;
        ASSERT_EQ(s_kept.impossible, s_fresh.impossible) << m.name;
        ++compared;
      }
    }
    EXPECT_EQ(compared, 1200);
  }
}
