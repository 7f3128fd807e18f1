// Reassembly of a chunked trajectory uplink into a gnc::TrajectoryTable staging buffer. Chunks may
// arrive in any order and more than once; the table is assembled and validated
// (gnc::validate_trajectory: CRC, monotonic time, rate bound, rest at the end) only when the
// ground commands the load, and handed to the flight core at the next tick boundary.
#pragma once

#include <array>
#include <cstdint>

#include "fsw/interface.hpp"
#include "gnc/guidance/trajectory.hpp"

namespace rocksteady::fsw {

struct ChunkResult {
  ChunkStatus status{ChunkStatus::kStored};
  bool started{false};          // this chunk opened a new uplink
  std::int32_t active_id{-1};   // kOtherUplinkActive: the upload id in progress
  bool completed{false};        // this chunk was the last missing one
};

class TrajectoryUplink {
 public:
  ChunkResult receive(const TrajectoryChunk& chunk);

  bool active() const { return upload_id_ >= 0; }
  std::int32_t upload_id() const { return upload_id_; }
  std::int32_t chunk_count() const { return chunk_count_; }
  std::int32_t chunks_received() const { return received_; }
  bool complete() const { return active() && received_ == chunk_count_; }

  // Fill the table header (count, checksum) and validate the whole table.
  gnc::TrajectoryError finalize(double eps_trans);
  const gnc::TrajectoryTable& table() const { return table_; }

  // A validated table waits for the tick boundary; chunks are refused meanwhile.
  void set_pending(bool p) { pending_ = p; }
  bool pending() const { return pending_; }

  void clear();

 private:
  gnc::TrajectoryTable table_{};
  std::array<bool, kMaxChunks> have_{};
  std::int32_t upload_id_{-1};
  std::int32_t chunk_count_{0};
  std::int32_t total_samples_{0};
  std::uint32_t crc_{0};
  std::int32_t received_{0};
  bool pending_{false};
};

}  // namespace rocksteady::fsw
