// rocksteady-ground: the operator's console. Subcommands:
//   send <command> [args...]   one command, waits for its acknowledgement (exit 0 accepted,
//                              1 rejected, 2 timeout or usage error)
//   monitor                    live telemetry, events and acknowledgements
//   log2csv LOG --channel CH   one channel of an LCM log as CSV
//   params                     the loadable parameters (set-gain)
// See ground/cli/README.md.
#include <unistd.h>
#include <CLI/CLI.hpp>

#include <algorithm>
#include <array>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

#include <lcm/lcm-cpp.hpp>

#include "gnc/model/mass_properties.hpp"
#include "gnc/model/rcs.hpp"
#include "ground/cli/bus.hpp"
#include "ground/cli/commands.hpp"
#include "ground/cli/ground_auth.hpp"
#include "fsw/auth/key_file.hpp"
#include "ground/cli/csv.hpp"
#include "ground/cli/dictionary.hpp"
#include "ground/cli/plot.hpp"
#include "ground/cli/sequence.hpp"
#include "ground/cli/sequence_store.hpp"
#include "ground/cli/trajectory_input.hpp"
#include "ground/planner/planner.hpp"
#include "wire/uplink.hpp"
#ifdef ROCKSTEADY_GROUND_CLI_WITH_CONFIG
#include "ground/config/config.hpp"
#include "ground/config/config_dir.hpp"
#endif
#ifdef ROCKSTEADY_GROUND_CLI_WITH_CONSOLE
#include "ground/console/server.hpp"
#endif

namespace cli = rocksteady::ground::cli;
namespace planner = rocksteady::ground::planner;

namespace {

struct SendArgs {
  std::string command;
  std::vector<std::string> args;
  bool quat{false};
  long long seq{0};  // 0: the next number from the state file
  int sender{1};
  double timeout{3.0};
  std::string state_dir;
  bool dry_run{false};
  // upload-trajectory
  long long upload_id{-1};
  bool no_load{false};
  double chunk_interval{0.02};
  double wait{5.0};
  int passes{3};
  bool file_model{false};
  double u_max{200.0};
  double delta_j{0.0};
  double delta_r{0.0};
  std::string mission, gnc, case_file, config_dir;
};

// The sequence number of the next command: --seq (recorded in the state file when there is one), or
// the next number from the state file.
class SeqSource {
 public:
  explicit SeqSource(const SendArgs& a) : fixed_(a.seq), dry_run_(a.dry_run), sender_(a.sender) {
    dir_ = a.state_dir.empty() ? cli::default_state_dir() : a.state_dir;
    if (!dir_.empty()) path_ = cli::sequence_file(dir_, a.sender);
  }
  const std::string& dir() const { return dir_; }
  std::int64_t next() {
    // With a command key: the key's counter (unless --seq), never a dry-run peek.
    if (fixed_ <= 0 && !dry_run_ && !cli::auth_lab_mode()) return cli::next_counter(dir_, sender_);
    if (fixed_ > 0) {
      const std::int64_t s = fixed_++;
      if (!path_.empty() && !dry_run_) {
        try {
          if (cli::auth_lab_mode()) {
            cli::SequenceStore(path_).next(s);
          } else {
            cli::next_counter(dir_, sender_, s);  // the key's counter follows it
          }
        } catch (const std::exception&) {
          // --seq works without a usable state file
        }
      }
      return s;
    }
    if (path_.empty()) {
      throw std::runtime_error("no state directory ($XDG_STATE_HOME or $HOME): give --seq");
    }
    // A dry run shows the number a send would take, and reserves nothing.
    if (dry_run_) return cli::SequenceStore(path_).last() + 1 + peeked_++;
    return cli::SequenceStore(path_).next();
  }

