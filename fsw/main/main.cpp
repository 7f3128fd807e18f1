// rocksteady-fsw: the flight application on the LCM bus (processor-in-the-loop, or the flight
// board's Linux process). Configuration is read once at start-up (YAML, through config/'s
// strict loader: the flight side's estimates only, never the truth); after that the loop is the
// FlightNode's, whose tick path does not allocate.
//
//   rocksteady-fsw --case 1 --clock lockstep --initial-mode DETUMBLE
//   rocksteady-fsw --case 1 --clock realtime --rate 100 -v
#include <algorithm>
#include <cctype>
#include <cinttypes>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <memory>
#include <string>
#include <vector>

#include <sys/prctl.h>

#include <CLI/CLI.hpp>
#include <lcm/lcm.h>

#include "fsw/bus/bus_mapping.hpp"
#include "fsw/bus/flight_node.hpp"
#include "config/config_files.hpp"
#include "fsw/auth/key_file.hpp"
#include "fsw/computer/flight_computer.hpp"
#include "fsw/executive/clock.hpp"
#include "hal/lcm/lcm_ports.hpp"
#include "rt/realtime.hpp"

namespace {

volatile std::sig_atomic_t g_stop = 0;
void on_signal(int /*sig*/) { g_stop = 1; }

std::string case_file(const std::string& config_dir, const std::string& arg) {
  if (!arg.empty() && std::all_of(arg.begin(), arg.end(), [](unsigned char c) { return std::isdigit(c); })) {
    return config_dir + "/cases/case" + arg + ".yaml";
  }
  return arg;
}

bool parse_law(const std::string& s, rocksteady::gnc::LawId& out) {
  for (int i = 0; i < rocksteady::gnc::kLawCount; ++i) {
    const auto id = static_cast<rocksteady::gnc::LawId>(i);
    if (s == rocksteady::gnc::to_string(id)) {
      out = id;
      return true;
    }
  }
  return false;
}

bool parse_mode(std::string s, rocksteady::gnc::Mode& out) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::toupper(c); });
  for (int i = 0; i < rocksteady::gnc::kModeCount; ++i) {
    const auto m = static_cast<rocksteady::gnc::Mode>(i);
    if (s == rocksteady::gnc::to_string(m)) {
      out = m;
      return true;
    }
  }
  return false;
}

void print_jitter(const char* label, std::vector<std::int64_t> v, double rate_hz) {
  if (v.empty()) return;
  for (auto& x : v) x = x < 0 ? -x : x;
  std::sort(v.begin(), v.end());
  const auto at = [&](double q) {
    const auto i = static_cast<std::size_t>(q * static_cast<double>(v.size() - 1) + 0.5);
    return static_cast<double>(v[std::min(i, v.size() - 1)]) * 1e-3;
  };
  std::printf("%s rate=%.6g Hz ticks=%zu median=%.1f us p99=%.1f us max=%.1f us\n", label, rate_hz,
              v.size(), at(0.5), at(0.99), static_cast<double>(v.back()) * 1e-3);
}

}  // namespace

