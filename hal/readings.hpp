// Device readings and device commands: the HAL's shape of a sensor frame and of a thruster firing.
// Plain structs of numbers, with no behaviour and no dependency beyond the flight core's types, so
// that the bus library (wire/) and ground equipment (the plant) can speak them without linking any
// HAL code. One shape per boundary (DESIGN.md): bus message <-> these <-> gnc::SensorSample /
// gnc::ThrusterCommand.
#pragma once

#include <array>
#include <cstdint>

#include "gnc/model/rcs.hpp"
#include "gnc/types.hpp"

namespace rocksteady::hal {

// --- Sensors ---------------------------------------------------------------------------------

struct GyroReading {
  double t{0.0};                      // s, sample time
  gnc::Vec3 rate{gnc::Vec3::Zero()};  // rad/s, in the gyro frame
  bool valid{false};                  // device's own validity flag
};

struct StarTrackerReading {
  double t{0.0};                       // s, sample time
  gnc::Vec4 quat{0.0, 0.0, 0.0, 1.0};  // attitude of the tracker frame in F_I, scalar last
  bool valid{false};
};

// One sensor frame as a sensor front end (plant, bus, board) delivers it.
struct RawSensors {
  std::int64_t seq{-1};  // frame number (echoed by the thruster command in lockstep)
  double t{0.0};         // s, frame time
  GyroReading gyro{};
  StarTrackerReading star{};
  // Set by a source whose frame numbering went backwards (a restarted sensor stream): the devices
  // forget their last readings before this frame is read.
  bool stream_restart{false};
};

// --- Thrusters -------------------------------------------------------------------------------

inline constexpr int kThrustersPerPod = 4;
inline constexpr int kThrusters = gnc::kPods * kThrustersPerPod;  // 16

// Physical thruster number: 4 * pod + position in the pod (0..3).
constexpr int thruster_index(int pod, int position) {
  return pod * kThrustersPerPod + position;
}

// What the thruster bank drives: 16 on/off thrusters with their force, and one latch valve per pod
// (closed: none of the pod's four thrusters can fire; a stuck-open thruster valve included).
struct ThrusterOutputs {
  bool enabled{false};
  std::array<bool, kThrusters> on{};
  std::array<double, kThrusters> force{};  // N, >= 0; zero when off
  std::array<bool, gnc::kPods> valve_open{true, true, true, true};
};

// The pod of a physical thruster.
constexpr int thruster_pod(int thruster) { return thruster / kThrustersPerPod; }

}  // namespace rocksteady::hal
