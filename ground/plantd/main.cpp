// rocksteady-plant: the truth model (ground/plant) as a process on the LCM bus, for
// processor-in-the-loop runs against rocksteady-fsw.
//
// Each control period k: publish RS_SENSORS frame k (and RS_PLANT_TRUTH, decimated), then
//   lockstep: wait for the RS_THRUSTER_CMD echoing seq k. A wait longer than --timeout-ms is
//     counted; the frame is re-sent (--retries times; the flight software answers a repeated frame
//     with the command it already computed), and if no echo comes the plant advances with the
//     previous command held (zero-order hold), counted. Before frame 0 is answered the plant waits
//     up to --startup-timeout for the flight software (not counted).
//   realtime: advance on wall-clock deadlines with the newest command received (zero-order hold).
// The plant commands nothing itself: mode commands come from the operator, a test or a script.
// Thruster commands go through the plant's valve driver: when none arrives for --valve-timeout s of
// plant time (a held period counts), every thruster is switched off. Fault injection (PIL):
// RS_PLANT_FAULT (plant_fault_cmd_t) on the ground bus adds or clears a thruster fault; each one is
// answered with an event (accepted, or rejected with the reason) and counted. The case file's
// `faults:` apply from the start. The flight software never hears any of it.
// At the end, --summary prints the study's figures of merit (SPEC §7), computed on the true state
// exactly as the in-process runner does (ground/merit). The plant links no flight software: it speaks
// device readings (hal/readings.hpp) through the bus library (wire/).
#include <poll.h>
#include <sys/resource.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cinttypes>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <exception>
#include <fstream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <lcm/lcm.h>

#include "gnc/units.hpp"
#include "ground/config/config.hpp"
#include "ground/merit/figures_of_merit.hpp"
#include "ground/plant/plant.hpp"
#include "lcmtypes/channels.hpp"
#include "rt/realtime.hpp"
#include "rt/udpm_receiver.hpp"
#include "wire/codec.hpp"
#include "wire/convert.hpp"

namespace {

using namespace rocksteady;

volatile std::sig_atomic_t g_stop = 0;
void on_signal(int /*sig*/) { g_stop = 1; }

using gnc::kNsPerS;

std::int64_t now_ns() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * kNsPerS + ts.tv_nsec;
}

std::string case_file(const std::string& config_dir, const std::string& arg) {
  if (!arg.empty() &&
      std::all_of(arg.begin(), arg.end(), [](unsigned char c) { return std::isdigit(c); })) {
    return config_dir + "/cases/case" + arg + ".yaml";
  }
  return arg;
}

// Plant events on RS_EVENTS (ids from 1000).
enum PlantEvent : std::int32_t {
  kRunStarted = 1000,
  kEchoTimeout = 1001,
  kRunFinished = 1002,
  kFaultAccepted = 1003,    // arg0: thruster, arg1: fault kind (or 0 for a clear)
  kFaultRejected = 1004,    // arg0: thruster, arg1: op; text: the reason
  kValveDriverTimeout = 1005,  // the valve driver switched the thrusters off (arg0: frame)
};

struct Bus {
  lcm_t* lcm{nullptr};
  lcm_t* ground{nullptr};  // --ground-lcm-url: telemetry in, events and truth out (else lcm)
  lcm_t* actuator{nullptr};  // --actuator-lcm-url: thruster commands in (else lcm)
  rocksteady::thruster_cmd_t scratch{};
  rocksteady::gnc_telemetry_t tlm{};
  bool have_cmd{false};
  rocksteady::thruster_cmd_t latest{};  // newest valid command
  wire::RxCounters rx{};
  std::uint64_t commands{0};
  bool have_tlm{false};
  rocksteady::plant_fault_cmd_t fault_scratch{};
  std::vector<rocksteady::plant_fault_cmd_t> fault_queue;  // applied by the loop between periods
  wire::RxCounters fault_rx{};
  int last_mode{-1};
  double fuel_hat{0.0};
  std::int64_t event_seq{0};
  unsigned char buf[4096]{};

