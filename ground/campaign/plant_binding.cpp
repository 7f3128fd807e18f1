#include "ground/campaign/plant_binding.hpp"

namespace rocksteady::campaign {

bool PlantBinding::poll(hal::RawSensors& out) {
  if (polled_ && polled_tick_ == plant_.ticks()) return false;  // nothing new this period
  polled_ = true;
  polled_tick_ = plant_.ticks();
  out = plant_.read_sensors();
  return true;
}

void PlantBinding::write(const hal::ThrusterOutputs& outputs, std::int64_t seq, double /*t*/) {
  thrusters_ = outputs;
  plant_.receive(outputs);
  last_seq_ = seq;
  ++writes_;
}

}  // namespace rocksteady::campaign
