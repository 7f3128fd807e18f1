// The HAL's two ports, implemented by each back end: LCM (processor-in-the-loop), the in-process plant
// binding, and the flight-board stub. Plain structs in, plain structs out; no heap, no exceptions.
#pragma once

#include <cstdint>

#include "hal/sensors.hpp"
#include "hal/thruster_bank.hpp"

namespace rocksteady::hal {

class SensorSource {
 public:
  virtual ~SensorSource() = default;
  // The newest sensor frame, if one arrived since the last call (false: nothing new).
  virtual bool poll(RawSensors& out) = 0;

 protected:
  SensorSource() = default;
  SensorSource(const SensorSource&) = default;
  SensorSource& operator=(const SensorSource&) = default;
};

class ThrusterSink {
 public:
  virtual ~ThrusterSink() = default;
  // Drive the thrusters; `seq` echoes the sensor frame the command answers.
  virtual void write(const ThrusterOutputs& outputs, std::int64_t seq, double t) = 0;

 protected:
  ThrusterSink() = default;
  ThrusterSink(const ThrusterSink&) = default;
  ThrusterSink& operator=(const ThrusterSink&) = default;
};

}  // namespace rocksteady::hal
