// A software watchdog: a thread with its own absolute deadline, fed by the flight rate group. If
// no feed arrives within the timeout, the thread calls the trip action WHILE the fed thread is
// still stuck (it does not wait for the stalled tick to return). The action is expected to make the
// outputs safe and end the process (a supervisor restarts it); if it returns, the watchdog stops.
//
// The watchdog is armed by the first feed (start-up, waiting for the first sensor frame, is not
// watched). feed() is one atomic store: safe to call from the tick.
#pragma once

#include <atomic>
#include <cstdint>
#include <thread>

namespace rocksteady::rt {

class Watchdog {
 public:
  // Called on the watchdog thread; `since_feed_ns` = now - last feed (>= the timeout).
  using Action = void (*)(void* context, std::int64_t since_feed_ns);

  Watchdog() = default;
  Watchdog(const Watchdog&) = delete;
  Watchdog& operator=(const Watchdog&) = delete;
  ~Watchdog() { stop(); }

  // Starts the thread. `fifo_priority` > 0 runs it under SCHED_FIFO at that priority (give it one
  // above the rate group's, so it can preempt a spinning tick); false if the thread could not be
  // started or its priority not set (the message is in error()).
  bool start(std::int64_t timeout_ns, Action action, void* context, int fifo_priority = 0);
  void feed();
  void stop();

  std::int64_t timeout_ns() const { return timeout_ns_; }
  const char* error() const { return error_; }

 private:
  void loop();

  std::int64_t timeout_ns_{0};
  Action action_{nullptr};
  void* context_{nullptr};
  std::atomic<std::int64_t> last_feed_ns_{0};  // 0: not armed
  std::atomic<bool> stop_{false};
  std::thread thread_;
  const char* error_{""};
};

}  // namespace rocksteady::rt
