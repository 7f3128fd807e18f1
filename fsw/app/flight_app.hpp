// The flight application: one gnc::Gnc inside the executive's rate groups (GNC, housekeeping),
// composed of parts that each own their counters: the frame time base (executive/time_base), the
// command dispatcher with its action queue (commands/dispatcher), the parameter and uplink life
// cycles (params/param_lifecycle, uplink/uplink_lifecycle), the event log and the table-driven
// translation of the core's mode events (events/). The flight computer (fsw/computer) wraps it with
// the HAL devices; every harness flies that.
//
// Threading: not thread-safe. submit(), receive_chunk() and the ticks are called from one thread
// (the bus loop or the campaign). Nothing here allocates after init(), throws or does I/O; init()
// resets everything. The object is large (two trajectory tables): make it static or allocate it
// once at start-up.
#pragma once

#include <array>
#include <cstdint>

#include "fsw/auth/auth.hpp"
#include "fsw/commands/dispatcher.hpp"
#include "fsw/events/event_log.hpp"
#include "fsw/events/event_translator.hpp"
#include "fsw/executive/clock.hpp"
#include "fsw/executive/executive.hpp"
#include "fsw/executive/tick_source.hpp"
#include "fsw/executive/time_base.hpp"
#include "fsw/interface.hpp"
#include "fsw/params/param_lifecycle.hpp"
#include "fsw/uplink/uplink_lifecycle.hpp"
#include "gnc/check.hpp"
#include "gnc/gnc.hpp"

namespace rocksteady::fsw {

struct FlightConfig {
  gnc::GncParams gnc{};
  ExecutiveConfig executive{};           // gnc_divider / base_rate_hz must equal gnc.dt
  double sensor_event_interval_s{10.0};  // throttle of sensor/frame reject and missed-tick events
  // A frame whose time is more than this ahead of the on-board time is rejected (one bad time tag
  // must not poison the time base).
  double max_frame_time_jump_s{60.0};
  // After this many consecutive rejected frames, the next frame with a finite time re-anchors the
  // time base (e.g. the sensor front end restarted its clock).
  std::uint32_t frame_resync_count{50};
  // ... and then only a run of this many frames with consistent times re-anchors it (never one).
  std::uint32_t frame_resync_run{3};
  // This many consecutive GNC cycles that slipped -> SAFE (thrusters off) with an event; 0: never.
  std::uint32_t overrun_safe_slips{10};
  // Command keys and persisted replay state, or lab mode (explicit; see fsw/auth/auth.hpp). The
  // default (no keys, no lab mode) is refused by init().
  auth::SecurityConfig security{};
};

// {ok, field, reason}: the project's one check result (gnc/check.hpp).
using InitResult = gnc::Check;

// What one base tick produced. Events are not here: drain them with pop_event().
struct Outputs {
  bool gnc_ran{false};  // command and telemetry are fresh: send the thruster command
  gnc::ThrusterCommand command{};
  gnc::GncTelemetry telemetry{};
  bool housekeeping_ran{false};  // health is fresh: publish it
  HealthTelemetry health{};
};

class FlightApp final : private BoundaryActions {
 public:
  FlightApp() = default;
  FlightApp(const FlightApp&) = delete;
  FlightApp& operator=(const FlightApp&) = delete;

  // Validates the configuration, initialises the flight core, resets every counter and queue.
  // `clock` measures execution times and throttles events; it must outlive the application.
  InitResult init(const FlightConfig& config, const Clock& clock);
  bool initialised() const { return clock_ != nullptr; }

  // --- Inputs ---------------------------------------------------------------------------------
  // Validates a ground command now and answers it; an accepted command that changes the flight
  // state (mode, law, target, table activation, trajectory hand-over, counter reset) takes effect
  // at the start of the next GNC tick. Raises an event either way.
  // With command keys the command must be authentic and fresh (fsw/auth): anything else is
  // answered NOT_AUTHENTICATED / STALE_SEQUENCE and changes nothing.
  CommandAck submit(const GroundCommand& cmd);
  // A command the flight software gives itself from its own start-up configuration (never bus
  // input): checked and executed like a ground command, without authentication.
  CommandAck submit_local(const GroundCommand& cmd) {
    return commands_.submit(cmd, dispatch_context());
  }
  // Stores one chunk of a trajectory uplink (events on start, completion, rejection).
  ChunkStatus receive_chunk(const TrajectoryChunk& chunk);
  // The downlink authenticator of an acknowledgement (false in lab mode: no authenticator).
  bool sign_ack(auth::AckFields& ack, auth::MacBytes& mac) const {
    return security_.sign_ack(ack, mac);
  }
  bool sign_event(auth::EventFields& event, auth::MacBytes& mac) const {
    return security_.sign_event(event, mac);
  }
  // What must survive a reboot (the bus layer persists it when its generation changes).
  const auth::SecurityState& security_state() const { return security_.state(); }
  const auth::CommandSecurity& security() const { return security_; }

