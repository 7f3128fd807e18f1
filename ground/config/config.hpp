// The configuration files assembled for a closed-loop run: the flight software's parameters
// (config/) and the plant's truth (true mass properties, thrusters, disturbance, sensor noise,
// initial state), SPEC Eq. (6).
#pragma once

#include <string>
#include <vector>

#include "config/config_files.hpp"
#include "config/yaml_reader.hpp"
#include "ground/plant/plant.hpp"

namespace rocksteady::config {

// Everything one closed-loop run needs.
struct RunSetup {
  std::string case_name;  // "case1"
  int case_number{0};
  std::string description;
  plant::PlantParams truth{};
  gnc::GncParams flight{};  // law: the default from gnc.yaml (a strategy overrides it)
  double duration_s{1e5};
  double omega_tol_rad_s{1e-4};
  double q_tol{1e-2};
  gnc::MassProperties mass_hat{};
};

// Applies the case's errors (true minus estimate) and validates the result.
RunSetup assemble(const MissionConfig& mission, const GncConfig& gnc, const CaseConfig& c);
RunSetup load_run(const std::string& mission_path, const std::string& gnc_path,
                  const std::string& case_path);
// load_case + assemble + the case file's plant-side keys (below): what every tool that flies a case
// file uses.
RunSetup load_case_run(const MissionConfig& mission, const GncConfig& gnc,
                       const std::string& case_path);

// The plant-side keys of a case file, which the flight software's loader skips (every key
// optional; absent: no fault, no timeout, the study's truth):
//   faults:                          # thruster faults, at most one per thruster
//     - {thruster: 3, kind: stuck_on, onset_s: 60}
//     - {thruster: 9, kind: degraded, onset_s: 5000, factor: 0.5}
//     - {thruster: 12, kind: stuck_off, onset_s: 0}
//   valve_driver_timeout_s: 1.0      # thrusters off when commands stop this long (0: never)
// thruster: 0..15 = 4 pod + position (= 2c for channel c's "+", 2c + 1 its "-"); kind: stuck_off,
// stuck_on (full u_max whatever is commanded while the pod's latch valve is open) or degraded
// (factor in (0, 1) required, and only there); onset_s >= 0 (default 0). Errors: ConfigError
// naming the file, faults[i].<key> and the reason.
void apply_case_plant_keys(const std::string& case_path, plant::PlantParams& truth);
std::vector<plant::ThrusterFault> parse_faults(const YAML::Node& list, const std::string& file,
                                               const std::string& key);

// Optional plant truth beyond the study's cases, a `plant_truth` mapping (every key optional;
// absent keys keep the study's truth: no gyro bias, every thruster at strength 1):
//   plant_truth:
//     gyro_bias_rad_s: [bx, by, bz]        # initial gyro bias, rad/s
//     gyro_bias_random_walk: 1.0e-9        # rad/s^(3/2)
//     thruster_strength: [k0, ..., k15]    # thruster 2c = channel c's "+", 2c+1 its "-"
// `node` is that mapping, `file` names it in errors (ConfigError: file, plant_truth.<key>,
// reason). The result is validated with the plant's own checks.
void apply_plant_truth(const YAML::Node& node, const std::string& file, plant::PlantParams& truth);

}  // namespace rocksteady::config
