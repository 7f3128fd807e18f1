// rocksteady-fsw's bus loop: one FlightApp on the LCM bus.
//
// Inputs (raw-buffer subscriptions, decoded with wire::safe_decode; a rejected message is
// counted in gnc_telemetry_t.rx_* and dropped, never fatal): RS_SENSORS, RS_GROUND_CMD,
// RS_TRAJ_UPLINK. Outputs: RS_THRUSTER_CMD (hal::ThrusterBank's physical thrusters, echoing the
// frame), RS_GNC_TLM, RS_EVENTS, RS_CMD_ACK.
//
// Two clocks:
//   lockstep  each new sensor frame is one base tick (fsw::LockstepSource); the thruster command
//             echoes the frame's seq. A repeated frame (the plant resending after a lost command)
//             is answered by re-publishing the command it already produced, without a second tick.
//             After the first frame, when no frame arrives for `frame_watchdog_s` of wall time, the
//             node runs frameless ticks at the base period, so the flight core's sensor timeout
//             takes it to SAFE (thrusters off, event) when the plant is gone.
//   realtime  fsw::RealTimeClockSource drives the base ticks on CLOCK_MONOTONIC; the bus is served
//             while waiting for each deadline; each tick consumes the newest frame that arrived
//             (a frameless tick when none did).
// A frame whose seq goes backwards is a restarted sensor stream: the sensor source flags it and the
// devices forget their last readings (the application re-anchors its time base after
// frame_resync_count frames).
//
// Inbound priority and bounds: sensor frames first. With a separate ground bus (set_ground_bus),
// the flight bus carries only RS_SENSORS / RS_THRUSTER_CMD and its socket is always served before
// the ground bus's; the ground-facing channels (RS_GROUND_CMD, RS_TRAJ_UPLINK in; RS_CMD_ACK,
// RS_EVENTS, RS_GNC_TLM out) move to the ground bus. Either way at most `ground_drain_max` ground
// messages are decoded per base tick (or per base period while no ticks run); the rest of that
// tick's ground messages are dropped undecoded and counted (NodeStats::ground_dropped, the status
// line).
//
// Software watchdog (NodeOptions::watchdog_s > 0): fed by each GNC cycle; when no cycle completes
// within the timeout, a watchdog thread (not the stalled one) raises event 203, commands every
// thruster off through hal::LcmThrusterSink::all_off and ends the process with kExitWatchdog so a
// supervisor restarts it.
//
// Only this object's thread calls lcm_handle. Nothing here allocates per message except LCM itself.
#pragma once

#include <atomic>
#include <csignal>
#include <cstdint>
#include <string>
#include <vector>

#include <lcm/lcm.h>

#include "fsw/bus/bus_mapping.hpp"
#include "fsw/computer/flight_computer.hpp"
#include "fsw/executive/clock.hpp"
#include "hal/lcm/lcm_ports.hpp"
#include "rt/udpm_receiver.hpp"
#include "rt/watchdog.hpp"
#include "wire/codec.hpp"

