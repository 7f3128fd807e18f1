// Executive: dividers, absolute deadlines, slips, missed ticks, throttled warnings; fake clock
// only.
#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "fsw/executive/clock.hpp"
#include "fsw/executive/executive.hpp"
#include "fsw/executive/tick_source.hpp"
#include "fsw_harness.hpp"

namespace rocksteady::fsw {
namespace {

constexpr std::int64_t kMs = 1000000;

ExecutiveConfig config(double base_hz, std::uint32_t gnc_div, std::uint32_t hk_div,
                       double slip_interval_s = 10.0) {
  ExecutiveConfig c;
  c.base_rate_hz = base_hz;
  c.gnc_divider = gnc_div;
  c.housekeeping_divider = hk_div;
  c.slip_event_interval_s = slip_interval_s;
  return c;
}

TEST(Executive, DividersScheduleEachGroupAtItsRate) {
  Executive exec;
  ASSERT_TRUE(exec.configure(config(100.0, 10, 100)).ok);
  std::vector<std::uint64_t> gnc_ticks;
  std::vector<std::uint64_t> hk_ticks;
  for (std::uint64_t i = 0; i < 300; ++i) {
    const TickPlan p = exec.plan(Tick{i, static_cast<std::int64_t>(i) * 10 * kMs, 0});
    ASSERT_TRUE(p.valid);
    if (p.due[static_cast<int>(GroupId::kGnc)]) gnc_ticks.push_back(i);
    if (p.due[static_cast<int>(GroupId::kHousekeeping)]) hk_ticks.push_back(i);
  }
  // 100 Hz base: GNC at 10 Hz (every 10th tick), housekeeping at 1 Hz (every 100th).
  const std::vector<std::uint64_t> hk_expected{0, 100, 200};
  EXPECT_EQ(hk_ticks, hk_expected);
  ASSERT_EQ(gnc_ticks.size(), 30u);
  for (std::size_t k = 0; k < gnc_ticks.size(); ++k) EXPECT_EQ(gnc_ticks[k], 10 * k);
  EXPECT_DOUBLE_EQ(exec.gnc_period_s(), 0.1);
  EXPECT_EQ(exec.base_period_ns(), 10 * kMs);
  EXPECT_EQ(exec.base_ticks(), 300u);
}

TEST(Executive, SkippedBaseTicksAreMissedCyclesOfTheGroupsDueOnThem) {
  Executive exec;
  ASSERT_TRUE(exec.configure(config(100.0, 10, 100)).ok);
  exec.plan(Tick{0, 0, 0});
  exec.plan(Tick{5, 0, 0});
  // Jump from base tick 5 to 237: ticks 6..236 are missed.
  const TickPlan p = exec.plan(Tick{237, 0, 231});
  ASSERT_TRUE(p.valid);
  int gnc_expected = 0;
  int hk_expected = 0;
  for (int i = 6; i <= 236; ++i) {  // enumerate the skipped ticks independently
    gnc_expected += i % 10 == 0 ? 1 : 0;
    hk_expected += i % 100 == 0 ? 1 : 0;
  }
  EXPECT_EQ(p.base_missed, 231u);
  EXPECT_EQ(p.missed[static_cast<int>(GroupId::kGnc)], static_cast<std::uint32_t>(gnc_expected));
  EXPECT_EQ(p.missed[static_cast<int>(GroupId::kHousekeeping)],
            static_cast<std::uint32_t>(hk_expected));
  EXPECT_EQ(exec.group(GroupId::kGnc).stats().missed_ticks, 23u);
  EXPECT_EQ(exec.group(GroupId::kHousekeeping).stats().missed_ticks, 2u);
  EXPECT_FALSE(p.due[static_cast<int>(GroupId::kGnc)]);
  // A tick that does not advance is refused and runs nothing.
  const TickPlan q = exec.plan(Tick{237, 0, 0});
  EXPECT_FALSE(q.valid);
  EXPECT_EQ(exec.out_of_order_ticks(), 1u);
}

TEST(Executive, RejectsBadConfiguration) {
  Executive exec;
  EXPECT_STREQ(exec.configure(config(0.0, 1, 10)).field, "executive.base_rate_hz");
  EXPECT_STREQ(exec.configure(config(10.0, 0, 10)).field, "executive.gnc_divider");
  EXPECT_STREQ(exec.configure(config(10.0, 1, 0)).field, "executive.housekeeping_divider");
  EXPECT_STREQ(exec.configure(config(10.0, 1, 10, -1.0)).field, "executive.slip_event_interval_s");
}

TEST(RealTimeClockSource, SleepsToAbsoluteDeadlinesWithoutDrift) {
  FakeClock clock(5 * kMs);
  RealTimeClockSource src(clock, 100 * kMs);
  Tick t;
  ASSERT_TRUE(src.next(t));
  EXPECT_EQ(t.index, 0u);
  EXPECT_EQ(t.start_ns, 5 * kMs);
  // Work of varying length: the deadlines stay on the grid start + k * period.
  const std::int64_t work[] = {30, 99, 1, 70, 50};
  for (int k = 1; k <= 5; ++k) {
    clock.advance(work[k - 1] * kMs);
    ASSERT_TRUE(src.next(t));
    EXPECT_EQ(t.index, static_cast<std::uint64_t>(k));
    EXPECT_EQ(t.start_ns, 5 * kMs + k * 100 * kMs);
    EXPECT_EQ(t.missed, 0u);
    EXPECT_EQ(clock.now_ns(), t.start_ns);
  }
  EXPECT_EQ(clock.sleeps(), 5u);
}

TEST(RealTimeClockSource, CountsMissedTicksWhenWorkOverrunsByWholePeriods) {
  FakeClock clock(0);
  RealTimeClockSource src(clock, 100 * kMs);
  Tick t;
  src.next(t);
  // A cycle of 350 ms: the deadlines at 100 and 200 ms are missed; the tick at 300 ms is already
  // due (in the past) and is returned at once, without sleeping.
  clock.advance(350 * kMs);
  ASSERT_TRUE(src.next(t));
  EXPECT_EQ(t.missed, 2u);
  EXPECT_EQ(t.index, 3u);
  EXPECT_EQ(t.start_ns, 300 * kMs);
  EXPECT_EQ(clock.sleeps(), 0u);
  // Back on the grid: next deadline 400 ms.
  ASSERT_TRUE(src.next(t));
  EXPECT_EQ(t.index, 4u);
  EXPECT_EQ(t.start_ns, 400 * kMs);
  EXPECT_EQ(t.missed, 0u);
  EXPECT_EQ(src.missed_total(), 2u);
}

TEST(RealTimeClockSource, CountsMissedTicksWhenTheSleepWakesLate) {
  FakeClock clock(0);
  RealTimeClockSource src(clock, 100 * kMs);
  Tick t;
  src.next(t);
  clock.set_wake_latency(99 * kMs);  // late, but by less than one period: nothing missed
  ASSERT_TRUE(src.next(t));
  EXPECT_EQ(t.missed, 0u);
  EXPECT_EQ(t.start_ns, 100 * kMs);
  clock.set_wake_latency(230 * kMs);  // woke at 430 ms for the 200 ms deadline: 2 missed
  ASSERT_TRUE(src.next(t));
  EXPECT_EQ(clock.now_ns(), 430 * kMs);
  EXPECT_EQ(t.missed, 2u);
  EXPECT_EQ(t.index, 4u);
  EXPECT_EQ(t.start_ns, 400 * kMs);
}

// The executive loop of rocksteady-fsw, on a fake clock: tick source -> plan -> group cycles.
struct FakeLoop {
  FakeClock clock{0};
  RealTimeClockSource src{clock, 100 * kMs};
  Executive exec;
  std::vector<SlipReport> slips;

