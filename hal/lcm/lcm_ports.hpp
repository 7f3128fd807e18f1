// The HAL's LCM device back end (processor-in-the-loop): the two ports over the bus.
// Subscribe with the raw-buffer handler and feed LcmSensorSource::on_message(): a malformed packet is
// counted and dropped, never thrown through LCM's dispatcher (ENVIRONMENT.md). Decoding and the
// message <-> reading mapping are the bus library's (wire/); this file only holds the devices' side.
#pragma once

#include <atomic>
#include <cstdint>
#include <mutex>

#include <lcm/lcm.h>

#include "hal/ports.hpp"
#include "hal/thruster_bank.hpp"
#include "wire/codec.hpp"

namespace rocksteady::hal {

class LcmSensorSource final : public SensorSource {
 public:
  // Raw bytes of one RS_SENSORS message. Returns true if it was decoded and kept as the newest
  // frame. A frame whose seq goes backwards is a restarted stream: it is kept, flagged
  // stream_restart, and counted in restarts().
  bool on_message(const void* buf, int len);

  // The newest kept frame, if one arrived since the last poll (an older unpolled one is superseded,
  // counted in superseded()).
  bool poll(RawSensors& out) override;

  // For a lockstep loop: is a frame waiting, and which one.
  bool pending() const { return fresh_; }
  std::int64_t pending_seq() const { return latest_.seq; }
  // Drop the waiting frame without ticking (a resent frame already answered).
  void drop() { fresh_ = false; }

  const wire::RxCounters& counters() const { return counters_; }
  std::uint64_t frames() const { return frames_; }
  std::uint64_t restarts() const { return restarts_; }
  std::uint64_t superseded() const { return superseded_; }

 private:
  rocksteady::sensor_frame_t scratch_{};
  RawSensors latest_{};
  bool fresh_{false};
  bool have_seq_{false};
  std::int64_t last_seq_{-1};
  bool restart_pending_{false};
  wire::RxCounters counters_{};
  std::uint64_t frames_{0};
  std::uint64_t restarts_{0};
  std::uint64_t superseded_{0};
};

// Thread-safe: write() runs on the tick's thread, all_off() may run on a watchdog thread while the
// tick is stalled (LCM's publish is thread-safe; the message and buffer here are under a mutex).
class LcmThrusterSink final : public ThrusterSink {
 public:
  // `wiring` maps the thrusters back to the channel forces the message also carries. Publishes on
  // `bus` once attached (before that, a write is counted as a publish error).
  explicit LcmThrusterSink(const ThrusterBankConfig& wiring, lcm_t* bus = nullptr)
      : bus_(bus), wiring_(wiring) {}
  void attach(lcm_t* bus) { bus_ = bus; }
  void write(const ThrusterOutputs& outputs, std::int64_t seq, double t) override;
  // Publish the last command again (lockstep: the plant resent a frame that was already answered).
  void republish();
  bool written() const { return written_.load(); }
  std::uint64_t publish_errors() const { return publish_errors_.load(); }

  // Commands every thruster off (thruster bank disabled, all 16 off, zero force; the latch valves
  // keep their last commanded state), echoing `seq`, and latches: later write() and republish()
  // calls publish nothing (counted in suppressed()).
  // For the watchdog: callable from any thread, also while write() is in progress on another.
  void all_off(std::int64_t seq, double t);
  bool latched_off() const { return off_latched_.load(); }
  // The message last built (a copy, under the lock).
  rocksteady::thruster_cmd_t last_message() {
    const std::lock_guard<std::mutex> lock(mutex_);
    return msg_;
  }
  std::uint64_t suppressed() const { return suppressed_.load(); }

 private:
  void publish_locked();

  lcm_t* bus_;
  ThrusterBankConfig wiring_;
  std::mutex mutex_;  // msg_ and buf_ (the flags and counters are atomic, for unlocked readers)
  rocksteady::thruster_cmd_t msg_{};
  std::atomic<bool> written_{false};
  unsigned char buf_[1024]{};
  std::atomic<std::uint64_t> publish_errors_{0};
  std::atomic<std::uint64_t> suppressed_{0};
  std::atomic<bool> off_latched_{false};
};

}  // namespace rocksteady::hal
