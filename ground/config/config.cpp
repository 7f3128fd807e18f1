#include "ground/config/config.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace rocksteady::config {

RunSetup assemble(const MissionConfig& m, const GncConfig& g, const CaseConfig& c) {
  RunSetup s;
  s.case_number = c.number;
  s.case_name = "case" + std::to_string(c.number);
  s.description = c.description;
  s.duration_s = c.duration_s;
  s.omega_tol_rad_s = m.omega_tol_rad_s;
  s.q_tol = m.q_tol;

  // Truth (the plant).
  plant::PlantParams& t = s.truth;
  t.mass = m.mass;
  t.rcs = rcs_layout(m, c.u_max);
  t.isp_s = m.isp_s;
  t.g0 = m.g0;
  t.control_period_s = g.params.dt;
  t.substeps = m.rk4_substeps;
  t.disturbance.sigma_nm = m.disturbance_sigma_nm;
  t.disturbance.hold_s = m.disturbance_hold_s;
  t.disturbance.bias_nm = c.bias_nm;
  t.sensors.period_s = m.sensor_period_s;
  t.sensors.gyro_psd = c.gyro_psd;
  t.sensors.star_psd = c.star_psd;
  t.beta0 = plant::att::mrp_to_quat(m.initial_mrp);
  t.omega0 = m.initial_omega;
  t.seed = c.seed;
  const double ratio = m.sensor_period_s / g.params.dt;
  if (ratio < 0.999999 || std::fabs(ratio - std::round(ratio)) > 1e-6) {
    throw ConfigError(m.file, "sensors.period_s",
                      "must be an integer multiple of the GNC period (1 / rate_hz in " + g.file + ")");
  }
  try {
    plant::validate(t);
  } catch (const std::invalid_argument& e) {
    throw ConfigError(c.file + " + " + m.file, "", e.what());
  }
  if (c.plant_truth.IsDefined() && !c.plant_truth.IsNull()) {
    apply_plant_truth(c.plant_truth, c.file, t);
  }

  // Estimates (the flight software), Eq. (6): estimate = true - error.
  s.flight = flight_params(m, g, c);
  s.mass_hat = s.flight.mass_hat;
  return s;
}

RunSetup load_run(const std::string& mission_path, const std::string& gnc_path,
                  const std::string& case_path) {
  const MissionConfig m = load_mission(mission_path);
  const GncConfig g = load_gnc(gnc_path);
  const CaseConfig c = load_case(case_path);
  return assemble(m, g, c);
}

void apply_plant_truth(const YAML::Node& node, const std::string& file, plant::PlantParams& truth) {
  MapReader r(node, file, "plant_truth");
  plant::PlantParams t = truth;
  if (r.has("gyro_bias_rad_s")) t.sensors.gyro_bias = r.vec3("gyro_bias_rad_s");
  if (r.has("gyro_bias_random_walk")) {
    t.sensors.gyro_bias_rw = r.non_negative("gyro_bias_random_walk");
  }
  if (r.has("thruster_strength")) {
    const Eigen::VectorXd k = r.list("thruster_strength", 16);
    for (int i = 0; i < 16; ++i) {
      if (!(k(i) >= 0.0)) r.fail("thruster_strength", "every factor must be >= 0");
      t.thruster_strength(i) = k(i);
    }
  }
  r.finish();
  try {
    plant::validate(t);
  } catch (const std::invalid_argument& e) {
    throw ConfigError(file, "plant_truth", e.what());
  }
  truth = t;
}

}  // namespace rocksteady::config
