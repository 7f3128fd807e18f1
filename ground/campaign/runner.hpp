// The in-process closed loop: plant and flight software in lockstep at the GNC rate, one process,
// as fast as the machine allows. Each tick: the plant's sensor sample -> FlightSide::step -> the
// plant advances one control period with the commanded channel forces (zero-order hold).
// Figures of merit (SPEC §7) are taken on the TRUE state after every tick.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "ground/campaign/flight_side.hpp"
#include "ground/campaign/strategy.hpp"
#include "ground/config/config.hpp"
#include "ground/merit/figures_of_merit.hpp"

namespace rocksteady::campaign {

// The figures of merit live in ground/merit (the plant process uses them too).
using merit::attitude_error;
using merit::ConvergenceTracker;

struct TimeRow {
  double t{0.0};
  Eigen::Vector3d omega{Eigen::Vector3d::Zero()};      // true
  Eigen::Vector3d omega_hat{Eigen::Vector3d::Zero()};  // flight estimate
  Eigen::Vector3d q{Eigen::Vector3d::Zero()};          // true, shadow-normalised MRP
  Eigen::Vector3d q_hat{Eigen::Vector3d::Zero()};
  Eigen::Vector3d torque_cmd{Eigen::Vector3d::Zero()};  // u_c
  gnc::Vec8 force{gnc::Vec8::Zero()};                   // channel forces commanded at t
  double fuel_kg{0.0};                                  // true, cumulative
  double fuel_hat_kg{0.0};                              // flight software's estimate
  gnc::Mode mode{gnc::Mode::kIdle};
  // Identification against the truth (written when the identifier runs): as IdentificationMark,
  // the innovation gate's counters (estimation README I18), the windows closed, the guards'
  // refusals (I14) and the last window's inertia excitation (I16).
  double j_rel{0.0};
  double r_err_m{0.0};
  double k_max_err{0.0};
  double j_nees{0.0};
  double r_nees{0.0};
  double r_sigma_max_m{0.0};  // largest reported 1 sigma of r
  std::uint32_t windows_gated{0};
  std::uint32_t gate_reinflations{0};
  std::uint32_t windows{0};         // identification windows closed
  std::uint32_t guard_refusals{0};  // updates refused by the guards (I14)
  bool excited_inertia{false};      // the last window excited the inertia scale (I16)
  // Fault detection (written when the detector runs): the last window's no-fault chi-square, the
  // leading hypothesis (0..15 stuck on, 16..31 stuck off, -1 none) and its LLR, the confirmed
  // jets (on | off | degraded) and the jet under a check (-1 none).
  double fdi_chi2{0.0};
  int fdi_best{-1};
  double fdi_best_llr{0.0};
  std::uint16_t fdi_confirmed{0};
  int fdi_check_jet{-1};
};

// Identification against the truth at one instant (the marks: 60, 300, 600, 1000, 3000 s).
struct IdentificationMark {
  double t_s{0.0};
  bool reached{false};   // the run lasted that long with the identifier on
  double j_rel{0.0};     // ||J_hat - J||_F / ||J||_F
  double r_err_m{0.0};   // ||r_hat - r||
  double k_max_err{0.0}; // max_i |k_hat_i - k_i|
  // Normalised squared errors with the reported 1 sigma (diagonal): chi-square with 6 and 3 dof
  // when the sigmas are consistent with the errors.
  double j_nees{0.0};
  double r_nees{0.0};
  bool inertia_confident{false};
  bool offset_confident{false};
  int offset_unobservable{0};
};

// One thruster's strength estimate against the truth kStrengthMarkAfterFiringS after the flight
// first commanded it (issue 18's target: within 2 % within 600 s of that thruster firing).
inline constexpr double kStrengthMarkAfterFiringS = 600.0;
struct StrengthMark {
  std::optional<double> first_fired_s;  // first tick its half of the channel was asked a positive
                                        // force with its pod's valve open
  bool reached{false};                  // the run lasted until first_fired_s + 600 s
  double err{0.0};                      // |k_hat - k| then
  double sigma{0.0};                    // the identifier's reported 1 sigma then
  bool confident{false};                // within the identifier's confidence bound then
  double impulse_ns{0.0};               // impulse asked of it from its first firing to the mark
};

// The estimator and the identifier against the truth over one run.
struct EstimationReport {
  std::string estimator;           // "passthrough", "filter", "mekf"
  double attitude_rms_rad{0.0};    // angle between the estimated and the true attitude, t >= 60 s
  double attitude_max_rad{0.0};
  double rate_rms_rad_s{0.0};      // |omega_hat - omega|, t >= 60 s
  double rate_max_rad_s{0.0};
  bool identifying{false};
  std::vector<IdentificationMark> marks;
  std::vector<StrengthMark> strengths;  // one per physical thruster when identifying
  std::uint32_t model_adoptions{0};
};

// Fault detection against the injected truth.
struct FdiReport {
  bool enabled{false};
  std::optional<double> first_suspicion_s;  // first window above the no-fault bound
  // The first such window at or after the injected fault's onset (its detection; a healthy
  // window above the bound earlier in the run is not it).
  std::optional<double> fault_detected_s;
  std::optional<double> first_confirmation_s;
  int thruster{-1};           // first confirmed thruster (flight index 2c "+", 2c+1 "-")
  std::string kind;           // stuck-on | stuck-off | degraded
  double factor{1.0};         // that thruster's latched strength factor at the end (degraded)
  int confirmations{0};       // thrusters confirmed over the run
  std::uint16_t confirmed_on{0};
  std::uint16_t confirmed_off{0};
  std::uint16_t confirmed_degraded{0};
  std::optional<double> valve_closed_s;
  std::uint32_t suspicions{0};
  std::uint32_t checks{0};  // (F19) jet checks started
  std::uint32_t checks_unfit{0};  // ... check windows not scored (they showed a model error)
  std::uint32_t surveys{0};       // (F36) ... of the checks, those the jet survey started
  std::uint32_t balance_tests{0};  // (F61) channel balance tests flown
  std::uint32_t balance_confirmations{0};  // (F61) ... faults they confirmed
  // The injected fault's jet as the flight commanded it after onset (from the truth's fault list
  // and the flight's command; the flight never sees the former): the first tick it was commanded
  // (its half of the channel asked a positive force with the pod's valve open), and the time and
  // impulse it was commanded from onset to the first confirmation (or the end of the run). A
  // stuck-off or degraded jet can only show while it is commanded.
  std::optional<double> fault_first_commanded_s;
  double fault_commanded_s{0.0};
  double fault_commanded_impulse_ns{0.0};
};

// The re-planner's policy for the replan strategies (ground/planner/replanner.hpp, ReplanPolicy):
// all times are simulated seconds.
struct ReplanOptions {
  double latency_s{10.0};          // a plan from the state at t is activated no earlier than t + latency
  double first_plan_s{300.0};      // identification on the D+PD reference at least this long
  double first_plan_max_s{600.0};  // first plan then even without a confident model
  double period_s{600.0};          // periodic re-plan (<= 0: off)
  double error_fraction{0.1};      // re-plan when |omega_hat - omega_d| > this |omega_d| (+ floor)
  bool on_model_update{true};      // re-plan when the flight adopts an identified model
  double min_interval_s{120.0};    // between two plans
  // Plan horizon, in shortest despins from the current state (<= 0: the re-planner's automatic
  // one: 16 when the flight tracks the plan's momentum, as these strategies do by default, 8 on
  // the law's rates; ground/planner/planner.hpp kMomentumHorizonFactor). Measured (README,
  // re-planning): 8 -> 16 with momentum tracking, case 7 with the MEKF 94.35 -> 92.86 kg.
  double horizon_factor{0.0};
  double min_horizon_s{0.0};       // and at least this long
  double early_plan_s{60.0};       // > 0: from then on, plan for the a-priori model as soon as
                                   // the identifier confirms it (replanner.hpp ReplanPolicy)
  double early_sigmas{3.0};        // the confirmation: within this many 1 sigma,
  double early_j_rel{0.02};        // each inertia 1 sigma at most this x |J_hat|,
  double early_r_m{1.0};           // each offset 1 sigma at most this (m)
  double refuted_max_s{3000.0};     // a-priori model refuted at first_plan_max_s: wait until then
  bool on_identified{true};        // re-plan when the identifier's model becomes confident
  // The flight's adoption (gnc identification.adopt_sigmas): a confident model that differs from
  // the table by more than this many of its 1 sigma is adopted, so that the NTCL tracks the plan
  // with the model it was planned for (0: only beyond the fixed confidence bounds, 1 % of |J|).
  double adopt_sigmas{3.0};
  double adopt_wait_s{60.0};  // a confident model the flight does not fly yet: wait for its adoption
  double adopt_settle_tau{3.0};  // after an adoption, no plan for this many rate-stage time constants
  // The flight's offset confidence bound for these strategies (identification.offset_confident_m;
  // <= 0: the flight's own, 5 cm): a model is adopted and planned for once the inertia is
  // confident and no offset direction is unobservable with every observed 1 sigma within this.
  // 1 m, the prior's 1 sigma: the offset's posterior mean (a better estimate than the table's
  // prior mean in every observed direction, the prior's in none) goes with the confident inertia.
  // Measured (README, re-planning): case 7 125.4 -> 105.4 kg, 200 draws p50 95.7 -> 89.6 kg.
  double offset_confident_m{1.0};
  // The flight's acquisition slew for these strategies (guidance.slew_s; <= 0: the flight's own,
  // Eqs. (46)-(48) unless gnc.yaml sets one): once the last plan is flown, a rest-to-rest turn to
  // q_final in this time. 4*10^4 s keeps the coast below the SPEC §7 rate goal (10^-4 rad/s) for
  // any turn up to pi with the default ramps. Measured (README, re-planning): every study case
  // uses less fuel, case 6 with the MEKF 93.70 -> 93.14 kg.
  double slew_s{40000.0};
  // The flight's momentum tracking for these strategies (guidance.track_momentum_k, 1/s; <= 0: the
  // flight's own, the law on the plan's rates unless gnc.yaml sets one): TRACK flies the plan's
  // inertial angular momentum, so a model error turns the body off the plan's attitude instead of
  // costing thrust. Measured (README, re-planning): case 7 with the MEKF 101.34 -> 94.35 kg.
  double momentum_k{1e-3};
};

// One plan of the re-planner, and what the flight did with it.
struct ReplanEvent {
  std::string trigger;       // first | periodic | tracking_error | model_update
  double t_state_s{0.0};     // the state it was planned from
  double t_due_s{0.0};       // t_state + latency
  double t_delivered_s{-1.0};  // uplinked (< 0: never)
  bool ok{false};
  std::string error;
  bool identified{false};    // planned for the identified model
  double planned_fuel_kg{0.0};
  double t_final_s{0.0};
  int nodes{0};
  int iterations{0};
  double wall_s{0.0};
  int upload_id{-1};
};

struct ReplanReport {
  bool enabled{false};
  int plans{0};      // solved and verified
  int failed{0};     // planner, validation or flight refusals
  int delivered{0};  // uplinked and loaded
  int switched{0};   // trajectory_switched at a boundary (re-plans while tracking)
  int refused{0};    // trajectory_stale at a boundary
  std::vector<ReplanEvent> events;
};

enum class RunStatus { kOk, kNoReference, kError };
const char* to_string(RunStatus s);

struct RunResult {
  std::string case_name;
  int case_number{0};
  std::string strategy;
  RunStatus status{RunStatus::kOk};
  std::string note;
  std::string faults{"none"};  // the plant's injected thruster faults (plant::describe)
  std::optional<double> t_omega_conv_s;
  std::optional<double> fuel_at_t_omega_kg;
  std::optional<double> t_q_conv_s;
  std::optional<double> fuel_at_t_q_kg;
  double total_fuel_kg{0.0};
  double fuel_hat_kg{0.0};     // the flight software's own estimate at the end
  double max_rate_rad_s{0.0};  // max |omega| (true)
  double final_rate_rad_s{0.0};
  double final_q_error{0.0};
  std::string final_mode;
  std::uint64_t ticks{0};
  std::uint64_t clipped_ticks{0};    // plant clipped a channel at u_max
  std::uint64_t saturated_ticks{0};  // flight allocator rescaled (Eq. 53)
  double sim_s{0.0};
  double wall_s{0.0};
  double plan_wall_s{0.0};
  EstimationReport estimation;
  FdiReport fdi;
  ReplanReport replan;
  std::vector<TimeRow> series;  // decimated
  std::string timeseries_path;
  std::string plot_path;
};

struct RunOptions {
  double duration_s{-1.0};       // < 0: the case's duration
  double log_interval_s{50.0};   // time-series decimation (0: no series)
  std::atomic<std::uint64_t>* progress_ticks{nullptr};  // advanced as the run proceeds
  // Called once before the first tick with the plant as built (after the flight side's setup), so
  // a caller can read back the models actually flown.
  std::function<void(const plant::Plant&)> on_start;
  ReplanOptions replan;  // the replan strategies' policy and planning latency
};

// Runs one case with one strategy. `trajectory` is required for fuel_optimal strategies; pass null
// to get a kNoReference result (with `no_reference_note`) without simulating.
RunResult run_closed_loop(const config::RunSetup& setup, const Strategy& strategy, FlightSide& flight,
                          const gnc::TrajectoryTable* trajectory, const RunOptions& options,
                          const std::string& no_reference_note = "no reference");

// The flight parameters of a strategy: the case's GncParams with the strategy's law.
gnc::GncParams flight_params(const config::RunSetup& setup, const Strategy& strategy);

// The normalised estimation error err' C^-1 err with C the packed covariance (gnc::pack_upper);
// when C is not positive definite, the sum of (err_i / sigma_i)^2. Instantiated for N = 3, 6.
template <int N>
double normalised_error(const Eigen::Matrix<double, N, 1>& err,
                        const Eigen::Matrix<double, N*(N + 1) / 2, 1>& cov_packed,
                        const Eigen::Matrix<double, N, 1>& sigma);


}  // namespace rocksteady::campaign
