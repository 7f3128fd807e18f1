// The application in closed loop with a test-only rigid body: command sequences, autonomous
// transitions, sensor timeout to SAFE, and bad sensor input that must never stop the software.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "fsw_harness.hpp"

namespace rocksteady::fsw {
namespace {

using test::AppFixture;
using test::V3;
using test::V4;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

double mode_arg(gnc::Mode m) {
  return static_cast<double>(static_cast<int>(m));
}

TEST(FlightApp, InitRejectsAnExecutivePeriodThatDiffersFromTheGncPeriod) {
  FakeClock clock;
  auto app = std::make_unique<FlightApp>();
  FlightConfig cfg = test::small_config();
  cfg.executive.base_rate_hz = 10.0;  // 0.1 s, but gnc.dt is 0.05 s
  const InitResult r = app->init(cfg, clock);
  EXPECT_FALSE(r.ok);
  EXPECT_STREQ(r.field, "executive.gnc_divider");
  cfg = test::small_config();
  cfg.gnc.mode.sensor_timeout_s = -1.0;
  EXPECT_STREQ(app->init(cfg, clock).field, "mode.sensor_timeout");
  EXPECT_FALSE(app->initialised());
}

TEST(FlightApp, IdleToDetumbleToHoldThroughCommands) {
  AppFixture f;
  f.loop.truth.omega = V3(0.08, -0.05, 0.04);  // well above omega_switch = 0.02 rad/s
  f.ticks(5);
  EXPECT_EQ(f.app->mode(), gnc::Mode::kIdle);
  EXPECT_FALSE(f.out.command.enabled);  // IDLE: thrusters inhibited
  test::drain(*f.app);

  const CommandAck a = f.send(Opcode::kSetMode, {mode_arg(gnc::Mode::kDetumble)});
  ASSERT_TRUE(a.accepted) << a.text;
  f.ticks(1);
  ASSERT_EQ(f.app->mode(), gnc::Mode::kDetumble);
  EXPECT_TRUE(f.out.command.enabled);
  // Rate damping: the commanded torque opposes the body rate.
  const V3 tau = f.loop.b * f.out.command.force;
  EXPECT_LT(tau.dot(f.loop.truth.omega), 0.0);

  int ticks = 0;
  while (f.app->mode() == gnc::Mode::kDetumble && ticks < 4000) {
    f.ticks(1);
    ++ticks;
  }
  ASSERT_EQ(f.app->mode(), gnc::Mode::kHold) << "no auto-hold after " << ticks << " ticks";
  // Auto-hold at |omega_hat| <= omega_switch: the truth is there too (pass-through estimator).
  EXPECT_LE(f.loop.truth.omega.norm(), 0.02 + 0.01);
  const auto ev = test::drain(*f.app);
  ASSERT_GE(ev.size(), 3u);
  EXPECT_EQ(ev[0].id, EventId::kCommandAccepted);
  EXPECT_EQ(ev[1].id, EventId::kModeChanged);
  EXPECT_EQ(ev[1].arg0, static_cast<std::int32_t>(gnc::Mode::kIdle));
  EXPECT_EQ(ev[1].arg1, static_cast<std::int32_t>(gnc::Mode::kDetumble));
  EXPECT_EQ(test::count_events(ev, EventId::kAutoHold), 1);

  // HOLD keeps the body quiet and converges on the target attitude (identity).
  const double err0 = f.out.telemetry.attitude_error.norm();
  f.ticks(600);
  EXPECT_EQ(f.app->mode(), gnc::Mode::kHold);
  EXPECT_LT(f.out.telemetry.attitude_error.norm(), err0 + 1e-12);
  EXPECT_LT(f.loop.truth.omega.norm(), 0.02);
  // Repeating the current mode is refused.
  EXPECT_EQ(f.send(Opcode::kSetMode, {mode_arg(gnc::Mode::kHold)}).reason,
            RejectReason::kNotAllowedInMode);
}

TEST(FlightApp, NoSensorFrameForTheTimeoutGoesSafeWithThrustersOff) {
  AppFixture f;
  f.loop.truth.omega = V3(0.08, 0.0, 0.0);
  f.ticks(3);
  ASSERT_TRUE(f.send(Opcode::kSetMode, {mode_arg(gnc::Mode::kDetumble)}).accepted);
  f.ticks(1);
  ASSERT_EQ(f.app->mode(), gnc::Mode::kDetumble);
  test::drain(*f.app);
  // Real-time tick source with no frames arriving: each GNC cycle runs with an invalid sample at
  // the scheduled time. timeout 0.5 s / dt 0.05 s: SAFE on the tick where the age exceeds 0.5 s.
  const double dt = f.app->active_params().dt;
  const double timeout = f.app->active_params().mode.sensor_timeout_s;
  const int expected = static_cast<int>(std::floor(timeout / dt)) + 1;
  int n = 0;
  std::uint64_t index = f.app->executive().base_ticks();
  while (f.app->mode() != gnc::Mode::kSafe && n < 100) {
    f.clock.advance(50000000);
    f.app->tick(Tick{index++, f.clock.now_ns(), 0}, nullptr, f.out);
    ++n;
  }
  ASSERT_EQ(f.app->mode(), gnc::Mode::kSafe);
  EXPECT_GE(n, expected - 1);
  EXPECT_LE(n, expected + 1);
  EXPECT_FALSE(f.out.command.enabled);
  EXPECT_EQ(f.out.command.force, gnc::Vec8::Zero());
  EXPECT_EQ(f.app->health().frameless_ticks, static_cast<std::uint32_t>(n));
  const auto ev = test::drain(*f.app);
  ASSERT_EQ(test::count_events(ev, EventId::kSensorTimeout), 1);
  for (const Event& e : ev) {
    if (e.id == EventId::kSensorTimeout) {
      EXPECT_EQ(e.severity, Severity::kError);
    }
  }
  // Frames come back: SAFE stays until the ground commands it out.
  f.ticks(10);
  EXPECT_EQ(f.app->mode(), gnc::Mode::kSafe);
  EXPECT_TRUE(f.send(Opcode::kSetMode, {mode_arg(gnc::Mode::kDetumble)}).accepted);
  f.ticks(1);
  EXPECT_EQ(f.app->mode(), gnc::Mode::kDetumble);
}

TEST(FlightApp, FramelessTickAtAnExplicitTimeCountsTowardsTheTimeout) {
  AppFixture f;
  f.ticks(3);
  const double t0 = f.loop.truth.t;
  Outputs out;
  f.app->gnc_tick_without_frame(t0 + 0.2, out);
  EXPECT_EQ(f.app->mode(), gnc::Mode::kIdle);
  f.app->gnc_tick_without_frame(t0 + 0.7, out);  // 0.75 s after the last good sample
  EXPECT_EQ(f.app->mode(), gnc::Mode::kSafe);
  EXPECT_DOUBLE_EQ(out.telemetry.t, t0 + 0.7);
}

TEST(FlightApp, BadSensorInputIsRejectedAndNeverStopsTheSoftware) {
  AppFixture f;
  f.loop.truth.omega = V3(0.05, 0.0, 0.0);
  f.ticks(3);
  ASSERT_TRUE(f.send(Opcode::kSetMode, {mode_arg(gnc::Mode::kDetumble)}).accepted);
  f.ticks(1);
  const std::uint32_t rejects0 = f.app->health().sensor_rejects;
  Outputs out;
  gnc::SensorSample s = f.loop.truth.sample();
  // Non-finite and out-of-range values: the flight core rejects the sample.
  s.t += 0.05;
  s.gyro_rate = V3(kNaN, 0, 0);
  f.app->gnc_tick(s, out);
  s.t += 0.05;
  s.gyro_rate = V3(1e6, 0, 0);           // above gyro_max_rate
  s.star_quat = V4(0.5, 0.5, 0.5, 2.0);  // not a unit quaternion
  f.app->gnc_tick(s, out);
  EXPECT_EQ(f.app->health().sensor_rejects, rejects0 + 2);
  EXPECT_TRUE(out.command.force.allFinite());
  // Bad time tags: non-finite, going back, jumping far ahead. The tick runs without a frame.
  const std::uint32_t frames0 = f.app->health().frames_rejected;
  s = f.loop.truth.sample();
  s.t = kNaN;
  f.app->gnc_tick(s, out);
  s.t = f.loop.truth.t - 10.0;
  f.app->gnc_tick(s, out);
  s.t = f.loop.truth.t + 1e9;
  f.app->gnc_tick(s, out);
  EXPECT_EQ(f.app->health().frames_rejected, frames0 + 3);
  EXPECT_TRUE(out.gnc_ran);
  EXPECT_TRUE(std::isfinite(out.telemetry.t));
  // Five bad samples in a row, 0.25 s: not yet a timeout. A flood of them: SAFE, never a crash.
  for (int i = 0; i < 40; ++i) {
    s.t = kNaN;
    f.app->gnc_tick(s, out);
  }
  EXPECT_EQ(f.app->mode(), gnc::Mode::kSafe);
  EXPECT_FALSE(out.command.enabled);
  // Events are throttled: one report per kind per interval, not one per bad sample.
  const auto ev = test::drain(*f.app);
  EXPECT_EQ(test::count_events(ev, EventId::kFrameRejected), 1);
  EXPECT_EQ(test::count_events(ev, EventId::kSensorRejected), 1);
}

TEST(FlightApp, TimeBaseResynchronisesAfterARunOfRejectedFrames) {
  FlightConfig cfg = test::small_config();
  cfg.frame_resync_count = 5;
  AppFixture f(cfg);
  f.loop.truth.t = 1000.0;
  f.ticks(3);
  f.loop.truth.t = 0.0;  // the sensor front end restarted its clock
  for (int i = 0; i < 5; ++i) f.ticks(1);
  EXPECT_EQ(f.app->health().frames_rejected, 5u);
  f.ticks(2);  // the 6th and 7th: a run of consistent frames, still rejected
  EXPECT_EQ(f.app->health().frames_rejected, 7u);
  f.ticks(1);  // the 8th completes the run (frame_resync_run 3) and re-anchors the base
  EXPECT_EQ(f.app->health().frames_rejected, 7u);
  EXPECT_NEAR(f.out.telemetry.t, f.loop.truth.t - 0.05, 1e-12);
}

TEST(FlightApp, HousekeepingPublishesHealthAtItsRate) {
  AppFixture f;  // 20 Hz base, housekeeping divider 20: 1 Hz
  int published = 0;
  for (int i = 0; i < 100; ++i) {
    f.ticks(1);
    if (f.out.housekeeping_ran) {
      ++published;
      EXPECT_EQ(f.out.health.gnc.cycles, static_cast<std::uint32_t>(i + 1));
      EXPECT_EQ(f.out.health.frames_accepted, static_cast<std::uint32_t>(i + 1));
    }
  }
  EXPECT_EQ(published, 5);  // base ticks 0, 20, 40, 60, 80
  EXPECT_EQ(f.app->health().housekeeping.cycles, 5u);
}

TEST(FlightApp, EventQueueDropsAndCountsWhenFull) {
  AppFixture f;
  test::drain(*f.app);  // the lab-mode announcement (event 0)
  for (int i = 0; i < EventQueue::kCapacity + 10; ++i) f.send(Opcode::kNoop);
  EXPECT_EQ(f.app->pending_events(), EventQueue::kCapacity);
  EXPECT_EQ(f.app->health().events_dropped, 10u);
  EXPECT_EQ(f.app->health().events_emitted, static_cast<std::uint32_t>(EventQueue::kCapacity + 11));
  Event e;
  ASSERT_TRUE(f.app->pop_event(e));
  EXPECT_EQ(e.seq, 1u);  // the oldest are kept
}

}  // namespace
}  // namespace rocksteady::fsw

