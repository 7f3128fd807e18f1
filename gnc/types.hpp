// Fixed-size linear-algebra types of the flight core. No dynamic sizes anywhere in gnc/.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>  // cross products

namespace rocksteady::gnc {

using Vec3 = Eigen::Vector3d;
using Vec4 = Eigen::Vector4d;
using Vec6 = Eigen::Matrix<double, 6, 1>;
using Vec8 = Eigen::Matrix<double, 8, 1>;
using Mat3 = Eigen::Matrix3d;
using Mat38 = Eigen::Matrix<double, 3, 8>;
using Mat83 = Eigen::Matrix<double, 8, 3>;
using Mat36 = Eigen::Matrix<double, 3, 6>;

inline constexpr int kChannels = 8;  // SPEC §4: eight signed thruster channels
inline constexpr int kPods = 4;      // SPEC §4: four RCS pods
// Sixteen physical thrusters: thruster 2c fires channel c's "+" direction, 2c+1 its "-" (SPEC §4;
// with the default HAL wiring this is also the physical index 4 * pod + position).
inline constexpr int kThrusters = 2 * kChannels;

using Vec16 = Eigen::Matrix<double, kThrusters, 1>;
using Vec21 = Eigen::Matrix<double, 21, 1>;  // a packed symmetric 6 x 6 (pack_upper)

// The upper triangle of a symmetric N x N matrix row by row ((0,0) (0,1) ... (0,N-1) (1,1) ...),
// and back: telemetry carries a covariance in N (N + 1) / 2 numbers.
template <int N>
Eigen::Matrix<double, N*(N + 1) / 2, 1> pack_upper(const Eigen::Matrix<double, N, N>& m) {
  Eigen::Matrix<double, N*(N + 1) / 2, 1> v;
  int k = 0;
  for (int i = 0; i < N; ++i) {
    for (int j = i; j < N; ++j) v(k++) = m(i, j);
  }
  return v;
}
template <int N>
Eigen::Matrix<double, N, N> unpack_upper(const Eigen::Matrix<double, N*(N + 1) / 2, 1>& v) {
  Eigen::Matrix<double, N, N> m;
  int k = 0;
  for (int i = 0; i < N; ++i) {
    for (int j = i; j < N; ++j) {
      m(i, j) = v(k);
      m(j, i) = v(k++);
    }
  }
  return m;
}

}  // namespace rocksteady::gnc