 private:
  std::int64_t fixed_;
  bool dry_run_;
  std::int32_t sender_;
  std::int64_t peeked_{0};
  std::string dir_;
  std::string path_;
};

std::unique_ptr<lcm::LCM> open_bus(const std::string& url) {
  auto lcm = std::make_unique<lcm::LCM>(url);
  if (!lcm->good()) {
    throw std::runtime_error("cannot open the LCM bus" + (url.empty() ? std::string() : " " + url));
  }
  return lcm;
}

void print_hint(const rocksteady::cmd_ack_t& ack) {
  if (ack.accepted == 0 && ack.reason == rocksteady::cmd_ack_t::REASON_NOT_AUTHENTICATED) {
    std::fprintf(stderr,
                 "hint: the flight did not accept this key; its active key id is %d (give "
                 "--key-id %d if the key file has it)\n",
                 ack.key_id, ack.key_id);
  }
  if (ack.accepted == 0 && ack.reason == rocksteady::cmd_ack_t::REASON_STALE_SEQUENCE) {
    std::fprintf(stderr,
                 "hint: the flight has accepted a higher sequence number from sender %d; give "
                 "--seq above the 'last seq' the monitor shows (the state file follows it)\n",
                 ack.sender_id);
  }
}

// Sends one encoded command and prints its verdict; returns the exit code.
int send_one(lcm::LCM* lcm, rocksteady::ground_cmd_t cmd, const std::string& description,
             SeqSource& seqs, const SendArgs& a) {
  cli::stamp(cmd, seqs.next(), a.sender);
  std::fprintf(stderr, "%s seq %lld sender %d\n", description.c_str(),
               static_cast<long long>(cmd.seq), a.sender);
  if (a.dry_run || lcm == nullptr) {
    std::printf("DRY RUN: opcode %d nargs %d args", cmd.opcode, cmd.nargs);
    for (int i = 0; i < cmd.nargs; ++i) std::printf(" %.17g", cmd.args[i]);
    std::printf("\n");
    return cli::kExitAccepted;
  }
  const cli::SendResult r = cli::send_and_wait(*lcm, cmd, a.timeout);
  switch (r.outcome) {
    case cli::SendResult::Outcome::kAccepted:
    case cli::SendResult::Outcome::kRejected:
      std::printf("%s\n", cli::format_ack_verdict(r.ack).c_str());
      print_hint(r.ack);
      break;
    case cli::SendResult::Outcome::kTimeout:
      std::printf("TIMEOUT: no acknowledgement of seq %lld within %g s\n",
                  static_cast<long long>(cmd.seq), a.timeout);
      break;
    case cli::SendResult::Outcome::kError:
      std::printf("ERROR: %s\n", r.error.c_str());
      break;
    case cli::SendResult::Outcome::kForged:
      std::printf("FORGED: %llu acknowledgement(s) of seq %lld failed authentication; no authentic "
                  "acknowledgement within %g s\n",
                  static_cast<unsigned long long>(r.forged_acks), static_cast<long long>(cmd.seq),
                  a.timeout);
      break;
  }
  if (r.forged_acks > 0 && r.outcome != cli::SendResult::Outcome::kForged) {
    std::fprintf(stderr, "warning: %llu forged acknowledgement(s) of this command ignored\n",
                 static_cast<unsigned long long>(r.forged_acks));
  }
  if (r.lab_mode && (r.outcome == cli::SendResult::Outcome::kAccepted ||
                     r.outcome == cli::SendResult::Outcome::kRejected)) {
    std::fprintf(stderr, "note: lab mode: the acknowledgement is not authenticated\n");
  }
  if (r.rx.rejected() > 0) {
    std::fprintf(stderr, "note: %s acknowledgement messages\n",
                 cli::describe_rejections(r.rx).c_str());
  }
  std::fflush(stdout);
  return r.exit_code();
}

planner::PlanModel expected_model(const SendArgs& a) {
  if (!a.mission.empty() || !a.gnc.empty() || !a.case_file.empty()) {
#ifdef ROCKSTEADY_GROUND_CLI_WITH_CONFIG
    if (a.case_file.empty()) {
      throw std::runtime_error(std::string(a.mission.empty() ? "--gnc" : "--mission") +
                               " needs --case (the case whose model the plan must match)");
    }
    std::string dir;
    if (a.mission.empty() || a.gnc.empty() ||
        std::all_of(a.case_file.begin(), a.case_file.end(), ::isdigit)) {
      const rocksteady::config::ConfigDir d = rocksteady::config::find_config_dir(a.config_dir);
      if (d.path.empty()) throw std::runtime_error(d.error);
      dir = d.path;
    }
    const std::string case_path = rocksteady::config::case_file(dir, a.case_file, "--case");
    const auto mission = rocksteady::config::load_mission(
        a.mission.empty() ? rocksteady::config::mission_file(dir) : a.mission);
    const auto run = rocksteady::config::assemble(
        mission,
        rocksteady::config::load_gnc(a.gnc.empty() ? rocksteady::config::gnc_file(dir) : a.gnc),
        rocksteady::config::load_case(case_path));
    planner::PlanModel m;
    m.j_hat = rocksteady::gnc::total_inertia(run.flight.mass_hat);
    m.b_hat = rocksteady::gnc::torque_matrix(run.flight.rcs, run.flight.mass_hat.r_so_bcm);
    m.u_max = run.flight.rcs.u_max;
    m.eps_trans = run.flight.guidance.eps_trans;
    m.omega_init = mission.initial_omega;
    return m;
#else
    throw std::runtime_error(
        "this build has no configuration loader: use --u-max/--delta-j/--delta-r");
#endif
  }
  return planner::study_case_model(a.u_max, a.delta_j, a.delta_r);
}

int upload(lcm::LCM* lcm, SeqSource& seqs, const SendArgs& a) {
  if (a.args.size() != 1) {
    std::fprintf(stderr,
                 "error: upload-trajectory takes 1 argument (the trajectory file), got %zu\n",
                 a.args.size());
    return cli::kExitUsage;
  }
  const std::string& path = a.args[0];
  planner::LoadResult loaded;
  try {
    loaded = a.file_model ? cli::load_trajectory_own_model(path)
                          : cli::load_trajectory(path, expected_model(a));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return cli::kExitUsage;
  }
  if (!loaded.ok) {
    std::fprintf(stderr, "error: %s\n", loaded.error.c_str());
    return cli::kExitUsage;
  }
  const auto table = std::make_unique<rocksteady::gnc::TrajectoryTable>(loaded.file.to_table());
  // The upload id: --upload-id, else a fresh sequence number (unique per sender and state file).
  const std::int32_t id = a.upload_id >= 0 ? static_cast<std::int32_t>(a.upload_id)
                                           : static_cast<std::int32_t>(seqs.next() % 2147483647);
  std::fprintf(stderr, "%s: case '%s', %d samples, t_final %.1f s, fuel %.4f kg -> upload id %d\n",
               path.c_str(), loaded.file.case_name.c_str(), table->count, loaded.file.t_final,
               loaded.file.fuel_kg, id);
  if (a.dry_run || lcm == nullptr) {
    std::printf("DRY RUN: %d chunks\n", rocksteady::wire::chunk_count(table->count));
    return cli::kExitAccepted;
  }
  cli::UploadOptions options;
  options.upload_id = id;
  options.chunk_interval_s = a.chunk_interval;
  options.wait_s = a.wait;
  options.passes = a.passes;
  options.state_dir = seqs.dir();
  options.sender = a.sender;
  const cli::UploadResult r = cli::upload_chunks(*lcm, *table, options, stderr);
  std::fprintf(stderr, "%s\n", r.message.c_str());
  if (r.refused) {
    std::printf("REFUSED: %s\n", r.message.c_str());
    return cli::kExitRunFailed;
  }
  if (!r.complete) {
    std::printf("TIMEOUT: %s\n", r.message.c_str());
    return cli::kExitRunFailed;
  }
  if (a.no_load) {
    std::printf("UPLOADED: upload id %d (load it with: send load-trajectory %d)\n", id, id);
    return cli::kExitAccepted;
  }
  const cli::Encoded e = cli::encode_command("load-trajectory", {std::to_string(id)});
  if (!e.ok) {
    std::fprintf(stderr, "error: %s\n", e.error.c_str());
    return cli::kExitUsage;
  }
  return send_one(lcm, e.cmd, e.description, seqs, a);
}

int run_send(const SendArgs& a, const std::string& url) {
  SeqSource seqs(a);
  try {
    if (a.command == "upload-trajectory") {
      if (a.quat) {
        std::fprintf(stderr, "error: --quat applies to set-target only\n");
        return cli::kExitUsage;
      }
      std::unique_ptr<lcm::LCM> lcm = a.dry_run ? nullptr : open_bus(url);
      return upload(lcm.get(), seqs, a);
    }
    cli::EncodeOptions options;
    options.quaternion = a.quat;
    const cli::Encoded e = cli::encode_command(a.command, a.args, options);
    if (!e.ok) {
      std::fprintf(stderr, "error: %s\n", e.error.c_str());
      return cli::kExitUsage;
    }
    std::unique_ptr<lcm::LCM> lcm = a.dry_run ? nullptr : open_bus(url);
    return send_one(lcm.get(), e.cmd, e.description, seqs, a);
  } catch (const std::exception& ex) {
    std::fprintf(stderr, "error: %s\n", ex.what());
    return cli::kExitUsage;
  }
}

int run_params_get(const SendArgs& a, const std::string& url) {
  try {
    SeqSource seqs(a);
    const cli::Encoded e = cli::encode_command("dump-params", {}, cli::EncodeOptions{});
    rocksteady::ground_cmd_t cmd = e.cmd;
    cli::stamp(cmd, seqs.next(), a.sender);
    std::unique_ptr<lcm::LCM> lcm = open_bus(url);
    const cli::ParamReadback r = cli::read_params(*lcm, cmd, a.timeout);
    if (r.send.outcome == cli::SendResult::Outcome::kRejected) {
      std::printf("%s\n", cli::format_ack_verdict(r.send.ack).c_str());
      return cli::kExitRunFailed;
    }
    if (!r.have_table && r.forged_tables > 0) {
      std::printf("FORGED: %llu parameter table(s) on RS_PARAMS failed authentication; none "
                  "believed\n",
                  static_cast<unsigned long long>(r.forged_tables));
      return cli::kExitRunFailed;
    }
    if (!r.have_table) {
      std::printf("TIMEOUT: no parameter table (seq %lld) within %g s%s\n",
                  static_cast<long long>(cmd.seq), a.timeout,
                  r.send.error.empty() ? "" : (": " + r.send.error).c_str());
      return cli::kExitRunFailed;
    }
    std::fputs(cli::format_params(r.table).c_str(), stdout);
    if (r.table_unauthenticated) std::printf("(lab mode: the table carries no authenticator)\n");
    if (r.forged_tables > 0) {
      std::printf("warning: %llu forged parameter table(s) on RS_PARAMS ignored\n",
                  static_cast<unsigned long long>(r.forged_tables));
    }
    return cli::kExitAccepted;
  } catch (const std::exception& ex) {
    std::fprintf(stderr, "error: %s\n", ex.what());
    return cli::kExitUsage;
  }
}

std::string send_footer() {
  std::string s = "Commands:\n";
  for (const cli::CommandHelp& h : cli::command_help()) {
    s += std::string("  ") + h.usage + "\n      " + h.what + "\n";
  }
  s += "Exit status: 0 accepted, 1 rejected or not acknowledged (timeout), 2 usage or "
       "configuration error.\n"
       "Negative numbers are arguments, e.g. set-target -0.1 0 0.2 (or put them after --).";
  return s;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Rocksteady operator console: commands, live telemetry, log conversion"};
  app.footer(
      "Exit status (every subcommand): 0 ok, 1 the run failed (command rejected or not "
      "acknowledged, sequence aborted, gnuplot failed), 2 usage or configuration error.");
  app.require_subcommand(1);
  std::string url;
  app.add_option("--lcm-url", url,
                 "LCM URL (default: $LCM_DEFAULT_URL, else udpm://239.255.76.67:7667?ttl=0)");
  cli::AuthOptions auth_opt;
  app.add_option("--key-file", auth_opt.key_file,
                 "command keys (mode 0600; default $ROCKSTEADY_KEY_FILE): commands and uplink "
                 "chunks are signed, acknowledgements verified (a forged one is reported)");
  app.add_option("--key-id", auth_opt.key_id,
                 "the key that signs (default $ROCKSTEADY_KEY_ID, else the lowest id in the file; "
                 "after KEY_ROTATE the new id)")
      ->check(CLI::PositiveNumber);
  app.add_flag("--lab", auth_opt.lab,
               "the flight runs with --lab-mode: nothing is signed, acknowledgements are not "
               "authenticated (default when $ROCKSTEADY_LAB_MODE=1 and no key file is given)");

  std::string keygen_path;
  int keygen_count = 2;
  CLI::App* keygen = app.add_subcommand(
      "keygen", "write a new command key file (mode 0600) for rocksteady-fsw --key-file and the "
                "ground tools' --key-file");
  keygen->add_option("file", keygen_path, "the key file to create (never overwritten)")->required();
  keygen->add_option("--keys", keygen_count,
                     "keys in the file, ids 1..N (the flight starts with 1; KEY_ROTATE moves up)")
      ->check(CLI::Range(1, rocksteady::fsw::auth::kMaxKeys))
      ->capture_default_str();

  SendArgs s;
  CLI::App* send = app.add_subcommand("send", "send one command and wait for its acknowledgement");
  send->footer(send_footer());
  send->add_option("command", s.command, "the command (see below)")->required();
  send->add_option("args", s.args, "its arguments");
  send->add_flag("--quat", s.quat, "set-target: the arguments are a unit quaternion x y z w");
  send->add_option("--seq", s.seq, "sequence number (default: the next from the state file)")
      ->check(CLI::PositiveNumber);
  send->add_option("--sender", s.sender, "sender id (default 1, the operator console)")
      ->check(CLI::NonNegativeNumber);
  send->add_option("--timeout", s.timeout, "seconds to wait for the acknowledgement (default 3)")
      ->check(CLI::PositiveNumber);
  send->add_option("--state-dir", s.state_dir,
                   "sequence state directory (default $XDG_STATE_HOME/rocksteady or "
                   "~/.local/state/rocksteady)");
  send->add_flag("--dry-run", s.dry_run, "encode and print, send nothing");
  send->add_option("--upload-id", s.upload_id,
                   "upload-trajectory: the upload id (default: a fresh "
                   "sequence number)")
      ->check(CLI::Range(0LL, 2147483647LL));
  send->add_flag("--no-load", s.no_load, "upload-trajectory: uplink only, no LOAD_TRAJECTORY");
  send->add_option("--chunk-interval", s.chunk_interval,
                   "upload-trajectory: seconds between chunks")
      ->check(CLI::NonNegativeNumber);
  send->add_option("--wait", s.wait, "upload-trajectory: seconds to wait for completion per pass")
      ->check(CLI::PositiveNumber);
  send->add_option("--passes", s.passes, "upload-trajectory: send the chunks at most this often")
      ->check(CLI::Range(1, 20));
  send->add_flag("--file-model", s.file_model,
                 "upload-trajectory: check the plan against the model recorded in the file");
  send->add_option("--u-max", s.u_max, "upload-trajectory: study-case model, u_max (N)");
  send->add_option("--delta-j", s.delta_j, "upload-trajectory: study-case model, ||dJ_ast||_2");
  send->add_option("--delta-r", s.delta_r, "upload-trajectory: study-case model, ||dr||_2 (m)");
  send->add_option("--case", s.case_file,
                   "upload-trajectory: check the plan against study case N (<config dir>/cases/"
                   "caseN.yaml) or a case file");
  send->add_option("--config-dir", s.config_dir,
                   "upload-trajectory: folder with mission.yaml, gnc.yaml, cases/ (default: "
                   "$ROCKSTEADY_CONFIG_DIR, else next to this program, else ./configs)");
  send->add_option("--mission", s.mission,
                   "upload-trajectory: mission YAML (default: <config dir>/mission.yaml)");
  send->add_option("--gnc", s.gnc, "upload-trajectory: GNC YAML (default: <config dir>/gnc.yaml)");

  cli::MonitorOptions mon;
  bool plain = false;
  bool ansi = false;
  CLI::App* monitor = app.add_subcommand("monitor", "live telemetry, events and acknowledgements");
  monitor->add_option("--count", mon.count, "exit after N telemetry messages")
      ->check(CLI::NonNegativeNumber);
  monitor->add_option("--seconds", mon.seconds, "exit after S seconds")
      ->check(CLI::NonNegativeNumber);
  monitor->add_flag("--plain", plain, "one line per message even on a terminal");
  monitor
      ->add_option("--stale-after", mon.stale_after_s,
                   "flag telemetry STALE after this many silent seconds (default 3, 0: never)")
      ->check(CLI::NonNegativeNumber);
  monitor->add_flag("--ansi", ansi, "redraw a status block even when not on a terminal");

  std::string log_path;
  std::string channel = "RS_GNC_TLM";
  std::string output;
  CLI::App* log2csv = app.add_subcommand("log2csv", "one channel of an LCM log as CSV");
  log2csv->add_option("logfile", log_path, "LCM log (lcm-logger)")
      ->required()
      ->check(CLI::ExistingFile);
  log2csv->add_option("--channel", channel, "channel to convert (default RS_GNC_TLM)");
  log2csv->add_option("-o,--output", output, "CSV file (default: standard output)");
  bool strict = false;
  log2csv->add_flag("--strict", strict, "exit 1 when an event of the channel was rejected");

  CLI::App* params = app.add_subcommand(
      "params", "the loadable parameters: list them (set-gain), or read the active table back");
  SendArgs pg;
  CLI::App* params_get = params->add_subcommand(
      "get", "PARAM_DUMP: print the flight's active parameter table (names, values, units)");
  params_get->add_option("--sender", pg.sender, "sender id (default 1, the operator console)")
      ->check(CLI::NonNegativeNumber);
  params_get->add_option("--seq", pg.seq, "sequence number (default: the next from the state file)")
      ->check(CLI::PositiveNumber);
  params_get->add_option("--timeout", pg.timeout, "seconds to wait for the table (default 3)")
      ->check(CLI::PositiveNumber);
  params_get->add_option("--state-dir", pg.state_dir, "where sequence numbers are kept");

  std::string seq_file;
  bool seq_check = false;
  cli::GateOptions run_gate;
  CLI::App* run = app.add_subcommand(
      "run", "run a command sequence: sends with acks, waits on telemetry conditions");
  run->footer(
      "A sequence is YAML:\n"
      "  name: hold-after-detumble\n"
      "  steps:\n"
      "    - send: set-mode DETUMBLE\n"
      "    - wait: mode == HOLD, timeout 600 s\n"
      "    - sleep: 5 s\n"
      "    - send: set-target 0.1 0 0\n"
      "The whole file is checked before the first command is sent; the run stops at the first\n"
      "rejection, missing acknowledgement or timeout.\n"
      "Exit status: 0 completed, 1 aborted (rejected, timeout), 2 invalid sequence or usage.");
  run->add_option("sequence", seq_file, "the sequence file (YAML)")->required();
  run->add_flag("--check", seq_check, "validate only, send nothing");
  run->add_option("--sender", run_gate.sender, "sender id (default 1, the operator console)")
      ->check(CLI::NonNegativeNumber);
  run->add_option("--timeout", run_gate.timeout_s,
                  "seconds to wait for each acknowledgement (default 3)")
      ->check(CLI::PositiveNumber);
  run->add_option("--state-dir", run_gate.state_dir, "sequence state directory (as for send)");

  std::string plot_in;
  std::string plot_out;
  std::vector<double> plot_q_final;
  CLI::App* plot = app.add_subcommand(
      "plot", "the Figure-3 plot of a run (PIL LCM log or run CSV) as PNG, with gnuplot");
  plot->footer(
      "Panels: body rate, attitude (MRP) and fuel; truth solid, on-board estimate dashed, "
      "reference dotted (when the input has them); t_omega,conv and t_q,conv (SPEC 7) marked, or "
      "NC.\nExit status: 0 written, 1 gnuplot failed, 2 unreadable input or usage.");
  plot->add_option("input", plot_in,
                   "LCM log (RS_PLANT_TRUTH, RS_GNC_TLM) or CSV (campaign timeseries.csv, plant "
                   "--out)")
      ->required()
      ->check(CLI::ExistingFile);
  plot->add_option("-o,--output", plot_out, "PNG file (default: INPUT with .png)");
  plot->add_option("--q-final", plot_q_final,
                   "target MRP for t_q,conv (default: from telemetry, else 0 0 0)")
      ->expected(3);

#ifdef ROCKSTEADY_GROUND_CLI_WITH_CONSOLE
  rocksteady::ground::console::ServeOptions so;
  CLI::App* serve = app.add_subcommand(
      "serve", "the browser console (NASA Open MCT): telemetry, events, commands over HTTP");
  serve->add_option("--bind", so.bind, "address to listen on (default 127.0.0.1, loopback only)");
  serve->add_option("--port", so.port, "TCP port (default 8090; 0: any free port, printed)")
      ->check(CLI::Range(0, 65535));
  serve->add_option("--web-root", so.web_root,
                    "folder with app/ and openmct/ (default: next to this program)");
  serve->add_option("--sender", so.sender, "sender id of the console's commands (default 2)")
      ->check(CLI::NonNegativeNumber);
  serve->add_option("--state-dir", so.state_dir, "sequence state directory (as for send)");
  serve
      ->add_option("--timeout", so.ack_timeout_s,
                   "seconds to wait for a command's acknowledgement (default 3)")
      ->check(CLI::PositiveNumber);
  serve
      ->add_option("--stale-after", so.stale_after_s,
                   "seconds without a message before a channel is flagged stale (default 3)")
      ->check(CLI::PositiveNumber);
#endif

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    app.exit(e);
    return cli::kExitUsage;
  }