  static void on_cmd(const lcm_recv_buf_t* rbuf, const char* /*ch*/, void* self) {
    auto& b = *static_cast<Bus*>(self);
    if (!wire::safe_decode(rbuf->data, static_cast<int>(rbuf->data_size), b.scratch, &b.rx)) {
      return;  // counted, ignored
    }
    ++b.commands;
    b.latest = b.scratch;
    b.have_cmd = true;
  }
  static void on_fault(const lcm_recv_buf_t* rbuf, const char* /*ch*/, void* self) {
    auto& b = *static_cast<Bus*>(self);
    if (wire::safe_decode(rbuf->data, static_cast<int>(rbuf->data_size), b.fault_scratch,
                          &b.fault_rx)) {
      b.fault_queue.push_back(b.fault_scratch);
    }  // else counted, ignored
  }
  static void on_tlm(const lcm_recv_buf_t* rbuf, const char* /*ch*/, void* self) {
    auto& b = *static_cast<Bus*>(self);
    if (wire::safe_decode(rbuf->data, static_cast<int>(rbuf->data_size), b.tlm)) {
      b.have_tlm = true;
      b.last_mode = b.tlm.mode;
      b.fuel_hat = b.tlm.fuel_kg;
    }
  }
  template <class T>
  void publish(const char* channel, const T& msg, lcm_t* on = nullptr) {
    const int n = wire::encode(msg, buf, static_cast<int>(sizeof buf));
    if (n > 0) lcm_publish(on != nullptr ? on : lcm, channel, buf, static_cast<unsigned int>(n));
  }
  lcm_t* ground_bus() const { return ground != nullptr ? ground : lcm; }
  lcm_t* command_bus() const { return actuator != nullptr ? actuator : lcm; }
  rt::UdpmReceiver* direct{nullptr};  // --direct-rx: thruster commands read by the loop itself
  // One message dispatched or the deadline passed. False on a bus error.
  bool wait_once(std::int64_t deadline) {
    std::int64_t rem = deadline - now_ns();
    if (rem < 0) rem = 0;
    timespec ts{};
    ts.tv_sec = static_cast<time_t>(rem / kNsPerS);
    ts.tv_nsec = static_cast<long>(rem % kNsPerS);
    // Only buses this process receives on are polled (lcm_get_fileno starts LCM's receive thread: a
    // publish-only bus, such as the sensor bus beside an actuator bus, must not get one).
    pollfd p[2]{};
    p[0].fd = direct != nullptr ? direct->fd() : lcm_get_fileno(command_bus());
    p[0].events = POLLIN;
    nfds_t n = 1;
    if (ground != nullptr) {
      p[1].fd = lcm_get_fileno(ground);
      p[1].events = POLLIN;
      n = 2;
    }
    const int r = ppoll(p, n, &ts, nullptr);
    if (r < 0) return errno == EINTR;
    if (r == 0) return true;
    if (p[0].revents != 0 && direct != nullptr) {
      const char* channel = nullptr;
      const void* data = nullptr;
      int size = 0;
      const int got = direct->receive(&channel, &data, &size);
      if (got > 0 && std::strcmp(channel, channels::kThrusterCmd) == 0) {
        lcm_recv_buf_t rbuf{};
        rbuf.data = const_cast<void*>(data);
        rbuf.data_size = static_cast<std::uint32_t>(size);
        rbuf.lcm = command_bus();
        on_cmd(&rbuf, channel, this);
      }
      return got >= 0;
    }
    return lcm_handle(p[0].revents != 0 ? command_bus() : ground) == 0;
  }
  void event(std::int8_t sev, std::int32_t id, std::int32_t a0, std::int32_t a1, double t,
             const std::string& text) {
    auto e = wire::make<rocksteady::event_t>();
    e.t = t;
    e.seq = event_seq++;
    e.severity = sev;
    e.id = id;
    e.arg0 = a0;
    e.arg1 = a1;
    e.text = text.substr(0, rocksteady::event_t::MAX_TEXT);
    publish(channels::kEvents, e, ground_bus());
  }
};

