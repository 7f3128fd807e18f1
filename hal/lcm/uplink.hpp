// Trajectory uplink over the bus: a gnc::TrajectoryTable split into trajectory_chunk_t messages on the
// ground, and reassembled on board in fixed storage. The assembled table is handed to
// gnc::Gnc::load_trajectory() only when every chunk arrived and the CRC-32 of the whole table
// (gnc::trajectory_checksum) matches the one each chunk carries. No heap.
#pragma once

#include <cstdint>

#include "gnc/guidance/trajectory.hpp"
#include "rocksteady/trajectory_chunk_t.hpp"

namespace rocksteady::hal::wire {

static_assert(gnc::kMaxTrajectorySamples == rocksteady::trajectory_chunk_t::MAX_TABLE_SAMPLES,
              "trajectory_chunk_t.lcm and gnc::kMaxTrajectorySamples disagree");

// Number of chunks for a table of `samples` samples.
int chunk_count(int samples);

// Chunk `index` of `table` (whose checksum field is recomputed, not trusted). False if out of range.
bool make_chunk(const gnc::TrajectoryTable& table, std::int32_t upload_id, int index,
                rocksteady::trajectory_chunk_t& out);

enum class UplinkResult : std::uint8_t {
  kAccepted = 0,   // stored; more chunks to come
  kDuplicate,      // this chunk was already stored (ignored)
  kComplete,       // the last missing chunk: the table is complete and its CRC matches
  kInconsistent,   // header differs from the upload in progress (total, CRC): chunk ignored
  kBadChecksum,    // all chunks arrived but the CRC does not match: the upload is discarded
  kMalformed,      // the chunk fails wire::check()
};
const char* to_string(UplinkResult r);

class TrajectoryAssembler {
 public:
  // A chunk with a new upload_id starts a new upload (the previous one, complete or not, is dropped).
  UplinkResult add(const rocksteady::trajectory_chunk_t& chunk);
  // Discard the upload `upload_id` if it is the current one.
  bool abort(std::int32_t upload_id);

  bool in_progress() const { return active_; }
  bool complete() const { return complete_; }
  std::int32_t upload_id() const { return upload_id_; }
  int received() const { return received_; }
  int total_chunks() const { return total_chunks_; }
  // Valid when complete(): the table with count and checksum set.
  const gnc::TrajectoryTable& table() const { return table_; }

 private:
  void reset();

  gnc::TrajectoryTable table_{};
  bool have_[gnc::kMaxTrajectorySamples / rocksteady::trajectory_chunk_t::SAMPLES]{};
  bool active_{false};
  bool complete_{false};
  std::int32_t upload_id_{-1};
  int total_chunks_{0};
  int total_samples_{0};
  std::uint32_t crc_{0};
  int received_{0};
};

}  // namespace rocksteady::hal::wire
