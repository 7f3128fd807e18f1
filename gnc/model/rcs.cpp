#include "gnc/model/rcs.hpp"

#include <cmath>

#include "gnc/math/rotation.hpp"

namespace rocksteady::gnc {

RcsLayout study_rcs_layout(double u_max, double radius, double z) {
  RcsLayout l;
  constexpr double kPi = 3.14159265358979323846;
  for (int k = 0; k < kPods; ++k) {
    const double theta = kPi / 4.0 + kPi / 2.0 * k;  // 45, 135, 225, 315 deg
    l.pod_position[k] = Vec3(radius * std::cos(theta), radius * std::sin(theta), z);
    l.channel_direction[2 * k] = Vec3(-std::sin(theta), std::cos(theta), 0.0);  // tangential
    l.channel_direction[2 * k + 1] = Vec3(0.0, 0.0, 1.0);                       // axial
    l.channel_pod[2 * k] = k;
    l.channel_pod[2 * k + 1] = k;
  }
  l.u_max = u_max;
  return l;
}

Mat38 torque_matrix(const RcsLayout& layout, const Vec3& r_so_bcm) {
  Mat38 b;
  for (int i = 0; i < kChannels; ++i) {
    const Vec3 arm = r_so_bcm + layout.pod_position[layout.channel_pod[i]];
    b.col(i) = arm.cross(layout.channel_direction[i]);  // SPEC §4
  }
  return b;
}

}  // namespace rocksteady::gnc
