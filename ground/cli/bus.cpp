#include "ground/cli/bus.hpp"

#include <algorithm>
#include <chrono>
#include <deque>
#include <thread>
#include <vector>

#include "ground/cli/dictionary.hpp"
#include "ground/cli/ground_auth.hpp"
#include "wire/codec.hpp"
#include "wire/uplink.hpp"
#include "lcmtypes/channels.hpp"

namespace rocksteady::ground::cli {

// (the bus library is rocksteady::wire)
using Clock = std::chrono::steady_clock;

namespace {

constexpr int kResendQuietMs = 500;

// Milliseconds left until `deadline` (at least 0), for handleTimeout.
int remaining_ms(Clock::time_point deadline) {
  const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now());
  return left.count() <= 0 ? 0 : static_cast<int>(left.count());
}

Clock::time_point after(double seconds) {
  return Clock::now() + std::chrono::duration_cast<Clock::duration>(
                            std::chrono::duration<double>(seconds < 0.0 ? 0.0 : seconds));
}

class AckWaiter {
 public:
  explicit AckWaiter(const rocksteady::ground_cmd_t& cmd) : cmd_(cmd) {}
  void on_ack(const lcm::ReceiveBuffer* rbuf, const std::string&) {
    rocksteady::cmd_ack_t ack;
    if (!wire::safe_decode(rbuf->data, static_cast<int>(rbuf->data_size), ack, &rx_)) return;
    if (ack.seq == cmd_.seq && ack.sender_id == cmd_.sender_id && ack.opcode == cmd_.opcode) {
      if (verify_ack(ack) == AckAuth::kForged) {
        ++forged_;
        return;
      }
      if (!matched_) ack_ = ack;
      matched_ = true;
    } else {
      ++others_;
    }
  }
  bool matched() const { return matched_; }
  const rocksteady::cmd_ack_t& ack() const { return ack_; }
  std::uint64_t others() const { return others_; }
  std::uint64_t forged() const { return forged_; }
  const wire::RxCounters& rx() const { return rx_; }

 private:
  rocksteady::ground_cmd_t cmd_;
  rocksteady::cmd_ack_t ack_{};
  bool matched_{false};
  std::uint64_t forged_{0};
  std::uint64_t others_{0};
  wire::RxCounters rx_{};
};

class UplinkWatcher {
 public:
  explicit UplinkWatcher(std::int32_t id, int chunks, std::FILE* log)
      : id_(id), chunks_(chunks), log_(log) {}
  void on_event(const lcm::ReceiveBuffer* rbuf, const std::string&) {
    rocksteady::event_t e;
    if (!wire::safe_decode(rbuf->data, static_cast<int>(rbuf->data_size), e)) return;
    if (e.arg0 != id_) return;
    // Only the flight's authentic events count (a forged uplink_complete must not end the upload).
    if (verify_event(e) == AckAuth::kForged) return;
    switch (e.id) {
      case kEventUplinkComplete:
        complete_ = true;
        break;
      case kEventChunkRejected:
        if (e.arg1 == kChunkStatusOtherUplinkActive) {
          refused_ = true;
          refusal_ = sanitize_text(e.text);
        }
        ++rejections_;
        last_rejection_ = Clock::now();
        if (log_ != nullptr) {
          std::fprintf(log_, "chunk rejected: %s\n",
                       e.text.empty() ? chunk_status_name(e.arg1).c_str()
                                      : sanitize_text(e.text).c_str());
        }
        break;
      case kEventUplinkAbandoned:
        abandoned_ = true;
        if (log_ != nullptr)
          std::fprintf(log_, "uplink abandoned by the flight: %s\n", sanitize_text(e.text).c_str());
        break;
      default:
        break;
    }
  }
  void on_telemetry(const lcm::ReceiveBuffer* rbuf, const std::string&) {
    rocksteady::gnc_telemetry_t m;
    if (!wire::safe_decode(rbuf->data, static_cast<int>(rbuf->data_size), m)) return;
    if (m.uplink_id == id_ && m.uplink_total_chunks == chunks_ &&
        m.uplink_chunks_received == chunks_) {
      complete_ = true;
    }
  }
  bool complete() const { return complete_; }
  bool abandoned() const { return abandoned_; }
  // The flight refuses this upload while another one is in progress: resending cannot help.
  bool refused() const { return refused_; }
  const std::string& refusal() const { return refusal_; }
  std::uint64_t rejections() const { return rejections_; }
  Clock::time_point last_rejection() const { return last_rejection_; }

