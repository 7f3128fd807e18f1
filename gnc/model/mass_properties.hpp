// Mass properties of the spacecraft + captured asteroid, SPEC Eq. (1).
// The plant holds a true instance, the flight software an estimated one: same type, two instances.
#pragma once

#include "gnc/types.hpp"

namespace rocksteady::gnc {

struct MassProperties {
  double m_sc{1.6e4};     // spacecraft mass, kg
  Vec3 r_scm_so{0, 0, 3.0};  // spacecraft CM relative to SO, in F_S (m)
  Mat3 j_sc{Mat3::Zero()};   // spacecraft inertia about its CM (kg m^2)
  double m_ast{1.2e6};    // asteroid mass, kg (for the record; Eq. (1) does not use it)
  Mat3 j_ast{Mat3::Zero()};  // asteroid inertia about the combined CM BCM (kg m^2)
  Vec3 r_so_bcm{Vec3::Zero()};  // SO relative to BCM (m)
};

// Eq. (1): J_tot = J_ast + J_sc + m_sc [ (r'r) I - r r' ],  r = r_SCM/SO + r_SO/BCM.
Mat3 total_inertia(const MassProperties& mp);

// The study's Table 2 values (SPEC §5): the true mass properties.
MassProperties study_true_mass_properties();

}  // namespace rocksteady::gnc