  if (*keygen) {
    const std::string err =
        rocksteady::fsw::auth::generate_key_file(keygen_path, keygen_count);
    if (!err.empty()) {
      std::fprintf(stderr, "error: %s\n", err.c_str());
      return 2;
    }
    std::printf("%s: %d command key(s), ids 1..%d, mode 0600\n", keygen_path.c_str(),
                keygen_count, keygen_count);
    return 0;
  }
  if (const std::string err = cli::configure_auth(auth_opt); !err.empty()) {
    std::fprintf(stderr, "error: %s\n", err.c_str());
    return 2;
  }

  if (*send) return run_send(s, url);

  if (*monitor) {
    mon.ansi = ansi || (!plain && isatty(STDOUT_FILENO) != 0);
    try {
      std::unique_ptr<lcm::LCM> lcm = open_bus(url);
      const cli::MonitorCounts c = cli::run_monitor(*lcm, mon, stdout);
      std::fprintf(stderr, "monitor: %llu telemetry, %llu events, %llu acks; %s\n",
                   static_cast<unsigned long long>(c.telemetry),
                   static_cast<unsigned long long>(c.events),
                   static_cast<unsigned long long>(c.acks), cli::describe_rejections(c.rx).c_str());
      return mon.count >= 0 && c.telemetry < static_cast<std::uint64_t>(mon.count) ? 1 : 0;
    } catch (const std::exception& e) {
      std::fprintf(stderr, "error: %s\n", e.what());
      return 2;
    }
  }

