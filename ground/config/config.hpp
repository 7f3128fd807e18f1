// The configuration files assembled for a closed-loop run: the flight software's parameters
// (config/) and the plant's truth (true mass properties, thrusters, disturbance, sensor noise,
// initial state), SPEC Eq. (6).
#pragma once

#include <string>

#include "config/config_files.hpp"
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

}  // namespace rocksteady::config
