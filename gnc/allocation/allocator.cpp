#include "gnc/allocation/allocator.hpp"

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

}  // namespace rocksteady::gnc
