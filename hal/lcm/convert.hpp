// LCM back end, data half: bus messages <-> the HAL's plain structs. No LCM calls, no heap.
#pragma once

#include <cstdint>

#include "gnc/gnc.hpp"
#include "hal/sensors.hpp"
#include "hal/thruster_bank.hpp"
#include "rocksteady/gnc_telemetry_t.hpp"
#include "rocksteady/sensor_frame_t.hpp"
#include "rocksteady/thruster_cmd_t.hpp"

namespace rocksteady::hal::wire {

// sensor_frame_t <-> RawSensors (sensor-frame readings; alignment is the Gyro/StarTracker's job).
RawSensors to_raw(const rocksteady::sensor_frame_t& m);
rocksteady::sensor_frame_t to_message(const RawSensors& s);

// ThrusterBank output (+ the channel forces it was made from) -> thruster_cmd_t, and back.
rocksteady::thruster_cmd_t to_message(const ThrusterOutputs& outputs, const gnc::Vec8& channel_force,
                                      std::int64_t seq, double t);
ThrusterOutputs to_outputs(const rocksteady::thruster_cmd_t& m);
gnc::Vec8 channel_forces(const rocksteady::thruster_cmd_t& m);

// The flight core's part of the telemetry (time, modes, estimates, reference, allocator, fuel,
// sensor rejects, channel forces). Executive, command and bus counters are the fsw's to fill.
void fill_gnc(const gnc::GncOutput& out, rocksteady::gnc_telemetry_t& m);

}  // namespace rocksteady::hal::wire
