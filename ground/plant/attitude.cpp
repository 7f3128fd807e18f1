#include "ground/plant/attitude.hpp"

#include <cmath>

namespace rocksteady::plant::att {

Mat3 cross_matrix(const Vec3& v) {
  Mat3 s;
  s << 0.0, -v.z(), v.y(),  //
      v.z(), 0.0, -v.x(),   //
      -v.y(), v.x(), 0.0;
  return s;
}

Vec4 quat_rate(const Vec4& beta, const Vec3& omega) {
  const Vec3 bv = beta.head<3>();
  const double b4 = beta(3);
  Vec4 d;
  d.head<3>() = 0.5 * (b4 * omega + bv.cross(omega));  // Eq. (3)
  d(3) = -0.5 * bv.dot(omega);                         // Eq. (3)
  return d;
}

Mat3 quat_to_matrix(const Vec4& beta) {
  const Vec3 bv = beta.head<3>();
  const double b4 = beta(3);
  return (b4 * b4 - bv.squaredNorm()) * Mat3::Identity() + 2.0 * bv * bv.transpose() +
         2.0 * b4 * cross_matrix(bv);
}

Vec4 matrix_to_quat(const Mat3& r) {
  // Pick the largest of 4 beta4^2, 4 beta_i^2 for a well-conditioned square root.
  const double tr = r.trace();
  const double c[4] = {1.0 + 2.0 * r(0, 0) - tr, 1.0 + 2.0 * r(1, 1) - tr,
                       1.0 + 2.0 * r(2, 2) - tr, 1.0 + tr};
  int k = 0;
  for (int i = 1; i < 4; ++i) {
    if (c[i] > c[k]) k = i;
  }
  const double s = 2.0 * std::sqrt(c[k]);  // 4 |beta_k|
  Vec4 b;
  // From R: R32 - R23 = 4 b4 b1, R13 - R31 = 4 b4 b2, R21 - R12 = 4 b4 b3,
  //         R12 + R21 = 4 b1 b2, R13 + R31 = 4 b1 b3, R23 + R32 = 4 b2 b3.
  switch (k) {
    case 0:
      b << 0.25 * s, (r(0, 1) + r(1, 0)) / s, (r(0, 2) + r(2, 0)) / s, (r(2, 1) - r(1, 2)) / s;
      break;
    case 1:
      b << (r(0, 1) + r(1, 0)) / s, 0.25 * s, (r(1, 2) + r(2, 1)) / s, (r(0, 2) - r(2, 0)) / s;
      break;
    case 2:
      b << (r(0, 2) + r(2, 0)) / s, (r(1, 2) + r(2, 1)) / s, 0.25 * s, (r(1, 0) - r(0, 1)) / s;
      break;
    default:
      b << (r(2, 1) - r(1, 2)) / s, (r(0, 2) - r(2, 0)) / s, (r(1, 0) - r(0, 1)) / s, 0.25 * s;
      break;
  }
  if (b(3) < 0.0) b = -b;
  return b.normalized();
}

Vec3 quat_to_mrp(const Vec4& beta) {
  const Vec4 b = beta(3) < 0.0 ? Vec4(-beta) : beta;
  return b.head<3>() / (1.0 + b(3));
}

Vec4 mrp_to_quat(const Vec3& q) {
  const double n = q.squaredNorm();
  Vec4 b;
  b.head<3>() = 2.0 * q / (1.0 + n);
  b(3) = (1.0 - n) / (1.0 + n);
  if (b(3) < 0.0) b = -b;
  return b;
}

Mat3 rotation_exp(const Vec3& v) {
  const double a = v.norm();
  if (a < 1e-12) return Mat3::Identity() + cross_matrix(v);
  const Mat3 k = cross_matrix(v / a);
  return Mat3::Identity() + std::sin(a) * k + (1.0 - std::cos(a)) * k * k;
}

void rk4_step(const Mat3& j, const Mat3& j_inv, const Vec3& torque, double h, Vec4& beta,
              Vec3& omega) {
  auto derivative = [&](const Vec4& b, const Vec3& w, Vec4& b_dot, Vec3& w_dot) {
    b_dot = quat_rate(b, w);                      // Eq. (3)
    w_dot = j_inv * ((j * w).cross(w) + torque);  // Eq. (2)
  };
  Vec4 k1b, k2b, k3b, k4b;
  Vec3 k1w, k2w, k3w, k4w;
  derivative(beta, omega, k1b, k1w);
  derivative(beta + 0.5 * h * k1b, omega + 0.5 * h * k1w, k2b, k2w);
  derivative(beta + 0.5 * h * k2b, omega + 0.5 * h * k2w, k3b, k3w);
  derivative(beta + h * k3b, omega + h * k3w, k4b, k4w);
  beta += (h / 6.0) * (k1b + 2.0 * k2b + 2.0 * k3b + k4b);
  omega += (h / 6.0) * (k1w + 2.0 * k2w + 2.0 * k3w + k4w);
  beta.normalize();
}

}  // namespace rocksteady::plant::att
