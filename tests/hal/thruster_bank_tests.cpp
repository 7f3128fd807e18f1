// ThrusterBank: SPEC §4 pod mapping, configuration validation, saturation and inhibition.
#include <gtest/gtest.h>

#include <cmath>

#include <Eigen/Geometry>

#include "gnc/model/mass_properties.hpp"
#include "gnc/model/rcs.hpp"
#include "hal/thruster_bank.hpp"

namespace rocksteady::hal {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Independent model of the 16 physical thrusters from SPEC §4's words: pod k at azimuth 45 + 90k deg,
// radius 2.5 m, z = 3 m; positions 0/1 fire along +/- the tangent (-sin, cos, 0), 2/3 along +/- z.
struct Physical {
  gnc::Vec3 position;
  gnc::Vec3 direction;
};
Physical physical_thruster(int pod, int position) {
  const double theta = (45.0 + 90.0 * pod) * kPi / 180.0;
  const gnc::Vec3 p(2.5 * std::cos(theta), 2.5 * std::sin(theta), 3.0);
  const gnc::Vec3 tangent(-std::sin(theta), std::cos(theta), 0.0);
  const gnc::Vec3 axial(0.0, 0.0, 1.0);
  const gnc::Vec3 d = position == 0 ? tangent : position == 1 ? -tangent : position == 2 ? axial : -axial;
  return {p, d};
}

ThrusterBank default_bank(double u_max = 200.0) {
  ThrusterBank bank;
  const gnc::RcsLayout layout = gnc::study_rcs_layout(u_max);
  EXPECT_TRUE(bank.configure(default_thruster_bank_config(u_max), &layout).ok());
  return bank;
}

TEST(ThrusterBank, PositiveChannelFiresPlusThrusterOfItsPod) {
  const ThrusterBank bank = default_bank();
  for (int ch = 0; ch < gnc::kChannels; ++ch) {
    for (const double sign : {1.0, -1.0}) {
      gnc::ThrusterCommand cmd;
      cmd.enabled = true;
      cmd.force(ch) = sign * 50.0;
      ThrusterOutputs out;
      bank.command(cmd, out);
      const int pod = ch / 2;
      const int position = (ch % 2 == 0 ? 0 : 2) + (sign > 0 ? 0 : 1);
      for (int t = 0; t < kThrusters; ++t) {
        const bool expect_on = t == thruster_index(pod, position);
        EXPECT_EQ(out.on[static_cast<std::size_t>(t)], expect_on) << "channel " << ch << " thruster " << t;
        EXPECT_DOUBLE_EQ(out.force[static_cast<std::size_t>(t)], expect_on ? 50.0 : 0.0);
      }
    }
  }
}

// The physical thrusters, summed as forces at their positions, give the flight core's B u.
TEST(ThrusterBank, PhysicalTorqueEqualsTorqueMatrixTimesChannelForces) {
  const double u_max = 200.0;
  const ThrusterBank bank = default_bank(u_max);
  const gnc::RcsLayout layout = gnc::study_rcs_layout(u_max);
  const gnc::Vec3 r_so_bcm(-0.0495, -0.0004, 3.5456);
  const gnc::Mat38 b = gnc::torque_matrix(layout, r_so_bcm);
  gnc::ThrusterCommand cmd;
  cmd.enabled = true;
  cmd.force << 12.5, -199.0, 3.0, 0.0, -77.0, 150.0, -0.5, 88.0;
  ThrusterOutputs out;
  const BankStatus status = bank.command(cmd, out);
  EXPECT_EQ(status.clamped, 0);
  gnc::Vec3 torque = gnc::Vec3::Zero();
  for (int pod = 0; pod < gnc::kPods; ++pod) {
    for (int pos = 0; pos < kThrustersPerPod; ++pos) {
      const auto t = static_cast<std::size_t>(thruster_index(pod, pos));
      if (!out.on[t]) continue;
      const Physical ph = physical_thruster(pod, pos);
      torque += (r_so_bcm + ph.position).cross(out.force[t] * ph.direction);
    }
  }
  const gnc::Vec3 expected = b * cmd.force;
  EXPECT_LT((torque - expected).norm(), 1e-9 * expected.norm());
}

TEST(ThrusterBank, ChannelForcesInvertTheMapping) {
  const ThrusterBank bank = default_bank();
  gnc::ThrusterCommand cmd;
  cmd.enabled = true;
  cmd.force << 1.0, -2.0, 30.0, -40.0, 0.0, 199.9, -199.9, 7.0;
  ThrusterOutputs out;
  bank.command(cmd, out);
  EXPECT_EQ((bank.channel_forces(out) - cmd.force).cwiseAbs().maxCoeff(), 0.0);
}

TEST(ThrusterBank, DisabledCommandInhibitsEveryThruster) {
  const ThrusterBank bank = default_bank();
  gnc::ThrusterCommand cmd;
  cmd.enabled = false;
  cmd.force.setConstant(100.0);
  ThrusterOutputs out;
  out.on.fill(true);
  bank.command(cmd, out);
  EXPECT_FALSE(out.enabled);
  for (int t = 0; t < kThrusters; ++t) {
    EXPECT_FALSE(out.on[static_cast<std::size_t>(t)]);
    EXPECT_EQ(out.force[static_cast<std::size_t>(t)], 0.0);
  }
}

TEST(ThrusterBank, LatchValveCommandsPassThroughEnabledOrNot) {
  const ThrusterBank bank = default_bank();
  gnc::ThrusterCommand cmd;
  EXPECT_EQ(cmd.valve_open, (std::array<bool, 4>{true, true, true, true}));  // default: all open
  for (int mask = 0; mask < 16; ++mask) {
    for (const bool enabled : {true, false}) {
      cmd.enabled = enabled;
      cmd.force.setConstant(50.0);
      for (int p = 0; p < 4; ++p) cmd.valve_open[static_cast<std::size_t>(p)] = ((mask >> p) & 1) == 0;
      ThrusterOutputs out;
      bank.command(cmd, out);
      EXPECT_EQ(out.valve_open, cmd.valve_open) << "mask " << mask;
      // The bank does not second-guess the valves: thrusters follow the channels alone (the valve
      // stops the propellant downstream).
      for (int t = 0; t < kThrusters; ++t) {
        EXPECT_EQ(out.on[static_cast<std::size_t>(t)], enabled && t % 2 == 0) << t;
      }
    }
  }
}

TEST(ThrusterBank, UnconfiguredBankFiresNothing) {
  const ThrusterBank bank;
  gnc::ThrusterCommand cmd;
  cmd.enabled = true;
  cmd.force.setConstant(10.0);
  ThrusterOutputs out;
  bank.command(cmd, out);
  EXPECT_FALSE(out.enabled);
  for (const bool on : out.on) EXPECT_FALSE(on);
}

TEST(ThrusterBank, ClampsAtUMaxAndSkipsNonFiniteChannels) {
  const ThrusterBank bank = default_bank(200.0);
  gnc::ThrusterCommand cmd;
  cmd.enabled = true;
  cmd.force << 250.0, -1e9, std::nan(""), INFINITY, 10.0, 0.0, 0.0, 0.0;
  ThrusterOutputs out;
  const BankStatus status = bank.command(cmd, out);
  EXPECT_EQ(status.clamped, 2);
  EXPECT_EQ(status.non_finite, 2);
  EXPECT_DOUBLE_EQ(out.force[thruster_index(0, 0)], 200.0);
  EXPECT_DOUBLE_EQ(out.force[thruster_index(0, 3)], 200.0);
  for (const int pos : {0, 1, 2, 3}) EXPECT_FALSE(out.on[static_cast<std::size_t>(thruster_index(1, pos))]);
  EXPECT_TRUE(out.on[thruster_index(2, 0)]);
}

TEST(ThrusterBank, ForcesAtOrBelowMinForceLeaveThrustersOff) {
  ThrusterBankConfig config = default_thruster_bank_config(200.0);
  config.min_force = 1.0;
  ThrusterBank bank;
  ASSERT_TRUE(bank.configure(config).ok());
  gnc::ThrusterCommand cmd;
  cmd.enabled = true;
  cmd.force << 1.0, -0.5, 1.5, 0.0, 0.0, 0.0, 0.0, 0.0;
  ThrusterOutputs out;
  bank.command(cmd, out);
  int on = 0;
  for (const bool b : out.on) on += b ? 1 : 0;
  EXPECT_EQ(on, 1);
  EXPECT_TRUE(out.on[thruster_index(1, 0)]);
}

TEST(ThrusterBank, CustomWiringIsFollowed) {
  // Pod 2's pairs swapped: its tangential pair sits at positions 3 (+) and 2 (-).
  ThrusterBankConfig config = default_thruster_bank_config(200.0);
  config.channel[4] = ChannelWiring{2, 3, 2};
  config.channel[5] = ChannelWiring{2, 1, 0};
  ThrusterBank bank;
  ASSERT_TRUE(bank.configure(config).ok());
  gnc::ThrusterCommand cmd;
  cmd.enabled = true;
  cmd.force(4) = 5.0;
  cmd.force(5) = -6.0;
  ThrusterOutputs out;
  bank.command(cmd, out);
  EXPECT_DOUBLE_EQ(out.force[thruster_index(2, 3)], 5.0);
  EXPECT_DOUBLE_EQ(out.force[thruster_index(2, 0)], 6.0);
  EXPECT_EQ((bank.channel_forces(out) - cmd.force).norm(), 0.0);
}

TEST(ThrusterBankConfig, DefaultWiringIsValid) {
  const gnc::RcsLayout layout = gnc::study_rcs_layout(200.0);
  EXPECT_TRUE(validate(default_thruster_bank_config(200.0), &layout).ok());
}

TEST(ThrusterBankConfig, RejectsThrusterUsedTwiceAndNamesTheChannel) {
  ThrusterBankConfig config = default_thruster_bank_config(200.0);
  config.channel[3] = ChannelWiring{1, 0, 3};  // pod 1 position 0 already belongs to channel 2
  const BankConfigCheck c = validate(config);
  EXPECT_EQ(c.error, BankConfigError::kThrusterUsedTwice);
  EXPECT_EQ(c.channel, 3);
}

TEST(ThrusterBankConfig, RejectsOutOfRangeAndDegenerateWiring) {
  ThrusterBankConfig config = default_thruster_bank_config(200.0);
  config.channel[6].pod = 4;
  EXPECT_EQ(validate(config).error, BankConfigError::kPodOutOfRange);
  config = default_thruster_bank_config(200.0);
  config.channel[1].minus = -1;
  EXPECT_EQ(validate(config).error, BankConfigError::kPositionOutOfRange);
  config = default_thruster_bank_config(200.0);
  config.channel[0].minus = config.channel[0].plus;
  EXPECT_EQ(validate(config).error, BankConfigError::kPlusEqualsMinus);
  config = default_thruster_bank_config(200.0);
  config.u_max = 0.0;
  EXPECT_EQ(validate(config).error, BankConfigError::kBadForceLimit);
  config = default_thruster_bank_config(200.0);
  config.min_force = 200.0;
  EXPECT_EQ(validate(config).error, BankConfigError::kBadForceLimit);
}

TEST(ThrusterBankConfig, RejectsWiringThatDisagreesWithTheRcsLayout) {
  gnc::RcsLayout layout = gnc::study_rcs_layout(200.0);
  // Swap pods 0 and 1 in the wiring only.
  ThrusterBankConfig config = default_thruster_bank_config(200.0);
  for (int ch = 0; ch < 4; ++ch) config.channel[static_cast<std::size_t>(ch)].pod = 1 - ch / 2;
  EXPECT_TRUE(validate(config).ok());
  const BankConfigCheck c = validate(config, &layout);
  EXPECT_EQ(c.error, BankConfigError::kPodDisagreesWithLayout);
  EXPECT_EQ(c.channel, 0);
}

TEST(ThrusterBankConfig, FailedConfigureKeepsThePreviousWiring) {
  ThrusterBank bank = default_bank();
  ThrusterBankConfig bad = default_thruster_bank_config(200.0);
  bad.channel[0].pod = -1;
  EXPECT_FALSE(bank.configure(bad).ok());
  EXPECT_TRUE(bank.configured());
  EXPECT_EQ(bank.config().channel[0].pod, 0);
}

}  // namespace
}  // namespace rocksteady::hal
