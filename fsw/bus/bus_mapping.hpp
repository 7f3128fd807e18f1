// The flight side of the bus: LCM messages <-> the flight application's plain structs
// (fsw/interface.hpp) and the HAL's sensor front end. No LCM calls, no heap after configuration
// (event_t / cmd_ack_t carry a std::string: give them capacity once with reserve_text()).
#pragma once

#include <cstdint>

#include "fsw/app/flight_app.hpp"
#include "fsw/interface.hpp"
#include "hal/lcm/codec.hpp"
#include "hal/sensors.hpp"
#include "rocksteady/cmd_ack_t.hpp"
#include "rocksteady/event_t.hpp"
#include "rocksteady/gnc_telemetry_t.hpp"
#include "rocksteady/ground_cmd_t.hpp"
#include "rocksteady/sensor_frame_t.hpp"
#include "rocksteady/trajectory_chunk_t.hpp"

namespace rocksteady::fsw::bus {

// ground_cmd_t (already safe-decoded) -> GroundCommand. Arguments beyond nargs are zero; the
// command table judges opcode, count and ranges and answers with a reason.
GroundCommand to_command(const rocksteady::ground_cmd_t& m);

// trajectory_chunk_t (already safe-decoded: counts and first_sample checked) -> TrajectoryChunk.
void to_chunk(const rocksteady::trajectory_chunk_t& m, TrajectoryChunk& out);

// Give the message's text its maximum capacity once, so later fills do not allocate.
void reserve_text(rocksteady::cmd_ack_t& m);
void reserve_text(rocksteady::event_t& m);

// CommandAck -> cmd_ack_t at on-board time t (text truncated to MAX_TEXT).
void to_message(const CommandAck& ack, double t, rocksteady::cmd_ack_t& m);
// Event -> event_t.
void to_message(const Event& e, rocksteady::event_t& m);

// The fsw's part of gnc_telemetry_t: executive, commanding, health counters, tables, uplink.
void fill_health(const HealthTelemetry& h, rocksteady::gnc_telemetry_t& m);
// Inbound bus counters (every input channel together).
void fill_rx(const hal::wire::RxCounters& rx, rocksteady::gnc_telemetry_t& m);

// The sensor front end of a bus frame: sensor-frame readings -> body frame (hal::Gyro,
// hal::StarTracker with their alignment) -> gnc::SensorSample at the frame's time.
class SensorFrontEnd {
 public:
  hal::SensorConfigError configure(const hal::SensorConfig& gyro, const hal::SensorConfig& star);
  // A restarted sensor stream: forget the last reading times.
  void reset();
  gnc::SensorSample sample(const rocksteady::sensor_frame_t& m);
  std::uint32_t gyro_rejects() const { return gyro_.rejects(); }
  std::uint32_t star_rejects() const { return star_.rejects(); }

 private:
  hal::Gyro gyro_{};
  hal::StarTracker star_{};
};

}  // namespace rocksteady::fsw::bus
