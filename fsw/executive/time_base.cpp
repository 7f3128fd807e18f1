#include "fsw/executive/time_base.hpp"

#include <cinttypes>
#include <cmath>

namespace rocksteady::fsw {

void FrameTimeBase::configure(const TimeBaseConfig& c) {
  config_ = c;
  throttle_.configure(c.event_interval_ns);
  reset();
}

void FrameTimeBase::reset() {
  throttle_.reset();
  have_frame_t_ = false;
  last_frame_t_ = 0.0;
  consecutive_rejects_ = 0;
  resync_run_ = 0;
  resync_t_ = 0.0;
  have_gnc_t_ = false;
  last_gnc_t_ = 0.0;
  cycles_missed_ = 0;
  frames_accepted_ = 0;
  frames_rejected_ = 0;
  frameless_ticks_ = 0;
}

double FrameTimeBase::scheduled_time() const {
  if (!have_gnc_t_) return 0.0;
  return last_gnc_t_ + config_.gnc_period_s * (1.0 + static_cast<double>(cycles_missed_));
}

bool FrameTimeBase::accept(double t, std::int64_t now_ns, EventLog& log) {
  bool ok = std::isfinite(t);
  const char* why = "non-finite time";
  if (ok && have_frame_t_) {
    if (!(t > last_frame_t_)) {
      ok = false;
      why = "time not after the previous frame";
    } else if (t - scheduled_time() > config_.max_frame_time_jump_s) {
      ok = false;
      why = "time jumps ahead of the on-board time";
    }
    if (!ok && std::isfinite(t) && consecutive_rejects_ >= config_.frame_resync_count) {
      // A candidate for a new time base: adopted only after a run of consistent frames.
      const bool consistent =
          resync_run_ > 0 && t > resync_t_ && t - resync_t_ <= config_.max_frame_time_jump_s;
      resync_run_ = consistent ? resync_run_ + 1 : 1;
      resync_t_ = t;
      if (resync_run_ >= (config_.frame_resync_run > 0 ? config_.frame_resync_run : 1)) {
        log.emit(Severity::kWarning, EventId::kFrameRejected, 0, 0,
                 "frame time base re-synchronised at t=%.6g s after %" PRIu32
                 " rejected frames and %" PRIu32 " consistent ones",
                 t, consecutive_rejects_, resync_run_);
        ok = true;
        have_gnc_t_ = false;  // the on-board time follows the new base, without a missed-tick gap
        cycles_missed_ = 0;
      }
    }
  }
  if (!ok) {
    ++frames_rejected_;
    ++consecutive_rejects_;
    std::uint32_t suppressed = 0;
    if (throttle_.allow(now_ns, suppressed)) {
      log.emit(Severity::kWarning, EventId::kFrameRejected,
               static_cast<std::int32_t>(frames_rejected_), static_cast<std::int32_t>(suppressed),
               "sensor frame rejected: %s (%" PRIu32 " so far)", why, frames_rejected_);
    }
    return false;
  }
  have_frame_t_ = true;
  last_frame_t_ = t;
  consecutive_rejects_ = 0;
  resync_run_ = 0;
  ++frames_accepted_;
  return true;
}

void FrameTimeBase::cycle_ran(double t, bool with_frame) {
  if (!with_frame) ++frameless_ticks_;
  last_gnc_t_ = t;
  have_gnc_t_ = true;
  cycles_missed_ = 0;
}

}  // namespace rocksteady::fsw
