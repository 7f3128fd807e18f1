// rocksteady-planner: the on-line re-planner as a process. It listens on the bus for the flight
// software's telemetry (RS_GNC_TLM: the state estimate, the identified model), re-plans Eq. (44)
// from the current state on the policy of ground/planner/replanner.hpp (warm-started from the rest of
// the plan being flown, self-verified), and uplinks each plan through the same authenticated,
// chunked, CRC-checked path as `rocksteady-ground send upload-trajectory` (upload_chunks, then
// LOAD_TRAJECTORY; the first plan also selects the fuel-optimal reference, which requests TRACK).
// The flight switches tables at a tick boundary (trajectory_switched) or refuses a stale one
// (trajectory_stale: the re-planner keeps the plan it had).
//
// Time is the flight's telemetry time: a plan made from the telemetry at t is uplinked no earlier
// than the first telemetry at t + latency. The latency must cover the solve and the uplink.
//
//   rocksteady-planner --key-file keys --case 1 --latency 30 --period 600
//
// Exit status: 0 done (limit reached or signal), 1 the bus or a plan delivery failed hard, 2 usage
// or configuration error.
#include <lcm/lcm-cpp.hpp>

#include <atomic>
#include <chrono>
#include <cmath>
#include <optional>
#include <csignal>
#include <cstdio>
#include <deque>
#include <exception>
#include <memory>
#include <string>

#include <CLI/CLI.hpp>

#include "ground/cli/bus.hpp"
#include "ground/cli/commands.hpp"
#include "ground/cli/ground_auth.hpp"
#include "ground/cli/sequence_store.hpp"
#include "ground/config/config.hpp"
#include "ground/config/config_dir.hpp"
#include "ground/planner/replanner.hpp"
#include "lcmtypes/channels.hpp"
#include "rocksteady/event_t.hpp"
#include "rocksteady/gnc_telemetry_t.hpp"
#include "wire/codec.hpp"

namespace cli = rocksteady::ground::cli;
namespace planner = rocksteady::ground::planner;
namespace gnc = rocksteady::gnc;

namespace {

std::atomic<bool> g_stop{false};
void on_signal(int) { g_stop = true; }

// Event ids as the bus carries them (fsw/interface.hpp).
constexpr std::int32_t kEvTrajectorySwitched = 137;
constexpr std::int32_t kEvTrajectoryStale = 138;

// The fields of the telemetry the re-planner reads.
gnc::GncTelemetry from_bus(const rocksteady::gnc_telemetry_t& m) {
  gnc::GncTelemetry t;
  t.t = m.t;
  t.mode = static_cast<gnc::Mode>(m.mode);
  t.omega_hat = gnc::Vec3(m.omega_hat[0], m.omega_hat[1], m.omega_hat[2]);
  // The reference's phase and attitude: momentum tracking's rates (Replanner::aimed_rate).
  t.phase = static_cast<gnc::ReferencePhase>(m.phase);
  t.q_hat = gnc::Vec3(m.q_hat[0], m.q_hat[1], m.q_hat[2]);
  t.q_d = gnc::Vec3(m.q_d[0], m.q_d[1], m.q_d[2]);
  t.alloc.torque_achieved =
      gnc::Vec3(m.torque_achieved[0], m.torque_achieved[1], m.torque_achieved[2]);
  t.est.identifying = m.identifying;
  for (int i = 0; i < 6; ++i) t.est.j(i) = m.id_j[i];
  for (int i = 0; i < 3; ++i) t.est.r(i) = m.id_r[i];
  for (int i = 0; i < 16; ++i) t.est.k(i) = m.id_k[i];
  t.est.inertia_confident = m.id_inertia_confident;
  t.est.offset_confident = m.id_offset_confident;
  t.est.thruster_confident = static_cast<std::uint16_t>(m.id_thruster_confident & 0xffff);
  t.est.adoptions = static_cast<std::uint32_t>(m.model_adoptions < 0 ? 0 : m.model_adoptions);
  return t;
}

struct Listener {
  std::deque<gnc::GncTelemetry> tlm;  // received, not yet handed to the re-planner
  rocksteady::wire::RxCounters rx{};
  std::uint64_t dropped{0};
  int switched{0};
  int stale{0};
  std::uint64_t forged_events{0};

