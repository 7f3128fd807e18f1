// The flight application: the executive's rate groups (GNC, housekeeping), the command dispatcher,
// the parameter tables, the trajectory uplink and the event queue around one gnc::Gnc. The same
// object flies in rocksteady-fsw (over the bus) and in the in-process campaign (lockstep), so every
// closed-loop run exercises this code.
//
// Threading: not thread-safe. submit(), receive_chunk() and the ticks are called from one thread
// (the bus loop or the campaign). Nothing here allocates after init(), throws or does I/O; init()
// resets everything. The object is large (two trajectory tables): make it static or allocate it
// once at start-up.
#pragma once

#include <array>
#include <cstdint>

#include "fsw/commands/command_table.hpp"
#include "fsw/events/event_queue.hpp"
#include "fsw/executive/clock.hpp"
#include "fsw/executive/executive.hpp"
#include "fsw/executive/tick_source.hpp"
#include "fsw/interface.hpp"
#include "fsw/params/param_table.hpp"
#include "fsw/uplink/trajectory_uplink.hpp"
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
  // This many consecutive GNC cycles that slipped -> SAFE (thrusters off) with an event; 0: never.
  std::uint32_t overrun_safe_slips{10};
};

struct InitResult {
  bool ok{true};
  const char* field{""};
  const char* reason{""};
};

// What one base tick produced. Events are not here: drain them with pop_event().
struct Outputs {
  bool gnc_ran{false};  // command and telemetry are fresh: send the thruster command
  gnc::ThrusterCommand command{};
  gnc::GncTelemetry telemetry{};
  bool housekeeping_ran{false};  // health is fresh: publish it
  HealthTelemetry health{};
};

class FlightApp {
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
  CommandAck submit(const GroundCommand& cmd);
  // Stores one chunk of a trajectory uplink (events on start, completion, rejection).
  ChunkStatus receive_chunk(const TrajectoryChunk& chunk);

  // One base tick from a tick source. `frame`: the sensor sample that arrived for this tick, or
  // nullptr. A GNC cycle without a fresh frame runs with an invalid sample at the scheduled time,
  // so the flight core's sensor timeout (-> SAFE, thrusters off) works without frames.
  void tick(const Tick& tick, const gnc::SensorSample* frame, Outputs& out);
  // Lockstep convenience (in-process campaign): one sensor sample = one base tick (with the
  // default gnc_divider of 1, one GNC tick).
  void gnc_tick(const gnc::SensorSample& sample, Outputs& out);
  // One base tick without a frame; the GNC cycle (if due) runs at time t with an invalid sample.
  void gnc_tick_without_frame(double t, Outputs& out);

  // --- Outputs besides Outputs ------------------------------------------------------------------
  bool pop_event(Event& e) { return events_.pop(e); }
  int pending_events() const { return events_.size(); }
  HealthTelemetry health() const;  // the counters now (housekeeping publishes the same)

  // --- Inspection -------------------------------------------------------------------------------
  gnc::Mode mode() const { return gnc_.mode(); }
  // On-board time: the sample time of the last GNC cycle (for acknowledgement time stamps).
  double onboard_time() const { return last_gnc_t_; }
  const gnc::Gnc& core() const { return gnc_; }
  // The flight core's output of the last GNC cycle, with its raw mode events (gnc::ModeEvents).
  const gnc::GncOutput& core_output() const { return gout_; }
  const gnc::GncParams& active_params() const { return gnc_.params(); }
  const ParamTable& param_table() const { return table_; }
  const Executive& executive() const { return exec_; }
  const TrajectoryUplink& uplink() const { return uplink_; }
  bool trajectory_loaded() const { return trajectory_loaded_; }
  int pending_commands() const { return action_count_; }

 private:
  enum class ActionKind : std::uint8_t {
    kMode,
    kLaw,
    kTarget,
    kActivateParams,
    kLoadTrajectory,
    kResetCounters,
  };
  struct Action {
    ActionKind kind{ActionKind::kMode};
    gnc::Mode mode{gnc::Mode::kIdle};
    gnc::LawId law{gnc::LawId::kNtcl};
    gnc::Vec3 target{gnc::Vec3::Zero()};
    std::int32_t upload_id{0};
  };
  static constexpr int kActionCapacity = 16;

  void reset_state();
  void run_tick(const Tick& tick, const gnc::SensorSample* frame, const double* t_frameless,
                Outputs& out);
  void run_gnc(const Tick& tick, const double* t_frameless, Outputs& out);
  void run_housekeeping(const Tick& tick, Outputs& out);
  void report_slip(GroupId g, const SlipReport& s);
  bool accept_frame_time(double t);
  double scheduled_time() const;
  void translate_core_events();

  // Commands.
  CommandCheck execute(const GroundCommand& cmd);
  CommandCheck execute_set_law(const GroundCommand& cmd);
  CommandCheck execute_load_trajectory(const GroundCommand& cmd);
  bool queue_has_room(int n) const { return action_count_ + n <= kActionCapacity; }
  void enqueue(const Action& a);
  void apply_pending(gnc::GncCommands& cmds);
  void apply_pre_step(const Action& a);
  gnc::Mode projected_mode() const;
  gnc::LawId projected_law() const;
  bool projected_trajectory() const;
  void reset_counters();

  void emit(Severity sev, EventId id, std::int32_t arg0, std::int32_t arg1, const char* fmt, ...)
      __attribute__((format(printf, 6, 7)));

  const Clock* clock_{nullptr};
  FlightConfig config_{};
  gnc::Gnc gnc_{};
  gnc::GncCommands cmds_{};
  gnc::GncOutput gout_{};
  gnc::GncParams activation_{};
  Executive exec_{};
  SequenceTracker seqs_{};
  ParamTable table_{};
  TrajectoryUplink uplink_{};
  EventQueue events_{};
  std::array<Action, kActionCapacity> actions_{};
  int action_head_{0};
  int action_count_{0};

  // Time base.
  gnc::SensorSample latest_frame_{};
  bool fresh_frame_{false};
  bool have_frame_t_{false};
  double last_frame_t_{0.0};
  std::uint32_t consecutive_frame_rejects_{0};
  bool have_gnc_t_{false};
  double last_gnc_t_{0.0};
  std::uint32_t gnc_cycles_missed_{0};  // GNC cycles skipped since the last one ran
  std::uint32_t consecutive_slips_{0};
  bool overrun_request_{false};  // this tick's SAFE request is the overrun protection's
  std::uint64_t next_index_{0};  // for the lockstep conveniences

  // Counters (telemetry).
  std::uint32_t cmd_accepted_{0};
  std::uint32_t cmd_rejected_{0};
  std::int64_t last_cmd_seq_{0};
  std::int32_t last_cmd_opcode_{-1};
  RejectReason last_reject_{RejectReason::kNone};
  std::uint64_t event_seq_{0};
  std::uint32_t frames_accepted_{0};
  std::uint32_t frames_rejected_{0};
  std::uint32_t frameless_ticks_{0};
  std::uint32_t sensor_rejects_base_{0};
  std::uint32_t table_loads_{0};
  std::uint32_t table_activations_{0};
  std::uint32_t chunks_rejected_{0};
  std::uint32_t trajectories_loaded_{0};
  bool trajectory_loaded_{false};

  Throttle sensor_throttle_{};
  Throttle frame_throttle_{};
  Throttle missed_throttle_{};
};

}  // namespace rocksteady::fsw
