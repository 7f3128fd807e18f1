// Bus messages <-> device readings and commands (hal/readings.hpp) and the flight core's output.
// One conversion per boundary; no LCM calls, no heap.
#pragma once

#include <cstdint>

#include "gnc/io.hpp"
#include "hal/readings.hpp"
#include "rocksteady/gnc_telemetry_t.hpp"
#include "rocksteady/sensor_frame_t.hpp"
#include "rocksteady/thruster_cmd_t.hpp"

namespace rocksteady::wire {

// sensor_frame_t <-> RawSensors (sensor-frame readings; alignment is the Gyro/StarTracker's job).
hal::RawSensors to_raw(const rocksteady::sensor_frame_t& m);
rocksteady::sensor_frame_t to_message(const hal::RawSensors& s);

// ThrusterBank output (+ the channel forces it was made from) -> thruster_cmd_t, and back.
rocksteady::thruster_cmd_t to_message(const hal::ThrusterOutputs& outputs,
                                      const gnc::Vec8& channel_force, std::int64_t seq, double t);
hal::ThrusterOutputs to_outputs(const rocksteady::thruster_cmd_t& m);
gnc::Vec8 channel_forces(const rocksteady::thruster_cmd_t& m);

// The flight core's part of the telemetry (time, modes, estimates, reference, allocator, fuel,
// sensor rejects, channel forces). Executive, command and bus counters are the fsw's to fill.
void fill_gnc(const gnc::GncOutput& out, rocksteady::gnc_telemetry_t& m);

}  // namespace rocksteady::wire
