// The configuration files assembled for a closed-loop run: the flight software's parameters
// (config/) and the plant's truth (true mass properties, thrusters, disturbance, sensor noise,
// initial state), SPEC Eq. (6).
#pragma once

#include <string>

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
