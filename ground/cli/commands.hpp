// Operator input -> ground_cmd_t. The words an operator types ("set-mode HOLD", "set-gain ntcl.K
// 1e4 1e4 2e4") are checked here, before anything goes on the bus: unknown command, wrong argument
// count, non-numeric or non-finite numbers, names that are not in the dictionary and the ranges the
// flight side's opcode table will check (fsw/README.md "Commands") are refused locally with a
// message that says what is expected. The encoding is the flight side's contract: opcode numbers,
// argument order, counts (tests/ground_cli checks every command against fsw::check_command).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "rocksteady/ground_cmd_t.hpp"

namespace rocksteady::ground::cli {

struct EncodeOptions {
  bool quaternion{
      false};  // set-target takes a quaternion [x y z w] (scalar last) instead of an MRP
};

struct Encoded {
  bool ok{false};
  std::string error;               // why the input was refused (when !ok)
  rocksteady::ground_cmd_t cmd{};  // kind, version, opcode, nargs, args; seq and sender are 0
  std::string description;         // what will be sent, for the operator ("SET_MODE HOLD")
};

// Encodes one command; `name` is the command word, `args` the words after it. Does not handle
// upload-trajectory (a procedure of many messages, see bus.hpp).
Encoded encode_command(const std::string& name, const std::vector<std::string>& args,
                       const EncodeOptions& options = {});

// The command words, and a one-line usage for each (for --help and error messages).
struct CommandHelp {
  const char* name;
  const char* usage;
  const char* what;
};
const std::vector<CommandHelp>& command_help();
std::string command_list();  // "noop, set-mode, ..."

// The opcode names (ground_cmd_t OP_*): "NOOP", "SET_MODE", ...; "OP <n>" otherwise.
std::string opcode_name(int opcode);

// A strict number: the whole word is a finite double ("1e4", "-0.2"); nothing else.
bool parse_number(const std::string& word, double& out);

// Fills the stamp of a command: sequence number and sender.
void stamp(rocksteady::ground_cmd_t& cmd, std::int64_t seq, std::int32_t sender_id);

}  // namespace rocksteady::ground::cli
