#include "fsw/events/event_log.hpp"

#include <cstdarg>
#include <cstdio>

namespace rocksteady::fsw {

void EventLog::emit(Severity sev, EventId id, std::int32_t arg0, std::int32_t arg1, const char* fmt,
                    ...) {
  Event e;
  e.seq = seq_++;
  e.t = t_;
  e.severity = sev;
  e.id = id;
  e.arg0 = arg0;
  e.arg1 = arg1;
  va_list ap;
  va_start(ap, fmt);
  std::vsnprintf(e.text.data(), e.text.size(), fmt, ap);  // truncates, never overflows
  va_end(ap);
  queue_.push(e);
}

}  // namespace rocksteady::fsw