  // One base tick from a tick source. `frame`: the sensor sample that arrived for this tick, or
  // nullptr. A GNC cycle without a fresh frame runs with an invalid sample at the scheduled time,
  // so the flight core's sensor timeout (-> SAFE, thrusters off) works without frames.
  void tick(const Tick& tick, const gnc::SensorSample* frame, Outputs& out);
  // Lockstep convenience (tests): one sensor sample = one base tick (with the default gnc_divider
  // of 1, one GNC tick).
  void gnc_tick(const gnc::SensorSample& sample, Outputs& out);
  // One base tick without a frame; the GNC cycle (if due) runs at time t with an invalid sample.
  void gnc_tick_without_frame(double t, Outputs& out);

  // Readings the devices rejected before the flight core saw them (non-finite values): counted in
  // HealthTelemetry::sensor_rejects.
  void note_sensor_rejects(std::uint32_t n) { device_rejects_ += n; }

  // --- Outputs besides Outputs ------------------------------------------------------------------
  bool pop_event(Event& e) { return events_.pop(e); }
  // The parameter table read back by an accepted PARAM_DUMP, once.
  bool take_param_dump(ParamDump& out) { return params_.take_dump(out); }
  int pending_events() const { return events_.pending(); }
  HealthTelemetry health() const;  // the counters now (housekeeping publishes the same)

  // --- Inspection -------------------------------------------------------------------------------
  gnc::Mode mode() const { return gnc_.mode(); }
  // On-board time: the sample time of the last GNC cycle (for acknowledgement time stamps).
  double onboard_time() const { return time_base_.onboard_time(); }
  const gnc::Gnc& core() const { return gnc_; }
  // The flight core's output of the last GNC cycle, with its raw mode events (gnc::ModeEvents).
  const gnc::GncOutput& core_output() const { return gout_; }
  const gnc::GncParams& active_params() const { return gnc_.params(); }
  const ParamTable& param_table() const { return params_.table(); }
  const Executive& executive() const { return exec_; }
  const TrajectoryUplink& uplink() const { return uplink_.uplink(); }
  bool trajectory_loaded() const { return trajectory_loaded_; }
  int pending_commands() const { return commands_.pending(); }

 private:
  // BoundaryActions: what the dispatcher's queue runs at the tick boundary.
  void activate_params() override { params_.activate(gnc_, events_); }
  void load_trajectory(std::int32_t upload_id) override;
  void reset_counters() override;
  void rotate_key(std::int32_t key_id) override;
  void report_auth_failure(auth::AuthResult r, int what, std::int64_t seq);

  DispatchContext dispatch_context();
  void run_tick(const Tick& tick, const gnc::SensorSample* frame, const double* t_frameless,
                Outputs& out);
  void run_gnc(const Tick& tick, const double* t_frameless, Outputs& out);
  void run_housekeeping(const Tick& tick, Outputs& out);
  void report_slip(GroupId g, const SlipReport& s);

  const Clock* clock_{nullptr};
  FlightConfig config_{};
  gnc::Gnc gnc_{};
  gnc::GncCommands cmds_{};
  gnc::GncOutput gout_{};
  Executive exec_{};
  FrameTimeBase time_base_{};
  CommandDispatcher commands_{};
  ParamLifecycle params_{};
  UplinkLifecycle uplink_{};
  EventLog events_{};
  EventTranslator translator_{};
  auth::CommandSecurity security_{};
  Throttle auth_throttle_{};

  gnc::SensorSample latest_frame_{};
  bool fresh_frame_{false};
  std::uint32_t consecutive_slips_{0};
  bool overrun_request_{false};  // this tick's SAFE request is the overrun protection's
  std::uint64_t next_index_{0};  // for the lockstep conveniences
  std::uint32_t sensor_rejects_base_{0};
  std::uint32_t device_rejects_{0};
  bool trajectory_loaded_{false};
  Throttle missed_throttle_{};
};

}  // namespace rocksteady::fsw
