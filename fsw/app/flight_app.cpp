#include "fsw/app/flight_app.hpp"

#include <cinttypes>
#include <cmath>
#include <cstdarg>
#include <cstdio>

namespace rocksteady::fsw {

namespace {

constexpr double kNsPerS = 1e9;

std::int64_t to_ns(double s) {
  return static_cast<std::int64_t>(std::llround(s * kNsPerS));
}

CommandCheck reject(RejectReason r, std::int32_t detail, const char* text) {
  return CommandCheck{r, detail, text};
}

}  // namespace

// ----------------------------------------------------------------------------------------------
// Set-up
// ----------------------------------------------------------------------------------------------

InitResult FlightApp::init(const FlightConfig& config, const Clock& clock) {
  const ConfigCheck e = exec_.configure(config.executive);
  if (!e.ok) return InitResult{false, e.field, e.reason};
  if (std::fabs(exec_.gnc_period_s() - config.gnc.dt) > 1e-9 * config.gnc.dt) {
    return InitResult{false, "executive.gnc_divider",
                      "the GNC rate group period (gnc_divider / base_rate_hz) differs from gnc.dt"};
  }
  if (!std::isfinite(config.sensor_event_interval_s) || config.sensor_event_interval_s < 0.0) {
    return InitResult{false, "sensor_event_interval_s", "must be >= 0"};
  }
  if (!std::isfinite(config.max_frame_time_jump_s) || config.max_frame_time_jump_s <= 0.0) {
    return InitResult{false, "max_frame_time_jump_s", "must be positive"};
  }
  const gnc::ParamCheck p = gnc_.init(config.gnc);
  if (!p.ok) return InitResult{false, p.field, p.reason};
  config_ = config;
  clock_ = &clock;
  reset_state();
  return InitResult{};
}

void FlightApp::reset_state() {
  cmds_ = gnc::GncCommands{};
  seqs_.reset();
  table_.reset(gnc_.params());
  uplink_.clear();
  events_ = EventQueue{};
  action_head_ = 0;
  action_count_ = 0;
  latest_frame_ = gnc::SensorSample{};
  fresh_frame_ = false;
  have_frame_t_ = false;
  last_frame_t_ = 0.0;
  consecutive_frame_rejects_ = 0;
  have_gnc_t_ = false;
  last_gnc_t_ = 0.0;
  gnc_cycles_missed_ = 0;
  consecutive_slips_ = 0;
  overrun_request_ = false;
  next_index_ = 0;
  cmd_accepted_ = 0;
  cmd_rejected_ = 0;
  last_cmd_seq_ = 0;
  last_cmd_opcode_ = -1;
  last_reject_ = RejectReason::kNone;
  event_seq_ = 0;
  frames_accepted_ = 0;
  frames_rejected_ = 0;
  frameless_ticks_ = 0;
  sensor_rejects_base_ = 0;
  table_loads_ = 0;
  table_activations_ = 0;
  chunks_rejected_ = 0;
  trajectories_loaded_ = 0;
  trajectory_loaded_ = false;
  const std::int64_t interval = to_ns(config_.sensor_event_interval_s);
  sensor_throttle_.configure(interval);
  sensor_throttle_.reset();
  frame_throttle_.configure(interval);
  frame_throttle_.reset();
  missed_throttle_.configure(to_ns(config_.executive.slip_event_interval_s));
  missed_throttle_.reset();
}

// ----------------------------------------------------------------------------------------------
// Events
// ----------------------------------------------------------------------------------------------

void FlightApp::emit(Severity sev, EventId id, std::int32_t arg0, std::int32_t arg1,
                     const char* fmt, ...) {
  Event e;
  e.seq = event_seq_++;
  e.t = last_gnc_t_;
  e.severity = sev;
  e.id = id;
  e.arg0 = arg0;
  e.arg1 = arg1;
  va_list ap;
  va_start(ap, fmt);
  std::vsnprintf(e.text.data(), e.text.size(), fmt, ap);  // truncates, never overflows
  va_end(ap);
  events_.push(e);
}

// ----------------------------------------------------------------------------------------------
// Ticks
// ----------------------------------------------------------------------------------------------

void FlightApp::tick(const Tick& tick, const gnc::SensorSample* frame, Outputs& out) {
  run_tick(tick, frame, nullptr, out);
}

void FlightApp::gnc_tick(const gnc::SensorSample& sample, Outputs& out) {
  out.gnc_ran = false;
  out.housekeeping_ran = false;
  if (clock_ == nullptr) return;
  run_tick(Tick{next_index_, clock_->now_ns(), 0}, &sample, nullptr, out);
}

void FlightApp::gnc_tick_without_frame(double t, Outputs& out) {
  out.gnc_ran = false;
  out.housekeeping_ran = false;
  if (clock_ == nullptr) return;
  run_tick(Tick{next_index_, clock_->now_ns(), 0}, nullptr, std::isfinite(t) ? &t : nullptr, out);
}

void FlightApp::run_tick(const Tick& tick, const gnc::SensorSample* frame,
                         const double* t_frameless, Outputs& out) {
  out.gnc_ran = false;
  out.housekeeping_ran = false;
  if (clock_ == nullptr) return;  // not initialised: nothing runs, nothing is commanded
  const TickPlan plan = exec_.plan(tick);
  if (!plan.valid) return;
  next_index_ = tick.index + 1;
  if (plan.base_missed > 0) {
    std::uint32_t suppressed = 0;
    if (missed_throttle_.allow(clock_->now_ns(), suppressed)) {
      emit(Severity::kWarning, EventId::kMissedTicks, static_cast<std::int32_t>(plan.base_missed),
           static_cast<std::int32_t>(suppressed),
           "%" PRIu32 " base tick(s) missed (%" PRIu32 " report(s) suppressed)", plan.base_missed,
           suppressed);
    }
  }
  gnc_cycles_missed_ += plan.missed[static_cast<int>(GroupId::kGnc)];
  if (frame != nullptr) {
    latest_frame_ = *frame;
    fresh_frame_ = true;
  }
  if (plan.due[static_cast<int>(GroupId::kGnc)]) run_gnc(tick, t_frameless, out);
  if (plan.due[static_cast<int>(GroupId::kHousekeeping)]) run_housekeeping(tick, out);
}

void FlightApp::report_slip(GroupId g, const SlipReport& s) {
  if (!s.report) return;
  emit(Severity::kWarning, EventId::kSlip, static_cast<std::int32_t>(g),
       static_cast<std::int32_t>(s.suppressed),
       "%s slip: previous cycle ended %.3f ms after this tick was due (%" PRIu32 " suppressed)",
       to_string(g), static_cast<double>(s.late_ns) * 1e-6, s.suppressed);
}

double FlightApp::scheduled_time() const {
  if (!have_gnc_t_) return 0.0;
  return last_gnc_t_ + exec_.gnc_period_s() * (1.0 + static_cast<double>(gnc_cycles_missed_));
}

bool FlightApp::accept_frame_time(double t) {
  bool ok = std::isfinite(t);
  const char* why = "non-finite time";
  if (ok && have_frame_t_) {
    if (!(t > last_frame_t_)) {
      ok = false;
      why = "time not after the previous frame";
    } else if (t - scheduled_time() > config_.max_frame_time_jump_s) {
      ok = false;
      why = "time jumps ahead of the on-board time";
    }
    if (!ok && std::isfinite(t) && consecutive_frame_rejects_ >= config_.frame_resync_count) {
      emit(Severity::kWarning, EventId::kFrameRejected, 0, 0,
           "frame time base re-synchronised at t=%.6g s after %" PRIu32 " rejected frames", t,
           consecutive_frame_rejects_);
      ok = true;
    }
  }
  if (!ok) {
    ++frames_rejected_;
    ++consecutive_frame_rejects_;
    std::uint32_t suppressed = 0;
    if (frame_throttle_.allow(clock_->now_ns(), suppressed)) {
      emit(Severity::kWarning, EventId::kFrameRejected, static_cast<std::int32_t>(frames_rejected_),
           static_cast<std::int32_t>(suppressed), "sensor frame rejected: %s (%" PRIu32 " so far)",
           why, frames_rejected_);
    }
    return false;
  }
  have_frame_t_ = true;
  last_frame_t_ = t;
  consecutive_frame_rejects_ = 0;
  ++frames_accepted_;
  return true;
}

void FlightApp::run_gnc(const Tick& tick, const double* t_frameless, Outputs& out) {
  RateGroup& group = exec_.group(GroupId::kGnc);
  const SlipReport slip = group.begin(tick.start_ns, clock_->now_ns());
  report_slip(GroupId::kGnc, slip);
  consecutive_slips_ = slip.slipped ? consecutive_slips_ + 1 : 0;

  // 1. Accepted commands take effect at the tick boundary.
  apply_pending(cmds_);

  // Repeated overruns: the loop cannot keep its rate, stop actuating (DESIGN.md, SAFE).
  overrun_request_ = false;
  if (config_.overrun_safe_slips > 0 && consecutive_slips_ >= config_.overrun_safe_slips &&
      gnc_.mode() != gnc::Mode::kSafe) {
    cmds_.has_mode_request = true;
    cmds_.mode_request = gnc::Mode::kSafe;
    overrun_request_ = true;
    emit(Severity::kError, EventId::kOverrunSafe, static_cast<std::int32_t>(consecutive_slips_), 0,
         "%" PRIu32 " consecutive GNC overruns: -> SAFE, thrusters off", consecutive_slips_);
  }

  // 2. The sample: the fresh frame if its time is sane, otherwise an invalid sample at the
  //    scheduled time (the flight core counts the sensor age and goes to SAFE on timeout).
  gnc::SensorSample sample;
  const bool have_frame = fresh_frame_ && accept_frame_time(latest_frame_.t);
  fresh_frame_ = false;
  if (have_frame) {
    sample = latest_frame_;
  } else {
    sample.t = t_frameless != nullptr ? *t_frameless : scheduled_time();
    sample.gyro_valid = false;
    sample.star_valid = false;
    ++frameless_ticks_;
  }

  // 3. The flight core.
  const gnc::LawId law_before = gnc_.params().law;
  gnc_.step(sample, cmds_, gout_);
  last_gnc_t_ = sample.t;
  have_gnc_t_ = true;
  gnc_cycles_missed_ = 0;
  trajectory_loaded_ = gout_.telemetry.trajectory_loaded;
  if (gnc_.params().law != law_before) {
    emit(Severity::kInfo, EventId::kLawChanged, static_cast<std::int32_t>(law_before),
         static_cast<std::int32_t>(gnc_.params().law), "control law %s -> %s",
         gnc::to_string(law_before), gnc::to_string(gnc_.params().law));
  }
  translate_core_events();

  out.command = gout_.command;
  out.telemetry = gout_.telemetry;
  out.gnc_ran = true;
  group.end(clock_->now_ns());
}

void FlightApp::translate_core_events() {
  for (int i = 0; i < gout_.events.count; ++i) {
    const gnc::ModeEvent& e = gout_.events.items[i];
    const auto from = static_cast<std::int32_t>(e.from);
    const auto to = static_cast<std::int32_t>(e.to);
    switch (e.id) {
      case gnc::EventId::kModeChanged:
        emit(Severity::kInfo, EventId::kModeChanged, from, to, "mode %s -> %s (%s)",
             gnc::to_string(e.from), gnc::to_string(e.to),
             overrun_request_ ? "overrun protection" : "ground request");
        break;
      case gnc::EventId::kAutoHold:
        emit(Severity::kInfo, EventId::kAutoHold, from, to,
             "mode %s -> %s: |omega| <= omega_switch", gnc::to_string(e.from),
             gnc::to_string(e.to));
        break;
      case gnc::EventId::kSensorTimeout:
        emit(Severity::kError, EventId::kSensorTimeout, from, to,
             "mode %s -> SAFE: no valid sensor sample for %.3g s, thrusters off",
             gnc::to_string(e.from), gnc_.params().mode.sensor_timeout_s);
        break;
      case gnc::EventId::kNonFiniteState:
        emit(Severity::kError, EventId::kNonFiniteState, from, to,
             "mode %s -> SAFE: non-finite estimate or command, thrusters off",
             gnc::to_string(e.from));
        break;
      case gnc::EventId::kRequestRejected:
        emit(Severity::kWarning, EventId::kModeRequestRejected, to,
             static_cast<std::int32_t>(e.reason), "mode request %s rejected at the tick: %s",
             gnc::to_string(e.to), gnc::to_string(e.reason));
        break;
      case gnc::EventId::kSensorRejected: {
        std::uint32_t suppressed = 0;
        if (sensor_throttle_.allow(clock_->now_ns(), suppressed)) {
          const std::uint32_t total = gout_.telemetry.sensor_rejects - sensor_rejects_base_;
          emit(Severity::kWarning, EventId::kSensorRejected, static_cast<std::int32_t>(total),
               static_cast<std::int32_t>(suppressed),
               "sensor sample rejected: invalid, non-finite or out of range (%" PRIu32 " so far)",
               total);
        }
        break;
      }
    }
  }
}

void FlightApp::run_housekeeping(const Tick& tick, Outputs& out) {
  RateGroup& group = exec_.group(GroupId::kHousekeeping);
  report_slip(GroupId::kHousekeeping, group.begin(tick.start_ns, clock_->now_ns()));
  out.health = health();
  out.housekeeping_ran = true;
  group.end(clock_->now_ns());
}

HealthTelemetry FlightApp::health() const {
  HealthTelemetry h;
  h.t = last_gnc_t_;
  h.base_ticks = exec_.base_ticks();
  h.base_missed = exec_.base_missed();
  h.mode = gnc_.mode();
  h.law = gnc_.params().law;
  h.gnc = exec_.group(GroupId::kGnc).stats();
  h.housekeeping = exec_.group(GroupId::kHousekeeping).stats();
  h.cmd_accepted = cmd_accepted_;
  h.cmd_rejected = cmd_rejected_;
  h.last_cmd_seq = last_cmd_seq_;
  h.last_cmd_opcode = last_cmd_opcode_;
  h.last_reject = last_reject_;
  h.cmd_pending = static_cast<std::uint32_t>(action_count_);
  h.events_emitted = static_cast<std::uint32_t>(event_seq_);
  h.events_dropped = events_.dropped();
  h.frames_accepted = frames_accepted_;
  h.frames_rejected = frames_rejected_;
  h.frameless_ticks = frameless_ticks_;
  h.sensor_rejects = gout_.telemetry.sensor_rejects - sensor_rejects_base_;
  h.table_loads = table_loads_;
  h.table_activations = table_activations_;
  h.table_loaded = table_.loaded();
  h.uplink_id = uplink_.upload_id();
  h.uplink_chunks_received = uplink_.chunks_received();
  h.uplink_chunk_count = uplink_.chunk_count();
  h.uplink_chunks_rejected = chunks_rejected_;
  h.trajectories_loaded = trajectories_loaded_;
  h.trajectory_loaded = trajectory_loaded_;
  return h;
}

// ----------------------------------------------------------------------------------------------
// Commands
// ----------------------------------------------------------------------------------------------

CommandAck FlightApp::submit(const GroundCommand& cmd) {
  CommandAck ack;
  ack.seq = cmd.seq;
  ack.source = cmd.source;
  ack.opcode = cmd.opcode;
  CommandCheck r;
  if (clock_ == nullptr) {
    r = reject(RejectReason::kBusy, 0, "flight application not initialised");
  } else {
    const RejectReason s = seqs_.check(cmd.source, cmd.seq);
    if (s == RejectReason::kStaleSequence) {
      r = reject(s, 0, "stale or repeated sequence number");
    } else if (s != RejectReason::kNone) {
      r = reject(s, 0, "too many command sources");
    } else {
      r = check_command(cmd, projected_mode());
      if (r.ok()) r = execute(cmd);
    }
  }
  ack.accepted = r.ok();
  ack.reason = r.reason;
  ack.detail = r.detail;
  ack.text = r.ok() ? "accepted" : r.text;

  const Opcode op = static_cast<Opcode>(cmd.opcode);
  const char* name = find_opcode(cmd.opcode) != nullptr ? to_string(op) : "opcode?";
  last_cmd_seq_ = cmd.seq;
  last_cmd_opcode_ = cmd.opcode;
  if (r.ok()) {
    seqs_.accept(cmd.source, cmd.seq);
    ++cmd_accepted_;
    emit(Severity::kInfo, EventId::kCommandAccepted, cmd.opcode, static_cast<std::int32_t>(cmd.seq),
         "%s seq %" PRId64 " from %" PRId32 " accepted", name, cmd.seq, cmd.source);
  } else {
    ++cmd_rejected_;
    last_reject_ = r.reason;
    emit(Severity::kWarning, EventId::kCommandRejected, cmd.opcode,
         static_cast<std::int32_t>(r.reason), "%s (%" PRId32 ") seq %" PRId64 " rejected: %s: %s",
         name, cmd.opcode, cmd.seq, to_string(r.reason), r.text);
  }
  return ack;
}

CommandCheck FlightApp::execute(const GroundCommand& cmd) {
  const auto op = static_cast<Opcode>(cmd.opcode);
  switch (op) {
    case Opcode::kNoop:
      return CommandCheck{};

    case Opcode::kSetMode: {
      const auto to = static_cast<gnc::Mode>(static_cast<int>(cmd.args[0]));
      const gnc::TransitionContext ctx{gnc_.estimator().initialised(), projected_trajectory(),
                                       projected_law()};
      const gnc::TransitionCheck c = gnc::check_transition(projected_mode(), to, ctx);
      if (c != gnc::TransitionCheck::kOk) {
        return reject(RejectReason::kNotAllowedInMode, static_cast<std::int32_t>(c),
                      gnc::to_string(c));
      }
      if (!queue_has_room(1)) return reject(RejectReason::kBusy, 0, "command queue full");
      Action a;
      a.kind = ActionKind::kMode;
      a.mode = to;
      enqueue(a);
      return CommandCheck{};
    }

    case Opcode::kSetTarget: {
      const gnc::Vec3 q(cmd.args[0], cmd.args[1], cmd.args[2]);
      if (q.norm() > 1.0) return reject(RejectReason::kOutOfRange, 0, "target MRP norm above 1");
      if (!queue_has_room(1)) return reject(RejectReason::kBusy, 0, "command queue full");
      Action a;
      a.kind = ActionKind::kTarget;
      a.target = q;
      enqueue(a);
      return CommandCheck{};
    }

    case Opcode::kSetLaw:
      return execute_set_law(cmd);

    case Opcode::kLoadTrajectory:
      return execute_load_trajectory(cmd);

    case Opcode::kAbortUplink: {
      const auto id = static_cast<std::int32_t>(cmd.args[0]);
      if (!uplink_.active() || uplink_.upload_id() != id) {
        return reject(RejectReason::kOutOfRange, 0, "no uplink with that id");
      }
      emit(Severity::kInfo, EventId::kUplinkAbandoned, id, uplink_.chunks_received(),
           "trajectory uplink %" PRId32 " aborted by ground (%" PRId32 " of %" PRId32 " chunks)",
           id, uplink_.chunks_received(), uplink_.chunk_count());
      uplink_.clear();  // a queued hand-over of this uplink finds nothing pending and is skipped
      return CommandCheck{};
    }

    case Opcode::kResetCounters: {
      if (!queue_has_room(1)) return reject(RejectReason::kBusy, 0, "command queue full");
      Action a;
      a.kind = ActionKind::kResetCounters;
      enqueue(a);
      return CommandCheck{};
    }

    case Opcode::kParamLoad: {
      const auto id = static_cast<std::int32_t>(cmd.args[0]);
      const ParamLoadResult r = table_.load(id, &cmd.args[1], cmd.arg_count - 1);
      if (!r.ok()) {
        if (r.reason == RejectReason::kInvalidTable) {
          emit(Severity::kWarning, EventId::kTableActivationFailed, id, 0,
               "parameter load %s rejected: %s %s", param_specs()[id].name, r.text, r.why);
        }
        return reject(r.reason, r.detail, r.text);
      }
      ++table_loads_;
      emit(Severity::kInfo, EventId::kTableLoaded, id, cmd.arg_count - 1,
           "parameter %s loaded into the inactive table", param_specs()[id].name);
      return CommandCheck{};
    }

    case Opcode::kParamActivate: {
      if (table_.staged())
        return reject(RejectReason::kBusy, 0, "an activation is already pending");
      if (!table_.loaded()) return reject(RejectReason::kNothingToActivate, 0, "no parameter load");
      if (!queue_has_room(1)) return reject(RejectReason::kBusy, 0, "command queue full");
      table_.stage();
      Action a;
      a.kind = ActionKind::kActivateParams;
      enqueue(a);
      return CommandCheck{};
    }

    case Opcode::kParamDiscard: {
      if (!table_.loaded()) return reject(RejectReason::kNothingToActivate, 0, "no parameter load");
      table_.discard(gnc_.params());
      emit(Severity::kInfo, EventId::kTableDiscarded, 0, 0,
           "inactive parameter table discarded (copy of the active one)");
      return CommandCheck{};
    }
  }
  return reject(RejectReason::kUnknownOpcode, cmd.opcode, "unknown opcode");
}

CommandCheck FlightApp::execute_set_law(const GroundCommand& cmd) {
  const auto law = static_cast<gnc::LawId>(static_cast<int>(cmd.args[0]));
  const auto ref = cmd.arg_count > 1 ? static_cast<ReferenceId>(static_cast<int>(cmd.args[1]))
                                     : ReferenceId::kKeep;
  const gnc::Mode pm = projected_mode();
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
    const auto c = gnc::TransitionCheck::kLawCannotTrack;
    return reject(RejectReason::kNotAllowedInMode, static_cast<std::int32_t>(c), gnc::to_string(c));
  }
  if (change_mode) {
    const gnc::TransitionContext ctx{gnc_.estimator().initialised(), projected_trajectory(), law};
    const gnc::TransitionCheck c = gnc::check_transition(pm, to, ctx);
    if (c != gnc::TransitionCheck::kOk) {
      return reject(RejectReason::kNotAllowedInMode, static_cast<std::int32_t>(c),
                    gnc::to_string(c));
    }
  }
  if (!queue_has_room(change_mode ? 2 : 1)) {
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
    enqueue(mode_action);
    enqueue(law_action);
  } else {
    enqueue(law_action);
    if (change_mode) enqueue(mode_action);
  }
  return CommandCheck{};
}

