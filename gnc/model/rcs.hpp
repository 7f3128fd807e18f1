// RCS geometry -> torque matrix B (SPEC §4), as data: pod positions, channel directions, u_max.
#pragma once

#include <array>

#include "gnc/types.hpp"

namespace rocksteady::gnc {

struct RcsLayout {
  // Pod positions p_k in F_S (relative to SO), metres.
  std::array<Vec3, kPods> pod_position{};
  // Unit force direction of each channel's "+" thruster, in F_S/F_B (same orientation).
  // Channel 2k: pod k tangential pair; channel 2k+1: pod k axial pair (SPEC §4).
  std::array<Vec3, kChannels> channel_direction{};
  std::array<int, kChannels> channel_pod{};  // which pod each channel belongs to
  double u_max{200.0};                        // per-channel force limit, N
  // Strength factor k_i of each physical thruster (index 2c "+", 2c+1 "-" of channel c): the force
  // it produces per newton commanded. 1 = as calibrated; the identifier's estimate once adopted.
  Vec16 strength{Vec16::Ones()};
};

// The SPEC §4 conceptual layout: pods at azimuth 45/135/225/315 deg, radius `radius`, plane z = `z`.
RcsLayout study_rcs_layout(double u_max, double radius = 2.5, double z = 3.0);

// Torque column B_i = (r_SO/BCM + p_k) x d_i.
Mat38 torque_matrix(const RcsLayout& layout, const Vec3& r_so_bcm);

}  // namespace rocksteady::gnc