rocksteady::plant_truth_t make_truth(std::int64_t seq, const plant::Plant& p) {
  auto m = wire::make<rocksteady::plant_truth_t>();
  m.seq = seq;
  m.t = p.t();
  for (int i = 0; i < 4; ++i) m.quat[i] = p.beta()(i);
  const plant::Vec3 q = p.mrp();
  for (int i = 0; i < 3; ++i) m.q[i] = q(i);
  for (int i = 0; i < 3; ++i) m.omega[i] = p.omega()(i);
  m.omega_norm = p.omega().norm();
  for (int i = 0; i < 8; ++i) m.channel_force[i] = p.applied_force()(i);
  const plant::Vec3 tc = p.control_torque();
  for (int i = 0; i < 3; ++i) m.torque_control[i] = tc(i);
  for (int i = 0; i < 3; ++i) m.torque_disturbance[i] = p.disturbance()(i);
  m.fuel_used_kg = p.fuel_kg();
  const plant::Vec16 thrust = p.thruster_thrust();
  for (int i = 0; i < hal::kThrusters; ++i) {
    const auto k = static_cast<std::size_t>(i);
    m.fault_kind[i] = static_cast<std::int8_t>(p.active_faults()[k]);
    m.fault_factor[i] = 1.0;
    m.fault_onset[i] = -1.0;
    m.thruster_force[i] = thrust(i);
  }
  for (const plant::ThrusterFault& f : p.faults()) {
    m.fault_onset[f.thruster] = f.onset_s;
    if (f.kind == plant::FaultKind::kDegraded) m.fault_factor[f.thruster] = f.factor;
  }
  for (int k = 0; k < gnc::kPods; ++k) m.valve_open[k] = p.valves()[static_cast<std::size_t>(k)] ? 1 : 0;
  m.command_timeout = p.command_timed_out() ? 1 : 0;
  return m;
}

// One RS_PLANT_FAULT command: applied to the plant, or the reason it was not.
std::string apply_fault_command(const rocksteady::plant_fault_cmd_t& c, plant::Plant& p) {
  using C = rocksteady::plant_fault_cmd_t;
  switch (c.op) {
    case C::OP_INJECT: {
      plant::ThrusterFault f;
      f.thruster = c.thruster;
      switch (c.fault_kind) {
        case C::FAULT_STUCK_OFF: f.kind = plant::FaultKind::kStuckOff; break;
        case C::FAULT_STUCK_ON: f.kind = plant::FaultKind::kStuckOn; break;
        case C::FAULT_DEGRADED: f.kind = plant::FaultKind::kDegraded; break;
        default: return "unknown fault kind " + std::to_string(c.fault_kind);
      }
      f.onset_s = std::max(0.0, c.onset_s);
      f.factor = f.kind == plant::FaultKind::kDegraded ? c.factor : 1.0;
      return p.inject(f);
    }
    case C::OP_CLEAR:
      if (c.thruster < 0 || c.thruster >= hal::kThrusters) return "thruster must be in [0, 15]";
      p.clear_fault(c.thruster);
      return "";
    case C::OP_CLEAR_ALL: p.clear_faults(); return "";
    default: return "unknown op " + std::to_string(c.op);
  }
}

