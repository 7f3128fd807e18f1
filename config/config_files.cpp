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
  } else if (est == "mekf") {
    g.estimator = EstimatorChoice::kMekf;
  } else {
    doc.fail("estimator", "expected auto, passthrough, filter or mekf, got '" + est + "'");
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

  // The MEKF's tuning (optional; the sensor noise itself comes from the case, flight_params).
  if (doc.has("mekf")) {
    MapReader r = doc.map("mekf");
    p.mekf.gyro_bias_rw = r.positive("gyro_bias_rw_rad_s32");
    p.mekf.model_sigma = r.non_negative("model_sigma_rad_sqrt_s");
    p.mekf.init_attitude_sigma = r.positive("init_attitude_sigma_rad");
    p.mekf.init_bias_sigma = r.positive("init_bias_sigma_rad_s");
    p.mekf.gate_chi2 = r.positive("gate_chi2");
    p.mekf.max_consecutive_rejects = r.integer("max_consecutive_rejects");
    if (r.has("rate_cutoff_rad_s")) p.mekf.rate_cutoff = r.non_negative("rate_cutoff_rad_s");
    r.finish();
  }

  // On-line identification (optional; off when absent). The priors are the case's estimates.
  if (doc.has("identification")) {
    MapReader r = doc.map("identification");
    gnc::IdentificationParams& id = p.identification;
    id.enabled = r.boolean("enabled");
    const std::string adopt = r.text("adopt");
    if (adopt == "off") {
      id.adopt = gnc::ModelAdoption::kOff;
    } else if (adopt == "auto") {
      id.adopt = gnc::ModelAdoption::kAuto;
    } else {
      r.fail("adopt", "expected off or auto, got '" + adopt + "'");
    }
    id.adopt_interval_s = r.positive("adopt_interval_s");
    if (r.has("adopt_sigmas")) id.adopt_sigmas = r.non_negative("adopt_sigmas");
    if (r.has("keep_model_after_fault")) {  // (I27)
      id.keep_model_after_fault = r.boolean("keep_model_after_fault");
    }
    gnc::IdentifierConfig& ic = id.config;
    const std::string mode = r.text("mode");
    if (mode == "joint") {
      ic.mode = gnc::IdentifierMode::kJoint;
    } else if (mode == "concurrent") {
      ic.mode = gnc::IdentifierMode::kConcurrent;
    } else {
      r.fail("mode", "expected joint or concurrent, got '" + mode + "'");
    }
    ic.window_s = r.positive("window_s");
    g.id_window_noisy_s = r.positive("window_noisy_s");
    if (r.has("window_early_s") || r.has("window_early_span_s")) {  // (I30), optional: off when absent
      ic.early_window_s = r.non_negative("window_early_s");
      ic.early_span_s = r.non_negative("window_early_span_s");
      if (ic.early_window_s > ic.window_s) r.fail("window_early_s", "must not exceed window_s");
    }
    ic.j_prior_sigma = r.positive("inertia_prior_sigma_kg_m2");
    ic.r_prior_sigma = r.positive("offset_prior_sigma_m");
    ic.k_prior_sigma = r.positive("strength_prior_sigma");
    ic.disturbance_sigma = r.non_negative("disturbance_sigma_nm");
    if (r.has("gyro_bias_sigma_rad_s")) {
      ic.gyro_bias_sigma = r.non_negative("gyro_bias_sigma_rad_s");
    }
    if (r.has("gyro_bias_estimated")) ic.gyro_bias_estimated = r.boolean("gyro_bias_estimated");
    if (r.has("mekf_bias_sigma_floor_rad_s")) {
      id.mekf_bias_sigma_floor = r.non_negative("mekf_bias_sigma_floor_rad_s");
    }
    if (r.has("second_order_noise")) ic.second_order_noise = r.boolean("second_order_noise");
    if (r.has("gate_chi2")) ic.gate_chi2 = r.non_negative("gate_chi2");
    if (r.has("gate_reinflate_after")) {
      ic.gate_reinflate_after = r.integer("gate_reinflate_after");
      if (ic.gate_reinflate_after < 1) r.fail("gate_reinflate_after", "must be >= 1");
    }
    if (r.has("min_inertia_information")) {
      ic.min_inertia_information = r.non_negative("min_inertia_information");
    }
    if (r.has("min_offset_information")) {
      ic.min_offset_information = r.non_negative("min_offset_information");
    }
    if (r.has("guard_halvings")) {  // (I28), optional: refused as before when absent
      ic.guard_halvings = r.integer("guard_halvings");
      if (ic.guard_halvings < 0 || ic.guard_halvings > 10) r.fail("guard_halvings", "must be in [0, 10]");
    }
    ic.j_forget_s = r.non_negative("inertia_forget_s");
    ic.r_forget_s = r.non_negative("offset_forget_s");
    ic.j_confident_rel = r.positive("inertia_confident_rel");
    ic.r_confident = r.positive("offset_confident_m");
    ic.k_confident = r.positive("strength_confident");
    if (r.has("excitation")) {  // README §I.6 (optional; off when absent)
      MapReader x = r.map("excitation");
      gnc::ExcitationConfig& xc = id.excitation;
      xc.enabled = x.boolean("enabled");
      xc.force_n = x.vec3("force_n");
      if (!(xc.force_n.minCoeff() >= 0.0 && xc.force_n.maxCoeff() > 0.0)) {
        x.fail("force_n", "every amplitude must be >= 0 and one > 0");
      }
      xc.duration_s = x.non_negative("duration_s");
      xc.r_sigma_stop_m = x.positive("r_sigma_stop_m");
      if (x.has("start_after_s")) xc.start_after_s = x.non_negative("start_after_s");
      if (x.has("r_sigma_target_m")) xc.r_sigma_target_m = x.non_negative("r_sigma_target_m");
      if (x.has("inertia_torque_nm")) {  // (X8), optional: no inertia phase when absent
        xc.inertia_torque_nm = x.vec3("inertia_torque_nm");
        if (!(xc.inertia_torque_nm.minCoeff() >= 0.0)) {
          x.fail("inertia_torque_nm", "every amplitude must be >= 0");
        }
      }
      x.finish();
    }
    r.finish();
  }

  // Thruster fault detection and isolation (optional; off when absent).
  if (doc.has("fdi")) {
    MapReader r = doc.map("fdi");
    gnc::FaultDetectorParams& fd = p.fdi;
    fd.enabled = r.boolean("enabled");
    fd.window_ticks = r.integer("window_ticks");
    g.fdi_window_noisy_ticks = r.integer("window_noisy_ticks");
    if (r.has("window_snr")) g.fdi_window_snr = r.non_negative("window_snr");  // (F30), optional
    fd.model_rel_floor = r.non_negative("model_rel_floor");
    if (r.has("model_floor_gyroscopic")) {  // (F22), optional (the floor on both terms when absent)
      fd.model_floor_gyroscopic = r.boolean("model_floor_gyroscopic");
    }
    fd.disturbance_sigma = r.non_negative("disturbance_sigma_nm");
    fd.confirm_llr = r.positive("confirm_llr");
    fd.margin_llr = r.non_negative("margin_llr");
    fd.suspect_chi2 = r.positive("suspect_chi2");
    fd.auto_isolate = r.boolean("auto_isolate");
    fd.model_sigmas = r.non_negative("model_sigmas");
    if (r.has("episode_restart")) fd.episode_restart = r.boolean("episode_restart");  // (F25), optional
    fd.probe_after_windows = r.integer("probe_after_windows");
    fd.probe_windows = r.integer("probe_windows");
    if (r.has("probe_aligned")) fd.probe_aligned = r.boolean("probe_aligned");  // (F27), optional
    if (r.has("centred_gyro_noise")) fd.centred_gyro_noise = r.boolean("centred_gyro_noise");  // (F28), optional
    if (r.has("probe_partial_rival")) fd.probe_partial_rival = r.boolean("probe_partial_rival");  // (F29), optional
    if (r.has("probe_read_closed")) fd.probe_read_closed = r.boolean("probe_read_closed");  // (F32), optional
    if (r.has("detect_early_ticks")) {  // (F33)
      fd.detect_early_ticks = r.integer("detect_early_ticks");
      if (fd.detect_early_ticks < 0 || fd.detect_early_ticks > 1000) {
        r.fail("detect_early_ticks", "must be in [0, 1000]");
      }
    }
    if (r.has("detect_early_chi2")) fd.detect_early_chi2 = r.positive("detect_early_chi2");
    if (r.has("skip_onset_window")) fd.skip_onset_window = r.boolean("skip_onset_window");  // (F21)
    if (r.has("onset_restart")) fd.onset_restart = r.boolean("onset_restart");  // (F45)
    if (r.has("probe_window_ticks")) {  // (F46)
      fd.probe_window_ticks = r.integer("probe_window_ticks");
      if (fd.probe_window_ticks != 0 && (fd.probe_window_ticks < 4 || fd.probe_window_ticks > 1000)) {
        r.fail("probe_window_ticks", "must be 0 or in [4, 1000]");
      }
    }
    if (r.has("probe_short_min_llr")) {  // (F47)
      fd.probe_short_min_llr = r.non_negative("probe_short_min_llr");
    }
    if (r.has("probe_start_llr")) {  // (F52)
      fd.probe_start_llr = r.non_negative("probe_start_llr");
      if (fd.probe_start_llr > 0.0 && !(fd.probe_start_llr < fd.confirm_llr)) {
        r.fail("probe_start_llr", "must be 0 or below confirm_llr");
      }
    }
    // (F14) stuck-on isolation inside identification; optional keys (off when absent).
    if (r.has("identified_isolation")) fd.identified_isolation = r.boolean("identified_isolation");
    if (r.has("identified_zero_chi2")) fd.identified_zero_chi2 = r.positive("identified_zero_chi2");
    if (r.has("identified_match_chi2")) {
      fd.identified_match_chi2 = r.positive("identified_match_chi2");
    }
    if (r.has("identified_margin_chi2")) {
      fd.identified_margin_chi2 = r.non_negative("identified_margin_chi2");
    }
    if (r.has("identified_windows")) fd.identified_windows = r.integer("identified_windows");
    if (r.has("identified_sweep")) fd.identified_sweep = r.boolean("identified_sweep");  // (F17)
    if (r.has("degraded_min_loss")) {  // (F18), off when absent
      fd.degraded_min_loss = r.non_negative("degraded_min_loss");
    }
    if (r.has("check_llr")) fd.check_llr = r.non_negative("check_llr");  // (F19), off when absent
    if (r.has("check_force_n")) fd.check_force_n = r.positive("check_force_n");
    if (r.has("check_windows")) fd.check_windows = r.integer("check_windows");
    if (r.has("check_interval_s")) fd.check_interval_s = r.non_negative("check_interval_s");
    if (r.has("check_fit_chi2")) fd.check_fit_chi2 = r.positive("check_fit_chi2");
    if (r.has("check_max_model_error")) {
      fd.check_max_model_error = r.positive("check_max_model_error");
    }
    if (r.has("check_min_llr")) fd.check_min_llr = r.non_negative("check_min_llr");  // (F24)
    if (r.has("check_quiet_start")) fd.check_quiet_start = r.boolean("check_quiet_start");  // (F34)
    if (r.has("check_score_unfit")) fd.check_score_unfit = r.boolean("check_score_unfit");  // (F35)
    if (r.has("survey_interval_s")) {  // (F36), off when absent
      fd.survey_interval_s = r.non_negative("survey_interval_s");
    }
    if (r.has("probe_chain")) fd.probe_chain = r.boolean("probe_chain");  // (F39)
    if (r.has("probe_read_elsewhere")) fd.probe_read_elsewhere = r.boolean("probe_read_elsewhere");  // (F40)
    if (r.has("check_model_null_space")) fd.check_model_null_space = r.boolean("check_model_null_space");  // (F42)
    if (r.has("survey_hold_only")) fd.survey_hold_only = r.boolean("survey_hold_only");  // (F43)
    if (r.has("survey_max_kick_rad_s")) fd.survey_max_kick_rad_s = r.non_negative("survey_max_kick_rad_s");  // (F44)
    if (r.has("survey_noise_kick")) fd.survey_noise_kick = r.boolean("survey_noise_kick");  // (F48)
    if (r.has("check_kick_after_fault")) fd.check_kick_after_fault = r.boolean("check_kick_after_fault");  // (F56)
    if (r.has("check_long_ticks")) {  // (F49), off when absent
      fd.check_long_ticks = r.integer("check_long_ticks");
      if (fd.check_long_ticks != 0 && (fd.check_long_ticks < 4 || fd.check_long_ticks > 1000)) {
        r.fail("check_long_ticks", "must be 0 or in [4, 1000]");
      }
    }
    if (r.has("check_long_energy")) fd.check_long_energy = r.positive("check_long_energy");
    if (r.has("check_long_evidence_energy")) {
      fd.check_long_evidence_energy = r.positive("check_long_evidence_energy");
    }
    if (r.has("degraded_loss_projection")) {  // (F51), off when absent
      fd.degraded_loss_projection = r.boolean("degraded_loss_projection");
    }
    if (r.has("check_long_reach")) {  // (F50), off when absent
      fd.check_long_reach = r.non_negative("check_long_reach");
      if (fd.check_long_reach > 0.95) r.fail("check_long_reach", "must be in [0, 0.95]");
    }
    if (r.has("episode_restart_leader")) fd.episode_restart_leader = r.boolean("episode_restart_leader");  // (F41)
    if (r.has("episode_restart_stale")) {  // (F38)
      fd.episode_restart_stale = r.boolean("episode_restart_stale");
    }
    if (r.has("check_blocker")) fd.check_blocker = r.boolean("check_blocker");  // (F37)
    if (r.has("survey_energy")) fd.survey_energy = r.positive("survey_energy");
    if (r.has("survey_loss_llr")) fd.survey_loss_llr = r.non_negative("survey_loss_llr");  // (F57)
    if (r.has("after_fault_max_j_rel")) {
      fd.after_fault_max_j_rel = r.non_negative("after_fault_max_j_rel");  // (F59)
    }
    if (r.has("balance")) {  // (F61) channel balance tests (optional; off when absent)
      MapReader b = r.map("balance");
      gnc::BalanceTestParams& bp = fd.balance;
      bp.kick_rad_s = b.non_negative("kick_rad_s");
      bp.force_n = b.positive("force_n");
      bp.quiet_ticks = b.integer("quiet_ticks");
      if (bp.quiet_ticks < 1 || bp.quiet_ticks > 10000) b.fail("quiet_ticks", "must be in [1, 10000]");
      bp.max_fire_ticks = b.integer("max_fire_ticks");
      if (bp.max_fire_ticks < 1 || bp.max_fire_ticks > 10000) {
        b.fail("max_fire_ticks", "must be in [1, 10000]");
      }
      bp.interval_s = b.non_negative("interval_s");
      bp.chi2_bound = b.positive("chi2_bound");
      bp.min_snr = b.positive("min_snr");
      bp.total_sigmas = b.positive("total_sigmas");
      bp.partial_sigmas = b.positive("partial_sigmas");
      if (bp.partial_sigmas < bp.total_sigmas) b.fail("partial_sigmas", "must be >= total_sigmas");
      bp.min_loss = b.non_negative("min_loss");
      if (bp.min_loss >= 1.0) b.fail("min_loss", "must be below 1");
      bp.max_tests = b.integer("max_tests");
      if (bp.max_tests < 1 || bp.max_tests > 1000) b.fail("max_tests", "must be in [1, 1000]");
      b.finish();
    }
    if (r.has("total_loss_sigmas")) {
      fd.total_loss_sigmas = r.non_negative("total_loss_sigmas");  // (F58)
    }
    if (r.has("survey_max_windows")) {
      fd.survey_max_windows = r.integer("survey_max_windows");
      if (fd.survey_max_windows < 1 || fd.survey_max_windows > 1000) {
        r.fail("survey_max_windows", "must be in [1, 1000]");
      }
    }
    if (r.has("check_fit_on_suspicion")) {  // (F31)
      fd.check_fit_on_suspicion = r.boolean("check_fit_on_suspicion");
    }
    p.fdi_table_rel_sigma = r.non_negative("table_model_rel_sigma");
    r.finish();
  }

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
  if (gd.has("slew_s")) p.guidance.slew_s = gd.non_negative("slew_s");
  if (gd.has("slew_ramp_s")) p.guidance.slew_ramp_s = gd.positive("slew_ramp_s");
  if (gd.has("track_momentum_k")) {
    p.guidance.track_momentum_k = gd.non_negative("track_momentum_k");
  }
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
  if (doc.has("plant_truth")) c.plant_truth = doc.get("plant_truth");
  // The plant's truth beyond the study (thruster faults, the valve driver's timeout): read by the
  // ground's loader (ground/config), never by the flight software.
  doc.skip("faults");
  doc.skip("valve_driver_timeout_s");
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
    case EstimatorChoice::kMekf: p.estimator.kind = gnc::EstimatorKind::kMekf; break;
  }
  // The MEKF's and the identifier's sensor noise: the case's (the sensors' data sheet), with a
  // floor for the noise-free cases so the filter stays well posed. SPEC §5: per-sample sigma =
  // sqrt(P / T_s); the MEKF's angle random walk is sqrt(P(dw)); its star-tracker attitude sigma
  // is 4 sigma_q (dtheta = 4 dq for small angles).
  p.mekf.gyro_arw = std::fmax(std::sqrt(c.gyro_psd), 1e-9);
  p.mekf.star_sigma = std::fmax(4.0 * std::sqrt(c.star_psd / m.sensor_period_s), 1e-7);
  p.identification.config.gyro_sigma = std::sqrt(c.gyro_psd / m.sensor_period_s);
  // A noise-free gyro is the study's idealised, perfect gyro: no bias either. A real one has the
  // data sheet's bias (gyro_bias_sigma_rad_s), carried by the identifier (README I17).
  if (c.gyro_psd <= 0.0) p.identification.config.gyro_bias_sigma = 0.0;
  // Nor is there any noise for the MEKF's rate stage (README M8) to filter: as the SPEC §6 rule
  // passes a perfect gyro through, the MEKF's rate is then the gyro less the bias, without the
  // model's lag (which with the case-4 model error costs the fuel-optimal trackers 50 %).
  if (c.gyro_psd <= 0.0) p.mekf.rate_cutoff = 0.0;
  if (noisy) {
    p.identification.config.window_s = g.id_window_noisy_s;
    // (I30) Early windows with quiet sensors only: a noisy gyro needs the long window from the first.
    p.identification.config.early_window_s = 0.0;
    p.identification.config.early_span_s = 0.0;
  }
  // A gyro is never noise-free: the detector assumes at least 1e-7 rad/s per sample (a
  // navigation-grade gyro's resolution), so the noise-free cases do not trust rates to the bit.
  // That floor was measured with the start sample's noise counted in every sample (2 sigma^2,
  // fdi README F28): with the centred noise its variance stays what was measured, 2 (1e-7)^2.
  const double gyro_floor = g.params.fdi.centred_gyro_noise ? 1e-7 * std::sqrt(2.0) : 1e-7;
  p.fdi.gyro_sigma = std::fmax(std::sqrt(c.gyro_psd / m.sensor_period_s), gyro_floor);
  if (noisy) {
    p.fdi.window_ticks = g.fdi_window_snr > 0.0
                             ? fdi_window_for_noise(p, std::sqrt(c.gyro_psd / m.sensor_period_s),
                                                    g.fdi_window_snr, g.params.fdi.window_ticks,
                                                    g.fdi_window_noisy_ticks)
                             : g.fdi_window_noisy_ticks;
    // (F46) The isolation test's window likewise: the shortest from gnc.yaml's in which the
    // weakest jet stands window_snr sigma above the gyro's noise, at most the bank's window (0,
    // the bank's window, without window_snr).
    if (p.fdi.probe_window_ticks > 0) {
      p.fdi.probe_window_ticks =
          g.fdi_window_snr > 0.0
              ? fdi_window_for_noise(p, std::sqrt(c.gyro_psd / m.sensor_period_s), g.fdi_window_snr,
                                     g.params.fdi.probe_window_ticks, p.fdi.window_ticks)
              : 0;
    }
  }
  const gnc::ParamCheck check = gnc::validate(p);
  if (!check.ok) {
    const std::string field = check.field;
    const bool model = field.rfind("mass_hat", 0) == 0 || field.rfind("rcs", 0) == 0;
    throw ConfigError(model ? m.file + " + " + c.file : g.file, field, check.reason);
  }
  return p;
}

