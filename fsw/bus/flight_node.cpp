#include "fsw/bus/flight_node.hpp"

#include <poll.h>

#include <cerrno>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>

#include <sys/resource.h>
#include <unistd.h>

#include "fsw/auth/key_file.hpp"
#include "gnc/units.hpp"
#include "lcmtypes/channels.hpp"
#include "wire/convert.hpp"

namespace rocksteady::fsw::bus {

namespace {

using gnc::kNsPerS;
constexpr std::int64_t kNsPerMs = 1000000;
// Bus-layer events number their own sequence from here (the application's events count from 0).
constexpr std::uint64_t kBusEventSeqBase = 1000000000000ULL;

std::int64_t to_ns(double s) {
  return static_cast<std::int64_t>(std::llround(s * static_cast<double>(kNsPerS)));
}

void accumulate(wire::RxCounters& a, const wire::RxCounters& b) {
  a.ok += b.ok;
  a.too_short += b.too_short;
  a.too_long += b.too_long;
  a.bad_fingerprint += b.bad_fingerprint;
  a.bad_length += b.bad_length;
  a.malformed += b.malformed;
  a.bad_kind += b.bad_kind;
  a.bad_version += b.bad_version;
  a.out_of_range += b.out_of_range;
}

// The Clock the real-time tick source sleeps on: it serves the bus until each deadline.
class ServingClock final : public Clock {
 public:
  ServingClock(FlightNode& node, const Clock& base, const volatile std::sig_atomic_t* stop)
      : node_(node), base_(base), stop_(stop) {}
  std::int64_t now_ns() const override { return base_.now_ns(); }
  void sleep_until(std::int64_t deadline_ns) override {
    while (!error_ && (stop_ == nullptr || *stop_ == 0) && base_.now_ns() < deadline_ns) {
      if (!node_.wait_once(deadline_ns)) error_ = true;
    }
  }
  bool error() const { return error_; }