namespace rocksteady::fsw::bus {

enum class ClockMode { kLockstep, kRealtime };

// Events of the bus layer itself (fsw::EventId are 100..; the plant's from 1000).
enum class BusEventId : std::int32_t {
  kStreamRestart = 200,  // sensor frame seq went backwards; arg0 = new seq, arg1 = restarts
  kFrameWatchdog = 201,  // lockstep: no frame for frame_watchdog_s, frameless ticks
  kRxRejected = 202,  // throttled; arg0 = channel (0 sensors, 1 ground cmd, 2 uplink), arg1 = total
  kWatchdog = 203,    // error; no GNC cycle within the watchdog time: thrusters off, process exits
                      // arg0 = ms since the last GNC cycle, arg1 = base tick of that cycle
  kStateFile = 204,   // error; the command-security state could not be written
};

// Exit status after the software watchdog fired (a supervisor restarts the process).
inline constexpr int kExitWatchdog = 5;

struct NodeOptions {
  ClockMode clock{ClockMode::kLockstep};
  double frame_watchdog_s{1.0};     // lockstep only
  std::uint32_t tlm_every{1};       // RS_GNC_TLM every N GNC cycles
  double exit_after_s{-1.0};        // wall time; < 0: run until stopped
  std::uint64_t exit_after_ticks{0};  // base ticks; 0: no limit
  bool verbose{false};              // one status line per wall second on stdout
  // Realtime: tick start minus its deadline, one value per base tick (capacity reserved by the
  // caller; values beyond it are not recorded).
  std::vector<std::int64_t>* jitter_ns{nullptr};
  // After the first GNC tick with an accepted frame, submit SET_MODE start_mode as a ground command from source
  // kStartupSource (the in-process campaign's habit: the estimator has a state by then).
  bool has_start_mode{false};
  gnc::Mode start_mode{gnc::Mode::kDetumble};
  // Ground messages (commands + uplink chunks) decoded per base tick; beyond it they are dropped.
  std::uint32_t ground_drain_max{64};
  // Software watchdog: no GNC cycle for this many wall seconds -> thrusters off, exit. 0: off.
  double watchdog_s{0.0};
  int watchdog_fifo_priority{0};  // > 0: the watchdog thread runs under SCHED_FIFO at this priority
  // FAULT INJECTION, for tests of the watchdog only: base tick `test_stall_at_tick` (> 0) stalls
  // before the flight computer runs, for test_stall_s wall seconds (0: forever).
  std::uint64_t test_stall_at_tick{0};
  double test_stall_s{0.0};
};

// Command source of the --start-mode command (the operator's sources are unaffected).
inline constexpr std::int32_t kStartupSource = 99;

struct NodeStats {
  std::uint64_t ticks{0};
  std::uint64_t frames{0};          // valid frames received
  std::uint64_t frames_superseded{0};  // realtime: a newer frame arrived before the tick
  std::uint64_t duplicate_frames{0};   // lockstep: repeated frame, command re-published
  std::uint64_t stale_frames{0};       // lockstep: older frame, dropped
  std::uint64_t stream_restarts{0};
  std::uint64_t watchdog_ticks{0};     // lockstep: frameless ticks after the watchdog fired
  std::uint64_t commands{0};
  std::uint64_t chunks{0};
  std::uint64_t publish_errors{0};
  wire::RxCounters rx_sensors{};
  wire::RxCounters rx_commands{};
  wire::RxCounters rx_uplink{};
  std::uint64_t ground_dropped{0};  // ground messages dropped undecoded (per-tick bound reached)
  std::uint64_t ground_bound_ticks{0};  // ticks in which the bound was reached
  std::uint64_t flight_handled{0};      // messages dispatched from the flight bus
  std::uint64_t ground_handled{0};      // messages dispatched from the ground bus (when separate)
  // Where the wall time goes (CLOCK_MONOTONIC, summed): waiting in ppoll, lcm_handle (LCM's queue,
  // decoding, the handlers), the flight computer's tick (devices, FlightApp, the thruster publish),
  // and after it (telemetry, events, the start command).
  std::int64_t ns_wait{0};
  std::int64_t ns_handle{0};
  std::int64_t ns_tick{0};
  std::int64_t ns_after_tick{0};
};

class FlightNode {
 public:
  // All referenced objects must outlive the node; `computer` initialised and driven by `sensors`
  // and `thrusters`, the ports on this node's bus.
  FlightNode(lcm_t* lcm, FlightComputer& computer, hal::LcmSensorSource& sensors,
             hal::LcmThrusterSink& thrusters, const Clock& clock);
  FlightNode(const FlightNode&) = delete;
  FlightNode& operator=(const FlightNode&) = delete;
  ~FlightNode();

  // A separate bus for the ground-facing channels (call before subscribe; nullptr: the one bus).
  void set_ground_bus(lcm_t* ground) { ground_ = ground; }
  // Sensor frames read from this socket by the loop itself instead of through LCM's receive thread
  // (call before subscribe; the flight bus must then carry nothing else the node needs).
  void set_direct_sensor_rx(rt::UdpmReceiver* rx) { direct_ = rx; }
  // Where the command-security state is persisted whenever it changes ("" = nowhere: the replay
  // windows then restart empty after a reboot; fsw/auth/key_file.hpp).
  void set_state_file(const std::string& path) { state_file_ = path; }
  bool subscribe();
  // Runs until *stop becomes non-zero or an exit limit is reached. Returns 0, or 1 on a bus error.
  int run(const NodeOptions& options, const volatile std::sig_atomic_t* stop);

