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

}  // namespace
}  // namespace rocksteady::fsw