CommandCheck FlightApp::execute_load_trajectory(const GroundCommand& cmd) {
  const auto id = static_cast<std::int32_t>(cmd.args[0]);
  if (!uplink_.active() || uplink_.upload_id() != id) {
    return reject(RejectReason::kOutOfRange, 0, "no uplink with that id");
  }
  if (uplink_.pending()) {
    return reject(RejectReason::kBusy, 0, "this table already waits for the tick boundary");
  }
  if (!uplink_.complete()) {
    return reject(RejectReason::kUploadIncomplete, uplink_.chunks_received(),
                  "chunks missing: resend them, then load");
  }
  if (!queue_has_room(1)) return reject(RejectReason::kBusy, 0, "command queue full");
  const gnc::TrajectoryError e = uplink_.finalize(gnc_.params().guidance.eps_trans);
  if (e != gnc::TrajectoryError::kOk) {
    emit(Severity::kWarning, EventId::kTrajectoryRejected, id, static_cast<std::int32_t>(e),
         "trajectory uplink %" PRId32 " rejected: %s; uplink discarded", id, gnc::to_string(e));
    uplink_.clear();
    return reject(RejectReason::kTrajectoryRejected, static_cast<std::int32_t>(e),
                  gnc::to_string(e));
  }
  uplink_.set_pending(true);
  Action a;
  a.kind = ActionKind::kLoadTrajectory;
  a.upload_id = id;
  enqueue(a);
  return CommandCheck{};
}

