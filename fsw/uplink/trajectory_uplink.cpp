#include "fsw/uplink/trajectory_uplink.hpp"

namespace rocksteady::fsw {

void TrajectoryUplink::clear() {
  have_.fill(false);
  upload_id_ = -1;
  chunk_count_ = 0;
  total_samples_ = 0;
  crc_ = 0;
  received_ = 0;
  pending_ = false;
  table_.count = 0;
}

ChunkResult TrajectoryUplink::receive(const TrajectoryChunk& c) {
  ChunkResult r;
  if (pending_) {
    r.status = ChunkStatus::kBusy;
    return r;
  }
  if (c.upload_id < 0 || c.total_samples < 2 || c.total_samples > gnc::kMaxTrajectorySamples ||
      c.chunk_count != (c.total_samples + kChunkSamples - 1) / kChunkSamples) {
    r.status = ChunkStatus::kBadHeader;
    return r;
  }
  if (c.chunk_index < 0 || c.chunk_index >= c.chunk_count) {
    r.status = ChunkStatus::kBadIndex;
    return r;
  }
  const std::int32_t first = c.chunk_index * kChunkSamples;
  const std::int32_t expected =
      c.chunk_index == c.chunk_count - 1 ? c.total_samples - first : kChunkSamples;
  if (c.n != expected) {
    r.status = ChunkStatus::kBadCount;
    return r;
  }
  if (active() && c.upload_id == upload_id_) {
    if (c.chunk_count != chunk_count_ || c.total_samples != total_samples_ || c.crc32 != crc_) {
      r.status = ChunkStatus::kHeaderMismatch;
      return r;
    }
  } else if (active()) {
    // An uplink ends only by its load or an authenticated ABORT_UPLINK naming its id: a chunk of
    // another upload (stray, or a new upload started before the ground aborted this one) is
    // refused and leaves the uplink in progress untouched.
    r.status = ChunkStatus::kOtherUplinkActive;
    r.active_id = upload_id_;
    return r;
  } else {
    clear();
    upload_id_ = c.upload_id;
    chunk_count_ = c.chunk_count;
    total_samples_ = c.total_samples;
    crc_ = c.crc32;
    r.started = true;
  }
  for (std::int32_t i = 0; i < c.n; ++i) table_.samples[first + i] = c.samples[i];
  if (!have_[c.chunk_index]) {
    have_[c.chunk_index] = true;
    ++received_;
    r.completed = received_ == chunk_count_;
  }
  r.status = ChunkStatus::kStored;
  return r;
}

gnc::TrajectoryError TrajectoryUplink::finalize(double eps_trans) {
  table_.count = total_samples_;
  table_.checksum = crc_;
  return gnc::validate_trajectory(table_, eps_trans);
}

}  // namespace rocksteady::fsw
