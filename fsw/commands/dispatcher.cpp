#include "fsw/commands/dispatcher.hpp"

#include <cinttypes>

namespace rocksteady::fsw {

namespace {

CommandCheck reject(RejectReason r, std::int32_t detail, const char* text) {
  return CommandCheck{r, detail, text};
}

CommandCheck refused_transition(gnc::TransitionCheck c) {
  return reject(RejectReason::kNotAllowedInMode, static_cast<std::int32_t>(c), gnc::to_string(c));
}

}  // namespace

void CommandDispatcher::reset() {
  seqs_.reset();
  queue_.clear();
  accepted_ = 0;
  rejected_ = 0;
  last_seq_ = 0;
  last_opcode_ = -1;
  last_reject_ = RejectReason::kNone;
}

gnc::Mode CommandDispatcher::projected_mode(const DispatchContext& ctx) const {
  return queue_.projected_mode(ctx.core.mode());
}

bool CommandDispatcher::projected_trajectory(const DispatchContext& ctx) const {
  if (ctx.trajectory_loaded) return true;
  return queue_.has(ActionKind::kLoadTrajectory) && ctx.uplink.uplink().pending();
}

CommandAck CommandDispatcher::submit(const GroundCommand& cmd, const DispatchContext& ctx) {
  CommandAck ack;
  ack.seq = cmd.seq;
  ack.source = cmd.source;
  ack.opcode = cmd.opcode;
  CommandCheck r;
  if (!ctx.ready) {
    r = reject(RejectReason::kBusy, 0, "flight application not initialised");
  } else {
    // Lab mode: per-source sequence numbers; with keys the per-key counter window has already been
    // checked (and consumed) by the security layer.
    const RejectReason s = ctx.security.lab_mode() ? seqs_.check(cmd.source, cmd.seq)
                                                   : RejectReason::kNone;
    if (s == RejectReason::kStaleSequence) {
      r = reject(s, 0, "stale or repeated sequence number");
    } else if (s != RejectReason::kNone) {
      r = reject(s, 0, "too many command sources");
    } else {
      r = check_command(cmd, projected_mode(ctx));
      if (r.ok()) r = execute(cmd, ctx);
    }
  }
  ack.accepted = r.ok();
  ack.reason = r.reason;
  ack.detail = r.detail;
  ack.text = r.ok() ? "accepted" : r.text;

  const Opcode op = static_cast<Opcode>(cmd.opcode);
  const char* name = find_opcode(cmd.opcode) != nullptr ? to_string(op) : "opcode?";
  last_seq_ = cmd.seq;
  last_opcode_ = cmd.opcode;
  if (r.ok()) {
    if (ctx.security.lab_mode()) seqs_.accept(cmd.source, cmd.seq);
    ++accepted_;
    ctx.log.emit(Severity::kInfo, EventId::kCommandAccepted, cmd.opcode,
                 static_cast<std::int32_t>(cmd.seq), "%s seq %" PRId64 " from %" PRId32 " accepted",
                 name, cmd.seq, cmd.source);
  } else {
    ++rejected_;
    last_reject_ = r.reason;
    ctx.log.emit(Severity::kWarning, EventId::kCommandRejected, cmd.opcode,
                 static_cast<std::int32_t>(r.reason),
                 "%s (%" PRId32 ") seq %" PRId64 " rejected: %s: %s", name, cmd.opcode, cmd.seq,
                 to_string(r.reason), r.text);
  }
  return ack;
}

CommandAck CommandDispatcher::refuse(const GroundCommand& cmd, RejectReason reason,
                                     const char* text) {
  CommandAck ack;
  ack.seq = cmd.seq;
  ack.source = cmd.source;
  ack.opcode = cmd.opcode;
  ack.accepted = false;
  ack.reason = reason;
  ack.text = text;
  ++rejected_;
  return ack;
}

CommandCheck CommandDispatcher::enqueue_one(const Action& a) {
  if (!queue_.has_room(1)) return reject(RejectReason::kBusy, 0, "command queue full");
  queue_.push(a);
  return CommandCheck{};
}

CommandCheck CommandDispatcher::execute(const GroundCommand& cmd, const DispatchContext& ctx) {
  Action a;
  switch (static_cast<Opcode>(cmd.opcode)) {
    case Opcode::kNoop:
      return CommandCheck{};
    case Opcode::kSetMode:
      return execute_set_mode(cmd, ctx);
    case Opcode::kSetTarget: {
      const gnc::Vec3 q(cmd.args[0], cmd.args[1], cmd.args[2]);
      if (q.norm() > 1.0) return reject(RejectReason::kOutOfRange, 0, "target MRP norm above 1");
      a.kind = ActionKind::kTarget;
      a.target = q;
      return enqueue_one(a);
    }
    case Opcode::kSetLaw:
      return execute_set_law(cmd, ctx);
    case Opcode::kLoadTrajectory:
      return execute_load_trajectory(cmd, ctx);
    case Opcode::kAbortUplink:
      return ctx.uplink.abort(static_cast<std::int32_t>(cmd.args[0]), ctx.log);
    case Opcode::kResetCounters:
      a.kind = ActionKind::kResetCounters;
      return enqueue_one(a);
    case Opcode::kParamLoad:
      return ctx.params.load(cmd, ctx.log);
    case Opcode::kParamActivate: {
      const CommandCheck c = ctx.params.check_stage();
      if (!c.ok()) return c;
      if (!queue_.has_room(1)) return reject(RejectReason::kBusy, 0, "command queue full");
      ctx.params.stage();
      a.kind = ActionKind::kActivateParams;
      queue_.push(a);
      return CommandCheck{};
    }
    case Opcode::kParamDiscard:
      return ctx.params.discard(ctx.core.params(), ctx.log);
    case Opcode::kParamDump:
      return ctx.params.dump(ctx.core.params(), ctx.onboard_time, ctx.log);
    case Opcode::kKeyRotate: {
      const auto id = static_cast<std::int32_t>(cmd.args[0]);
      if (ctx.security.lab_mode()) {
        return reject(RejectReason::kNotAllowedInMode, 0, "lab mode: there are no command keys");
      }
      if (queue_.has(ActionKind::kRotateKey)) {
        return reject(RejectReason::kBusy, 0, "a key rotation is already pending");
      }
      if (!ctx.security.can_rotate_to(id)) {
        return reject(RejectReason::kOutOfRange, 0, "key id unknown or not newer than the active");
      }
      a.kind = ActionKind::kRotateKey;
      a.key_id = id;
      return enqueue_one(a);
    }
    case Opcode::kParamLoadIdentified:
      return ctx.params.load_identified(ctx.core, ctx.log);
    case Opcode::kFaultDeclare:
      a.kind = ActionKind::kFaultDeclare;
      a.thruster = static_cast<std::int8_t>(cmd.args[0]);
      a.fault = static_cast<gnc::FaultKind>(static_cast<int>(cmd.args[1]));
      // A degraded thruster is declared with the fraction of its thrust it still delivers; a
      // stuck one has none.
      if (a.fault == gnc::FaultKind::kDegraded && cmd.arg_count < 3) {
        return reject(RejectReason::kBadLength, 2, "a degraded thruster needs its strength factor");
      }
      if (a.fault != gnc::FaultKind::kDegraded && cmd.arg_count > 2) {
        return reject(RejectReason::kBadLength, 2, "only a degraded thruster has a strength factor");
      }
      if (a.fault == gnc::FaultKind::kDegraded) a.factor = cmd.args[2];
      return enqueue_one(a);
    case Opcode::kFaultClear:
      a.kind = ActionKind::kFaultDeclare;
      a.thruster = static_cast<std::int8_t>(cmd.args[0]);
      a.fault = gnc::FaultKind::kNone;
      return enqueue_one(a);
    case Opcode::kValve:
      a.kind = ActionKind::kValve;
      a.thruster = static_cast<std::int8_t>(cmd.args[0]);
      a.flag = cmd.args[1] != 0.0;
      return enqueue_one(a);
    case Opcode::kIsolationInhibit:
      a.kind = ActionKind::kIsolation;
      a.flag = cmd.args[0] != 0.0;
      return enqueue_one(a);
  }
  return reject(RejectReason::kUnknownOpcode, cmd.opcode, "unknown opcode");
}

CommandCheck CommandDispatcher::execute_set_mode(const GroundCommand& cmd,
                                                 const DispatchContext& ctx) {
  const auto to = static_cast<gnc::Mode>(static_cast<int>(cmd.args[0]));
  const gnc::TransitionContext tc{ctx.core.estimate_ready(), projected_trajectory(ctx),
                                  queue_.projected_law(ctx.core.params().law)};
  const gnc::TransitionCheck c = gnc::check_transition(projected_mode(ctx), to, tc);
  if (c != gnc::TransitionCheck::kOk) return refused_transition(c);
  Action a;
  a.kind = ActionKind::kMode;
  a.mode = to;
  return enqueue_one(a);
}

CommandCheck CommandDispatcher::execute_set_law(const GroundCommand& cmd,
                                                const DispatchContext& ctx) {
  const auto law = static_cast<gnc::LawId>(static_cast<int>(cmd.args[0]));
  const auto ref = cmd.arg_count > 1 ? static_cast<ReferenceId>(static_cast<int>(cmd.args[1]))
                                     : ReferenceId::kKeep;
  const gnc::Mode pm = projected_mode(ctx);
  bool change_mode = false;
  gnc::Mode to = pm;
  if (ref == ReferenceId::kDpdRef && pm != gnc::Mode::kDetumble && pm != gnc::Mode::kHold) {
    change_mode = true;
    to = gnc::Mode::kDetumble;  // Eq. (51): damping, then HOLD at omega_switch
  } else if (ref == ReferenceId::kFuelOptimal && pm != gnc::Mode::kTrack) {
    change_mode = true;
    to = gnc::Mode::kTrack;  // Eqs. (45)-(48)
  }
  const bool tracking_after = change_mode ? to == gnc::Mode::kTrack : pm == gnc::Mode::kTrack;
  if (law == gnc::LawId::kDpd && tracking_after) {
    return refused_transition(gnc::TransitionCheck::kLawCannotTrack);
  }
  if (change_mode) {
    const gnc::TransitionContext tc{ctx.core.estimate_ready(), projected_trajectory(ctx),
                                    law};
    const gnc::TransitionCheck c = gnc::check_transition(pm, to, tc);
    if (c != gnc::TransitionCheck::kOk) return refused_transition(c);
  }
  if (!queue_.has_room(change_mode ? 2 : 1)) {
    return reject(RejectReason::kBusy, 0, "command queue full");
  }
  Action law_action;
  law_action.kind = ActionKind::kLaw;
  law_action.law = law;
  Action mode_action;
  mode_action.kind = ActionKind::kMode;
  mode_action.mode = to;
  // The flight core applies a law before a mode request within one tick, and refuses D+PD while
  // tracking: leaving TRACK for D+PD goes mode first, law on the next tick.
  if (change_mode && pm == gnc::Mode::kTrack) {
    queue_.push(mode_action);
    queue_.push(law_action);
  } else {
    queue_.push(law_action);
    if (change_mode) queue_.push(mode_action);
  }
  return CommandCheck{};
}

CommandCheck CommandDispatcher::execute_load_trajectory(const GroundCommand& cmd,
                                                        const DispatchContext& ctx) {
  const auto id = static_cast<std::int32_t>(cmd.args[0]);
  const TrajectoryUplink& u = ctx.uplink.uplink();
  // The uplink's own checks first (unknown id, already pending, incomplete), then the queue.
  if (u.active() && u.upload_id() == id && !u.pending() && u.complete() && !queue_.has_room(1)) {
    return reject(RejectReason::kBusy, 0, "command queue full");
  }
  const CommandCheck c = ctx.uplink.request_load(id, ctx.core.params(), ctx.log);
  if (!c.ok()) return c;
  Action a;
  a.kind = ActionKind::kLoadTrajectory;
  a.upload_id = id;
  queue_.push(a);
  return CommandCheck{};
}

void CommandDispatcher::apply_pending(gnc::GncCommands& cmds, BoundaryActions& actions,
                                      EventLog& log) {
  cmds = gnc::GncCommands{};
  bool stop = false;
  while (!queue_.empty() && !stop) {
    const Action& a = queue_.front();
    const bool core_slot_used = cmds.has_mode_request || cmds.has_law || cmds.has_target;
    switch (a.kind) {
      case ActionKind::kActivateParams:
      case ActionKind::kLoadTrajectory:
      case ActionKind::kResetCounters:
      case ActionKind::kRotateKey:
        if (core_slot_used) {
          stop = true;
        } else if (a.kind == ActionKind::kRotateKey) {
          actions.rotate_key(a.key_id);
        } else if (a.kind == ActionKind::kActivateParams) {
          actions.activate_params();
        } else if (a.kind == ActionKind::kLoadTrajectory) {
          actions.load_trajectory(a.upload_id);
        } else {
          actions.reset_counters();
        }
        break;
      case ActionKind::kLaw:
        if (cmds.has_law || cmds.has_mode_request) {
          stop = true;
        } else {
          cmds.has_law = true;
          cmds.law = a.law;
        }
        break;
      case ActionKind::kMode:
        if (cmds.has_mode_request) {
          stop = true;
        } else {
          cmds.has_mode_request = true;
          cmds.mode_request = a.mode;
        }
        break;
      case ActionKind::kFaultDeclare:
        if (cmds.has_fault_declaration) {
          stop = true;
        } else {
          cmds.has_fault_declaration = true;
          cmds.fault_thruster = a.thruster;
          cmds.fault_kind = a.fault;
          cmds.fault_factor = a.factor;
        }
        break;
      case ActionKind::kValve:
        if (cmds.has_valve) {
          stop = true;
        } else {
          cmds.has_valve = true;
          cmds.valve_pod = a.thruster;
          cmds.valve_open = a.flag;
        }
        break;
      case ActionKind::kIsolation:
        if (cmds.has_isolation_inhibit) {
          stop = true;
        } else {
          cmds.has_isolation_inhibit = true;
          cmds.isolation_inhibited = a.flag;
        }
        break;
      case ActionKind::kTarget:
        if (cmds.has_target) {
          stop = true;
        } else {
          cmds.has_target = true;
          cmds.target_mrp = a.target;
          log.emit(Severity::kInfo, EventId::kTargetSet, 0, 0, "target q_final = [%.6g %.6g %.6g]",
                   a.target.x(), a.target.y(), a.target.z());
        }
        break;
    }
    if (!stop) queue_.pop();
  }
}

}  // namespace rocksteady::fsw
