#include "gnc/gnc.hpp"

#include <cmath>

#include "gnc/math/rotation.hpp"

namespace rocksteady::gnc {

namespace {
bool actuating(Mode m) { return m == Mode::kDetumble || m == Mode::kHold || m == Mode::kTrack; }
}  // namespace

void Gnc::configure_components() {
  const Mat3 j_hat = total_inertia(params_.mass_hat);  // Eq. (1) with the estimates
  filter_.configure(params_.estimator, j_hat, params_.dt);
  modes_.configure(params_.mode, params_.guidance.omega_switch);
  refs_.configure(params_.guidance, params_.dt);
  laws_.configure(law_gains(params_), j_hat, params_.dt);
  // B_hat from the estimated r_SO/BCM (SPEC §4); validate() has checked its rank.
  alloc_.configure(torque_matrix(params_.rcs, params_.mass_hat.r_so_bcm), params_.rcs.u_max,
                   params_.allocator);
}

ParamCheck Gnc::init(const GncParams& params) {
  const ParamCheck c = validate(params);
  if (!c.ok) return c;
  params_ = params;
  configure_components();
  filter_.reset();
  modes_.reset(params.mode.initial);
  laws_.reset_state();
  trajectories_.clear();
  fuel_kg_ = 0.0;
  tick_ = 0;
  sensor_rejects_ = 0;
  have_time_ = false;
  last_torque_.setZero();
  last_saturated_ = false;
  return c;
}

ParamCheck Gnc::set_params(const GncParams& params) {
  const ParamCheck c = validate(params);
  if (!c.ok) return c;
  const Vec3 target = refs_.target();
  const bool target_changed = !(params.guidance.q_final == params_.guidance.q_final);
  params_ = params;
  configure_components();
  if (!target_changed) refs_.set_target(target);  // keep a ground-commanded target
  return c;
}

TransitionCheck Gnc::check_mode_request(Mode to) const {
  const TransitionContext ctx{filter_.initialised(), trajectories_.valid(), params_.law};
  return check_transition(modes_.mode(), to, ctx);
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
  filter_.update(m, last_torque_);
  const Vec3 omega_hat = filter_.omega();
  const Vec3 q_hat = filter_.q();

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
  const TransitionContext ctx{filter_.initialised(), trajectories_.valid(), params_.law};
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
    u_c = laws_.compute(params_.law, in, rr);
    if (!u_c.allFinite()) {
      u_c.setZero();
      rr = RateReference{};
      modes_.update(ModeInputs{false, mode, ctx, omega_hat.norm(), 0.0, false},
                    out.events);  // -> SAFE
    }
  }

  // 5. Allocator, Eq. (53) or Eq. (52) (params_.allocator); fuel estimate, Eq. (54).
  Vec8 u = Vec8::Zero();
  AllocatorStatus status;
  const bool enabled = actuating(modes_.mode());
  if (enabled) {
    alloc_.allocate(u_c, u, status);
  } else {
    status.torque_requested.setZero();
    status.torque_achieved.setZero();
  }
  fuel_kg_ += fuel_rate(u, params_.isp_s, params_.g0) * params_.dt;
  last_torque_ = status.torque_achieved;
  last_saturated_ = status.saturated;

  out.command.force = u;
  out.command.enabled = enabled;
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
}

}  // namespace rocksteady::gnc
