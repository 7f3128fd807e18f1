// Trajectory uplink: chunking on the ground, reassembly and CRC check on board.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include "hal/lcm/codec.hpp"
#include "hal/lcm/uplink.hpp"

namespace rocksteady::hal::wire {
namespace {

using Chunk = rocksteady::trajectory_chunk_t;

std::unique_ptr<gnc::TrajectoryTable> table_of(int n) {
  auto t = std::make_unique<gnc::TrajectoryTable>();
  t->count = n;
  for (int i = 0; i < n; ++i) {
    auto& s = t->samples[static_cast<std::size_t>(i)];
    s.t = 10.0 * i;
    s.omega_d = gnc::Vec3(1e-3 * std::sin(0.1 * i), 2e-3, -1e-3 * i / n);
    s.omega_d_dot = gnc::Vec3(1e-5, -1e-5 * i, 0.0);
    if (i == n - 1) {  // a plan ends at rest
      s.omega_d.setZero();
      s.omega_d_dot.setZero();
    }
  }
  t->checksum = gnc::trajectory_checksum(*t);
  return t;
}

void expect_same_table(const gnc::TrajectoryTable& a, const gnc::TrajectoryTable& b) {
  ASSERT_EQ(a.count, b.count);
  EXPECT_EQ(a.checksum, b.checksum);
  for (int i = 0; i < a.count; ++i) {
    const auto k = static_cast<std::size_t>(i);
    EXPECT_EQ(a.samples[k].t, b.samples[k].t);
    EXPECT_EQ(a.samples[k].omega_d, b.samples[k].omega_d);
    EXPECT_EQ(a.samples[k].omega_d_dot, b.samples[k].omega_d_dot);
  }
}

TEST(Uplink, ChunkCountCoversTheTable) {
  EXPECT_EQ(chunk_count(2), 1);
  EXPECT_EQ(chunk_count(Chunk::SAMPLES), 1);
  EXPECT_EQ(chunk_count(Chunk::SAMPLES + 1), 2);
  EXPECT_EQ(chunk_count(gnc::kMaxTrajectorySamples), gnc::kMaxTrajectorySamples / Chunk::SAMPLES);
}

TEST(Uplink, ChunksInAnyOrderWithDuplicatesReassembleTheTable) {
  const auto table = table_of(100);  // 4 chunks, the last one partial
  auto asm_ = std::make_unique<TrajectoryAssembler>();
  const int n = chunk_count(table->count);
  ASSERT_EQ(n, 4);
  Chunk c{};
  const int order[] = {2, 0, 0, 3, 1};
  const UplinkResult expected[] = {UplinkResult::kAccepted, UplinkResult::kAccepted,
                                   UplinkResult::kDuplicate, UplinkResult::kAccepted,
                                   UplinkResult::kComplete};
  for (int i = 0; i < 5; ++i) {
    ASSERT_TRUE(make_chunk(*table, 9, order[i], c));
    EXPECT_EQ(check(c), DecodeStatus::kOk);
    EXPECT_EQ(asm_->add(c), expected[i]) << i;
  }
  ASSERT_TRUE(asm_->complete());
  EXPECT_EQ(asm_->upload_id(), 9);
  expect_same_table(asm_->table(), *table);
  EXPECT_EQ(gnc::validate_trajectory(asm_->table(), 1.0), gnc::TrajectoryError::kOk);
}

TEST(Uplink, CorruptedSampleFailsTheTableChecksum) {
  const auto table = table_of(40);
  auto asm_ = std::make_unique<TrajectoryAssembler>();
  Chunk c{};
  ASSERT_TRUE(make_chunk(*table, 1, 0, c));
  EXPECT_EQ(asm_->add(c), UplinkResult::kAccepted);
  ASSERT_TRUE(make_chunk(*table, 1, 1, c));
  c.omega_d[3][1] += 1e-12;
  EXPECT_EQ(asm_->add(c), UplinkResult::kBadChecksum);
  EXPECT_FALSE(asm_->complete());
  EXPECT_FALSE(asm_->in_progress());
}

TEST(Uplink, ChunkFromAnotherTableIsInconsistent) {
  const auto a = table_of(70);
  const auto b = table_of(90);
  auto asm_ = std::make_unique<TrajectoryAssembler>();
  Chunk c{};
  ASSERT_TRUE(make_chunk(*a, 4, 0, c));
  EXPECT_EQ(asm_->add(c), UplinkResult::kAccepted);
  ASSERT_TRUE(make_chunk(*b, 4, 1, c));  // same upload id, different header
  EXPECT_EQ(asm_->add(c), UplinkResult::kInconsistent);
  EXPECT_EQ(asm_->received(), 1);
}

TEST(Uplink, NewUploadIdRestartsAndAbortDiscards) {
  const auto a = table_of(70);
  auto asm_ = std::make_unique<TrajectoryAssembler>();
  Chunk c{};
  ASSERT_TRUE(make_chunk(*a, 1, 0, c));
  asm_->add(c);
  ASSERT_TRUE(make_chunk(*a, 2, 0, c));
  EXPECT_EQ(asm_->add(c), UplinkResult::kAccepted);
  EXPECT_EQ(asm_->upload_id(), 2);
  EXPECT_EQ(asm_->received(), 1);
  EXPECT_FALSE(asm_->abort(1));
  EXPECT_TRUE(asm_->abort(2));
  EXPECT_FALSE(asm_->in_progress());
}

TEST(Uplink, MalformedChunksAreRejected) {
  const auto a = table_of(70);
  auto asm_ = std::make_unique<TrajectoryAssembler>();
  Chunk c{};
  ASSERT_TRUE(make_chunk(*a, 1, 2, c));
  Chunk bad = c;
  bad.count = -1;
  EXPECT_EQ(check(bad), DecodeStatus::kOutOfRange);
  EXPECT_EQ(asm_->add(bad), UplinkResult::kMalformed);
  bad = c;
  bad.chunk_index = 3;  // beyond total_chunks
  EXPECT_EQ(asm_->add(bad), UplinkResult::kMalformed);
  bad = c;
  bad.total_samples = gnc::kMaxTrajectorySamples + 1;
  EXPECT_EQ(asm_->add(bad), UplinkResult::kMalformed);
  bad = c;
  bad.t[5] = NAN;
  EXPECT_EQ(asm_->add(bad), UplinkResult::kMalformed);
  bad = c;
  bad.table_crc = -1;
  EXPECT_EQ(asm_->add(bad), UplinkResult::kMalformed);
  EXPECT_FALSE(asm_->in_progress());
  EXPECT_FALSE(make_chunk(*a, 1, 3, c));
  EXPECT_FALSE(make_chunk(*a, -1, 0, c));
}

}  // namespace
}  // namespace rocksteady::hal::wire