  const NodeStats& stats() const { return stats_; }
  wire::RxCounters rx_total() const;

  // Waits for the bus until `deadline_ns` (monotonic) or until one message was dispatched.
  // Returns false on a bus error.
  bool wait_once(std::int64_t deadline_ns);

 private:
  static void on_sensors(const lcm_recv_buf_t* rbuf, const char* channel, void* self);
  static void on_command(const lcm_recv_buf_t* rbuf, const char* channel, void* self);
  static void on_chunk(const lcm_recv_buf_t* rbuf, const char* channel, void* self);
  static void on_watchdog(void* self, std::int64_t since_feed_ns);
  bool ground_budget();  // false: drop this ground message (counted)
  void test_stall(const Tick& t, const NodeOptions& o);

  int run_lockstep(const NodeOptions& o, const volatile std::sig_atomic_t* stop);
  int run_realtime(const NodeOptions& o, const volatile std::sig_atomic_t* stop);

  void tick(const Tick& tick, const NodeOptions& o);
  void sync_sensor_stats();
  void publish_telemetry(const NodeOptions& o);
  void drain_events();
  void persist_security();
  void bus_event(Severity sev, BusEventId id, std::int32_t arg0, std::int32_t arg1,
                 const char* text);
  void note_rx_reject(int channel, const wire::RxCounters& c);
  template <class T> void publish(const char* channel, const T& msg);
  void status_line(const char* prefix) const;
  bool limits_reached(const NodeOptions& o, std::int64_t start_ns) const;

  lcm_t* lcm_;
  lcm_t* ground_{nullptr};  // separate ground bus, or nullptr
  lcm_t* out_{nullptr};     // where acks, events, telemetry go (ground_ or lcm_)
  rt::UdpmReceiver* direct_{nullptr};
  FlightComputer& computer_;
  hal::LcmSensorSource& sensors_;
  hal::LcmThrusterSink& thrusters_;
  const Clock& clock_;
  lcm_subscription_t* subs_[3]{nullptr, nullptr, nullptr};
  std::uint64_t restarts_seen_{0};     // restarts reported as events
  std::uint64_t restarts_handled_{0};  // restarts the lockstep numbering has followed

  rocksteady::ground_cmd_t scratch_cmd_{};
  rocksteady::trajectory_chunk_t scratch_chunk_{};
  TrajectoryChunk chunk_{};
  rocksteady::cmd_ack_t ack_msg_{};
  rocksteady::event_t event_msg_{};
  rocksteady::gnc_telemetry_t tlm_msg_{};
  ParamDump dump_{};
  rocksteady::param_table_t params_msg_{};
  std::uint64_t gnc_cycles_{0};
  std::uint64_t bus_event_seq_{0};
  std::int64_t last_rx_event_ns_[3]{0, 0, 0};
  bool rx_event_fired_[3]{false, false, false};
  std::int64_t last_status_ns_{0};
  std::uint64_t last_index_{0};
  bool have_index_{false};
  bool bus_error_{false};
  bool start_done_{false};
  std::string state_file_;
  std::uint64_t state_written_{0};  // generation of the security state last written
  unsigned char buf_[4096]{};
  NodeStats stats_{};
  std::uint32_t ground_drain_max_{64};
  std::uint32_t ground_left_{64};    // ground messages still allowed in this tick
  std::int64_t ground_reset_ns_{0};  // when the budget was last refilled
  std::int64_t period_ns_{0};
  // Watchdog: its thread reads only these atomics and its own message and buffer.
  rt::Watchdog watchdog_;
  std::atomic<std::int64_t> wd_seq_{0};
  std::atomic<double> wd_t_{0.0};
  std::atomic<std::uint64_t> wd_tick_{0};
  std::atomic<std::int32_t> wd_key_id_{0};  // the active command key, for the watchdog's event
  rocksteady::event_t wd_event_msg_{};
  unsigned char wd_buf_[1024]{};
};

}  // namespace rocksteady::fsw::bus
