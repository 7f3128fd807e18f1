#include "gnc/allocation/allocator.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include <Eigen/LU>
#include <Eigen/Eigenvalues>

namespace rocksteady::gnc {

double torque_matrix_rcond(const Mat38& b) {
  const Mat3 bbt = b * b.transpose();
  if (!bbt.allFinite()) {
    return 0.0;
  }
  Eigen::SelfAdjointEigenSolver<Mat3> es;
  es.computeDirect(bbt, Eigen::EigenvaluesOnly);
  const double hi = es.eigenvalues().maxCoeff();
  const double lo = es.eigenvalues().minCoeff();
  return hi > 0.0 && lo > 0.0 ? lo / hi : 0.0;
}

AllocatorLimits nominal_limits(double u_max) {
  AllocatorLimits l;
  l.lo.setConstant(-u_max);
  l.hi.setConstant(u_max);
  l.bias.setZero();
  return l;
}

namespace {

// Tolerances of the failure-handling path.
constexpr double kRankTol = 1e-9;   // eigenvalue of B_F B_F' (relative to the largest) counted as 0
constexpr double kSignTol = 1e-12;  // |u_i| / u_max below this is zero (sign checks)
constexpr double kSpanTol = 1e-9;   // relative tolerance of the cone test
constexpr int kMaxPasses = kChannels;

// Eigen-decomposition of a symmetric 3x3 (closed form: no heap, no iteration count).
struct Sym3 {
  Mat3 v{Mat3::Identity()};
  Vec3 lambda{Vec3::Zero()};
};
Sym3 eig3(const Mat3& m) {
  Eigen::SelfAdjointEigenSolver<Mat3> es;
  es.computeDirect(m);
  return Sym3{es.eigenvectors(), es.eigenvalues()};
}

// The rank of m = b b' (symmetric positive semi-definite, eigenvalues l1 <= l2 <= l3): the number
// of eigenvalues above kRankTol l3. Decided in closed form from the invariants t = tr m = l1+l2+l3,
// e = l1 l2 + l1 l3 + l2 l3 and d = det m = l1 l2 l3 wherever they are conclusive, and by the
// eigenvalues only in between:
//   l3 <= t <= 3 l3;  l2 l3 <= e <= 3 l2 l3;  d / e <= l1 <= 3 d / e, so
//   e > 3 kRankTol t^2  => l2 > kRankTol l3,   e <= kRankTol t^2 / 9 => l2 <= kRankTol l3,
//   d > kRankTol t e    => l1 > kRankTol l3,   3 d <= kRankTol t e / 3 => l1 <= kRankTol l3.
// The closed-form eigenvalues of a 3x3 are accurate only to about 1e-8 of the largest, which made
// a single channel look like rank 2; the invariants are exact where it matters (a rank-deficient
// set of columns gives e or d at rounding level; d is used only while its rounding is far below
// the threshold). It also saves the eigen-decomposition on the tick
// a latch valve first closes (the Cortex-M7 budget).
int rank_of_gram(const Mat3& m) {
  const double t = m.trace();
  if (!(t > 0.0)) return 0;
  const double e = 0.5 * (t * t - (m * m).trace());
  const double d = m.determinant();
  int low2 = -1;  // l2 above the threshold: 1 yes, 0 no, -1 undecided
  if (e > 3.0 * kRankTol * t * t) low2 = 1;
  if (e <= kRankTol * t * t / 9.0) low2 = 0;
  if (low2 == 0) return 1;
  // d carries a rounding error of about 1e-16 t^3: compared with kRankTol t e only while e is
  // large enough for that to be far below the threshold.
  int low1 = -1;
  if (e > 1e-4 * t * t) {
    if (d > kRankTol * t * e) low1 = 1;
    if (3.0 * d <= kRankTol * t * e / 3.0) low1 = 0;
  }
  if (low2 == 1 && low1 >= 0) return 2 + low1;
  // In the band: the eigenvalues decide.
  const Sym3 e3 = eig3(m);
  const double top = e3.lambda.maxCoeff();
  int r = 0;
  for (int i = 0; i < 3; ++i) r += e3.lambda(i) > kRankTol * top ? 1 : 0;
  return std::max(r, 1);
}

// B_F B_F' for the columns of b in the mask (bit i: column i), summed column by column without
// forming B_F (the Cortex-M7 budget of the tick a latch valve first closes).
Mat3 gram_of(const Mat38& b, std::uint8_t cols) {
  Mat3 m = Mat3::Zero();
  for (int i = 0; i < kChannels; ++i) {
    if ((cols >> i) & 1U) m.noalias() += b.col(i) * b.col(i).transpose();
  }
  return m;
}

// Eq. (53) re-derived for the columns of b in the mask (the others zero): B_F' (B_F B_F')^+, the
// minimum-norm least-squares inverse (the right inverse when rank 3).
Mat83 pinv_of(const Mat38& b, std::uint8_t cols, int& rank) {
  const Mat3 m = gram_of(b, cols);
  rank = rank_of_gram(m);
  Mat3 inv = Mat3::Zero();
  if (rank == 3) {
    inv = m.inverse();  // as Eq. (53) in configure()
  } else if (rank > 0) {
    const Sym3 e = eig3(m);  // ascending: the rank largest eigenpairs span the columns
    for (int i = 3 - rank; i < 3; ++i) {
      inv += e.v.col(i) * e.v.col(i).transpose() / e.lambda(i);
    }
  }
  Mat83 out;
  for (int i = 0; i < kChannels; ++i) {
    if ((cols >> i) & 1U) {
      out.row(i) = (inv * b.col(i)).transpose();  // inv is symmetric: (b_i' inv)' = inv b_i
    } else {
      out.row(i).setZero();
    }
  }
  return out;
}

// The limits as the allocator uses them: within [-u_max, u_max] and their sign; NaN -> out.
void clip_limits(const AllocatorLimits& in, double u_max, Vec8& lo, Vec8& hi, Vec3& bias) {
  for (int i = 0; i < kChannels; ++i) {
    const double l = in.lo(i), h = in.hi(i);
    if (std::isnan(l) || std::isnan(h)) {
      lo(i) = hi(i) = 0.0;
      continue;
    }
    lo(i) = std::min(0.0, std::max(-u_max, l));
    hi(i) = std::max(0.0, std::min(u_max, h));
  }
  bias = in.bias.allFinite() ? in.bias : Vec3::Zero();
}

}  // namespace

Authority authority(const Mat38& b, const Vec8& lo, const Vec8& hi) {
  Authority a;
  std::uint8_t act = 0;
  // The one-way thrust torques the limits allow: +B_i where hi_i > 0, -B_i where lo_i < 0.
  std::array<Vec3, 2 * kChannels> gen{};
  int n = 0;
  for (int i = 0; i < kChannels; ++i) {
    const bool up = hi(i) > 0.0, down = lo(i) < 0.0;
    if (!(up || down) || !(b.col(i).norm() > 0.0)) continue;
    ++a.active_channels;
    act = static_cast<std::uint8_t>(act | (1U << i));
    if (up) gen[static_cast<std::size_t>(n++)] = b.col(i);
    if (down) gen[static_cast<std::size_t>(n++)] = -b.col(i);
  }
  a.rank = rank_of_gram(gram_of(b, act));
  if (a.rank < 3) return a;
  // Every active channel may push both ways (a closed pod, nominal limits): the generators come in
  // pairs +-B_i, so their cone is their span, R^3 at rank 3. The pair test below is only for
  // one-way channels (a failed half); it is 7-8 k Cortex-M7 instructions, on the tick an
  // isolation test first closes a pod.
  if (n == 2 * a.active_channels) {
    a.spans = true;
    return a;
  }
  // The cone of the generators is R^3 unless some y != 0 has y'g >= 0 for every generator g; the
  // extreme rays of that dual cone are orthogonal to two independent generators, so it is enough to
  // try y = +-(g_a x g_b) over the pairs.
  // The norms are computed once (the same values as computed in place: the Cortex-M7 budget of
  // the tick a new pattern first appears).
  std::array<double, 2 * kChannels> norm{};
  for (int j = 0; j < n; ++j) {
    norm[static_cast<std::size_t>(j)] = gen[static_cast<std::size_t>(j)].norm();
  }
  for (int p = 0; p < n; ++p) {
    for (int q = p + 1; q < n; ++q) {
      const Vec3& ga = gen[static_cast<std::size_t>(p)];
      const Vec3& gb = gen[static_cast<std::size_t>(q)];
      const Vec3 y = ga.cross(gb);
      const double ny = y.norm();
      if (!(ny > kSpanTol * norm[static_cast<std::size_t>(p)] * norm[static_cast<std::size_t>(q)])) {
        continue;
      }
      for (const double sign : {1.0, -1.0}) {
        bool separates = true;
        for (int j = 0; j < n && separates; ++j) {
          const Vec3& g = gen[static_cast<std::size_t>(j)];
          separates = sign * y.dot(g) >= -kSpanTol * ny * norm[static_cast<std::size_t>(j)];
        }
        if (separates) return a;  // a half-space holds every generator: spans is false
      }
    }
  }
  a.spans = true;
  return a;
}

const Mat83& Allocator::pinv_for(std::uint8_t free, int& rank) const {
  for (const PinvMemo& m : pinv_memo_) {
    if (m.valid && m.free == free) {
      rank = m.rank;
      return m.pinv;
    }
  }
  // Not kept: Eq. (53) for B_hat's free columns.
  PinvMemo& m = pinv_memo_[static_cast<std::size_t>(pinv_memo_next_)];
  pinv_memo_next_ = (pinv_memo_next_ + 1) % kPinvMemos;
  m.pinv = pinv_of(b_hat_, free, m.rank);
  m.free = free;
  m.valid = true;
  rank = m.rank;
  return m.pinv;
}

const char* to_string(AllocatorKind k) {
  switch (k) {
    case AllocatorKind::kPseudoInverse: return "pinv";
    case AllocatorKind::kL1: return "l1";
  }
  return "?";
}

bool Allocator::configure(const Mat38& b_hat, double u_max, AllocatorKind kind) {
  if (torque_matrix_rcond(b_hat) < 1e-12 || !(u_max > 0.0) ||
      static_cast<int>(kind) >= kAllocatorKindCount || !l1_.configure(b_hat, u_max)) {
    return false;
  }
  kind_ = kind;
  b_hat_ = b_hat;
  authority_memo_ = AuthorityMemo{};  // B_hat changed: nothing kept is valid
  pinv_memo_ = {};
  pinv_memo_next_ = 0;
  u_max_ = u_max;
  const Mat3 bbt = b_hat * b_hat.transpose();
  // Eq. (53): B' (B B')^-1. The 3x3 inverse is closed-form (fixed size, no solver workspace that
  // could reach the heap); B B' is SPD and well conditioned (validated rank).
  pinv_ = b_hat.transpose() * bbt.inverse();
  return true;
}

void Allocator::allocate(const Vec3& u_c, Vec8& u, AllocatorStatus& status) const {
  u = pinv_ * u_c;  // Eq. (53)
  status.torque_requested = u_c;
  const double peak = u.lpNorm<Eigen::Infinity>();
  if (peak > u_max_) {
    status.scale = u_max_ / peak;  // keeps the torque direction (SPEC §4)
    u *= status.scale;
    status.saturated = true;
  } else {
    status.scale = 1.0;
    status.saturated = false;
  }
  status.l1_fallback = false;
  status.l1_iterations = 0;
  if (kind_ == AllocatorKind::kL1) {
    // Eq. (52) for the torque the rescaled pseudoinverse achieves: attainable (that u attains it),
    // same direction and magnitude. Keep the pseudoinverse's forces if the LP cannot certify a
    // solution or (never expected) would spend more fuel.
    const L1Solution s = l1_.solve(status.scale * u_c);
    status.l1_iterations = s.iterations;
    if (s.ok && s.u.lpNorm<1>() <= u.lpNorm<1>() * (1.0 + 1e-12) + 1e-12 * u_max_) {
      u = s.u;
    } else {
      status.l1_fallback = true;
    }
  }
  status.torque_achieved = b_hat_ * u;
}

void Allocator::allocate(const Vec3& u_c, const AllocatorLimits& limits, Vec8& u,
                         AllocatorStatus& status) const {
  Vec8 lo, hi;
  Vec3 bias;
  clip_limits(limits, u_max_, lo, hi, bias);
  status.torque_requested = u_c;
  status.l1_fallback = false;
  status.l1_iterations = 0;
  if ((lo.array() == -u_max_).all() && (hi.array() == u_max_).all() && (bias.array() == 0.0).all()) {
    allocate(u_c, u, status);  // nominal: the study's allocation, bit for bit
    status.active_channels = kChannels;
    status.rank = 3;
    status.reduced_authority = false;
    status.impossible = false;
    status.shortfall = u_c - status.torque_achieved;
    return;
  }
  std::uint16_t pattern = 0;
  for (int i = 0; i < kChannels; ++i) {
    if (hi(i) > 0.0) pattern = static_cast<std::uint16_t>(pattern | (1U << (2 * i)));
    if (lo(i) < 0.0) pattern = static_cast<std::uint16_t>(pattern | (1U << (2 * i + 1)));
  }
  if (!authority_memo_.valid || authority_memo_.pattern != pattern) {
    authority_memo_.value = authority(b_hat_, lo, hi);
    authority_memo_.pattern = pattern;
    authority_memo_.valid = true;
  }
  const Authority auth = authority_memo_.value;
  status.active_channels = static_cast<std::uint8_t>(auth.active_channels);
  status.rank = static_cast<std::uint8_t>(auth.rank);
  status.reduced_authority = !auth.spans;
  status.impossible = auth.rank == 0;

  // The channels' torque: what u_c asks beyond the bias.
  const Vec3 tau = u_c - bias;
  u.setZero();
  std::array<bool, kChannels> free{};
  for (int i = 0; i < kChannels; ++i) free[static_cast<std::size_t>(i)] = lo(i) < hi(i);
  const double sign_tol = kSignTol * u_max_;
  int rank = 0;
  for (int pass = 0; pass < kMaxPasses; ++pass) {
    std::uint8_t free_bits = 0;
    for (int i = 0; i < kChannels; ++i) {
      if (free[static_cast<std::size_t>(i)]) {
        free_bits = static_cast<std::uint8_t>(free_bits | (1U << i));
      }
    }
    u = pinv_for(free_bits, rank) * tau;  // Eq. (53) for the free channels
    // A channel pushed the way its interval forbids (e.g. the "+" half of a failed thruster) stays
    // at zero; the others take over.
    bool changed = false;
    for (int i = 0; i < kChannels; ++i) {
      const auto k = static_cast<std::size_t>(i);
      if (!free[k]) continue;
      if ((u(i) > sign_tol && !(hi(i) > 0.0)) || (u(i) < -sign_tol && !(lo(i) < 0.0))) {
        free[k] = false;
        changed = true;
      }
    }
    if (!changed) break;
  }
  for (int i = 0; i < kChannels; ++i) {
    if (!free[static_cast<std::size_t>(i)]) u(i) = 0.0;
  }
  // Direction-preserving rescale into the box (SPEC §4's rescale, for asymmetric bounds).
  double scale = 1.0;
  for (int i = 0; i < kChannels; ++i) {
    if (u(i) > hi(i)) scale = std::min(scale, hi(i) / u(i));
    if (u(i) < lo(i)) scale = std::min(scale, lo(i) / u(i));
  }
  scale = std::max(0.0, scale);
  u *= scale;
  for (int i = 0; i < kChannels; ++i) u(i) = std::min(hi(i), std::max(lo(i), u(i)));  // rounding
  status.saturated = scale < 1.0;
  status.scale = scale;
  if (kind_ == AllocatorKind::kL1) {
    // Eq. (52) within the same bounds for the torque the pseudoinverse's forces make (attainable:
    // those forces attain it).
    const L1Solution s = l1_.solve(b_hat_ * u, lo, hi);
    status.l1_iterations = s.iterations;
    if (s.ok && s.u.lpNorm<1>() <= u.lpNorm<1>() * (1.0 + 1e-12) + 1e-12 * u_max_) {
      u = s.u;
    } else {
      status.l1_fallback = true;
    }
  }
  status.torque_achieved = b_hat_ * u + bias;
  status.shortfall = u_c - status.torque_achieved;
}

}  // namespace rocksteady::gnc
