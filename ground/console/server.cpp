#include "ground/console/server.hpp"

#include <httplib.h>
#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <thread>

#include <lcm/lcm-cpp.hpp>

#include "ground/cli/command_gate.hpp"
#include "ground/cli/commands.hpp"
#include "ground/cli/sequence.hpp"
#include "ground/console/telemetry_store.hpp"
#include "ground/dictionary/dictionary.hpp"

namespace rocksteady::ground::console {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

double now_ms() {
  using namespace std::chrono;
  return static_cast<double>(
             duration_cast<microseconds>(system_clock::now().time_since_epoch()).count()) /
         1000.0;
}

// JSON has no NaN or infinity: those become null.
json number(double v) {
  return std::isfinite(v) ? json(v) : json(nullptr);
}

json values_json(const std::vector<double>& values) {
  json a = json::array();
  for (double v : values) a.push_back(number(v));
  return a;
}

json event_json(const EventRecord& e) {
  return {{"index", e.index},
          {"utc", e.utc_ms},
          {"t", e.t},
          {"severity", e.severity},
          {"severity_name", e.severity_name},
          {"id", e.id},
          {"name", e.name},
          {"arg0", e.arg0},
          {"arg1", e.arg1},
          {"text", e.text}};
}

// Every channel of the dictionary, raw, into the store; on its own thread and its own LCM.
class Bridge {
 public:
  Bridge(const std::string& url, TelemetryStore& store) : lcm_(url), store_(store) {}
  bool good() { return lcm_.good(); }
  void start() {
    for (const dictionary::Channel& c : dictionary::channels()) {
      lcm_.subscribe(c.channel, &Bridge::on_message, this);
    }
    thread_ = std::thread([this] {
      while (!stop_) {
        if (lcm_.handleTimeout(100) < 0) break;
      }
    });
  }
  void stop() {
    stop_ = true;
    if (thread_.joinable()) thread_.join();
  }

 private:
  void on_message(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
    store_.add(channel, rbuf->data, static_cast<int>(rbuf->data_size), now_ms());
  }
  lcm::LCM lcm_;
  TelemetryStore& store_;
  std::thread thread_;
  std::atomic<bool> stop_{false};
};

json stats_json(const TelemetryStore& store, double now, double stale_after_ms) {
  json out = json::object();
  for (const auto& [name, s] : store.stats()) {
    const double age = s.last_utc_ms < 0.0 ? -1.0 : now - s.last_utc_ms;
    out[name] = {{"received", s.received},
                 {"rejected", s.rejected},
                 {"last_utc", s.last_utc_ms < 0.0 ? json(nullptr) : json(s.last_utc_ms)},
                 {"age_ms", age < 0.0 ? json(nullptr) : json(age)},
                 {"stale", age < 0.0 || age > stale_after_ms}};
  }
  return out;
}

std::vector<std::string> string_list(const json& j, const char* key) {
  std::vector<std::string> out;
  if (!j.contains(key)) return out;
  const json& a = j.at(key);
  if (!a.is_array()) throw std::runtime_error(std::string("'") + key + "' must be a list");
  for (const json& v : a) {
    if (v.is_string()) {
      out.push_back(v.get<std::string>());
    } else if (v.is_number()) {
      out.push_back(v.dump());
    } else {
      throw std::runtime_error(std::string("'") + key + "' must hold strings or numbers");
    }
  }
  return out;
}

}  // namespace

std::string find_web_root() {
  const auto has_app = [](const fs::path& p) {
    std::error_code ec;
    return fs::exists(p / "app" / "index.html", ec) && fs::exists(p / "openmct" / "openmct.js", ec);
  };
  if (const char* env = std::getenv("ROCKSTEADY_CONSOLE_WEB"); env != nullptr && env[0] != '\0') {
    return has_app(env) ? std::string(env) : std::string();
  }
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (ec) return "";
  for (const fs::path& p :
       {exe.parent_path() / "console-web",
        exe.parent_path().parent_path() / "share" / "rocksteady" / "console-web"}) {
    if (has_app(p)) return p.string();
  }
  return "";
}

