// Fuel-optimal despin planner, SPEC Eq. (44): minimise int |u_d|_1 dt subject to the estimated
// model's dynamics (41) and the limits (43). Ground code: solves a Hermite-Simpson transcription
// (transcription.hpp) with IPOPT, verifies its own answer, and hands the flight side a
// gnc::TrajectoryTable (via the trajectory file, trajectory_file.hpp).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "gnc/guidance/trajectory.hpp"
#include "gnc/params.hpp"
#include "gnc/types.hpp"

namespace rocksteady::ground::planner {

using gnc::Mat3;
using gnc::Mat38;
using gnc::Vec3;
using gnc::Vec8;

// Fuel, Eq. (54): m = cost / (I_sp g0).
inline constexpr double kIsp = 287.0;  // s
inline constexpr double kG0 = 9.8;     // m/s^2

// [Rocksteady choice] default grid: 101 nodes (201 collocation points = table samples). See
// ground/planner/README.md for why this is enough (grid refinement changes the fuel by ~1e-5).
inline constexpr int kDefaultNodes = 101;
// [Rocksteady choice] default horizon: kHorizonFactor times the shortest possible despin time.
inline constexpr double kHorizonFactor = 8.0;
// [Rocksteady choice] the re-planner's horizon when the flight tracks the plan's inertial angular
// momentum (guidance.track_momentum_k > 0): the model error then turns the body off the plan's
// attitude instead of costing thrust, so the cheaper, longer plan is flown as planned (README.md,
// re-planning: case 7 with the MEKF 94.35 -> 92.86 kg; without momentum tracking 16 shortest
// despins lost in the dispersion's tail, so the rate law keeps kHorizonFactor).
inline constexpr double kMomentumHorizonFactor = 16.0;
// The study's horizon ("study-horizon"): its fuel-optimal trackers despin over about 44 000 s (their
// reference decays over hours, which exposes them to the gyroscopic model error, SPEC §8 C2-C3).
inline constexpr double kStudyHorizon = 44000.0;

// The model the plan is for: the flight software's estimate (hatted quantities, SPEC Eq. 6).
struct PlanModel {
  Mat3 j_hat{Mat3::Identity()};   // estimated total inertia J_tot (kg m^2)
  Mat38 b_hat{Mat38::Zero()};     // estimated torque matrix (m)
  double u_max{200.0};            // per-channel force limit (N)
  double eps_trans{0.05236};      // rate bound, 0.5 rpm (rad/s)
  Vec3 omega_init{Vec3::Zero()};  // initial body rate (rad/s)
};

// [Rocksteady choice] automatic uniform grid: a node every kUniformStep seconds (measured on case 1:
// 28 s and 27.5 s spacing pass the open-loop check at 5600 s and 11 000 s with little margin).
inline constexpr double kUniformStep = 25.0;
// [Rocksteady choice] tumble-following grid (README.md, "Long horizons"): intervals per turn of the
// body, the floor of the rate the grid follows (fraction of |omega_init|), the fewest nodes.
inline constexpr double kIntervalsPerTurn = 8.0;
inline constexpr double kTumbleFloor = 0.15;
inline constexpr int kMinTumbleNodes = 41;
// Second pass: the error-equidistributing grid keeps at least this many intervals per turn.
inline constexpr double kFloorIntervalsPerTurn = 4.0;
// Mesh refinement: first error target (fraction of the open-loop limit), rounds at most.
inline constexpr double kRegridSafety = 0.25;
inline constexpr int kMaxRegrids = 3;
// [Rocksteady choice] long horizons (README.md, "Long horizons"): the despin is planned over at most
// max(kActiveHorizon, the automatic horizon) seconds and the plan rests after it. Measured (case 1):
// the fuel at 11 000 s is 0.7 % below the 5 560 s plan's, for 8x the planning time, and beyond
// 12 775 s a 25 s grid no longer fits the on-board table.
inline constexpr double kActiveHorizon = 5600.0;
// ... and at most kActiveFactor automatic horizons (64 shortest despins): at u_max = 1000 N (case 4,
// t_auto = 245 s) the candidates beyond 1 963 s needed 355-512 nodes and 20 s each to land in a
// dearer local minimum (75.6 kg against 65.8 kg at 1 963 s). Case 1's 5 600 s is 4 t_auto.
inline constexpr double kActiveFactor = 8.0;
// A fixed horizon up to kFullFactor automatic horizons (and the active horizon) is planned in full;
// a longer one as the cheapest of the doubling candidates, then rest (README.md, "Long horizons").
inline constexpr double kFullFactor = 4.0;
// Barrier parameter a warm-started solve starts from.
inline constexpr double kWarmMu = 1e-7;
// Iterations a warm-started solve gets before it is repeated cold (case 3 at 1390 s: a warm
// refinement that wanders for 1000 iterations made the plan 3x slower than the cold one).
inline constexpr int kWarmMaxIterations = 150;

struct PlanSettings {
  // Grid nodes N (2N-1 samples). 0 = automatic: with the uniform grid, one node every kUniformStep
  // seconds (at least kDefaultNodes); with the tumble grid, from the total rotation angle
  // (intervals_per_turn per turn), then mesh refinement on the plan's own interval errors.
  int nodes{0};
  // false (default): the uniform grid. true: node spacing follows the tumble (about the same
  // rotation angle per interval), refined where the open-loop error is largest. ground/planner/
  // README.md, "Long horizons", has the measurements behind the default.
  bool tumble_grid{false};
  double intervals_per_turn{kIntervalsPerTurn};
  // Final time [Rocksteady choice]: fixed by default. Without a time cost the minimum fuel is a
  // non-increasing function of the horizon (a plan that reaches rest at T extends to any T' > T by
  // resting), so a free final time ends at its upper bound anyway (or anywhere on a flat stretch);
  // fixing it removes the dense t_f column from the NLP and roughly halves the iterations.
  // free_final_time = true solves with t_f free in [t_final_min, t_final_max].
  bool free_final_time{false};
  // Final-time bounds [s]; values <= 0 mean automatic (see resolve_final_time_bounds). With a fixed
  // final time, t_f = t_final_max.
  double t_final_min{0.0};
  double t_final_max{0.0};
  // Long horizons (fixed final time, automatic uniform grid): a horizon longer than the active
  // horizon, or than kFullFactor t_auto, is planned as a despin over at most min(horizon, active)
  // followed by rest until t_final_max. The despin is the least-fuel verified plan among the
  // horizons t_auto, 2 t_auto, 4 t_auto, ... up to that (and that itself when the last doubling is
  // more than 25 % short of it) (t_auto = the automatic horizon, kHorizonFactor t_lower), each
  // solved cold, so the fuel never exceeds the automatic-horizon plan's. 0 = automatic:
  // max(t_auto, min(kActiveHorizon, kActiveFactor t_auto)). A positive value sets the active
  // horizon and plans every horizon up to it in full; a negative one plans every horizon in full
  // (no rest tail).
  double active_horizon_max{0.0};
  double tolerance{1e-9};    // IPOPT tol (scaled NLP)
  int max_iterations{1000};
  int print_level{0};  // IPOPT print_level (0 = quiet, 5 = per-iteration log)
  // The grid-convergence check of the chosen plan (README.md, "Grid-convergence check"):
  // kCoarsen (default) re-solves on every other node, warm-started from the plan's own node values;
  // for a transcription of order p >= 1 the coarse-fine fuel difference is (2^p - 1) times the
  // plan's own discretisation error, so it bounds that error. kBisect re-solves on every interval
  // halved (2N-1 nodes), which measures (1 - 2^-p) of it and costs 5-30x more.
  enum class RefinementCheck { kCoarsen, kBisect };
  bool verify_refinement{true};      // run the grid-convergence check and compare the fuel
  RefinementCheck refinement_check{RefinementCheck::kCoarsen};
  double refinement_limit{0.01};     // allowed relative fuel change on refinement
  // Long horizons: the candidate despins are solved in this many worker processes at once (each
  // its own IPOPT and MUMPS: MUMPS is process-global, so not threads). 1: in this process, one
  // after the other. 0: one per hardware thread. Results do not depend on it. A process that runs
  // other threads (the campaign's workers) keeps 1: a forked child inherits only its caller.
  int jobs{1};
  double propagation_limit{1e-3};    // allowed open-loop error, relative to |omega_init|
};

struct PlanSample;

struct PlanProblem {
  std::string case_name{"custom"};
  PlanModel model;
  PlanSettings settings;
  // Optional warm start (not part of the problem's hash): a plan of a nearby problem, e.g. the
  // remaining part of the plan being flown (remaining_plan). Its final time is used when it lies in
  // the final-time range; a shorter plan is extended by rest.
  const std::vector<PlanSample>* warm_start{nullptr};
};

struct PlanSample {
  double t{0.0};
  Vec3 omega_d{Vec3::Zero()};
  Vec3 omega_d_dot{Vec3::Zero()};  // = J^-1 ((J omega_d) x omega_d + B u_d), Eq. (41)
  Vec8 u_d{Vec8::Zero()};
};

struct Verification {
  bool passed{false};
  std::string failure;            // first failed check, empty when passed
  double max_defect{0.0};         // Hermite-Simpson defects, rad/s (recomputed from the samples)
  double max_rate_excess{0.0};    // max(|omega_d| - eps_trans, 0), rad/s
  double max_control_excess{0.0}; // max(|u_i| - u_max, 0), N
  double boundary_error{0.0};     // |omega_d(0) - omega_init| + |omega_d(t_f)|, rad/s
  double propagation_error{0.0};  // max |omega_open_loop - omega_d| at the samples, rad/s
  double propagated_final_rate{0.0};  // |omega_open_loop(t_f)|, rad/s
  bool refinement_checked{false};
  int refined_nodes{0};           // nodes of the check's grid (fewer: coarsened; more: bisected)
  double refined_fuel_kg{0.0};    // fuel of the plan re-solved on the check's grid
  double refinement_change{0.0};  // |fuel_refined - fuel| / fuel
  int refined_iterations{0};
  double refined_seconds{0.0};
};

struct PlanResult {
  bool ok{false};
  std::string error;  // why the plan failed (solver status or failed verification)
  double cost_ns{0.0};    // int |u|_1 dt (N s)
  double fuel_kg{0.0};    // Eq. (54)
  double t_final{0.0};    // s
  double t_final_min{0.0};  // the resolved final-time range (s)
  double t_final_max{0.0};
  int nodes{0};
  // End of the despin: t_final, or, for a long horizon (active_horizon_max), the end of the active
  // part after which the plan rests (its last two samples: omega_d = 0, u_d = 0).
  double t_active{0.0};
  int iterations{0};        // IPOPT iterations of the main solve (all candidates for a long horizon)
  double solve_seconds{0.0};  // wall time of the main solve
  std::vector<PlanSample> samples;  // every collocation point (nodes and midpoints)
  Verification verification;
};

// Automatic final-time range [Rocksteady choice]:
//   t_lower = |H0| / (u_max sum_i |B_i|): no admissible torque is larger than u_max sum_i |B_i|, and
//             the gyroscopic term does not change |H| = |J omega|, so no plan can be shorter;
//   t_max = kHorizonFactor t_lower (README.md: case 1, 8x -> 85.0 kg, 16x -> 83.7 kg, 32x -> 81.8 kg);
//   t_min = t_lower when the final time is free, t_max when it is fixed.
// Explicit positive settings override either end.
void resolve_final_time_bounds(const PlanModel& model, const PlanSettings& settings, double& t_min,
                               double& t_max);

// Solves Eq. (44) for the model and verifies the answer. Never throws for solver failures:
// ok = false with the reason in `error`.
PlanResult plan(const PlanProblem& problem);

// Re-checks samples against the model: defects, bounds, boundary conditions, open-loop propagation.
// (plan() calls this; exposed so tests and the file loader can re-verify.)
Verification verify_samples(const PlanModel& model, const std::vector<PlanSample>& samples,
                            double propagation_limit);

// The flight-side table of a plan (t, omega_d, omega_d_dot; checksum set). The last omega_d is
// exactly zero. Throws std::length_error if there are more samples than the table holds.
gnc::TrajectoryTable to_table(const std::vector<PlanSample>& samples);

// The estimated model of a study case (SPEC §5, Table 3): J_ast_hat = J_ast - dJ diag(-1, 1, 0.5),
// r_hat = r - dr [1 1 1]/sqrt(3); study RCS layout; omega_init of Table 2.
PlanModel study_case_model(double u_max, double delta_j_norm, double delta_r_norm);

// The part of a plan after `t_now`, time-shifted to start at 0 (interpolated first sample; the
// sample count kept odd, node-midpoint structure kept): the warm start of a re-plan from the state
// reached at t_now.
std::vector<PlanSample> remaining_plan(const std::vector<PlanSample>& samples, double t_now);

// The model a re-plan from the flight's current state is for. Today: the flight's active parameter
// table (J_hat from mass_hat, B_hat from the RCS layout and r_hat). The identified model (J, r,
// thruster strengths k) replaces the table here, and only here, once the flight reports it.
PlanModel replan_model(const gnc::GncParams& active, const Vec3& omega_hat);

// 64-bit FNV-1a hash of the model and the settings (the cache key; also stored in the file).
std::uint64_t problem_hash(const PlanProblem& problem);

}  // namespace rocksteady::ground::planner
