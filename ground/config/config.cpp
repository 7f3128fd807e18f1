#include "ground/config/config.hpp"

#include <array>
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
  return load_case_run(m, g, case_path);
}

RunSetup load_case_run(const MissionConfig& mission, const GncConfig& gnc,
                       const std::string& case_path) {
  RunSetup s = assemble(mission, gnc, load_case(case_path));
  apply_case_plant_keys(case_path, s.truth);
  return s;
}

std::vector<plant::ThrusterFault> parse_faults(const YAML::Node& list, const std::string& file,
                                               const std::string& key) {
  if (!list.IsSequence()) {
    throw ConfigError(file, key, "expected a list of faults ({thruster, kind, onset_s, factor})");
  }
  std::vector<plant::ThrusterFault> out;
  std::array<bool, hal::kThrusters> seen{};
  for (std::size_t i = 0; i < list.size(); ++i) {
    const std::string at = key + "[" + std::to_string(i) + "]";
    if (!list[i].IsMap()) throw ConfigError(file, at, "expected a mapping {thruster, kind, ...}");
    MapReader r(list[i], file, at);
    plant::ThrusterFault f;
    f.thruster = r.integer("thruster");
    if (f.thruster < 0 || f.thruster >= hal::kThrusters) {
      r.fail("thruster", "must be in [0, 15] (4 pod + position), got " + std::to_string(f.thruster));
    }
    const std::string kind = r.text("kind");
    if (!plant::parse_fault_kind(kind, f.kind)) {
      r.fail("kind", "expected stuck_off, stuck_on or degraded, got '" + kind + "'");
    }
    f.onset_s = r.has("onset_s") ? r.non_negative("onset_s") : 0.0;
    if (f.kind == plant::FaultKind::kDegraded) {
      f.factor = r.number("factor");
      if (!(f.factor > 0.0 && f.factor < 1.0)) r.fail("factor", "must be in (0, 1)");
    } else if (r.has("factor")) {
      r.fail("factor", "only a degraded thruster has a factor");
    }
    r.finish();
    if (seen[static_cast<std::size_t>(f.thruster)]) {
      r.fail("thruster", "thruster " + std::to_string(f.thruster) + " already has a fault");
    }
    seen[static_cast<std::size_t>(f.thruster)] = true;
    out.push_back(f);
  }
  return out;
}

void apply_case_plant_keys(const std::string& case_path, plant::PlantParams& truth) {
  const YAML::Node doc = load_yaml_file(case_path);
  if (!doc.IsMap()) return;  // load_case has reported it
  plant::PlantParams t = truth;
  if (const YAML::Node f = doc["faults"]; f.IsDefined() && !f.IsNull()) {
    t.faults = parse_faults(f, case_path, "faults");
  }
  if (const YAML::Node v = doc["valve_driver_timeout_s"]; v.IsDefined()) {
    YAML::Node wrap;
    wrap["valve_driver_timeout_s"] = v;
    MapReader r(wrap, case_path, "");
    t.command_timeout_s = r.non_negative("valve_driver_timeout_s");
  }
  try {
    plant::validate(t);
  } catch (const std::invalid_argument& e) {
    throw ConfigError(case_path, "faults", e.what());
  }
  truth = t;
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
