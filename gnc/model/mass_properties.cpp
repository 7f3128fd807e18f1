#include "gnc/model/mass_properties.hpp"

namespace rocksteady::gnc {

Mat3 total_inertia(const MassProperties& mp) {
  const Vec3 r = mp.r_scm_so + mp.r_so_bcm;
  // Eq. (1)
  return mp.j_ast + mp.j_sc + mp.m_sc * (r.squaredNorm() * Mat3::Identity() - r * r.transpose());
}

MassProperties study_true_mass_properties() {
  MassProperties mp;
  mp.m_sc = 1.6e4;
  mp.r_scm_so = Vec3(0.0, 0.0, 3.0);
  mp.j_sc = 1e4 * Vec3(5.584, 5.584, 1.568).asDiagonal();
  mp.m_ast = 1.2e6;
  mp.j_ast << 0.8658, 0.4432, -0.0005,  //
      0.4432, 3.4900, 0.0002,           //
      -0.0005, 0.0002, 3.5579;
  mp.j_ast *= 1e7;
  mp.r_so_bcm = Vec3(-0.0495, -0.0004, 3.5456);
  return mp;
}

}  // namespace rocksteady::gnc
