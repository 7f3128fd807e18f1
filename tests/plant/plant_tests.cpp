// The plant's truth dynamics, actuators and sensors against independent closed forms and statistics.
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

#include "ground/plant/plant.hpp"

namespace rocksteady::plant {
namespace {

PlantParams quiet_params() {
  PlantParams p;
  p.disturbance.sigma_nm = 0.0;
  p.omega0 = Vec3(0.01, 0.02, 0.03);  // SPEC §5 initial rate
  p.beta0 = att::mrp_to_quat(Vec3(0.05, 0.04, 0.03));
  return p;
}

TEST(PlantTruth, TorqueFreeConservesInertialMomentumAndEnergy) {
  PlantParams p = quiet_params();
  Plant plant(p);
  const Vec3 h0 = plant.angular_momentum_inertial();
  const double e0 = plant.kinetic_energy();
  const Vec8 zero = Vec8::Zero();
  double worst_h = 0.0, worst_e = 0.0;
  while (plant.t() < 1e4 - 1e-9) {  // 10^4 s
    plant.advance(zero, true);
    worst_h = std::max(worst_h, (plant.angular_momentum_inertial() - h0).norm() / h0.norm());
    worst_e = std::max(worst_e, std::fabs(plant.kinetic_energy() - e0) / e0);
  }
  EXPECT_LE(worst_h, 1e-9);
  EXPECT_LE(worst_e, 1e-9);
  // It really tumbled: the body rate changed direction.
  EXPECT_GT((plant.omega() - p.omega0).norm(), 1e-3);
}

TEST(PlantTruth, AxisymmetricBodyMatchesClosedFormPrecession) {
  PlantParams p = quiet_params();
  // Axisymmetric about z: every inertia term and the offset r are symmetric about z.
  p.mass.j_sc = Vec3(5e4, 5e4, 2e4).asDiagonal();
  p.mass.j_ast = Vec3(2e7, 2e7, 3.5e7).asDiagonal();
  p.mass.r_so_bcm = Vec3(0.0, 0.0, 3.5);
  p.omega0 = Vec3(0.02, -0.01, 0.05);
  p.beta0 = att::matrix_to_quat(att::rotation_exp(Vec3(0.3, -0.6, 0.2)));
  p.substeps = 2;
  Plant plant(p);
  const Mat3 j = plant.inertia();
  ASSERT_NEAR(j(0, 0), j(1, 1), 1e-6);
  ASSERT_NEAR(j(0, 1), 0.0, 1e-9);
  const double i1 = j(0, 0), i3 = j(2, 2);
  const Vec3 w0 = p.omega0;
  const double lambda = (i3 - i1) / i1 * w0.z();  // body-frame precession rate
  const Mat3 r0 = att::quat_to_matrix(p.beta0);
  const Vec3 h_inertial = r0 * (j * w0);
  const Vec3 n = h_inertial.normalized();
  const double a = h_inertial.norm() / i1;  // inertial precession rate about H

  const double t_end = 2000.0;
  const Vec8 zero = Vec8::Zero();
  while (plant.t() < t_end - 1e-9) plant.advance(zero, true);
  const double t = plant.t();
  // Euler's equations: (w1 + i w2)(t) = (w1 + i w2)(0) e^{i lambda t}, w3 constant.
  const Vec3 w_expected(w0.x() * std::cos(lambda * t) - w0.y() * std::sin(lambda * t),
                        w0.x() * std::sin(lambda * t) + w0.y() * std::cos(lambda * t), w0.z());
  EXPECT_LT((plant.omega() - w_expected).norm(), 1e-10);
  // Attitude: R(t) = exp(S(n) a t) R0 exp(-S(e3) lambda t).
  const Mat3 r_expected = att::rotation_exp(n * a * t) * r0 * att::rotation_exp(Vec3(0, 0, -lambda * t));
  EXPECT_LT((att::quat_to_matrix(plant.beta()) - r_expected).norm(), 1e-9);
}

// Error after `periods` periods of `dt` with n substeps, against a much finer solution.
double rk4_error(int substeps, const Plant& reference) {
  PlantParams p = reference.params();
  p.substeps = substeps;
  Plant plant(p);
  const Vec8 u = (Vec8() << 150, -80, 40, 0, -120, 60, 0, 90).finished();
  for (int k = 0; k < 10; ++k) plant.advance(u, true);
  return (plant.omega() - reference.omega()).norm() + (plant.beta() - reference.beta()).norm();
}

TEST(PlantTruth, Rk4ConvergesAtFourthOrder) {
  PlantParams p = quiet_params();
  p.omega0 = Vec3(0.2, 0.1, -0.3);  // fast enough that the step error dominates roundoff
  p.control_period_s = 2.0;
  p.sensors.period_s = 2.0;
  p.substeps = 512;
  Plant reference(p);
  const Vec8 u = (Vec8() << 150, -80, 40, 0, -120, 60, 0, 90).finished();
  for (int k = 0; k < 10; ++k) reference.advance(u, true);
  const double e1 = rk4_error(2, reference);
  const double e2 = rk4_error(4, reference);
  const double e3 = rk4_error(8, reference);
  ASSERT_GT(e3, 1e-12);  // well above roundoff
  EXPECT_NEAR(std::log2(e1 / e2), 4.0, 0.3);
  EXPECT_NEAR(std::log2(e2 / e3), 4.0, 0.3);
}

TEST(PlantTruth, ConstantForcesFromRestGiveJInverseBuTimesT) {
  PlantParams p = quiet_params();
  p.omega0.setZero();
  Plant plant(p);
  const Vec8 u = (Vec8() << 100, 0, -50, 20, 0, 0, 180, -10).finished();
  plant.advance(u, true);
  const Vec3 expected = plant.inertia().inverse() * (plant.torque_matrix() * u) * 0.1;
  // The gyroscopic term is O(w^2): relative effect ~ |w| t ~ 1e-6 here.
  EXPECT_LT((plant.omega() - expected).norm(), 1e-5 * expected.norm());
  // B is built from the true r_SO/BCM, SPEC §4.
  EXPECT_LT((plant.torque_matrix() - gnc::torque_matrix(p.rcs, p.mass.r_so_bcm)).norm(), 1e-12);
}

TEST(PlantActuators, ClipsEachChannelAtUmaxAndIntegratesFuel) {
  PlantParams p = quiet_params();
  p.rcs.u_max = 200.0;
  Plant plant(p);
  const Vec8 u = (Vec8() << 1000, -1000, 50, -20, 199, -250, 0, 10).finished();
  plant.advance(u, true);
  const Vec8 expected = (Vec8() << 200, -200, 50, -20, 199, -200, 0, 10).finished();
  EXPECT_EQ(plant.applied_force(), expected);
  EXPECT_TRUE(plant.clipped());
  // Eq. (54): sum |u| dt / (Isp g0).
  const double fuel = expected.cwiseAbs().sum() * 0.1 / (287.0 * 9.8);
  EXPECT_NEAR(plant.fuel_kg(), fuel, 1e-15);
  plant.advance(u, false);  // inhibited: no force, no fuel
  EXPECT_EQ(plant.applied_force(), Vec8::Zero());
  EXPECT_NEAR(plant.fuel_kg(), fuel, 1e-15);
  EXPECT_EQ(plant.clipped_periods(), 1u);
}

TEST(PlantDisturbance, HeldPerIntervalWithSigmaPerAxis) {
  PlantParams p = quiet_params();
  p.disturbance.sigma_nm = 1.0 / std::sqrt(3.0);
  p.disturbance.hold_s = 10.0;
  p.control_period_s = 2.0;
  p.sensors.period_s = 2.0;
  Plant plant(p);
  std::vector<Vec3> draws;
  Vec3 previous = Vec3::Zero();
  const int n_draws = 6000;
  for (int k = 0; k < 5 * n_draws; ++k) {
    plant.advance(Vec8::Zero(), false);
    if (k % 5 == 0) {
      draws.push_back(plant.disturbance());
      EXPECT_NE(plant.disturbance(), previous);
    } else {
      EXPECT_EQ(plant.disturbance(), previous);  // held for 10 s
    }
    previous = plant.disturbance();
  }
  for (int a = 0; a < 3; ++a) {
    double s = 0, s2 = 0;
    for (const Vec3& d : draws) {
      s += d(a);
      s2 += d(a) * d(a);
    }
    const double mean = s / n_draws;
    const double sd = std::sqrt(s2 / n_draws - mean * mean);
    EXPECT_NEAR(mean, 0.0, 5.0 * p.disturbance.sigma_nm / std::sqrt(n_draws));
    EXPECT_NEAR(sd / p.disturbance.sigma_nm, 1.0, 5.0 / std::sqrt(2.0 * n_draws));
  }
}

struct NoiseStats {
  Vec3 mean_w, sd_w, mean_q, sd_q;
  int n;
};

NoiseStats measure_noise(const PlantParams& p, int n) {
  Plant plant(p);
  Vec3 sw = Vec3::Zero(), sw2 = Vec3::Zero(), sq = Vec3::Zero(), sq2 = Vec3::Zero();
  const auto every = static_cast<int>(std::llround(p.sensors.period_s / p.control_period_s));
  for (int k = 0; k < n; ++k) {
    const hal::RawSensors s = plant.read_sensors();
    const Vec3 ew = s.gyro.rate - plant.omega();
    Vec3 eq = att::quat_to_mrp(s.star.quat) - plant.mrp();
    sw += ew;
    sw2 += ew.cwiseProduct(ew);
    sq += eq;
    sq2 += eq.cwiseProduct(eq);
    for (int i = 0; i < every; ++i) plant.advance(Vec8::Zero(), false);
  }
  NoiseStats st;
  st.n = n;
  st.mean_w = sw / n;
  st.mean_q = sq / n;
  st.sd_w = (sw2 / n - st.mean_w.cwiseProduct(st.mean_w)).cwiseSqrt();
  st.sd_q = (sq2 / n - st.mean_q.cwiseProduct(st.mean_q)).cwiseSqrt();
  return st;
}

TEST(PlantSensors, NoiseStandardDeviationIsSqrtPowerOverPeriod) {
  for (double ts : {0.1, 0.5}) {
    PlantParams p = quiet_params();
    p.omega0.setZero();  // at rest: the true MRP stays far from the shadow-set switch
    p.sensors.period_s = ts;
    p.sensors.gyro_psd = 1e-10;  // case 6/7 values
    p.sensors.star_psd = 1e-6;
    p.seed = 77;
    const int n = 20000;
    const NoiseStats st = measure_noise(p, n);
    const double sigma_w = std::sqrt(p.sensors.gyro_psd / ts);
    const double sigma_q = std::sqrt(p.sensors.star_psd / ts);
    const double tol = 5.0 / std::sqrt(2.0 * n);  // 5 sigma of the sample s.d.
    for (int a = 0; a < 3; ++a) {
      EXPECT_NEAR(st.sd_w(a) / sigma_w, 1.0, tol) << "ts " << ts << " axis " << a;
      EXPECT_NEAR(st.sd_q(a) / sigma_q, 1.0, tol) << "ts " << ts << " axis " << a;
      EXPECT_NEAR(st.mean_w(a), 0.0, 5.0 * sigma_w / std::sqrt(n));
      EXPECT_NEAR(st.mean_q(a), 0.0, 5.0 * sigma_q / std::sqrt(n));
    }
  }
}

TEST(PlantSensors, PerfectSensorsDeliverTheTruth) {
  PlantParams p = quiet_params();
  Plant plant(p);
  const hal::RawSensors s = plant.read_sensors();
  EXPECT_EQ(s.seq, 0);
  EXPECT_EQ(s.t, 0.0);
  EXPECT_TRUE(s.gyro.valid);
  EXPECT_TRUE(s.star.valid);
  EXPECT_EQ(s.gyro.rate, p.omega0);
  EXPECT_NEAR(std::fabs(s.star.quat.dot(p.beta0)), 1.0, 1e-15);
  EXPECT_NEAR(s.star.quat.norm(), 1.0, 1e-15);
}

TEST(PlantSensors, SampleIsHeldBetweenSensorPeriods) {
  PlantParams p = quiet_params();
  p.sensors.period_s = 0.3;  // three control periods
  p.sensors.gyro_psd = 1e-10;
  Plant plant(p);
  const hal::RawSensors s0 = plant.read_sensors();
  plant.advance(Vec8::Zero(), false);
  const hal::RawSensors s1 = plant.read_sensors();
  EXPECT_EQ(s1.seq, 1);                // a frame every control period
  EXPECT_NEAR(s1.t, 0.1, 1e-12);
  EXPECT_EQ(s1.gyro.t, s0.gyro.t);     // carrying the held readings
  EXPECT_EQ(s1.gyro.rate, s0.gyro.rate);
  plant.advance(Vec8::Zero(), false);
  plant.advance(Vec8::Zero(), false);
  const hal::RawSensors s3 = plant.read_sensors();
  EXPECT_NEAR(s3.gyro.t, 0.3, 1e-12);
  EXPECT_NE(s3.gyro.rate, s0.gyro.rate);
}

// A noisy, disturbed, actuated run; returns every sample and state as raw doubles.
std::vector<double> noisy_run(std::uint64_t seed) {
  PlantParams p = quiet_params();
  p.disturbance.sigma_nm = 1.0 / std::sqrt(3.0);
  p.disturbance.bias_nm = Vec3(0.1, -0.2, 0.05);
  p.sensors.gyro_psd = 1e-10;
  p.sensors.star_psd = 1e-6;
  p.seed = seed;
  Plant plant(p);
  std::vector<double> out;
  for (int k = 0; k < 2000; ++k) {
    const hal::RawSensors s = plant.read_sensors();
    out.insert(out.end(), s.gyro.rate.data(), s.gyro.rate.data() + 3);
    out.insert(out.end(), s.star.quat.data(), s.star.quat.data() + 4);
    Vec8 u = Vec8::Zero();
    u(k % 8) = -1e4 * s.gyro.rate(k % 3);
    plant.advance(u, true);
    out.insert(out.end(), plant.beta().data(), plant.beta().data() + 4);
    out.insert(out.end(), plant.omega().data(), plant.omega().data() + 3);
    out.push_back(plant.fuel_kg());
  }
  return out;
}

TEST(PlantSensors, SameSeedSameBitsOtherSeedOtherBits) {
  const std::vector<double> a = noisy_run(2024);
  const std::vector<double> b = noisy_run(2024);
  const std::vector<double> c = noisy_run(2025);
  ASSERT_EQ(a.size(), b.size());
  EXPECT_EQ(std::memcmp(a.data(), b.data(), a.size() * sizeof(double)), 0);
  EXPECT_NE(std::memcmp(a.data(), c.data(), a.size() * sizeof(double)), 0);
  // reset() replays the same streams.
  PlantParams p = quiet_params();
  p.sensors.gyro_psd = 1e-10;
  Plant plant(p);
  const Vec3 first = plant.read_sensors().gyro.rate;
  plant.advance(Vec8::Zero(), false);
  plant.reset();
  EXPECT_EQ(plant.read_sensors().gyro.rate, first);
}

// The thruster input: each physical thruster lands on its channel by the SPEC §4 wiring, written
// out here independently (pod k: tangential pair at positions 0 (+) and 1 (-) is channel 2k, axial
// pair at positions 2 (+) and 3 (-) is channel 2k+1).
TEST(PlantThrusters, PhysicalThrustersMapOntoTheirChannels) {
  for (int pod = 0; pod < 4; ++pod) {
    for (int pos = 0; pos < 4; ++pos) {
      hal::ThrusterOutputs o;
      o.enabled = true;
      const int i = 4 * pod + pos;
      o.on[static_cast<std::size_t>(i)] = true;
      o.force[static_cast<std::size_t>(i)] = 37.5;
      Vec8 expect = Vec8::Zero();
      expect(2 * pod + pos / 2) = pos % 2 == 0 ? 37.5 : -37.5;
      EXPECT_EQ(Plant::channel_forces(o), expect) << "thruster " << i;
      o.enabled = false;
      EXPECT_EQ(Plant::channel_forces(o), Vec8::Zero());
    }
  }
  // advance(thrusters) is advance(channel forces): same bits.
  PlantParams p = quiet_params();
  Plant a(p), b(p);
  hal::ThrusterOutputs o;
  o.enabled = true;
  o.on[0] = o.on[7] = o.on[13] = true;
  o.force[0] = 120.0;
  o.force[7] = 200.0;
  o.force[13] = 55.0;
  a.advance(o);
  b.advance(Plant::channel_forces(o), true);
  EXPECT_EQ(a.omega(), b.omega());
  EXPECT_EQ(a.fuel_kg(), b.fuel_kg());
}

TEST(PlantSensors, GyroBiasIsAddedAndWalksWithItsOwnStream) {
  PlantParams p = quiet_params();
  p.sensors.gyro_bias = Vec3(1e-4, -2e-4, 5e-5);
  Plant constant(p);
  EXPECT_LT((constant.read_sensors().gyro.rate - constant.omega() - p.sensors.gyro_bias).norm(), 1e-16);
  // Random walk: increments per sensor period have sigma rw sqrt(T_s) per axis.
  p.sensors.gyro_bias_rw = 1e-6;
  p.sensors.star_psd = 1e-8;
  Plant walking(p);
  PlantParams q = p;
  q.sensors.gyro_bias_rw = 0.0;
  q.sensors.gyro_bias.setZero();
  Plant plain(q);
  double sum2 = 0.0;
  const int n = 20000;
  Vec3 last = walking.gyro_bias();
  for (int k = 0; k < n; ++k) {
    const hal::RawSensors a = walking.read_sensors();
    const hal::RawSensors b = plain.read_sensors();
    // The other streams are untouched: the star tracker sees the same noise.
    ASSERT_EQ(a.star.quat, b.star.quat);
    EXPECT_LT((a.gyro.rate - walking.omega() - walking.gyro_bias()).norm(), 1e-16);
    sum2 += (walking.gyro_bias() - last).squaredNorm();
    last = walking.gyro_bias();
    walking.advance(Vec8::Zero(), false);
    plain.advance(Vec8::Zero(), false);
  }
  const double sigma = std::sqrt(sum2 / (3.0 * (n - 1)));
  EXPECT_NEAR(sigma, 1e-6 * std::sqrt(0.1), 0.02 * 1e-6 * std::sqrt(0.1));
}

TEST(PlantActuators, ThrusterStrengthScalesThatThrustersForceOnly) {
  PlantParams p = quiet_params();
  p.omega0.setZero();
  p.thruster_strength(4) = 0.5;   // channel 2 "+"
  p.thruster_strength(7) = 0.25;  // channel 3 "-"
  Plant plant(p);
  const Vec8 u = (Vec8() << 100, 0, 50, -20, 0, 0, 180, -10).finished();
  // Independent: the + thruster of channel 2 delivers half its force; channel 3 fires "-".
  Vec8 delivered = u;
  delivered(2) *= 0.5;
  delivered(3) *= 0.25;
  const Mat38 b = gnc::torque_matrix(p.rcs, p.mass.r_so_bcm);
  EXPECT_LT((plant.thruster_torque(u) - b * delivered).norm(), 1e-12 * (b * delivered).norm());
  // A "-" firing of channel 2 is not affected by the "+" thruster's factor.
  const Vec8 minus = (Vec8() << 0, 0, -50, 0, 0, 0, 0, 0).finished();
  EXPECT_LT((plant.thruster_torque(minus) - b * minus).norm(), 1e-12);
  plant.advance(u, true);
  const Vec3 expected = plant.inertia().inverse() * (b * delivered) * 0.1;
  EXPECT_LT((plant.omega() - expected).norm(), 1e-5 * expected.norm());
  // Fuel is counted on the commanded force.
  EXPECT_NEAR(plant.fuel_kg(), u.cwiseAbs().sum() * 0.1 / (287.0 * 9.8), 1e-15);
}

TEST(PlantParams, RejectsBadValuesNamingTheField) {
  auto rejects = [](PlantParams p, const char* field) {
    try {
      Plant plant(p);
      ADD_FAILURE() << "accepted bad " << field;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
    }
  };
  PlantParams p = quiet_params();
  p.sensors.gyro_psd = -1e-10;
  rejects(p, "sensors.gyro_psd");
  p = quiet_params();
  p.mass.j_ast(0, 0) = -1e7;
  rejects(p, "mass.j_ast");
  p = quiet_params();
  p.sensors.gyro_bias_rw = -1.0;
  rejects(p, "sensors.gyro_bias_rw");
  p = quiet_params();
  p.sensors.gyro_bias.x() = NAN;
  rejects(p, "sensors.gyro_bias");
  p = quiet_params();
  p.thruster_strength(3) = -0.1;
  rejects(p, "thruster_strength");
  p = quiet_params();
  p.sensors.period_s = 0.15;
  rejects(p, "sensors.period_s");
  p = quiet_params();
  p.substeps = 0;
  rejects(p, "substeps");
}

}  // namespace
}  // namespace rocksteady::plant