  void on_tlm(const lcm::ReceiveBuffer* rbuf, const std::string&) {
    rocksteady::gnc_telemetry_t m;
    if (!rocksteady::wire::safe_decode(rbuf->data, static_cast<int>(rbuf->data_size), m, &rx)) {
      return;  // malformed: counted, ignored
    }
    if (!std::isfinite(m.t) || m.mode < 0 || m.mode > 4) return;
    tlm.push_back(from_bus(m));
    if (tlm.size() > 4096) {  // a long solve: keep the newest
      tlm.pop_front();
      ++dropped;
    }
  }
  void on_event(const lcm::ReceiveBuffer* rbuf, const std::string&) {
    rocksteady::event_t e;
    if (!rocksteady::wire::safe_decode(rbuf->data, static_cast<int>(rbuf->data_size), e, &rx)) {
      return;
    }
    if (e.id != kEvTrajectorySwitched && e.id != kEvTrajectoryStale) return;
    if (cli::verify_event(e) == cli::AckAuth::kForged) {
      ++forged_events;
      return;
    }
    if (e.id == kEvTrajectorySwitched) ++switched;
    if (e.id == kEvTrajectoryStale) ++stale;
  }
};

// One command, signed, and its authentic acknowledgement. "" or why not.
std::string command(lcm::LCM& lcm, const std::string& word, const std::vector<std::string>& args,
                    const std::string& state_dir, std::int32_t sender, double timeout_s) {
  const cli::Encoded e = cli::encode_command(word, args);
  if (!e.ok) return e.error;
  rocksteady::ground_cmd_t cmd = e.cmd;
  cli::stamp(cmd, cli::next_counter(state_dir, sender), sender);
  const cli::SendResult r = cli::send_and_wait(lcm, cmd, timeout_s);
  switch (r.outcome) {
    case cli::SendResult::Outcome::kAccepted: return "";
    case cli::SendResult::Outcome::kRejected: return e.description + " rejected: " + r.ack.text;
    case cli::SendResult::Outcome::kTimeout: return e.description + ": no acknowledgement";
    case cli::SendResult::Outcome::kForged: return e.description + ": forged acknowledgements only";
    case cli::SendResult::Outcome::kError: return e.description + ": " + r.error;
  }
  return "?";
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Rocksteady on-line re-planner: plans from the flight's telemetry, uplinks the plans"};
  app.footer("Exit status: 0 done, 1 the bus failed, 2 usage or configuration error.");
  std::string url;
  std::string config_dir_arg, mission, gnc_file, case_arg = "1";
  std::string law = "ntcl";
  cli::AuthOptions auth;
  std::string state_dir;
  std::int32_t sender = 3;
  double ack_timeout = 3.0;
  double duration = -1.0;
  int exit_after_switches = -1;
  std::int32_t first_upload_id = 1000;
  planner::ReplanPolicy pol;
  app.add_option("--lcm-url", url, "LCM URL (default: $LCM_DEFAULT_URL or LCM's default)");
  app.add_option("--config-dir", config_dir_arg, "folder with mission.yaml, gnc.yaml, cases/");
  app.add_option("--mission", mission, "mission file (default <config-dir>/mission.yaml)");
  app.add_option("--gnc", gnc_file, "GNC file (default <config-dir>/gnc.yaml): the flight's table");
  app.add_option("--case", case_arg, "case number or case file (the flight's estimates)")
      ->capture_default_str();
  app.add_option("--law", law, "the tracking law the first plan selects")->capture_default_str();
  app.add_option("--key-file", auth.key_file, "command keys (mode 0600; default $ROCKSTEADY_KEY_FILE)");
  app.add_option("--key-id", auth.key_id, "the key that signs (default: the lowest id)");
  app.add_flag("--lab", auth.lab, "the flight runs with --lab-mode: nothing is signed");
  app.add_option("--state-dir", state_dir, "counter state directory (default: the ground's)");
  app.add_option("--sender", sender, "sender id")->capture_default_str();
  app.add_option("--ack-timeout", ack_timeout, "seconds to wait for each acknowledgement")
      ->capture_default_str();
  app.add_option("--latency", pol.latency_s,
                 "planning latency, s of flight time: a plan from the telemetry at t is uplinked "
                 "no earlier than t + latency (must cover the solve and the uplink)")
      ->capture_default_str();
  app.add_option("--first-plan", pol.first_plan_s, "identify at least this long, s")
      ->capture_default_str();
  app.add_option("--first-plan-max", pol.first_plan_max_s,
                 "first plan by then even without a confident model, s")
      ->capture_default_str();
  app.add_option("--period", pol.period_s, "periodic re-plan, s (0: off)")->capture_default_str();
  app.add_option("--min-interval", pol.min_interval_s, "between two plans, s")->capture_default_str();
  app.add_option("--error-fraction", pol.error_fraction, "tracking-error trigger (0: off)")
      ->capture_default_str();
  app.add_option("--horizon-factor", pol.horizon_factor,
                 "horizon, shortest despins (0: automatic, 16 when the gnc file's "
                 "guidance.track_momentum_k > 0, else 8)")
      ->capture_default_str();
  app.add_option("--min-horizon", pol.min_horizon_s, "shortest horizon, s")->capture_default_str();
  app.add_option("--max-plans", pol.max_plans, "plans at most")->capture_default_str();
  app.add_option("--adopt-wait", pol.adopt_wait_s,
                 "a confident identified model the flight does not fly yet: wait at most this long "
                 "for its adoption before planning for it, s (0: off)")
      ->capture_default_str();
  app.add_option("--adopt-settle", pol.adopt_settle_tau,
                 "after the flight adopts a model, no plan for this many time constants of its "
                 "rate stage (the rate estimate relaxes to the new model; 0: off)")
      ->capture_default_str();
  app.add_option("--first-upload-id", first_upload_id, "upload id of the first plan")
      ->capture_default_str();
  app.add_option("--duration", duration, "exit after this many wall seconds (< 0: never)");
  app.add_option("--exit-after-switches", exit_after_switches,
                 "exit once the flight switched this many re-plans in during TRACK (< 0: never)");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int rc = app.exit(e);
    return rc == 0 ? 0 : 2;
  }
  if (pol.latency_s < 0.0 || pol.first_plan_max_s < pol.first_plan_s) {
    std::fprintf(stderr, "rocksteady-planner: --latency must be >= 0 and --first-plan-max >= "
                         "--first-plan\n");
    return 2;
  }

