#include "ground/campaign/runner.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <memory>

#include <Eigen/Cholesky>

#include "gnc/estimation/identifier.hpp"
#include "gnc/math/rotation.hpp"
#include "ground/campaign/plant_binding.hpp"
#include "ground/plant/plant.hpp"
#ifdef ROCKSTEADY_HAVE_PLANNER
#include "ground/planner/replanner.hpp"
#endif

namespace rocksteady::campaign {

const char* to_string(RunStatus s) {
  switch (s) {
    case RunStatus::kOk: return "ok";
    case RunStatus::kNoReference: return "no_reference";
    case RunStatus::kError: return "error";
  }
  return "?";
}

template <int N>
double normalised_error(const Eigen::Matrix<double, N, 1>& err,
                        const Eigen::Matrix<double, N*(N + 1) / 2, 1>& cov_packed,
                        const Eigen::Matrix<double, N, 1>& sigma) {
  const Eigen::Matrix<double, N, N> c = gnc::unpack_upper<N>(cov_packed);
  const Eigen::LLT<Eigen::Matrix<double, N, N>> llt(c);
  if (llt.info() == Eigen::Success && c.diagonal().minCoeff() > 0.0) {
    const double e = err.dot(llt.solve(err));
    if (std::isfinite(e)) return e;
  }
  // Not positive definite (not yet reported, or a direction known exactly): the 1 sigma alone.
  return err.cwiseQuotient(sigma.cwiseMax(1e-300)).squaredNorm();
}
template double normalised_error<3>(const Eigen::Matrix<double, 3, 1>&,
                                    const Eigen::Matrix<double, 6, 1>&,
                                    const Eigen::Matrix<double, 3, 1>&);
template double normalised_error<6>(const Eigen::Matrix<double, 6, 1>&,
                                    const Eigen::Matrix<double, 21, 1>&,
                                    const Eigen::Matrix<double, 6, 1>&);

gnc::GncParams flight_params(const config::RunSetup& setup, const Strategy& strategy) {
  gnc::GncParams p = setup.flight;
  p.law = strategy.law;
  if (strategy.mekf) p.estimator.kind = gnc::EstimatorKind::kMekf;
  if (strategy.identify) {
    p.identification.enabled = true;
    p.identification.adopt = gnc::ModelAdoption::kAuto;
    if (strategy.excite) p.identification.excitation.enabled = true;
  }
  if (strategy.fdi) p.fdi.enabled = true;
  return p;
}

RunResult run_closed_loop(const config::RunSetup& setup, const Strategy& strategy, FlightSide& flight,
                          const gnc::TrajectoryTable* trajectory, const RunOptions& options,
                          const std::string& no_reference_note) {
  RunResult r;
  r.case_name = setup.case_name;
  r.case_number = setup.case_number;
  r.strategy = strategy.name;
  r.faults = plant::describe(setup.truth.faults);
  if (strategy.needs_trajectory() && trajectory == nullptr) {
    r.status = RunStatus::kNoReference;
    r.note = no_reference_note;
    return r;
  }
  const auto wall0 = std::chrono::steady_clock::now();

  plant::Plant plant(setup.truth);
  PlantBinding ports(plant);
  FlightSetup fs;
  fs.params = flight_params(setup, strategy);
  if (strategy.replans()) {
    fs.params.identification.adopt_sigmas = options.replan.adopt_sigmas;
    if (options.replan.offset_confident_m > 0.0) {
      fs.params.identification.config.r_confident = options.replan.offset_confident_m;
    }
    if (options.replan.slew_s > 0.0) fs.params.guidance.slew_s = options.replan.slew_s;
    if (options.replan.momentum_k > 0.0) {
      fs.params.guidance.track_momentum_k = options.replan.momentum_k;
    }
  }
  fs.start_mode = strategy.needs_trajectory() ? gnc::Mode::kTrack : gnc::Mode::kDetumble;
  fs.trajectory = strategy.needs_trajectory() ? trajectory : nullptr;
  flight.setup(fs, ports, ports);
  if (options.on_start) options.on_start(plant);

  // The re-planner, in simulated time: it reads the flight's telemetry each tick and uplinks its
  // plans through the flight side (chunks + LOAD_TRAJECTORY), no earlier than t + latency.
#ifdef ROCKSTEADY_HAVE_PLANNER
  std::unique_ptr<ground::planner::Replanner> replanner;
  int refusals_seen = 0;
  if (strategy.replans()) {
    ground::planner::ReplanPolicy pol;
    const ReplanOptions& o = options.replan;
    pol.latency_s = o.latency_s;
    pol.first_plan_s = o.first_plan_s;
    pol.first_plan_max_s = o.first_plan_max_s;
    pol.period_s = o.period_s;
    pol.error_fraction = o.error_fraction;
    pol.on_model_update = o.on_model_update;
    pol.min_interval_s = o.min_interval_s;
    pol.horizon_factor = o.horizon_factor;
    pol.min_horizon_s = o.min_horizon_s;
    pol.early_plan_s = o.early_plan_s;
    pol.early_sigmas = o.early_sigmas;
    pol.early_j_rel = o.early_j_rel;
    pol.early_r_m = o.early_r_m;
    pol.refuted_max_s = o.refuted_max_s;
    pol.on_identified = o.on_identified;
    pol.adopt_wait_s = o.adopt_wait_s;
    pol.adopt_settle_tau = o.adopt_settle_tau;
    replanner = std::make_unique<ground::planner::Replanner>(fs.params, pol);
  }
#else
  if (strategy.replans()) {
    r.status = RunStatus::kNoReference;
    r.note = "no reference: re-planning needs the planner (not built into this campaign)";
    return r;
  }
#endif

  const double dt = setup.truth.control_period_s;
  const double duration = options.duration_s >= 0.0 ? options.duration_s : setup.duration_s;
  const auto n_ticks = static_cast<std::uint64_t>(std::llround(duration / dt));
  const Eigen::Vector3d q_final = fs.params.guidance.q_final;
  std::uint64_t log_every = 0;
  if (options.log_interval_s > 0.0) {
    log_every = std::max<std::uint64_t>(1, static_cast<std::uint64_t>(
                                               std::llround(options.log_interval_s / dt)));
    r.series.reserve(static_cast<std::size_t>(n_ticks / log_every + 2));
  }

  // The identifier's errors against the truth, with its reported covariances (NEES e' C^-1 e, 6
  // and 3 dof; the correlations count: J's errors along the thrust scale (I29) are one number in
  // six parameters): the marks and the time series.
  const Eigen::Matrix3d j_true = plant.inertia();
  const Eigen::Vector3d r_true = setup.truth.mass.r_so_bcm;
  const gnc::Vec16 k_true = setup.truth.thruster_strength;
  struct IdentificationErrors {
    double j_rel, r_err_m, k_max_err, j_nees, r_nees;
  };
  auto identification_errors = [&](const gnc::EstimationTelemetry& e) {
    const Eigen::Matrix3d j_hat = gnc::inertia_matrix(e.j);
    const gnc::Vec6 da = gnc::inertia_params(j_hat) - gnc::inertia_params(j_true);
    return IdentificationErrors{
        (j_hat - j_true).norm() / j_true.norm(), (e.r - r_true).norm(),
        (e.k - k_true).cwiseAbs().maxCoeff(),
        normalised_error<6>(da, e.j_cov, e.j_sigma),
        normalised_error<3>(e.r - r_true, e.r_cov, e.r_sigma)};
  };

  ConvergenceTracker omega_conv(setup.omega_tol_rad_s);
  ConvergenceTracker q_conv(setup.q_tol);
  auto record = [&](const gnc::GncOutput& o) {
    TimeRow row;
    row.t = plant.t();
    row.omega = plant.omega();
    row.q = plant.mrp();
    row.omega_hat = o.telemetry.omega_hat;
    row.q_hat = o.telemetry.q_hat;
    row.torque_cmd = o.telemetry.alloc.torque_requested;
    // Channel forces of the thrusters fired at t (the plant applies them, clipped at u_max, until
    // t + dt).
    row.force = ports.channel_forces();
    row.fuel_kg = plant.fuel_kg();
    row.fuel_hat_kg = o.telemetry.fuel_kg;
    row.mode = o.telemetry.mode;
    if (o.telemetry.est.identifying) {
      const gnc::EstimationTelemetry& e = o.telemetry.est;
      const IdentificationErrors ie = identification_errors(e);
      row.j_rel = ie.j_rel;
      row.r_err_m = ie.r_err_m;
      row.k_max_err = ie.k_max_err;
      row.j_nees = ie.j_nees;
      row.r_nees = ie.r_nees;
      row.r_sigma_max_m = e.r_sigma.maxCoeff();
      row.windows_gated = e.windows_gated;
      row.gate_reinflations = e.gate_reinflations;
      row.windows = e.windows;
      row.guard_refusals = e.guard_refusals;
      row.excited_inertia = e.excited_inertia;
    }
    if (o.telemetry.fdi.enabled) {
      const gnc::FdiTelemetry& f = o.telemetry.fdi;
      row.fdi_chi2 = f.chi2;
      row.fdi_best = f.best;
      row.fdi_best_llr = f.best_llr;
      row.fdi_confirmed =
          static_cast<std::uint16_t>(f.confirmed_on | f.confirmed_off | f.confirmed_degraded);
      row.fdi_check_jet = f.check_jet;
    }
    r.series.push_back(row);
  };

  // t = 0: the initial state counts for the figures of merit.
  omega_conv.add(0.0, plant.omega().norm(), 0.0);
  q_conv.add(0.0, attitude_error(plant.mrp(), q_final), 0.0);
  r.max_rate_rad_s = plant.omega().norm();

  // Estimation against the truth: the estimate of tick k belongs to the state before the plant
  // advances.
  EstimationReport& est = r.estimation;
  est.estimator = fs.params.estimator.kind == gnc::EstimatorKind::kMekf     ? "mekf"
                  : fs.params.estimator.kind == gnc::EstimatorKind::kFilter ? "filter"
                                                                            : "passthrough";
  est.identifying = fs.params.identification.enabled;
  const double marks[] = {60.0, 300.0, 600.0, 1000.0, 3000.0, 10000.0, 30000.0};
  std::size_t next_mark = 0;
  if (est.identifying) {
    for (double m : marks) est.marks.push_back(IdentificationMark{m});
    est.strengths.resize(16);
  }
  double sq_att = 0.0;
  double sq_rate = 0.0;
  std::uint64_t n_est = 0;
  auto score_estimate = [&](const gnc::GncOutput& o) {
    const double t = plant.t();
    if (t >= 60.0) {
      const gnc::Vec4 qh = gnc::mrp::to_quaternion(o.telemetry.q_hat);
      const gnc::Vec4& qt = plant.beta();
      const double c = std::min(1.0, std::fabs(qh.dot(qt)));
      const double angle = 2.0 * std::atan2(std::sqrt(std::max(0.0, 1.0 - c * c)), c);
      const double werr = (o.telemetry.omega_hat - plant.omega()).norm();
      sq_att += angle * angle;
      sq_rate += werr * werr;
      est.attitude_max_rad = std::max(est.attitude_max_rad, angle);
      est.rate_max_rad_s = std::max(est.rate_max_rad_s, werr);
      ++n_est;
    }
    if (next_mark < est.marks.size() && t >= marks[next_mark] - 1e-9) {
      const gnc::EstimationTelemetry& e = o.telemetry.est;
      IdentificationMark& m = est.marks[next_mark++];
      const IdentificationErrors ie = identification_errors(e);
      m.reached = true;
      m.j_rel = ie.j_rel;
      m.r_err_m = ie.r_err_m;
      m.k_max_err = ie.k_max_err;
      m.j_nees = ie.j_nees;
      m.r_nees = ie.r_nees;
      m.inertia_confident = e.inertia_confident;
      m.offset_confident = e.offset_confident;
      m.offset_unobservable = e.offset_unobservable;
    }
    // Each thruster's strength 600 s after the flight first asked it for thrust: thruster 2c is
    // the "+" half of channel c, 2c+1 the "-" half; a closed pod fires neither.
    for (int i = 0; i < static_cast<int>(est.strengths.size()); ++i) {
      StrengthMark& sm = est.strengths[static_cast<std::size_t>(i)];
      if (sm.reached) continue;
      const int c = i / 2;
      const double asked = o.command.enabled ? o.command.force(c) : 0.0;
      const double half = i % 2 == 0 ? std::max(asked, 0.0) : std::max(-asked, 0.0);
      const auto pod =
          static_cast<std::size_t>(fs.params.rcs.channel_pod[static_cast<std::size_t>(c)]);
      const bool fired = half > 0.0 && o.command.valve_open[pod];
      if (!sm.first_fired_s) {
        if (!fired) continue;
        sm.first_fired_s = t;
      }
      if (t >= *sm.first_fired_s + kStrengthMarkAfterFiringS - 1e-9) {
        const gnc::EstimationTelemetry& e = o.telemetry.est;
        sm.reached = true;
        sm.err = std::abs(e.k(i) - k_true(i));
        sm.sigma = e.k_sigma(i);
        sm.confident = ((e.thruster_confident >> i) & 1u) != 0;
      } else if (fired) {
        sm.impulse_ns += half * fs.params.dt;
      }
    }
  };

  std::uint64_t pending_progress = 0;
  for (std::uint64_t k = 0; k < n_ticks; ++k) {
    flight.step();
    const gnc::GncOutput& out = flight.output();
    score_estimate(out);
#ifdef ROCKSTEADY_HAVE_PLANNER
    if (replanner) {
      if (flight.trajectory_refusals() > refusals_seen) {
        refusals_seen = flight.trajectory_refusals();
        replanner->refused("trajectory_stale at the switch");
      }
      if (const auto d = replanner->update(out.telemetry)) {
        std::string why;
        if (!flight.uplink_plan(*d->table, d->upload_id, d->first, fs.params.law, why)) {
          replanner->refused(why);
        }
      }
    }
#endif
    if (fs.params.fdi.enabled) {
      const gnc::FdiTelemetry& f = out.telemetry.fdi;
      FdiReport& d = r.fdi;
      d.enabled = true;
      const double t = plant.t();
      if (!d.first_suspicion_s && f.suspicions > 0) d.first_suspicion_s = t;
      const std::uint16_t now =
          static_cast<std::uint16_t>(f.confirmed_on | f.confirmed_off | f.confirmed_degraded);
      if (!d.first_confirmation_s && now != 0) {
        d.first_confirmation_s = t;
        for (int i = 0; i < 16; ++i) {
          if ((now >> i) & 1u) {
            d.thruster = i;
            d.kind = ((f.confirmed_on >> i) & 1u)    ? "stuck-on"
                     : ((f.confirmed_off >> i) & 1u) ? "stuck-off"
                                                     : "degraded";
            break;
          }
        }
      }
      if (d.thruster >= 0) d.factor = f.strength_factor(d.thruster);
      if (!d.valve_closed_s) {
        for (bool v : f.valve_open) {
          if (!v) d.valve_closed_s = t;
        }
      }
      d.confirmed_on = f.confirmed_on;
      d.confirmed_off = f.confirmed_off;
      d.confirmed_degraded = f.confirmed_degraded;
      if (!setup.truth.faults.empty() && !d.fault_detected_s && f.suspicions > d.suspicions &&
          t >= setup.truth.faults.front().onset_s) {
        d.fault_detected_s = t;
      }
      d.suspicions = f.suspicions;
      d.checks = f.checks;
      d.checks_unfit = f.checks_unfit;
      d.surveys = f.surveys;
      d.balance_tests = f.balance_tests;
      d.balance_confirmations = f.balance_confirmations;
      if (!setup.truth.faults.empty()) {
        // The first injected fault's jet, commanded by the flight this tick (held over it).
        const plant::ThrusterFault& inj = setup.truth.faults.front();
        const int c = inj.thruster / 2;
        const double asked = out.command.enabled ? out.command.force(c) : 0.0;
        const double half = inj.thruster % 2 == 0 ? std::max(asked, 0.0) : std::max(-asked, 0.0);
        const auto pod = static_cast<std::size_t>(fs.params.rcs.channel_pod[static_cast<std::size_t>(c)]);
        if (t >= inj.onset_s && half > 0.0 && out.command.valve_open[pod]) {
          if (!d.fault_first_commanded_s) d.fault_first_commanded_s = t;
          if (!d.first_confirmation_s || *d.first_confirmation_s >= t) {
            d.fault_commanded_s += fs.params.dt;
            d.fault_commanded_impulse_ns += half * fs.params.dt;
          }
        }
      }
    }
    if (log_every != 0 && k % log_every == 0) {
      // The row at time t_k: the state, the estimate and the command computed from it.
      record(out);
    }
    ports.advance();
    if (out.telemetry.alloc.saturated) ++r.saturated_ticks;

    const double w = plant.omega().norm();
    const double t = plant.t();
    const double fuel = plant.fuel_kg();
    omega_conv.add(t, w, fuel);
    q_conv.add(t, attitude_error(plant.mrp(), q_final), fuel);
    r.max_rate_rad_s = std::max(r.max_rate_rad_s, w);
    if (!std::isfinite(w)) {
      r.status = RunStatus::kError;
      r.note = "non-finite plant state at t = " + std::to_string(t);
      break;
    }
    if (options.progress_ticks != nullptr && ++pending_progress == 4096) {
      options.progress_ticks->fetch_add(pending_progress, std::memory_order_relaxed);
      pending_progress = 0;
    }
  }
  if (options.progress_ticks != nullptr) {
    options.progress_ticks->fetch_add(pending_progress, std::memory_order_relaxed);
  }
  const gnc::GncOutput& out = flight.output();
  if (log_every != 0) record(out);  // the final state

  r.t_omega_conv_s = omega_conv.time();
  r.fuel_at_t_omega_kg = omega_conv.fuel_kg();
  r.t_q_conv_s = q_conv.time();
  r.fuel_at_t_q_kg = q_conv.fuel_kg();
  r.total_fuel_kg = plant.fuel_kg();
  r.fuel_hat_kg = out.telemetry.fuel_kg;
  r.final_rate_rad_s = plant.omega().norm();
  r.final_q_error = attitude_error(plant.mrp(), q_final);
  r.final_mode = gnc::to_string(out.telemetry.mode);
  if (n_est > 0) {
    est.attitude_rms_rad = std::sqrt(sq_att / static_cast<double>(n_est));
    est.rate_rms_rad_s = std::sqrt(sq_rate / static_cast<double>(n_est));
  }
  est.model_adoptions = out.telemetry.est.adoptions;
  for (int i = 0; i < 16; ++i) {
    r.fdi.confirmations +=
        (((r.fdi.confirmed_on | r.fdi.confirmed_off | r.fdi.confirmed_degraded) >> i) & 1u) ? 1 : 0;
  }
#ifdef ROCKSTEADY_HAVE_PLANNER
  if (replanner) {
    ReplanReport& rep = r.replan;
    rep.enabled = true;
    rep.switched = flight.trajectory_switches();
    rep.refused = flight.trajectory_refusals();
    for (const ground::planner::ReplanRecord& x : replanner->records()) {
      ReplanEvent e;
      e.trigger = ground::planner::to_string(x.trigger);
      e.t_state_s = x.t_state;
      e.t_due_s = x.t_due;
      e.t_delivered_s = x.t_delivered;
      e.ok = x.ok;
      e.error = x.error;
      e.identified = x.identified;
      e.planned_fuel_kg = x.fuel_kg;
      e.t_final_s = x.t_final;
      e.nodes = x.nodes;
      e.iterations = x.iterations;
      e.wall_s = x.wall_s;
      e.upload_id = x.upload_id;
      rep.plans += x.ok || x.t_delivered >= 0.0 ? 1 : 0;
      rep.failed += x.ok ? 0 : 1;
      rep.delivered += x.ok && x.t_delivered >= 0.0 ? 1 : 0;
      r.plan_wall_s += x.wall_s;
      rep.events.push_back(e);
    }
    char buf[200];
    std::snprintf(buf, sizeof buf,
                  "re-planner: %d plans delivered (%d switched in TRACK, %d refused stale), %d "
                  "failed; latency %.0f s",
                  rep.delivered, rep.switched, rep.refused, rep.failed, options.replan.latency_s);
    r.note = buf;
    if (rep.delivered == 0 && r.status == RunStatus::kOk) {
      for (const ReplanEvent& e : rep.events) {
        if (!e.error.empty()) {
          r.note += "; first failure: " + e.error;
          break;
        }
      }
    }
  }
#endif
  r.ticks = plant.ticks();
  r.clipped_ticks = plant.clipped_periods();
  r.sim_s = plant.t();
  r.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  return r;
}

}  // namespace rocksteady::campaign
