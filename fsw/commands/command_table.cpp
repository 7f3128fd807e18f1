#include "fsw/commands/command_table.hpp"

#include <cmath>

#include "fsw/params/param_table.hpp"

namespace rocksteady::fsw {

namespace {

constexpr double kIdMax = 2147483647.0;  // upload ids are int32 >= 0
constexpr double kValueMax = 1e30;       // parameter values: finite, sane magnitude

constexpr ArgRange integer(double lo, double hi) {
  return ArgRange{lo, hi, true};
}
constexpr ArgRange real(double lo, double hi) {
  return ArgRange{lo, hi, false};
}

constexpr std::array<OpcodeSpec, kOpcodeCount> kTable{{
    {Opcode::kNoop, 0, 0, kAllModes, {}},
    {Opcode::kSetMode, 1, 1, kAllModes, {integer(0, gnc::kModeCount - 1)}},
    // A TRACK plan was computed for its target: change the target in HOLD, not while tracking.
    {Opcode::kSetTarget, 3, 3, kAllButTrack, {real(-1, 1), real(-1, 1), real(-1, 1)}},
    {Opcode::kSetLaw, 1, 2, kAllModes, {integer(0, gnc::kLawCount - 1), integer(0, 2)}},
    // Loading outside TRACK replaces the table at the boundary; in TRACK the validated table goes
    // to the standby buffer and the core switches to it at the boundary (a re-plan), re-synchronising
    // the reference to the estimate, or refuses it there as stale and keeps the active one.
    {Opcode::kLoadTrajectory, 1, 1, kAllModes, {integer(0, kIdMax)}},
    {Opcode::kAbortUplink, 1, 1, kAllModes, {integer(0, kIdMax)}},
    {Opcode::kResetCounters, 0, 0, kAllModes, {}},
    {Opcode::kParamLoad,
     2,
     7,
     kAllModes,
     {integer(0, kParamCount - 1), real(-kValueMax, kValueMax), real(-kValueMax, kValueMax),
      real(-kValueMax, kValueMax), real(-kValueMax, kValueMax), real(-kValueMax, kValueMax),
      real(-kValueMax, kValueMax)}},
    {Opcode::kParamActivate, 0, 0, kAllModes, {}},
    {Opcode::kParamDiscard, 0, 0, kAllModes, {}},
    {Opcode::kParamDump, 0, 0, kAllModes, {}},
    {Opcode::kKeyRotate, 1, 1, kAllModes, {integer(1, kIdMax)}},
    {Opcode::kParamLoadIdentified, 0, 0, kAllModes, {}},
    {Opcode::kFaultDeclare, 2, 3, kAllModes, {integer(0, 15), integer(1, 3), real(0.01, 0.99)}},
    {Opcode::kFaultClear, 1, 1, kAllModes, {integer(-1, 15)}},
    {Opcode::kValve, 2, 2, kAllModes, {integer(0, 3), integer(0, 1)}},
    {Opcode::kIsolationInhibit, 1, 1, kAllModes, {integer(0, 1)}},
}};

constexpr bool rows_in_opcode_order() {
  for (int i = 0; i < kOpcodeCount; ++i) {
    if (static_cast<int>(kTable[i].opcode) != i) return false;
  }
  return true;
}
static_assert(rows_in_opcode_order(), "opcode table rows must be indexed by opcode");

}  // namespace

const std::array<OpcodeSpec, kOpcodeCount>& opcode_table() {
  return kTable;
}

const OpcodeSpec* find_opcode(std::int32_t opcode) {
  if (opcode < 0 || opcode >= kOpcodeCount) return nullptr;
  return &kTable[opcode];
}

CommandCheck check_command(const GroundCommand& cmd, gnc::Mode mode) {
  const OpcodeSpec* spec = find_opcode(cmd.opcode);
  if (spec == nullptr)
    return CommandCheck{RejectReason::kUnknownOpcode, cmd.opcode, "unknown opcode"};
  if (cmd.arg_count < spec->min_args || cmd.arg_count > spec->max_args) {
    return CommandCheck{RejectReason::kBadLength, cmd.arg_count, "wrong number of arguments"};
  }
  for (int i = 0; i < cmd.arg_count; ++i) {
    if (!std::isfinite(cmd.args[i])) {
      return CommandCheck{RejectReason::kArgNotFinite, i, "argument not finite"};
    }
  }
  for (int i = 0; i < cmd.arg_count; ++i) {
    const ArgRange& r = spec->ranges[i];
    const double v = cmd.args[i];
    if (v < r.lo || v > r.hi)
      return CommandCheck{RejectReason::kOutOfRange, i, "argument out of range"};
    if (r.integer && std::trunc(v) != v) {
      return CommandCheck{RejectReason::kOutOfRange, i, "argument must be an integer"};
    }
  }
  if ((spec->allowed_modes & mode_bit(mode)) == 0) {
    return CommandCheck{RejectReason::kNotAllowedInMode, 0, "opcode not allowed in this mode"};
  }
  return CommandCheck{};
}

int SequenceTracker::find(std::int32_t source) const {
  for (int i = 0; i < used_; ++i) {
    if (slots_[i].source == source) return i;
  }
  return -1;
}

RejectReason SequenceTracker::check(std::int32_t source, std::int64_t seq) const {
  const int i = find(source);
  const std::int64_t last = i < 0 ? 0 : slots_[i].last_seq;  // sequence numbers start at 1
  if (seq <= last) return RejectReason::kStaleSequence;
  return RejectReason::kNone;  // a new source takes a free slot or the least recently used one
}

void SequenceTracker::accept(std::int32_t source, std::int64_t seq) {
  int i = find(source);
  if (i < 0) {
    if (used_ < kMaxSources) {
      i = used_++;
    } else {
      i = 0;
      for (int k = 1; k < used_; ++k) {
        if (slots_[k].used_at < slots_[i].used_at) i = k;
      }
    }
    slots_[i].source = source;
  }
  slots_[i].last_seq = seq;
  slots_[i].used_at = ++clock_;
}

}  // namespace rocksteady::fsw