std::string fmt_opt(const std::optional<double>& v, const char* unit, int prec) {
  if (!v) return "NC";
  char b[64];
  std::snprintf(b, sizeof b, "%.*f %s", prec, *v, unit);
  return b;
}
std::string exact(const std::optional<double>& v) {
  if (!v) return "NC";
  char b[64];
  std::snprintf(b, sizeof b, "%.17g", *v);
  return b;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App cli{"Rocksteady plant (truth model) on the LCM bus"};
  std::string config_dir = "configs";
  std::string mission_path, gnc_path, case_arg = "1", lcm_url, mode = "lockstep", out_csv;
  double duration = -1.0, timeout_ms = 200.0, startup_timeout_s = 10.0, log_interval_s = 10.0;
  int retries = 2;
  std::uint32_t truth_every = 1;
  bool summary = false, verbose = false;
  cli.add_option("--config-dir", config_dir, "folder with mission.yaml, gnc.yaml, cases/")
      ->capture_default_str();
  cli.add_option("--mission", mission_path, "mission file (default <config-dir>/mission.yaml)");
  cli.add_option("--gnc", gnc_path, "GNC file (default <config-dir>/gnc.yaml; q_final, u_max)");
  cli.add_option("--case", case_arg, "case number or case file")->capture_default_str();
  cli.add_option("--mode", mode, "lockstep or realtime")
      ->check(CLI::IsMember({"lockstep", "realtime"}))
      ->capture_default_str();
  cli.add_option("--duration", duration, "simulated seconds (default: the case's)");
  cli.add_option("--timeout-ms", timeout_ms, "lockstep: wait for each echo this long")
      ->capture_default_str();
  cli.add_option("--retries", retries, "lockstep: resend a frame this often before holding")
      ->capture_default_str();
  cli.add_option("--startup-timeout", startup_timeout_s,
                 "lockstep: wait this long (s) for the flight software to answer frame 0")
      ->capture_default_str();
  cli.add_option("--truth-every", truth_every, "publish RS_PLANT_TRUTH every N periods (0: never)")
      ->capture_default_str();
  cli.add_option("--lcm-url", lcm_url, "LCM URL (default: LCM_DEFAULT_URL or LCM's default)");
  cli.add_flag("--summary", summary, "print the figures of merit and the bus statistics at the end");
  cli.add_option("--out", out_csv, "time series CSV (true state, forces, fuel)");
  cli.add_option("--log-interval", log_interval_s, "CSV row interval, s")->capture_default_str();
  cli.add_flag("-v,--verbose", verbose, "progress once per wall second");
  double valve_timeout_s = 1.0;
  cli.add_option("--valve-timeout", valve_timeout_s,
                 "valve driver: switch every thruster off after this many seconds of plant time "
                 "without a thruster command (0: hold the last command forever; default: the case "
                 "file's valve_driver_timeout_s when set, else 1 s)");
  std::string ground_url;
  cli.add_option("--ground-lcm-url", ground_url,
                 "separate ground bus (as rocksteady-fsw's): telemetry in, events and truth out");
  std::string actuator_url;
  cli.add_option("--actuator-lcm-url", actuator_url,
                 "receive thruster commands on this bus (as rocksteady-fsw's); --lcm-url then "
                 "carries only the sensor frames this process publishes");
  bool direct_rx = false;
  cli.add_flag("--direct-rx", direct_rx,
               "read thruster commands from the --actuator-lcm-url socket in the loop thread (no "
               "LCM receive thread); needs --actuator-lcm-url and --ground-lcm-url");
  rt::RealtimeOptions rt_opt;
  rt::add_options(cli, rt_opt);
  CLI11_PARSE(cli, argc, argv);
  if (direct_rx && (actuator_url.empty() || ground_url.empty())) {
    std::fprintf(stderr,
                 "rocksteady-plant: --direct-rx needs --actuator-lcm-url and --ground-lcm-url\n");
    return 2;
  }
  if (mission_path.empty()) mission_path = config_dir + "/mission.yaml";
  if (gnc_path.empty()) gnc_path = config_dir + "/gnc.yaml";

  config::RunSetup setup;
  try {
    setup = config::load_run(mission_path, gnc_path, case_file(config_dir, case_arg));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rocksteady-plant: %s\n", e.what());
    return 2;
  }
  if (cli.count("--valve-timeout") > 0 || setup.truth.command_timeout_s == 0.0) {
    if (!(valve_timeout_s >= 0.0) || !std::isfinite(valve_timeout_s)) {
      std::fprintf(stderr, "rocksteady-plant: --valve-timeout must be >= 0\n");
      return 2;
    }
    setup.truth.command_timeout_s = valve_timeout_s;
  }
  plant::Plant plant(setup.truth);
  const double dt = setup.truth.control_period_s;
  const double run_s = duration >= 0.0 ? duration : setup.duration_s;
  const auto n_ticks = static_cast<std::uint64_t>(std::llround(run_s / dt));
  const Eigen::Vector3d q_final = setup.flight.guidance.q_final;
  const bool lockstep = mode == "lockstep";

  std::ofstream csv;
  std::uint64_t csv_every = 0;
  if (!out_csv.empty()) {
    csv.open(out_csv);
    if (!csv) {
      std::fprintf(stderr, "rocksteady-plant: cannot write %s\n", out_csv.c_str());
      return 2;
    }
    csv << "t_s,omega_x,omega_y,omega_z,q_x,q_y,q_z,fuel_kg,u0,u1,u2,u3,u4,u5,u6,u7\n";
    csv.precision(17);
    csv_every = std::max<std::uint64_t>(1, static_cast<std::uint64_t>(std::llround(log_interval_s / dt)));
  }
  auto write_row = [&]() {
    if (!csv.is_open()) return;
    csv << plant.t();
    for (int i = 0; i < 3; ++i) csv << ',' << plant.omega()(i);
    const plant::Vec3 q = plant.mrp();
    for (int i = 0; i < 3; ++i) csv << ',' << q(i);
    csv << ',' << plant.fuel_kg();
    for (int i = 0; i < 8; ++i) csv << ',' << plant.applied_force()(i);
    csv << '\n';
  };

  // Real-time hardening (meant for --mode realtime) before the bus is opened.
  if (const int rc = rt::apply_and_report(rt_opt, "rocksteady-plant", stdout); rc != 0) return rc;

  Bus bus;
  bus.lcm = lcm_create(lcm_url.empty() ? nullptr : lcm_url.c_str());
  if (bus.lcm == nullptr) {
    std::fprintf(stderr, "rocksteady-plant: cannot open the LCM bus\n");
    return 3;
  }
  if (!ground_url.empty()) {
    bus.ground = lcm_create(ground_url.c_str());
    if (bus.ground == nullptr) {
      std::fprintf(stderr, "rocksteady-plant: cannot open the ground bus %s\n", ground_url.c_str());
      return 3;
    }
  }
  if (!actuator_url.empty()) {
    bus.actuator = lcm_create(actuator_url.c_str());
    if (bus.actuator == nullptr) {
      std::fprintf(stderr, "rocksteady-plant: cannot open the actuator bus %s\n",
                   actuator_url.c_str());
      return 3;
    }
  }
  rt::UdpmReceiver direct;
  if (direct_rx) {
    if (!direct.open(actuator_url)) {
      std::fprintf(stderr, "rocksteady-plant: --direct-rx: %s\n", direct.error().c_str());
      return 3;
    }
    bus.direct = &direct;
  } else {
    lcm_subscribe(bus.command_bus(), channels::kThrusterCmd, &Bus::on_cmd, &bus);
  }
  lcm_subscribe(bus.ground_bus(), channels::kGncTelemetry, &Bus::on_tlm, &bus);
  lcm_subscribe(bus.ground_bus(), channels::kPlantFault, &Bus::on_fault, &bus);
  bus.fault_queue.reserve(64);
  std::uint64_t faults_accepted = 0, faults_rejected = 0, driver_timeouts = 0;
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);

  merit::ConvergenceTracker omega_conv(setup.omega_tol_rad_s);
  merit::ConvergenceTracker q_conv(setup.q_tol);
  omega_conv.add(0.0, plant.omega().norm(), 0.0);
  q_conv.add(0.0, merit::attitude_error(plant.mrp(), q_final), 0.0);
  double max_rate = plant.omega().norm();

  std::uint64_t timeouts = 0, resends = 0, holds = 0, stale = 0, wiring_mismatch = 0, applied = 0;
  std::uint64_t fresh_periods = 0;
  bool started = !lockstep;
  bool bus_error = false;
  hal::ThrusterOutputs thrusters{};  // held over each period (zero-order hold)
  const auto timeout_ns = static_cast<std::int64_t>(timeout_ms * 1e6);  // ms -> ns
  const auto period_ns = static_cast<std::int64_t>(std::llround(dt * static_cast<double>(kNsPerS)));
  bus.event(rocksteady::event_t::SEV_INFO, kRunStarted, 0, 0, 0.0,
            "plant run started: " + setup.case_name + " (" + mode + ")");
  if (verbose) {
    std::printf("rocksteady-plant: %s, %s, %.6g s in %" PRIu64 " periods\n", setup.case_name.c_str(),
                mode.c_str(), run_s, n_ticks);
    std::fflush(stdout);
  }

  const auto wall0 = std::chrono::steady_clock::now();
  std::int64_t last_progress = now_ns();
  const std::int64_t rt_start = now_ns();
  std::uint64_t k = 0;
  for (; k < n_ticks && g_stop == 0; ++k) {
    const rocksteady::sensor_frame_t frame = wire::to_message(plant.read_sensors());
    bus.publish(channels::kSensors, frame);
    if (truth_every > 0 && k % truth_every == 0) {
      bus.publish(channels::kPlantTruth, make_truth(static_cast<std::int64_t>(k), plant),
                  bus.ground_bus());
    }
    if (csv_every != 0 && k % csv_every == 0) write_row();

    if (lockstep) {
      // Wait for the command echoing k.
      bool got = false;
      int attempts = 0;
      std::int64_t deadline = now_ns() + timeout_ns;
      const std::int64_t startup_deadline =
          now_ns() + static_cast<std::int64_t>(startup_timeout_s * static_cast<double>(kNsPerS));
      bus.have_cmd = false;
      while (!got && g_stop == 0) {
        if (!bus.wait_once(deadline)) {
          bus_error = true;
          break;
        }
        if (bus.have_cmd) {
          bus.have_cmd = false;
          if (bus.latest.seq == static_cast<std::int64_t>(k)) {
            got = true;
            break;
          }
          ++stale;  // an answer to an older frame (e.g. to a resend)
          continue;
        }
        if (now_ns() < deadline) continue;
        if (!started) {  // the flight software is not up yet: keep offering frame 0
          if (now_ns() >= startup_deadline) break;
          bus.publish(channels::kSensors, frame);
          deadline = now_ns() + timeout_ns;
          continue;
        }
        ++timeouts;
        if (timeouts == 1 || timeouts % 100 == 0) {
          bus.event(rocksteady::event_t::SEV_WARNING, kEchoTimeout, static_cast<std::int32_t>(k),
                    static_cast<std::int32_t>(timeouts), plant.t(),
                    "no thruster command echoing the frame within the timeout");
        }
        if (attempts++ < retries) {
          ++resends;
          bus.publish(channels::kSensors, frame);
          deadline = now_ns() + timeout_ns;
          continue;
        }
        break;  // hold the previous command
      }
      if (bus_error) break;
      if (!started && !got) {
        std::fprintf(stderr,
                     "rocksteady-plant: no answer from the flight software within %.3g s\n",
                     startup_timeout_s);
        lcm_destroy(bus.lcm);
        return 4;
      }
      started = true;
      if (got) {
        thrusters = wire::to_outputs(bus.latest);
        plant.receive(thrusters);
        const plant::Vec8 from_thrusters = plant::Plant::channel_forces(thrusters);
        for (int i = 0; i < 8; ++i) {
          if (std::fabs(from_thrusters(i) - bus.latest.channel_force[i]) >
              1e-9 * (1.0 + std::fabs(from_thrusters(i)))) {
            ++wiring_mismatch;
            break;
          }
        }
        ++applied;
      } else if (g_stop == 0) {
        ++holds;
      }
    } else {
      // Real time: serve the bus until the next period, then apply the newest command.
      const std::int64_t deadline = rt_start + static_cast<std::int64_t>(k + 1) * period_ns;
      bus.have_cmd = false;
      bool fresh = false;
      while (g_stop == 0 && now_ns() < deadline) {
        if (!bus.wait_once(deadline)) {
          bus_error = true;
          break;
        }
        if (bus.have_cmd) {
          bus.have_cmd = false;
          thrusters = wire::to_outputs(bus.latest);
          plant.receive(thrusters);
          ++applied;
          if (bus.latest.seq == static_cast<std::int64_t>(k)) fresh = true;
        }
      }
      if (bus_error) break;
      if (fresh) {
        ++fresh_periods;
      } else {
        ++holds;
      }
    }
    if (g_stop != 0) break;

    // Fault injection between periods: the next period has it.
    for (const rocksteady::plant_fault_cmd_t& c : bus.fault_queue) {
      const std::string why = apply_fault_command(c, plant);
      if (why.empty()) {
        ++faults_accepted;
        bus.event(rocksteady::event_t::SEV_INFO, kFaultAccepted, c.thruster, c.fault_kind, plant.t(),
                  "plant fault command seq " + std::to_string(c.seq) + " applied: " +
                      plant::describe(plant.faults()));
      } else {
        ++faults_rejected;
        bus.event(rocksteady::event_t::SEV_WARNING, kFaultRejected, c.thruster, c.op, plant.t(),
                  "plant fault command seq " + std::to_string(c.seq) + " rejected: " + why);
      }
    }
    bus.fault_queue.clear();

    const bool was_timed_out = plant.command_timed_out();
    plant.advance();  // the command last received, through the valve driver
    if (plant.command_timed_out() && !was_timed_out) {
      ++driver_timeouts;
      bus.event(rocksteady::event_t::SEV_WARNING, kValveDriverTimeout, static_cast<std::int32_t>(k), 0,
                plant.t(), "valve driver: no thruster command, every thruster off");
    }
    const double w = plant.omega().norm();
    const double t = plant.t();
    omega_conv.add(t, w, plant.fuel_kg());
    q_conv.add(t, merit::attitude_error(plant.mrp(), q_final), plant.fuel_kg());
    max_rate = std::max(max_rate, w);
    if (verbose && now_ns() - last_progress >= kNsPerS) {
      last_progress = now_ns();
      std::printf("plant: t=%.1f s |omega|=%.3e rad/s fuel=%.3f kg timeouts=%" PRIu64 "\n", t, w,
                  plant.fuel_kg(), timeouts);
      std::fflush(stdout);
    }
  }
  // Drain what is still in flight (the telemetry of the last frame) for the summary.
  const std::int64_t drain_until = now_ns() + 50000000;
  while (now_ns() < drain_until && bus.wait_once(drain_until)) {
  }
  if (csv_every != 0) write_row();
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  bus.event(rocksteady::event_t::SEV_INFO, kRunFinished, static_cast<std::int32_t>(timeouts),
            static_cast<std::int32_t>(holds), plant.t(), "plant run finished");

  if (summary) {
    rusage ru{};
    getrusage(RUSAGE_SELF, &ru);  // every thread: the loop and LCM's receive threads
    const double cpu_s = static_cast<double>(ru.ru_utime.tv_sec + ru.ru_stime.tv_sec) +
                         static_cast<double>(ru.ru_utime.tv_usec + ru.ru_stime.tv_usec) * 1e-6;
    const long ctx = ru.ru_nvcsw + ru.ru_nivcsw;
    const double ticks_per_s = wall > 0.0 ? static_cast<double>(plant.ticks()) / wall : 0.0;
    const char* mode_name = bus.last_mode >= 0 && bus.last_mode < gnc::kModeCount
                                ? gnc::to_string(static_cast<gnc::Mode>(bus.last_mode))
                                : "?";
    std::printf("%s over LCM (%s): %.6g s simulated in %.2f s wall, %.0f periods/s\n",
                setup.case_name.c_str(), mode.c_str(), plant.t(), wall, ticks_per_s);
    std::printf("  t_omega,conv        %s\n", fmt_opt(omega_conv.time(), "s", 1).c_str());
    std::printf("  fuel at t_omega     %s\n", fmt_opt(omega_conv.fuel_kg(), "kg", 3).c_str());
    std::printf("  t_q,conv            %s\n", fmt_opt(q_conv.time(), "s", 1).c_str());
    std::printf("  fuel at t_q         %s\n", fmt_opt(q_conv.fuel_kg(), "kg", 3).c_str());
    std::printf("  total fuel          %.3f kg (flight estimate %.3f kg)\n", plant.fuel_kg(),
                bus.fuel_hat);
    std::printf("  max |omega|         %.5f rad/s, final %.3e rad/s, final |q - q_final| %.3e\n",
                max_rate, plant.omega().norm(), merit::attitude_error(plant.mrp(), q_final));
    std::printf("  flight mode (last telemetry) %s\n", mode_name);
    std::printf("  bus: commands %" PRIu64 " applied %" PRIu64 ", echo timeouts %" PRIu64
                ", resends %" PRIu64 ", held periods %" PRIu64 ", stale %" PRIu64
                ", rx rejected %" PRIu64 ", thruster/channel mismatches %" PRIu64 "\n",
                bus.commands, applied, timeouts, resends, holds, stale, bus.rx.rejected(),
                wiring_mismatch);
    std::printf("  faults: %s; commands accepted %" PRIu64 ", rejected %" PRIu64
                ", malformed %" PRIu64 "; valve-driver timeouts %" PRIu64 " (%" PRIu64
                " periods off)\n",
                plant::describe(plant.faults()).c_str(), faults_accepted, faults_rejected,
                bus.fault_rx.rejected(), driver_timeouts, plant.timeout_periods());
    std::printf("summary: case=%d mode=%s periods=%" PRIu64
                " t_omega=%s fuel_omega=%s t_q=%s "
                "fuel_q=%s total_fuel=%.17g final_rate=%.17g final_q_error=%.17g flight_mode=%s "
                "timeouts=%" PRIu64 " resends=%" PRIu64 " holds=%" PRIu64 " rx_rejected=%" PRIu64
                " fresh=%" PRIu64 " wall_s=%.3f cpu_s=%.3f ctx=%ld\n",
                setup.case_number, mode.c_str(), plant.ticks(), exact(omega_conv.time()).c_str(),
                exact(omega_conv.fuel_kg()).c_str(), exact(q_conv.time()).c_str(),
                exact(q_conv.fuel_kg()).c_str(), plant.fuel_kg(), plant.omega().norm(),
                merit::attitude_error(plant.mrp(), q_final), mode_name, timeouts, resends, holds,
                bus.rx.rejected(), fresh_periods, wall, cpu_s, ctx);
    std::fflush(stdout);
  }
  lcm_destroy(bus.lcm);
  if (bus.ground != nullptr) lcm_destroy(bus.ground);
  if (bus.actuator != nullptr) lcm_destroy(bus.actuator);
  return bus_error ? 1 : 0;
}
