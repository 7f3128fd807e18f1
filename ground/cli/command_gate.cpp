#include "ground/cli/command_gate.hpp"

#include <exception>
#include <memory>

#include "ground/cli/bus.hpp"
#include "ground/cli/commands.hpp"
#include "ground/cli/ground_auth.hpp"
#include "ground/cli/monitor_format.hpp"
#include "ground/cli/sequence_store.hpp"

namespace rocksteady::ground::cli {

const char* to_string(GateResult::Outcome o) {
  switch (o) {
    case GateResult::Outcome::kAccepted:
      return "accepted";
    case GateResult::Outcome::kRejected:
      return "rejected";
    case GateResult::Outcome::kTimeout:
      return "timeout";
    case GateResult::Outcome::kInvalid:
      return "invalid";
    case GateResult::Outcome::kError:
      return "error";
  }
  return "error";
}

CommandGate::CommandGate(GateOptions options) : options_(std::move(options)) {
  if (options_.state_dir.empty()) options_.state_dir = default_state_dir();
}

std::string CommandGate::check(const std::string& command, const std::vector<std::string>& args) {
  if (command == "upload-trajectory") return "upload-trajectory is not available here (use send)";
  const Encoded e = encode_command(command, args);
  return e.ok ? std::string() : e.error;
}

GateResult CommandGate::send(const std::string& command, const std::vector<std::string>& args,
                             lcm::LCM* lcm) {
  GateResult r;
  const std::string invalid = check(command, args);
  if (!invalid.empty()) {
    r.outcome = GateResult::Outcome::kInvalid;
    r.message = invalid;
    return r;
  }
  Encoded e = encode_command(command, args);
  r.description = e.description;
  std::lock_guard<std::mutex> lock(mutex_);
  try {
    if (options_.state_dir.empty()) {
      throw std::runtime_error(
          "no state directory for sequence numbers ($XDG_STATE_HOME or $HOME)");
    }
    r.seq = next_counter(options_.state_dir, options_.sender);
    stamp(e.cmd, r.seq, options_.sender);
    std::unique_ptr<lcm::LCM> own;
    if (lcm == nullptr) {
      own = std::make_unique<lcm::LCM>(options_.lcm_url);
      if (!own->good()) throw std::runtime_error("cannot open the LCM bus");
      lcm = own.get();
    }
    const SendResult s = send_and_wait(*lcm, e.cmd, options_.timeout_s);
    switch (s.outcome) {
      case SendResult::Outcome::kAccepted:
      case SendResult::Outcome::kRejected:
        r.outcome = s.outcome == SendResult::Outcome::kAccepted ? GateResult::Outcome::kAccepted
                                                                : GateResult::Outcome::kRejected;
        r.ack = s.ack;
        r.message = format_ack_verdict(s.ack);
        break;
      case SendResult::Outcome::kTimeout:
        r.outcome = GateResult::Outcome::kTimeout;
        r.message = "no acknowledgement of seq " + std::to_string(r.seq) + " within " +
                    std::to_string(options_.timeout_s).substr(0, 4) + " s";
        break;
      case SendResult::Outcome::kError:
        r.outcome = GateResult::Outcome::kError;
        r.message = s.error;
        break;
      case SendResult::Outcome::kForged:
        r.outcome = GateResult::Outcome::kError;
        r.message = "FORGED: " + std::to_string(s.forged_acks) + " acknowledgement(s) of seq " +
                    std::to_string(r.seq) + " failed authentication; no authentic one arrived";
        break;
    }
  } catch (const std::exception& ex) {
    r.outcome = GateResult::Outcome::kError;
    r.message = ex.what();
  }
  return r;
}

}  // namespace rocksteady::ground::cli
