// The CLI's bus procedures: send one command and wait for its acknowledgement, uplink a trajectory
// table in chunks and wait until the flight has all of them, and the live monitor. Every inbound
// message is decoded with wire::safe_decode from a raw-buffer subscription.
#pragma once

#include <cstdint>
#include <cstdio>
#include <string>

#include <lcm/lcm-cpp.hpp>

#include "gnc/guidance/trajectory.hpp"
#include "ground/cli/monitor_format.hpp"
#include "rocksteady/cmd_ack_t.hpp"
#include "rocksteady/ground_cmd_t.hpp"
#include "rocksteady/param_table_t.hpp"

namespace rocksteady::ground::cli {

// Exit codes, one convention for every Rocksteady tool: 0 ok, 1 the run failed (for send: the
// command was rejected or not acknowledged), 2 usage or configuration error.
inline constexpr int kExitAccepted = 0;
inline constexpr int kExitRejected = 1;
inline constexpr int kExitRunFailed = 1;
inline constexpr int kExitUsage = 2;

struct SendResult {
  // kForged: acknowledgements of this command arrived, none with a valid downlink authenticator.
  enum class Outcome { kAccepted, kRejected, kTimeout, kError, kForged };
  Outcome outcome{Outcome::kError};
  rocksteady::cmd_ack_t ack{};  // the matching acknowledgement (accepted / rejected)
  std::string error;            // kError: what failed
  std::uint64_t other_acks{0};  // acknowledgements of other commands seen meanwhile
  std::uint64_t forged_acks{0};  // acknowledgements of this command that failed authentication
  bool lab_mode{false};          // the ground is in lab mode: the ack was not authenticated
  wire::RxCounters rx{};   // decode outcomes on RS_CMD_ACK
  int exit_code() const;
};

// Authenticates `cmd` (ground_auth.hpp; its seq must be the key's next counter), publishes it on
// RS_GROUND_CMD and waits up to `timeout_s` for an authentic cmd_ack_t that echoes its seq, sender
// and opcode. Acknowledgements that fail authentication are counted, never believed.
SendResult send_and_wait(lcm::LCM& lcm, const rocksteady::ground_cmd_t& cmd, double timeout_s);

struct ParamReadback {
  SendResult send;                  // the PARAM_DUMP's acknowledgement
  bool have_table{false};
  rocksteady::param_table_t table{};  // the flight's active table (RS_PARAMS), authentic
  bool table_unauthenticated{false};  // lab mode: the table carries no authenticator
  std::uint64_t forged_tables{0};     // tables on RS_PARAMS that failed authentication
};

// Publishes a PARAM_DUMP `cmd` and waits up to `timeout_s` for its acknowledgement and, once
// accepted, for the table the flight publishes with it. A table that fails the downlink
// authenticator is counted in forged_tables and never returned.
ParamReadback read_params(lcm::LCM& lcm, const rocksteady::ground_cmd_t& cmd, double timeout_s);

// The read-back as text: one line per parameter with its name, values and units.
std::string format_params(const rocksteady::param_table_t& table);

struct UploadOptions {
  std::int32_t upload_id{0};
  double chunk_interval_s{0.02};  // pause between chunks: the flight drains its bus once per tick
                                  // and LCM queues 30 messages per subscription
  double wait_s{5.0};             // per pass: how long to wait for uplink_complete
  int passes{3};                  // send every chunk up to this many times (repeats are harmless)
  // Each chunk sent takes the key's next counter from here (ground_auth.hpp next_counter).
  std::string state_dir;
  std::int32_t sender{1};
};

struct UploadResult {
  bool complete{false};
  bool refused{false};  // the flight has another upload in progress (abort it first)
  int chunks{0};
  int passes_used{0};
  std::uint64_t chunk_rejections{0};  // chunk_rejected events for this upload
  std::string message;                // how it ended
};

// Sends every chunk of `table` on RS_TRAJ_UPLINK and waits for the flight's uplink_complete event
// (or telemetry showing every chunk received) for this upload id. Progress lines go to `log`.
UploadResult upload_chunks(lcm::LCM& lcm, const gnc::TrajectoryTable& table,
                           const UploadOptions& options, std::FILE* log);

struct MonitorOptions {
  long count{-1};             // stop after this many telemetry messages (< 0: no limit)
  double seconds{-1.0};       // stop after this long (< 0: no limit)
  bool ansi{false};           // redraw a status block (terminal) instead of one line per message
  int event_lines{10};        // events kept under the status block (ansi)
  double stale_after_s{3.0};  // no telemetry this long: flag it STALE (<= 0: never)
};

// Runs until a limit is reached; returns what it saw.
MonitorCounts run_monitor(lcm::LCM& lcm, const MonitorOptions& options, std::FILE* out);

}  // namespace rocksteady::ground::cli
