// The re-planner: from the flight's telemetry (state estimate, identified model), decides when to
// plan, plans Eq. (44) from the current state (warm-started from the rest of the plan being flown),
// verifies (plan()'s self-verification and gnc::validate_trajectory), and hands the table for the
// uplink no earlier than `latency_s` after the state it was planned from.
//
// Time is the flight's (telemetry) time, never the wall clock: the campaign and the dispersion tool
// run it in simulated time (the solve happens at once, the delivery waits for t + latency), so a run
// is deterministic; rocksteady-planner runs the same object on the bus telemetry.
//
// Policy (ReplanPolicy):
//   first plan   after first_plan_s of identification on the D+PD reference, as soon as the
//                identified model is confident (inertia and offset), at the latest at
//                first_plan_max_s (then with the best model there is);
//   re-plans     while the plan is flown, at least min_interval_s apart, on any of:
//                  periodic: period_s after the last plan;
//                  tracking error: |omega_hat - omega_d| > error_fraction |omega_d| + error_floor;
//                  model update: the flight adopted an identified model (adoption count grew);
//   horizon      the first plan: horizon_factor shortest despins (at least min_horizon_s; by
//                default 16 when the flight tracks the plan's momentum, 8 otherwise); a
//                re-plan: the rest of the plan being flown, or horizon_factor shortest despins
//                from the current state if that is longer (a fixed minimum would recede for ever);
//   stop         once |omega_hat| < stop_rate_fraction |omega| at the first plan, or the plan's
//                end is less than one shortest-despin time away (the tail is rest-to-rest).
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "gnc/guidance/trajectory.hpp"
#include "gnc/io.hpp"
#include "gnc/params.hpp"
#include "ground/planner/planner.hpp"

namespace rocksteady::ground::planner {

struct ReplanPolicy {
  double first_plan_s{300.0};       // identify at least this long before the first plan
  double first_plan_max_s{600.0};   // plan then even if the model is not confident yet
  // Early plan for the a-priori model (<= 0: off): from early_plan_s on until the first plan
  // (before first_plan_s too, and after it while the identified model is not confident yet),
  // plan for the flight's table as soon as the identifier's estimate agrees with it: every
  // inertia and offset component within early_sigmas of its reported 1 sigma, with that 1 sigma
  // at most early_j_rel |J_hat| (inertia) and early_r_m (offset). A model that is confirmed this
  // way is planned for at once instead of being identified on the D+PD reference for longer.
  double early_plan_s{60.0};
  double early_sigmas{3.0};
  double early_j_rel{0.02};
  double early_r_m{1.0};
  // At first_plan_max_s without a confident model: if the identifier's estimate refutes the
  // a-priori model (a component beyond early_sigmas of its 1 sigma, whatever the 1 sigma), wait
  // for the identified model until refuted_max_s instead of planning for a model known to be
  // wrong (<= first_plan_max_s: off, plan for the a-priori model at first_plan_max_s).
  double refuted_max_s{3000.0};
  double period_s{600.0};           // periodic re-plan (<= 0: off)
  double error_fraction{0.1};       // tracking-error trigger (<= 0: off)
  double error_floor{2e-4};         // rad/s
  bool on_model_update{true};       // re-plan when the flight adopted an identified model
  bool on_identified{true};         // re-plan when the plan flown is for the a-priori model and the
                                    // identifier's model became confident (adopted or not)
  double min_interval_s{120.0};     // between two plans (also after a failed one)
  double latency_s{10.0};           // planning latency: delivered no earlier than t + latency
  // t_f = factor x shortest despin from the state (<= 0: automatic, kMomentumHorizonFactor when the
  // flight tracks the plan's momentum, guidance.track_momentum_k > 0, else kHorizonFactor).
  double horizon_factor{0.0};
  double min_horizon_s{0.0};  // the first plan at least this long (the least fuel falls with t_f)
  // Plan for the model the flight tracks with: once the identified model is confident, while it
  // refutes the flight's active model (some J or r component beyond early_sigmas of its 1 sigma;
  // the flight adopts such a model at its next boundary), the plan waits for the adoption, at
  // most adopt_wait_s after the model became confident (<= 0: off).
  double adopt_wait_s{60.0};
  // After the flight adopts a model, no plan for adopt_settle_tau time constants of its rate
  // stage (<= 0: off). With noisy sensors the flight's rate estimate is predicted through Eq. (2)
  // with its model and pulled towards the gyro with the gain 1 - exp(-omega_c dt) (the SPEC §6
  // filter, and the MEKF's rate stage M8): a model off by dJ biases it by about
  // |J^-1 (dJ w) x w| / omega_c (case 7 on its a-priori model: 2.3e-3 rad/s, 7 % of |w|), and
  // after an adoption that bias decays as exp(-omega_c t). A plan made meanwhile starts from a
  // rate that is not the flight's. 3 time constants (48 s at the SPEC's omega_c) leave 5 %. No
  // wait when the estimate is the measurement (noise-free sensors, no rate stage).
  double adopt_settle_tau{3.0};
  double stop_rate_fraction{0.05};
  int max_plans{20};
};

// Why a plan was made (kEarly: the first plan, for the a-priori model the identifier confirmed).
enum class ReplanTrigger : std::uint8_t { kFirst, kPeriodic, kTrackingError, kModelUpdate, kEarly };
const char* to_string(ReplanTrigger t);

struct ReplanRecord {
  ReplanTrigger trigger{ReplanTrigger::kFirst};
  double t_state{0.0};     // the telemetry the plan is made from (it starts from the rate
                           // predicted for the switch, t_state + latency + one tick)
  double t_due{0.0};       // t_state + latency
  double t_delivered{-1.0};  // when it was handed over for the uplink (< 0: not yet / never)
  bool ok{false};
  std::string error;       // planner or validation failure
  bool identified{false};  // planned with the identified model (else the flight's table)
  double fuel_kg{0.0};     // planned fuel from the state
  double t_final{0.0};
  int nodes{0};
  int iterations{0};
  double wall_s{0.0};      // solve time (reporting only; never used in a decision)
  std::int32_t upload_id{-1};
};

struct Delivery {
  std::shared_ptr<const gnc::TrajectoryTable> table;
  std::int32_t upload_id{0};
  bool first{false};  // the first plan: the flight enters TRACK with it
  double t_state{0.0};
};

class Replanner {
 public:
  // `flight`: the flight software's parameter table as the ground knows it (RCS layout, u_max,
  // eps_trans, the a-priori mass properties); the identified J and r replace its model.
  Replanner(const gnc::GncParams& flight, const ReplanPolicy& policy,
            std::int32_t first_upload_id = 10);

