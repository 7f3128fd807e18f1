#include "wire/convert.hpp"

#include "wire/codec.hpp"

namespace rocksteady::wire {

namespace {

template <int N, class Vec> void put(const Vec& v, double (&a)[N]) {
  for (int i = 0; i < N; ++i) a[i] = v(i);
}
template <int N, class Vec> void get(const double (&a)[N], Vec& v) {
  for (int i = 0; i < N; ++i) v(i) = a[i];
}

}  // namespace

hal::RawSensors to_raw(const rocksteady::sensor_frame_t& m) {
  hal::RawSensors s{};
  s.seq = m.seq;
  s.t = m.t;
  s.gyro.t = m.gyro_t;
  get(m.gyro_rate, s.gyro.rate);
  s.gyro.valid = m.gyro_valid != 0;
  s.star.t = m.star_t;
  get(m.star_quat, s.star.quat);
  s.star.valid = m.star_valid != 0;
  return s;
}

rocksteady::sensor_frame_t to_message(const hal::RawSensors& s) {
  auto m = make<rocksteady::sensor_frame_t>();
  m.seq = s.seq;
  m.t = s.t;
  m.gyro_t = s.gyro.t;
  put(s.gyro.rate, m.gyro_rate);
  m.gyro_valid = s.gyro.valid ? 1 : 0;
  m.star_t = s.star.t;
  put(s.star.quat, m.star_quat);
  m.star_valid = s.star.valid ? 1 : 0;
  return m;
}

rocksteady::thruster_cmd_t to_message(const hal::ThrusterOutputs& outputs, const gnc::Vec8& channel_force,
                                      std::int64_t seq, double t) {
  auto m = make<rocksteady::thruster_cmd_t>();
  m.seq = seq;
  m.t = t;
  m.enabled = outputs.enabled ? 1 : 0;
  put(channel_force, m.channel_force);
  for (int i = 0; i < hal::kThrusters; ++i) {
    const auto k = static_cast<std::size_t>(i);
    m.thruster_on[i] = outputs.on[k] ? 1 : 0;
    m.thruster_force[i] = outputs.on[k] ? outputs.force[k] : 0.0;
  }
  for (int p = 0; p < gnc::kPods; ++p) {
    m.valve_closed[p] = outputs.valve_open[static_cast<std::size_t>(p)] ? 0 : 1;
  }
  return m;
}

hal::ThrusterOutputs to_outputs(const rocksteady::thruster_cmd_t& m) {
  hal::ThrusterOutputs o{};
  o.enabled = m.enabled != 0;
  for (int i = 0; i < hal::kThrusters; ++i) {
    const auto k = static_cast<std::size_t>(i);
    o.on[k] = o.enabled && m.thruster_on[i] != 0;
    o.force[k] = o.on[k] ? m.thruster_force[i] : 0.0;
  }
  for (int p = 0; p < gnc::kPods; ++p) o.valve_open[static_cast<std::size_t>(p)] = m.valve_closed[p] == 0;
  return o;
}

gnc::Vec8 channel_forces(const rocksteady::thruster_cmd_t& m) {
  gnc::Vec8 u;
  get(m.channel_force, u);
  return u;
}

void fill_gnc(const gnc::GncOutput& out, rocksteady::gnc_telemetry_t& m) {
  const gnc::GncTelemetry& g = out.telemetry;
  m.kind = rocksteady::gnc_telemetry_t::KIND;
  m.version = rocksteady::gnc_telemetry_t::VERSION;
  m.t = g.t;
  m.tick = g.tick;
  m.mode = static_cast<std::int8_t>(g.mode);
  m.law = static_cast<std::int8_t>(g.law);
  m.phase = static_cast<std::int8_t>(g.phase);
  m.trajectory_loaded = g.trajectory_loaded ? 1 : 0;
  put(g.omega_hat, m.omega_hat);
  put(g.q_hat, m.q_hat);
  put(g.q_d, m.q_d);
  put(g.omega_r, m.omega_r);
  put(g.attitude_error, m.attitude_error);
  put(g.a_hat, m.a_hat);
  put(g.integral, m.integral);
  put(g.alloc.torque_requested, m.torque_requested);
  put(g.alloc.torque_achieved, m.torque_achieved);
  m.saturated = g.alloc.saturated ? 1 : 0;
  m.alloc_scale = g.alloc.scale;
  m.thrusters_enabled = out.command.enabled ? 1 : 0;
  put(out.command.force, m.channel_force);
  m.fuel_kg = g.fuel_kg;
  m.sensor_rejects = g.sensor_rejects;
  const gnc::EstimationTelemetry& e = g.est;
  m.mekf_active = e.mekf ? 1 : 0;
  put(e.gyro_bias, m.gyro_bias);
  put(e.attitude_sigma, m.attitude_sigma);
  put(e.bias_sigma, m.gyro_bias_sigma);
  m.star_gated = e.star_gated;
  m.identifying = e.identifying ? 1 : 0;
  put(e.j, m.id_j);
  put(e.j_sigma, m.id_j_sigma);
  put(e.r, m.id_r);
  put(e.r_sigma, m.id_r_sigma);
  put(e.k, m.id_k);
  put(e.k_sigma, m.id_k_sigma);
  put(e.j_cov, m.id_j_cov);
  put(e.r_cov, m.id_r_cov);
  m.id_thrust_scale_sigma = e.thrust_scale_sigma;
  m.id_inertia_confident = e.inertia_confident ? 1 : 0;
  m.id_offset_confident = e.offset_confident ? 1 : 0;
  m.id_thruster_confident = e.thruster_confident;
  m.id_excited_inertia = e.excited_inertia ? 1 : 0;
  m.id_excited_offset = e.excited_offset ? 1 : 0;
  m.id_excited_thrusters = e.excited_thrusters;
  m.id_offset_unobservable = static_cast<std::int8_t>(e.offset_unobservable);
  put(e.residual_torque, m.id_residual_torque);
  m.id_residual_chi2 = e.residual_chi2;
  m.id_windows = e.windows;
  put(e.rate_bias_sigma, m.id_rate_bias_sigma);
  m.id_windows_gated = e.windows_gated;
  m.id_gate_reinflations = e.gate_reinflations;
  m.id_guard_refusals = e.guard_refusals;
  m.id_excitation_active = e.excitation_active ? 1 : 0;
  put(e.excitation_force, m.id_excitation_force);
  m.id_excitation_gamma = e.excitation_gamma;
  m.id_excitation_inertia = e.excitation_inertia ? 1 : 0;
  put(e.excitation_torque, m.id_excitation_torque);
  m.id_candidate = static_cast<std::int8_t>(e.candidate);
  m.model_adoptions = e.adoptions;
  const gnc::FdiTelemetry& f = g.fdi;
  m.fdi_enabled = f.enabled ? 1 : 0;
  put(f.residual, m.fdi_residual);
  m.fdi_chi2 = f.chi2;
  m.fdi_noise_sigma = f.noise_sigma;
  m.fdi_best = f.best;
  m.fdi_best_llr = f.best_llr;
  m.fdi_runner_up_llr = f.runner_up_llr;
  m.fdi_suspected_on = f.suspected_on;
  m.fdi_suspected_off = f.suspected_off;
  m.fdi_confirmed_on = f.confirmed_on;
  m.fdi_confirmed_off = f.confirmed_off;
  m.fdi_confirmed_degraded = f.confirmed_degraded;
  for (int i = 0; i < gnc::kThrusters; ++i) m.fdi_strength_factor[i] = f.strength_factor(i);
  for (int p = 0; p < gnc::kPods; ++p) m.valve_open[p] = f.valve_open[static_cast<std::size_t>(p)] ? 1 : 0;
  m.isolation_inhibited = f.isolation_inhibited ? 1 : 0;
  m.fdi_windows = f.windows;
  m.fdi_probe_pod = f.probe_pod;
  m.fdi_probes = f.probes;
  m.fdi_check_jet = f.check_jet;
  m.fdi_checks = f.checks;
  m.reduced_authority = g.alloc.reduced_authority ? 1 : 0;
  m.alloc_rank = static_cast<std::int8_t>(g.alloc.rank);
}

}  // namespace rocksteady::wire
