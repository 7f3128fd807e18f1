// (F19) The jet check's firing: the minimum-norm change of the channel forces that moves channel
// c with no torque on the model, du = e_c - B^T (B B^T)^-1 B e_c (the projection of e_c on the
// kernel of B). The flight fires it (Gnc::apply_jet_check) and the detector rates it (F24).
// (F55) A channel that cannot move both ways (a half latched, its pod's valve closed) is held:
// its column is left out of B (B_f), so du is the projection on the kernel of B_f and du_j = 0 for
// it. Otherwise the least change asks such a channel for a little of its dead half, and the
// flight's scaling into the bounds (gamma = 0 there) leaves the check unflown.
#pragma once

#include <cstdint>

#include <Eigen/Cholesky>

#include "gnc/types.hpp"

namespace rocksteady::gnc {

// du for channel c of the channels' torque matrix b, unscaled (du(c) in (0, 1]), the channels of
// `held` (bit j: channel j; c itself is never held) left still; false when B_f B_f^T cannot be
// factored or channel c has no kernel component (it lies in B_f's row space).
inline bool jet_check_move(const Mat38& b, int c, Vec8& du, std::uint8_t held = 0) {
  Mat38 bf = b;
  for (int j = 0; j < kChannels; ++j) {
    if (j != c && ((held >> j) & 1u) != 0) bf.col(j).setZero();
  }
  const Mat3 g = bf * bf.transpose();
  const Eigen::LDLT<Mat3> ldlt(g);
  if (ldlt.info() != Eigen::Success) return false;
  if (held != 0 && !(ldlt.rcond() > 1e-9)) return false;  // the free channels span no 3-D torque
  du = -(bf.transpose() * ldlt.solve(Vec3(bf.col(c))));
  du(c) += 1.0;
  return du(c) > 1e-6 && du.allFinite();
}

}  // namespace rocksteady::gnc