  // One telemetry sample (each GNC tick in simulation; each packet on the bus). May plan (at once,
  // from this sample). Returns a plan whose delivery is due (t >= t_state + latency).
  std::optional<Delivery> update(const gnc::GncTelemetry& tl);

  // The flight's verdict on the last delivery (command refused, or the table refused at the
  // boundary): a refused plan is forgotten, the one flown before is kept as the reference.
  void refused(const std::string& why);

  const std::vector<ReplanRecord>& records() const { return records_; }
  int plans_delivered() const { return delivered_; }
  bool tracking() const { return flying_ != nullptr; }
  const ReplanPolicy& policy() const { return policy_; }
  // The model the next plan is for (the latest confident identified model, else the table).
  const gnc::GncParams& model() const { return model_; }
  // The plan horizon in shortest despins: the policy's, or the automatic one for the flight's
  // TRACK (ReplanPolicy::horizon_factor <= 0).
  double horizon_factor() const;

 private:
  std::optional<ReplanTrigger> decide(const gnc::GncTelemetry& tl);
  void plan_now(const gnc::GncTelemetry& tl, ReplanTrigger why);
  // The rate the flight will have `ahead` seconds after this telemetry.
  gnc::Vec3 predict(const gnc::GncTelemetry& tl, double ahead) const;
  // The rate the flight aims at for the plan's omega_d: omega_d itself, or, with momentum tracking
  // (guidance.track_momentum_k) while the plan runs, the rate that carries the plan's momentum in
  // today's body frame, J_hat^-1 dR J_hat omega_d with dR = R(q_hat)' R(q_d) from the telemetry.
  gnc::Vec3 aimed_rate(const gnc::GncTelemetry& tl, const gnc::Vec3& omega_d) const;
  // The identified model is confident but the flight still flies a model it refutes.
  bool awaiting_adoption(const gnc::GncTelemetry& tl) const;

  gnc::GncParams flight_;
  gnc::GncParams model_;
  gnc::GncParams flown_;  // the flight's active model: the table, then each adopted model
  std::uint32_t adoptions_flown_{0};
  double t_adopted_{0.0};  // flight time of the last adoption seen
  // After an adoption, the rate stage's settling time (ReplanPolicy::adopt_settle_tau), s.
  double settle_s() const;
  bool settling(const gnc::GncTelemetry& tl) const {
    return adoptions_flown_ > 0 && tl.t - t_adopted_ < settle_s();
  }
  bool identified_{false};
  double t_identified_{0.0};
  ReplanPolicy policy_;
  std::int32_t next_upload_id_;
  std::vector<ReplanRecord> records_;
  std::uint32_t adoptions_seen_{0};
  int delivered_{0};
  // The plan waiting for its delivery time.
  std::shared_ptr<const std::vector<PlanSample>> pending_samples_;
  std::shared_ptr<const gnc::TrajectoryTable> pending_table_;
  std::size_t pending_record_{0};
  // The plan being flown, its start on the flight's clock (plan time = t - t0), its end.
  std::shared_ptr<const std::vector<PlanSample>> flying_;
  std::shared_ptr<const gnc::TrajectoryTable> flying_table_;
  std::shared_ptr<const std::vector<PlanSample>> previous_;  // kept in case the flight refuses
  std::shared_ptr<const gnc::TrajectoryTable> previous_table_;
  std::size_t delivered_record_{0};
  double t0_{0.0};
  double previous_t0_{0.0};
  double t_end_{0.0};
  double last_plan_t_{-1e300};
  double first_rate_{0.0};
  bool resync_{false};  // the next sample re-synchronises t0 (as the flight does at the switch)
  bool stopped_{false};
};

// The identifier's estimate agrees with the flight's a-priori model: every J_tot and r_SO/BCM
// component within `sigmas` of its reported 1 sigma, each inertia 1 sigma at most j_rel |J_hat| and
// each offset 1 sigma at most r_m (so the agreement means something), inertia and offset observable
// enough to be reported (at least one window).
bool apriori_confirmed(const gnc::GncParams& flight, const gnc::EstimationTelemetry& est,
                       double sigmas, double j_rel, double r_m);

// The flight's table with the identified model (J_tot, r_SO/BCM, the confident thruster strengths)
// from its telemetry, when the inertia and the offset are confident; nullopt otherwise.
std::optional<gnc::GncParams> identified_params(const gnc::GncParams& flight,
                                                const gnc::EstimationTelemetry& est);

}  // namespace rocksteady::ground::planner