 private:
  std::int32_t id_;
  int chunks_;
  std::FILE* log_;
  bool complete_{false};
  bool abandoned_{false};
  bool refused_{false};
  std::string refusal_;
  std::uint64_t rejections_{0};
  Clock::time_point last_rejection_{};
};

class Monitor {
 public:
  Monitor(const MonitorOptions& options, std::FILE* out) : options_(options), out_(out) {}

  void on_telemetry(const lcm::ReceiveBuffer* rbuf, const std::string&) {
    if (!wire::safe_decode(rbuf->data, static_cast<int>(rbuf->data_size), tlm_, &counts_.rx))
      return;
    ++counts_.telemetry;
    have_tlm_ = true;
    last_tlm_ = Clock::now();
    if (stale_reported_ && !options_.ansi) {
      std::fprintf(out_, "LIVE telemetry on %s again\n", channels::kGncTelemetry);
    }
    stale_reported_ = false;
    if (options_.ansi) {
      redraw();
    } else {
      std::fprintf(out_, "TLM %s\n", format_status_line(tlm_, counts_).c_str());
      std::fflush(out_);
    }
  }
  void on_event(const lcm::ReceiveBuffer* rbuf, const std::string&) {
    rocksteady::event_t e;
    if (!wire::safe_decode(rbuf->data, static_cast<int>(rbuf->data_size), e, &counts_.rx)) return;
    ++counts_.events;
    // With a key: the flight's events are signed; anything else is shown as such.
    const bool forged = auth_configured() && verify_event(e) == AckAuth::kForged;
    // The plant's events (ids from 1000) are the simulator's, which holds no flight key.
    const bool simulator = forged && e.id >= kFirstPlantEventId && e.key_id == 0;
    show(std::string(simulator ? "EVENT (simulator) "
                     : forged  ? "EVENT (unauthenticated) "
                               : "EVENT ") +
         format_event(e));
  }
  void on_ack(const lcm::ReceiveBuffer* rbuf, const std::string&) {
    rocksteady::cmd_ack_t a;
    if (!wire::safe_decode(rbuf->data, static_cast<int>(rbuf->data_size), a, &counts_.rx)) return;
    ++counts_.acks;
    const bool forged = auth_configured() && verify_ack(a) == AckAuth::kForged;
    show(std::string(forged ? "ACK (FORGED) " : "ACK ") + format_ack(a));
  }
  const MonitorCounts& counts() const { return counts_; }

  // Called between receptions: flags telemetry that has stopped (the flight software died, the
  // link is down) instead of leaving the last values on screen as if they were current.
  void check_stale() {
    if (options_.stale_after_s <= 0.0) return;
    const Clock::time_point ref = have_tlm_ ? last_tlm_ : started_;
    const double silent = std::chrono::duration<double>(Clock::now() - ref).count();
    if (silent < options_.stale_after_s) return;
    char line[160];
    std::snprintf(line, sizeof line, "STALE: no telemetry on %s for %.1f s%s",
                  channels::kGncTelemetry, silent,
                  have_tlm_ ? " (values below are old)" : " (none received yet)");
    stale_line_ = line;
    const bool first = !stale_reported_;
    stale_reported_ = true;
    if (options_.ansi) {
      redraw();
    } else if (first) {
      std::fprintf(out_, "%s\n", line);
      std::fflush(out_);
    }
  }

