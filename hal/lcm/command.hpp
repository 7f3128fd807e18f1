// The ground-command validator: judges one decoded ground_cmd_t on its own (opcode, argument count,
// finiteness and ranges) and gives the cmd_ack_t reason. What depends on on-board state (sequence
// freshness, authentication, mode rules, uplink state) is the command dispatcher's to add.
#pragma once

#include <cstdint>

#include "rocksteady/cmd_ack_t.hpp"
#include "rocksteady/ground_cmd_t.hpp"

namespace rocksteady::hal::wire {

struct CommandCheck {
  std::int32_t reason{rocksteady::cmd_ack_t::REASON_OK};
  std::int32_t detail{0};  // the offending argument index for argument errors
  bool ok() const { return reason == rocksteady::cmd_ack_t::REASON_OK; }
};

// Number of arguments each opcode takes (-1 for an unknown opcode).
int expected_args(std::int32_t opcode);

// [Rocksteady choice] bound on a commanded target MRP's norm: |q| <= 1 is the short set, larger
// norms are shadow sets of rotations near 360 deg; beyond this the command is out of range.
inline constexpr double kMaxTargetMrpNorm = 1e3;

CommandCheck check_command(const rocksteady::ground_cmd_t& cmd);

// The acknowledgement of `cmd` with the verdict `result`, at on-board time t.
rocksteady::cmd_ack_t make_ack(const rocksteady::ground_cmd_t& cmd, const CommandCheck& result,
                               double t);

}  // namespace rocksteady::hal::wire