  if (*log2csv) {
    try {
      cli::Log2CsvStats st;
      if (output.empty()) {
        st = cli::log2csv(log_path, channel, std::cout);
      } else {
        std::ofstream out(output, std::ios::trunc);
        if (!out) throw std::runtime_error(output + ": cannot write");
        st = cli::log2csv(log_path, channel, out);
      }
      std::fprintf(stderr, "%s: %llu events, %llu on %s, %llu rows; %s\n", log_path.c_str(),
                   static_cast<unsigned long long>(st.events),
                   static_cast<unsigned long long>(st.on_channel), channel.c_str(),
                   static_cast<unsigned long long>(st.written),
                   cli::describe_rejections(st.rx).c_str());
      return strict && st.rejected() > 0 ? 1 : 0;
    } catch (const std::exception& e) {
      std::fprintf(stderr, "error: %s\n", e.what());
      return 2;
    }
  }

  if (*plot) {
    try {
      const cli::PlotData d = cli::load_plot_data(plot_in);
      cli::PlotOptions po;
      po.output = plot_out.empty()
                      ? std::filesystem::path(plot_in).replace_extension(".png").string()
                      : plot_out;
      if (plot_q_final.size() == 3) {
        po.q_final = std::array<double, 3>{plot_q_final[0], plot_q_final[1], plot_q_final[2]};
      }
      const std::string error = cli::write_plot(d, po);
      if (!error.empty()) {
        std::fprintf(stderr, "error: %s\n", error.c_str());
        return 1;
      }
      std::printf("%s\n", po.output.c_str());
      return 0;
    } catch (const std::exception& e) {
      std::fprintf(stderr, "error: %s\n", e.what());
      return 2;
    }
  }

