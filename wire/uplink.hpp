// Trajectory uplink over the bus, ground side: a gnc::TrajectoryTable split into trajectory_chunk_t
// messages. On board, fsw/uplink reassembles them and checks the table's CRC-32
// (gnc::trajectory_checksum), which every chunk carries.
#pragma once

#include <cstdint>

#include "gnc/guidance/trajectory.hpp"
#include "rocksteady/trajectory_chunk_t.hpp"

namespace rocksteady::wire {

static_assert(gnc::kMaxTrajectorySamples == rocksteady::trajectory_chunk_t::MAX_TABLE_SAMPLES,
              "trajectory_chunk_t.lcm and gnc::kMaxTrajectorySamples disagree");

// Number of chunks for a table of `samples` samples.
int chunk_count(int samples);

// Chunk `index` of `table` (whose checksum field is recomputed, not trusted). False if out of range.
bool make_chunk(const gnc::TrajectoryTable& table, std::int32_t upload_id, int index,
                rocksteady::trajectory_chunk_t& out);

}  // namespace rocksteady::wire
