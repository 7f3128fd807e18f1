// The flight core's mode events (gnc::ModeEvent) as the application's events, by a table: one row
// per gnc::EventId with the fsw event id, severity, arguments and text. Sensor-reject events are
// throttled (at most one per interval, with the count of suppressed reports).
#pragma once

#include <cstdint>

#include "fsw/events/event_log.hpp"
#include "fsw/executive/executive.hpp"
#include "gnc/gnc.hpp"

namespace rocksteady::fsw {

// What a row's text and arguments need besides the event itself.
struct TranslationContext {
  bool overrun_request{false};      // this tick's SAFE request was the overrun protection's
  double sensor_timeout_s{0.0};     // mode.sensor_timeout_s
  std::uint32_t sensor_rejects{0};  // since the last counter reset
  std::int64_t now_ns{0};           // for the throttle
};

class EventTranslator {
 public:
  void configure(std::int64_t sensor_event_interval_ns);
  void translate(const gnc::ModeEvents& events, const TranslationContext& ctx, EventLog& log);

 private:
  Throttle sensor_throttle_{};
};

}  // namespace rocksteady::fsw
