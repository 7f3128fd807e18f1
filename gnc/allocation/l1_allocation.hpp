// Fuel-optimal thrust allocation, Eq. (52): min |u|_1 s.t. B_hat u = tau, |u|_inf <= u_max.
//
// An exact solver for this fixed-size linear program: a bounded-variable (upper-bounded) primal
// simplex over the split channels u = u+ - u-, 0 <= u+-_i <= u_max (16 columns, 3 equality rows),
// two phases (phase 1 drives three artificials out of the basis from u = 0), and an iteration cap.
// Pricing: Dantzig's rule while steps make progress, Bland's rule (lowest index enters, ties in the
// ratio test to the lowest index) through any run of degenerate steps, so it cannot cycle. The 3x3
// basis is re-inverted from its columns at every iteration (no drift of an updated inverse).
// Warm start (default on): B_hat and the costs do not change between solves, only the torque and
// the bounds, so the previous optimal basis (or its mirror, u+ <-> u-, for a torque of the other
// sign) stays dual feasible; a bounded dual simplex takes it to a primal-feasible basis and the
// same phase 2 certifies optimality. A warm start that fails (cap, singular, no entering column)
// starts cold. The final solution is computed from the basis in ascending order, so a warm and a
// cold start that reach the same vertex give the same numbers.
// Everything is fixed-size: no heap, no exceptions, no I/O, deterministic (the result depends on
// the previous solve only through which optimal vertex is found when the optimum is not unique).
//
// The caller chooses a torque that is attainable (Allocator uses the pseudoinverse's scaled torque,
// which is); `ok == false` means the solve could not certify a solution (iteration cap, singular
// basis, infeasible phase 1, or a residual check failed) and `u` must not be used.
#pragma once

#include <array>
#include <cstdint>

#include "gnc/types.hpp"

namespace rocksteady::gnc {

struct L1Solution {
  Vec8 u{Vec8::Zero()};         // channel forces, N
  bool ok{false};               // u is an optimal, feasible solution of Eq. (52)
  std::uint16_t iterations{0};  // simplex pivots and bound flips, both phases (and dual steps)
  bool warm{false};             // reached from the previous solve's basis (no phase 1)
};

// How solves started since configure().
struct L1StartCounts {
  std::uint32_t warm{0};
  std::uint32_t cold{0};
};

class L1Allocation {
 public:
  // Well above what the eight-channel problem needs (tests record the observed maximum: ~10 with
  // the default pricing, ~30 with Bland's rule alone).
  static constexpr int kMaxIterations = 64;

  enum class Pricing : std::uint8_t {
    kDantzigThenBland = 0,  // flight default: few iterations
    kBland = 1,             // Bland's rule throughout (slower; the anti-cycling rule, tested alone)
  };

  // Stores the scaled problem data. Returns false for a non-finite or zero B_hat or u_max <= 0
  // (rank is the caller's check: Allocator::configure and parameter validation).
  bool configure(const Mat38& b_hat, double u_max, Pricing pricing = Pricing::kDantzigThenBland);
  // Eq. (52) for the torque `tau` (N m).
  L1Solution solve(const Vec3& tau) const;
  // Eq. (52) with per-channel asymmetric bounds lo_i <= u_i <= hi_i (lo_i <= 0 <= hi_i, |.| <=
  // u_max; a channel with lo_i = hi_i = 0 is out): min |u|_1 s.t. B_hat u = tau.
  L1Solution solve(const Vec3& tau, const Vec8& lo, const Vec8& hi) const;
  // Warm start on (default) or off (every solve from u = 0; for comparison and tests). Turning it
  // on or off, and configure(), forget the previous basis.
  void set_warm_start(bool on) {
    warm_start_ = on;
    hint_.valid = false;
  }
  const L1StartCounts& start_counts() const { return stats_; }

 private:
  Mat38 b_scaled_{Mat38::Zero()};  // B_hat / b_scale_
  double b_scale_{1.0};            // max |B_hat_ij|, m
  double u_max_{0.0};
  Pricing pricing_{Pricing::kDantzigThenBland};
  bool warm_start_{true};
  // The last certified solution's basis (structural columns only) and which nonbasic columns sat
  // at their upper bound: the warm start's starting point, nothing else.
  struct Hint {
    bool valid{false};
    std::array<int, 3> basis{};
    std::array<bool, 2 * kChannels> upper{};
  };
  mutable Hint hint_{};
  mutable L1StartCounts stats_{};
};

}  // namespace rocksteady::gnc
