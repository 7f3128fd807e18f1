// The flight computer: the flight application (fsw::FlightApp) with its HAL devices (hal::Gyro,
// hal::StarTracker, hal::ThrusterBank), driven only through a pair of HAL ports. Every harness
// flies this object and supplies nothing but the ports (DESIGN.md, "one flight path, three ways to
// run it"):
//
//   harness                 SensorSource                 ThrusterSink
//   in-process campaign     ground's plant binding       ground's plant binding
//   rocksteady-fsw (PIL)    hal::LcmSensorSource         hal::LcmThrusterSink
//   flight board            hal::FlightBoardStub         hal::FlightBoardStub
//
// One base tick: poll the sensor source for the newest frame -> the devices check each reading and
// write the body-frame values into the flight core's gnc::SensorSample -> FlightApp (executive,
// commands, Gnc) -> the thruster bank turns the channel forces into the 16 physical thrusters ->
// the thruster sink, echoing the frame's sequence number. Ground commands, uplink chunks, events
// and telemetry go through the methods below (the bus layer moves them; it never touches a device).
//
// Not thread-safe; no heap, no exceptions, no I/O after init(). Large (the application holds two
// trajectory tables): give it static storage or allocate it once at start-up.
#pragma once

#include <cstdint>

#include "fsw/app/flight_app.hpp"
#include "hal/ports.hpp"
#include "hal/sensors.hpp"
#include "hal/thruster_bank.hpp"

namespace rocksteady::fsw {

struct FlightComputerConfig {
  FlightConfig app{};
  hal::SensorConfig gyro{};
  hal::SensorConfig star_tracker{};
  hal::ThrusterBankConfig thrusters{};  // default: SPEC §4 wiring at the flight's u_max
};

// The default configuration for a flight configuration: aligned sensors, SPEC §4 wiring.
FlightComputerConfig default_computer_config(const FlightConfig& app);

// What one tick did.
struct TickReport {
  bool frame{false};    // a sensor frame was polled for this tick
  bool gnc_ran{false};  // the GNC cycle ran, and the thrusters were written
  bool housekeeping_ran{false};
};

class FlightComputer {
 public:
  // The ports must outlive the computer.
  FlightComputer(hal::SensorSource& sensors, hal::ThrusterSink& thrusters)
      : sensors_(sensors), thrusters_(thrusters) {}
  FlightComputer(const FlightComputer&) = delete;
  FlightComputer& operator=(const FlightComputer&) = delete;

  // Validates and installs everything (devices first, then the application). `clock` measures
  // execution times and throttles events; it must outlive the computer.
  InitResult init(const FlightComputerConfig& config, const Clock& clock);

  // One base tick from a tick source (real time, lockstep, or the board's timer).
  TickReport tick(const Tick& tick);
  // Lockstep convenience: the next base tick (index after the last one, start = clock's now).
  TickReport step();

  // --- Ground side (the bus layer or the campaign moves these) ---------------------------------
  CommandAck submit(const GroundCommand& cmd) { return app_.submit(cmd); }
  CommandAck submit_local(const GroundCommand& cmd) { return app_.submit_local(cmd); }
  ChunkStatus receive_chunk(const TrajectoryChunk& chunk) { return app_.receive_chunk(chunk); }
  bool pop_event(Event& e) { return app_.pop_event(e); }
  bool take_param_dump(ParamDump& out) { return app_.take_param_dump(out); }
  const Outputs& outputs() const { return out_; }  // the last tick's command and telemetry
  HealthTelemetry health() const { return app_.health(); }
  const gnc::GncOutput& core_output() const { return app_.core_output(); }
  gnc::Mode mode() const { return app_.mode(); }
  double onboard_time() const { return app_.onboard_time(); }
  std::int64_t echo_seq() const { return echo_seq_; }  // frame the last thruster write answered
  const FlightApp& app() const { return app_; }
  std::uint32_t gyro_rejects() const { return gyro_.rejects(); }
  std::uint32_t star_rejects() const { return star_.rejects(); }

 private:
  hal::SensorSource& sensors_;
  hal::ThrusterSink& thrusters_;
  hal::Gyro gyro_{};
  hal::StarTracker star_{};
  hal::ThrusterBank bank_{};
  FlightApp app_{};
  const Clock* clock_{nullptr};
  hal::RawSensors frame_{};
  hal::ThrusterOutputs thruster_out_{};
  Outputs out_{};
  std::int64_t echo_seq_{0};
  std::uint64_t next_index_{0};
};

}  // namespace rocksteady::fsw
