// Thrust allocation: right pseudoinverse, Eq. (53), with a direction-preserving rescale at u_max,
// optionally followed by the fuel-optimal allocation of that same torque, Eq. (52); fuel flow,
// Eq. (54).
#pragma once

#include <array>
#include <cstdint>
#include <limits>

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

// What each channel may still do, and the torque nobody commands (failure handling). Per channel an
// asymmetric interval [lo_i, hi_i], lo_i <= 0 <= hi_i, of *effective* force (the force the channel's
// torque column B_i multiplies): a failed or isolated "+" thruster gives hi_i = 0, a pod behind a
// closed latch valve gives lo = hi = 0 on both its channels (the channel is out), a "+" thruster of
// strength k gives hi_i = k u_max (the caller divides by k when it commands that thruster).
// `bias` is a known torque the channels do not control, e.g. a stuck-on thruster's B_i u_max until
// its valve closes: the allocator makes B_hat u + bias ~ u_c. Bounds are clipped to the allocator's
// [-u_max, u_max] (so the default +-infinity means the whole channel) and to their sign
// (lo_i <= 0 <= hi_i); a NaN bound takes the channel out, a non-finite bias counts as zero.
struct AllocatorLimits {
  Vec8 lo{Vec8::Constant(-std::numeric_limits<double>::infinity())};  // N
  Vec8 hi{Vec8::Constant(std::numeric_limits<double>::infinity())};   // N
  Vec3 bias{Vec3::Zero()};                                            // N m
};
// Every channel whole, no bias: the limits of a healthy RCS at u_max.
AllocatorLimits nominal_limits(double u_max);

struct AllocatorStatus {
  Vec3 torque_requested{Vec3::Zero()};  // u_c
  Vec3 torque_achieved{Vec3::Zero()};   // B_hat u after the rescale, plus the limits' bias
  bool saturated{false};                // the rescale was active this tick
  double scale{1.0};                    // u_max / |u|_inf when saturated, else 1
  // kL1 only: the linear program could not certify a solution and the pseudoinverse's forces flew.
  bool l1_fallback{false};
  std::uint16_t l1_iterations{0};  // kL1 only: simplex iterations, both phases
  // Authority left by the limits (always full with nominal limits):
  std::uint8_t active_channels{kChannels};  // channels with lo_i < hi_i
  std::uint8_t rank{3};                     // rank of their torque columns
  // Some torque direction cannot be produced: rank < 3, or the cone of the usable one-way thrust
  // torques (+B_i where hi_i > 0, -B_i where lo_i < 0) does not span R^3. Control goes on with the
  // best achievable torque.
  bool reduced_authority{false};
  bool impossible{false};              // no channel left (rank 0): no control at all
  Vec3 shortfall{Vec3::Zero()};        // u_c - torque_achieved
};

// The authority the limits leave (independent of the torque asked): how many channels are active,
// the rank of their columns, and whether the cone of their one-way thrust torques spans R^3.
struct Authority {
  int active_channels{0};
  int rank{0};
  bool spans{false};  // every torque direction can be produced (full authority, in direction)
};
Authority authority(const Mat38& b, const Vec8& lo, const Vec8& hi);

class Allocator {
 public:
  // Precomputes B_hat' (B_hat B_hat')^-1. Returns false if B_hat B_hat' is singular (rank < 3) or
  // the kind is unknown.
  bool configure(const Mat38& b_hat, double u_max,
                 AllocatorKind kind = AllocatorKind::kPseudoInverse);
  // Eq. (53) plus rescale; with kL1, then Eq. (52) for the same (rescaled) torque, so both kinds
  // achieve the same torque and kL1 never spends more |u|_1. Writes channel forces and the status.
  void allocate(const Vec3& u_c, Vec8& u, AllocatorStatus& status) const;
  // The same under per-channel limits and a bias torque (failures): B_hat u + bias ~ u_c with
  // lo <= u <= hi. Eq. (53) re-derived for the active channels, B_F' (B_F B_F')^+ (least squares
  // when they span less than R^3); a channel whose force would take a sign its interval forbids is
  // set to zero and the rest re-solved (at most 8 passes); then the whole vector is scaled to fit
  // the box, which keeps the direction of the channels' torque u_c - bias. kL1: then Eq. (52) for
  // that torque within the same bounds. Nominal limits give exactly allocate(u_c, u, status).
  void allocate(const Vec3& u_c, const AllocatorLimits& limits, Vec8& u,
                AllocatorStatus& status) const;
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
  // Under limits, the authority and the re-derived Eq. (53) depend only on B_hat (fixed between
  // configure() calls) and on which channels may push which way, so they are kept for the last
  // patterns seen instead of being recomputed every tick (the Cortex-M7 tick budget: an eigen-
  // decomposition and the cone test per tick while a pod is isolated). Like the L1 warm-start
  // hint, a cache: results are bit-identical with or without it.
  struct AuthorityMemo {
    bool valid{false};
    std::uint16_t pattern{0};  // bit 2i: channel i may push +, bit 2i+1: may push -
    Authority value{};
  };
  static constexpr int kPinvMemos = 4;
  struct PinvMemo {
    bool valid{false};
    std::uint8_t free{0};  // bit i: channel i free
    int rank{0};
    Mat83 pinv{Mat83::Zero()};
  };
  mutable AuthorityMemo authority_memo_{};
  mutable std::array<PinvMemo, kPinvMemos> pinv_memo_{};
  mutable int pinv_memo_next_{0};
  // Eq. (53) for the channels whose bit is set in `free` (the others' columns zeroed), kept.
  const Mat83& pinv_for(std::uint8_t free, int& rank) const;
};

// Reciprocal condition number of B B' (0 when rank-deficient); used by parameter validation.
double torque_matrix_rcond(const Mat38& b);


// Eq. (54): fuel mass flow, kg/s, for channel forces u.
inline double fuel_rate(const Vec8& u, double isp_s, double g0) {
  return u.lpNorm<1>() / (isp_s * g0);
}

}  // namespace rocksteady::gnc
