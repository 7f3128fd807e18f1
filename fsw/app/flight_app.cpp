#include "fsw/app/flight_app.hpp"

#include <cinttypes>
#include <cmath>

#include "gnc/units.hpp"

namespace rocksteady::fsw {

namespace {

std::int64_t to_ns(double s) {
  return static_cast<std::int64_t>(std::llround(s * static_cast<double>(gnc::kNsPerS)));
}

// Event arguments are int32: counts saturate instead of wrapping negative.
std::int32_t sat_i32(std::uint64_t v) {
  return v > 2147483647u ? 2147483647 : static_cast<std::int32_t>(v);
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
  const auth::CommandSecurity::InitCheck sc = security_.init(config.security);
  if (!sc.ok) return InitResult{false, sc.field, sc.reason};
  config_ = config;
  clock_ = &clock;

  cmds_ = gnc::GncCommands{};
  commands_.reset();
  params_.reset(gnc_.params());
  uplink_.reset();
  events_.reset();
  const std::int64_t interval = to_ns(config_.sensor_event_interval_s);
  time_base_.configure(TimeBaseConfig{exec_.gnc_period_s(), config_.max_frame_time_jump_s,
                                      config_.frame_resync_count, config_.frame_resync_run,
                                      interval});
  translator_.configure(interval);
  missed_throttle_.configure(to_ns(config_.executive.slip_event_interval_s));
  missed_throttle_.reset();
  auth_throttle_.configure(interval);
  auth_throttle_.reset();
  if (security_.lab_mode()) {
    events_.emit(Severity::kWarning, EventId::kLabMode, 0, 0,
                 "LAB MODE: ground commands are NOT authenticated");
  }
  latest_frame_ = gnc::SensorSample{};
  fresh_frame_ = false;
  consecutive_slips_ = 0;
  overrun_request_ = false;
  next_index_ = 0;
  sensor_rejects_base_ = 0;
  device_rejects_ = 0;
  trajectory_loaded_ = false;
  return InitResult{};
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
      events_.emit(Severity::kWarning, EventId::kMissedTicks, sat_i32(plan.base_missed),
                   sat_i32(suppressed),
                   "%" PRIu32 " base tick(s) missed (%" PRIu32 " report(s) suppressed)",
                   plan.base_missed, suppressed);
    }
  }
  time_base_.missed_cycles(plan.missed[static_cast<int>(GroupId::kGnc)]);
  if (frame != nullptr) {
    latest_frame_ = *frame;
    fresh_frame_ = true;
  }
  if (plan.due[static_cast<int>(GroupId::kGnc)]) run_gnc(tick, t_frameless, out);
  if (plan.due[static_cast<int>(GroupId::kHousekeeping)]) run_housekeeping(tick, out);
}

void FlightApp::report_slip(GroupId g, const SlipReport& s) {
  if (!s.report) return;
  events_.emit(Severity::kWarning, EventId::kSlip, static_cast<std::int32_t>(g),
               static_cast<std::int32_t>(s.suppressed),
               "%s slip: previous cycle ended %.3f ms after this tick was due (%" PRIu32
               " suppressed)",
               to_string(g), static_cast<double>(s.late_ns) * 1e-6, s.suppressed);
}

