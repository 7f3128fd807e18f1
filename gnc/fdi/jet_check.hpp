// (F19) The jet check's firing: the minimum-norm change of the channel forces that moves channel
// c with no torque on the model, du = e_c - B^T (B B^T)^-1 B e_c (the projection of e_c on the
// kernel of B). The flight fires it (Gnc::apply_jet_check) and the detector rates it (F24).
#pragma once

#include <Eigen/Cholesky>

#include "gnc/types.hpp"

namespace rocksteady::gnc {

// du for channel c of the channels' torque matrix b, unscaled (du(c) in (0, 1]); false when B B^T
// cannot be factored or channel c has no kernel component (it lies in B's row space).
inline bool jet_check_move(const Mat38& b, int c, Vec8& du) {
  const Mat3 g = b * b.transpose();
  const Eigen::LDLT<Mat3> ldlt(g);
  if (ldlt.info() != Eigen::Success) return false;
  du = -(b.transpose() * ldlt.solve(Vec3(b.col(c))));
  du(c) += 1.0;
  return du(c) > 1e-6 && du.allFinite();
}

}  // namespace rocksteady::gnc
