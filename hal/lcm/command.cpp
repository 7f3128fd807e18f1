#include "hal/lcm/command.hpp"

#include <cmath>

#include "gnc/params.hpp"
#include "hal/lcm/codec.hpp"

namespace rocksteady::hal::wire {

namespace {

using Cmd = rocksteady::ground_cmd_t;
using Ack = rocksteady::cmd_ack_t;

bool integral_in(double v, double lo, double hi) {
  return v >= lo && v <= hi && std::floor(v) == v;
}

}  // namespace

int expected_args(std::int32_t opcode) {
  switch (opcode) {
    case Cmd::OP_NOOP: return 0;
    case Cmd::OP_SET_MODE: return 1;
    case Cmd::OP_SET_TARGET: return 3;
    case Cmd::OP_SET_LAW: return 1;
    case Cmd::OP_LOAD_TRAJECTORY: return 1;
    case Cmd::OP_ABORT_UPLINK: return 1;
    case Cmd::OP_RESET_COUNTERS: return 0;
    default: return -1;
  }
}

CommandCheck check_command(const Cmd& cmd) {
  if (check(cmd) != DecodeStatus::kOk) return {Ack::REASON_INTERNAL, 0};
  if (cmd.seq <= 0) return {Ack::REASON_STALE_SEQUENCE, 0};
  const int n = expected_args(cmd.opcode);
  if (n < 0) return {Ack::REASON_UNKNOWN_OPCODE, 0};
  if (cmd.nargs != n) return {Ack::REASON_BAD_ARG_COUNT, cmd.nargs};
  for (int i = 0; i < n; ++i) {
    if (!std::isfinite(cmd.args[i])) return {Ack::REASON_ARG_NOT_FINITE, i};
  }
  const double a0 = cmd.args[0];
  switch (cmd.opcode) {
    case Cmd::OP_SET_MODE:
      if (!integral_in(a0, 0.0, gnc::kModeCount - 1)) return {Ack::REASON_ARG_OUT_OF_RANGE, 0};
      break;
    case Cmd::OP_SET_LAW:
      if (!integral_in(a0, 0.0, gnc::kLawCount - 1)) return {Ack::REASON_ARG_OUT_OF_RANGE, 0};
      break;
    case Cmd::OP_SET_TARGET: {
      const double norm = std::sqrt(cmd.args[0] * cmd.args[0] + cmd.args[1] * cmd.args[1] +
                                    cmd.args[2] * cmd.args[2]);
      if (!(norm <= kMaxTargetMrpNorm)) return {Ack::REASON_ARG_OUT_OF_RANGE, 0};
      break;
    }
    case Cmd::OP_LOAD_TRAJECTORY:
    case Cmd::OP_ABORT_UPLINK:
      if (!integral_in(a0, 0.0, 2147483647.0)) return {Ack::REASON_ARG_OUT_OF_RANGE, 0};
      break;
    default: break;
  }
  return {};
}

Ack make_ack(const Cmd& cmd, const CommandCheck& result, double t) {
  Ack a = make<Ack>();
  a.t = t;
  a.seq = cmd.seq;
  a.sender_id = cmd.sender_id;
  a.opcode = cmd.opcode;
  a.accepted = result.ok() ? 1 : 0;
  a.reason = result.reason;
  a.detail = result.detail;
  return a;
}

}  // namespace rocksteady::hal::wire