void FlightApp::run_gnc(const Tick& tick, const double* t_frameless, Outputs& out) {
  RateGroup& group = exec_.group(GroupId::kGnc);
  const SlipReport slip = group.begin(tick.start_ns, clock_->now_ns());
  report_slip(GroupId::kGnc, slip);
  consecutive_slips_ = slip.slipped ? consecutive_slips_ + 1 : 0;

  // 1. Accepted commands take effect at the tick boundary.
  commands_.apply_pending(cmds_, *this, events_);

  // Repeated overruns: the loop cannot keep its rate, stop actuating (DESIGN.md, SAFE).
  overrun_request_ = false;
  if (config_.overrun_safe_slips > 0 && consecutive_slips_ >= config_.overrun_safe_slips &&
      gnc_.mode() != gnc::Mode::kSafe) {
    cmds_.has_mode_request = true;
    cmds_.mode_request = gnc::Mode::kSafe;
    overrun_request_ = true;
    events_.emit(
        Severity::kError, EventId::kOverrunSafe, static_cast<std::int32_t>(consecutive_slips_), 0,
        "%" PRIu32 " consecutive GNC overruns: -> SAFE, thrusters off", consecutive_slips_);
  }

  // 2. The sample: the fresh frame if its time is sane, otherwise an invalid sample at the
  //    scheduled time (the flight core counts the sensor age and goes to SAFE on timeout).
  const bool have_frame =
      fresh_frame_ && time_base_.accept(latest_frame_.t, clock_->now_ns(), events_);
  fresh_frame_ = false;
  if (!have_frame) {
    latest_frame_ = gnc::SensorSample{};  // invalid readings
    latest_frame_.t = t_frameless != nullptr ? *t_frameless : time_base_.scheduled_time();
  }

  // 3. The flight core.
  const gnc::LawId law_before = gnc_.params().law;
  gnc_.step(latest_frame_, cmds_, gout_);
  time_base_.cycle_ran(latest_frame_.t, have_frame);
  events_.set_time(latest_frame_.t);
  trajectory_loaded_ = gout_.telemetry.trajectory_loaded;
  if (gnc_.params().law != law_before) {
    events_.emit(Severity::kInfo, EventId::kLawChanged, static_cast<std::int32_t>(law_before),
                 static_cast<std::int32_t>(gnc_.params().law), "control law %s -> %s",
                 gnc::to_string(law_before), gnc::to_string(gnc_.params().law));
  }
  translator_.translate(
      gout_.events,
      TranslationContext{overrun_request_, gnc_.params().mode.sensor_timeout_s,
                         gout_.telemetry.sensor_rejects - sensor_rejects_base_, clock_->now_ns()},
      events_);

  out.command = gout_.command;
  out.telemetry = gout_.telemetry;
  out.gnc_ran = true;
  group.end(clock_->now_ns());
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
  h.t = time_base_.onboard_time();
  h.base_ticks = exec_.base_ticks();
  h.base_missed = exec_.base_missed();
  h.mode = gnc_.mode();
  h.law = gnc_.params().law;
  h.gnc = exec_.group(GroupId::kGnc).stats();
  h.housekeeping = exec_.group(GroupId::kHousekeeping).stats();
  h.cmd_accepted = commands_.accepted();
  h.cmd_rejected = commands_.rejected();
  h.last_cmd_seq = commands_.last_seq();
  h.last_cmd_opcode = commands_.last_opcode();
  h.last_reject = commands_.last_reject();
  h.cmd_pending = static_cast<std::uint32_t>(commands_.pending());
  h.events_emitted = static_cast<std::uint32_t>(events_.emitted());
  h.events_dropped = events_.dropped();
  h.frames_accepted = time_base_.frames_accepted();
  h.frames_rejected = time_base_.frames_rejected();
  h.frameless_ticks = time_base_.frameless_ticks();
  h.sensor_rejects = gout_.telemetry.sensor_rejects - sensor_rejects_base_ + device_rejects_;
  h.table_loads = params_.loads();
  h.table_activations = params_.activations();
  h.table_loaded = params_.table().loaded();
  h.uplink_id = uplink_.uplink().upload_id();
  h.uplink_chunks_received = uplink_.uplink().chunks_received();
  h.uplink_chunk_count = uplink_.uplink().chunk_count();
  h.uplink_chunks_rejected = uplink_.chunks_rejected();
  h.trajectories_loaded = uplink_.loaded();
  h.trajectory_loaded = trajectory_loaded_;
  h.lab_mode = security_.lab_mode();
  h.auth_key_id = security_.active_key_id();
  h.auth_rejected = security_.auth_rejected();
  h.replays_rejected = security_.replays_rejected();
  return h;
}

// ----------------------------------------------------------------------------------------------
// Commands and uplink
// ----------------------------------------------------------------------------------------------

DispatchContext FlightApp::dispatch_context() {
  return DispatchContext{clock_ != nullptr, gnc_,    trajectory_loaded_, time_base_.onboard_time(),
                         params_,           uplink_, events_,           security_};
}

void FlightApp::report_auth_failure(auth::AuthResult r, int what, std::int64_t seq) {
  std::uint32_t suppressed = 0;
  if (clock_ == nullptr || !auth_throttle_.allow(clock_->now_ns(), suppressed)) return;
  events_.emit(Severity::kWarning, EventId::kAuthRejected, static_cast<std::int32_t>(r), what,
               "%s seq %" PRId64 " refused: %s (%" PRIu32 " report(s) suppressed)",
               what == 0 ? "command" : "uplink chunk", seq, auth::to_string(r), suppressed);
}

CommandAck FlightApp::submit(const GroundCommand& cmd) {
  if (clock_ != nullptr) {
    const auth::AuthResult a = security_.verify(cmd);
    if (a != auth::AuthResult::kOk && a != auth::AuthResult::kLabMode) {
      report_auth_failure(a, 0, cmd.seq);
      const bool replay = a == auth::AuthResult::kReplay || a == auth::AuthResult::kBadCounter;
      return commands_.refuse(cmd,
                              replay ? RejectReason::kStaleSequence
                                     : RejectReason::kNotAuthenticated,
                              auth::to_string(a));
    }
  }
  return commands_.submit(cmd, dispatch_context());
}

ChunkStatus FlightApp::receive_chunk(const TrajectoryChunk& chunk) {
  if (clock_ == nullptr) return ChunkStatus::kBusy;
  const auth::AuthResult a = security_.verify(chunk);
  if (a != auth::AuthResult::kOk && a != auth::AuthResult::kLabMode) {
    report_auth_failure(a, 1, chunk.seq);
    return ChunkStatus::kNotAuthenticated;
  }
  return uplink_.receive(chunk, events_);
}

void FlightApp::rotate_key(std::int32_t key_id) {
  const std::int32_t from = security_.active_key_id();
  if (security_.rotate(key_id)) {
    events_.emit(Severity::kInfo, EventId::kKeyRotated, from, key_id,
                 "command key %" PRId32 " -> %" PRId32, from, key_id);
  }
}

void FlightApp::load_trajectory(std::int32_t upload_id) {
  if (uplink_.hand_over(upload_id, gnc_, events_)) trajectory_loaded_ = true;
}

void FlightApp::reset_counters() {
  commands_.reset_counters();
  time_base_.reset_counters();
  sensor_rejects_base_ = gout_.telemetry.sensor_rejects;
  device_rejects_ = 0;
  uplink_.reset_counters();
  exec_.reset_counters();
  events_.reset_dropped();
  events_.emit(Severity::kInfo, EventId::kCountersReset, 0, 0, "counters reset");
}

}  // namespace rocksteady::fsw
