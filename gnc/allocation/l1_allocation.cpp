#include "gnc/allocation/l1_allocation.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include <Eigen/LU>

namespace rocksteady::gnc {

namespace {

// Columns 0..7: u+ (B_hat columns), 8..15: u- (minus the columns), 16..18: phase-1 artificials.
// The problem is scaled so that every column entry is at most 1 and every bound is 0 or 1:
// x = u+- / u_max, torque / (u_max max|B_ij|).
constexpr int kStructural = 2 * kChannels;
constexpr int kVars = kStructural + 3;
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kCostTol = 1e-11;  // reduced-cost optimality tolerance (costs are 0 or 1)
constexpr double kPivotTol = 1e-9;  // smallest usable entry of B_b^-1 a_j in the ratio test
constexpr double kTieTol = 1e-12;   // ratios this close are ties (Bland: smallest index leaves)
constexpr double kFeasTol = 1e-9;   // bound and residual tolerance of the certified solution
constexpr double kDetTol = 1e-12;   // |det B_b| below this: the basis is treated as singular
constexpr int kDegenerateBeforeBland = 2;  // degenerate steps in a row before Bland's rule
constexpr int kMaxDualSteps = 12;  // dual simplex steps of a warm start before starting cold

struct Lp {
  const Mat38* a{nullptr};
  Vec3 art_sign{Vec3::Ones()};
  std::array<int, 3> basis{};
  std::array<bool, kVars> basic{};
  std::array<bool, kVars> upper{};  // a nonbasic variable sits at its upper bound
  std::array<double, kVars> ub{};
  int phase{1};
  int iterations{0};
  bool bland_only{false};
  // The basis solution of the current basis and nonbasic bounds (basic_solution), kept until a
  // pivot, a bound flip or a reload changes them: one solve computes it once per basis, not once
  // per caller. The torque is the same for the whole solve.
  bool solved{false};
  Mat3 binv;
  Vec3 xb;