int fdi_window_for_noise(const gnc::GncParams& p, double gyro_sigma, double snr, int min_ticks,
                         int max_ticks) {
  if (!(gyro_sigma > 0.0) || max_ticks <= min_ticks) return min_ticks;
  const gnc::Mat3 j_inv = gnc::total_inertia(p.mass_hat).inverse();
  const gnc::Mat38 b = gnc::torque_matrix(p.rcs, p.mass_hat.r_so_bcm);
  double a_min = 1e300;
  for (int c = 0; c < gnc::kChannels; ++c) {
    a_min = std::fmin(a_min, (j_inv * b.col(c)).norm() * p.rcs.u_max);
  }
  const double sigma = (p.fdi.centred_gyro_noise ? 1.0 : std::sqrt(2.0)) * gyro_sigma;
  for (int n = min_ticks; n < max_ticks; ++n) {
    const double nn = static_cast<double>(n);
    if (a_min * p.dt * std::sqrt(nn * (nn * nn - 1.0) / 12.0) / sigma >= snr) return n;
  }
  return max_ticks;
}

gnc::GncParams load_flight_params(const std::string& mission_path, const std::string& gnc_path,
                                  const std::string& case_path) {
  return flight_params(load_mission(mission_path), load_gnc(gnc_path), load_case(case_path));
}

}  // namespace rocksteady::config
