// The ground-command contract as data: one row per opcode with its argument count, the modes it is
// allowed in and a range per argument. check_command() applies the row (everything that does not
// need the application's state); the application adds sequence numbers and per-opcode semantics.
#pragma once

#include <array>
#include <cstdint>

#include "fsw/interface.hpp"
#include "gnc/params.hpp"

namespace rocksteady::fsw {

using ModeMask = std::uint8_t;
constexpr ModeMask mode_bit(gnc::Mode m) {
  return static_cast<ModeMask>(1u << static_cast<int>(m));
}
inline constexpr ModeMask kAllModes = 0x1F;
inline constexpr ModeMask kAllButTrack =
    static_cast<ModeMask>(kAllModes & ~mode_bit(gnc::Mode::kTrack));

struct ArgRange {
  double lo{0.0};
  double hi{0.0};
  bool integer{false};
};

struct OpcodeSpec {
  Opcode opcode{Opcode::kNoop};
  std::int32_t min_args{0};
  std::int32_t max_args{0};
  ModeMask allowed_modes{kAllModes};
  std::array<ArgRange, kMaxCommandArgs> ranges{};  // ranges[i] for args[i], i < max_args
};

const std::array<OpcodeSpec, kOpcodeCount>& opcode_table();
// nullptr for an unknown opcode.
const OpcodeSpec* find_opcode(std::int32_t opcode);

struct CommandCheck {
  RejectReason reason{RejectReason::kNone};
  std::int32_t detail{0};
  const char* text{""};
  bool ok() const { return reason == RejectReason::kNone; }
};

// Unknown opcode, bad length, non-finite argument, out-of-range argument (detail = its index),
// not allowed in `mode`, in that order.
CommandCheck check_command(const GroundCommand& cmd, gnc::Mode mode);

// Lab mode only (with keys, fsw/auth's per-key counter windows replace it): per-source sequence
// numbers; a command's seq must be above the last accepted one of its source. A new source takes
// the least recently used slot when all are taken, so sources can never lock each other out (lab
// mode offers no protection against replay: anyone may send anything).
class SequenceTracker {
 public:
  static constexpr int kMaxSources = 16;
  // kNone or kStaleSequence.
  RejectReason check(std::int32_t source, std::int64_t seq) const;
  void accept(std::int32_t source, std::int64_t seq);
  void reset() { used_ = 0; }

 private:
  int find(std::int32_t source) const;
  struct Slot {
    std::int32_t source{0};
    std::int64_t last_seq{0};
    std::uint64_t used_at{0};
  };
  std::array<Slot, kMaxSources> slots_{};
  int used_{0};
  std::uint64_t clock_{0};
};

}  // namespace rocksteady::fsw
