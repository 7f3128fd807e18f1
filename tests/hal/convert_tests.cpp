// LCM back end conversions: sensor frames and thruster commands through the wire and back.
#include <gtest/gtest.h>

#include <array>
#include <vector>

#include "gnc/model/rcs.hpp"
#include "wire/codec.hpp"
#include "wire/convert.hpp"
#include "hal/lcm/lcm_ports.hpp"

namespace rocksteady::wire {
namespace {

using hal::GyroReading;
using hal::LcmSensorSource;
using hal::LcmThrusterSink;
using hal::kThrusters;
using hal::RawSensors;
using hal::StarTrackerReading;
using hal::ThrusterBank;
using hal::ThrusterOutputs;
using hal::default_thruster_bank_config;

template <class T> std::vector<unsigned char> bytes(const T& m) {
  std::vector<unsigned char> b(static_cast<std::size_t>(m.getEncodedSize()));
  EXPECT_GT(encode(m, b.data(), static_cast<int>(b.size())), 0);
  return b;
}

RawSensors sample_raw(std::int64_t seq) {
  RawSensors s;
  s.seq = seq;
  s.t = 0.1 * static_cast<double>(seq);
  s.gyro = GyroReading{s.t - 0.01, gnc::Vec3(0.01, 0.02, -0.03), true};
  s.star = StarTrackerReading{s.t - 0.02, gnc::Vec4(0.1, 0.2, 0.3, 0.927362), false};
  return s;
}

TEST(Convert, SensorFrameRoundTripsThroughTheWire) {
  const RawSensors in = sample_raw(5);
  const auto b = bytes(to_message(in));
  rocksteady::sensor_frame_t m{};
  ASSERT_TRUE(safe_decode(b.data(), static_cast<int>(b.size()), m));
  const RawSensors out = to_raw(m);
  EXPECT_EQ(out.seq, in.seq);
  EXPECT_EQ(out.t, in.t);
  EXPECT_EQ(out.gyro.t, in.gyro.t);
  EXPECT_EQ(out.gyro.rate, in.gyro.rate);
  EXPECT_EQ(out.gyro.valid, in.gyro.valid);
  EXPECT_EQ(out.star.t, in.star.t);
  EXPECT_EQ(out.star.quat, in.star.quat);
  EXPECT_EQ(out.star.valid, in.star.valid);
}

TEST(Convert, ThrusterCommandRoundTripsThroughTheWire) {
  ThrusterBank bank;
  const gnc::RcsLayout layout = gnc::study_rcs_layout(200.0);
  ASSERT_TRUE(bank.configure(default_thruster_bank_config(200.0), &layout).ok());
  gnc::ThrusterCommand cmd;
  cmd.enabled = true;
  cmd.force << 10.0, -20.0, 0.0, 200.0, -150.0, 1.0, -1.0, 33.0;
  ThrusterOutputs outputs;
  bank.command(cmd, outputs);
  const auto b = bytes(to_message(outputs, cmd.force, 77, 7.7));
  rocksteady::thruster_cmd_t m{};
  ASSERT_TRUE(safe_decode(b.data(), static_cast<int>(b.size()), m));
  EXPECT_EQ(m.seq, 77);
  EXPECT_EQ(channel_forces(m), cmd.force);
  const ThrusterOutputs back = to_outputs(m);
  EXPECT_EQ(back.on, outputs.on);
  EXPECT_EQ(back.force, outputs.force);
  EXPECT_EQ(bank.channel_forces(back), cmd.force);
}

TEST(Convert, LatchValvesRoundTripAndAFreshMessageMeansOpen) {
  for (int mask = 0; mask < 16; ++mask) {
    ThrusterOutputs o;
    o.enabled = mask % 3 == 0;
    for (int p = 0; p < 4; ++p) o.valve_open[static_cast<std::size_t>(p)] = ((mask >> p) & 1) == 0;
    const auto b = bytes(to_message(o, gnc::Vec8::Zero(), mask, 0.1 * mask));
    rocksteady::thruster_cmd_t m{};
    ASSERT_TRUE(safe_decode(b.data(), static_cast<int>(b.size()), m));
    for (int p = 0; p < 4; ++p) EXPECT_EQ(m.valve_closed[p], (mask >> p) & 1);
    EXPECT_EQ(to_outputs(m).valve_open, o.valve_open) << "mask " << mask;
  }
  // A message whose valve fields were never set (all zero) keeps every valve open.
  EXPECT_EQ(to_outputs(make<rocksteady::thruster_cmd_t>()).valve_open,
            (std::array<bool, 4>{true, true, true, true}));
  // A valve flag other than 0/1 is out of range.
  auto m = make<rocksteady::thruster_cmd_t>();
  m.valve_closed[2] = 3;
  const auto b = bytes(m);
  rocksteady::thruster_cmd_t back{};
  EXPECT_EQ(decode(b.data(), static_cast<int>(b.size()), back), DecodeStatus::kOutOfRange);
}

TEST(LcmThrusterSinkAllOff, SwitchesEveryThrusterOffButKeepsTheLatchValvesAsCommanded) {
  LcmThrusterSink sink(default_thruster_bank_config(200.0));  // no bus: publishes are counted errors
  ThrusterOutputs o;
  o.enabled = true;
  o.on[5] = true;
  o.force[5] = 120.0;
  o.valve_open = {true, false, true, false};
  sink.write(o, 41, 4.1);
  EXPECT_EQ(sink.last_message().valve_closed[1], 1);
  sink.all_off(42, 4.2);
  const rocksteady::thruster_cmd_t m = sink.last_message();
  EXPECT_EQ(m.enabled, 0);
  EXPECT_EQ(m.seq, 42);
  for (int i = 0; i < kThrusters; ++i) {
    EXPECT_EQ(m.thruster_on[i], 0) << i;
    EXPECT_EQ(m.thruster_force[i], 0.0) << i;
  }
  EXPECT_EQ(to_outputs(m).valve_open, (std::array<bool, 4>{true, false, true, false}));
  EXPECT_TRUE(sink.latched_off());
}

TEST(Convert, DisabledCommandDecodesToAllOff) {
  auto m = make<rocksteady::thruster_cmd_t>();
  m.enabled = 0;
  m.thruster_on[3] = 1;
  m.thruster_force[3] = 50.0;
  const ThrusterOutputs o = to_outputs(m);
  EXPECT_FALSE(o.enabled);
  EXPECT_FALSE(o.on[3]);
  EXPECT_EQ(o.force[3], 0.0);
}

TEST(Convert, GncOutputFillsTelemetryThatPassesTheChecks) {
  gnc::GncOutput out;
  out.telemetry.t = 12.0;
  out.telemetry.tick = 120;
  out.telemetry.mode = gnc::Mode::kHold;
  out.telemetry.law = gnc::LawId::kSo3;
  out.telemetry.phase = gnc::ReferencePhase::kHold;
  out.telemetry.omega_hat = gnc::Vec3(1e-3, 2e-3, 3e-3);
  out.telemetry.alloc.torque_requested = gnc::Vec3(10, 20, 30);
  out.telemetry.alloc.saturated = true;
  out.telemetry.alloc.scale = 0.5;
  out.telemetry.fuel_kg = 1.25;
  out.telemetry.sensor_rejects = 4;
  out.command.enabled = true;
  out.command.force(6) = -12.0;
  auto m = make<rocksteady::gnc_telemetry_t>();
  fill_gnc(out, m);
  EXPECT_EQ(check(m), DecodeStatus::kOk);
  EXPECT_EQ(m.tick, 120);
  EXPECT_EQ(m.mode, 2);
  EXPECT_EQ(m.law, 4);
  EXPECT_EQ(m.phase, 2);
  EXPECT_EQ(m.omega_hat[2], 3e-3);
  EXPECT_EQ(m.torque_requested[1], 20.0);
  EXPECT_EQ(m.saturated, 1);
  EXPECT_EQ(m.alloc_scale, 0.5);
  EXPECT_EQ(m.channel_force[6], -12.0);
  EXPECT_EQ(m.thrusters_enabled, 1);
  EXPECT_EQ(m.fuel_kg, 1.25);
  EXPECT_EQ(m.sensor_rejects, 4);
}

TEST(LcmSensorSource, DeliversNewestFrameCountsGarbageAndFlagsARestartedStream) {
  LcmSensorSource source;
  RawSensors s;
  EXPECT_FALSE(source.poll(s));
  const auto f3 = bytes(to_message(sample_raw(3)));
  const auto f4 = bytes(to_message(sample_raw(4)));
  const auto f0 = bytes(to_message(sample_raw(0)));
  const auto f1 = bytes(to_message(sample_raw(1)));
  std::vector<unsigned char> junk(f3.begin(), f3.begin() + 20);
  EXPECT_TRUE(source.on_message(f3.data(), static_cast<int>(f3.size())));
  EXPECT_FALSE(source.on_message(junk.data(), static_cast<int>(junk.size())));
  EXPECT_TRUE(source.on_message(f4.data(), static_cast<int>(f4.size())));
  EXPECT_TRUE(source.pending());
  EXPECT_EQ(source.pending_seq(), 4);
  ASSERT_TRUE(source.poll(s));
  EXPECT_EQ(s.seq, 4);  // the newest; frame 3 was superseded before the tick
  EXPECT_FALSE(s.stream_restart);
  EXPECT_FALSE(source.poll(s));
  EXPECT_EQ(source.superseded(), 1u);
  EXPECT_EQ(source.counters().ok, 2u);
  EXPECT_EQ(source.counters().too_short, 1u);
  // The numbering goes backwards: a restarted stream, flagged on the next frame polled only.
  EXPECT_TRUE(source.on_message(f0.data(), static_cast<int>(f0.size())));
  EXPECT_EQ(source.restarts(), 1u);
  ASSERT_TRUE(source.poll(s));
  EXPECT_EQ(s.seq, 0);
  EXPECT_TRUE(s.stream_restart);
  EXPECT_TRUE(source.on_message(f1.data(), static_cast<int>(f1.size())));
  ASSERT_TRUE(source.poll(s));
  EXPECT_FALSE(s.stream_restart);
  // A waiting frame can be dropped unticked (a lockstep resend).
  EXPECT_TRUE(source.on_message(f1.data(), static_cast<int>(f1.size())));
  source.drop();
  EXPECT_FALSE(source.poll(s));
}

}  // namespace
}  // namespace rocksteady::wire
