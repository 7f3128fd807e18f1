// Trajectory uplink, ground side: chunking a table into trajectory_chunk_t messages.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include "wire/codec.hpp"
#include "wire/uplink.hpp"

namespace rocksteady::wire {
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

// Reassemble in the test (independently of fsw/uplink) and compare with the original table.
TEST(Uplink, ChunksCarryTheWholeTableAndItsChecksum) {
  for (const int n : {2, 31, 32, 33, 100, gnc::kMaxTrajectorySamples}) {
    const auto table = table_of(n);
    auto rebuilt = std::make_unique<gnc::TrajectoryTable>();
    const int chunks = chunk_count(n);
    for (int i = chunks - 1; i >= 0; --i) {
      Chunk c{};
      ASSERT_TRUE(make_chunk(*table, 9, i, c));
      ASSERT_EQ(check(c), DecodeStatus::kOk) << n << ' ' << i;
      EXPECT_EQ(c.total_chunks, chunks);
      EXPECT_EQ(c.total_samples, n);
      EXPECT_EQ(static_cast<std::uint32_t>(c.table_crc), table->checksum);
      for (int k = 0; k < c.count; ++k) {
        auto& s = rebuilt->samples[static_cast<std::size_t>(c.first_sample + k)];
        s.t = c.t[k];
        s.omega_d = gnc::Vec3(c.omega_d[k][0], c.omega_d[k][1], c.omega_d[k][2]);
        s.omega_d_dot = gnc::Vec3(c.omega_d_dot[k][0], c.omega_d_dot[k][1], c.omega_d_dot[k][2]);
      }
      rebuilt->count += c.count;
    }
    rebuilt->checksum = gnc::trajectory_checksum(*rebuilt);
    expect_same_table(*rebuilt, *table);
    EXPECT_EQ(gnc::validate_trajectory(*rebuilt, 1.0), gnc::TrajectoryError::kOk);
  }
}

TEST(Uplink, ChecksumIsRecomputedNotTrusted) {
  auto table = table_of(40);
  const std::uint32_t right = table->checksum;
  table->checksum = 12345;
  Chunk c{};
  ASSERT_TRUE(make_chunk(*table, 1, 0, c));
  EXPECT_EQ(static_cast<std::uint32_t>(c.table_crc), right);
}

TEST(Uplink, OutOfRangeChunksFailTheChecks) {
  const auto a = table_of(70);
  Chunk c{};
  ASSERT_TRUE(make_chunk(*a, 1, 2, c));
  Chunk bad = c;
  bad.count = -1;
  EXPECT_EQ(check(bad), DecodeStatus::kOutOfRange);
  bad = c;
  bad.chunk_index = 3;  // beyond total_chunks
  EXPECT_EQ(check(bad), DecodeStatus::kOutOfRange);
  bad = c;
  bad.first_sample = 0;
  EXPECT_EQ(check(bad), DecodeStatus::kOutOfRange);
  bad = c;
  bad.total_samples = gnc::kMaxTrajectorySamples + 1;
  EXPECT_EQ(check(bad), DecodeStatus::kOutOfRange);
  bad = c;
  bad.t[5] = NAN;
  EXPECT_EQ(check(bad), DecodeStatus::kOutOfRange);
  bad = c;
  bad.table_crc = -1;
  EXPECT_EQ(check(bad), DecodeStatus::kOutOfRange);
  bad = c;
  bad.upload_id = -1;
  EXPECT_EQ(check(bad), DecodeStatus::kOutOfRange);
  EXPECT_FALSE(make_chunk(*a, 1, 3, c));
  EXPECT_FALSE(make_chunk(*a, -1, 0, c));
  EXPECT_FALSE(make_chunk(*table_of(1), 1, 0, c));
}

}  // namespace
}  // namespace rocksteady::wire