  FakeLoop() { exec.configure(config(10.0, 1, 10)); }
  // One base tick whose GNC cycle takes `work_ms`.
  Tick run(std::int64_t work_ms) {
    Tick t;
    src.next(t);
    const TickPlan p = exec.plan(t);
    if (p.due[static_cast<int>(GroupId::kGnc)]) {
      RateGroup& g = exec.group(GroupId::kGnc);
      const SlipReport s = g.begin(t.start_ns, clock.now_ns());
      if (s.slipped) slips.push_back(s);
      clock.advance(work_ms * kMs);
      g.end(clock.now_ns());
    }
    return t;
  }
};

TEST(Executive, SlipWhenTheNextTickIsDueBeforeTheCycleEnded) {
  FakeLoop loop;
  loop.run(40);
  loop.run(60);
  EXPECT_TRUE(loop.slips.empty());
  loop.run(120);                // overruns its 100 ms period by 20 ms
  const Tick t = loop.run(10);  // this tick was due 20 ms before the previous cycle ended
  EXPECT_EQ(t.missed, 0u);
  ASSERT_EQ(loop.slips.size(), 1u);
  EXPECT_EQ(loop.slips[0].late_ns, 20 * kMs);
  EXPECT_TRUE(loop.slips[0].report);
  const RateGroupStats& s = loop.exec.group(GroupId::kGnc).stats();
  EXPECT_EQ(s.slips, 1u);
  EXPECT_EQ(s.missed_ticks, 0u);
  EXPECT_EQ(s.cycles, 4u);
  EXPECT_EQ(s.last_exec_ns, 10 * kMs);
  EXPECT_EQ(s.max_exec_ns, 120 * kMs);
}

TEST(Executive, OverrunByMoreThanAPeriodIsASlipAndMissedTicks) {
  FakeLoop loop;
  loop.run(10);
  loop.run(270);  // ends 270 ms after its start: deadlines +100 and +200 are missed
  loop.run(10);
  const RateGroupStats& s = loop.exec.group(GroupId::kGnc).stats();
  EXPECT_EQ(s.missed_ticks, 1u);  // the deadline at +100 ms; +200 ms runs late (a slip)
  EXPECT_EQ(s.slips, 1u);
  EXPECT_EQ(loop.exec.base_missed(), 1u);
  ASSERT_EQ(loop.slips.size(), 1u);
  EXPECT_EQ(loop.slips[0].late_ns, 70 * kMs);
}

TEST(RateGroup, SlipWarningIsThrottledWithASuppressedCount) {
  RateGroup g;
  g.configure(1, 1000 * kMs);  // at most one warning per second
  int reports = 0;
  std::uint32_t suppressed_reported = 0;
  // A cycle every 100 ms that always ends 10 ms after the next tick was due: 30 slips in 3 s.
  std::int64_t tick = 0;
  g.begin(tick, tick);
  g.end(tick + 110 * kMs);
  for (int k = 1; k <= 30; ++k) {
    tick = k * 100 * kMs;
    const SlipReport r = g.begin(tick, tick + 10 * kMs);
    EXPECT_TRUE(r.slipped);
    if (r.report) {
      ++reports;
      suppressed_reported += r.suppressed;
    }
    g.end(tick + 110 * kMs);
  }
  // Reports at the 1st slip and then once per second of clock: t = 0.11, 1.11, 2.11 s.
  EXPECT_EQ(reports, 3);
  EXPECT_EQ(g.stats().slips, 30u);
  // Everything not reported was counted as suppressed; the last 9 are still pending.
  EXPECT_EQ(suppressed_reported + 9u, 30u - 3u);
}

TEST(LockstepSource, GapsInFrameSequenceAreMissedTicksAndOldFramesAreDropped) {
  LockstepSource src;
  Tick t;
  EXPECT_FALSE(src.next(t));  // no frame yet: no tick
  ASSERT_TRUE(src.on_frame(10, 1000));
  ASSERT_TRUE(src.next(t));
  EXPECT_EQ(t.index, 0u);
  EXPECT_EQ(t.start_ns, 1000);
  EXPECT_FALSE(src.next(t));  // one tick per frame
  ASSERT_TRUE(src.on_frame(11, 2000));
  ASSERT_TRUE(src.next(t));
  EXPECT_EQ(t.index, 1u);
  EXPECT_EQ(t.missed, 0u);
  ASSERT_TRUE(src.on_frame(14, 5000));  // frames 12 and 13 never arrived
  ASSERT_TRUE(src.next(t));
  EXPECT_EQ(t.index, 4u);
  EXPECT_EQ(t.missed, 2u);
  EXPECT_FALSE(src.on_frame(14, 6000));  // repeated
  EXPECT_FALSE(src.on_frame(13, 6000));  // older
  EXPECT_FALSE(src.on_frame(-1, 6000));  // invalid
  EXPECT_FALSE(src.next(t));
  EXPECT_EQ(src.stale_frames(), 3u);
  EXPECT_EQ(src.missed_total(), 2u);
}

// Through the application: slips and missed ticks reach health telemetry and raise throttled
// warnings.
TEST(FlightAppExecutive, SlipsAndMissedTicksAreTelemeteredWithThrottledWarnings) {
  FakeClock clock(1000 * kMs);
  auto app = std::make_unique<FlightApp>();
  FlightConfig cfg = test::small_config();  // 20 Hz, slip warnings at most every 10 s
  ASSERT_TRUE(app->init(cfg, clock).ok);
  Outputs out;
  app->tick(Tick{0, 1000 * kMs, 0}, nullptr, out);  // cycle ends at clock 1000 ms
  // Each next tick claims to have been due before the previous cycle ended: a slip each time.
  for (std::uint64_t k = 1; k <= 5; ++k) {
    app->tick(Tick{k, 990 * kMs, 0}, nullptr, out);
  }
  HealthTelemetry h = app->health();
  EXPECT_EQ(h.gnc.slips, 5u);
  std::vector<Event> ev = test::drain(*app);
  EXPECT_EQ(test::count_events(ev, EventId::kSlip), 1);  // throttled
  // 11 s later the next slip is reported again, with the 4 suppressed ones counted.
  clock.advance(11000 * kMs);
  app->tick(Tick{6, 990 * kMs, 0}, nullptr, out);
  ev = test::drain(*app);
  ASSERT_EQ(test::count_events(ev, EventId::kSlip), 1);
  for (const Event& e : ev) {
    if (e.id == EventId::kSlip) {
      EXPECT_EQ(e.arg0, static_cast<std::int32_t>(GroupId::kGnc));
      EXPECT_EQ(e.arg1, 4);
      EXPECT_EQ(e.severity, Severity::kWarning);
    }
  }
  // Missed ticks: from base tick 6 to 30 (23 skipped; housekeeping every 20th: tick 20 missed).
  app->tick(Tick{30, 20000 * kMs, 23}, nullptr, out);
  h = app->health();
  EXPECT_EQ(h.base_missed, 23u);
  EXPECT_EQ(h.gnc.missed_ticks, 23u);
  EXPECT_EQ(h.housekeeping.missed_ticks, 1u);
  ev = test::drain(*app);
  EXPECT_EQ(test::count_events(ev, EventId::kMissedTicks), 1);
  EXPECT_EQ(h.gnc.cycles, 8u);
}

}  // namespace
}  // namespace rocksteady::fsw

namespace rocksteady::fsw {
namespace {

TEST(Executive, LockstepConfigurationMatchesTheGncPeriod) {
  for (const double dt : {0.05, 0.1, 0.25, 1.0}) {
    const ExecutiveConfig c = lockstep_executive(dt, 1.0);
    Executive exec;
    ASSERT_TRUE(exec.configure(c).ok) << dt;
    EXPECT_NEAR(exec.gnc_period_s(), dt, 1e-12 * dt);
    EXPECT_EQ(c.housekeeping_divider, static_cast<std::uint32_t>(std::lround(1.0 / dt)));
  }
  EXPECT_EQ(lockstep_executive(0.1, 0.0).housekeeping_divider, 1u);  // at least every tick
}

}  // namespace
}  // namespace rocksteady::fsw