  rocksteady::config::RunSetup setup;
  try {
    const rocksteady::config::ConfigDir dir = rocksteady::config::find_config_dir(config_dir_arg);
    if (mission.empty()) mission = dir.path + "/mission.yaml";
    if (gnc_file.empty()) gnc_file = dir.path + "/gnc.yaml";
    const std::string case_file = case_arg.find_first_not_of("0123456789") == std::string::npos
                                      ? dir.path + "/cases/case" + case_arg + ".yaml"
                                      : case_arg;
    setup = rocksteady::config::load_run(mission, gnc_file, case_file);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rocksteady-planner: configuration error: %s\n", e.what());
    return 2;
  }
  bool law_ok = false;
  for (int i = 0; i < gnc::kLawCount; ++i) {
    if (law == gnc::to_string(static_cast<gnc::LawId>(i)) && i != static_cast<int>(gnc::LawId::kDpd)) {
      setup.flight.law = static_cast<gnc::LawId>(i);
      law_ok = true;
    }
  }
  if (!law_ok) {
    std::fprintf(stderr, "rocksteady-planner: --law: '%s' is not a tracking law\n", law.c_str());
    return 2;
  }
  if (const std::string err = cli::configure_auth(auth); !err.empty()) {
    std::fprintf(stderr, "rocksteady-planner: %s\n", err.c_str());
    return 2;
  }
  if (state_dir.empty()) state_dir = cli::default_state_dir();

