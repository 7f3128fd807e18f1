#include "hal/lcm/uplink.hpp"

#include "hal/lcm/codec.hpp"

namespace rocksteady::hal::wire {

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

const char* to_string(UplinkResult r) {
  switch (r) {
    case UplinkResult::kAccepted: return "accepted";
    case UplinkResult::kDuplicate: return "duplicate";
    case UplinkResult::kComplete: return "complete";
    case UplinkResult::kInconsistent: return "inconsistent with the upload in progress";
    case UplinkResult::kBadChecksum: return "table checksum mismatch";
    case UplinkResult::kMalformed: return "malformed chunk";
  }
  return "unknown";
}

void TrajectoryAssembler::reset() {
  for (bool& h : have_) h = false;
  active_ = false;
  complete_ = false;
  upload_id_ = -1;
  total_chunks_ = 0;
  total_samples_ = 0;
  crc_ = 0;
  received_ = 0;
  table_.count = 0;
  table_.checksum = 0;
}

bool TrajectoryAssembler::abort(std::int32_t upload_id) {
  if (!active_ || upload_id != upload_id_) return false;
  reset();
  return true;
}

UplinkResult TrajectoryAssembler::add(const Chunk& chunk) {
  if (check(chunk) != DecodeStatus::kOk) return UplinkResult::kMalformed;
  const auto crc = static_cast<std::uint32_t>(chunk.table_crc);
  if (!active_ || chunk.upload_id != upload_id_) {
    reset();
    active_ = true;
    upload_id_ = chunk.upload_id;
    total_chunks_ = chunk.total_chunks;
    total_samples_ = chunk.total_samples;
    crc_ = crc;
  } else if (chunk.total_chunks != total_chunks_ || chunk.total_samples != total_samples_ ||
             crc != crc_) {
    return UplinkResult::kInconsistent;
  }
  const auto idx = static_cast<std::size_t>(chunk.chunk_index);
  if (have_[idx]) return UplinkResult::kDuplicate;
  for (int i = 0; i < chunk.count; ++i) {
    gnc::TrajectorySample& s = table_.samples[static_cast<std::size_t>(chunk.first_sample + i)];
    s.t = chunk.t[i];
    for (int a = 0; a < 3; ++a) {
      s.omega_d(a) = chunk.omega_d[i][a];
      s.omega_d_dot(a) = chunk.omega_d_dot[i][a];
    }
  }
  have_[idx] = true;
  ++received_;
  if (received_ < total_chunks_) return UplinkResult::kAccepted;
  table_.count = total_samples_;
  table_.checksum = crc_;
  if (gnc::trajectory_checksum(table_) != crc_) {
    reset();
    return UplinkResult::kBadChecksum;
  }
  complete_ = true;
  return UplinkResult::kComplete;
}

}  // namespace rocksteady::hal::wire
