#include "fsw/uplink/uplink_lifecycle.hpp"

#include <cinttypes>

namespace rocksteady::fsw {

void UplinkLifecycle::reset() {
  uplink_.clear();
  chunks_rejected_ = 0;
  loaded_ = 0;
}

ChunkStatus UplinkLifecycle::receive(const TrajectoryChunk& chunk, EventLog& log) {
  const ChunkResult r = uplink_.receive(chunk);
  if (r.status != ChunkStatus::kStored) {
    ++chunks_rejected_;
    log.emit(Severity::kWarning, EventId::kChunkRejected, chunk.upload_id,
             static_cast<std::int32_t>(r.status),
             "uplink %" PRId32 " chunk %" PRId32 " rejected: %s", chunk.upload_id,
             chunk.chunk_index, to_string(r.status));
    return r.status;
  }
  if (r.abandoned) {
    log.emit(Severity::kWarning, EventId::kUplinkAbandoned, r.abandoned_id, r.abandoned_received,
             "trajectory uplink %" PRId32 " abandoned for %" PRId32 " (%" PRId32
             " chunks received)",
             r.abandoned_id, chunk.upload_id, r.abandoned_received);
  }
  if (r.started) {
    log.emit(Severity::kInfo, EventId::kUplinkStarted, chunk.upload_id, chunk.chunk_count,
             "trajectory uplink %" PRId32 " started: %" PRId32 " samples in %" PRId32 " chunks",
             chunk.upload_id, chunk.total_samples, chunk.chunk_count);
  }
  if (r.completed) {
    log.emit(Severity::kInfo, EventId::kUplinkComplete, chunk.upload_id, chunk.chunk_count,
             "trajectory uplink %" PRId32 " complete: ready to load", chunk.upload_id);
  }
  return r.status;
}

CommandCheck UplinkLifecycle::request_load(std::int32_t id, double eps_trans, EventLog& log) {
  if (!uplink_.active() || uplink_.upload_id() != id) {
    return CommandCheck{RejectReason::kOutOfRange, 0, "no uplink with that id"};
  }
  if (uplink_.pending()) {
    return CommandCheck{RejectReason::kBusy, 0, "this table already waits for the tick boundary"};
  }
  if (!uplink_.complete()) {
    return CommandCheck{RejectReason::kUploadIncomplete, uplink_.chunks_received(),
                        "chunks missing: resend them, then load"};
  }
  const gnc::TrajectoryError e = uplink_.finalize(eps_trans);
  if (e != gnc::TrajectoryError::kOk) {
    log.emit(Severity::kWarning, EventId::kTrajectoryRejected, id, static_cast<std::int32_t>(e),
             "trajectory uplink %" PRId32 " rejected: %s; uplink discarded", id, gnc::to_string(e));
    uplink_.clear();
    return CommandCheck{RejectReason::kTrajectoryRejected, static_cast<std::int32_t>(e),
                        gnc::to_string(e)};
  }
  uplink_.set_pending(true);
  return CommandCheck{};
}

CommandCheck UplinkLifecycle::abort(std::int32_t id, EventLog& log) {
  if (!uplink_.active() || uplink_.upload_id() != id) {
    return CommandCheck{RejectReason::kOutOfRange, 0, "no uplink with that id"};
  }
  log.emit(Severity::kInfo, EventId::kUplinkAbandoned, id, uplink_.chunks_received(),
           "trajectory uplink %" PRId32 " aborted by ground (%" PRId32 " of %" PRId32 " chunks)",
           id, uplink_.chunks_received(), uplink_.chunk_count());
  uplink_.clear();  // a queued hand-over of this uplink finds nothing pending and is skipped
  return CommandCheck{};
}

bool UplinkLifecycle::hand_over(std::int32_t id, gnc::Gnc& core, EventLog& log) {
  if (!pending(id)) return false;  // aborted meanwhile
  const gnc::TrajectoryError e = core.load_trajectory(uplink_.table());
  if (e == gnc::TrajectoryError::kOk) {
    ++loaded_;
    log.emit(Severity::kInfo, EventId::kTrajectoryLoaded, id, uplink_.table().count,
             "trajectory uplink %" PRId32 " loaded: %d samples", id, uplink_.table().count);
  } else {
    log.emit(Severity::kError, EventId::kTrajectoryRejected, id, static_cast<std::int32_t>(e),
             "trajectory uplink %" PRId32 " refused by the core: %s", id, gnc::to_string(e));
  }
  uplink_.clear();
  return e == gnc::TrajectoryError::kOk;
}

}  // namespace rocksteady::fsw
