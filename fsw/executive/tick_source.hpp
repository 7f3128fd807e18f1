// Tick sources of the executive. A tick is one base period: its index (gaps = missed ticks), the
// time it became due, and how many ticks were skipped before it.
//   RealTimeClockSource: absolute deadlines start + k * period on a Clock; a wake-up late by one
//     period or more skips the deadlines that passed and counts them as missed.
//   LockstepSource: one tick per sensor frame (the plant owns the clock); gaps in the frames'
//     sequence numbers are missed ticks, repeated or older frames are dropped and counted.
#pragma once

#include <cstdint>

#include "fsw/executive/clock.hpp"

namespace rocksteady::fsw {

struct Tick {
  std::uint64_t index{0};    // base tick number; 0 is the first
  std::int64_t start_ns{0};  // when the tick became due (deadline, or frame arrival)
  std::uint32_t missed{0};   // ticks skipped between the previous tick and this one
};

class TickSource {
 public:
  virtual ~TickSource() = default;
  // The next tick. Real-time: blocks until it is due, always true. Lockstep: never blocks, false
  // when no frame is waiting.
  virtual bool next(Tick& tick) = 0;
};

class RealTimeClockSource final : public TickSource {
 public:
  RealTimeClockSource(Clock& clock, std::int64_t period_ns)
      : clock_(clock), period_ns_(period_ns) {}
  // The first call returns tick 0 at the current time; then waits for each absolute deadline.
  bool next(Tick& tick) override;
  std::uint32_t missed_total() const { return missed_total_; }
  std::int64_t period_ns() const { return period_ns_; }

 private:
  Clock& clock_;
  std::int64_t period_ns_;
  std::int64_t deadline_ns_{0};
  std::uint64_t index_{0};
  bool started_{false};
  std::uint32_t missed_total_{0};
};

class LockstepSource final : public TickSource {
 public:
  // A frame more than this many sequence numbers ahead of the newest accepted one is implausible
  // (one spoofed frame must not become 10^15 missed ticks): rejected and counted, never adopted
  // from one frame. Only a run of kResyncRun such frames, each 1..kResyncStep above the previous,
  // re-synchronises the numbering (the ticks then continue without a gap).
  static constexpr std::int64_t kMaxSeqJump = 1000;
  static constexpr std::uint32_t kResyncRun = 5;
  static constexpr std::int64_t kResyncStep = 10;

  // A sensor frame numbered `seq` arrived at `arrival_ns`. False (counted) for a negative, repeated
  // or older sequence number, or an implausible jump: such a frame makes no tick.
  bool on_frame(std::int64_t seq, std::int64_t arrival_ns);
  bool next(Tick& tick) override;
  std::uint64_t missed_total() const { return missed_total_; }
  std::uint64_t stale_frames() const { return stale_frames_; }
  std::uint64_t jump_rejects() const { return jump_rejects_; }
  std::uint64_t resyncs() const { return resyncs_; }

 private:
  bool have_first_{false};
  std::int64_t first_seq_{0};
  std::int64_t latest_seq_{0};  // newest frame accepted
  std::int64_t latest_arrival_ns_{0};
  bool pending_{false};
  bool have_returned_{false};
  std::uint64_t last_index_{0};  // last tick handed out
  std::uint64_t missed_total_{0};
  std::uint64_t stale_frames_{0};
  std::uint64_t jump_rejects_{0};
  std::uint64_t resyncs_{0};
  std::uint32_t candidate_run_{0};  // consecutive implausible frames consistent with each other
  std::int64_t candidate_seq_{0};
};

}  // namespace rocksteady::fsw
