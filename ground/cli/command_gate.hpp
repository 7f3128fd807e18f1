// One command through the command contract, as a function: the operator's words are encoded and
// checked (commands.hpp), stamped with the sender's next sequence number (sequence_store.hpp),
// published, and answered by the flight's acknowledgement (bus.hpp). Used by the browser console's
// server and by command sequences, so that every path to the flight is the one `send` takes.
#pragma once

#include <cstdint>
#include <mutex>
#include <string>
#include <vector>

#include <lcm/lcm-cpp.hpp>

#include "rocksteady/cmd_ack_t.hpp"

namespace rocksteady::ground::cli {

struct GateOptions {
  std::string lcm_url;  // "" = LCM's default
  std::int32_t sender{1};
  std::string state_dir;  // "" = default_state_dir()
  double timeout_s{3.0};  // for the acknowledgement
};

struct GateResult {
  enum class Outcome { kAccepted, kRejected, kTimeout, kInvalid, kError };
  Outcome outcome{Outcome::kError};
  std::string description;  // "SET_MODE HOLD"
  std::int64_t seq{0};
  rocksteady::cmd_ack_t ack{};  // kAccepted / kRejected
  std::string message;          // the verdict as the operator reads it
};
const char* to_string(GateResult::Outcome o);  // "accepted", "rejected", ...

class CommandGate {
 public:
  explicit CommandGate(GateOptions options);
  // Validates, sends and waits. `lcm`: an open bus to use (only from the thread that handles it),
  // or nullptr to open one for this command. Serialised: one command at a time.
  GateResult send(const std::string& command, const std::vector<std::string>& args,
                  lcm::LCM* lcm = nullptr);
  // Encodes only: the error message, or "" when the command is valid.
  static std::string check(const std::string& command, const std::vector<std::string>& args);

 private:
  GateOptions options_;
  std::mutex mutex_;
};

}  // namespace rocksteady::ground::cli
