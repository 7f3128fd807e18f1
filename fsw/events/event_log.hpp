// The application's event log: numbers events, stamps them with the on-board time and queues them
// (EventQueue: a full queue drops and counts). Every part of the application emits through one log.
// No heap; the text is formatted into the event's fixed buffer (truncated, never overflowed).
#pragma once

#include <cstdint>

#include "fsw/events/event_queue.hpp"
#include "fsw/interface.hpp"

namespace rocksteady::fsw {

class EventLog {
 public:
  void reset() {
    queue_ = EventQueue{};
    seq_ = 0;
    t_ = 0.0;
  }
  // On-board time stamped on the events that follow (the time of the last GNC tick).
  void set_time(double t) { t_ = t; }

  void emit(Severity sev, EventId id, std::int32_t arg0, std::int32_t arg1, const char* fmt, ...)
      __attribute__((format(printf, 6, 7)));

  bool pop(Event& e) { return queue_.pop(e); }
  int pending() const { return queue_.size(); }
  std::uint64_t emitted() const { return seq_; }
  std::uint32_t dropped() const { return queue_.dropped(); }
  void reset_dropped() { queue_.reset_dropped(); }

 private:
  EventQueue queue_{};
  std::uint64_t seq_{0};
  double t_{0.0};
};

}  // namespace rocksteady::fsw
