#include "ground/planner/replanner.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <limits>

#include "gnc/estimation/identifier.hpp"
#include "gnc/math/rotation.hpp"

namespace rocksteady::ground::planner {

const char* to_string(ReplanTrigger t) {
  switch (t) {
    case ReplanTrigger::kFirst: return "first";
    case ReplanTrigger::kPeriodic: return "periodic";
    case ReplanTrigger::kTrackingError: return "tracking_error";
    case ReplanTrigger::kModelUpdate: return "model_update";
    case ReplanTrigger::kEarly: return "early";
  }
  return "?";
}

std::optional<gnc::GncParams> identified_params(const gnc::GncParams& flight,
                                                const gnc::EstimationTelemetry& est) {
  if (!est.identifying || !est.inertia_confident || !est.offset_confident) return std::nullopt;
  gnc::Vec16 k = flight.rcs.strength;
  for (int i = 0; i < 16; ++i) {
    if ((est.thruster_confident >> i) & 1u) k(i) = est.k(i);
  }
  gnc::GncParams p = gnc::with_model(flight, gnc::inertia_matrix(est.j), est.r, k);
  if (!gnc::validate(p).ok) return std::nullopt;
  return p;
}

bool apriori_confirmed(const gnc::GncParams& flight, const gnc::EstimationTelemetry& est,
                       double sigmas, double j_rel, double r_m) {
  if (!est.identifying || est.windows == 0) return false;
  if (!est.j.allFinite() || !est.j_sigma.allFinite() || !est.r.allFinite() ||
      !est.r_sigma.allFinite()) {
    return false;
  }
  const gnc::Vec6 j0 = gnc::inertia_params(gnc::total_inertia(flight.mass_hat));
  const double j_bound = j_rel * j0.norm();
  for (int i = 0; i < 6; ++i) {
    if (!(est.j_sigma(i) > 0.0) || est.j_sigma(i) > j_bound) return false;
    if (std::abs(est.j(i) - j0(i)) > sigmas * est.j_sigma(i)) return false;
  }
  const gnc::Vec3& r0 = flight.mass_hat.r_so_bcm;
  for (int i = 0; i < 3; ++i) {
    if (!(est.r_sigma(i) > 0.0) || est.r_sigma(i) > r_m) return false;
    if (std::abs(est.r(i) - r0(i)) > sigmas * est.r_sigma(i)) return false;
  }
  return true;
}

namespace {

// The shortest possible despin from omega (planner.hpp, resolve_final_time_bounds).
double shortest_despin(const PlanModel& m) {
  PlanSettings s;
  s.t_final_max = 0.0;
  double t_min = 0.0;
  double t_max = 0.0;
  resolve_final_time_bounds(m, s, t_min, t_max);
  return t_max / kHorizonFactor;
}

// The sample whose omega_d is nearest omega (the flight's re-synchronisation, References::reset_track).
double nearest_sample_time(const gnc::TrajectoryTable& t, const gnc::Vec3& omega) {
  int best = 0;
  double best_d2 = (t.samples[0].omega_d - omega).squaredNorm();
  for (int i = 1; i < t.count; ++i) {
    const double d2 = (t.samples[i].omega_d - omega).squaredNorm();
    if (d2 < best_d2) {
      best_d2 = d2;
      best = i;
    }
  }
  return t.samples[best].t;
}

}  // namespace

Replanner::Replanner(const gnc::GncParams& flight, const ReplanPolicy& policy,
                     std::int32_t first_upload_id)
    : flight_(flight),
      model_(flight),
      flown_(flight),
      policy_(policy),
      next_upload_id_(first_upload_id) {}

double Replanner::settle_s() const {
  if (!(policy_.adopt_settle_tau > 0.0)) return 0.0;
  double omega_c = 0.0;  // the rate stage's cutoff, rad/s (0: the rate is the gyro's)
  if (flight_.estimator.kind == gnc::EstimatorKind::kFilter) omega_c = flight_.estimator.omega_c;
  if (flight_.estimator.kind == gnc::EstimatorKind::kMekf) omega_c = flight_.mekf.rate_cutoff;
  return omega_c > 0.0 ? policy_.adopt_settle_tau / omega_c : 0.0;
}

bool Replanner::awaiting_adoption(const gnc::GncTelemetry& tl) const {
  if (!identified_ || !(policy_.adopt_wait_s > 0.0)) return false;
  if (tl.t - t_identified_ >= policy_.adopt_wait_s) return false;
  const double inf = std::numeric_limits<double>::infinity();
  return !apriori_confirmed(flown_, tl.est, policy_.early_sigmas, inf, inf);
}

double Replanner::horizon_factor() const {
  if (policy_.horizon_factor > 0.0) return policy_.horizon_factor;
  return flight_.guidance.track_momentum_k > 0.0 ? kMomentumHorizonFactor : kHorizonFactor;
}

gnc::Vec3 Replanner::aimed_rate(const gnc::GncTelemetry& tl, const gnc::Vec3& omega_d) const {
  if (!(flight_.guidance.track_momentum_k > 0.0) || tl.phase != gnc::ReferencePhase::kTrack) {
    return omega_d;
  }
  const gnc::Mat3 j = gnc::total_inertia(flown_.mass_hat);
  const gnc::Mat3 dr = gnc::mrp::to_dcm(tl.q_hat).transpose() * gnc::mrp::to_dcm(tl.q_d);
  return j.inverse() * (dr * (j * omega_d));
}

gnc::Vec3 Replanner::predict(const gnc::GncTelemetry& tl, double ahead) const {
  if (flying_table_ != nullptr && tl.mode == gnc::Mode::kTrack && !resync_) {
    // Tracking: the flight follows the plan; carry today's tracking error along (with momentum
    // tracking, the plan's rates turned as the body has turned off the plan's attitude).
    const double tau = tl.t - t0_;
    return aimed_rate(tl, gnc::interpolate(*flying_table_, tau + ahead).omega_d) + tl.omega_hat -
           aimed_rate(tl, gnc::interpolate(*flying_table_, tau).omega_d);
  }
  // Not tracking yet (the D+PD reference): Euler's equations (SPEC Eq. 2) for the model with the
  // torque the flight applies now held in the body frame, RK4.
  const gnc::Mat3 j = gnc::total_inertia(model_.mass_hat);
  const gnc::Mat3 j_inv = j.inverse();
  const gnc::Vec3 torque = tl.alloc.torque_achieved.allFinite() ? tl.alloc.torque_achieved
                                                                 : gnc::Vec3::Zero();
  auto f = [&](const gnc::Vec3& w) -> gnc::Vec3 { return j_inv * ((j * w).cross(w) + torque); };
  gnc::Vec3 w = tl.omega_hat;
  const int steps = std::max(1, static_cast<int>(std::ceil(ahead / 0.1)));
  const double h = ahead / steps;
  for (int i = 0; i < steps; ++i) {
    const gnc::Vec3 k1 = f(w);
    const gnc::Vec3 k2 = f(w + 0.5 * h * k1);
    const gnc::Vec3 k3 = f(w + 0.5 * h * k2);
    const gnc::Vec3 k4 = f(w + h * k3);
    w += (h / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
  }
  return w;
}

std::optional<Delivery> Replanner::update(const gnc::GncTelemetry& tl) {
  if (const auto id = identified_params(flight_, tl.est)) {
    model_ = *id;
    if (!identified_) t_identified_ = tl.t;
    identified_ = true;
  }
  if (tl.est.adoptions != adoptions_flown_) {
    // The flight adopted its identified model at this boundary: the one in this telemetry.
    adoptions_flown_ = tl.est.adoptions;
    t_adopted_ = tl.t;
    if (const auto id = identified_params(flight_, tl.est)) flown_ = *id;
  }
  if (resync_ && flying_table_ != nullptr) {
    // The flight switched at the boundary after the delivery and re-synchronised its plan clock
    // to the estimate of that tick: the same rule here keeps the two clocks together.
    t0_ = tl.t - nearest_sample_time(*flying_table_, tl.omega_hat);
    resync_ = false;
  }
  if (pending_table_ == nullptr) {
    if (const auto why = decide(tl)) plan_now(tl, *why);  // may be due at once (no latency)
  }
  if (pending_table_ != nullptr) {
    if (tl.t + 1e-9 < records_[pending_record_].t_due) return std::nullopt;
    Delivery d;
    d.table = pending_table_;
    d.upload_id = records_[pending_record_].upload_id;
    d.first = flying_ == nullptr;
    d.t_state = records_[pending_record_].t_state;
    records_[pending_record_].t_delivered = tl.t;
    delivered_record_ = pending_record_;
    previous_ = flying_;
    previous_table_ = flying_table_;
    previous_t0_ = t0_;
    flying_ = pending_samples_;
    flying_table_ = pending_table_;
    t0_ = tl.t;  // until the re-synchronisation at the next sample
    resync_ = true;
    pending_samples_.reset();
    pending_table_.reset();
    ++delivered_;
    return d;
  }
  return std::nullopt;
}

void Replanner::refused(const std::string& why) {
  if (delivered_record_ < records_.size()) {
    ReplanRecord& r = records_[delivered_record_];
    r.ok = false;
    r.error = "refused by the flight: " + why;
  }
  if (delivered_ > 0) --delivered_;
  flying_ = previous_;
  flying_table_ = previous_table_;
  t0_ = previous_t0_;
  resync_ = false;
}

std::optional<ReplanTrigger> Replanner::decide(const gnc::GncTelemetry& tl) {
  if (stopped_ || static_cast<int>(records_.size()) >= policy_.max_plans) return std::nullopt;
  if (tl.t - last_plan_t_ < policy_.min_interval_s) return std::nullopt;
  if (!tl.omega_hat.allFinite()) return std::nullopt;
  if (flying_ == nullptr) {
    if (tl.mode == gnc::Mode::kSafe || tl.mode == gnc::Mode::kIdle) return std::nullopt;
    // The confirmation counts until the first plan (not only before first_plan_s): with noisy
    // sensors the inertia 1 sigma reaches early_j_rel after first_plan_s (cases 5 and 6: 360 s
    // and 540 s), and the D+PD reference flown until first_plan_max_s costs more than the plan.
    if (policy_.early_plan_s > 0.0 && tl.t >= policy_.early_plan_s && !identified_ &&
        apriori_confirmed(flight_, tl.est, policy_.early_sigmas, policy_.early_j_rel,
                          policy_.early_r_m)) {
      return ReplanTrigger::kEarly;
    }
    if (tl.t < policy_.first_plan_s) return std::nullopt;
    if (!identified_ && tl.t < policy_.first_plan_max_s) return std::nullopt;
    if (awaiting_adoption(tl) || settling(tl)) return std::nullopt;
    if (!identified_ && tl.t < policy_.refuted_max_s && tl.est.identifying &&
        tl.est.windows > 0 &&
        !apriori_confirmed(flight_, tl.est, policy_.early_sigmas,
                           std::numeric_limits<double>::infinity(),
                           std::numeric_limits<double>::infinity())) {
      return std::nullopt;  // the estimate refutes the table: wait for the identified model
    }
    return ReplanTrigger::kFirst;
  }
  if (tl.mode != gnc::Mode::kTrack || resync_ || settling(tl)) return std::nullopt;
  const double w = tl.omega_hat.norm();
  const PlanModel m = replan_model(model_, tl.omega_hat);
  if (w < policy_.stop_rate_fraction * first_rate_ || t_end_ - tl.t < shortest_despin(m)) {
    stopped_ = true;  // the rest is the plan's tail: re-planning it buys nothing
    return std::nullopt;
  }
  if (policy_.on_model_update && tl.est.adoptions > adoptions_seen_) {
    return ReplanTrigger::kModelUpdate;
  }
  if (policy_.on_identified && identified_ && delivered_record_ < records_.size() &&
      !records_[delivered_record_].identified && !awaiting_adoption(tl)) {
    return ReplanTrigger::kModelUpdate;
  }
  if (policy_.error_fraction > 0.0 && flying_table_ != nullptr) {
    const gnc::Vec3 w_d = aimed_rate(tl, gnc::interpolate(*flying_table_, tl.t - t0_).omega_d);
    if ((tl.omega_hat - w_d).norm() > policy_.error_fraction * w_d.norm() + policy_.error_floor) {
      return ReplanTrigger::kTrackingError;
    }
  }
  if (policy_.period_s > 0.0 && tl.t - last_plan_t_ >= policy_.period_s) {
    return ReplanTrigger::kPeriodic;
  }
  return std::nullopt;
}

void Replanner::plan_now(const gnc::GncTelemetry& tl, ReplanTrigger why) {
  last_plan_t_ = tl.t;
  adoptions_seen_ = tl.est.adoptions;
  ReplanRecord rec;
  rec.trigger = why;
  rec.t_state = tl.t;
  rec.t_due = tl.t + policy_.latency_s;
  rec.identified = identified_;
  const auto wall0 = std::chrono::steady_clock::now();

  // The plan starts where the flight will be when it switches: the command goes up at t + latency
  // and takes effect at the next tick boundary. Its first sample is then the flight's state, so the
  // flight's re-synchronisation (nearest sample) lands on it rather than up to half a sample
  // spacing off (measured: a 1 s clock error costs more fuel than the whole identification phase).
  const double ahead = policy_.latency_s + flight_.dt;
  const gnc::Vec3 omega_start = predict(tl, ahead);
  PlanProblem p;
  p.case_name = "replan";
  p.model = replan_model(model_, omega_start);
  const double t_lower = shortest_despin(p.model);
  double t_f = 0.0;
  // Receding horizon: never shorter than the rest of the plan being flown, nor than horizon_factor
  // shortest despins from here (the least fuel falls with the horizon, steeply below ~4x: keeping
  // the first plan's end would make every re-plan dearer than the plan it replaces).
  t_f = horizon_factor() * t_lower;
  if (flying_ == nullptr) {
    t_f = std::max(t_f, policy_.min_horizon_s);
  } else {
    t_f = std::max(t_f, t_end_ - tl.t);
  }
  p.settings.t_final_max = t_f;
  std::vector<PlanSample> rest;
  if (flying_ != nullptr) {
    const double tau = tl.t + ahead - t0_;
    if (tau > 0.0 && tau < flying_->back().t) {
      rest = remaining_plan(*flying_, tau);
      if (rest.size() >= 3) p.warm_start = &rest;
    }
  }
  try {
    PlanResult r = plan(p);
    rec.iterations = r.iterations;
    rec.nodes = r.nodes;
    rec.t_final = r.t_final;
    rec.fuel_kg = r.fuel_kg;
    if (!r.ok) {
      rec.error = r.error;
    } else {
      auto table = std::make_shared<gnc::TrajectoryTable>(to_table(r.samples));
      const gnc::TrajectoryError e = gnc::validate_trajectory(*table, p.model.eps_trans);
      if (e != gnc::TrajectoryError::kOk) {
        rec.error = std::string("plan fails the on-board validation: ") + gnc::to_string(e);
      } else {
        rec.ok = true;
        rec.upload_id = next_upload_id_++;
        pending_table_ = std::move(table);
        pending_samples_ = std::make_shared<const std::vector<PlanSample>>(std::move(r.samples));
        pending_record_ = records_.size();
        if (flying_ == nullptr) first_rate_ = tl.omega_hat.norm();
        t_end_ = tl.t + ahead + r.t_final;
      }
    }
  } catch (const std::exception& e) {
    rec.error = std::string("planner error: ") + e.what();
  }
  rec.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  records_.push_back(rec);
}

}  // namespace rocksteady::ground::planner
