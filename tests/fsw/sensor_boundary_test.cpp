// Plausibility at the sensor boundary: frame sequence numbers and times that jump beyond a bound
// are rejected and counted, never adopted as a new time base from one frame; re-synchronisation
// only after a run of consistent frames; counters and event arguments that cannot overflow.
#include <gtest/gtest.h>

#include <cstdint>

#include "fsw/executive/executive.hpp"
#include "fsw/executive/tick_source.hpp"
#include "fsw_harness.hpp"

namespace rocksteady::fsw {
namespace {

constexpr std::int64_t kMs = 1000000;

// The spoofed frame of the finding: seq 10^15 after seq 10 becomes no tick, no missed ticks.
TEST(SensorBoundary, OneFrameWithAHugeSequenceJumpIsRejectedAndCounted) {
  LockstepSource src;
  Tick t;
  for (std::int64_t s = 0; s <= 10; ++s) {
    ASSERT_TRUE(src.on_frame(s, s * kMs));
    ASSERT_TRUE(src.next(t));
  }
  EXPECT_FALSE(src.on_frame(1000000000000000LL, 11 * kMs));
  EXPECT_FALSE(src.next(t));
  EXPECT_EQ(src.jump_rejects(), 1u);
  ASSERT_TRUE(src.on_frame(11, 12 * kMs));  // the genuine stream goes on
  ASSERT_TRUE(src.next(t));
  EXPECT_EQ(t.index, 11u);
  EXPECT_EQ(t.missed, 0u);
  EXPECT_EQ(src.missed_total(), 0u);
  // Just inside the bound: a real gap, counted as missed ticks.
  ASSERT_TRUE(src.on_frame(11 + LockstepSource::kMaxSeqJump, 13 * kMs));
  ASSERT_TRUE(src.next(t));
  EXPECT_EQ(t.missed, static_cast<std::uint32_t>(LockstepSource::kMaxSeqJump - 1));
}

TEST(SensorBoundary, ANewNumberingIsAdoptedOnlyAfterARunOfConsistentFrames) {
  LockstepSource src;
  Tick t;
  for (std::int64_t s = 0; s < 5; ++s) {
    ASSERT_TRUE(src.on_frame(s, 0));
    ASSERT_TRUE(src.next(t));
  }
  const std::int64_t base = 5000000;
  // Inconsistent implausible frames (a spoofer's scattershot) never resynchronise.
  for (int i = 0; i < 20; ++i) {
    EXPECT_FALSE(src.on_frame(base + (i % 2 == 0 ? 0 : 1000000) + i, 0));
  }
  // A run of kResyncRun frames each 1 above the previous: the last one is adopted, ticks go on.
  for (std::uint32_t i = 0; i + 1 < LockstepSource::kResyncRun; ++i) {
    EXPECT_FALSE(src.on_frame(base + 100 + i, 0));
  }
  ASSERT_TRUE(src.on_frame(base + 100 + LockstepSource::kResyncRun - 1, 0));
  ASSERT_TRUE(src.next(t));
  EXPECT_EQ(t.index, 5u);
  EXPECT_EQ(t.missed, 0u);
  EXPECT_EQ(src.resyncs(), 1u);
  ASSERT_TRUE(src.on_frame(base + 100 + LockstepSource::kResyncRun, 0));
  ASSERT_TRUE(src.next(t));
  EXPECT_EQ(t.index, 6u);
}

TEST(SensorBoundary, MissedTickCountsSaturateInsteadOfWrapping) {
  Executive e;
  ASSERT_TRUE(e.configure(lockstep_executive(0.1, 1.0)).ok);
  ASSERT_TRUE(e.plan(Tick{0, 0, 0}).valid);
  const std::uint64_t far = (1ULL << 33) + 5;  // 2^33 + 4 missed: truncated to 32 bits = 4
  const TickPlan p = e.plan(Tick{far, 0, 0});
  ASSERT_TRUE(p.valid);
  EXPECT_EQ(p.base_missed, 0xFFFFFFFFu);
  EXPECT_EQ(e.base_missed(), 0xFFFFFFFFu);
  e.plan(Tick{far + 10, 0, 0});
  EXPECT_EQ(e.base_missed(), 0xFFFFFFFFu);  // stays saturated
}

// Through the application: the missed-ticks event's argument never overflows negative.
TEST(SensorBoundary, MissedTicksEventArgumentIsNeverNegative) {
  test::AppFixture f;
  Outputs out;
  test::drain(*f.app);
  f.app->tick(Tick{0, 0, 0}, nullptr, out);
  f.app->tick(Tick{2764463428ULL + (1ULL << 32), 0, 0}, nullptr, out);
  bool seen = false;
  for (const Event& e : test::drain(*f.app)) {
    if (e.id != EventId::kMissedTicks) continue;
    seen = true;
    EXPECT_GT(e.arg0, 0);
    EXPECT_GE(e.arg1, 0);
  }
  EXPECT_TRUE(seen);
}

// The frame time base: one frame far ahead (t = 10^9 s) is refused; after the resync count of
// rejections, one stray frame still does not re-anchor the base; a consistent run does.
TEST(SensorBoundary, TimeBaseIsNeverReanchoredByOneFrame) {
  FlightConfig cfg = test::small_config();
  cfg.frame_resync_count = 5;
  cfg.frame_resync_run = 3;
  test::AppFixture f(cfg);
  f.ticks(5);
  const double t_before = f.app->onboard_time();
  Outputs out;
  gnc::SensorSample spoof = f.loop.truth.sample();
  spoof.t = 1e9;
  f.app->gnc_tick(spoof, out);
  EXPECT_EQ(f.app->health().frames_rejected, 1u);
  EXPECT_LT(f.app->onboard_time(), t_before + 1.0);
  // Many spoofed frames, each alone (interleaved with the genuine stream's stale times).
  for (int i = 0; i < 10; ++i) {
    spoof.t = 1e9 + 1e6 * i;
    f.app->gnc_tick(spoof, out);
    gnc::SensorSample stale = f.loop.truth.sample();
    stale.t = 1e12 - 1e9 * i;  // decreasing: never consistent with the previous candidate
    f.app->gnc_tick(stale, out);
  }
  EXPECT_LT(f.app->onboard_time(), t_before + 10.0);
  EXPECT_EQ(f.app->health().frames_rejected, 21u);
  // A consistent run (a sensor front end that really restarted at t = 5000 s): adopted at its
  // third frame.
  for (int i = 0; i < 3; ++i) {
    gnc::SensorSample s = f.loop.truth.sample();
    s.t = 5000.0 + 0.05 * i;
    f.app->gnc_tick(s, out);
  }
  EXPECT_EQ(f.app->health().frames_rejected, 23u);
  EXPECT_NEAR(f.app->onboard_time(), 5000.1, 1e-9);
}

}  // namespace
}  // namespace rocksteady::fsw
