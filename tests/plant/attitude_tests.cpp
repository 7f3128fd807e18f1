// The plant's own quaternion/MRP math against closed forms.
#include <cmath>

#include <gtest/gtest.h>

#include "ground/plant/attitude.hpp"

namespace rocksteady::plant {
namespace {

TEST(PlantAttitude, QuaternionMatrixIsRodriguesRotation) {
  const Vec3 axis = Vec3(0.3, -0.5, 0.8).normalized();
  const double angle = 2.1;
  Vec4 beta;
  beta.head<3>() = std::sin(angle / 2) * axis;
  beta(3) = std::cos(angle / 2);
  const Mat3 r = att::quat_to_matrix(beta);
  EXPECT_LT((r - att::rotation_exp(angle * axis)).norm(), 1e-14);
  EXPECT_LT((r * r.transpose() - Mat3::Identity()).norm(), 1e-14);
  EXPECT_NEAR(r.determinant(), 1.0, 1e-14);
  // A rotation about the axis leaves the axis fixed.
  EXPECT_LT((r * axis - axis).norm(), 1e-14);
}

TEST(PlantAttitude, MatrixToQuaternionRoundTripsEveryBranch) {
  const Vec3 axes[] = {Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1), Vec3(1, 1, 1).normalized()};
  for (const Vec3& a : axes) {
    for (double angle : {0.1, 1.5, 3.0, 3.14}) {
      const Mat3 r = att::rotation_exp(angle * a);
      const Vec4 b = att::matrix_to_quat(r);
      EXPECT_GE(b(3), 0.0);
      EXPECT_LT((att::quat_to_matrix(b) - r).norm(), 1e-13) << angle;
    }
  }
}

TEST(PlantAttitude, MrpIsShadowNormalisedAndRoundTrips) {
  const Vec3 axis = Vec3(-0.2, 0.4, 0.9).normalized();
  for (double angle : {0.2, 1.0, 3.0, 4.0, 6.0}) {
    Vec4 beta;
    beta.head<3>() = std::sin(angle / 2) * axis;
    beta(3) = std::cos(angle / 2);
    const Vec3 q = att::quat_to_mrp(beta);
    EXPECT_LE(q.norm(), 1.0 + 1e-15);
    // The MRP's magnitude is tan(phi/4) with phi the principal angle in [0, pi].
    const double phi = angle > 3.14159265358979323846 ? 2 * 3.14159265358979323846 - angle : angle;
    EXPECT_NEAR(q.norm(), std::tan(phi / 4), 1e-14);
    const Vec4 back = att::mrp_to_quat(q);
    EXPECT_LT((att::quat_to_matrix(back) - att::quat_to_matrix(beta)).norm(), 1e-14);
  }
}

TEST(PlantAttitude, QuaternionRateMatchesFiniteDifferenceOfBodyRotation) {
  // R(t) = R0 exp(S(w) t) has body rate w; compare Eq. (3) with the finite difference.
  const Vec3 w(0.3, -0.2, 0.5);
  const Mat3 r0 = att::rotation_exp(Vec3(0.4, 0.1, -0.7));
  const double h = 1e-6;
  const Vec4 b0 = att::matrix_to_quat(r0);
  Vec4 bp = att::matrix_to_quat(r0 * att::rotation_exp(w * h));
  Vec4 bm = att::matrix_to_quat(r0 * att::rotation_exp(-w * h));
  const Vec4 fd = (bp - bm) / (2 * h);
  EXPECT_LT((fd - att::quat_rate(b0, w)).norm(), 1e-9);
}

}  // namespace
}  // namespace rocksteady::plant
