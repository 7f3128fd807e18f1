// The command dispatcher (F Prime's command contract): every ground command is checked now against
// the opcode table, its source's sequence numbers and the state it would meet (the projected mode,
// law and trajectory once everything queued is applied), answered with an acknowledgement, evented
// and counted. Accepted commands that change the flight state wait in the action queue and take
// effect at the start of the next GNC tick, in submission order.
#pragma once

#include <cstdint>

#include "fsw/auth/auth.hpp"
#include "fsw/commands/action_queue.hpp"
#include "fsw/commands/command_table.hpp"
#include "fsw/events/event_log.hpp"
#include "fsw/params/param_lifecycle.hpp"
#include "fsw/uplink/uplink_lifecycle.hpp"
#include "gnc/gnc.hpp"

namespace rocksteady::fsw {

// What a command is checked against, and the parts it acts on at once.
struct DispatchContext {
  bool ready;  // false: the application is not initialised (everything is refused)
  const gnc::Gnc& core;
  bool trajectory_loaded;
  double onboard_time;
  ParamLifecycle& params;
  UplinkLifecycle& uplink;
  EventLog& log;
  // The command security layer. Authentication happens before submit(); in lab mode (nothing is
  // authenticated) the dispatcher keeps per-source sequence numbers instead of per-key counters.
  const auth::CommandSecurity& security;
};

// The actions that happen at the tick boundary before the flight core runs.
class BoundaryActions {
 public:
  virtual void activate_params() = 0;
  virtual void load_trajectory(std::int32_t upload_id) = 0;
  virtual void reset_counters() = 0;
  virtual void rotate_key(std::int32_t key_id) = 0;

 protected:
  BoundaryActions() = default;
  BoundaryActions(const BoundaryActions&) = default;
  BoundaryActions& operator=(const BoundaryActions&) = default;
  ~BoundaryActions() = default;
};

class CommandDispatcher {
 public:
  void reset();

  CommandAck submit(const GroundCommand& cmd, const DispatchContext& ctx);
  // A command that failed authentication: answered and counted, nothing else changes (no sequence
  // state, no queue, no last-command telemetry).
  CommandAck refuse(const GroundCommand& cmd, RejectReason reason, const char* text);

  // At the start of a GNC tick: the longest prefix of the queue that keeps submission order within
  // one tick (the core takes one mode request, one law and one target per tick and applies the law
  // before the mode; boundary actions run before the core and not after a core request).
  void apply_pending(gnc::GncCommands& cmds, BoundaryActions& actions, EventLog& log);

  int pending() const { return queue_.size(); }
  std::uint32_t accepted() const { return accepted_; }
  std::uint32_t rejected() const { return rejected_; }
  std::int64_t last_seq() const { return last_seq_; }
  std::int32_t last_opcode() const { return last_opcode_; }
  RejectReason last_reject() const { return last_reject_; }
  void reset_counters() {
    accepted_ = 0;
    rejected_ = 0;
    last_reject_ = RejectReason::kNone;
  }

 private:
  CommandCheck execute(const GroundCommand& cmd, const DispatchContext& ctx);
  CommandCheck execute_set_mode(const GroundCommand& cmd, const DispatchContext& ctx);
  CommandCheck execute_set_law(const GroundCommand& cmd, const DispatchContext& ctx);
  CommandCheck execute_load_trajectory(const GroundCommand& cmd, const DispatchContext& ctx);
  CommandCheck enqueue_one(const Action& a);
  gnc::Mode projected_mode(const DispatchContext& ctx) const;
  bool projected_trajectory(const DispatchContext& ctx) const;

  SequenceTracker seqs_{};
  ActionQueue queue_{};
  std::uint32_t accepted_{0};
  std::uint32_t rejected_{0};
  std::int64_t last_seq_{0};
  std::int32_t last_opcode_{-1};
  RejectReason last_reject_{RejectReason::kNone};
};

}  // namespace rocksteady::fsw
