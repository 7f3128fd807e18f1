#include "gnc/gnc.hpp"

#include <cmath>

#include <Eigen/Cholesky>

#include "gnc/fdi/jet_check.hpp"
#include "gnc/math/rotation.hpp"

namespace rocksteady::gnc {

namespace {
bool actuating(Mode m) { return m == Mode::kDetumble || m == Mode::kHold || m == Mode::kTrack; }
}  // namespace

void Gnc::configure_components() {
  const Mat3 j_hat = total_inertia(params_.mass_hat);  // Eq. (1) with the estimates
  filter_.configure(params_.estimator, j_hat, params_.dt);
  if (params_.estimator.kind == EstimatorKind::kMekf) mekf_.configure(build_mekf_config(params_));
  mekf_.set_rate_model(j_hat);
  modes_.configure(params_.mode, params_.guidance.omega_switch);
  refs_.configure(params_.guidance, params_.dt);
  laws_.configure(law_gains(params_), j_hat, params_.dt);
  // B_hat from the estimated r_SO/BCM (SPEC §4); validate() has checked its rank.
  alloc_.configure(torque_matrix(params_.rcs, params_.mass_hat.r_so_bcm), params_.rcs.u_max,
                   params_.allocator);
  // The excitation's null-space basis follows the table's B_hat; computed over the next ticks
  // (IdentificationExcitation::step_model), off until then.
  if (excitation_on()) excite_.set_model(alloc_.b_hat(), params_.rcs);
}

bool Gnc::excitation_on() const {
  return params_.identification.enabled && params_.identification.excitation.enabled;
}

ParamCheck Gnc::init(const GncParams& params) {
  const ParamCheck c = validate(params);
  if (!c.ok) return c;
  params_ = params;
  configure_components();
  filter_.reset();
  mekf_.reset();
  // The identifier starts from this table's model as its prior; a later table switch keeps its
  // estimate (set_params).
  if (params_.identification.enabled) ident_.configure(build_identifier_config(params_));
  excite_.configure(params_.identification.excitation);
  excite_.restart();
  if (excitation_on()) excite_.set_model(alloc_.b_hat(), params_.rcs);
  excite_status_ = ExcitationStatus{};
  fault_torque_scored_ = 0;
  fdi_.configure(params_.fdi, params_.rcs, params_.rcs.u_max, params_.dt);
  fdi_.clear(-1);
  valve_open_ = {{true, true, true, true}};
  last_valve_ = valve_open_;
  isolation_inhibited_ = false;
  reduced_reported_ = false;
  release_fault_model();
  refresh_fault_model();
  modes_.reset(params.mode.initial);
  laws_.reset_state();
  trajectories_.clear();
  fuel_kg_ = 0.0;
  tick_ = 0;
  sensor_rejects_ = 0;
  have_time_ = false;
  last_torque_.setZero();
  last_saturated_ = false;
  last_force_.setZero();
  id_bias_ = params_.mekf.init_bias;
  candidate_status_ = params_.identification.enabled ? ModelCandidate::kNotConfident
                                                     : ModelCandidate::kDisabled;
  candidate_windows_ = 0;
  fault_model_stale_ = false;
  reinflate_pending_ = false;
  last_adoption_t_ = 0.0;
  adopted_once_ = false;
  adoptions_ = 0;
  return c;
}

ParamCheck Gnc::set_params(const GncParams& params) { return apply_params(params, true); }

ParamCheck Gnc::apply_params(const GncParams& params, bool declared_change) {
  const ParamCheck c = validate(params);
  if (!c.ok) return c;
  const Vec3 target = refs_.target();
  const bool target_changed = !(params.guidance.q_final == params_.guidance.q_final);
  const bool estimator_changed = params.estimator.kind != params_.estimator.kind;
  const bool identification_started = params.identification.enabled && !params_.identification.enabled;
  // A table whose model differs from what the identifier believes is a declared change: the
  // identifier keeps its estimate and goes back to its prior covariance. A table holding the
  // identified model (adopted automatically or loaded by the ground) changes nothing.
  bool model_changed = false;
  if (params_.identification.enabled) {
    const IdentifierEstimate& e = ident_.estimate();
    IdentifiedModel m{e.j, e.r, params.rcs.strength};
    for (int i = 0; i < kThrusters; ++i) {
      if (e.thruster_confident[static_cast<std::size_t>(i)]) m.k(i) = e.k(i);
    }
    model_changed = differs(params, m);
  }
  params_ = params;
  configure_components();
  {
    // The detector takes the table now active; what it has confirmed stays latched, and its
    // counts go on (telemetry counts the flight's suspicions, checks, tests).
    const FaultDetectorStatus before = fdi_.status();
    const std::uint16_t on = fdi_.confirmed_on();
    const std::uint16_t off = fdi_.confirmed_off();
    const std::uint16_t degraded = fdi_.confirmed_degraded();
    Vec16 factor;
    for (int i = 0; i < kThrusters; ++i) factor(i) = fdi_.strength_factor(i);
    fdi_.configure(params_.fdi, params_.rcs, params_.rcs.u_max, params_.dt);
    for (int i = 0; i < kThrusters; ++i) {
      if ((on >> i) & 1u) fdi_.declare(i, FaultKind::kStuckOn);
      if ((off >> i) & 1u) fdi_.declare(i, FaultKind::kStuckOff);
      if ((degraded >> i) & 1u) fdi_.declare(i, FaultKind::kDegraded, factor(i));
    }
    fdi_.carry_counts(before);
  }
  if (estimator_changed) {
    filter_.reset();
    mekf_.reset();
  }
  if (!params_.identification.enabled) candidate_status_ = ModelCandidate::kDisabled;
  excite_.configure(params_.identification.excitation);  // keeps the excitation time spent
  if (identification_started) {
    excite_.restart();
    ident_.configure(build_identifier_config(params_));
    fault_torque_scored_ = 0;
    candidate_status_ = ModelCandidate::kNotConfident;
    candidate_windows_ = 0;
    fault_model_stale_ = false;
    reinflate_pending_ = false;
  } else if (model_changed && declared_change) {
    candidate_status_ = ModelCandidate::kNotConfident;  // re-evaluated against this table
    ident_.reinflate_all();
    excite_.restart();  // r is to be learned again
  }
  release_fault_model();
  refresh_fault_model();
  if (!target_changed) refs_.set_target(target);  // keep a ground-commanded target
  return c;
}

void Gnc::refresh_fault_model() {
  FaultModel m;
  if (params_.identification.enabled) {
    const IdentifierEstimate& e = ident_.estimate();
    m.j = e.j;
    m.r = e.r;
    m.k = e.k;
    // The 1 sigma from the identifier's covariances as they are now (a re-inflation shows at
    // once); directions of r the firings have not shown stay at their prior: uncertain.
    m.j_rel_sigma = std::sqrt(ident_.inertia_covariance().diagonal().maxCoeff()) / e.j.norm();
    m.r_cov = ident_.offset_covariance();
    m.k_sigma = std::sqrt(ident_.strength_covariance().diagonal().maxCoeff());
  } else {
    m.j = total_inertia(params_.mass_hat);
    m.r = params_.mass_hat.r_so_bcm;
    m.k = params_.rcs.strength;
    m.j_rel_sigma = params_.fdi_table_rel_sigma;
    const double rs = params_.identification.config.r_prior_sigma;
    m.r_cov = Mat3::Identity() * (rs * rs);
    m.k_sigma = params_.identification.config.k_prior_sigma;
  }
  // (F12) The identifier's innovation gate (I18) re-inflates J, r and k when its windows no
  // longer fit the model: the data changed, which is what the detector isolates. Taking the
  // re-inflated covariance would blind the detector (its noise (F5) grows a hundredfold) while
  // the identifier re-converges with the fault absorbed. The detector keeps the model it had
  // until the identifier is again at least as certain in J, r and k; a confirmation (which
  // re-inflates on purpose) or a new table releases it.
  if (params_.identification.enabled) {
    const std::uint32_t gr = ident_.counters().gate_reinflations;
    if (gr != gate_reinflations_seen_) {
      gate_reinflations_seen_ = gr;
      fault_model_held_ = params_.fdi.enabled;
    }
    if (fault_model_held_) {
      const FaultModel& h = fault_model_given_;
      const bool as_certain = m.j_rel_sigma <= h.j_rel_sigma &&
                              m.r_cov.diagonal().maxCoeff() <= h.r_cov.diagonal().maxCoeff() &&
                              m.k_sigma <= h.k_sigma;
      if (!as_certain) return;
      fault_model_held_ = false;
    }
  }
  fault_model_given_ = m;
  fdi_.set_model(m);
}

void Gnc::release_fault_model() {
  fault_model_held_ = false;
  gate_reinflations_seen_ = params_.identification.enabled ? ident_.counters().gate_reinflations : 0;
}

void Gnc::apply_fault_overrides(const GncCommands& commands, ModeEvents& events) {
  const Mode mode = modes_.mode();
  if (commands.has_fault_declaration) {
    const int i = commands.fault_thruster;
    if (commands.fault_kind == FaultKind::kNone) {
      fdi_.clear(i);
    } else if (i >= 0 && i < kThrusters) {
      fdi_.declare(i, commands.fault_kind, commands.fault_factor);
      if (params_.identification.enabled) ident_.reinflate_thruster(i);
    }
    ModeEvent e{EventId::kFaultOverride, mode, mode, TransitionCheck::kOk};
    e.arg0 = static_cast<std::int16_t>(i);
    e.arg1 = static_cast<std::int16_t>(commands.fault_kind);
    events.push(e);
  }
  if (commands.has_valve && commands.valve_pod >= 0 && commands.valve_pod < kPods) {
    valve_open_[static_cast<std::size_t>(commands.valve_pod)] = commands.valve_open;
    ModeEvent e{EventId::kFaultOverride, mode, mode, TransitionCheck::kOk};
    e.arg0 = commands.valve_pod;
    e.arg1 = static_cast<std::int16_t>(commands.valve_open ? 10 : 11);  // valve open / close
    events.push(e);
  }
  if (commands.has_isolation_inhibit) {
    isolation_inhibited_ = commands.isolation_inhibited;
    ModeEvent e{EventId::kFaultOverride, mode, mode, TransitionCheck::kOk};
    e.arg0 = -1;
    e.arg1 = static_cast<std::int16_t>(commands.isolation_inhibited ? 20 : 21);
    events.push(e);
  }
}

void Gnc::detect_faults(const Vec3& omega, bool omega_valid, ModeEvents& events) {
  if (!params_.fdi.enabled) return;
  FaultDetectorInput in;
  in.omega = omega;
  in.omega_valid = omega_valid;
  for (int c = 0; c < kChannels; ++c) {
    const double f = last_force_(c);
    in.thrust(2 * c) = f > 0.0 ? f : 0.0;
    in.thrust(2 * c + 1) = f < 0.0 ? -f : 0.0;
  }
  in.valve_open = last_valve_;
  in.survey_allowed = !params_.fdi.survey_hold_only || modes_.mode() == Mode::kHold;  // (F43)
  in.balance_allowed = modes_.mode() == Mode::kHold;  // (F61)
  const FaultEvents fe = fdi_.update(in);
  // (F9) The detector's isolation test closes a pod for a few windows; it is an isolation
  // action, so the ground's inhibit and auto_isolate govern it as they govern the confirmation's.
  const int probe_before = probe_pod_;
  probe_pod_ = params_.fdi.auto_isolate && !isolation_inhibited_ ? fdi_.probe_pod() : -1;
  const Mode mode = modes_.mode();
  if (probe_pod_ != probe_before) {  // a test starts or ends (or another pod is tested)
    if (probe_before >= 0) {
      ModeEvent e{EventId::kIsolationTest, mode, mode, TransitionCheck::kOk};
      e.arg0 = static_cast<std::int16_t>(probe_before);
      e.arg1 = 0;
      events.push(e);
    }
    if (probe_pod_ >= 0) {
      ModeEvent e{EventId::kIsolationTest, mode, mode, TransitionCheck::kOk};
      e.arg0 = static_cast<std::int16_t>(probe_pod_);
      e.arg1 = 1;
      events.push(e);
    }
  }
  if (fe.suspected && !fe.confirmed) {
    ModeEvent e{EventId::kFaultSuspected, mode, mode, TransitionCheck::kOk};
    // (F33) Detected before its window closed: no hypothesis is ranked on it yet.
    const int best = fe.early ? -1 : fdi_.status().best;
    e.arg0 = static_cast<std::int16_t>(best < 0 ? -1 : best % kThrusters);
    e.arg1 = static_cast<std::int16_t>(best < 0 ? 0 : best < kThrusters ? 1 : 2);
    events.push(e);
  }
  if (fe.confirmed) {
    ModeEvent e{EventId::kFaultConfirmed, mode, mode, TransitionCheck::kOk};
    e.arg0 = static_cast<std::int16_t>(fe.thruster);
    e.arg1 = static_cast<std::int16_t>(fe.kind);
    events.push(e);
    // Until the confirmation the fault was unmodelled: every group the identifier fitted since
    // onset absorbed it. Its covariance goes back to the prior (estimates kept), which also makes
    // the detector insensitive until the model is re-identified (no cascade of confirmations).
    // That is done at the start of the next tick (step 1b): this one closes the valve and
    // reallocates, and the detector, which has just dropped its windows, scores none before then.
    if (params_.identification.enabled) reinflate_pending_ = true;
    restart_after_confirmation_ = fe.kind != FaultKind::kStuckOn;
    const int pod = params_.rcs.channel_pod[fe.thruster / 2];
    const auto p = static_cast<std::size_t>(pod);
    if (fe.kind == FaultKind::kStuckOn && params_.fdi.auto_isolate && !isolation_inhibited_ &&
        valve_open_[p]) {
      valve_open_[p] = false;  // the pod's latch valve: the stuck jet stops, its pod with it
      ModeEvent v{EventId::kValveClosed, mode, mode, TransitionCheck::kOk};
      v.arg0 = static_cast<std::int16_t>(pod);
      v.arg1 = static_cast<std::int16_t>(fe.thruster);
      events.push(v);
    }
  }
  // (F19) A jet check starts or ends (after the fault events: a tick holds at most four).
  const int check = fdi_.check_jet();
  if (check != check_event_) {
    ModeEvent e{EventId::kJetCheck, mode, mode, TransitionCheck::kOk};
    e.arg0 = static_cast<std::int16_t>(check >= 0 ? check : check_event_);
    e.arg1 = static_cast<std::int16_t>(check >= 0 ? 1 : 0);
    events.push(e);
    check_event_ = check;
  }
}

void Gnc::apply_jet_check(const AllocatorLimits& lim, Vec8& u) {
  // (F19) Thruster i is the "+" (even) or "-" (odd) half of channel c. The check moves u by
  //   du = s f (e_c - B^T (B B^T)^-1 B e_c) / (e_c - B^T (B B^T)^-1 B e_c)_c,   s = +1 / -1,
  // the minimum-norm change with B du = 0 that moves channel c by s f (the projection of e_c on
  // the kernel of B), then scales it by the largest gamma in [0, 1] that keeps every channel
  // in [lo, hi] (as the excitation's X5). A channel in the row space of B (no kernel
  // component) or a jet whose half is unusable (valve closed, latched) is not checked, and a
  // channel that cannot move both ways is held still by the move (F55).
  // B is the detector's model, with the identified centre of mass (F42), latched for the whole
  // check when it starts; or, without F42, the active table's B_hat.
  const int i = fdi_.check_jet();
  const int c = i / 2;
  const double s = (i % 2 == 0) ? 1.0 : -1.0;
  if ((s > 0.0 && !(lim.hi(c) > 0.0)) || (s < 0.0 && !(lim.lo(c) < 0.0))) return;
  if (check_move_jet_ != i) {
    // (F55) A channel that cannot move both ways is held (the detector's model: its latches and
    // the valves; the table's: the bounds).
    std::uint8_t held = 0;
    for (int j = 0; j < kChannels; ++j) {
      if (!(lim.hi(j) > 0.0) || !(lim.lo(j) < 0.0)) held = static_cast<std::uint8_t>(held | (1u << j));
    }
    check_move_ok_ = fdi_.check_on_model() ? fdi_.check_move(c, check_move_)
                                           : jet_check_move(alloc_.b_hat(), c, check_move_, held);
    check_move_jet_ = i;
  }
  if (!check_move_ok_) return;
  Vec8 du = check_move_ * (s * fdi_.check_force() / check_move_(c));
  double gamma = 1.0;
  for (int j = 0; j < kChannels; ++j) {
    if (du(j) > 0.0) gamma = std::fmin(gamma, (lim.hi(j) - u(j)) / du(j));
    if (du(j) < 0.0) gamma = std::fmin(gamma, (lim.lo(j) - u(j)) / du(j));
  }
  gamma = std::fmax(0.0, gamma);
  u += gamma * du;
  check_jet_ = i;
}

std::array<bool, kPods> Gnc::commanded_valves() const {
  std::array<bool, kPods> v = valve_open_;
  if (probe_pod_ >= 0 && probe_pod_ < kPods) v[static_cast<std::size_t>(probe_pod_)] = false;
  return v;
}

AllocatorLimits Gnc::allocation_limits() const {
  // In produced force (B_hat's units): a thruster of strength k reaches k u_max. A thruster is
  // usable when its pod's valve is open and no fault is latched on it; a latched stuck-on thruster
  // behind an open valve is a known bias torque (SPEC §4 column, + or - side).
  AllocatorLimits l;
  l.bias.setZero();
  const double u_max = params_.rcs.u_max;
  const std::uint16_t on = fdi_.confirmed_on();
  const std::uint16_t off = fdi_.confirmed_off();
  const Mat38& b = alloc_.b_hat();
  const std::array<bool, kPods> valves = commanded_valves();
  for (int c = 0; c < kChannels; ++c) {
    const bool open = valves[static_cast<std::size_t>(params_.rcs.channel_pod[c])];
    const int tp = 2 * c;
    const int tm = 2 * c + 1;
    const bool plus_ok = open && !(((on | off) >> tp) & 1u);
    const bool minus_ok = open && !(((on | off) >> tm) & 1u);
    l.hi(c) = plus_ok ? params_.rcs.strength(tp) * u_max : 0.0;
    l.lo(c) = minus_ok ? -params_.rcs.strength(tm) * u_max : 0.0;
    if (open && ((on >> tp) & 1u)) l.bias += b.col(c) * (params_.rcs.strength(tp) * u_max);
    if (open && ((on >> tm) & 1u)) l.bias -= b.col(c) * (params_.rcs.strength(tm) * u_max);
  }
  if (fdi_.confirmed_degraded() != 0) {  // (F18) a jet latched degraded: its factor of it
    for (int c = 0; c < kChannels; ++c) {
      l.hi(c) *= fdi_.strength_factor(2 * c);
      l.lo(c) *= fdi_.strength_factor(2 * c + 1);
    }
  }
  return l;
}

TransitionCheck Gnc::check_mode_request(Mode to) const {
  const TransitionContext ctx{estimate_ready(), trajectories_.valid(), params_.law};
  return check_transition(modes_.mode(), to, ctx);
}

bool Gnc::estimate_ready() const {
  return params_.estimator.kind == EstimatorKind::kMekf ? mekf_.initialised() : filter_.initialised();
}

ModelCandidate Gnc::identified_model(IdentifiedModel& out) const {
  if (!params_.identification.enabled) return ModelCandidate::kDisabled;
  const IdentifierEstimate& e = ident_.estimate();
  if (!e.inertia_confident || !e.offset_confident) return ModelCandidate::kNotConfident;
  out.j = e.j;
  out.r = e.r;
  // Only the strengths the data have pinned replace the table's; the others keep theirs.
  out.k = params_.rcs.strength;
  for (int i = 0; i < kThrusters; ++i) {
    if (e.thruster_confident[static_cast<std::size_t>(i)]) out.k(i) = e.k(i);
  }
  return differs(params_, out) ? ModelCandidate::kOk : ModelCandidate::kUnchanged;
}

bool Gnc::differs(const GncParams& p, const IdentifiedModel& m) const {
  const IdentifierConfig& c = params_.identification.config;
  const Mat3 j = total_inertia(p.mass_hat);
  if ((m.j - j).norm() > c.j_confident_rel * j.norm() ||
      (m.r - p.mass_hat.r_so_bcm).norm() > c.r_confident ||
      (m.k - p.rcs.strength).cwiseAbs().maxCoeff() > c.k_confident) {
    return true;
  }
  // Resolved by the data: the table lies outside the estimate's adopt_sigmas box (per parameter,
  // the identifier's 1 sigma; an unobservable offset direction keeps a large sigma and never
  // counts).
  const double n = params_.identification.adopt_sigmas;
  if (!(n > 0.0)) return false;
  const IdentifierEstimate& e = ident_.estimate();
  const Vec6 dj = inertia_params(m.j) - inertia_params(j);
  for (int i = 0; i < 6; ++i) {
    if (e.j_sigma(i) > 0.0 && std::abs(dj(i)) > n * e.j_sigma(i)) return true;
  }
  const Vec3 dr = m.r - p.mass_hat.r_so_bcm;
  for (int i = 0; i < 3; ++i) {
    if (e.r_sigma(i) > 0.0 && std::abs(dr(i)) > n * e.r_sigma(i)) return true;
  }
  return false;
}

ModelCandidate Gnc::model_candidate(GncParams& out) const {
  IdentifiedModel m;
  const ModelCandidate c = identified_model(m);
  if (c != ModelCandidate::kOk) return c;
  out = with_model(params_, m.j, m.r, m.k);
  return validate(out).ok ? ModelCandidate::kOk : ModelCandidate::kInvalid;
}

void Gnc::adopt_model(double t, ModeEvents& events) {
  const IdentificationParams& ip = params_.identification;
  if (!ip.enabled || ip.adopt != ModelAdoption::kAuto) return;
  if (adopted_once_ && t - last_adoption_t_ < ip.adopt_interval_s) return;
  const ModelCandidate c = candidate_status_;  // evaluated when the last window closed
  if (c != ModelCandidate::kOk && c != ModelCandidate::kInvalid) return;
  adopted_once_ = true;
  last_adoption_t_ = t;  // a refused model is not retried before the interval either
  if (c == ModelCandidate::kInvalid) {
    events.push(ModeEvent{EventId::kModelRefused, modes_.mode(), modes_.mode(),
                          TransitionCheck::kOk});
    return;
  }
  const LawId law = params_.law;  // the law stays the commanded one
  candidate_.law = law;
  candidate_status_ = ModelCandidate::kUnchanged;
  if (apply_params(candidate_, false).ok) {
    ++adoptions_;
    events.push(ModeEvent{EventId::kModelAdopted, modes_.mode(), modes_.mode(),
                          TransitionCheck::kOk});
  }
}

TrajectoryError Gnc::load_trajectory(const TrajectoryTable& table) {
  return trajectories_.load(table, params_.guidance.eps_trans, modes_.mode() == Mode::kTrack);
}

void Gnc::step(const SensorSample& sample, const GncCommands& commands, GncOutput& out) {
  out.events.clear();
  const double t = sample.t;
  if (!have_time_) {
    last_good_t_ = t;  // first call: the sensor age starts counting now
    have_time_ = true;
  }

  // 0. Tick boundary: an identified model adopted by the automatic policy takes effect now, and
  // the ground's fault overrides.
  adopt_model(t, out.events);
  apply_fault_overrides(commands, out.events);

  // 1. Estimator: accept only finite, in-range samples.
  const EstimatorParams& ep = params_.estimator;
  Measurement m;
  m.omega_valid = sample.gyro_valid && sample.gyro_rate.allFinite() &&
                  sample.gyro_rate.norm() <= ep.gyro_max_rate;
  const double qn = sample.star_quat.norm();
  m.q_valid = sample.star_valid && sample.star_quat.allFinite() &&
              std::fabs(qn - 1.0) <= ep.quat_norm_tolerance;
  if ((sample.gyro_valid && !m.omega_valid) || (sample.star_valid && !m.q_valid)) {
    ++sensor_rejects_;
    out.events.push(ModeEvent{EventId::kSensorRejected, modes_.mode(), modes_.mode(),
                              TransitionCheck::kOk});
  }
  if (m.omega_valid) m.omega = sample.gyro_rate;
  if (m.q_valid) m.q = mrp::from_quaternion(sample.star_quat / qn);
  if (m.omega_valid && m.q_valid) last_good_t_ = t;
  Vec3 omega_hat;
  Vec3 q_hat;
  if (ep.kind == EstimatorKind::kMekf) {
    MekfInput mi;
    mi.t = t;
    mi.gyro_rate = m.omega;
    mi.gyro_valid = m.omega_valid;
    if (m.q_valid) mi.star_quat = sample.star_quat / qn;
    mi.star_valid = m.q_valid;
    mi.torque = last_torque_;
    mekf_.update(mi);
    omega_hat = mekf_.omega();
    q_hat = mekf_.q();
  } else {
    filter_.update(m, last_torque_);
    omega_hat = filter_.omega();
    q_hat = filter_.q();
  }

  // 1b. Identification (gnc/estimation/README.md §I): this tick's rate and the forces commanded
  // over the previous tick. The rate is the gyro: the SPEC §6 filter's rate is model-predicted
  // with J_hat, which is what is being identified. With the MEKF the gyro is corrected by its bias
  // estimate latched at the start of each window: a bias estimate that moves inside a window
  // would read as a change of angular momentum, whereas a constant offset cancels in the window
  // equation's derivative term (the triangular window's w' integrates to zero).
  if (params_.identification.enabled) {
    IdentifierInput in;
    const bool mekf = ep.kind == EstimatorKind::kMekf;
    in.omega = mekf ? Vec3(m.omega - id_bias_) : m.omega;
    in.omega_valid = m.omega_valid && (!mekf || mekf_.initialised());
    in.force = last_force_;
    // (F18) A thruster latched degraded delivers its factor of what was commanded: the identifier
    // fits its strength relative to that (k_hat near 1 again once the factor is right).
    if (fdi_.confirmed_degraded() != 0) {
      for (int c = 0; c < kChannels; ++c) {
        in.force(c) *= fdi_.strength_factor(in.force(c) >= 0.0 ? 2 * c : 2 * c + 1);
      }
    }
    // While the detector suspects a fault it has not isolated, the identifier does not fit it
    // into J, r and k: those windows are discarded (gnc/fdi/README.md (F7)).
    // With the stuck-on isolation inside identification (F14), a suspected stuck-on is what the
    // identifier's fault torque d (I22) absorbs, so its windows are kept: they are the evidence.
    const bool stuck_on_suspected = fdi_.status().best >= 0 && fdi_.status().best < kThrusters;
    in.force_valid = !(params_.fdi.enabled && fdi_.suspecting() &&
                       !(params_.fdi.identified_isolation && stuck_on_suspected)) &&
                     !(params_.fdi.enabled && fdi_.sweeping());  // (F17) valves moving
    // The identifier's step blocks stay off the fault detector's heavy evaluation steps
    // (gnc/fdi/README.md (F10)).
    const bool fdi_busy = params_.fdi.enabled && fdi_.heavy_step_next();
    const bool reinflating = reinflate_pending_;
    // (I27) The window open at the confirmation holds the fault unmodelled (a stuck-on jet's
    // torque until its valve closed, a stuck-off jet's missing thrust until it was latched):
    // with the model kept, that window is dropped (the next sample opens a clean one).
    if (reinflating && params_.identification.keep_model_after_fault) in.force_valid = false;
    // The tick after a re-inflation the identifier's block is the rewrite of its covariance
    // (Identifier::reinflate_all); the detector's model refresh waits for the tick after that.
    const bool rewriting = ident_.covariance_rewrite_pending() && !fdi_busy && !reinflating;
    // ... and the linearisation of a step (the detector's model refresh waits for another tick).
    const bool linearising = ident_.heavy_block_next() && !fdi_busy && !reinflating;
    if (reinflating) {  // a fault confirmed on the last tick (step 1c)
      reinflate_pending_ = false;
      // (I27) The identifier's model as it stood, for a restart from it below (when asked).
      const bool keep = params_.identification.keep_model_after_fault;
      const IdentifierEstimate kept = keep ? ident_.estimate() : IdentifierEstimate{};
      const double kept_j_rel =
          keep ? std::sqrt(ident_.inertia_covariance().diagonal().maxCoeff()) / kept.j.norm()
               : 0.0;
      const Mat3 kept_r_cov = keep ? ident_.offset_covariance() : Mat3::Zero();
      ident_.reinflate_all();
      // (F12) The detector held the model from before the identifier's gate refused the fault's
      // windows; the identifier fitted the unmodelled fault since. The fault is modelled now
      // (latched): after a stuck-off or a partial loss the identifier starts again from the held
      // model and its uncertainty, when that model was identified (its inertia within the
      // confidence bound). Not after a stuck-on: the identifier's fault torque (F14) has carried
      // it, and restarting from the held model (with its uncertainty the detector takes it as
      // known) confirmed a second, wrong fault in 14 of 112 runs with a jet stuck on at 60 s.
      if (fault_model_held_ && restart_after_confirmation_ &&
          fault_model_given_.j_rel_sigma <= params_.identification.config.j_confident_rel) {
        const FaultModel& h = fault_model_given_;
        ident_.restart_at(h.j, h.j_rel_sigma * h.j.norm(), h.r, h.r_cov, h.k, h.k_sigma);
      } else if (keep && kept_j_rel <= params_.identification.config.j_confident_rel) {
        // (I27) The body did not change and the fault is latched from now on; what J and r
        // absorbed of it before the confirmation is taken to be within the floors below.
        // Re-learnt from the prior, they were re-fitted on the windows of a late despin and of
        // HOLD (weak, and in HOLD correlated with the disturbance): J 17-26 % off at 30 000 s at
        // the median of the runs with a confirmation (gnc/estimation/README.md I.9).
        const IdentifierConfig& ic = params_.identification.config;
        const double j_sigma = std::fmax(kept_j_rel, ic.j_confident_rel) * kept.j.norm();
        const Mat3 r_cov = kept_r_cov + ic.r_confident * ic.r_confident * Mat3::Identity();
        ident_.restart_at(kept.j, j_sigma, kept.r, r_cov, kept.k, kept.k_sigma.maxCoeff());
      }
      release_fault_model();
      fault_model_stale_ = true;  // the detector takes the re-inflated model on a later tick
    }
    ident_.update(in, !fdi_busy && !reinflating);
    // (F14) The identifier's stuck-on evidence (I23), once per scored window.
    const IdentifierFaultTorque& ft = ident_.fault_torque();
    if (ft.scored != fault_torque_scored_) {
      fault_torque_scored_ = ft.scored;
      StuckOnEvidence ev;
      ev.fitted = ft.fitted;
      ev.chi2_zero = ft.chi2_zero;
      ev.chi2_jet = ft.chi2_jet;
      ev.chi2_column = ft.chi2_column;
      fdi_.identified_evidence(ev);
    }
    bool window_latched = false;
    if (ident_.counters().windows != candidate_windows_) {  // once per window, not per tick
      window_latched = true;
      candidate_windows_ = ident_.counters().windows;
      candidate_status_ = model_candidate(candidate_);
      if (mekf) {
        // The identifier's bias (I17) is the bias left in the rate it is given: estimated, it
        // follows the new subtraction; as a consider parameter, its 1 sigma is the MEKF's.
        // Either applies once the closed window's step is done.
        if (params_.identification.config.gyro_bias_estimated) {
          ident_.shift_rate_bias(mekf_.bias() - id_bias_);
        } else {
          ident_.consider_rate_bias(
              mekf_.bias_sigma().cwiseMax(params_.identification.mekf_bias_sigma_floor));
        }
        id_bias_ = mekf_.bias();
      }
      fault_model_stale_ = true;
    }
    // The detector predicts with the latest identified model; one that arrives while a closed
    // window is evaluated is held by the detector until the evaluation ends (F10). The refresh
    // (a 3x3 inverse and eigenvalues, 16 columns) waits for a tick that neither latches the
    // identifier's window, nor carries a heavy step of the detector, nor the identifier's
    // linearisation or covariance rewrite.
    // The excitation's basis stages (after a model change) take the same quiet ticks.
    excite_quiet_ = !fdi_busy && !window_latched && !reinflating;
    if (fault_model_stale_ && !fdi_busy && !window_latched && !reinflating && !rewriting &&
        !linearising) {
      refresh_fault_model();
      fault_model_stale_ = false;
    }
  }

  // 1c. Fault detection and isolation (gnc/fdi/README.md): the same rate, the same thrust.
  detect_faults(ep.kind == EstimatorKind::kMekf ? Vec3(m.omega - id_bias_) : m.omega,
                m.omega_valid && (ep.kind != EstimatorKind::kMekf || mekf_.initialised()),
                out.events);

  // 2. Mode manager: ground requests at the tick boundary, then autonomous transitions.
  const Mode before = modes_.mode();
  if (commands.has_law) {
    if (!(before == Mode::kTrack && commands.law == LawId::kDpd) &&
        static_cast<int>(commands.law) < kLawCount && commands.law != params_.law) {
      params_.law = commands.law;
      laws_.reset_state();
    }
  }
  if (commands.has_target && commands.target_mrp.allFinite()) {
    refs_.set_target(commands.target_mrp);
  }
  const TransitionContext ctx{estimate_ready(), trajectories_.valid(), params_.law};
  const bool finite = omega_hat.allFinite() && q_hat.allFinite();
  modes_.update(ModeInputs{commands.has_mode_request, commands.mode_request, ctx, omega_hat.norm(),
                           t - last_good_t_, finite},
                out.events);
  const Mode mode = modes_.mode();
  if (actuating(mode) && !actuating(before)) laws_.reset_state();

  // 3. Reference. A staged trajectory becomes active here, at the tick boundary, and TRACK
  // re-synchronises to the estimate on it.
  const SwitchOutcome sw = trajectories_.switch_at_boundary(omega_hat, stale_tolerance(omega_hat));
  if (sw != SwitchOutcome::kNone) {
    const bool switched = sw == SwitchOutcome::kSwitched;
    out.events.push(ModeEvent{switched ? EventId::kTrajectorySwitched : EventId::kTrajectoryStale,
                              mode, mode, TransitionCheck::kOk});
    if (switched && mode == Mode::kTrack && !modes_.entered()) {
      refs_.reset_track(t, q_hat, omega_hat, trajectories_.active());
    }
  }
  const ReferenceSample ref =
      refs_.update(mode, modes_.entered(), t, q_hat, omega_hat, trajectories_.active());

  // 4. Control law.
  RateReference rr;
  Vec3 u_c = Vec3::Zero();
  if (actuating(mode)) {
    const LawInput in{omega_hat, q_hat, ref, last_saturated_};
    if (ref.phase == ReferencePhase::kTrack && params_.guidance.track_momentum_k > 0.0) {
      u_c = momentum_torque(laws_.j_hat(), laws_.j_hat_inverse(), params_.guidance.track_momentum_k,
                            q_hat, omega_hat, ref, rr);
    } else {
      u_c = laws_.compute(params_.law, in, rr);
    }
    if (!u_c.allFinite()) {
      u_c.setZero();
      rr = RateReference{};
      modes_.update(ModeInputs{false, mode, ctx, omega_hat.norm(), 0.0, false},
                    out.events);  // -> SAFE
    }
  }

  // 5. Allocator, Eq. (53) or Eq. (52) (params_.allocator); fuel estimate, Eq. (54).
  // The allocator works in produced force (B_hat's columns are per newton produced); a thruster
  // of strength k_i is commanded u / k_i, within u_max.
  Vec8 u = Vec8::Zero();
  AllocatorStatus status;
  const bool enabled = actuating(modes_.mode());
  AllocatorLimits limits;
  if (enabled) {
    limits = allocation_limits();
    // (F61) During a channel balance test the body drifts free (5d): nothing to allocate.
    const bool drifting = params_.fdi.enabled && fdi_.balance_channel() >= 0;
    if (!drifting) alloc_.allocate(u_c, limits, u, status);
    if (status.reduced_authority && !reduced_reported_) {
      out.events.push(ModeEvent{EventId::kReducedAuthority, modes_.mode(), modes_.mode(),
                                TransitionCheck::kOk, static_cast<std::int16_t>(status.rank),
                                static_cast<std::int16_t>(status.active_channels)});
    }
    reduced_reported_ = status.reduced_authority;
  } else {
    status.torque_requested.setZero();
    status.torque_achieved.setZero();
  }
  // 5b. Identification excitation (gnc/estimation/README.md §I.6, X1-X8): first, in DETUMBLE, the
  // inertia phase (X8: the net force nulled, a couple added to the law's torque), then a net
  // force in the null space of B_hat (the torque on the model unchanged) while r is not yet
  // known; within the channels' box. Healthy RCS only (no latched fault, no closed valve, no
  // suspicion).
  excite_status_ = ExcitationStatus{};
  if (excitation_on()) {
    if (excite_quiet_) excite_.step_model();
    if (enabled && !(params_.fdi.enabled && fdi_.suspecting())) {
      const AllocatorLimits& lim = limits;
      const bool healthy = (lim.lo.array() < 0.0).all() && (lim.hi.array() > 0.0).all() &&
                           (lim.bias.array() == 0.0).all();
      const IdentifierEstimate& e = ident_.estimate();
      const double identified_s = ident_.identified_s();
      if (healthy && modes_.mode() == Mode::kDetumble && excite_.inertia_wanted(identified_s)) {
        // (X8) Before start_after_s: the allocation made force-free (r_hat still unknown) and a
        // couple added, one axis per window. In DETUMBLE only: there the despin's own torque
        // dwarfs the couple; in HOLD or TRACK it would be a pointing disturbance.
        excite_status_ = excite_.apply_inertia(excite_.inertia_torque(ident_.counters().windows),
                                               lim.lo, lim.hi, params_.dt, u);
      } else if (healthy && excite_.wanted(e.r_sigma.maxCoeff(), ident_.observability().offset_unobservable,
                                    identified_s)) {
        // (X7) The amplitude for this window's noise (fixed within a window: the noise is the
        // last closed window's).
        excite_.size_to_window_noise(ident_.latched_window_noise(), ident_.latched_window_s());
        excite_status_ = excite_.apply(excite_.force(ident_.counters().windows), lim.lo, lim.hi,
                                       params_.dt, u);
      }
    }
  }
  // 5c. Jet check (gnc/fdi/README.md F19): the detector asks for a jet its evidence suspects of
  // producing less than commanded to be fired firmly, in the null space of the detector's model
  // (F42) or of B_hat.
  check_jet_ = -1;
  if (fdi_.check_jet() < 0) check_move_jet_ = -1;  // the next check latches its own move
  if (enabled && params_.fdi.enabled && fdi_.check_jet() >= 0) apply_jet_check(limits, u);
  // 5d. Channel balance test (gnc/fdi/README.md F61): in HOLD, the body drifts free while the
  // detector fires one half of a channel after the other (within the channel's bounds), so that
  // nothing but the test moves it.
  if (enabled && params_.fdi.enabled && fdi_.balance_channel() >= 0) {
    const int c = fdi_.balance_channel();
    u.setZero();
    u(c) = std::fmin(limits.hi(c), std::fmax(limits.lo(c), fdi_.balance_command()));
  }
  if (fdi_.confirmed_degraded() != 0) {
    // (F18) A thruster latched degraded produces its factor of its strength: commanded that much
    // more (the limits above kept it within u_max).
    for (int c = 0; c < kChannels; ++c) {
      u(c) /= fdi_.strength_factor(u(c) >= 0.0 ? 2 * c : 2 * c + 1);
    }
  }
  Vec8 force = Vec8::Zero();
  for (int c = 0; c < kChannels; ++c) {
    const double k = u(c) >= 0.0 ? params_.rcs.strength(2 * c) : params_.rcs.strength(2 * c + 1);
    force(c) = std::fmax(-params_.rcs.u_max, std::fmin(params_.rcs.u_max, u(c) / k));
  }
  fuel_kg_ += fuel_rate(force, params_.isp_s, params_.g0) * params_.dt;
  last_torque_ = status.torque_achieved;
  last_saturated_ = status.saturated;
  last_force_ = force;

  out.command.force = force;
  out.command.enabled = enabled;
  out.command.valve_open = commanded_valves();
  last_valve_ = out.command.valve_open;
  GncTelemetry& tl = out.telemetry;
  tl.t = t;
  tl.tick = tick_++;
  tl.mode = modes_.mode();
  tl.law = params_.law;
  tl.phase = enabled ? ref.phase : ReferencePhase::kNone;
  tl.omega_hat = omega_hat;
  tl.q_hat = q_hat;
  tl.q_d = ref.q.q;
  tl.omega_r = rr.omega_r;
  tl.attitude_error = q_hat - mrp::nearest_set(refs_.target(), q_hat);
  tl.alloc = status;
  tl.fuel_kg = fuel_kg_;
  tl.sensor_rejects = sensor_rejects_;
  tl.trajectory_loaded = trajectories_.valid();
  tl.a_hat = laws_.a_hat();
  tl.integral = laws_.integral();
  fill_estimation_telemetry(tl);
  FdiTelemetry& f = tl.fdi;
  const FaultDetectorStatus& fs = fdi_.status();
  f.enabled = params_.fdi.enabled;
  f.residual = fs.residual;
  f.chi2 = fs.chi2;
  f.noise_sigma = fs.noise_sigma;
  f.best = static_cast<std::int8_t>(fs.best);
  f.best_llr = fs.best_llr;
  f.runner_up_llr = fs.runner_up_llr;
  f.suspected_on = fs.suspected_on;
  f.suspected_off = fs.suspected_off;
  f.confirmed_on = fs.confirmed_on;
  f.confirmed_off = fs.confirmed_off;
  // The factors are all 1 unless a thruster is latched degraded: copied only then, or when the
  // last latch was cleared (the Cortex-M7 budget: 16 copies a tick otherwise).
  if (fs.confirmed_degraded != 0 || f.confirmed_degraded != 0) {
    for (int i = 0; i < kThrusters; ++i) f.strength_factor(i) = fdi_.strength_factor(i);
  }
  f.confirmed_degraded = fs.confirmed_degraded;
  f.valve_open = commanded_valves();
  f.isolation_inhibited = isolation_inhibited_;
  f.windows = fs.windows;
  f.suspicions = fs.suspicions;
  f.probe_pod = static_cast<std::int8_t>(probe_pod_);
  f.probes = fs.probes;
  f.check_jet = static_cast<std::int8_t>(check_jet_);
  f.checks = fs.checks;
  f.checks_unfit = fs.checks_unfit;
  f.surveys = fs.surveys;
  f.balance_channel = static_cast<std::int8_t>(fs.balance_channel);
  f.balance_tests = fs.balance_tests;
  f.balance_confirmations = fs.balance_confirmations;
  f.unverified = fs.unverified;
}

void Gnc::fill_estimation_telemetry(GncTelemetry& tl) const {
  EstimationTelemetry& e = tl.est;
  const bool mekf = params_.estimator.kind == EstimatorKind::kMekf;
  // With the MEKF and the identifier both running every field is written below; otherwise the
  // telemetry is cleared first (the clear alone is 270 Cortex-M7 instructions a tick).
  if (!mekf || !params_.identification.enabled) e = EstimationTelemetry{};
  e.mekf = mekf;
  if (mekf) {
    e.gyro_bias = mekf_.bias();
    e.attitude_sigma = mekf_.attitude_sigma();
    e.bias_sigma = mekf_.bias_sigma();
    e.star_gated = mekf_.counters().gated;
  }
  e.adoptions = adoptions_;
  if (!params_.identification.enabled) return;
  const IdentifierEstimate& est = ident_.estimate();
  const IdentifierExcitation& exc = ident_.excitation();
  e.identifying = true;
  e.j = inertia_params(est.j);
  e.j_sigma = est.j_sigma;
  e.r = est.r;
  e.r_sigma = est.r_sigma;
  e.k = est.k;
  e.k_sigma = est.k_sigma;
  e.j_cov = est.j_cov;
  e.r_cov = est.r_cov;
  e.thrust_scale_sigma = est.thrust_scale_sigma;
  e.inertia_confident = est.inertia_confident;
  e.offset_confident = est.offset_confident;
  std::uint16_t confident = 0;
  std::uint16_t excited = 0;
  for (int i = 0; i < kThrusters; ++i) {
    const auto b = static_cast<std::uint16_t>(1u << i);
    if (est.thruster_confident[static_cast<std::size_t>(i)]) confident |= b;
    if (exc.thruster[static_cast<std::size_t>(i)]) excited |= b;
  }
  e.thruster_confident = confident;
  e.excited_thrusters = excited;
  e.excited_inertia = exc.inertia_scale;
  e.excited_offset = exc.offset;
  e.offset_unobservable = static_cast<std::uint8_t>(ident_.observability().offset_unobservable);
  e.residual_torque = est.residual_torque;
  e.residual_chi2 = est.residual_chi2;
  const IdentifierCounters& ic = ident_.counters();
  e.windows = ic.windows;
  e.rate_bias_sigma = est.gyro_bias_sigma;
  e.windows_gated = ic.windows_gated;
  e.gate_reinflations = ic.gate_reinflations;
  e.guard_refusals = ic.inertia_refused + ic.offset_refused;
  e.excitation_active = excite_status_.active;
  e.excitation_force = excite_status_.force;
  e.excitation_gamma = excite_status_.gamma;
  e.excitation_inertia = excite_status_.inertia;
  e.excitation_torque = excite_status_.torque;
  e.candidate = candidate_status_;
}

}  // namespace rocksteady::gnc
