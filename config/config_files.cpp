#include "config/config_files.hpp"

#include <cmath>
#include <string>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include "config/yaml_reader.hpp"
#include "gnc/param_bounds.hpp"

namespace rocksteady::config {

namespace {

constexpr double kPi = 3.14159265358979323846;

bool spd(const Mat3& m) { return Eigen::LLT<Mat3>(0.5 * (m + m.transpose())).info() == Eigen::Success; }

Mat3 inertia(MapReader& r, const std::string& key) {
  const Mat3 j = r.matrix3(key);
  if (!spd(j)) r.fail(key, "inertia is not positive definite");
  return j;
}

Mat3 gain(MapReader& r, const std::string& key) {
  const Mat3 k = r.matrix3(key);
  if (!spd(k)) r.fail(key, "gain is not positive definite");
  return k;
}

void tracking(MapReader r, gnc::TrackingGains& g) {
  g.k = gain(r, "K");
  g.lambda = gain(r, "Lambda");
  r.finish();
}

}  // namespace

MissionConfig load_mission(const std::string& path) {
  MissionConfig m;
  m.file = path;
  MapReader doc(load_yaml_file(path), path, "");

  MapReader sc = doc.map("spacecraft");
  m.mass.m_sc = sc.positive("mass_kg");
  m.mass.r_scm_so = sc.vec3("r_scm_so_m");
  m.mass.j_sc = inertia(sc, "inertia_kg_m2");
  sc.finish();

  MapReader ast = doc.map("asteroid");
  m.mass.m_ast = ast.positive("mass_kg");
  m.mass.j_ast = inertia(ast, "inertia_kg_m2");
  m.mass.r_so_bcm = ast.vec3("r_so_bcm_m");
  ast.finish();
  if (!spd(gnc::total_inertia(m.mass))) {
    throw ConfigError(path, "asteroid", "total inertia J_tot (Eq. 1) is not positive definite");
  }

  MapReader rcs = doc.map("rcs");
  const Eigen::VectorXd az = rcs.list("pod_azimuths_deg", 4);
  for (int k = 0; k < 4; ++k) m.pod_azimuths_deg[static_cast<std::size_t>(k)] = az(k);
  m.pod_radius_m = rcs.positive("pod_radius_m");
  m.pod_plane_z_m = rcs.number("pod_plane_z_m");
  m.isp_s = rcs.positive("isp_s");
  m.g0 = rcs.positive("g0_m_s2");
  rcs.finish();

  MapReader sens = doc.map("sensors");
  m.sensor_period_s = sens.positive("period_s");
  sens.finish();

  MapReader dist = doc.map("disturbance");
  m.disturbance_sigma_nm = dist.non_negative("sigma_per_axis_nm");
  m.disturbance_hold_s = dist.positive("hold_s");
  dist.finish();

  MapReader init = doc.map("initial_state");
  m.initial_mrp = init.vec3("mrp");
  if (m.initial_mrp.norm() > 1.0) init.fail("mrp", "|q| must be <= 1 (shadow-normalised MRP)");
  m.initial_omega = init.vec3("omega_rad_s");
  init.finish();

  MapReader dir = doc.map("uncertainty_directions");
  m.delta_j_diag_direction = dir.vec3("delta_j_ast_diag");
  const double dj = m.delta_j_diag_direction.cwiseAbs().maxCoeff();
  if (!(dj > 0.0)) dir.fail("delta_j_ast_diag", "direction must not be zero");
  m.delta_j_diag_direction /= dj;  // unit spectral norm
  m.delta_r_direction = dir.vec3("delta_r_so_bcm");
  if (!(m.delta_r_direction.norm() > 0.0)) dir.fail("delta_r_so_bcm", "direction must not be zero");
  m.delta_r_direction.normalize();
  dir.finish();

  MapReader goals = doc.map("goals");
  m.omega_tol_rad_s = goals.positive("omega_tol_rad_s");
  m.q_tol = goals.positive("q_tol");
  goals.finish();

  MapReader sim = doc.map("simulation");
  m.rk4_substeps = sim.integer("rk4_substeps");
  if (m.rk4_substeps < 1 || m.rk4_substeps > 10000) sim.fail("rk4_substeps", "must be in [1, 10000]");
  sim.finish();

  doc.finish();
  return m;
}

GncConfig load_gnc(const std::string& path) {
  GncConfig g;
  g.file = path;
  gnc::GncParams& p = g.params;
  MapReader doc(load_yaml_file(path), path, "");

  p.dt = 1.0 / doc.positive("rate_hz");

  const std::string est = doc.text("estimator");
  if (est == "auto") {
    g.estimator = EstimatorChoice::kAuto;
  } else if (est == "passthrough") {
    g.estimator = EstimatorChoice::kPassThrough;
  } else if (est == "filter") {
    g.estimator = EstimatorChoice::kFilter;
  } else {
    doc.fail("estimator", "expected auto, passthrough or filter, got '" + est + "'");
  }

  // SPEC §4: optional; the study's pseudoinverse, Eq. (53), unless the fuel-optimal Eq. (52).
  if (doc.has("allocator")) {
    const std::string alloc = doc.text("allocator");
    if (alloc == "pinv") {
      p.allocator = gnc::AllocatorKind::kPseudoInverse;
    } else if (alloc == "l1") {
      p.allocator = gnc::AllocatorKind::kL1;
    } else {
      doc.fail("allocator", "expected pinv or l1, got '" + alloc + "'");
    }
  }

  MapReader f = doc.map("filter");
  p.estimator.omega_c = f.positive("omega_c_rad_s");
  p.estimator.predict_substeps = f.integer("predict_substeps");
  p.estimator.gyro_max_rate = f.positive("gyro_max_rate_rad_s");
  p.estimator.quat_norm_tolerance = f.positive("quat_norm_tolerance");
  f.finish();

  MapReader laws = doc.map("laws");
  tracking(laws.map("ntcl"), p.ntcl);
  tracking(laws.map("el"), p.el);
  tracking(laws.map("feedforward"), p.feedforward);
  {
    MapReader r = laws.map("integral");
    p.integral.k = gain(r, "K");
    p.integral.lambda = gain(r, "Lambda");
    p.integral.k_i = gain(r, "K_I");
    p.integral.integral_limit_nm = r.positive("integral_limit_nm");
    r.finish();
  }
  {
    MapReader r = laws.map("adaptive");
    p.adaptive.k = gain(r, "K");
    p.adaptive.lambda = gain(r, "Lambda");
    p.adaptive.gamma = r.positive("Gamma");
    p.adaptive.eig_floor_ratio = r.positive("eig_floor_ratio");
    p.adaptive.eig_ceiling_ratio = r.positive("eig_ceiling_ratio");
    r.finish();
  }
  {
    MapReader r = laws.map("so3");
    p.so3.k = gain(r, "K");
    p.so3.lambda = gain(r, "Lambda");
    r.finish();
  }
  {
    MapReader r = laws.map("dpd");
    p.dpd.k_d = gain(r, "K_d");
    p.dpd.k_p = r.positive("k_p");
    r.finish();
  }
  laws.finish();

  MapReader gd = doc.map("guidance");
  p.guidance.omega_switch = gd.positive("omega_switch_rad_s");
  p.guidance.k_qd = gd.positive("k_qd");
  p.guidance.q_final = gd.vec3("q_final");
  p.guidance.track_reset_period_s = gd.non_negative("track_reset_period_s");
  p.guidance.eps_trans = gd.positive("eps_trans_rpm") * 2.0 * kPi / 60.0;
  gd.finish();

  MapReader md = doc.map("modes");
  p.mode.auto_hold = md.boolean("auto_hold");
  p.mode.sensor_timeout_s = md.positive("sensor_timeout_s");
  md.finish();

  doc.finish();
  return g;
}

CaseConfig load_case(const std::string& path) {
  CaseConfig c;
  c.file = path;
  MapReader doc(load_yaml_file(path), path, "");
  c.number = doc.integer("case");
  if (c.number < 1) doc.fail("case", "case number must be >= 1");
  if (doc.has("description")) c.description = doc.text("description");
  c.delta_j_norm = doc.non_negative("delta_j_ast_norm_kg_m2");
  c.delta_r_norm = doc.non_negative("delta_r_so_bcm_norm_m");
  c.gyro_psd = doc.non_negative("gyro_noise_psd_rad2_s2");
  c.star_psd = doc.non_negative("star_noise_psd");
  c.u_max = doc.positive("u_max_n");
  if (!gnc::within_bound("rcs.u_max", c.u_max)) {
    doc.fail("u_max_n", std::string("outside its physical range: ") +
                            gnc::find_param_bound("rcs.u_max")->why);
  }
  c.bias_nm = doc.vec3("disturbance_bias_nm");
  c.duration_s = doc.positive("duration_s");
  if (!gnc::within_bound("case.duration_s", c.duration_s)) {
    doc.fail("duration_s", std::string("outside its physical range: ") +
                               gnc::find_param_bound("case.duration_s")->why);
  }
  c.seed = doc.unsigned_integer("seed");
  doc.finish();
  return c;
}

gnc::RcsLayout rcs_layout(const MissionConfig& m, double u_max) {
  gnc::RcsLayout l;
  for (int k = 0; k < gnc::kPods; ++k) {
    const double th = m.pod_azimuths_deg[static_cast<std::size_t>(k)] * kPi / 180.0;
    l.pod_position[k] = Vec3(m.pod_radius_m * std::cos(th), m.pod_radius_m * std::sin(th),
                             m.pod_plane_z_m);
    l.channel_direction[2 * k] = Vec3(-std::sin(th), std::cos(th), 0.0);  // tangential pair
    l.channel_direction[2 * k + 1] = Vec3(0.0, 0.0, 1.0);                 // axial pair
    l.channel_pod[2 * k] = k;
    l.channel_pod[2 * k + 1] = k;
  }
  l.u_max = u_max;
  return l;
}

gnc::GncParams flight_params(const MissionConfig& m, const GncConfig& g, const CaseConfig& c) {
  // Estimates (the flight software), Eq. (6): estimate = true - error.
  gnc::MassProperties hat = m.mass;
  hat.j_ast = m.mass.j_ast - c.delta_j_norm * Mat3(m.delta_j_diag_direction.asDiagonal());
  hat.r_so_bcm = m.mass.r_so_bcm - c.delta_r_norm * m.delta_r_direction;
  if (!spd(hat.j_ast)) {
    throw ConfigError(c.file, "delta_j_ast_norm_kg_m2",
                      "the estimated asteroid inertia J_ast - dJ_ast is not positive definite");
  }
  gnc::GncParams p = g.params;
  p.mass_hat = hat;
  p.rcs = rcs_layout(m, c.u_max);
  p.isp_s = m.isp_s;
  p.g0 = m.g0;
  const bool noisy = c.gyro_psd > 0.0 || c.star_psd > 0.0;
  switch (g.estimator) {
    case EstimatorChoice::kAuto:  // SPEC §6: the filter only where the sensors are noisy
      p.estimator.kind = noisy ? gnc::EstimatorKind::kFilter : gnc::EstimatorKind::kPassThrough;
      break;
    case EstimatorChoice::kPassThrough: p.estimator.kind = gnc::EstimatorKind::kPassThrough; break;
    case EstimatorChoice::kFilter: p.estimator.kind = gnc::EstimatorKind::kFilter; break;
  }
  const gnc::ParamCheck check = gnc::validate(p);
  if (!check.ok) {
    const std::string field = check.field;
    const bool model = field.rfind("mass_hat", 0) == 0 || field.rfind("rcs", 0) == 0;
    throw ConfigError(model ? m.file + " + " + c.file : g.file, field, check.reason);
  }
  return p;
}

gnc::GncParams load_flight_params(const std::string& mission_path, const std::string& gnc_path,
                                  const std::string& case_path) {
  return flight_params(load_mission(mission_path), load_gnc(gnc_path), load_case(case_path));
}

}  // namespace rocksteady::config