  Vec3 column(int j) const {
    if (j < kChannels) return a->col(j);
    if (j < kStructural) return -a->col(j - kChannels);
    Vec3 e = Vec3::Zero();
    e(j - kStructural) = art_sign(j - kStructural);
    return e;
  }
  // Phase 1: minimise the artificials; phase 2: Eq. (52), the sum of u+ and u-.
  double cost(int j) const {
    const bool artificial = j >= kStructural;
    return (phase == 1) == artificial ? 1.0 : 0.0;
  }
};

// Basis inverse and the basic variables' values for the current nonbasic bounds. The u- columns
// are the u+ columns negated, so their terms are added (the same numbers as subtracting -a_j).
bool basic_solution(Lp& lp, const Vec3& tau, Mat3& binv, Vec3& xb) {
  if (!lp.solved) {
    Mat3 bb;
    for (int r = 0; r < 3; ++r) bb.col(r) = lp.column(lp.basis[static_cast<std::size_t>(r)]);
    bool invertible = false;
    double det = 0.0;
    bb.computeInverseAndDetWithCheck(lp.binv, det, invertible, kDetTol);
    if (!invertible) return false;
    Vec3 rhs = tau;
    for (int j = 0; j < kChannels; ++j) {
      const auto k = static_cast<std::size_t>(j);
      if (!lp.basic[k] && lp.upper[k]) rhs -= lp.ub[k] * lp.a->col(j);
    }
    for (int j = 0; j < kChannels; ++j) {
      const auto k = static_cast<std::size_t>(j + kChannels);
      if (!lp.basic[k] && lp.upper[k]) rhs += lp.ub[k] * lp.a->col(j);
    }
    lp.xb = lp.binv * rhs;
    lp.solved = true;
  }
  binv = lp.binv;
  xb = lp.xb;
  return xb.allFinite();
}

// v . a_i for the eight u+ columns; a u- column's product is the negative (v . (-a) is -(v . a)
// to the bit: the same products, negated, summed in the same order).
Vec8 column_products(const Lp& lp, const Vec3& v) {
  Vec8 p;
  for (int i = 0; i < kChannels; ++i) p(i) = v.dot(Vec3(lp.a->col(i)));
  return p;
}

// One simplex phase to optimality. False: iteration cap, singular basis or no bounded step.
bool run_phase(Lp& lp, const Vec3& tau) {
  int degenerate_run = 0;
  for (;;) {
    Mat3 binv;
    Vec3 xb;
    if (!basic_solution(lp, tau, binv, xb)) return false;
    Vec3 cb;
    for (int r = 0; r < 3; ++r) cb(r) = lp.cost(lp.basis[static_cast<std::size_t>(r)]);
    const Vec3 y = binv.transpose() * cb;  // simplex multipliers

    // Entering: Dantzig's rule (the largest reduced-cost violation, ties to the lowest index) while
    // steps make progress; Bland's rule (the lowest-index improving nonbasic) once a run of
    // degenerate steps starts, until a step makes progress again: the objective strictly decreases
    // between runs and Bland's rule cannot cycle within one, so the method terminates.
    // Artificials never re-enter.
    const bool bland = lp.bland_only || degenerate_run >= kDegenerateBeforeBland;
    const Vec8 ya = column_products(lp, y);
    int enter = -1;
    double violation = 0.0;
    for (int j = 0; j < kStructural; ++j) {
      const auto k = static_cast<std::size_t>(j);
      if (lp.basic[k] || !(lp.ub[k] > 0.0)) continue;  // a variable fixed at zero never enters
      const double d = lp.cost(j) - (j < kChannels ? ya(j) : -ya(j - kChannels));
      const double v = lp.upper[k] ? d : -d;  // > 0: moving off the bound lowers the cost
      if (v > kCostTol && v > violation) {
        enter = j;
        violation = v;
        if (bland) break;
      }
    }
    if (enter < 0) return true;  // optimal for this phase
    if (lp.iterations >= L1Allocation::kMaxIterations) return false;
    ++lp.iterations;

    const auto ke = static_cast<std::size_t>(enter);
    const double dir = lp.upper[ke] ? -1.0 : 1.0;  // the entering variable moves by dir * theta
    const Vec3 w = binv * lp.column(enter);        // x_B(theta) = x_B - dir theta w

    // Leaving: the smallest ratio; ties go to the lowest variable index (Bland).
    int leave_row = -1;
    bool leave_to_upper = false;
    double best = kInf;
    for (int r = 0; r < 3; ++r) {
      const int v = lp.basis[static_cast<std::size_t>(r)];
      const double g = dir * w(r);
      double t = kInf;
      bool to_upper = false;
      if (g > kPivotTol) {
        t = std::max(0.0, xb(r)) / g;
      } else if (g < -kPivotTol && lp.ub[static_cast<std::size_t>(v)] < kInf) {
        t = std::max(0.0, lp.ub[static_cast<std::size_t>(v)] - xb(r)) / -g;
        to_upper = true;
      } else {
        continue;
      }
      const bool tie = std::fabs(t - best) <= kTieTol;
      if ((!tie && t < best) ||
          (tie && leave_row >= 0 && v < lp.basis[static_cast<std::size_t>(leave_row)])) {
        best = tie ? std::min(t, best) : t;
        leave_row = r;
        leave_to_upper = to_upper;
      }
    }

    const double flip = lp.ub[ke];  // the entering variable reaches its other bound first
    degenerate_run = std::min(flip, best) <= kTieTol ? degenerate_run + 1 : 0;
    if (flip <= best + kTieTol) {
      if (!(flip < kInf)) return false;  // unbounded step (not reachable: all columns bounded)
      lp.upper[ke] = !lp.upper[ke];
      lp.solved = false;
      continue;
    }
    if (leave_row < 0) return false;
    const auto kr = static_cast<std::size_t>(leave_row);
    const auto kl = static_cast<std::size_t>(lp.basis[kr]);
    lp.basic[kl] = false;
    lp.upper[kl] = leave_to_upper;
    lp.basis[kr] = enter;
    lp.basic[ke] = true;
    lp.upper[ke] = false;
    lp.solved = false;
  }
}


// Largest bound violation of the basic variables, 0 when the basis is primal feasible.
double infeasibility(const Lp& lp, const Vec3& xb, int* row) {
  double worst = 0.0;
  for (int r = 0; r < 3; ++r) {
    const double ub = lp.ub[static_cast<std::size_t>(lp.basis[static_cast<std::size_t>(r)])];
    const double v = std::max(-xb(r), xb(r) - ub);
    if (v > worst) {
      worst = v;
      if (row != nullptr) *row = r;
    }
  }
  return worst > kFeasTol ? worst : 0.0;
}

// Bounded dual simplex (phase-2 costs) from a dual-feasible basis to a primal-feasible one: the
// most violated basic variable leaves to the bound it violates; the entering variable keeps every
// reduced cost's sign (smallest |d_j / alpha_j|, ties to the lowest index). True: primal feasible
// (phase 2 then certifies optimality). False: no entering variable (this basis proves the bounds
// cannot meet the torque), a singular basis or the iteration cap: the caller starts cold.
bool run_dual(Lp& lp, const Vec3& tau, int max_steps) {
  for (int step = 0;; ++step) {
    Mat3 binv;
    Vec3 xb;
    if (!basic_solution(lp, tau, binv, xb)) return false;
    int r = -1;
    if (infeasibility(lp, xb, &r) == 0.0) return true;
    if (step >= max_steps || lp.iterations >= L1Allocation::kMaxIterations) return false;
    const auto kr = static_cast<std::size_t>(r);
    const int leaving = lp.basis[kr];
    const bool to_upper = xb(r) > lp.ub[static_cast<std::size_t>(leaving)];
    Vec3 cb;
    for (int i = 0; i < 3; ++i) cb(i) = lp.cost(lp.basis[static_cast<std::size_t>(i)]);
    const Vec3 y = binv.transpose() * cb;
    const Vec3 row = binv.row(r).transpose();
    const Vec8 ra = column_products(lp, row);
    const Vec8 ya = column_products(lp, y);
    int enter = -1;
    double best = kInf;
    for (int j = 0; j < kStructural; ++j) {
      const auto k = static_cast<std::size_t>(j);
      if (lp.basic[k] || !(lp.ub[k] > 0.0)) continue;
      const bool plus = j < kChannels;
      const int c = plus ? j : j - kChannels;
      const double alpha = plus ? ra(c) : -ra(c);
      const double dir = lp.upper[k] ? -1.0 : 1.0;
      // x_r moves by -dir theta alpha: up (towards 0) when it is negative, down when above ub.
      const double move = -dir * alpha;
      if (!(to_upper ? move < -kPivotTol : move > kPivotTol)) continue;
      const double d = std::fabs(lp.cost(j) - (plus ? ya(c) : -ya(c)));
      const double ratio = d / std::fabs(alpha);
      if (ratio < best - kTieTol) {
        best = ratio;
        enter = j;
      }
    }
    if (enter < 0) return false;
    ++lp.iterations;
    const auto ke = static_cast<std::size_t>(enter);
    lp.basic[static_cast<std::size_t>(leaving)] = false;
    lp.upper[static_cast<std::size_t>(leaving)] = to_upper;
    lp.basis[kr] = enter;
    lp.basic[ke] = true;
    lp.upper[ke] = false;
    lp.solved = false;
  }
}

// The basis in ascending variable order: the final solution is computed from the same matrix
// whichever path (cold or warm) reached the basis, so both give the same numbers.
void sort_basis(Lp& lp) {
  auto& b = lp.basis;
  const auto before = b;
  if (b[0] > b[1]) std::swap(b[0], b[1]);
  if (b[1] > b[2]) std::swap(b[1], b[2]);
  if (b[0] > b[1]) std::swap(b[0], b[1]);
  if (b != before) lp.solved = false;  // the same basis in another column order
}

// The index of variable j in the problem for -tau: u+ and u- swap (their columns are each
// other's negatives), so a basis optimal for tau is, mirrored, optimal for -tau.
int mirrored(int j) { return j < kChannels ? j + kChannels : j - kChannels; }

}  // namespace

bool L1Allocation::configure(const Mat38& b_hat, double u_max, Pricing pricing) {
  const double s = b_hat.cwiseAbs().maxCoeff();
  if (!b_hat.allFinite() || !(s > 0.0) || !std::isfinite(u_max) || !(u_max > 0.0)) return false;
  b_scale_ = s;
  hint_.valid = false;
  stats_ = L1StartCounts{};
  b_scaled_ = b_hat / s;
  u_max_ = u_max;
  pricing_ = pricing;
  return true;
}

// Eq. (52): min |u|_1 s.t. B_hat u = tau, |u|_inf <= u_max.
L1Solution L1Allocation::solve(const Vec3& tau) const {
  return solve(tau, Vec8::Constant(-u_max_), Vec8::Constant(u_max_));
}

// Eq. (52) with per-channel bounds: u+_i in [0, hi_i], u-_i in [0, -lo_i].
L1Solution L1Allocation::solve(const Vec3& tau, const Vec8& lo, const Vec8& hi) const {
  L1Solution out;
  if (!(u_max_ > 0.0) || !tau.allFinite() || !lo.allFinite() || !hi.allFinite()) return out;
  const Vec3 tau_s = tau / (u_max_ * b_scale_);
  std::array<double, kStructural> bound{};
  for (int i = 0; i < kChannels; ++i) {
    bound[static_cast<std::size_t>(i)] = std::min(1.0, std::max(0.0, hi(i) / u_max_));
    bound[static_cast<std::size_t>(i + kChannels)] = std::min(1.0, std::max(0.0, -lo(i) / u_max_));
  }

  Lp lp;
  lp.a = &b_scaled_;
  lp.bland_only = pricing_ == Pricing::kBland;
  Mat3 binv;
  Vec3 xb;

  // Warm start: the previous solution's basis, or its mirror. The costs and B_hat are the same
  // from one solve to the next (only the torque and the bounds change), so that basis is still
  // dual feasible and the dual simplex takes it to a feasible one in a few steps; phase 2 then
  // certifies it exactly as it certifies a cold start.
  bool warm = false;
  if (warm_start_ && hint_.valid) {
    auto load = [&](bool mirror) {
      lp.solved = false;
      for (int j = 0; j < kVars; ++j) {
        const auto k = static_cast<std::size_t>(j);
        lp.basic[k] = false;
        lp.upper[k] = false;
        lp.ub[k] = j < kStructural ? bound[k] : 0.0;
      }
      for (int j = 0; j < kStructural; ++j) {
        const auto k = static_cast<std::size_t>(mirror ? mirrored(j) : j);
        lp.upper[k] = hint_.upper[static_cast<std::size_t>(j)] && lp.ub[k] > 0.0;
      }
      for (int r = 0; r < 3; ++r) {
        const int j = hint_.basis[static_cast<std::size_t>(r)];
        const int v = mirror ? mirrored(j) : j;
        lp.basis[static_cast<std::size_t>(r)] = v;
        lp.basic[static_cast<std::size_t>(v)] = true;
        lp.upper[static_cast<std::size_t>(v)] = false;
      }
      lp.phase = 2;
      return basic_solution(lp, tau_s, binv, xb) ? infeasibility(lp, xb, nullptr) : kInf;
    };
    const double as_is = load(false);
    bool mirror = false;
    if (as_is > 0.0) {
      const double flipped = load(true);
      mirror = flipped < as_is;
      if (!mirror) load(false);
    }
    warm = (mirror || as_is < kInf) && run_dual(lp, tau_s, kMaxDualSteps);
    ++(warm ? stats_.warm : stats_.cold);
  } else {
    ++stats_.cold;
  }

  if (!warm) {
    lp.solved = false;
    for (int i = 0; i < 3; ++i) lp.art_sign(i) = tau_s(i) < 0.0 ? -1.0 : 1.0;
    for (int j = 0; j < kVars; ++j) {
      const auto k = static_cast<std::size_t>(j);
      lp.basic[k] = j >= kStructural;
      lp.upper[k] = false;
      lp.ub[k] = j < kStructural ? bound[k] : kInf;
    }
    lp.basis = {kStructural, kStructural + 1, kStructural + 2};

    // Phase 1: from u = 0 with the artificials carrying the torque, to a feasible vertex.
    lp.phase = 1;
    const bool phase1 = run_phase(lp, tau_s);
    out.iterations = static_cast<std::uint16_t>(lp.iterations);
    if (!phase1) return out;
    if (!basic_solution(lp, tau_s, binv, xb)) return out;
    for (int r = 0; r < 3; ++r) {
      if (lp.basis[static_cast<std::size_t>(r)] >= kStructural && xb(r) > kFeasTol) return out;
    }
    // Artificials still basic (at zero: redundant-looking rows) are fixed at zero from now on.
    for (int j = kStructural; j < kVars; ++j) lp.ub[static_cast<std::size_t>(j)] = 0.0;
  }

  // Phase 2: Eq. (52).
  lp.phase = 2;
  const bool phase2 = run_phase(lp, tau_s);
  out.iterations = static_cast<std::uint16_t>(lp.iterations);
  out.warm = warm;
  if (!phase2) return out;
  sort_basis(lp);
  if (!basic_solution(lp, tau_s, binv, xb)) return out;

  std::array<double, kVars> x{};
  for (int j = 0; j < kVars; ++j) {
    const auto k = static_cast<std::size_t>(j);
    x[k] = lp.upper[k] ? lp.ub[k] : 0.0;
  }
  for (int r = 0; r < 3; ++r)
    x[static_cast<std::size_t>(lp.basis[static_cast<std::size_t>(r)])] = xb(r);
  for (int j = 0; j < kVars; ++j) {
    const double top = j < kStructural ? bound[static_cast<std::size_t>(j)] : 0.0;
    const double v = x[static_cast<std::size_t>(j)];
    if (!(v >= -kFeasTol && v <= top + kFeasTol)) return out;
  }
  Vec8 v;
  for (int i = 0; i < kChannels; ++i) {
    const double d = x[static_cast<std::size_t>(i)] - x[static_cast<std::size_t>(i + kChannels)];
    v(i) = std::min(bound[static_cast<std::size_t>(i)],
                    std::max(-bound[static_cast<std::size_t>(i + kChannels)], d));
  }
  if ((b_scaled_ * v - tau_s).lpNorm<Eigen::Infinity>() > kFeasTol) return out;
  out.u = u_max_ * v;
  out.ok = true;
  hint_.valid = true;
  for (int r = 0; r < 3; ++r) {
    const int j = lp.basis[static_cast<std::size_t>(r)];
    hint_.basis[static_cast<std::size_t>(r)] = j;
    if (j >= kStructural) hint_.valid = false;  // an artificial at zero: no basis to keep
  }
  for (int j = 0; j < kStructural; ++j) {
    hint_.upper[static_cast<std::size_t>(j)] = lp.upper[static_cast<std::size_t>(j)];
  }
  return out;
}

}  // namespace rocksteady::gnc
