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
  gnc::SensorSample s;
  ASSERT_EQ(gyro.read(GyroReading{10.0, c_bs.transpose() * omega_b, true}, 10.05, s),
            ReadingStatus::kOk);
  ASSERT_TRUE(s.gyro_valid);
  EXPECT_LT((s.gyro_rate - omega_b).norm(), 1e-15);
}

TEST(StarTracker, ComposesTheTrackerAttitudeWithTheAlignment) {
  const gnc::Mat3 c_bs = rotation(2.1, gnc::Vec3(0.3, 0.4, -1.0));
  const gnc::Mat3 r_ib = rotation(-1.3, gnc::Vec3(-0.5, 1.0, 0.2));
  StarTracker st;
  ASSERT_EQ(st.configure(aligned(c_bs)), SensorConfigError::kOk);
  // v_I = R_IB v_B = R_IB C_BS v_S: the tracker sees R_IS = R_IB C_BS.
  const gnc::Vec4 beta_is = gnc::quat::from_dcm(r_ib * c_bs);
  gnc::SensorSample a;
  ASSERT_EQ(st.read(StarTrackerReading{5.0, beta_is, true}, 5.0, a), ReadingStatus::kOk);
  ASSERT_TRUE(a.star_valid);
  EXPECT_LT((gnc::quat::to_dcm(a.star_quat) - r_ib).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_NEAR(a.star_quat.norm(), 1.0, 1e-12);
}

TEST(StarTracker, IdentityAlignmentPassesTheQuaternionThrough) {
  StarTracker st;
  ASSERT_EQ(st.configure(SensorConfig{}), SensorConfigError::kOk);
  const gnc::Vec4 beta = gnc::Vec4(0.1, -0.2, 0.3, 0.9).normalized();
  gnc::SensorSample a;
  st.read(StarTrackerReading{1.0, beta, true}, 1.0, a);
  ASSERT_TRUE(a.star_valid);
  EXPECT_LT((a.star_quat - beta).norm(), 1e-15);
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
  gnc::SensorSample s;
  EXPECT_EQ(g.read(GyroReading{0.0, gnc::Vec3::Zero(), true}, 0.0, s), ReadingStatus::kNotConfigured);
}

TEST(Gyro, RejectsInvalidNonFiniteStaleAndRepeatedReadings) {
  Gyro g;
  gnc::SensorSample s;
  ASSERT_EQ(g.configure(SensorConfig{}), SensorConfigError::kOk);  // max age 0.5 s
  const gnc::Vec3 w(0.1, 0.2, 0.3);
  EXPECT_EQ(g.read(GyroReading{1.0, w, false}, 1.0, s), ReadingStatus::kDeviceInvalid);
  EXPECT_EQ(g.read(GyroReading{1.0, gnc::Vec3(NAN, 0, 0), true}, 1.0, s),
            ReadingStatus::kNonFinite);
  EXPECT_EQ(g.read(GyroReading{1.0, w, true}, 1.6, s), ReadingStatus::kStale);
  EXPECT_EQ(g.read(GyroReading{2.0, w, true}, 1.0, s), ReadingStatus::kStale);  // future
  EXPECT_EQ(g.read(GyroReading{1.0, w, true}, 1.2, s), ReadingStatus::kOk);
  EXPECT_EQ(g.read(GyroReading{1.0, w, true}, 1.3, s), ReadingStatus::kNotAdvancing);
  EXPECT_EQ(g.read(GyroReading{1.1, w, true}, 1.3, s), ReadingStatus::kOk);
  EXPECT_EQ(g.rejects(), 5u);
  gnc::SensorSample bad;
  EXPECT_EQ(g.read(GyroReading{0.5, w, true}, 1.3, bad), ReadingStatus::kStale);
  EXPECT_FALSE(bad.gyro_valid);
  EXPECT_EQ(bad.gyro_rate, gnc::Vec3::Zero());  // an unusable reading never leaks its values
}

TEST(Sensors, EachDeviceWritesOnlyItsOwnPartOfTheSample) {
  Gyro g;
  StarTracker st;
  ASSERT_EQ(g.configure(SensorConfig{}), SensorConfigError::kOk);
  ASSERT_EQ(st.configure(SensorConfig{}), SensorConfigError::kOk);
  gnc::SensorSample s;
  s.t = 4.2;
  ASSERT_EQ(g.read(GyroReading{4.2, gnc::Vec3(1, 2, 3), true}, 4.2, s), ReadingStatus::kOk);
  EXPECT_EQ(st.read(StarTrackerReading{4.2, gnc::Vec4(1, 0, 0, 0), false}, 4.2, s),
            ReadingStatus::kDeviceInvalid);
  EXPECT_EQ(s.t, 4.2);
  EXPECT_TRUE(s.gyro_valid);
  EXPECT_EQ(s.gyro_rate, gnc::Vec3(1, 2, 3));
  EXPECT_FALSE(s.star_valid);
  EXPECT_EQ(s.star_quat, gnc::Vec4(0, 0, 0, 1));  // invalid readings never leak their values
}

}  // namespace
}  // namespace rocksteady::hal
