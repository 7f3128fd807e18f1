// Thrust allocation: right pseudoinverse, Eq. (53), with a direction-preserving rescale at u_max,
// optionally followed by the fuel-optimal allocation of that same torque, Eq. (52); fuel flow,
// Eq. (54).
#pragma once

#include <cstdint>

#include "gnc/allocation/l1_allocation.hpp"
#include "gnc/types.hpp"

namespace rocksteady::gnc {

// Which allocation flies (SPEC §4). The pseudoinverse is the study's choice and the default.
enum class AllocatorKind : std::uint8_t {
  kPseudoInverse = 0,  // Eq. (53), rescaled at u_max
  kL1 = 1,             // Eq. (52) for the torque the rescaled Eq. (53) achieves
};
inline constexpr int kAllocatorKindCount = 2;
const char* to_string(AllocatorKind k);  // "pinv", "l1"

struct AllocatorStatus {
  Vec3 torque_requested{Vec3::Zero()};  // u_c
  Vec3 torque_achieved{Vec3::Zero()};   // B_hat u after the rescale
  bool saturated{false};                // the rescale was active this tick
  double scale{1.0};                    // u_max / |u|_inf when saturated, else 1
  // kL1 only: the linear program could not certify a solution and the pseudoinverse's forces flew.
  bool l1_fallback{false};
  std::uint16_t l1_iterations{0};  // kL1 only: simplex iterations, both phases
};

class Allocator {
 public:
  // Precomputes B_hat' (B_hat B_hat')^-1. Returns false if B_hat B_hat' is singular (rank < 3) or
  // the kind is unknown.
  bool configure(const Mat38& b_hat, double u_max,
                 AllocatorKind kind = AllocatorKind::kPseudoInverse);
  // Eq. (53) plus rescale; with kL1, then Eq. (52) for the same (rescaled) torque, so both kinds
  // achieve the same torque and kL1 never spends more |u|_1. Writes channel forces and the status.
  void allocate(const Vec3& u_c, Vec8& u, AllocatorStatus& status) const;
  AllocatorKind kind() const { return kind_; }
  const Mat38& b_hat() const { return b_hat_; }
  const Mat83& pinv() const { return pinv_; }
  double u_max() const { return u_max_; }

 private:
  Mat38 b_hat_{Mat38::Zero()};
  Mat83 pinv_{Mat83::Zero()};
  double u_max_{0.0};
  AllocatorKind kind_{AllocatorKind::kPseudoInverse};
  L1Allocation l1_{};
};

// Reciprocal condition number of B B' (0 when rank-deficient); used by parameter validation.
double torque_matrix_rcond(const Mat38& b);

// Eq. (54): fuel mass flow, kg/s, for channel forces u.
inline double fuel_rate(const Vec8& u, double isp_s, double g0) {
  return u.lpNorm<1>() / (isp_s * g0);
}

}  // namespace rocksteady::gnc
