// Zero heap allocations in the flight loop after init: global operator new (and, outside the
// sanitizer build, malloc) are counted once armed. Covers ticks with frames, without frames, bad
// frames, command submission, trajectory chunks, table activation, events and their draining.
#include <gtest/gtest.h>

#include "heap_counter.hpp"

#include <cstdlib>

#include "fsw_harness.hpp"


namespace rocksteady::fsw {
namespace {

using Armed = rocksteady::test::HeapArmed;

// The instrument itself: an allocation while armed is seen.
TEST(FlightAppAllocation, CounterSeesAnAllocationWhileArmed) {
  long n = 0;
  {
    const Armed armed;
    auto p = std::make_unique<std::vector<int>>(100, 1);
    volatile int sink = (*p)[99];
    (void)sink;
    n = rocksteady::test::heap_allocations();
  }
  EXPECT_GE(n, 2);
}

TEST(FlightAppAllocation, TheFlightLoopAllocatesNothingAfterInit) {
  // Everything the loop needs exists before arming (the test's own containers included).
  test::AppFixture f;
  f.loop.truth.omega = test::V3(0.08, -0.05, 0.04);
  auto plan = std::make_unique<gnc::TrajectoryTable>();
  test::linear_despin_table(test::V3(0.05, 0.0, 0.0), 10.0, 70, *plan);
  const std::vector<TrajectoryChunk> chunks = test::chunks_of(*plan, 1);
  const GroundCommand detumble = test::command(1, Opcode::kSetMode, {1.0});
  const GroundCommand bad = test::command(2, Opcode::kSetTarget, {0.9, 0.9, 0.0});
  const GroundCommand load_kp = test::command(3, Opcode::kParamLoad, {18.0, 4.0});
  const GroundCommand activate = test::command(4, Opcode::kParamActivate);
  const GroundCommand load_traj = test::command(5, Opcode::kLoadTrajectory, {1.0});
  const GroundCommand bad_table = test::command(6, Opcode::kParamLoad, {0.0, -1.0, 1.0, 1.0});
  const GroundCommand stale = test::command(1, Opcode::kNoop);  // repeats the first
  Event e;
  Outputs out;
  gnc::SensorSample nan_frame;
  nan_frame.t = std::numeric_limits<double>::quiet_NaN();
  f.ticks(3);
  long allocations = -1;
  {
    const Armed armed;
    for (int i = 0; i < 400; ++i) {
      if (i == 5) f.app->submit(detumble);
      if (i == 6) f.app->submit(bad);
      if (i == 7) f.app->submit(stale);
      if (i == 8) f.app->submit(bad_table);
      if (i == 10) f.app->submit(load_kp);
      if (i == 11) f.app->submit(activate);
      if (i >= 20 && i < 20 + static_cast<int>(chunks.size())) f.app->receive_chunk(chunks[i - 20]);
      if (i == 30) f.app->submit(load_traj);
      if (i == 50) f.app->gnc_tick(nan_frame, out);
      if (i == 51) f.app->gnc_tick_without_frame(f.loop.truth.t, out);
      f.loop.tick(*f.app, f.out);
      while (f.app->pop_event(e)) {
      }
      f.clock.advance(50000000);
    }
    allocations = rocksteady::test::heap_allocations();
  }
  EXPECT_EQ(allocations, 0);
  // The loop did what it was asked: detumbled into HOLD, activated the table, loaded the plan.
  EXPECT_EQ(f.app->mode(), gnc::Mode::kHold);
  EXPECT_EQ(f.app->active_params().dpd.k_p, 4.0);
  EXPECT_TRUE(f.app->trajectory_loaded());
  const HealthTelemetry h = f.app->health();
  EXPECT_EQ(h.cmd_accepted, 4u);
  EXPECT_EQ(h.cmd_rejected, 3u);
}

// A re-plan while tracking: chunks, LOAD_TRAJECTORY in TRACK, the switch at the boundary and a
// stale plan refused there, all without the heap.
TEST(FlightAppAllocation, ReplanInTrackSwitchesAtTheBoundaryWithoutTheHeap) {
  test::AppFixture f;
  const test::V3 w0(0.05, -0.02, 0.01);
  f.loop.truth.omega = w0;
  f.ticks(2);
  auto first = std::make_unique<gnc::TrajectoryTable>();
  test::linear_despin_table(w0, 20.0, 70, *first);
  for (const auto& c : test::chunks_of(*first, 1)) f.app->receive_chunk(c);
  ASSERT_TRUE(f.app->submit(test::command(1, Opcode::kLoadTrajectory, {1.0})).accepted);
  ASSERT_TRUE(f.app->submit(test::command(2, Opcode::kSetMode, {3.0})).accepted);
  f.ticks(2);
  ASSERT_EQ(f.app->mode(), gnc::Mode::kTrack);
  auto replan = std::make_unique<gnc::TrajectoryTable>();
  test::linear_despin_table(f.app->core_output().telemetry.omega_hat, 40.0, 91, *replan);
  auto stale = std::make_unique<gnc::TrajectoryTable>();
  test::linear_despin_table(-w0, 40.0, 91, *stale);
  const std::vector<TrajectoryChunk> c_replan = test::chunks_of(*replan, 2);
  const std::vector<TrajectoryChunk> c_stale = test::chunks_of(*stale, 3);
  const GroundCommand load_replan = test::command(3, Opcode::kLoadTrajectory, {2.0});
  const GroundCommand load_stale = test::command(4, Opcode::kLoadTrajectory, {3.0});
  Event e;
  int switched = 0;
  int refused = 0;
  long allocations = -1;
  {
    const Armed armed;
    for (int i = 0; i < 60; ++i) {
      if (i < static_cast<int>(c_replan.size())) f.app->receive_chunk(c_replan[i]);
      if (i == 5) f.app->submit(load_replan);
      if (i >= 10 && i < 10 + static_cast<int>(c_stale.size())) f.app->receive_chunk(c_stale[i - 10]);
      if (i == 20) f.app->submit(load_stale);
      f.loop.tick(*f.app, f.out);
      while (f.app->pop_event(e)) {
        switched += e.id == EventId::kTrajectorySwitched ? 1 : 0;
        refused += e.id == EventId::kTrajectoryStale ? 1 : 0;
      }
      f.clock.advance(50000000);
    }
    allocations = rocksteady::test::heap_allocations();
  }
  EXPECT_EQ(allocations, 0);
  EXPECT_EQ(switched, 1);
  EXPECT_EQ(refused, 1);
  EXPECT_EQ(f.app->mode(), gnc::Mode::kTrack);
  EXPECT_EQ(f.app->core().trajectories().active().checksum, replan->checksum);
}

}  // namespace
}  // namespace rocksteady::fsw