int main(int argc, char** argv) {
  using namespace rocksteady;
  namespace bus = rocksteady::fsw::bus;
  CLI::App cli{"Rocksteady flight software on the LCM bus"};
  std::string config_dir = "configs";
  std::string mission_path, gnc_path, case_arg = "1";
  std::string lcm_url;
  std::string clock_name = "lockstep";
  std::string law_name, initial_mode;
  double rate_hz = 0.0;
  bus::NodeOptions opt;
  bool jitter = false;
  cli.add_option("--config-dir", config_dir, "folder with mission.yaml, gnc.yaml, cases/")
      ->capture_default_str();
  cli.add_option("--mission", mission_path, "mission file (default <config-dir>/mission.yaml)");
  cli.add_option("--gnc", gnc_path, "GNC file (default <config-dir>/gnc.yaml)");
  cli.add_option("--case", case_arg, "case number or case file (the flight side's estimates)")
      ->capture_default_str();
  cli.add_option("--lcm-url", lcm_url, "LCM URL (default: LCM_DEFAULT_URL or LCM's default)");
  cli.add_option("--clock", clock_name, "lockstep (one tick per sensor frame) or realtime")
      ->check(CLI::IsMember({"lockstep", "realtime"}))
      ->capture_default_str();
  cli.add_option("--rate", rate_hz, "realtime base rate, Hz (default: the GNC rate; a multiple of it)");
  cli.add_option("--law", law_name, "control law: ntcl, el, integral, adaptive, so3, dpd, feedforward");
  cli.add_option("--initial-mode", initial_mode, "boot mode (mode.initial): IDLE, DETUMBLE, HOLD, SAFE");
  std::string start_mode;
  cli.add_option("--start-mode", start_mode,
                 "after the first GNC tick, command this mode as the ground would (e.g. DETUMBLE)");
  cli.add_option("--frame-watchdog", opt.frame_watchdog_s,
                 "lockstep: no sensor frame for this many wall seconds -> frameless ticks (-> SAFE)")
      ->capture_default_str();
  cli.add_option("--tlm-every", opt.tlm_every, "publish RS_GNC_TLM every N GNC cycles")
      ->capture_default_str();
  cli.add_option("--exit-after", opt.exit_after_s, "exit after this many wall seconds");
  cli.add_option("--exit-after-ticks", opt.exit_after_ticks, "exit after this many base ticks");
  cli.add_flag("-v,--verbose", opt.verbose, "one status line per second");
  cli.add_flag("--jitter", jitter, "realtime: print tick-start deviation statistics at exit");
  std::string ground_url;
  cli.add_option(
      "--ground-lcm-url", ground_url,
      "separate bus for the ground channels (commands, uplink, acks, events, telemetry); "
      "the --lcm-url bus then carries only sensor frames and thruster commands");
  std::string actuator_url;
  cli.add_option("--actuator-lcm-url", actuator_url,
                 "publish thruster commands on this bus (default: --lcm-url); with "
                 "--ground-lcm-url, --lcm-url then carries only sensor frames: each process hears "
                 "only what it consumes (faster lockstep)");
  bool direct_rx = false;
  cli.add_flag("--direct-rx", direct_rx,
               "read sensor frames from the --lcm-url socket in the loop thread (no LCM receive "
               "thread: one wake-up per frame); needs --actuator-lcm-url and --ground-lcm-url");
  cli.add_option(
         "--ground-drain-max", opt.ground_drain_max,
         "ground messages decoded per base tick; the rest of the tick's are dropped, counted")
      ->check(CLI::Range(1u, 100000u))
      ->capture_default_str();
  std::string key_file, state_file;
  bool lab_mode = false;
  cli.add_option("--key-file", key_file,
                 "command keys (mode 0600, owner only; made by `rocksteady-ground keygen`): ground "
                 "commands and uplink chunks must carry their HMAC, acknowledgements carry one");
  cli.add_option("--state-file", state_file,
                 "replay-protection state (active key, highest counter per key), restored at start "
                 "and rewritten whenever it changes (default: <key-file>.state)");
  cli.add_flag("--lab-mode", lab_mode,
               "LAB MODE: no keys, commands NOT authenticated (announced by an event, flagged in "
               "every telemetry packet)");
  double watchdog_ms = 0.0;
  cli.add_option("--watchdog-ms", watchdog_ms,
                 "software watchdog: no GNC cycle for this long -> event 203, all thrusters off, "
                 "exit status 5 (0: off)")
      ->check(CLI::NonNegativeNumber);
  rocksteady::rt::RealtimeOptions rt_opt;
  rocksteady::rt::add_options(cli, rt_opt);
  auto* stall = cli.add_option("--test-stall-at-tick", opt.test_stall_at_tick,
                               "FAULT INJECTION for watchdog tests: stall base tick N (> 0)")
                    ->check(CLI::PositiveNumber);
  stall->group("Fault injection (tests only)");
  cli.add_option("--test-stall-s", opt.test_stall_s,
                 "FAULT INJECTION: length of the stall, wall seconds (0: forever)")
      ->needs(stall)
      ->check(CLI::NonNegativeNumber)
      ->group("Fault injection (tests only)");
  CLI11_PARSE(cli, argc, argv);

  if (lab_mode == !key_file.empty()) {
    std::fprintf(stderr, "rocksteady-fsw: give exactly one of --key-file (authenticated commands) "
                         "and --lab-mode (no authentication)\n");
    return 2;
  }
  if (lab_mode && !state_file.empty()) {
    std::fprintf(stderr, "rocksteady-fsw: --state-file needs --key-file\n");
    return 2;
  }
  if (mission_path.empty()) mission_path = config_dir + "/mission.yaml";
  if (gnc_path.empty()) gnc_path = config_dir + "/gnc.yaml";

  fsw::FlightConfig fc;
  try {
    fc.gnc = config::load_flight_params(mission_path, gnc_path, case_file(config_dir, case_arg));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rocksteady-fsw: %s\n", e.what());
    return 2;
  }

  fc.security.lab_mode = lab_mode;
  if (!lab_mode) {
    if (const std::string err = fsw::auth::load_key_file(key_file, fc.security.keys); !err.empty()) {
      std::fprintf(stderr, "rocksteady-fsw: %s\n", err.c_str());
      return 2;
    }
    if (state_file.empty()) state_file = key_file + ".state";
    bool missing = false;
    if (const std::string err = fsw::auth::load_state_file(state_file, fc.security, missing);
        !err.empty()) {
      std::fprintf(stderr, "rocksteady-fsw: %s\n", err.c_str());
      return 2;
    }
    std::printf("rocksteady-fsw: %d command key(s) loaded%s\n", fc.security.keys.count,
                missing ? ", no state file yet (first start)" : ", replay state restored");
  } else {
    std::printf("rocksteady-fsw: LAB MODE: ground commands are NOT authenticated\n");
  }
  if (!law_name.empty() && !parse_law(law_name, fc.gnc.law)) {
    std::fprintf(stderr, "rocksteady-fsw: unknown law '%s'\n", law_name.c_str());
    return 2;
  }
  if (!initial_mode.empty() && !parse_mode(initial_mode, fc.gnc.mode.initial)) {
    std::fprintf(stderr, "rocksteady-fsw: unknown mode '%s'\n", initial_mode.c_str());
    return 2;
  }
  if (!start_mode.empty()) {
    opt.has_start_mode = true;
    if (!parse_mode(start_mode, opt.start_mode)) {
      std::fprintf(stderr, "rocksteady-fsw: unknown mode '%s'\n", start_mode.c_str());
      return 2;
    }
  }
  const double dt = fc.gnc.dt;
  if (clock_name == "lockstep") {
    opt.clock = bus::ClockMode::kLockstep;
    fc.executive = fsw::lockstep_executive(dt, 1.0);
  } else {
    opt.clock = bus::ClockMode::kRealtime;
    const double base = rate_hz > 0.0 ? rate_hz : 1.0 / dt;
    const double divider = std::round(base * dt);
    if (divider < 1.0 || std::fabs(divider - base * dt) > 1e-9 * divider) {
      std::fprintf(stderr, "rocksteady-fsw: --rate %g Hz is not a multiple of the GNC rate %g Hz\n",
                   base, 1.0 / dt);
      return 2;
    }
    fc.executive.base_rate_hz = base;
    fc.executive.gnc_divider = static_cast<std::uint32_t>(divider);
    fc.executive.housekeeping_divider = static_cast<std::uint32_t>(std::max(1.0, std::round(base)));
  }

  if (watchdog_ms > 0.0) {
    // The watchdog is fed by each GNC cycle: it must allow a whole GNC period and, in lockstep, the
    // frame watchdog's silence before frameless ticks resume.
    const double min_s = dt + (opt.clock == bus::ClockMode::kLockstep ? opt.frame_watchdog_s : 0.0);
    if (watchdog_ms * 1e-3 <= min_s) {
      std::fprintf(
          stderr,
          "rocksteady-fsw: --watchdog-ms %g is too short: it must exceed the GNC period "
          "(%g ms)%s, i.e. be above %g ms\n",
          watchdog_ms, dt * 1e3,
          opt.clock == bus::ClockMode::kLockstep ? " plus --frame-watchdog in lockstep" : "",
          min_s * 1e3);
      return 2;
    }
    opt.watchdog_s = watchdog_ms * 1e-3;
  }

  // Real-time hardening before the bus is opened: LCM's receive threads and the watchdog inherit
  // it.
  rocksteady::rt::RealtimeResult rt_result;
  if (const int rc = rocksteady::rt::apply_and_report(rt_opt, "rocksteady-fsw", stdout, &rt_result);
      rc != 0) {
    return rc;
  }
  if (rt_result.fifo_priority_applied > 0) {
    opt.watchdog_fifo_priority = std::min(99, rt_result.fifo_priority_applied + 1);
  }
  if (opt.watchdog_s > 0.0) {
    std::printf(
        "rocksteady-fsw: watchdog: %g ms, fed by the GNC rate group%s\n", watchdog_ms,
        opt.watchdog_fifo_priority > 0 ? " (thread under SCHED_FIFO, one above the tick)" : "");
  }
  if (opt.test_stall_at_tick > 0) {
    std::printf("rocksteady-fsw: FAULT INJECTION armed: base tick %llu will stall\n",
                static_cast<unsigned long long>(opt.test_stall_at_tick));
  }
  std::fflush(stdout);

  if (direct_rx && (actuator_url.empty() || ground_url.empty())) {
    std::fprintf(stderr,
                 "rocksteady-fsw: --direct-rx needs --actuator-lcm-url and --ground-lcm-url (the "
                 "--lcm-url bus must carry only sensor frames)\n");
    return 2;
  }

  fsw::MonotonicClock clock;
  // The flight computer and its LCM ports (sensor frames in, thruster commands out; the frames are
  // aligned with the body frame, so the devices' alignment is the identity).
  const fsw::FlightComputerConfig cc = fsw::default_computer_config(fc);
  hal::LcmSensorSource sensors;
  hal::LcmThrusterSink thrusters(cc.thrusters);
  static fsw::FlightComputer computer(sensors, thrusters);  // large: static storage, once
  const fsw::InitResult ir = computer.init(cc, clock);
  if (!ir.ok) {
    std::fprintf(stderr, "rocksteady-fsw: configuration rejected: %s: %s\n", ir.field, ir.reason);
    return 2;
  }
  lcm_t* lcm = lcm_create(lcm_url.empty() ? nullptr : lcm_url.c_str());
  if (lcm == nullptr) {
    std::fprintf(stderr, "rocksteady-fsw: cannot open the LCM bus\n");
    return 3;
  }
  lcm_t* ground = nullptr;
  if (!ground_url.empty()) {
    ground = lcm_create(ground_url.c_str());
    if (ground == nullptr) {
      std::fprintf(stderr, "rocksteady-fsw: cannot open the ground bus %s\n", ground_url.c_str());
      lcm_destroy(lcm);
      return 3;
    }
  }
  lcm_t* actuator = nullptr;
  if (!actuator_url.empty()) {
    actuator = lcm_create(actuator_url.c_str());  // publish only: no receive thread
    if (actuator == nullptr) {
      std::fprintf(stderr, "rocksteady-fsw: cannot open the actuator bus %s\n",
                   actuator_url.c_str());
      lcm_destroy(lcm);
      if (ground != nullptr) lcm_destroy(ground);
      return 3;
    }
  }
  thrusters.attach(actuator != nullptr ? actuator : lcm);
  std::vector<std::int64_t> jitter_ns;
  if (jitter && opt.clock == bus::ClockMode::kRealtime) {
    const double base = fc.executive.base_rate_hz;
    const double secs = opt.exit_after_s > 0.0 ? opt.exit_after_s : 3600.0;
    jitter_ns.reserve(static_cast<std::size_t>(base * secs) + 16);
    opt.jitter_ns = &jitter_ns;
  }

  // Real time: wake up at the deadline, not up to the default 50 us timer slack later.
  if (opt.clock == bus::ClockMode::kRealtime) prctl(PR_SET_TIMERSLACK, 1UL, 0UL, 0UL, 0UL);
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  int rc = 0;
  {
    bus::FlightNode node(lcm, computer, sensors, thrusters, clock);
    node.set_ground_bus(ground);
    if (!lab_mode) node.set_state_file(state_file);
    rocksteady::rt::UdpmReceiver direct;
    if (direct_rx) {
      const char* env = std::getenv("LCM_DEFAULT_URL");
      const std::string url =
          !lcm_url.empty() ? lcm_url : (env != nullptr ? env : "udpm://239.255.76.67:7667?ttl=0");
      if (!direct.open(url)) {
        std::fprintf(stderr, "rocksteady-fsw: --direct-rx: %s\n", direct.error().c_str());
        return 3;
      }
      node.set_direct_sensor_rx(&direct);
    }
    if (!node.subscribe()) {
      std::fprintf(stderr, "rocksteady-fsw: cannot subscribe\n");
      lcm_destroy(lcm);
      if (ground != nullptr) lcm_destroy(ground);
      if (actuator != nullptr) lcm_destroy(actuator);
      return 3;
    }
    if (opt.verbose) {
      std::printf("rocksteady-fsw: %s, base %.6g Hz, GNC every %u, law %s, boot mode %s\n",
                  clock_name.c_str(), fc.executive.base_rate_hz, fc.executive.gnc_divider,
                  gnc::to_string(fc.gnc.law), gnc::to_string(fc.gnc.mode.initial));
      std::fflush(stdout);
    }
    rc = node.run(opt, &g_stop);
    if (jitter) {
      print_jitter("fsw jitter:", jitter_ns, fc.executive.base_rate_hz);
      const bus::NodeStats& st = node.stats();
      const fsw::HealthTelemetry h = computer.health();
      std::printf(
          "fsw bus: ticks=%llu frameless=%u frames=%llu superseded=%llu missed=%u "
          "ground_dropped=%llu ground_bound_ticks=%llu rx_rejected=%llu\n",
          static_cast<unsigned long long>(st.ticks), h.frameless_ticks,
          static_cast<unsigned long long>(st.frames),
          static_cast<unsigned long long>(st.frames_superseded), h.base_missed,
          static_cast<unsigned long long>(st.ground_dropped),
          static_cast<unsigned long long>(st.ground_bound_ticks),
          static_cast<unsigned long long>(node.rx_total().rejected()));
    }
  }
  lcm_destroy(lcm);
  if (ground != nullptr) lcm_destroy(ground);
  if (actuator != nullptr) lcm_destroy(actuator);
  return rc;
}