  lcm::LCM lcm(url);
  if (!lcm.good()) {
    std::fprintf(stderr, "rocksteady-planner: cannot open the bus\n");
    return 1;
  }
  Listener listener;
  lcm.subscribe(rocksteady::channels::kGncTelemetry, &Listener::on_tlm, &listener);
  lcm.subscribe(rocksteady::channels::kEvents, &Listener::on_event, &listener);
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);

  planner::Replanner rp(setup.flight, pol, first_upload_id);
  std::printf("rocksteady-planner: %s, law %s, latency %.1f s, first plan after %.0f s (by %.0f s), "
              "period %.0f s, %s\n",
              setup.case_name.c_str(), law.c_str(), pol.latency_s, pol.first_plan_s,
              pol.first_plan_max_s, pol.period_s, cli::auth_lab_mode() ? "lab mode" : "signed");
  std::fflush(stdout);
  const auto start = std::chrono::steady_clock::now();
  int stale_seen = 0;
  std::size_t records_seen = 0;
  int failures = 0;
  while (!g_stop) {
    if (duration >= 0.0 &&
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() > duration) {
      break;
    }
    if (exit_after_switches >= 0 && listener.switched >= exit_after_switches) break;
    lcm.handleTimeout(100);
    if (listener.stale > stale_seen) {
      stale_seen = listener.stale;
      rp.refused("trajectory_stale at the switch");
      std::printf("flight refused the plan as stale; the previous plan stays the reference\n");
    }
    while (!listener.tlm.empty() && !g_stop) {
      const gnc::GncTelemetry tl = listener.tlm.front();
      listener.tlm.pop_front();
      const std::optional<planner::Delivery> d = rp.update(tl);
      for (; records_seen < rp.records().size(); ++records_seen) {
        const planner::ReplanRecord& r = rp.records()[records_seen];
        std::printf("plan %s from t=%.1f s (%s model): %s%s, %.3f kg over %.0f s, %d nodes, "
                    "%.2f s to solve, due t=%.1f s\n",
                    planner::to_string(r.trigger), r.t_state, r.identified ? "identified" : "table",
                    r.ok ? "ok" : "failed: ", r.ok ? "" : r.error.c_str(), r.fuel_kg, r.t_final,
                    r.nodes, r.wall_s, r.t_due);
        std::fflush(stdout);
      }
      if (!d) continue;
      // The uplink: exactly the operator console's procedure.
      cli::UploadOptions up;
      up.upload_id = d->upload_id;
      up.state_dir = state_dir;
      up.sender = sender;
      const cli::UploadResult u = cli::upload_chunks(lcm, *d->table, up, stderr);
      std::string why;
      if (!u.complete) {
        why = "uplink incomplete: " + u.message;
        command(lcm, "abort-uplink", {std::to_string(d->upload_id)}, state_dir, sender,
                ack_timeout);
      } else {
        why = command(lcm, "load-trajectory", {std::to_string(d->upload_id)}, state_dir, sender,
                      ack_timeout);
        if (why.empty() && d->first) {
          why = command(lcm, "select-law", {law, "fuel-optimal"}, state_dir, sender, ack_timeout);
        }
      }
      if (!why.empty()) {
        ++failures;
        rp.refused(why);
        std::printf("delivery of upload %d failed: %s\n", d->upload_id, why.c_str());
      } else {
        std::printf("delivered upload %d at t=%.1f s (planned from t=%.1f s)%s\n", d->upload_id,
                    tl.t, d->t_state, d->first ? ", TRACK requested" : "");
      }
      std::fflush(stdout);
      listener.tlm.clear();  // the uplink took bus time: continue from fresh telemetry
    }
  }
  std::printf("rocksteady-planner exit: plans=%zu delivered=%d switched=%d stale=%d "
              "delivery_failures=%d telemetry_dropped=%llu malformed=%llu forged_events=%llu\n",
              rp.records().size(), rp.plans_delivered(), listener.switched, listener.stale,
              failures, static_cast<unsigned long long>(listener.dropped),
              static_cast<unsigned long long>(listener.rx.rejected()),
              static_cast<unsigned long long>(listener.forged_events));
  return 0;
}
