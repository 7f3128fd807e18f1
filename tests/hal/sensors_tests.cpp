// Gyro and StarTracker: sensor-to-body alignment, timestamps and validity.
#include <gtest/gtest.h>

#include <cmath>

#include <Eigen/Geometry>

#include "gnc/math/rotation.hpp"
#include "hal/sensors.hpp"

namespace rocksteady::hal {
namespace {

gnc::Mat3 rotation(double angle, const gnc::Vec3& axis) {
  return Eigen::AngleAxisd(angle, axis.normalized()).toRotationMatrix();
}

SensorConfig aligned(const gnc::Mat3& c_bs) {
  SensorConfig c;
  c.body_from_sensor = c_bs;
  c.max_age_s = 0.5;
  return c;
}

TEST(Gyro, RotatesTheRateFromSensorToBodyFrame) {
  const gnc::Mat3 c_bs = rotation(0.7, gnc::Vec3(1.0, -2.0, 0.5));
  Gyro gyro;
  ASSERT_EQ(gyro.configure(aligned(c_bs)), SensorConfigError::kOk);
  const gnc::Vec3 omega_b(0.01, -0.02, 0.03);
  // A gyro mounted with C_BS measures omega_S = C_BS' omega_B.
  const BodyRate r = gyro.read(GyroReading{10.0, c_bs.transpose() * omega_b, true}, 10.05);
  ASSERT_TRUE(r.valid);
  EXPECT_LT((r.rate - omega_b).norm(), 1e-15);
  EXPECT_EQ(r.t, 10.0);
}

TEST(StarTracker, ComposesTheTrackerAttitudeWithTheAlignment) {
  const gnc::Mat3 c_bs = rotation(2.1, gnc::Vec3(0.3, 0.4, -1.0));
  const gnc::Mat3 r_ib = rotation(-1.3, gnc::Vec3(-0.5, 1.0, 0.2));
  StarTracker st;
  ASSERT_EQ(st.configure(aligned(c_bs)), SensorConfigError::kOk);
  // v_I = R_IB v_B = R_IB C_BS v_S: the tracker sees R_IS = R_IB C_BS.
  const gnc::Vec4 beta_is = gnc::quat::from_dcm(r_ib * c_bs);
  const BodyAttitude a = st.read(StarTrackerReading{5.0, beta_is, true}, 5.0);
  ASSERT_TRUE(a.valid);
  EXPECT_LT((gnc::quat::to_dcm(a.quat) - r_ib).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_NEAR(a.quat.norm(), 1.0, 1e-12);
}

TEST(StarTracker, IdentityAlignmentPassesTheQuaternionThrough) {
  StarTracker st;
  ASSERT_EQ(st.configure(SensorConfig{}), SensorConfigError::kOk);
  const gnc::Vec4 beta = gnc::Vec4(0.1, -0.2, 0.3, 0.9).normalized();
  const BodyAttitude a = st.read(StarTrackerReading{1.0, beta, true}, 1.0);
  ASSERT_TRUE(a.valid);
  EXPECT_LT((a.quat - beta).norm(), 1e-15);
}

TEST(SensorConfig, RejectsNonRotationsAndBadAge) {
  SensorConfig c;
  c.body_from_sensor = 2.0 * gnc::Mat3::Identity();
  EXPECT_EQ(validate(c), SensorConfigError::kNotARotation);
  c.body_from_sensor = gnc::Mat3::Identity();
  c.body_from_sensor(2, 2) = -1.0;  // a reflection: orthogonal, det -1
  EXPECT_EQ(validate(c), SensorConfigError::kNotARotation);
  c.body_from_sensor = gnc::Mat3::Identity();
  c.max_age_s = 0.0;
  EXPECT_EQ(validate(c), SensorConfigError::kBadMaxAge);
  Gyro g;
  EXPECT_EQ(g.configure(c), SensorConfigError::kBadMaxAge);
  EXPECT_EQ(g.read(GyroReading{0.0, gnc::Vec3::Zero(), true}, 0.0).status,
            ReadingStatus::kNotConfigured);
}

TEST(Gyro, RejectsInvalidNonFiniteStaleAndRepeatedReadings) {
  Gyro g;
  ASSERT_EQ(g.configure(SensorConfig{}), SensorConfigError::kOk);  // max age 0.5 s
  const gnc::Vec3 w(0.1, 0.2, 0.3);
  EXPECT_EQ(g.read(GyroReading{1.0, w, false}, 1.0).status, ReadingStatus::kDeviceInvalid);
  EXPECT_EQ(g.read(GyroReading{1.0, gnc::Vec3(NAN, 0, 0), true}, 1.0).status,
            ReadingStatus::kNonFinite);
  EXPECT_EQ(g.read(GyroReading{1.0, w, true}, 1.6).status, ReadingStatus::kStale);
  EXPECT_EQ(g.read(GyroReading{2.0, w, true}, 1.0).status, ReadingStatus::kStale);  // future
  EXPECT_EQ(g.read(GyroReading{1.0, w, true}, 1.2).status, ReadingStatus::kOk);
  EXPECT_EQ(g.read(GyroReading{1.0, w, true}, 1.3).status, ReadingStatus::kNotAdvancing);
  EXPECT_EQ(g.read(GyroReading{1.1, w, true}, 1.3).status, ReadingStatus::kOk);
  EXPECT_EQ(g.rejects(), 5u);
  const BodyRate bad = g.read(GyroReading{0.5, w, true}, 1.3);
  EXPECT_FALSE(bad.valid);
  EXPECT_EQ(bad.rate, gnc::Vec3::Zero());
}

TEST(MakeSample, CarriesTickTimeAndPerSensorValidity) {
  BodyRate r;
  r.valid = true;
  r.rate = gnc::Vec3(1, 2, 3);
  BodyAttitude a;
  a.valid = false;
  a.quat = gnc::Vec4(1, 0, 0, 0);
  const gnc::SensorSample s = make_sample(4.2, r, a);
  EXPECT_EQ(s.t, 4.2);
  EXPECT_TRUE(s.gyro_valid);
  EXPECT_EQ(s.gyro_rate, r.rate);
  EXPECT_FALSE(s.star_valid);
  EXPECT_EQ(s.star_quat, gnc::Vec4(0, 0, 0, 1));  // invalid readings never leak their values
}

}  // namespace
}  // namespace rocksteady::hal
