// Thrust allocation: right pseudoinverse, Eq. (53), with a direction-preserving rescale at u_max,
// and fuel flow, Eq. (54).
#pragma once

#include "gnc/types.hpp"

namespace rocksteady::gnc {

struct AllocatorStatus {
  Vec3 torque_requested{Vec3::Zero()};  // u_c
  Vec3 torque_achieved{Vec3::Zero()};   // B_hat u after the rescale
  bool saturated{false};                // the rescale was active this tick
  double scale{1.0};                    // u_max / |u|_inf when saturated, else 1
};

class Allocator {
 public:
  // Precomputes B_hat' (B_hat B_hat')^-1. Returns false if B_hat B_hat' is singular (rank < 3).
  bool configure(const Mat38& b_hat, double u_max);
  // Eq. (53) plus rescale; writes channel forces and the status.
  void allocate(const Vec3& u_c, Vec8& u, AllocatorStatus& status) const;
  const Mat38& b_hat() const { return b_hat_; }
  const Mat83& pinv() const { return pinv_; }
  double u_max() const { return u_max_; }

 private:
  Mat38 b_hat_{Mat38::Zero()};
  Mat83 pinv_{Mat83::Zero()};
  double u_max_{0.0};
};

// Reciprocal condition number of B B' (0 when rank-deficient); used by parameter validation.
double torque_matrix_rcond(const Mat38& b);

// Eq. (54): fuel mass flow, kg/s, for channel forces u.
inline double fuel_rate(const Vec8& u, double isp_s, double g0) {
  return u.lpNorm<1>() / (isp_s * g0);
}

}  // namespace rocksteady::gnc