ChunkStatus FlightApp::receive_chunk(const TrajectoryChunk& chunk) {
  const ChunkResult r = uplink_.receive(chunk);
  if (r.status != ChunkStatus::kStored) {
    ++chunks_rejected_;
    emit(Severity::kWarning, EventId::kChunkRejected, chunk.upload_id,
         static_cast<std::int32_t>(r.status), "uplink %" PRId32 " chunk %" PRId32 " rejected: %s",
         chunk.upload_id, chunk.chunk_index, to_string(r.status));
    return r.status;
  }
  if (r.abandoned) {
    emit(Severity::kWarning, EventId::kUplinkAbandoned, r.abandoned_id, r.abandoned_received,
         "trajectory uplink %" PRId32 " abandoned for %" PRId32 " (%" PRId32 " chunks received)",
         r.abandoned_id, chunk.upload_id, r.abandoned_received);
  }
  if (r.started) {
    emit(Severity::kInfo, EventId::kUplinkStarted, chunk.upload_id, chunk.chunk_count,
         "trajectory uplink %" PRId32 " started: %" PRId32 " samples in %" PRId32 " chunks",
         chunk.upload_id, chunk.total_samples, chunk.chunk_count);
  }
  if (r.completed) {
    emit(Severity::kInfo, EventId::kUplinkComplete, chunk.upload_id, chunk.chunk_count,
         "trajectory uplink %" PRId32 " complete: ready to load", chunk.upload_id);
  }
  return r.status;
}