 private:
  FlightNode& node_;
  const Clock& base_;
  const volatile std::sig_atomic_t* stop_;
  bool error_{false};
};

}  // namespace

FlightNode::FlightNode(lcm_t* lcm, FlightComputer& computer, hal::LcmSensorSource& sensors,
                       hal::LcmThrusterSink& thrusters, const Clock& clock)
    : lcm_(lcm), computer_(computer), sensors_(sensors), thrusters_(thrusters), clock_(clock) {
  reserve_text(ack_msg_);
  reserve_text(event_msg_);
  wd_event_msg_ = wire::make<rocksteady::event_t>();
  reserve_text(wd_event_msg_);
  tlm_msg_ = wire::make<rocksteady::gnc_telemetry_t>();
  out_ = lcm_;
}

FlightNode::~FlightNode() {
  watchdog_.stop();
  for (int i = 0; i < 3; ++i) {
    lcm_t* bus = i == 0 ? lcm_ : out_;
    if (subs_[i] != nullptr && bus != nullptr) lcm_unsubscribe(bus, subs_[i]);
    subs_[i] = nullptr;
  }
}

bool FlightNode::subscribe() {
  out_ = ground_ != nullptr ? ground_ : lcm_;
  if (direct_ == nullptr) {
    subs_[0] = lcm_subscribe(lcm_, channels::kSensors, &FlightNode::on_sensors, this);
    if (subs_[0] == nullptr) return false;
  }
  subs_[1] = lcm_subscribe(out_, channels::kGroundCmd, &FlightNode::on_command, this);
  subs_[2] = lcm_subscribe(out_, channels::kTrajUplink, &FlightNode::on_chunk, this);
  if (subs_[1] == nullptr || subs_[2] == nullptr) return false;
  // A whole table's uplink (32 chunks) may arrive between two ticks.
  lcm_subscription_set_queue_capacity(subs_[2], 64);
  return true;
}

wire::RxCounters FlightNode::rx_total() const {
  wire::RxCounters t;
  accumulate(t, sensors_.counters());
  accumulate(t, stats_.rx_commands);
  accumulate(t, stats_.rx_uplink);
  return t;
}

// ----------------------------------------------------------------------------------------------
// Inputs
// ----------------------------------------------------------------------------------------------

void FlightNode::on_sensors(const lcm_recv_buf_t* rbuf, const char* /*channel*/, void* self) {
  auto& n = *static_cast<FlightNode*>(self);
  const wire::RxCounters before = n.sensors_.counters();
  if (!n.sensors_.on_message(rbuf->data, static_cast<int>(rbuf->data_size))) {
    if (n.sensors_.counters().rejected() != before.rejected()) {
      n.note_rx_reject(0, n.sensors_.counters());
    }
    return;
  }
  n.sync_sensor_stats();
  if (n.sensors_.restarts() != n.restarts_seen_) {
    // The sensor stream restarted (a new plant, a rebooted front end): the devices forget their old
    // readings when the flagged frame is polled.
    n.restarts_seen_ = n.sensors_.restarts();
    n.bus_event(Severity::kWarning, BusEventId::kStreamRestart,
                static_cast<std::int32_t>(n.sensors_.pending_seq()),
                static_cast<std::int32_t>(n.stats_.stream_restarts),
                "sensor frame seq went backwards: sensor stream restarted");
  }
}

void FlightNode::sync_sensor_stats() {
  stats_.frames = sensors_.frames();
  stats_.frames_superseded = sensors_.superseded();
  stats_.stream_restarts = sensors_.restarts();
  stats_.rx_sensors = sensors_.counters();
}

bool FlightNode::ground_budget() {
  if (ground_left_ > 0) {
    --ground_left_;
    if (ground_left_ == 0) ++stats_.ground_bound_ticks;
    return true;
  }
  ++stats_.ground_dropped;
  return false;
}

void FlightNode::on_command(const lcm_recv_buf_t* rbuf, const char* /*channel*/, void* self) {
  auto& n = *static_cast<FlightNode*>(self);
  if (!n.ground_budget()) return;
  if (!wire::safe_decode(rbuf->data, static_cast<int>(rbuf->data_size), n.scratch_cmd_,
                              &n.stats_.rx_commands)) {
    n.note_rx_reject(1, n.stats_.rx_commands);
    return;
  }
  ++n.stats_.commands;
  const CommandAck ack = n.computer_.submit(to_command(n.scratch_cmd_));
  // Persist the consumed counter before the acknowledgement goes out.
  n.persist_security();
  to_message(ack, n.computer_.onboard_time(), n.ack_msg_);
  sign(n.computer_.app(), n.ack_msg_);
  n.publish(channels::kCmdAck, n.ack_msg_);
  if (n.computer_.take_param_dump(n.dump_)) {  // PARAM_DUMP: the table goes out with the ack
    to_message(n.dump_, n.computer_.app(), n.params_msg_);
    n.publish(channels::kParams, n.params_msg_);
  }
  n.drain_events();
}

void FlightNode::on_chunk(const lcm_recv_buf_t* rbuf, const char* /*channel*/, void* self) {
  auto& n = *static_cast<FlightNode*>(self);
  if (!n.ground_budget()) return;
  if (!wire::safe_decode(rbuf->data, static_cast<int>(rbuf->data_size), n.scratch_chunk_,
                              &n.stats_.rx_uplink)) {
    n.note_rx_reject(2, n.stats_.rx_uplink);
    return;
  }
  ++n.stats_.chunks;
  to_chunk(n.scratch_chunk_, n.chunk_);
  n.computer_.receive_chunk(n.chunk_);  // the application raises the events, counts rejections
  n.persist_security();
  n.drain_events();
}

void FlightNode::persist_security() {
  const auth::SecurityState& s = computer_.app().security_state();
  if (state_file_.empty() || s.generation == state_written_) return;
  const std::string err = auth::write_state_file(state_file_, s);
  if (err.empty()) {
    state_written_ = s.generation;
  } else {
    bus_event(Severity::kError, BusEventId::kStateFile, 0, 0, "cannot persist the command state");
    std::fprintf(stderr, "rocksteady-fsw: %s\n", err.c_str());
  }
}

void FlightNode::note_rx_reject(int channel, const wire::RxCounters& c) {
  const std::int64_t now = clock_.now_ns();
  if (rx_event_fired_[channel] && now - last_rx_event_ns_[channel] < kNsPerS) return;
  rx_event_fired_[channel] = true;
  last_rx_event_ns_[channel] = now;
  static const char* const kText[3] = {"malformed message on RS_SENSORS: counted, ignored",
                                       "malformed message on RS_GROUND_CMD: counted, ignored",
                                       "malformed message on RS_TRAJ_UPLINK: counted, ignored"};
  bus_event(Severity::kWarning, BusEventId::kRxRejected, channel,
            static_cast<std::int32_t>(c.rejected()), kText[channel]);
}

// ----------------------------------------------------------------------------------------------
// Outputs
// ----------------------------------------------------------------------------------------------

template <class T> void FlightNode::publish(const char* channel, const T& msg) {
  const int n = wire::encode(msg, buf_, static_cast<int>(sizeof buf_));
  if (n < 0 || lcm_publish(out_, channel, buf_, static_cast<unsigned int>(n)) != 0) {
    ++stats_.publish_errors;
  }
}

void FlightNode::drain_events() {
  Event e;
  while (computer_.pop_event(e)) {
    to_message(e, event_msg_);
    sign(computer_.app(), event_msg_);
    publish(channels::kEvents, event_msg_);
  }
}

void FlightNode::bus_event(Severity sev, BusEventId id, std::int32_t arg0, std::int32_t arg1,
                           const char* text) {
  Event e;
  e.seq = kBusEventSeqBase + bus_event_seq_++;
  e.t = computer_.onboard_time();
  e.severity = sev;
  e.id = static_cast<EventId>(id);
  e.arg0 = arg0;
  e.arg1 = arg1;
  std::snprintf(e.text.data(), e.text.size(), "%s", text);
  to_message(e, event_msg_);
  sign(computer_.app(), event_msg_);
  publish(channels::kEvents, event_msg_);
}

void FlightNode::test_stall(const Tick& t, const NodeOptions& o) {
  if (o.test_stall_at_tick == 0 || t.index != o.test_stall_at_tick) return;
  std::fprintf(stderr,
               "rocksteady-fsw: FAULT INJECTION (--test-stall-at-tick): tick %llu stalls %s\n",
               static_cast<unsigned long long>(t.index),
               o.test_stall_s > 0.0 ? "for --test-stall-s" : "forever");
  std::fflush(stderr);
  const std::int64_t until = clock_.now_ns() + to_ns(o.test_stall_s);
  while (o.test_stall_s <= 0.0 || clock_.now_ns() < until) {
    timespec ts{0, 10 * kNsPerMs};
    nanosleep(&ts, nullptr);
  }
}

void FlightNode::tick(const Tick& t, const NodeOptions& o) {
  test_stall(t, o);
  const std::int64_t t0 = clock_.now_ns();
  const TickReport r = computer_.tick(t);  // sensors in and thrusters out through the ports
  const std::int64_t t1 = clock_.now_ns();
  stats_.ns_tick += t1 - t0;
  last_index_ = t.index;
  have_index_ = true;
  ++stats_.ticks;
  ground_left_ = ground_drain_max_;  // a new tick: a new ground budget
  ground_reset_ns_ = t.start_ns;
  if (r.gnc_ran) {
    // The GNC rate group completed a cycle: feed the watchdog (the only place it is fed).
    wd_seq_.store(computer_.echo_seq(), std::memory_order_relaxed);
    wd_t_.store(computer_.onboard_time(), std::memory_order_relaxed);
    wd_tick_.store(t.index, std::memory_order_relaxed);
    wd_key_id_.store(computer_.app().security().active_key_id(), std::memory_order_relaxed);
    watchdog_.feed();
  }
  if (r.gnc_ran) publish_telemetry(o);
  persist_security();  // a key rotation takes effect at the tick boundary
  drain_events();
  if (o.has_start_mode && !start_done_ && r.gnc_ran && computer_.health().frames_accepted > 0) {
    start_done_ = true;
    GroundCommand c;
    c.seq = 1;
    c.source = kStartupSource;
    c.opcode = static_cast<std::int32_t>(Opcode::kSetMode);
    c.arg_count = 1;
    c.args[0] = static_cast<double>(static_cast<int>(o.start_mode));
    to_message(computer_.submit_local(c), computer_.onboard_time(), ack_msg_);
    sign(computer_.app(), ack_msg_);
    publish(channels::kCmdAck, ack_msg_);
    drain_events();
  }
  stats_.ns_after_tick += clock_.now_ns() - t1;
}

void FlightNode::publish_telemetry(const NodeOptions& o) {
  if (o.tlm_every <= 1 || gnc_cycles_ % o.tlm_every == 0) {
    wire::fill_gnc(computer_.core_output(), tlm_msg_);
    tlm_msg_.frame_seq = computer_.echo_seq();
    fill_health(computer_.health(), tlm_msg_);
    fill_rx(rx_total(), tlm_msg_);
    publish(channels::kGncTelemetry, tlm_msg_);
  }
  ++gnc_cycles_;
}

void FlightNode::status_line(const char* prefix) const {
  const HealthTelemetry h = computer_.health();
  const wire::RxCounters rx = rx_total();
  std::printf("%s t=%.1f s mode=%s law=%s ticks=%" PRIu64 " frames=%" PRIu64
              " frameless=%u superseded=%" PRIu64 " cmd=%u/%u rx_ok=%" PRIu64
              " rx_rejected=%" PRIu64 " restarts=%" PRIu64 " ground_dropped=%" PRIu64
              " ground_bound_ticks=%" PRIu64 " missed=%u\n",
              prefix, h.t, gnc::to_string(h.mode), gnc::to_string(h.law), stats_.ticks,
              stats_.frames, h.frameless_ticks, stats_.frames_superseded, h.cmd_accepted,
              h.cmd_rejected, rx.ok, rx.rejected(), stats_.stream_restarts, stats_.ground_dropped,
              stats_.ground_bound_ticks, h.base_missed);
  std::fflush(stdout);
}

// Runs on the watchdog thread while the tick thread is stuck: only atomics, the thread-safe
// thruster sink, the key material (read-only after init), and the watchdog's own message and
// buffer (LCM's publish is thread-safe).
void FlightNode::on_watchdog(void* self, std::int64_t since_feed_ns) {
  auto& n = *static_cast<FlightNode*>(self);
  const std::int64_t seq = n.wd_seq_.load();
  const double t = n.wd_t_.load();
  const std::uint64_t tick = n.wd_tick_.load();
  const auto ms = static_cast<std::int32_t>(since_feed_ns / kNsPerMs);
  n.thrusters_.all_off(seq, t);
  auto& e = n.wd_event_msg_;
  e.t = t;
  e.seq = static_cast<std::int64_t>(kBusEventSeqBase - 1);  // outside both numberings
  e.severity = static_cast<std::int8_t>(Severity::kError);
  e.id = static_cast<std::int32_t>(BusEventId::kWatchdog);
  e.arg0 = ms;
  e.arg1 = static_cast<std::int32_t>(tick);
  char text[96];
  std::snprintf(text, sizeof text, "watchdog: no GNC cycle for %d ms: thrusters off, exiting", ms);
  e.text = text;
  // Signed with the key the tick thread last used (the key material is fixed after init), so the
  // ground can tell the flight's watchdog from a forged one.
  e.key_id = 0;
  auth::EventFields f = event_fields(e);
  auth::MacBytes mac{};
  (void)n.computer_.app().security().sign_event_with(n.wd_key_id_.load(), f, mac);
  e.key_id = f.key_id;
  for (int i = 0; i < kMacSize; ++i) e.mac[i] = static_cast<std::int8_t>(mac[static_cast<std::size_t>(i)]);
  const int len = wire::encode(e, n.wd_buf_, static_cast<int>(sizeof n.wd_buf_));
  if (len > 0) lcm_publish(n.out_, channels::kEvents, n.wd_buf_, static_cast<unsigned int>(len));
  std::fprintf(stderr,
               "rocksteady-fsw: WATCHDOG: no GNC cycle for %d ms (last at base tick %llu): every "
               "thruster commanded off, exiting with status %d\n",
               ms, static_cast<unsigned long long>(tick), kExitWatchdog);
  std::fflush(stderr);
  std::fflush(stdout);
  _exit(kExitWatchdog);
}

// ----------------------------------------------------------------------------------------------
// Loops
// ----------------------------------------------------------------------------------------------

bool FlightNode::wait_once(std::int64_t deadline_ns) {
  std::int64_t now = clock_.now_ns();
  if (period_ns_ > 0 && now - ground_reset_ns_ >= period_ns_) {
    // No tick for a base period (before the first frame, or a silent plant): refill the budget.
    ground_left_ = ground_drain_max_;
    ground_reset_ns_ = now;
  }
  std::int64_t rem = deadline_ns - now;
  if (rem < 0) rem = 0;
  timespec ts{};
  ts.tv_sec = static_cast<time_t>(rem / kNsPerS);
  ts.tv_nsec = static_cast<long>(rem % kNsPerS);
  pollfd p[2]{};
  p[0].fd = direct_ != nullptr ? direct_->fd() : lcm_get_fileno(lcm_);
  p[0].events = POLLIN;
  nfds_t n = 1;
  if (ground_ != nullptr) {
    p[1].fd = lcm_get_fileno(ground_);
    p[1].events = POLLIN;
    n = 2;
  }
  const int r = ppoll(p, n, &ts, nullptr);
  const std::int64_t woke = clock_.now_ns();
  stats_.ns_wait += woke - now;
  if (r < 0) return errno == EINTR;  // a signal: the caller looks at its stop flag
  if (r == 0) return true;          // deadline
  // The flight bus (sensor frames) always first; the ground bus only when the flight bus is idle.
  lcm_t* bus = (p[0].revents & (POLLIN | POLLERR | POLLHUP)) != 0 ? lcm_ : ground_;
  if (bus == lcm_) {
    ++stats_.flight_handled;
  } else {
    ++stats_.ground_handled;
  }
  if (bus == lcm_ && direct_ != nullptr) {
    const char* channel = nullptr;
    const void* data = nullptr;
    int size = 0;
    const int got = direct_->receive(&channel, &data, &size);
    if (got > 0 && std::strcmp(channel, channels::kSensors) == 0) {
      lcm_recv_buf_t rbuf{};
      rbuf.data = const_cast<void*>(data);
      rbuf.data_size = static_cast<std::uint32_t>(size);
      rbuf.recv_utime = woke / 1000;
      rbuf.lcm = lcm_;
      on_sensors(&rbuf, channel, this);
    }
    stats_.ns_handle += clock_.now_ns() - woke;
    if (got < 0) {
      bus_error_ = true;
      return false;
    }
    return true;
  }
  const int handled = lcm_handle(bus);
  stats_.ns_handle += clock_.now_ns() - woke;
  if (handled != 0) {
    bus_error_ = true;
    return false;
  }
  return true;
}

bool FlightNode::limits_reached(const NodeOptions& o, std::int64_t start_ns) const {
  if (o.exit_after_ticks > 0 && stats_.ticks >= o.exit_after_ticks) return true;
  if (o.exit_after_s >= 0.0 && clock_.now_ns() - start_ns >= to_ns(o.exit_after_s)) return true;
  return false;
}

int FlightNode::run(const NodeOptions& o, const volatile std::sig_atomic_t* stop) {
  last_status_ns_ = clock_.now_ns();
  period_ns_ = computer_.app().executive().base_period_ns();
  ground_drain_max_ = o.ground_drain_max;
  ground_left_ = ground_drain_max_;
  ground_reset_ns_ = last_status_ns_;
  if (o.watchdog_s > 0.0) {
    if (!watchdog_.start(to_ns(o.watchdog_s), &FlightNode::on_watchdog, this,
                         o.watchdog_fifo_priority)) {
      std::fprintf(stderr, "rocksteady-fsw: watchdog: %s\n", watchdog_.error());
      return 1;
    }
  }
  const int rc = o.clock == ClockMode::kLockstep ? run_lockstep(o, stop) : run_realtime(o, stop);
  watchdog_.stop();
  if (o.verbose) {
    status_line("fsw exit:");
    const double n = stats_.ticks > 0 ? static_cast<double>(stats_.ticks) : 1.0;
    rusage ru{};
    getrusage(RUSAGE_SELF, &ru);
    std::printf("fsw process: cpu_s=%.3f ctx=%ld\n",
                static_cast<double>(ru.ru_utime.tv_sec + ru.ru_stime.tv_sec) +
                    static_cast<double>(ru.ru_utime.tv_usec + ru.ru_stime.tv_usec) * 1e-6,
                ru.ru_nvcsw + ru.ru_nivcsw);
    std::printf(
        "fsw time per tick: wait %.2f us, lcm_handle %.2f us, computer tick %.2f us, "
        "telemetry+events %.2f us (%" PRIu64 " ticks, %" PRIu64 " messages handled)\n",
        static_cast<double>(stats_.ns_wait) * 1e-3 / n,
        static_cast<double>(stats_.ns_handle) * 1e-3 / n,
        static_cast<double>(stats_.ns_tick) * 1e-3 / n,
        static_cast<double>(stats_.ns_after_tick) * 1e-3 / n, stats_.ticks,
        stats_.flight_handled + stats_.ground_handled);
    std::fflush(stdout);
  }
  return rc;
}

int FlightNode::run_lockstep(const NodeOptions& o, const volatile std::sig_atomic_t* stop) {
  const std::int64_t start = clock_.now_ns();
  const std::int64_t period = computer_.app().executive().base_period_ns();
  const std::int64_t watchdog = to_ns(o.frame_watchdog_s);
  LockstepSource source;
  std::uint64_t offset = 0;
  bool streaming = false;       // a frame has arrived (the watchdog is armed)
  bool frameless = false;       // the watchdog fired: frameless ticks at the base period
  std::int64_t last_frame_ns = start;
  std::int64_t next_frameless_ns = start;

  while ((stop == nullptr || *stop == 0) && !limits_reached(o, start)) {
    std::int64_t deadline;
    if (!streaming) {
      deadline = clock_.now_ns() + 100 * kNsPerMs;  // wake up to look at the stop flag
    } else if (!frameless) {
      deadline = last_frame_ns + watchdog;
    } else {
      deadline = next_frameless_ns;
    }
    if (!wait_once(deadline)) return 1;
    const std::int64_t now = clock_.now_ns();

    if (sensors_.pending()) {
      const std::int64_t seq = sensors_.pending_seq();
      const bool restarted = sensors_.restarts() != restarts_handled_;
      if (!restarted && !frameless && thrusters_.written() && seq == computer_.echo_seq()) {
        // The plant resends a frame whose command it did not get: answer again, no new tick.
        sensors_.drop();
        ++stats_.duplicate_frames;
        thrusters_.republish();
        last_frame_ns = now;
        continue;
      }
      if (restarted || frameless) {
        // A new stream, or the old one after a gap: new frame numbering, ticks continue.
        source = LockstepSource{};
        offset = have_index_ ? last_index_ + 1 : 0;
        restarts_handled_ = sensors_.restarts();
        frameless = false;
      }
      if (!source.on_frame(seq, now)) {
        sensors_.drop();
        ++stats_.stale_frames;
        continue;
      }
      Tick t;
      if (source.next(t)) {
        t.index += offset;
        tick(t, o);
      } else {
        sensors_.drop();
      }
      streaming = true;
      last_frame_ns = now;
    } else if (streaming && now >= deadline) {
      if (!frameless) {
        frameless = true;
        next_frameless_ns = now;
        bus_event(Severity::kWarning, BusEventId::kFrameWatchdog,
                  static_cast<std::int32_t>(computer_.echo_seq()), 0,
                  "no sensor frame within the watchdog time: frameless ticks at the base rate");
      }
      const Tick t{have_index_ ? last_index_ + 1 : 0, now, 0};
      sensors_.drop();  // nothing is waiting here; a frame would have been handled above
      tick(t, o);
      ++stats_.watchdog_ticks;
      next_frameless_ns += period;
      if (next_frameless_ns < now) next_frameless_ns = now + period;
    }
    if (o.verbose && now - last_status_ns_ >= kNsPerS) {
      last_status_ns_ = now;
      status_line("fsw:");
    }
  }
  return bus_error_ ? 1 : 0;
}

int FlightNode::run_realtime(const NodeOptions& o, const volatile std::sig_atomic_t* stop) {
  const std::int64_t start = clock_.now_ns();
  ServingClock serving(*this, clock_, stop);
  RealTimeClockSource source(serving, computer_.app().executive().base_period_ns());
  while ((stop == nullptr || *stop == 0) && !limits_reached(o, start)) {
    Tick t;
    source.next(t);
    const std::int64_t now = clock_.now_ns();
    if (serving.error()) return 1;
    if (stop != nullptr && *stop != 0) break;
    if (o.jitter_ns != nullptr && o.jitter_ns->size() < o.jitter_ns->capacity()) {
      o.jitter_ns->push_back(now - t.start_ns);
    }
    tick(t, o);  // the newest frame that arrived, if any, is polled by the computer
    if (o.verbose && now - last_status_ns_ >= kNsPerS) {
      last_status_ns_ = now;
      status_line("fsw:");
    }
  }
  return bus_error_ ? 1 : 0;
}

}  // namespace rocksteady::fsw::bus