namespace rocksteady::fsw {
namespace {

TEST(FlightApp, RepeatedOverrunsGoSafe) {
  FlightConfig cfg = test::small_config();
  cfg.overrun_safe_slips = 4;
  test::AppFixture f(cfg);
  f.loop.truth.omega = test::V3(0.08, 0.0, 0.0);
  f.ticks(3);
  ASSERT_TRUE(f.send(Opcode::kSetMode, {1.0}).accepted);
  f.ticks(1);
  ASSERT_EQ(f.app->mode(), gnc::Mode::kDetumble);
  test::drain(*f.app);
  // Every tick claims to have been due before the previous cycle ended: an overrun each time.
  std::uint64_t index = f.app->executive().base_ticks();
  int n = 0;
  while (f.app->mode() != gnc::Mode::kSafe && n < 20) {
    const std::int64_t end_of_previous = f.clock.now_ns();
    f.clock.advance(50000000);
    gnc::SensorSample s = f.loop.truth.sample();
    f.app->tick(Tick{index++, end_of_previous - 1, 0}, &s, f.out);
    f.loop.truth.step(0.05, test::V3::Zero());
    ++n;
  }
  EXPECT_EQ(n, 4);
  EXPECT_EQ(f.app->mode(), gnc::Mode::kSafe);
  EXPECT_FALSE(f.out.command.enabled);
  EXPECT_EQ(f.app->health().gnc.slips, 4u);
  const auto ev = test::drain(*f.app);
  EXPECT_EQ(test::count_events(ev, EventId::kOverrunSafe), 1);
}

TEST(FlightApp, OccasionalSlipsDoNotGoSafe) {
  FlightConfig cfg = test::small_config();
  cfg.overrun_safe_slips = 4;
  test::AppFixture f(cfg);
  std::uint64_t index = 0;
  for (int k = 0; k < 40; ++k) {
    const std::int64_t end_of_previous = f.clock.now_ns();
    f.clock.advance(50000000);
    gnc::SensorSample s = f.loop.truth.sample();
    const bool slip = k % 4 != 0;  // three in a row at most
    f.app->tick(Tick{index++, slip ? end_of_previous - 1 : f.clock.now_ns(), 0}, &s, f.out);
    f.loop.truth.step(0.05, test::V3::Zero());
  }
  EXPECT_EQ(f.app->mode(), gnc::Mode::kIdle);
  EXPECT_EQ(f.app->health().gnc.slips, 30u);  // k = 1..39 except multiples of 4
}

}  // namespace
}  // namespace rocksteady::fsw
