#include "fsw/executive/tick_source.hpp"

namespace rocksteady::fsw {

bool RealTimeClockSource::next(Tick& tick) {
  if (!started_) {
    started_ = true;
    deadline_ns_ = clock_.now_ns();
    index_ = 0;
    tick = Tick{0, deadline_ns_, 0};
    return true;
  }
  std::int64_t due = deadline_ns_ + period_ns_;
  if (clock_.now_ns() < due) clock_.sleep_until(due);
  // Woke (or arrived) late by at least one period: the deadlines in between are missed. The tick
  // keeps the most recent deadline that has passed, so the executive sees the slip.
  const std::int64_t late = clock_.now_ns() - due;
  std::uint32_t missed = 0;
  if (late >= period_ns_) {
    const std::int64_t skipped = late / period_ns_;
    missed = static_cast<std::uint32_t>(skipped);
    due += skipped * period_ns_;
  }
  deadline_ns_ = due;
  index_ += 1 + missed;
  missed_total_ += missed;
  tick = Tick{index_, deadline_ns_, missed};
  return true;
}

bool LockstepSource::on_frame(std::int64_t seq, std::int64_t arrival_ns) {
  if (seq < 0 || (have_first_ && seq <= latest_seq_)) {
    ++stale_frames_;
    return false;
  }
  if (have_first_ && seq - latest_seq_ > kMaxSeqJump) {
    ++jump_rejects_;
    const bool consistent = candidate_run_ > 0 && seq > candidate_seq_ &&
                            seq - candidate_seq_ <= kResyncStep;
    candidate_run_ = consistent ? candidate_run_ + 1 : 1;
    candidate_seq_ = seq;
    if (candidate_run_ < kResyncRun) return false;
    // A run of consistent frames: the sender's numbering really moved. Continue the ticks from
    // the last one handed out, without counting the jump as missed ticks.
    ++resyncs_;
    const auto next_index = have_returned_ ? last_index_ + 1 : 0;
    first_seq_ = seq - static_cast<std::int64_t>(next_index);
  }
  candidate_run_ = 0;
  if (!have_first_) {
    have_first_ = true;
    first_seq_ = seq;
  }
  latest_seq_ = seq;
  latest_arrival_ns_ = arrival_ns;
  pending_ = true;  // a frame not yet ticked is superseded: it counts as missed
  return true;
}

bool LockstepSource::next(Tick& tick) {
  if (!pending_) return false;
  pending_ = false;
  const auto index = static_cast<std::uint64_t>(latest_seq_ - first_seq_);
  std::uint32_t missed = 0;
  if (have_returned_ && index > last_index_ + 1) {
    const std::uint64_t gap = index - last_index_ - 1;  // <= kMaxSeqJump by on_frame
    missed = gap > 0xFFFFFFFFull ? 0xFFFFFFFFu : static_cast<std::uint32_t>(gap);
  }
  have_returned_ = true;
  last_index_ = index;
  missed_total_ += missed;
  tick = Tick{index, latest_arrival_ns_, missed};
  return true;
}

}  // namespace rocksteady::fsw
