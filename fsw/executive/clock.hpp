// Time for the executive: a monotonic clock in nanoseconds and an absolute-deadline sleep.
// MonotonicClock is the flight one (CLOCK_MONOTONIC, clock_nanosleep TIMER_ABSTIME); FakeClock is
// driven by tests (and by in-process runs that want repeatable health telemetry).
#pragma once

#include <cstdint>

namespace rocksteady::fsw {

class Clock {
 public:
  virtual ~Clock() = default;
  virtual std::int64_t now_ns() const = 0;
  // Returns at or after the absolute time `deadline_ns` (immediately if it has passed).
  virtual void sleep_until(std::int64_t deadline_ns) = 0;
};

class MonotonicClock final : public Clock {
 public:
  std::int64_t now_ns() const override;
  void sleep_until(std::int64_t deadline_ns) override;  // retries on EINTR
};

class FakeClock final : public Clock {
 public:
  explicit FakeClock(std::int64_t start_ns = 0) : now_ns_(start_ns) {}
  std::int64_t now_ns() const override { return now_ns_; }
  // Jumps to the deadline (if in the future), then adds the configured wake-up latency.
  void sleep_until(std::int64_t deadline_ns) override;

  void advance(std::int64_t dt_ns) { now_ns_ += dt_ns; }
  void set(std::int64_t t_ns) { now_ns_ = t_ns; }
  // Every later sleep wakes this much after its deadline (a loaded or preempted processor).
  void set_wake_latency(std::int64_t latency_ns) { wake_latency_ns_ = latency_ns; }
  std::uint32_t sleeps() const { return sleeps_; }

 private:
  std::int64_t now_ns_{0};
  std::int64_t wake_latency_ns_{0};
  std::uint32_t sleeps_{0};
};

}  // namespace rocksteady::fsw
