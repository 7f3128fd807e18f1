#include "rt/watchdog.hpp"

#include <pthread.h>
#include <sched.h>
#include <time.h>

#include <cerrno>

namespace rocksteady::rt {

namespace {

constexpr std::int64_t kNsPerS = 1000000000;

std::int64_t now_ns() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * kNsPerS + ts.tv_nsec;
}

void sleep_until(std::int64_t t_ns) {
  timespec ts{};
  ts.tv_sec = static_cast<time_t>(t_ns / kNsPerS);
  ts.tv_nsec = static_cast<long>(t_ns % kNsPerS);
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
  }
}

}  // namespace

bool Watchdog::start(std::int64_t timeout_ns, Action action, void* context, int fifo_priority) {
  if (thread_.joinable() || timeout_ns <= 0 || action == nullptr) {
    error_ = "watchdog already running, or no timeout or action";
    return false;
  }
  timeout_ns_ = timeout_ns;
  action_ = action;
  context_ = context;
  stop_.store(false);
  last_feed_ns_.store(0);
  thread_ = std::thread([this] { loop(); });
  pthread_setname_np(thread_.native_handle(), "rs-watchdog");
  if (fifo_priority > 0) {
    sched_param sp{};
    sp.sched_priority = fifo_priority;
    if (pthread_setschedparam(thread_.native_handle(), SCHED_FIFO, &sp) != 0) {
      error_ = "cannot give the watchdog thread its SCHED_FIFO priority";
      stop();
      return false;
    }
  }
  return true;
}

void Watchdog::feed() {
  std::int64_t t = now_ns();
  if (t == 0) t = 1;  // 0 means "not armed"
  last_feed_ns_.store(t, std::memory_order_release);
}

void Watchdog::stop() {
  stop_.store(true);
  if (thread_.joinable()) thread_.join();
}

void Watchdog::loop() {
  // Polls its own deadline: the next check is at (last feed + timeout), or a short idle step while
  // unarmed, so a stop() is noticed within a few milliseconds.
  constexpr std::int64_t kIdleNs = 5 * 1000000;
  while (!stop_.load()) {
    const std::int64_t fed = last_feed_ns_.load(std::memory_order_acquire);
    const std::int64_t now = now_ns();
    if (fed == 0) {
      sleep_until(now + kIdleNs);
      continue;
    }
    const std::int64_t deadline = fed + timeout_ns_;
    if (now >= deadline) {
      action_(context_, now - fed);
      return;  // the action normally ends the process
    }
    const std::int64_t next = deadline - now > kIdleNs ? now + kIdleNs : deadline;
    sleep_until(next);
  }
}

}  // namespace rocksteady::rt