int serve(const ServeOptions& o) {
  const std::string web = o.web_root.empty() ? find_web_root() : o.web_root;
  if (web.empty()) {
    std::fprintf(stderr,
                 "error: serve: no web root with app/index.html and openmct/openmct.js (give "
                 "--web-root or set ROCKSTEADY_CONSOLE_WEB; scripts/setup.sh installs Open MCT)\n");
    return 2;
  }
  TelemetryStore store;
  Bridge bridge(o.lcm_url, store);
  if (!bridge.good()) {
    std::fprintf(stderr, "error: serve: cannot open the LCM bus %s\n", o.lcm_url.c_str());
    return 2;
  }
  cli::GateOptions gate_options;
  gate_options.lcm_url = o.lcm_url;
  gate_options.sender = o.sender;
  gate_options.state_dir = o.state_dir;
  gate_options.timeout_s = o.ack_timeout_s;
  cli::CommandGate gate(gate_options);
  const double stale_ms = o.stale_after_s * 1000.0;
  std::atomic<bool> stopping{false};

  httplib::Server svr;
  if (!svr.set_mount_point("/openmct", web + "/openmct") ||
      !svr.set_mount_point("/", web + "/app")) {
    std::fprintf(stderr, "error: serve: cannot serve %s\n", web.c_str());
    return 2;
  }
  svr.Get("/api/dictionary", [](const httplib::Request&, httplib::Response& res) {
    res.set_content(dictionary::json_text(), "application/json");
  });
  svr.Get("/api/history", [&](const httplib::Request& req, httplib::Response& res) {
    const std::string channel = req.get_param_value("channel");
    const std::string key = req.get_param_value("key");
    const dictionary::Channel* c = dictionary::find_channel(channel);
    const int point = c == nullptr ? -1 : dictionary::find_point(*c, key);
    if (point < 0) {
      res.status = 404;
      res.set_content(
          json({{"error", "no point '" + key + "' on channel '" + channel + "'"}}).dump(),
          "application/json");
      return;
    }
    double start = 0.0;
    double end = 1e300;
    try {
      if (req.has_param("start")) start = std::stod(req.get_param_value("start"));
      if (req.has_param("end")) end = std::stod(req.get_param_value("end"));
    } catch (const std::exception&) {
      res.status = 400;
      res.set_content(json({{"error", "start and end are milliseconds since the epoch"}}).dump(),
                      "application/json");
      return;
    }
    json out = json::array();
    for (const auto& [utc, v] : store.history(channel, point, start, end)) {
      out.push_back({utc, number(v)});
    }
    res.set_content(out.dump(), "application/json");
  });
  svr.Get("/api/latest", [&](const httplib::Request&, httplib::Response& res) {
    json out = {{"now", now_ms()}, {"stale_after_ms", stale_ms}};
    json samples = json::object();
    for (const dictionary::Channel& c : dictionary::channels()) {
      const Sample s = store.latest(c.channel);
      if (s.values.empty()) continue;
      samples[c.channel] = {{"utc", s.utc_ms}, {"values", values_json(s.values)}, {"text", s.text}};
    }
    out["samples"] = samples;
    out["stats"] = stats_json(store, out["now"].get<double>(), stale_ms);
    res.set_content(out.dump(), "application/json");
  });
  svr.Get("/api/events", [&](const httplib::Request& req, httplib::Response& res) {
    std::uint64_t after = 0;
    if (req.has_param("after"))
      after = std::strtoull(req.get_param_value("after").c_str(), nullptr, 10);
    json out = json::array();
    for (const EventRecord& e : store.events_after(after)) out.push_back(event_json(e));
    res.set_content(out.dump(), "application/json");
  });
  svr.Get("/api/stream", [&](const httplib::Request&, httplib::Response& res) {
    res.set_header("Cache-Control", "no-cache");
    auto last_ms = std::make_shared<double>(0.0);
    auto last_event = std::make_shared<std::uint64_t>(0);
    // The events already known are sent by /api/events; the stream starts after them.
    const auto known = store.events_after(0);
    if (!known.empty()) *last_event = known.back().index;
    res.set_chunked_content_provider("text/event-stream", [&, last_ms, last_event](
                                                              std::size_t,
                                                              httplib::DataSink& sink) {
      if (stopping) return false;
      std::this_thread::sleep_for(std::chrono::milliseconds(250));
      const double now = now_ms();
      json msg = {{"now", now}, {"stale_after_ms", stale_ms}};
      json samples = json::object();
      for (const auto& [name, s] : store.newer_than(*last_ms)) {
        samples[name] = {{"utc", s.utc_ms}, {"values", values_json(s.values)}, {"text", s.text}};
        *last_ms = std::max(*last_ms, s.utc_ms);
      }
      msg["samples"] = samples;
      json events = json::array();
      for (const EventRecord& e : store.events_after(*last_event)) {
        events.push_back(event_json(e));
        *last_event = e.index;
      }
      msg["events"] = events;
      msg["stats"] = stats_json(store, now, stale_ms);
      const std::string frame = "data: " + msg.dump() + "\n\n";
      return sink.write(frame.data(), frame.size());
    });
  });
  svr.Get("/api/commands", [](const httplib::Request&, httplib::Response& res) {
    json out = json::array();
    for (const cli::CommandHelp& h : cli::command_help()) {
      if (std::string(h.name) == "upload-trajectory") continue;
      out.push_back({{"name", h.name}, {"usage", h.usage}, {"what", h.what}});
    }
    res.set_content(out.dump(), "application/json");
  });
  svr.Post("/api/command", [&](const httplib::Request& req, httplib::Response& res) {
    json out;
    try {
      const json body = json::parse(req.body);
      if (!body.contains("command") || !body["command"].is_string()) {
        throw std::runtime_error("'command' (a string) is required");
      }
      const std::string command = body["command"].get<std::string>();
      const std::vector<std::string> args = string_list(body, "args");
      const cli::GateResult r = gate.send(command, args);
      out = {{"outcome", cli::to_string(r.outcome)},
             {"accepted", r.outcome == cli::GateResult::Outcome::kAccepted},
             {"description", r.description},
             {"seq", r.seq},
             {"message", r.message}};
      if (r.outcome == cli::GateResult::Outcome::kAccepted ||
          r.outcome == cli::GateResult::Outcome::kRejected) {
        out["reason"] = r.ack.reason;
        out["reason_name"] = dictionary::enum_name("reason", r.ack.reason).value_or("?");
        out["detail"] = r.ack.detail;
        out["text"] = r.ack.text;
        out["opcode_name"] = dictionary::enum_name("opcode", r.ack.opcode).value_or("?");
      }
    } catch (const std::exception& e) {
      res.status = 400;
      out = {{"outcome", "invalid"},
             {"accepted", false},
             {"message", std::string("request: ") + e.what()}};
    }
    res.set_content(out.dump(), "application/json");
  });
  // A sequence from the browser: validated completely, then run on a bus of its own, one at a time.
  std::mutex sequence_mutex;
  svr.Post("/api/sequence", [&](const httplib::Request& req, httplib::Response& res) {
    json out;
    const cli::SequenceParse parsed = cli::parse_sequence(req.body, "sequence");
    if (!parsed.ok) {
      std::string report;
      for (const std::string& e : parsed.errors) report += e + "\n";
      report += std::to_string(parsed.errors.size()) + " error(s); nothing was sent";
      out = {{"outcome", "invalid"}, {"errors", parsed.errors}, {"report", report}};
      res.status = 400;
    } else {
      std::unique_lock<std::mutex> lock(sequence_mutex, std::try_to_lock);
      if (!lock.owns_lock()) {
        out = {{"outcome", "busy"}, {"report", "another sequence is running"}};
        res.status = 409;
      } else {
        lcm::LCM lcm(o.lcm_url);
        const cli::SequenceReport r = cli::run_sequence(parsed.sequence, gate, lcm, nullptr);
        const bool done = r.outcome == cli::SequenceReport::Outcome::kCompleted;
        out = {{"outcome", done ? "completed" : "aborted"},
               {"failed_step", r.failed_step},
               {"lines", r.lines},
               {"summary", r.summary},
               {"report", r.text()}};
      }
    }
    res.set_content(out.dump(), "application/json");
  });

  int port = o.port;
  if (port == 0) {
    port = svr.bind_to_any_port(o.bind);
    if (port < 0) port = -1;
  } else if (!svr.bind_to_port(o.bind, port)) {
    port = -1;
  }
  if (port < 0) {
    std::fprintf(stderr, "error: serve: cannot listen on %s:%d (--bind/--port)\n", o.bind.c_str(),
                 o.port);
    return 2;
  }
  bridge.start();

  // SIGINT/SIGTERM stop the server from a thread of its own (sigwait), not from a handler.
  sigset_t set;
  sigemptyset(&set);
  sigaddset(&set, SIGINT);
  sigaddset(&set, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &set, nullptr);
  std::thread waiter([&] {
    int sig = 0;
    sigwait(&set, &sig);
    stopping = true;
    svr.stop();
  });
  std::printf("console: http://%s:%d/  (web root %s)\n", o.bind.c_str(), port, web.c_str());
  std::fflush(stdout);
  svr.listen_after_bind();
  bridge.stop();
  if (!stopping) {
    stopping = true;
    pthread_kill(waiter.native_handle(), SIGTERM);
  }
  waiter.join();
  std::fprintf(stderr, "console: stopped\n");
  return 0;
}

}  // namespace rocksteady::ground::console