 private:
  void show(const std::string& line) {
    if (!options_.ansi) {
      std::fprintf(out_, "%s\n", line.c_str());
      std::fflush(out_);
      return;
    }
    recent_.push_back(line);
    while (static_cast<int>(recent_.size()) > options_.event_lines) recent_.pop_front();
    redraw();
  }
  void redraw() {
    // Cursor home, each line overwritten and its rest cleared, then the rest of the screen
    // cleared: no flicker from a full clear.
    constexpr const char* kEol = "\x1b[K\n";
    std::string screen = "\x1b[H";
    if (stale_reported_) screen += "\x1b[1;41m" + stale_line_ + "\x1b[0m" + kEol;
    if (have_tlm_) {
      for (const std::string& l : format_status(tlm_, counts_)) screen += l + kEol;
    } else {
      screen += "waiting for telemetry on " + std::string(channels::kGncTelemetry) + " ..." + kEol;
    }
    screen += std::string("--- events and acks ---") + kEol;
    for (const std::string& l : recent_) screen += l + kEol;
    screen += "\x1b[J";
    std::fputs(screen.c_str(), out_);
    std::fflush(out_);
  }

  MonitorOptions options_;
  std::FILE* out_;
  MonitorCounts counts_{};
  rocksteady::gnc_telemetry_t tlm_{};
  bool have_tlm_{false};
  std::deque<std::string> recent_;
  Clock::time_point started_{Clock::now()};
  Clock::time_point last_tlm_{};
  bool stale_reported_{false};
  std::string stale_line_;
};

}  // namespace

int SendResult::exit_code() const {
  switch (outcome) {
    case Outcome::kAccepted:
      return kExitAccepted;
    case Outcome::kRejected:
      return kExitRejected;
    case Outcome::kTimeout:
    case Outcome::kError:
    case Outcome::kForged:
      return kExitRunFailed;
  }
  return kExitRunFailed;
}

SendResult send_and_wait(lcm::LCM& lcm, const rocksteady::ground_cmd_t& cmd_in, double timeout_s) {
  SendResult r;
  rocksteady::ground_cmd_t cmd = cmd_in;
  try {
    authenticate(cmd);
  } catch (const std::exception& e) {
    r.error = e.what();
    return r;
  }
  r.lab_mode = auth_lab_mode();
  AckWaiter waiter(cmd);
  lcm::Subscription* sub = lcm.subscribe(channels::kCmdAck, &AckWaiter::on_ack, &waiter);
  if (sub == nullptr) {
    r.error = "cannot subscribe to " + std::string(channels::kCmdAck);
    return r;
  }
  if (lcm.publish(channels::kGroundCmd, &cmd) != 0) {
    lcm.unsubscribe(sub);
    r.error = "publishing on " + std::string(channels::kGroundCmd) + " failed";
    return r;
  }
  const Clock::time_point deadline = after(timeout_s);
  while (!waiter.matched()) {
    const int ms = remaining_ms(deadline);
    if (ms <= 0) break;
    if (lcm.handleTimeout(ms) < 0) {
      r.error = "LCM receive failed";
      break;
    }
  }
  lcm.unsubscribe(sub);
  r.other_acks = waiter.others();
  r.forged_acks = waiter.forged();
  r.rx = waiter.rx();
  if (waiter.matched()) {
    r.ack = waiter.ack();
    r.outcome =
        r.ack.accepted != 0 ? SendResult::Outcome::kAccepted : SendResult::Outcome::kRejected;
  } else if (r.error.empty()) {
    r.outcome = waiter.forged() > 0 ? SendResult::Outcome::kForged : SendResult::Outcome::kTimeout;
  }
  return r;
}

namespace {
class ParamCatcher {
 public:
  void on_table(const lcm::ReceiveBuffer* rbuf, const std::string&) {
    rocksteady::param_table_t t;
    if (!wire::safe_decode(rbuf->data, static_cast<int>(rbuf->data_size), t, &rx_)) return;
    // Only the flight's authentic read-back is believed; a forged table is counted and dropped.
    const AckAuth a = verify_params(t);
    if (a == AckAuth::kForged) {
      ++forged_;
      return;
    }
    table_ = t;
    lab_ = a == AckAuth::kLabMode;
    have_ = true;
  }
  bool have() const { return have_; }
  bool lab() const { return lab_; }
  std::uint64_t forged() const { return forged_; }
  const rocksteady::param_table_t& table() const { return table_; }

 private:
  rocksteady::param_table_t table_{};
  bool have_{false};
  bool lab_{false};
  std::uint64_t forged_{0};
  wire::RxCounters rx_{};
};
}  // namespace

