// Trajectory uplink: reassembly from out-of-order chunks, a missing chunk, a CRC mismatch, bad
// headers, and the hand-over to the flight core at the tick boundary.
#include <gtest/gtest.h>

#include <algorithm>
#include <memory>

#include "fsw/uplink/trajectory_uplink.hpp"
#include "fsw_harness.hpp"

namespace rocksteady::fsw {
namespace {

using test::AppFixture;
using test::V3;

struct Plan {
  std::unique_ptr<gnc::TrajectoryTable> table = std::make_unique<gnc::TrajectoryTable>();
  explicit Plan(int n = 70, double duration = 20.0) {
    test::linear_despin_table(V3(0.05, -0.02, 0.01), duration, n, *table);
  }
};

TEST(TrajectoryUplink, OutOfOrderChunksReassembleTheTable) {
  Plan plan(70);  // 3 chunks: 32, 32, 6 samples
  auto chunks = test::chunks_of(*plan.table, 4);
  ASSERT_EQ(chunks.size(), 3u);
  auto up = std::make_unique<TrajectoryUplink>();
  ChunkResult r = up->receive(chunks[2]);
  EXPECT_EQ(r.status, ChunkStatus::kStored);
  EXPECT_TRUE(r.started);
  EXPECT_EQ(up->receive(chunks[0]).status, ChunkStatus::kStored);
  EXPECT_EQ(up->receive(chunks[0]).status, ChunkStatus::kStored);  // a repeat is harmless
  EXPECT_FALSE(up->complete());
  EXPECT_EQ(up->chunks_received(), 2);
  r = up->receive(chunks[1]);
  EXPECT_TRUE(r.completed);
  ASSERT_TRUE(up->complete());
  ASSERT_EQ(up->finalize(plan.table->samples[0].omega_d.norm() + 1.0), gnc::TrajectoryError::kOk);
  const gnc::TrajectoryTable& got = up->table();
  ASSERT_EQ(got.count, 70);
  for (int i = 0; i < 70; ++i) {
    EXPECT_EQ(got.samples[i].t, plan.table->samples[i].t) << i;
    EXPECT_EQ(got.samples[i].omega_d, plan.table->samples[i].omega_d) << i;
    EXPECT_EQ(got.samples[i].omega_d_dot, plan.table->samples[i].omega_d_dot) << i;
  }
}

TEST(TrajectoryUplink, BadChunkHeadersAreRejected) {
  Plan plan(70);
  const auto chunks = test::chunks_of(*plan.table, 1);
  auto up = std::make_unique<TrajectoryUplink>();
  TrajectoryChunk c = chunks[0];
  c.chunk_count = 2;  // 70 samples need 3 chunks
  EXPECT_EQ(up->receive(c).status, ChunkStatus::kBadHeader);
  c = chunks[0];
  c.total_samples = gnc::kMaxTrajectorySamples + 1;
  EXPECT_EQ(up->receive(c).status, ChunkStatus::kBadHeader);
  c = chunks[0];
  c.upload_id = -2;
  EXPECT_EQ(up->receive(c).status, ChunkStatus::kBadHeader);
  c = chunks[0];
  c.chunk_index = 3;
  EXPECT_EQ(up->receive(c).status, ChunkStatus::kBadIndex);
  c = chunks[2];
  c.n = 32;  // the last chunk carries the remaining 6
  EXPECT_EQ(up->receive(c).status, ChunkStatus::kBadCount);
  EXPECT_FALSE(up->active());
  ASSERT_EQ(up->receive(chunks[0]).status, ChunkStatus::kStored);
  c = chunks[1];
  c.crc32 ^= 1u;  // same upload id, different table
  EXPECT_EQ(up->receive(c).status, ChunkStatus::kHeaderMismatch);
}

TEST(TrajectoryUplinkApp, LoadHandsTheTableToTheCoreAtTheTickBoundary) {
  AppFixture f;
  f.ticks(2);
  Plan plan(70);
  const auto chunks = test::chunks_of(*plan.table, 9);
  for (int i : {1, 2, 0}) ASSERT_EQ(f.app->receive_chunk(chunks[i]), ChunkStatus::kStored);
  HealthTelemetry h = f.app->health();
  EXPECT_EQ(h.uplink_id, 9);
  EXPECT_EQ(h.uplink_chunks_received, 3);
  const CommandAck a = f.send(Opcode::kLoadTrajectory, {9.0});
  ASSERT_TRUE(a.accepted) << a.text;
  EXPECT_FALSE(f.app->trajectory_loaded());
  // While the validated table waits for the boundary, chunks are refused.
  EXPECT_EQ(f.app->receive_chunk(chunks[0]), ChunkStatus::kBusy);
  EXPECT_EQ(f.send(Opcode::kLoadTrajectory, {9.0}).reason, RejectReason::kBusy);
  // TRACK is already allowed: the trajectory will be there when the request is applied.
  EXPECT_TRUE(f.send(Opcode::kSetLaw, {0.0, 2.0}).accepted);
  f.ticks(1);
  EXPECT_TRUE(f.app->trajectory_loaded());
  EXPECT_TRUE(f.out.telemetry.trajectory_loaded);
  EXPECT_EQ(f.app->mode(), gnc::Mode::kTrack);
  h = f.app->health();
  EXPECT_EQ(h.trajectories_loaded, 1u);
  EXPECT_EQ(h.uplink_id, -1);
  const auto ev = test::drain(*f.app);
  EXPECT_EQ(test::count_events(ev, EventId::kUplinkStarted), 1);
  EXPECT_EQ(test::count_events(ev, EventId::kUplinkComplete), 1);
  EXPECT_EQ(test::count_events(ev, EventId::kTrajectoryLoaded), 1);
  EXPECT_EQ(test::count_events(ev, EventId::kChunkRejected), 1);
}

TEST(TrajectoryUplinkApp, MissingChunkBlocksTheLoadAndTrack) {
  AppFixture f;
  f.ticks(2);
  Plan plan(70);
  const auto chunks = test::chunks_of(*plan.table, 3);
  f.app->receive_chunk(chunks[0]);
  f.app->receive_chunk(chunks[2]);
  const CommandAck a = f.send(Opcode::kLoadTrajectory, {3.0});
  EXPECT_EQ(a.reason, RejectReason::kUploadIncomplete);
  EXPECT_EQ(a.detail, 2);  // chunks received
  EXPECT_EQ(f.send(Opcode::kSetMode, {3.0}).detail,
            static_cast<std::int32_t>(gnc::TransitionCheck::kNoTrajectory));
  // The missing chunk arrives: now it loads.
  f.app->receive_chunk(chunks[1]);
  EXPECT_TRUE(f.send(Opcode::kLoadTrajectory, {3.0}).accepted);
}

TEST(TrajectoryUplinkApp, CrcMismatchRejectsTheTable) {
  AppFixture f;
  f.ticks(2);
  Plan plan(70);
  auto chunks = test::chunks_of(*plan.table, 5);
  chunks[1].samples[7].omega_d.x() += 1e-9;  // one corrupted value; the CRC is of the original
  for (const auto& c : chunks) f.app->receive_chunk(c);
  const CommandAck a = f.send(Opcode::kLoadTrajectory, {5.0});
  EXPECT_EQ(a.reason, RejectReason::kTrajectoryRejected);
  EXPECT_EQ(a.detail, static_cast<std::int32_t>(gnc::TrajectoryError::kBadChecksum));
  EXPECT_FALSE(f.app->uplink().active());  // discarded: the ground sends it again
  f.ticks(1);
  EXPECT_FALSE(f.app->trajectory_loaded());
  const auto ev = test::drain(*f.app);
  EXPECT_EQ(test::count_events(ev, EventId::kTrajectoryRejected), 1);
}

TEST(TrajectoryUplinkApp, OnlyAnAbortEndsAnUnfinishedUploadAndAnotherUploadIsRefused) {
  AppFixture f;
  Plan a(70);
  Plan b(40);
  const auto ca = test::chunks_of(*a.table, 1);
  const auto cb = test::chunks_of(*b.table, 2);
  EXPECT_EQ(f.app->receive_chunk(ca[0]), ChunkStatus::kStored);
  // A chunk of another upload (a stray one, or a new upload begun without aborting) is refused
  // and the uplink in progress keeps every chunk it had.
  EXPECT_EQ(f.app->receive_chunk(cb[1]), ChunkStatus::kOtherUplinkActive);
  EXPECT_EQ(f.app->uplink().upload_id(), 1);
  EXPECT_EQ(f.app->uplink().chunks_received(), 1);
  EXPECT_EQ(f.app->health().uplink_chunks_rejected, 1u);
  {
    const auto ev = test::drain(*f.app);
    EXPECT_EQ(test::count_events(ev, EventId::kUplinkAbandoned), 0);
    ASSERT_EQ(test::count_events(ev, EventId::kChunkRejected), 1);
    for (const auto& e : ev) {
      if (e.id != EventId::kChunkRejected) continue;
      EXPECT_EQ(e.arg0, 2);
      EXPECT_EQ(e.arg1, static_cast<std::int32_t>(ChunkStatus::kOtherUplinkActive));
      EXPECT_NE(std::string(e.text.data()).find("ABORT_UPLINK 1"), std::string::npos) << e.text.data();
    }
  }
  // The first upload completes and loads despite the stray chunk.
  for (std::size_t i = 1; i < ca.size(); ++i) {
    EXPECT_EQ(f.app->receive_chunk(ca[i]), ChunkStatus::kStored);
  }
  EXPECT_TRUE(f.app->uplink().complete());
  // Only an ABORT_UPLINK naming the upload in progress ends it; then the other upload can start.
  EXPECT_EQ(f.send(Opcode::kAbortUplink, {2.0}).reason, RejectReason::kOutOfRange);
  EXPECT_TRUE(f.app->uplink().active());
  EXPECT_TRUE(f.send(Opcode::kAbortUplink, {1.0}).accepted);
  EXPECT_FALSE(f.app->uplink().active());
  EXPECT_EQ(f.app->receive_chunk(cb[1]), ChunkStatus::kStored);
  EXPECT_EQ(f.app->uplink().upload_id(), 2);
  const auto ev = test::drain(*f.app);
  EXPECT_EQ(test::count_events(ev, EventId::kUplinkAbandoned), 1);  // the abort
}

// A re-plan while tracking: LOAD_TRAJECTORY in TRACK validates the uplinked table into the standby
// buffer and the core switches to it at the tick boundary (trajectory_switched), re-synchronising
// the reference to the estimate; TRACK never stops and the target stays locked.
TEST(TrajectoryUplinkApp, TrackSwitchesToAnUplinkedReplanAtTheTickBoundary) {
  AppFixture f;
  const V3 w0(0.05, -0.02, 0.01);
  f.loop.truth.omega = w0;
  f.ticks(2);
  Plan first(70, 20.0);
  for (const auto& c : test::chunks_of(*first.table, 1)) f.app->receive_chunk(c);
  ASSERT_TRUE(f.send(Opcode::kLoadTrajectory, {1.0}).accepted);
  ASSERT_TRUE(f.send(Opcode::kSetMode, {3.0}).accepted);
  f.ticks(1);
  ASSERT_EQ(f.app->mode(), gnc::Mode::kTrack);
  f.ticks(20);  // 1 s into the plan
  test::drain(*f.app);
  const int index_before = f.app->core().trajectories().active_index();

  // The re-plan: from the rate now, a slower despin (40 s), 91 samples.
  const V3 w_now = f.app->core_output().telemetry.omega_hat;
  gnc::TrajectoryTable replan{};
  test::linear_despin_table(w_now, 40.0, 91, replan);
  for (const auto& c : test::chunks_of(replan, 2)) {
    EXPECT_EQ(f.app->receive_chunk(c), ChunkStatus::kStored);
  }
  EXPECT_GT((f.app->core_output().telemetry.q_d - f.app->core_output().telemetry.q_hat).norm(),
            0.0);
  const CommandAck a = f.send(Opcode::kLoadTrajectory, {2.0});
  ASSERT_TRUE(a.accepted) << a.text;
  // Still the first table until the boundary.
  EXPECT_EQ(f.app->core().trajectories().active_index(), index_before);
  EXPECT_EQ(f.app->core().trajectories().active().count, 70);
  f.ticks(1);
  EXPECT_EQ(f.app->mode(), gnc::Mode::kTrack);
  EXPECT_NE(f.app->core().trajectories().active_index(), index_before);
  EXPECT_EQ(f.app->core().trajectories().active().count, 91);
  EXPECT_EQ(f.app->core().trajectories().active().samples[90].t, 40.0);
  EXPECT_FALSE(f.app->core().trajectories().switch_pending());
  EXPECT_EQ(f.app->health().trajectories_loaded, 2u);
  const auto ev = test::drain(*f.app);
  EXPECT_EQ(test::count_events(ev, EventId::kTrajectoryLoaded), 1);
  EXPECT_EQ(test::count_events(ev, EventId::kTrajectorySwitched), 1);
  EXPECT_EQ(test::count_events(ev, EventId::kTrajectoryStale), 0);
  // The reference re-synchronised to the estimate at the switch: q_d restarts at q_hat (before it,
  // q_d had been propagated along the first plan for a second and differed from q_hat).
  EXPECT_LT((f.app->core_output().telemetry.q_d - f.app->core_output().telemetry.q_hat).norm(),
            1e-12);
  // Still tracking afterwards, and the rate keeps falling along the new plan.
  f.ticks(200);
  EXPECT_EQ(f.app->mode(), gnc::Mode::kTrack);
  EXPECT_LT(f.loop.truth.omega.norm(), w_now.norm());
  // Other rules of TRACK are unchanged: the target stays, D+PD cannot track.
  EXPECT_EQ(f.send(Opcode::kSetTarget, {0.1, 0.0, 0.0}).reason, RejectReason::kNotAllowedInMode);
  const CommandAck dpd = f.send(Opcode::kSetLaw, {5.0});
  EXPECT_EQ(dpd.reason, RejectReason::kNotAllowedInMode);
  EXPECT_EQ(dpd.detail, static_cast<std::int32_t>(gnc::TransitionCheck::kLawCannotTrack));
}

// A stale re-plan (no sample near the rate estimate: planned for another state) is loaded, refused
// at the boundary (trajectory_stale), and TRACK keeps following the table it had; a failed one
// (bad CRC) is refused at the command and changes nothing.
TEST(TrajectoryUplinkApp, StaleOrFailedReplanInTrackIsRefusedAndTheActiveTableKept) {
  AppFixture f;
  const V3 w0(0.05, -0.02, 0.01);
  f.loop.truth.omega = w0;
  f.ticks(2);
  Plan first(70, 20.0);
  for (const auto& c : test::chunks_of(*first.table, 1)) f.app->receive_chunk(c);
  ASSERT_TRUE(f.send(Opcode::kLoadTrajectory, {1.0}).accepted);
  ASSERT_TRUE(f.send(Opcode::kSetMode, {3.0}).accepted);
  f.ticks(1);
  ASSERT_EQ(f.app->mode(), gnc::Mode::kTrack);
  test::drain(*f.app);
  const int index_before = f.app->core().trajectories().active_index();

  // Failed: one corrupted value under the original CRC.
  gnc::TrajectoryTable bad{};
  const V3 w_now = f.app->core_output().telemetry.omega_hat;
  test::linear_despin_table(w_now, 30.0, 50, bad);
  auto chunks = test::chunks_of(bad, 2);
  chunks[0].samples[3].omega_d.y() += 1e-6;
  for (const auto& c : chunks) f.app->receive_chunk(c);
  const CommandAck a = f.send(Opcode::kLoadTrajectory, {2.0});
  EXPECT_EQ(a.reason, RejectReason::kTrajectoryRejected);
  EXPECT_EQ(a.detail, static_cast<std::int32_t>(gnc::TrajectoryError::kBadChecksum));
  f.ticks(1);
  EXPECT_EQ(f.app->core().trajectories().active_index(), index_before);
  EXPECT_EQ(f.app->core().trajectories().active().count, 70);

  // Stale: a valid despin from the opposite rate. Its samples (1 - s)(-w) are at least |w| from
  // the estimate w, above the 20 % tolerance; it validates, loads, and is refused at the boundary.
  const V3 w = f.app->core_output().telemetry.omega_hat;
  gnc::TrajectoryTable stale{};
  test::linear_despin_table(-w, 30.0, 50, stale);
  double nearest = 1e9;
  for (int i = 0; i < stale.count; ++i) {
    nearest = std::min(nearest, (stale.samples[i].omega_d - w).norm());
  }
  ASSERT_GT(nearest, gnc::stale_tolerance(w) * 1.5);  // independent check: it really is stale
  for (const auto& c : test::chunks_of(stale, 3)) {
    EXPECT_EQ(f.app->receive_chunk(c), ChunkStatus::kStored);
  }
  ASSERT_TRUE(f.send(Opcode::kLoadTrajectory, {3.0}).accepted);
  f.ticks(1);
  EXPECT_EQ(f.app->mode(), gnc::Mode::kTrack);
  EXPECT_EQ(f.app->core().trajectories().active_index(), index_before);
  EXPECT_EQ(f.app->core().trajectories().active().count, 70);
  EXPECT_EQ(f.app->core().trajectories().active().checksum, first.table->checksum);
  EXPECT_FALSE(f.app->core().trajectories().switch_pending());
  const auto ev = test::drain(*f.app);
  EXPECT_EQ(test::count_events(ev, EventId::kTrajectoryRejected), 1);  // the bad CRC
  EXPECT_EQ(test::count_events(ev, EventId::kTrajectoryStale), 1);
  EXPECT_EQ(test::count_events(ev, EventId::kTrajectorySwitched), 0);
  // The uplink path is free again for the next re-plan.
  EXPECT_FALSE(f.app->uplink().active());
}

// The finding: a table with omega_d_dot = +-1 rad/s^2 and a recomputed CRC loaded, and TRACK drove
// |omega_r| to 9.9 rad/s. Samples within eps_trans are not enough: the flight follows the cubic
// Hermite interpolation of omega_d and omega_d_dot, so both are bounded now.
TEST(TrajectoryUplinkApp, AccelerationsAndTheInterpolationBetweenSamplesAreBounded) {
  auto load = [](gnc::TrajectoryTable& t, std::int32_t id) {
    t.checksum = gnc::trajectory_checksum(t);  // the attacker recomputes the CRC
    AppFixture f;
    f.ticks(2);
    for (const TrajectoryChunk& c : test::chunks_of(t, id)) {
      EXPECT_EQ(f.app->receive_chunk(c), ChunkStatus::kStored);
    }
    const CommandAck a = f.send(Opcode::kLoadTrajectory, {static_cast<double>(id)});
    f.ticks(1);
    return std::make_pair(a, f.app->trajectory_loaded());
  };
  // The small test vehicle: eps_trans 1 rad/s. Every sample inside it, but omega_d_dot alternating
  // +-1e3 rad/s^2: far above what its thrusters can produce, and the interpolation swings out.
  Plan wild(70, 20.0);
  for (int i = 0; i + 1 < wild.table->count; ++i) {
    wild.table->samples[i].omega_d_dot = V3((i % 2 == 0 ? 1e3 : -1e3), 0.0, 0.0);
  }
  auto [a, loaded] = load(*wild.table, 5);
  EXPECT_FALSE(a.accepted);
  EXPECT_EQ(a.reason, RejectReason::kTrajectoryRejected);
  EXPECT_FALSE(loaded);
  // Plausible accelerations, but an interpolation that leaves eps_trans between two samples
  // (slopes of opposite sign at samples on the bound): refused too.
  Plan edge(70, 20.0);
  for (int i = 0; i < edge.table->count; ++i) {
    edge.table->samples[i].omega_d = V3(i + 1 < edge.table->count ? 0.999 : 0.0, 0.0, 0.0);
    edge.table->samples[i].omega_d_dot = V3(i % 2 == 0 ? 0.5 : -0.5, 0.0, 0.0);
  }
  edge.table->samples[edge.table->count - 1].omega_d_dot.setZero();
  const double mid = gnc::interpolate(*edge.table, 0.5 * (edge.table->samples[0].t +
                                                         edge.table->samples[1].t)).omega_d.norm();
  ASSERT_GT(mid, 1.01);  // independent check that this table really leaves the bound
  auto [b, loaded_b] = load(*edge.table, 6);
  EXPECT_EQ(b.reason, RejectReason::kTrajectoryRejected) << b.text;
  EXPECT_FALSE(loaded_b);
  // The ordinary despin plan still loads.
  Plan ok(70, 20.0);
  auto [c, loaded_c] = load(*ok.table, 7);
  EXPECT_TRUE(c.accepted) << c.text;
  EXPECT_TRUE(loaded_c);
}

}  // namespace
}  // namespace rocksteady::fsw
