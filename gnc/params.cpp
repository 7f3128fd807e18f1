#include "gnc/params.hpp"

#include <cmath>

#include <Eigen/Cholesky>

#include "gnc/allocation/allocator.hpp"
#include "gnc/param_bounds.hpp"

namespace rocksteady::gnc {

GncParams study_gnc_params(double u_max) {
  GncParams p;
  p.mass_hat = study_true_mass_properties();
  p.rcs = study_rcs_layout(u_max);
  return p;
}

LawGains law_gains(const GncParams& p) {
  return LawGains{p.ntcl, p.el, p.feedforward, p.integral, p.adaptive, p.so3, p.dpd};
}

MekfConfig build_mekf_config(const GncParams& p) {
  MekfConfig c = p.mekf;
  c.dt = p.dt;
  c.gyro_max_rate = p.estimator.gyro_max_rate;
  c.quat_norm_tolerance = p.estimator.quat_norm_tolerance;
  return c;
}

void apply_flight_identification_settings(GncParams& p, double gyro_sigma) {
  IdentifierConfig& c = p.identification.config;
  const bool noisy = gyro_sigma > 0.0;
  c.mode = IdentifierMode::kJoint;
  c.window_s = noisy ? 60.0 : 20.0;
  c.early_window_s = noisy ? 0.0 : 12.0;  // (I30)
  c.early_span_s = noisy ? 0.0 : 60.0;
  c.j_prior_sigma = 1e7;
  c.r_prior_sigma = 1.0;
  c.k_prior_sigma = 0.01;
  c.disturbance_sigma = 0.57735026918962576;
  c.gyro_sigma = gyro_sigma;
  c.gyro_bias_sigma = noisy ? 3e-5 : 0.0;
  c.gyro_bias_estimated = false;
  c.second_order_noise = true;
  c.gate_chi2 = 16.27;
  c.gate_reinflate_after = 3;
  c.min_inertia_information = 1.0;
  c.min_offset_information = 1.0;
  c.guard_halvings = 3;
  c.j_forget_s = 0.0;
  c.r_forget_s = 0.0;
  c.j_confident_rel = 0.01;
  c.r_confident = 0.05;
  c.k_confident = 0.02;
  p.identification.adopt_interval_s = 300.0;
  p.identification.adopt_sigmas = 0.0;
  p.identification.mekf_bias_sigma_floor = 3e-6;
}

IdentifierConfig build_identifier_config(const GncParams& p) {
  IdentifierConfig c = p.identification.config;
  c.dt = p.dt;
  c.rcs = p.rcs;
  c.j0 = total_inertia(p.mass_hat);
  c.r0 = p.mass_hat.r_so_bcm;
  c.k0 = p.rcs.strength;
  // (I30) Early windows only while the excitation's inertia phase (X8) can fly its couples:
  // without them, short windows from a far prior measured worse at 60 s (estimation README I.12).
  const ExcitationConfig& x = p.identification.excitation;
  if (!(x.enabled && (x.inertia_torque_nm.array() > 0.0).any())) {
    c.early_window_s = 0.0;
    c.early_span_s = 0.0;
  }
  // (I22) With the detector's stuck-on isolation inside identification (F14), the identifier
  // carries a constant fault torque whose prior 1 sigma is the largest single-jet torque.
  c.fault_torque_sigma = 0.0;
  if (p.fdi.enabled && p.fdi.identified_isolation) {
    for (int i = 0; i < kThrusters; ++i) {
      const Vec3 arm = (thruster_position(p.rcs, i) + c.r0).cross(thruster_direction(p.rcs, i));
      c.fault_torque_sigma = std::fmax(c.fault_torque_sigma, arm.norm() * p.rcs.u_max);
    }
  }
  return c;
}

GncParams with_model(const GncParams& p, const Mat3& j_tot, const Vec3& r, const Vec16& k) {
  GncParams out = p;
  out.mass_hat.r_so_bcm = r;
  MassProperties sc_only = out.mass_hat;
  sc_only.j_ast.setZero();
  out.mass_hat.j_ast = j_tot - total_inertia(sc_only);  // Eq. (1) solved for J_ast
  out.mass_hat.j_ast = 0.5 * (out.mass_hat.j_ast + out.mass_hat.j_ast.transpose());
  out.rcs.strength = k;
  return out;
}

bool all_finite(const Mat3& m) { return m.allFinite(); }

bool is_symmetric_positive_definite(const Mat3& m) {
  if (!m.allFinite()) return false;
  if ((m - m.transpose()).norm() > 1e-9 * (1.0 + m.norm())) return false;
  const Eigen::LLT<Mat3> llt(0.5 * (m + m.transpose()));
  return llt.info() == Eigen::Success;
}

namespace {

ParamCheck bad(const char* field, const char* reason) { return ParamCheck{false, field, reason}; }


// Returns a failed check for `field` if m is not SPD.
bool check_spd(const Mat3& m, const char* field, ParamCheck& out) {
  if (!m.allFinite()) {
    out = bad(field, "non-finite value");
    return false;
  }
  if (!is_symmetric_positive_definite(m)) {
    out = bad(field, "not symmetric positive definite");
    return false;
  }
  return true;
}

}  // namespace

ParamCheck validate(const GncParams& p) {
  ParamCheck r;
  if (!finite_positive(p.dt)) return bad("dt", "GNC period must be positive and finite");
  if (p.dt > 10.0) return bad("dt", "GNC period above 10 s");

  const MassProperties& m = p.mass_hat;
  if (!finite_positive(m.m_sc)) return bad("mass_hat.m_sc", "mass must be positive and finite");
  if (!m.r_scm_so.allFinite()) return bad("mass_hat.r_scm_so", "non-finite value");
  if (!m.r_so_bcm.allFinite()) return bad("mass_hat.r_so_bcm", "non-finite value");
  if (!check_spd(m.j_sc, "mass_hat.j_sc", r)) return r;
  if (!check_spd(m.j_ast, "mass_hat.j_ast", r)) return r;
  if (!check_spd(total_inertia(m), "mass_hat (J_tot, Eq. 1)", r)) return r;

  if (!finite_positive(p.rcs.u_max)) return bad("rcs.u_max", "must be positive and finite");
  for (int k = 0; k < kPods; ++k) {
    if (!p.rcs.pod_position[k].allFinite()) return bad("rcs.pod_position", "non-finite value");
  }
  for (int i = 0; i < kChannels; ++i) {
    const Vec3& d = p.rcs.channel_direction[i];
    if (!d.allFinite() || std::fabs(d.norm() - 1.0) > 1e-6) {
      return bad("rcs.channel_direction", "not a unit vector");
    }
    if (p.rcs.channel_pod[i] < 0 || p.rcs.channel_pod[i] >= kPods) {
      return bad("rcs.channel_pod", "pod index out of range");
    }
  }
  for (int i = 0; i < kThrusters; ++i) {
    // A thruster producing less than 10 % of its calibrated force is a failed thruster (a fault
    // declaration), not a strength; more than 150 % is not a plausible calibration error.
    if (!std::isfinite(p.rcs.strength(i)) || p.rcs.strength(i) < 0.1 || p.rcs.strength(i) > 1.5) {
      return bad("rcs.strength", "thruster strength must be in [0.1, 1.5]");
    }
  }
  if (torque_matrix_rcond(torque_matrix(p.rcs, m.r_so_bcm)) < 1e-9) {
    return bad("rcs", "B_hat is rank-deficient (cannot produce torque about every axis)");
  }

  if (static_cast<int>(p.allocator) >= kAllocatorKindCount) {
    return bad("allocator", "unknown allocator");
  }

  if (static_cast<int>(p.law) >= kLawCount) {
    return bad("law", "unknown control law");
  }
  if (!check_spd(p.ntcl.k, "ntcl.K", r) || !check_spd(p.ntcl.lambda, "ntcl.Lambda", r)) return r;
  if (!check_spd(p.el.k, "el.K", r) || !check_spd(p.el.lambda, "el.Lambda", r)) return r;
  if (!check_spd(p.feedforward.k, "feedforward.K", r) ||
      !check_spd(p.feedforward.lambda, "feedforward.Lambda", r)) {
    return r;
  }
  if (!check_spd(p.integral.k, "integral.K", r) ||
      !check_spd(p.integral.lambda, "integral.Lambda", r) ||
      !check_spd(p.integral.k_i, "integral.K_I", r)) {
    return r;
  }
  if (!finite_positive(p.integral.integral_limit_nm)) {
    return bad("integral.integral_limit", "must be positive and finite");
  }
  if (!check_spd(p.adaptive.k, "adaptive.K", r) ||
      !check_spd(p.adaptive.lambda, "adaptive.Lambda", r)) {
    return r;
  }
  if (!finite_positive(p.adaptive.gamma)) return bad("adaptive.Gamma", "must be positive");
  if (!finite_positive(p.adaptive.eig_floor_ratio) || p.adaptive.eig_floor_ratio >= 1.0) {
    return bad("adaptive.eig_floor_ratio", "must be in (0, 1)");
  }
  if (!std::isfinite(p.adaptive.eig_ceiling_ratio) || p.adaptive.eig_ceiling_ratio <= 1.0) {
    return bad("adaptive.eig_ceiling_ratio", "must be greater than 1");
  }
  if (!check_spd(p.so3.k, "so3.K", r) || !check_spd(p.so3.lambda, "so3.Lambda", r)) return r;
  if (!check_spd(p.dpd.k_d, "dpd.K_d", r)) return r;
  if (!finite_positive(p.dpd.k_p)) return bad("dpd.k_p", "must be positive and finite");

  const GuidanceParams& g = p.guidance;
  if (!finite_positive(g.omega_switch)) return bad("guidance.omega_switch", "must be positive");
  if (!finite_positive(g.eps_trans)) return bad("guidance.eps_trans", "must be positive");
  if (g.omega_switch >= g.eps_trans) {
    return bad("guidance.omega_switch", "must be below eps_trans");
  }
  if (!finite_positive(g.k_qd)) return bad("guidance.k_qd", "must be positive");
  if (!g.q_final.allFinite() || g.q_final.norm() > 1.0) {
    return bad("guidance.q_final", "must be a finite MRP with |q| <= 1");
  }
  if (!std::isfinite(g.track_reset_period_s) || g.track_reset_period_s < 0.0) {
    return bad("guidance.track_reset_period", "must be >= 0");
  }
  if (!std::isfinite(g.slew_s) || g.slew_s < 0.0) return bad("guidance.slew", "must be >= 0");
  if (!finite_positive(g.slew_ramp_s)) return bad("guidance.slew_ramp", "must be positive");
  if (!std::isfinite(g.track_momentum_k) || g.track_momentum_k < 0.0) {
    return bad("guidance.track_momentum_k", "must be >= 0");
  }

  const EstimatorParams& e = p.estimator;
  if (static_cast<int>(e.kind) >= kEstimatorKindCount) {
    return bad("estimator.kind", "unknown estimator");
  }
  if (!finite_positive(e.omega_c)) return bad("estimator.omega_c", "must be positive");
  if (e.omega_c * p.dt > 3.14159265358979323846) {
    return bad("estimator.omega_c", "cutoff above the Nyquist rate of the GNC period");
  }
  if (e.predict_substeps < 1 || e.predict_substeps > 100) {
    return bad("estimator.predict_substeps", "must be in [1, 100]");
  }

  if (!finite_positive(e.gyro_max_rate)) return bad("estimator.gyro_max_rate", "must be positive");
  if (!finite_positive(e.quat_norm_tolerance) || e.quat_norm_tolerance >= 1.0) {
    return bad("estimator.quat_norm_tolerance", "must be in (0, 1)");
  }

  if (e.kind == EstimatorKind::kMekf) {
    const MekfConfigCheck mc = validate(build_mekf_config(p));
    if (!mc.ok) return bad(mc.field, mc.reason);
  }
  const IdentificationParams& id = p.identification;
  if (static_cast<int>(id.adopt) >= kModelAdoptionCount) {
    return bad("identification.adopt", "unknown adoption policy");
  }
  if (!finite_positive(id.adopt_interval_s)) {
    return bad("identification.adopt_interval", "must be positive and finite");
  }
  if (!finite_non_negative(id.adopt_sigmas)) {
    return bad("identification.adopt_sigmas", "must be >= 0 and finite");
  }
  if (!finite_non_negative(id.mekf_bias_sigma_floor)) {
    return bad("identification.mekf_bias_sigma_floor", "must be >= 0 and finite");
  }
  if (id.enabled) {
    const IdentifierConfigCheck ic = validate(build_identifier_config(p));
    if (!ic.ok) return bad(ic.field, ic.reason);
  }
  if (id.excitation.enabled) {
    const ExcitationConfigCheck xc = validate(id.excitation);
    if (!xc.ok) return bad(xc.field, xc.reason);
  }

  if (p.fdi.enabled) {
    const Check fc = validate(p.fdi);
    if (!fc.ok) return fc;
  }
  if (!finite_non_negative(p.fdi_table_rel_sigma)) {
    return bad("fdi_table_rel_sigma", "must be >= 0 and finite");
  }

  if (static_cast<int>(p.mode.initial) >= kModeCount) {
    return bad("mode.initial", "unknown mode");
  }
  if (p.mode.initial == Mode::kTrack) return bad("mode.initial", "cannot boot into TRACK");
  if (!finite_positive(p.mode.sensor_timeout_s) || p.mode.sensor_timeout_s < p.dt) {
    return bad("mode.sensor_timeout", "must be at least one GNC period");
  }
  if (!finite_positive(p.isp_s)) return bad("isp", "must be positive");
  if (!finite_positive(p.g0)) return bad("g0", "must be positive");
  return check_bounds(p);  // the physical ranges (gnc/param_bounds.cpp)
}

}  // namespace rocksteady::gnc