ParamReadback read_params(lcm::LCM& lcm, const rocksteady::ground_cmd_t& cmd_in,
                          double timeout_s) {
  ParamReadback r;
  rocksteady::ground_cmd_t cmd = cmd_in;
  try {
    authenticate(cmd);
  } catch (const std::exception& e) {
    r.send.error = e.what();
    return r;
  }
  ParamCatcher catcher;
  AckWaiter waiter(cmd);
  lcm::Subscription* tsub = lcm.subscribe(channels::kParams, &ParamCatcher::on_table, &catcher);
  lcm::Subscription* asub = lcm.subscribe(channels::kCmdAck, &AckWaiter::on_ack, &waiter);
  if (tsub == nullptr || asub == nullptr || lcm.publish(channels::kGroundCmd, &cmd) != 0) {
    r.send.error = "cannot subscribe or publish on the bus";
  } else {
    const Clock::time_point deadline = after(timeout_s);
    while (!(waiter.matched() && (catcher.have() || waiter.ack().accepted == 0))) {
      const int ms = remaining_ms(deadline);
      if (ms <= 0) break;
      if (lcm.handleTimeout(ms) < 0) {
        r.send.error = "LCM receive failed";
        break;
      }
    }
  }
  if (tsub != nullptr) lcm.unsubscribe(tsub);
  if (asub != nullptr) lcm.unsubscribe(asub);
  r.send.other_acks = waiter.others();
  r.send.forged_acks = waiter.forged();
  r.send.rx = waiter.rx();
  if (waiter.matched()) {
    r.send.ack = waiter.ack();
    r.send.outcome = r.send.ack.accepted != 0 ? SendResult::Outcome::kAccepted
                                              : SendResult::Outcome::kRejected;
  } else if (r.send.error.empty()) {
    r.send.outcome = waiter.forged() > 0 ? SendResult::Outcome::kForged
                                         : SendResult::Outcome::kTimeout;
  }
  r.have_table = catcher.have();
  r.table = catcher.table();
  r.table_unauthenticated = catcher.lab();
  r.forged_tables = catcher.forged();
  return r;
}

std::string format_params(const rocksteady::param_table_t& table) {
  std::string out;
  char line[512];
  std::snprintf(line, sizeof line, "active parameter table at t = %.3f s (dump %lld)\n", table.t,
                static_cast<long long>(table.dump_seq));
  out += line;
  for (int i = 0; i < table.count; ++i) {
    const std::optional<ParamEntry> p = find_param(std::to_string(i));
    std::string values;
    for (int k = 0; k < table.value_count[i]; ++k) {
      std::snprintf(line, sizeof line, "%s%.9g", k == 0 ? "" : " ", table.values[i][k]);
      values += line;
    }
    if (table.value_count[i] == 6) values = "[xx yy zz xy xz yz] " + values;
    std::snprintf(line, sizeof line, "%2d  %-30s %-16s %s\n", i, p ? p->name : "?",
                  p && p->units[0] != '\0' ? p->units : "-", values.c_str());
    out += line;
  }
  return out;
}

