// A trajectory uplink's life cycle: chunks are stored as they arrive (events when an uplink starts,
// completes, is aborted or a chunk is rejected; a chunk of another upload never ends one in progress); LOAD_TRAJECTORY validates the complete table and
// queues the hand-over, which happens at the next tick boundary; ABORT_UPLINK discards it.
#pragma once

#include <cstdint>

#include "fsw/commands/command_table.hpp"
#include "fsw/events/event_log.hpp"
#include "fsw/uplink/trajectory_uplink.hpp"
#include "gnc/gnc.hpp"

namespace rocksteady::fsw {

class UplinkLifecycle {
 public:
  void reset();

  ChunkStatus receive(const TrajectoryChunk& chunk, EventLog& log);
  // LOAD_TRAJECTORY: the complete table is finalised and validated now; on success it waits for
  // the boundary (the caller queues the hand-over).
  // The table must pass gnc::validate_trajectory and the dynamics check below.
  CommandCheck request_load(std::int32_t upload_id, const gnc::GncParams& params, EventLog& log);
  CommandCheck abort(std::int32_t upload_id, EventLog& log);
  // At the tick boundary: hand the table to the core (skipped if the uplink was aborted meanwhile).
  // True when the core took it.
  bool hand_over(std::int32_t upload_id, gnc::Gnc& core, EventLog& log);

  const TrajectoryUplink& uplink() const { return uplink_; }
  bool pending(std::int32_t upload_id) const {
    return uplink_.pending() && uplink_.upload_id() == upload_id;
  }
  std::uint32_t chunks_rejected() const { return chunks_rejected_; }
  std::uint32_t loaded() const { return loaded_; }
  void reset_counters() { chunks_rejected_ = 0; }

 private:
  TrajectoryUplink uplink_{};
  std::uint32_t chunks_rejected_{0};
  std::uint32_t loaded_{0};
};

}  // namespace rocksteady::fsw