// ----------------------------------------------------------------------------------------------
// The pending queue: accepted commands, applied at the start of a GNC tick
// ----------------------------------------------------------------------------------------------

void FlightApp::enqueue(const Action& a) {
  actions_[(action_head_ + action_count_) % kActionCapacity] = a;
  ++action_count_;
}

gnc::Mode FlightApp::projected_mode() const {
  gnc::Mode m = gnc_.mode();
  for (int i = 0; i < action_count_; ++i) {
    const Action& a = actions_[(action_head_ + i) % kActionCapacity];
    if (a.kind == ActionKind::kMode) m = a.mode;
  }
  return m;
}

gnc::LawId FlightApp::projected_law() const {
  gnc::LawId l = gnc_.params().law;
  for (int i = 0; i < action_count_; ++i) {
    const Action& a = actions_[(action_head_ + i) % kActionCapacity];
    if (a.kind == ActionKind::kLaw) l = a.law;
  }
  return l;
}

bool FlightApp::projected_trajectory() const {
  if (trajectory_loaded_) return true;
  for (int i = 0; i < action_count_; ++i) {
    const Action& a = actions_[(action_head_ + i) % kActionCapacity];
    if (a.kind == ActionKind::kLoadTrajectory && uplink_.pending()) return true;
  }
  return false;
}

