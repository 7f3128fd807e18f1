// The frame time base: which sensor frames' time tags the application accepts, and the on-board
// time of the GNC cycles. A frame's time must be finite, after the previous frame's and at most
// max_frame_time_jump_s ahead of the on-board time; a rejected frame is counted and evented
// (throttled). After frame_resync_count rejected frames in a row, a run of frame_resync_run frames
// whose times are consistent with each other (increasing, steps of at most max_frame_time_jump_s)
// re-anchors the base at the last of them (a restarted sensor front end); one frame never does. Without a frame, a GNC cycle runs at the scheduled time:
// the last cycle's time plus one period per cycle since.
#pragma once

#include <cstdint>

#include "fsw/events/event_log.hpp"
#include "fsw/executive/executive.hpp"

namespace rocksteady::fsw {

struct TimeBaseConfig {
  double gnc_period_s{0.1};
  double max_frame_time_jump_s{60.0};
  std::uint32_t frame_resync_count{50};
  std::uint32_t frame_resync_run{3};  // >= 1
  std::int64_t event_interval_ns{0};  // throttle of the frame-rejected events
};

class FrameTimeBase {
 public:
  void configure(const TimeBaseConfig& c);
  void reset();

  // Is the frame time t acceptable now? Counts and events either way.
  bool accept(double t, std::int64_t now_ns, EventLog& log);
  // The GNC cycles that the executive skipped since the last one ran.
  void missed_cycles(std::uint32_t n) { cycles_missed_ += n; }
  // When a cycle without a frame runs.
  double scheduled_time() const;
  // A GNC cycle ran at t (with or without a frame).
  void cycle_ran(double t, bool with_frame);

  bool have_time() const { return have_gnc_t_; }
  double onboard_time() const { return last_gnc_t_; }
  std::uint32_t frames_accepted() const { return frames_accepted_; }
  std::uint32_t frames_rejected() const { return frames_rejected_; }
  std::uint32_t frameless_ticks() const { return frameless_ticks_; }
  void reset_counters() {
    frames_rejected_ = 0;
    frameless_ticks_ = 0;
  }

 private:
  TimeBaseConfig config_{};
  Throttle throttle_{};
  bool have_frame_t_{false};
  double last_frame_t_{0.0};
  std::uint32_t consecutive_rejects_{0};
  std::uint32_t resync_run_{0};  // consistent candidate frames so far
  double resync_t_{0.0};        // time of the last candidate
  bool have_gnc_t_{false};
  double last_gnc_t_{0.0};
  std::uint32_t cycles_missed_{0};
  std::uint32_t frames_accepted_{0};
  std::uint32_t frames_rejected_{0};
  std::uint32_t frameless_ticks_{0};
};

}  // namespace rocksteady::fsw
