#include "gnc/math/rotation.hpp"

#include <cmath>

namespace rocksteady::gnc {

Mat3 skew(const Vec3& v) {
  Mat3 s;
  s << 0.0, -v.z(), v.y(),  //
      v.z(), 0.0, -v.x(),   //
      -v.y(), v.x(), 0.0;
  return s;
}

Vec3 vee(const Mat3& m) {
  // Skew-symmetric part of m, then read off: vee(S(v)) = v exactly.
  return Vec3(m(2, 1) - m(1, 2), m(0, 2) - m(2, 0), m(1, 0) - m(0, 1)) * 0.5;
}

namespace mrp {

Mat3 z_matrix(const Vec3& q) {
  const double qq = q.squaredNorm();
  // Eq. (4)
  return 0.5 * (0.5 * (1.0 - qq) * Mat3::Identity() + q * q.transpose() + skew(q));
}

Mat3 z_inverse(const Vec3& q) {
  const double qq = q.squaredNorm();
  const double d = (1.0 + qq) * (1.0 + qq);
  // Closed form of Z^-1 (SPEC §1)
  return (4.0 / d) * ((1.0 - qq) * Mat3::Identity() - 2.0 * skew(q) + 2.0 * q * q.transpose());
}

Mat3 z_dot(const Vec3& q, const Vec3& q_dot) {
  // d/dt of Eq. (4)
  return 0.5 * (-q.dot(q_dot) * Mat3::Identity() + q_dot * q.transpose() + q * q_dot.transpose() +
                skew(q_dot));
}

Vec3 shadow(const Vec3& q) {
  const double qq = q.squaredNorm();
  return -q / qq;
}

Vec3 normalize(const Vec3& q) { return q.squaredNorm() > 1.0 ? shadow(q) : q; }

Vec3 nearest_set(const Vec3& q, const Vec3& to) {
  if (q.squaredNorm() < 1e-12) return q;
  const Vec3 s = shadow(q);
  return (s - to).squaredNorm() < (q - to).squaredNorm() ? s : q;
}

WithRates shadow_with_rates(const WithRates& in) {
  const Vec3& q = in.q;
  const Vec3& qd = in.q_dot;
  const Vec3& qdd = in.q_ddot;
  const double n = q.squaredNorm();
  const double nd = 2.0 * q.dot(qd);
  const double ndd = 2.0 * (qd.squaredNorm() + q.dot(qdd));
  WithRates out;
  out.q = -q / n;
  out.q_dot = -qd / n + q * (nd / (n * n));
  out.q_ddot = -qdd / n + qd * (2.0 * nd / (n * n)) + q * (ndd / (n * n)) -
               q * (2.0 * nd * nd / (n * n * n));
  return out;
}

WithRates same_set_as(const WithRates& ref, const Vec3& q) {
  // The identity's shadow is at infinity: nearest_set keeps it as is.
  return nearest_set(ref.q, q) == ref.q ? ref : shadow_with_rates(ref);
}

Vec4 to_quaternion(const Vec3& q) {
  const double qq = q.squaredNorm();
  Vec4 b;
  b.head<3>() = 2.0 * q / (1.0 + qq);
  b.w() = (1.0 - qq) / (1.0 + qq);
  return b;
}

Vec3 from_quaternion(const Vec4& beta) {
  const Vec4 b = beta.w() < 0.0 ? Vec4(-beta) : beta;
  const Vec4 u = b / b.norm();
  return u.head<3>() / (1.0 + u.w());
}

Mat3 to_dcm(const Vec3& q) {
  const double qq = q.squaredNorm();
  const Mat3 s = skew(q);
  const double d = (1.0 + qq) * (1.0 + qq);
  return Mat3::Identity() + (8.0 * s * s + 4.0 * (1.0 - qq) * s) / d;
}

Vec3 from_dcm(const Mat3& r) { return from_quaternion(quat::from_dcm(r)); }

Vec3 compose(const Vec3& q1, const Vec3& q2) {
  return from_quaternion(quat::multiply(to_quaternion(q1), to_quaternion(q2)));
}

Vec3 relative(const Vec3& q_b, const Vec3& q_r) {
  return from_quaternion(quat::multiply(quat::conjugate(to_quaternion(q_r)), to_quaternion(q_b)));
}

}  // namespace mrp

namespace quat {

Vec4 multiply(const Vec4& a, const Vec4& b) {
  const Vec3 av = a.head<3>();
  const Vec3 bv = b.head<3>();
  Vec4 c;
  c.head<3>() = a.w() * bv + b.w() * av + av.cross(bv);
  c.w() = a.w() * b.w() - av.dot(bv);
  return c;
}

Vec4 rate(const Vec4& beta, const Vec3& omega) {
  const Vec3 bv = beta.head<3>();
  Vec4 d;
  d.head<3>() = 0.5 * (beta.w() * omega + bv.cross(omega));  // Eq. (3)
  d.w() = -0.5 * bv.dot(omega);
  return d;
}

Mat3 to_dcm(const Vec4& beta) {
  const Vec4 b = beta / beta.norm();
  const Vec3 v = b.head<3>();
  return (b.w() * b.w() - v.squaredNorm()) * Mat3::Identity() + 2.0 * v * v.transpose() +
         2.0 * b.w() * skew(v);
}

Vec4 from_dcm(const Mat3& r) {
  // Shepperd: pick the largest of (tr, r00, r11, r22) for numerical safety.
  const double tr = r.trace();
  Vec4 b;
  if (tr >= r(0, 0) && tr >= r(1, 1) && tr >= r(2, 2)) {
    const double s = 2.0 * std::sqrt(1.0 + tr);
    b << (r(2, 1) - r(1, 2)) / s, (r(0, 2) - r(2, 0)) / s, (r(1, 0) - r(0, 1)) / s, 0.25 * s;
  } else if (r(0, 0) >= r(1, 1) && r(0, 0) >= r(2, 2)) {
    const double s = 2.0 * std::sqrt(1.0 + r(0, 0) - r(1, 1) - r(2, 2));
    b << 0.25 * s, (r(0, 1) + r(1, 0)) / s, (r(0, 2) + r(2, 0)) / s, (r(2, 1) - r(1, 2)) / s;
  } else if (r(1, 1) >= r(2, 2)) {
    const double s = 2.0 * std::sqrt(1.0 + r(1, 1) - r(0, 0) - r(2, 2));
    b << (r(0, 1) + r(1, 0)) / s, 0.25 * s, (r(1, 2) + r(2, 1)) / s, (r(0, 2) - r(2, 0)) / s;
  } else {
    const double s = 2.0 * std::sqrt(1.0 + r(2, 2) - r(0, 0) - r(1, 1));
    b << (r(0, 2) + r(2, 0)) / s, (r(1, 2) + r(2, 1)) / s, 0.25 * s, (r(1, 0) - r(0, 1)) / s;
  }
  if (b.w() < 0.0) {
    b = -b;
  }
  return b / b.norm();
}

Vec4 error(const Vec4& beta, const Vec4& beta_target) {
  Vec4 e = multiply(conjugate(beta_target), beta);
  if (e.w() < 0.0) {
    e = -e;
  }
  return e;
}

}  // namespace quat

namespace so3 {

namespace {
double c_of(double tr_q) { return 1.0 / (2.0 * std::sqrt(1.0 + tr_q)); }
}  // namespace

Vec3 attitude_error(const Mat3& r, const Mat3& r_d) {
  const Mat3 q = r_d.transpose() * r;
  // Eq. (35); vee here is of the skew matrix Q - Q', so multiply back the 1/2 of vee().
  return c_of(q.trace()) * 2.0 * vee(q);
}

Mat3 e_matrix(const Mat3& r, const Mat3& r_d) {
  const Mat3 q = r_d.transpose() * r;
  const Vec3 e_r = attitude_error(r, r_d);
  // Eq. (36)
  return c_of(q.trace()) *
         (q.trace() * Mat3::Identity() - q.transpose() + 2.0 * e_r * e_r.transpose());
}

ErrorRates error_with_rates(const Mat3& r, const Mat3& r_d, const Vec3& e_omega) {
  const Mat3 q = r_d.transpose() * r;
  const Mat3 q_dot = q * skew(e_omega);  // d/dt (R_d' R) = Q S(e_omega)
  const double t = q.trace();
  const double t_dot = q_dot.trace();
  const double c = c_of(t);
  const double c_dot = -c * t_dot / (2.0 * (1.0 + t));
  ErrorRates out;
  const Vec3 v = 2.0 * vee(q);  // vee(Q - Q')
  const Vec3 v_dot = 2.0 * vee(q_dot);
  out.e_r = c * v;
  out.e_r_dot = c_dot * v + c * v_dot;
  const Mat3 inner = t * Mat3::Identity() - q.transpose() + 2.0 * out.e_r * out.e_r.transpose();
  const Mat3 inner_dot = t_dot * Mat3::Identity() - q_dot.transpose() +
                         2.0 * (out.e_r_dot * out.e_r.transpose() + out.e_r * out.e_r_dot.transpose());
  out.e = c * inner;
  out.e_dot = c_dot * inner + c * inner_dot;
  return out;
}

}  // namespace so3

}  // namespace rocksteady::gnc
