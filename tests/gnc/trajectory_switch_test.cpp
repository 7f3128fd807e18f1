// Double-buffered trajectory tables (gnc/guidance/trajectory_buffers.hpp): a plan loaded while TRACK
// runs waits in the standby table and becomes active at the next tick boundary with an event, the
// reference re-synchronised to the estimate; a stale or invalid plan is refused and the active one
// kept.
#include <gtest/gtest.h>

#include "gnc/gnc.hpp"
#include "gnc/guidance/trajectory_buffers.hpp"
#include "gnc_harness.hpp"

namespace rocksteady::gnc {
namespace {

int count_events(const GncOutput& out, EventId id) {
  int n = 0;
  for (int i = 0; i < out.events.count; ++i) n += out.events.items[i].id == id ? 1 : 0;
  return n;
}

// A small vehicle in TRACK on a linear despin plan, some seconds into it.
struct Tracking : ::testing::Test {
  GncParams p = test::small_vehicle_params();
  test::SmallLoop loop{p};
  TrajectoryTable first{};
  double t_entry{0.0};
  void SetUp() override {
    ASSERT_TRUE(loop.gnc.init(p).ok);
    loop.body.omega = Vec3(0.06, -0.04, 0.05);  // gentle: within the small RCS's authority
    test::linear_despin_table(loop.body.omega, 60.0, first);
    ASSERT_EQ(loop.gnc.load_trajectory(first), TrajectoryError::kOk);
    GncCommands c;
    c.has_mode_request = true;
    c.mode_request = Mode::kTrack;
    t_entry = loop.t;  // plan time 0
    loop.tick(c);
    ASSERT_EQ(loop.gnc.mode(), Mode::kTrack);
    for (int i = 0; i < 100; ++i) loop.tick();  // 5 s into the plan
  }
};

TEST(TrajectoryBuffers, LoadWhileNotTrackingActivatesAtOnceAndKeepsTheCopy) {
  TrajectoryBuffers b;
  EXPECT_FALSE(b.valid());
  TrajectoryTable t;
  test::linear_despin_table(Vec3(0.1, 0.0, 0.0), 10.0, t);
  ASSERT_EQ(b.load(t, 1.0, false), TrajectoryError::kOk);
  EXPECT_TRUE(b.valid());
  EXPECT_FALSE(b.switch_pending());
  const int first = b.active_index();
  t.samples[3].omega_d.x() = 9.0;  // the caller's copy changes; the active table does not
  EXPECT_EQ(b.active().samples[3].omega_d.x(), 0.1 * (1.0 - 0.03));
  ASSERT_EQ(b.load(TrajectoryTable{}, 1.0, false), TrajectoryError::kTooFewSamples);
  EXPECT_EQ(b.active_index(), first);  // an invalid table touches nothing
}

TEST(TrajectoryBuffers, StagedTableSwitchesOnlyAtTheBoundaryAndOnlyWhenNotStale) {
  TrajectoryBuffers b;
  TrajectoryTable a;
  TrajectoryTable c;
  test::linear_despin_table(Vec3(0.1, 0.0, 0.0), 10.0, a);
  test::linear_despin_table(Vec3(0.0, 0.05, 0.0), 10.0, c);
  ASSERT_EQ(b.load(a, 1.0, false), TrajectoryError::kOk);
  const int ia = b.active_index();
  ASSERT_EQ(b.load(c, 1.0, true), TrajectoryError::kOk);
  EXPECT_TRUE(b.switch_pending());
  EXPECT_EQ(b.active_index(), ia);  // still the old one until the boundary
  EXPECT_EQ(b.load(c, 1.0, true), TrajectoryError::kBusyTracking);  // one staged at a time
  // omega_hat far from every sample of c: stale, refused, the old table stays.
  EXPECT_EQ(b.switch_at_boundary(Vec3(0.0, 0.0, 0.5), 0.01), SwitchOutcome::kRefusedStale);
  EXPECT_EQ(b.active_index(), ia);
  EXPECT_FALSE(b.switch_pending());
  EXPECT_EQ(b.switch_at_boundary(Vec3::Zero(), 0.01), SwitchOutcome::kNone);
  // Staged again, the estimate on the plan: switched.
  ASSERT_EQ(b.load(c, 1.0, true), TrajectoryError::kOk);
  EXPECT_EQ(b.switch_at_boundary(Vec3(0.0, 0.03, 0.0), 0.01), SwitchOutcome::kSwitched);
  EXPECT_NE(b.active_index(), ia);
  EXPECT_EQ(b.active().samples[0].omega_d, c.samples[0].omega_d);
}

TEST_F(Tracking, ReplanFromTheCurrentStateSwitchesAtTheNextTickWithAnEventAndResyncs) {
  // The re-plan: a new linear despin from the current rate, over a different duration.
  TrajectoryTable replan;
  test::linear_despin_table(loop.body.omega, 40.0, replan);
  const int before = loop.gnc.trajectories().active_index();
  ASSERT_EQ(loop.gnc.load_trajectory(replan), TrajectoryError::kOk);
  EXPECT_TRUE(loop.gnc.trajectories().switch_pending());
  EXPECT_EQ(loop.gnc.trajectories().active_index(), before);  // not inside the call
  loop.tick();
  EXPECT_EQ(count_events(loop.out, EventId::kTrajectorySwitched), 1);
  EXPECT_EQ(loop.gnc.trajectories().active_index(), 1 - before);
  EXPECT_FALSE(loop.gnc.trajectories().switch_pending());
  EXPECT_EQ(loop.gnc.mode(), Mode::kTrack);
  // Re-synchronised: the desired attitude restarts from the estimate at the switch tick.
  EXPECT_LT((loop.out.telemetry.q_d - loop.out.telemetry.q_hat).norm(), 1e-12);
  // ... and TRACK follows the new plan from the switch on (checked 30 s later, before the
  // augmentation near rest), not the old one.
  const double t_switch = loop.t - p.dt;
  while (loop.t < t_switch + 30.0) {
    loop.tick();
    ASSERT_EQ(count_events(loop.out, EventId::kTrajectorySwitched), 0);
  }
  ASSERT_EQ(loop.out.telemetry.phase, ReferencePhase::kTrack);
  const Vec3 new_plan = interpolate(replan, loop.t - t_switch).omega_d;
  const Vec3 old_plan = interpolate(first, loop.t - t_entry).omega_d;
  EXPECT_LT((loop.body.omega - new_plan).norm(), 0.1 * (loop.body.omega - old_plan).norm());
}

TEST_F(Tracking, StaleReplanIsRefusedAtTheBoundaryAndTheOldPlanKept) {
  TrajectoryTable stale;  // planned for a rate the body does not have
  test::linear_despin_table(Vec3(-0.3, 0.2, -0.25), 40.0, stale);
  const int before = loop.gnc.trajectories().active_index();
  ASSERT_EQ(loop.gnc.load_trajectory(stale), TrajectoryError::kOk);
  loop.tick();
  EXPECT_EQ(count_events(loop.out, EventId::kTrajectoryStale), 1);
  EXPECT_EQ(count_events(loop.out, EventId::kTrajectorySwitched), 0);
  EXPECT_EQ(loop.gnc.trajectories().active_index(), before);
  EXPECT_EQ(loop.gnc.mode(), Mode::kTrack);
  // Still on the first plan: omega follows its omega_d.
  const TrajectoryTable& active = loop.gnc.trajectories().active();
  EXPECT_EQ(active.checksum, first.checksum);
}

TEST_F(Tracking, InvalidReplanIsRejectedAndNothingIsStaged) {
  TrajectoryTable bad;
  test::linear_despin_table(loop.body.omega, 40.0, bad);
  bad.samples[5].omega_d.x() += 1e-3;  // checksum no longer matches
  EXPECT_EQ(loop.gnc.load_trajectory(bad), TrajectoryError::kBadChecksum);
  EXPECT_FALSE(loop.gnc.trajectories().switch_pending());
  loop.tick();
  EXPECT_EQ(count_events(loop.out, EventId::kTrajectorySwitched), 0);
  EXPECT_EQ(count_events(loop.out, EventId::kTrajectoryStale), 0);
}

}  // namespace
}  // namespace rocksteady::gnc
