// Mass properties (Eq. 1), RCS geometry -> B (SPEC §4) and the allocator (Eqs. 53-54).
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <random>

#include "gnc/allocation/allocator.hpp"
#include "gnc/model/mass_properties.hpp"
#include "gnc/model/rcs.hpp"

namespace rocksteady::gnc {
namespace {

TEST(MassProperties, TotalInertiaIsEquationOne) {
  const MassProperties mp = study_true_mass_properties();
  const Mat3 j = total_inertia(mp);
  // Hand computation: r = [0 0 3] + [-0.0495 -0.0004 3.5456] = [-0.0495 -0.0004 6.5456].
  const double rx = -0.0495, ry = -0.0004, rz = 6.5456, m = 1.6e4;
  EXPECT_NEAR(j(0, 0), 0.8658e7 + 5.584e4 + m * (ry * ry + rz * rz), 1e-6);
  EXPECT_NEAR(j(1, 1), 3.4900e7 + 5.584e4 + m * (rx * rx + rz * rz), 1e-6);
  EXPECT_NEAR(j(2, 2), 3.5579e7 + 1.568e4 + m * (rx * rx + ry * ry), 1e-6);
  EXPECT_NEAR(j(0, 1), 0.4432e7 - m * rx * ry, 1e-6);
  EXPECT_NEAR(j(0, 2), -0.0005e7 - m * rx * rz, 1e-6);
  EXPECT_NEAR(j(1, 2), 0.0002e7 - m * ry * rz, 1e-6);
  EXPECT_LT((j - j.transpose()).norm(), 1e-9);
}

TEST(Rcs, TorqueColumnsMatchHandComputation) {
  const MassProperties mp = study_true_mass_properties();
  const Mat38 b = torque_matrix(study_rcs_layout(200.0), mp.r_so_bcm);
  // Channel 0: pod 0 at 45 deg, tangential d = (-sin45, cos45, 0), arm = r_SO/BCM + p_0 with
  // p_0 = (2.5 cos45, 2.5 sin45, 3.0): arm x d worked out by hand.
  EXPECT_NEAR(b(0, 0), -4.628438146934665, 1e-12);
  EXPECT_NEAR(b(1, 0), -4.628438146934665, 1e-12);
  EXPECT_NEAR(b(2, 0), 2.4647153716187913, 1e-12);
  // Channel 1: pod 0 axial, d = z: arm x z = (arm_y, -arm_x, 0).
  EXPECT_NEAR(b(0, 1), 1.767366952966369, 1e-12);
  EXPECT_NEAR(b(1, 1), -1.7182669529663688, 1e-12);
  EXPECT_NEAR(b(2, 1), 0.0, 1e-15);
  // Full rank: the layout can torque about every axis.
  EXPECT_GT(torque_matrix_rcond(b), 1e-3);
}

TEST(Rcs, RankDeficientLayoutIsDetected) {
  RcsLayout l = study_rcs_layout(200.0);
  for (auto& d : l.channel_direction) d = Vec3(0, 0, 1);  // all axial: no torque about z
  EXPECT_LT(torque_matrix_rcond(torque_matrix(l, Vec3::Zero())), 1e-12);
  Allocator a;
  EXPECT_FALSE(a.configure(torque_matrix(l, Vec3::Zero()), 200.0));
}

class AllocatorTest : public ::testing::Test {
 protected:
  void SetUp() override {
    b_ = torque_matrix(study_rcs_layout(200.0), study_true_mass_properties().r_so_bcm);
    ASSERT_TRUE(alloc_.configure(b_, 200.0));
  }
  Mat38 b_;
  Allocator alloc_;
};

TEST_F(AllocatorTest, PseudoinverseReproducesTorqueAndIsMinimumNorm) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-300.0, 300.0);
  // Independent minimum-norm solution: complete orthogonal decomposition of B.
  const Eigen::MatrixXd bd = b_;
  const Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> cod(bd);
  for (int i = 0; i < 50; ++i) {
    const Vec3 uc(u(rng), u(rng), u(rng));
    Vec8 force;
    AllocatorStatus st;
    alloc_.allocate(uc, force, st);
    ASSERT_FALSE(st.saturated);
    EXPECT_LT((b_ * force - uc).norm(), 1e-9 * uc.norm());  // B u = u_c
    const Eigen::VectorXd ref = cod.solve(Eigen::VectorXd(uc));
    EXPECT_LT((force - ref).norm(), 1e-9 * ref.norm());
    // Adding any null-space component makes the solution longer.
    const Eigen::MatrixXd null = Eigen::FullPivLU<Eigen::MatrixXd>(bd).kernel();
    for (int k = 0; k < null.cols(); ++k) {
      EXPECT_GT((force + 0.1 * null.col(k)).norm(), force.norm());
    }
  }
}

TEST_F(AllocatorTest, RescaleKeepsDirectionAndNeverExceedsUmax) {
  std::mt19937 rng(8);
  std::normal_distribution<double> n(0.0, 1.0);
  int saturated = 0;
  for (int i = 0; i < 200; ++i) {
    const Vec3 uc = Vec3(n(rng), n(rng), n(rng)) * 5000.0;
    Vec8 force;
    AllocatorStatus st;
    alloc_.allocate(uc, force, st);
    EXPECT_LE(force.lpNorm<Eigen::Infinity>(), 200.0 * (1 + 1e-12));
    const Vec3 achieved = b_ * force;
    EXPECT_LT((achieved - st.torque_achieved).norm(), 1e-9);
    EXPECT_LT(achieved.normalized().cross(uc.normalized()).norm(), 1e-12);  // same direction
    EXPECT_GT(achieved.dot(uc), 0.0);
    if (st.saturated) {
      ++saturated;
      EXPECT_NEAR(force.lpNorm<Eigen::Infinity>(), 200.0, 1e-9);
      EXPECT_NEAR(achieved.norm(), st.scale * uc.norm(), 1e-9 * uc.norm());
      EXPECT_LT(st.scale, 1.0);
    }
  }
  EXPECT_GT(saturated, 100);  // the test did exercise the rescale
}

TEST(Fuel, FlowIsEquationFiftyFour) {
  Vec8 u;
  u << 100, -50, 0, 25, -200, 0, 10, -1;
  EXPECT_DOUBLE_EQ(fuel_rate(u, 287.0, 9.8), 386.0 / (287.0 * 9.8));
}

}  // namespace
}  // namespace rocksteady::gnc