UploadResult upload_chunks(lcm::LCM& lcm, const gnc::TrajectoryTable& table,
                           const UploadOptions& options, std::FILE* log) {
  UploadResult r;
  r.chunks = wire::chunk_count(table.count);
  std::vector<rocksteady::trajectory_chunk_t> chunks(static_cast<std::size_t>(r.chunks));
  for (int i = 0; i < r.chunks; ++i) {
    if (!wire::make_chunk(table, options.upload_id, i, chunks[static_cast<std::size_t>(i)])) {
      r.message = "cannot chunk the table (" + std::to_string(table.count) + " samples)";
      return r;
    }
  }
  UplinkWatcher watcher(options.upload_id, r.chunks, log);
  lcm::Subscription* ev = lcm.subscribe(channels::kEvents, &UplinkWatcher::on_event, &watcher);
  lcm::Subscription* tlm =
      lcm.subscribe(channels::kGncTelemetry, &UplinkWatcher::on_telemetry, &watcher);

  for (int pass = 1; pass <= options.passes && !watcher.complete() && !watcher.abandoned() &&
                     !watcher.refused();
       ++pass) {
    r.passes_used = pass;
    const std::uint64_t rejections_before = watcher.rejections();
    for (rocksteady::trajectory_chunk_t& c : chunks) {
      // Every transmission is a new message: the key's next counter, a new authenticator.
      try {
        c.seq = next_counter(options.state_dir, options.sender);
        authenticate(c);
      } catch (const std::exception& e) {
        r.message = e.what();
        lcm.unsubscribe(ev);
        lcm.unsubscribe(tlm);
        return r;
      }
      if (lcm.publish(channels::kTrajUplink, &c) != 0) {
        r.message = "publishing on " + std::string(channels::kTrajUplink) + " failed";
        lcm.unsubscribe(ev);
        lcm.unsubscribe(tlm);
        return r;
      }
      // Pace the chunks and keep reading (the events of earlier chunks) meanwhile.
      const Clock::time_point next = after(options.chunk_interval_s);
      for (int ms = remaining_ms(next); ms > 0; ms = remaining_ms(next)) lcm.handleTimeout(ms);
    }
    if (log != nullptr) {
      std::fprintf(log, "upload %d: pass %d sent %d chunks (%d samples, crc %08x)\n",
                   options.upload_id, pass, r.chunks, table.count,
                   static_cast<unsigned>(chunks.front().table_crc));
    }
    // Wait for completion; after a rejected chunk (e.g. busy: the previous table is still waiting
    // for the tick boundary) the next pass starts once the rejections have stopped for a while.
    const Clock::time_point deadline = after(options.wait_s);
    while (!watcher.complete() && !watcher.abandoned() && !watcher.refused()) {
      if (watcher.rejections() > rejections_before &&
          Clock::now() - watcher.last_rejection() > std::chrono::milliseconds(kResendQuietMs)) {
        break;
      }
      const int ms = std::min(remaining_ms(deadline), kResendQuietMs);
      if (ms <= 0) break;
      lcm.handleTimeout(ms);
    }
  }
  lcm.unsubscribe(ev);
  lcm.unsubscribe(tlm);
  r.complete = watcher.complete();
  r.refused = !r.complete && watcher.refused();
  r.chunk_rejections = watcher.rejections();
  if (r.complete) {
    r.message = "upload " + std::to_string(options.upload_id) + " complete on board (" +
                std::to_string(r.chunks) + " chunks)";
  } else if (watcher.abandoned()) {
    r.message = "the flight abandoned upload " + std::to_string(options.upload_id);
  } else if (watcher.refused()) {
    r.message = "the flight refuses upload " + std::to_string(options.upload_id) +
                " while another is in progress (" + watcher.refusal() +
                "): abort that one with `send abort-uplink ID`, then upload again";
  } else {
    r.message = "no uplink_complete for upload " + std::to_string(options.upload_id) + " after " +
                std::to_string(r.passes_used) + " passes";
  }
  return r;
}

MonitorCounts run_monitor(lcm::LCM& lcm, const MonitorOptions& options, std::FILE* out) {
  Monitor monitor(options, out);
  lcm::Subscription* subs[] = {
      lcm.subscribe(channels::kGncTelemetry, &Monitor::on_telemetry, &monitor),
      lcm.subscribe(channels::kEvents, &Monitor::on_event, &monitor),
      lcm.subscribe(channels::kCmdAck, &Monitor::on_ack, &monitor),
  };
  const bool timed = options.seconds >= 0.0;
  const Clock::time_point deadline = after(options.seconds);
  for (;;) {
    if (options.count >= 0 &&
        monitor.counts().telemetry >= static_cast<std::uint64_t>(options.count))
      break;
    int ms = 500;
    if (timed) {
      ms = remaining_ms(deadline);
      if (ms <= 0) break;
    }
    if (lcm.handleTimeout(std::min(ms, 500)) < 0) break;
    monitor.check_stale();
  }
  for (lcm::Subscription* s : subs) {
    if (s != nullptr) lcm.unsubscribe(s);
  }
  return monitor.counts();
}

}  // namespace rocksteady::ground::cli