// Applies the longest prefix of the queue that keeps submission order within one tick: the flight
// core takes one mode request, one law and one target per tick and applies the law before the
// mode; table activation, trajectory hand-over and counter resets happen before the core runs.
void FlightApp::apply_pending(gnc::GncCommands& cmds) {
  cmds = gnc::GncCommands{};
  bool stop = false;
  while (action_count_ > 0 && !stop) {
    const Action& a = actions_[action_head_];
    const bool core_slot_used = cmds.has_mode_request || cmds.has_law || cmds.has_target;
    switch (a.kind) {
      case ActionKind::kActivateParams:
      case ActionKind::kLoadTrajectory:
      case ActionKind::kResetCounters:
        if (core_slot_used) {
          stop = true;
        } else {
          apply_pre_step(a);
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
      case ActionKind::kTarget:
        if (cmds.has_target) {
          stop = true;
        } else {
          cmds.has_target = true;
          cmds.target_mrp = a.target;
          emit(Severity::kInfo, EventId::kTargetSet, 0, 0, "target q_final = [%.6g %.6g %.6g]",
               a.target.x(), a.target.y(), a.target.z());
        }
        break;
    }
    if (!stop) {
      action_head_ = (action_head_ + 1) % kActionCapacity;
      --action_count_;
    }
  }
}

void FlightApp::apply_pre_step(const Action& a) {
  switch (a.kind) {
    case ActionKind::kActivateParams: {
      activation_ = table_.staged_table();
      activation_.law = gnc_.params().law;  // the law is selected by command, not by the table
      const gnc::ParamCheck c = gnc_.set_params(activation_);
      if (c.ok) {
        ++table_activations_;
        table_.activated(gnc_.params());
        emit(Severity::kInfo, EventId::kTableActivated,
             static_cast<std::int32_t>(table_activations_), 0,
             "parameter table activated at the tick boundary");
      } else {
        table_.activation_failed();
        emit(Severity::kError, EventId::kTableActivationFailed, 0, 0,
             "parameter table activation failed: %s %s", c.field, c.reason);
      }
      break;
    }
    case ActionKind::kLoadTrajectory: {
      if (!uplink_.pending() || uplink_.upload_id() != a.upload_id) break;  // aborted meanwhile
      const gnc::TrajectoryError e = gnc_.load_trajectory(uplink_.table());
      if (e == gnc::TrajectoryError::kOk) {
        ++trajectories_loaded_;
        trajectory_loaded_ = true;
        emit(Severity::kInfo, EventId::kTrajectoryLoaded, a.upload_id, uplink_.table().count,
             "trajectory uplink %" PRId32 " loaded: %d samples", a.upload_id,
             uplink_.table().count);
      } else {
        emit(Severity::kError, EventId::kTrajectoryRejected, a.upload_id,
             static_cast<std::int32_t>(e), "trajectory uplink %" PRId32 " refused by the core: %s",
             a.upload_id, gnc::to_string(e));
      }
      uplink_.clear();
      break;
    }
    case ActionKind::kResetCounters:
      reset_counters();
      break;
    case ActionKind::kMode:
    case ActionKind::kLaw:
    case ActionKind::kTarget:
      break;
  }
}

void FlightApp::reset_counters() {
  cmd_accepted_ = 0;
  cmd_rejected_ = 0;
  last_reject_ = RejectReason::kNone;
  frames_rejected_ = 0;
  frameless_ticks_ = 0;
  sensor_rejects_base_ = gout_.telemetry.sensor_rejects;
  chunks_rejected_ = 0;
  exec_.reset_counters();
  events_.reset_dropped();
  emit(Severity::kInfo, EventId::kCountersReset, 0, 0, "counters reset");
}

}  // namespace rocksteady::fsw
