// A stand-in for the flight side's bus layer, for the networked ground CLI tests: answers every
// ground_cmd_t on RS_GROUND_CMD with a cmd_ack_t judged by the flight's own checks
// (fsw::check_command in a fixed mode, fsw::SequenceTracker), reassembles trajectory uplinks with
// fsw::TrajectoryUplink (uplink_complete event when the last chunk arrives; LOAD_TRAJECTORY
// accepted only if the table validates, CRC included) and can publish telemetry at 20 Hz.
//
//   ground_cli_test_responder --url URL --ready FILE [--mode IDLE..SAFE] [--commands N]
//                             [--telemetry] [--seconds S]
// Exits after N commands (default 1; 0: never) or S seconds (default 10). Writes FILE once it is
// subscribed. Exit 0 when it stopped after N commands, 3 on timeout.
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <memory>
#include <string>

#include <lcm/lcm-cpp.hpp>

#include "fsw/bus/bus_mapping.hpp"
#include "fsw/commands/command_table.hpp"
#include "fsw/uplink/trajectory_uplink.hpp"
#include "wire/codec.hpp"

namespace wire = rocksteady::wire;
namespace fsw = rocksteady::fsw;

namespace {

struct Responder {
  lcm::LCM* lcm{nullptr};
  rocksteady::gnc::Mode mode{rocksteady::gnc::Mode::kIdle};
  fsw::SequenceTracker seqs;
  std::unique_ptr<fsw::TrajectoryUplink> uplink = std::make_unique<fsw::TrajectoryUplink>();
  long commands{0};
  long chunks{0};
  std::int64_t event_seq{0};

  void event(std::int32_t id, std::int32_t arg0, std::int32_t arg1, const std::string& text) {
    auto e = wire::make<rocksteady::event_t>();
    e.seq = ++event_seq;
    e.severity = rocksteady::event_t::SEV_INFO;
    e.id = id;
    e.arg0 = arg0;
    e.arg1 = arg1;
    e.text = text;
    lcm->publish(rocksteady::channels::kEvents, &e);
  }

  void on_command(const lcm::ReceiveBuffer* rbuf, const std::string&) {
    rocksteady::ground_cmd_t m;
    if (!wire::safe_decode(rbuf->data, static_cast<int>(rbuf->data_size), m)) return;
    const fsw::GroundCommand cmd = fsw::bus::to_command(m);  // the flight's own mapping

    fsw::CommandCheck c;
    const fsw::RejectReason seq = seqs.check(cmd.source, cmd.seq);
    if (seq != fsw::RejectReason::kNone) {
      c = fsw::CommandCheck{seq, 0, "stale sequence"};
    } else {
      c = fsw::check_command(cmd, mode);
    }
    if (c.ok() && cmd.opcode == static_cast<int>(fsw::Opcode::kLoadTrajectory)) {
      const auto id = static_cast<std::int32_t>(cmd.args[0]);
      if (!uplink->active() || uplink->upload_id() != id) {
        c = fsw::CommandCheck{fsw::RejectReason::kOutOfRange, 0, "no uplink with that id"};
      } else if (!uplink->complete()) {
        c = fsw::CommandCheck{fsw::RejectReason::kUploadIncomplete, uplink->chunks_received(),
                              "uplink incomplete"};
      } else {
        const rocksteady::gnc::TrajectoryError e = uplink->finalize(1e9);
        if (e != rocksteady::gnc::TrajectoryError::kOk) {
          c = fsw::CommandCheck{fsw::RejectReason::kTrajectoryRejected,
                                static_cast<std::int32_t>(e), rocksteady::gnc::to_string(e)};
        }
      }
    }
    if (c.ok()) seqs.accept(cmd.source, cmd.seq);

    auto ack = wire::make<rocksteady::cmd_ack_t>();
    ack.seq = m.seq;
    ack.sender_id = m.sender_id;
    ack.opcode = m.opcode;
    ack.accepted = c.ok() ? 1 : 0;
    ack.reason = static_cast<std::int32_t>(c.reason);
    ack.detail = c.detail;
    ack.text = c.text;
    lcm->publish(rocksteady::channels::kCmdAck, &ack);
    ++commands;
  }

  void on_chunk(const lcm::ReceiveBuffer* rbuf, const std::string&) {
    rocksteady::trajectory_chunk_t m;
    if (!wire::safe_decode(rbuf->data, static_cast<int>(rbuf->data_size), m)) return;
    ++chunks;
    fsw::TrajectoryChunk c;
    fsw::bus::to_chunk(m, c);  // the flight's own mapping
    const fsw::ChunkResult r = uplink->receive(c);
    if (r.status != fsw::ChunkStatus::kStored) {
      event(117, m.upload_id, static_cast<std::int32_t>(r.status), fsw::to_string(r.status));
    } else if (r.completed) {
      event(120, m.upload_id, 0, "uplink complete");
    }
  }
};

}  // namespace

int main(int argc, char** argv) {
  std::string url;
  std::string ready;
  long max_commands = 1;
  double seconds = 10.0;
  bool telemetry = false;
  Responder r;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const bool more = i + 1 < argc;
    if (a == "--url" && more) {
      url = argv[++i];
    } else if (a == "--ready" && more) {
      ready = argv[++i];
    } else if (a == "--mode" && more) {
      const std::string m = argv[++i];
      const char* names[] = {"IDLE", "DETUMBLE", "HOLD", "TRACK", "SAFE"};
      for (int k = 0; k < 5; ++k) {
        if (m == names[k]) r.mode = static_cast<rocksteady::gnc::Mode>(k);
      }
    } else if (a == "--commands" && more) {
      max_commands = std::atol(argv[++i]);
    } else if (a == "--seconds" && more) {
      seconds = std::atof(argv[++i]);
    } else if (a == "--telemetry") {
      telemetry = true;
    } else {
      std::fprintf(stderr, "responder: bad argument %s\n", a.c_str());
      return 2;
    }
  }
  lcm::LCM lcm(url);
  if (!lcm.good()) {
    std::fprintf(stderr, "responder: cannot open %s\n", url.c_str());
    return 2;
  }
  r.lcm = &lcm;
  lcm.subscribe(rocksteady::channels::kGroundCmd, &Responder::on_command, &r);
  lcm.subscribe(rocksteady::channels::kTrajUplink, &Responder::on_chunk, &r);
  if (!ready.empty()) std::ofstream(ready) << "ready\n";

  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  const auto deadline =
      start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
  auto next_tlm = start;
  std::int64_t tick = 0;
  while (max_commands <= 0 || r.commands < max_commands) {
    const auto now = Clock::now();
    if (now >= deadline) {
      std::fprintf(stderr, "responder: timeout after %ld commands, %ld chunks\n", r.commands,
                   r.chunks);
      return 3;
    }
    if (telemetry && now >= next_tlm) {
      auto m = wire::make<rocksteady::gnc_telemetry_t>();
      m.t = 0.1 * static_cast<double>(tick);
      m.tick = tick++;
      m.mode = static_cast<std::int8_t>(r.mode);
      m.law = 4;
      m.omega_hat[0] = 3e-3;
      m.omega_hat[1] = -4e-3;
      m.fuel_kg = 12.5;
      m.rate_group_count = 2;
      m.rg_cycles[0] = tick;
      m.uplink_id = -1;
      lcm.publish(rocksteady::channels::kGncTelemetry, &m);
      next_tlm = now + std::chrono::milliseconds(50);
    }
    lcm.handleTimeout(20);
  }
  std::fprintf(stderr, "responder: %ld commands, %ld chunks\n", r.commands, r.chunks);
  return 0;
}