  if (*run) {
    const cli::SequenceParse parsed = cli::load_sequence(seq_file);
    if (!parsed.ok) {
      for (const std::string& e : parsed.errors) std::fprintf(stderr, "error: %s\n", e.c_str());
      std::fprintf(stderr, "%s: %zu error(s); nothing was sent\n", seq_file.c_str(),
                   parsed.errors.size());
      return 2;
    }
    std::fprintf(stderr, "%s: %zu steps, valid\n", seq_file.c_str(), parsed.sequence.steps.size());
    if (seq_check) return 0;
    try {
      run_gate.lcm_url = url;
      cli::CommandGate gate(run_gate);
      std::unique_ptr<lcm::LCM> lcm = open_bus(url);
      const cli::SequenceReport r = cli::run_sequence(parsed.sequence, gate, *lcm, stdout);
      return r.outcome == cli::SequenceReport::Outcome::kCompleted ? 0 : 1;
    } catch (const std::exception& e) {
      std::fprintf(stderr, "error: %s\n", e.what());
      return 2;
    }
  }

#ifdef ROCKSTEADY_GROUND_CLI_WITH_CONSOLE
  if (*serve) {
    so.lcm_url = url;
    return rocksteady::ground::console::serve(so);
  }
#endif

  if (*params_get) return run_params_get(pg, url);
  if (*params) {
    for (const cli::ParamEntry& p : cli::param_dictionary()) {
      const char* kind = p.kind == cli::ParamKind::kMatrix   ? "matrix: 3 (diagonal) or 6 values"
                         : p.kind == cli::ParamKind::kScalar ? "scalar: 1 value"
                                                             : "flag: 0 or 1";
      std::printf("%2d  %-30s %-16s %s\n", p.id, p.name, p.units[0] != '\0' ? p.units : "-", kind);
    }
    return 0;
  }
  return 2;
}
