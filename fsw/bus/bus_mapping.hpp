// The flight side of the bus: LCM messages <-> the flight application's plain structs
// (fsw/interface.hpp): commands, acknowledgements, uplink chunks, events, health telemetry. Sensor
// frames and thruster commands are not here: they are device readings, mapped by the bus library
// (wire/convert.hpp) inside the HAL's LCM ports. No LCM calls, no heap after configuration
// (event_t / cmd_ack_t carry a std::string: give them capacity once with reserve_text()).
#pragma once

#include <cstdint>

#include "fsw/app/flight_app.hpp"
#include "fsw/interface.hpp"
#include "wire/codec.hpp"
#include "rocksteady/cmd_ack_t.hpp"
#include "rocksteady/event_t.hpp"
#include "rocksteady/gnc_telemetry_t.hpp"
#include "rocksteady/ground_cmd_t.hpp"
#include "rocksteady/param_table_t.hpp"
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

// CommandAck -> cmd_ack_t at on-board time t (text truncated to MAX_TEXT), without authenticator.
void to_message(const CommandAck& ack, double t, rocksteady::cmd_ack_t& m);
// The acknowledgement's fields as the authenticator covers them (text points into m).
auth::AckFields ack_fields(const rocksteady::cmd_ack_t& m);
// Adds the downlink authenticator (key_id, mac); false in lab mode (key_id 0, zero mac).
bool sign(const FlightApp& app, rocksteady::cmd_ack_t& m);
// The event's fields as the authenticator covers them, and its downlink authenticator.
auth::EventFields event_fields(const rocksteady::event_t& m);
bool sign(const FlightApp& app, rocksteady::event_t& m);
// Event -> event_t.
void to_message(const Event& e, rocksteady::event_t& m);
// ParamDump -> param_table_t, with the flight's downlink authenticator (no MAC in lab mode).
void to_message(const ParamDump& d, const FlightApp& app, rocksteady::param_table_t& m);

// The fsw's part of gnc_telemetry_t: executive, commanding, health counters, tables, uplink.
void fill_health(const HealthTelemetry& h, rocksteady::gnc_telemetry_t& m);
// Inbound bus counters (every input channel together).
void fill_rx(const wire::RxCounters& rx, rocksteady::gnc_telemetry_t& m);


}  // namespace rocksteady::fsw::bus
