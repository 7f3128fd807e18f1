#include "wire/uplink.hpp"

#include "wire/codec.hpp"

namespace rocksteady::wire {

namespace {
using Chunk = rocksteady::trajectory_chunk_t;
}

int chunk_count(int samples) { return (samples + Chunk::SAMPLES - 1) / Chunk::SAMPLES; }

bool make_chunk(const gnc::TrajectoryTable& table, std::int32_t upload_id, int index, Chunk& out) {
  if (table.count < 2 || table.count > gnc::kMaxTrajectorySamples || upload_id < 0) return false;
  const int chunks = chunk_count(table.count);
  if (index < 0 || index >= chunks) return false;
  out = make<Chunk>();
  out.upload_id = upload_id;
  out.chunk_index = index;
  out.total_chunks = chunks;
  out.total_samples = table.count;
  out.first_sample = index * Chunk::SAMPLES;
  const int remaining = table.count - out.first_sample;
  out.count = remaining < Chunk::SAMPLES ? remaining : Chunk::SAMPLES;
  out.table_crc = gnc::trajectory_checksum(table);
  for (int i = 0; i < out.count; ++i) {
    const gnc::TrajectorySample& s = table.samples[static_cast<std::size_t>(out.first_sample + i)];
    out.t[i] = s.t;
    for (int a = 0; a < 3; ++a) {
      out.omega_d[i][a] = s.omega_d(a);
      out.omega_d_dot[i][a] = s.omega_d_dot(a);
    }
  }
  return true;
}

}  // namespace rocksteady::wire
