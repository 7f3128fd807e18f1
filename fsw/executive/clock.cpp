#include "fsw/executive/clock.hpp"

#include <cerrno>
#include <ctime>

#include "gnc/units.hpp"

namespace rocksteady::fsw {

using gnc::kNsPerS;

std::int64_t MonotonicClock::now_ns() const {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * kNsPerS + static_cast<std::int64_t>(ts.tv_nsec);
}

void MonotonicClock::sleep_until(std::int64_t deadline_ns) {
  timespec ts{};
  ts.tv_sec = static_cast<time_t>(deadline_ns / kNsPerS);
  ts.tv_nsec = static_cast<long>(deadline_ns % kNsPerS);
  // Absolute deadline: a signal or a late wake-up never accumulates drift.
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
  }
}

void FakeClock::sleep_until(std::int64_t deadline_ns) {
  ++sleeps_;
  if (deadline_ns > now_ns_) now_ns_ = deadline_ns;
  now_ns_ += wake_latency_ns_;
}

}  // namespace rocksteady::fsw
