// What the operator reads: telemetry as a status block (terminal) or one line (pipes, logs), events
// and acknowledgements as lines. Pure functions of the messages, so they are tested without a bus.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "wire/codec.hpp"

namespace rocksteady::ground::cli {

// What the monitor itself has seen on the bus (not the flight's counters, which are in telemetry).
struct MonitorCounts {
  std::uint64_t telemetry{0};
  std::uint64_t events{0};
  std::uint64_t acks{0};
  wire::RxCounters rx{};  // the monitor's own decode outcomes over the three channels
};

// Attitude error as an angle: 4 atan(|q|) for an MRP q, in degrees.
double mrp_angle_deg(const double (&q)[3]);
// |v| of a 3-vector.
double norm3(const double (&v)[3]);

// The status block, one string per line (no line breaks inside). Sections: mode/law/phase, rates,
// attitude error, actuators and fuel, rate groups, commanding, health counters, uplink.
std::vector<std::string> format_status(const rocksteady::gnc_telemetry_t& m,
                                       const MonitorCounts& c);
// One line with the same essentials ("t=12.300 mode=HOLD law=ntcl ...").
std::string format_status_line(const rocksteady::gnc_telemetry_t& m, const MonitorCounts& c);

// Text from the bus made safe for a terminal: control characters (ESC and every byte below 0x20,
// DEL) and bytes that are not valid UTF-8 become \xNN, so no message can move the cursor, clear
// the screen, set the title or hide a line. Every tool prints bus text through this.
std::string sanitize_text(const std::string& text);

// "[t=12.300] WARNING command_rejected (101) arg0=2 arg1=7: SET_TARGET ... rejected ..."
std::string format_event(const rocksteady::event_t& e);
// "ACCEPTED" or "REJECTED: <reason> (<detail>): <text>", without the seq prefix.
std::string format_ack_verdict(const rocksteady::cmd_ack_t& a);
// "ack seq 12 from 1 SET_MODE: ACCEPTED" (for the monitor's stream of acks).
std::string format_ack(const rocksteady::cmd_ack_t& a);

}  // namespace rocksteady::ground::cli
