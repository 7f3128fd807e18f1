// One draw flown: its case configuration (a pure function of the draw), one plan shared by the
// fuel-optimal strategies, every strategy through the campaign runner (the flight application in
// process), the parameters read back from the models actually flown, and the result as JSON.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "ground/campaign/runner.hpp"
#include "ground/campaign/trajectory_source.hpp"
#include "ground/config/config.hpp"
#include "ground/dispersion/sampler.hpp"
#include "ground/dispersion/spec.hpp"

namespace rocksteady::dispersion {

// What the plant (truth) and the flight software (estimate) were actually built with.
struct Readback {
  Mat3 delta_j{Mat3::Zero()};  // plant J_ast minus flight J_ast_hat
  double delta_j_norm{0.0};    // spectral norm
  Vec3 delta_r{Vec3::Zero()};  // plant r_SO/BCM minus flight estimate
  double delta_r_norm{0.0};
  Vec3 omega0{Vec3::Zero()};  // plant state at t = 0
  Vec3 mrp0{Vec3::Zero()};
  double gyro_psd{0.0};
  double star_psd{0.0};
  double disturbance_sigma_nm{0.0};
  std::uint64_t noise_seed{0};
  double u_max_true_n{0.0};
  double u_max_flight_n{0.0};
  std::string allocator;  // the flight software's: pinv or l1
  std::string faults;     // the plant's thruster faults (plant::describe), "none"
};
Readback read_back(const plant::Plant& plant, const gnc::GncParams& flown);

struct StrategyOutcome {
  std::string strategy;
  std::string status;  // ok | no_plan | error | crashed
  std::string note;
  bool success{false};  // both SPEC §7 goals and |omega| <= eps_trans throughout
  std::optional<double> t_omega_conv_s;
  std::optional<double> fuel_at_t_omega_kg;
  std::optional<double> t_q_conv_s;
  std::optional<double> fuel_at_t_q_kg;
  std::optional<double> total_fuel_kg;
  double fuel_hat_kg{0.0};
  double max_rate_rad_s{0.0};
  double final_rate_rad_s{0.0};
  double final_q_error{0.0};
  std::string final_mode;
  std::uint64_t ticks{0};
  std::uint64_t clipped_ticks{0};
  std::uint64_t saturated_ticks{0};
  double sim_s{0.0};
  double wall_s{0.0};  // timing (not part of the result proper)
  campaign::EstimationReport estimation;  // estimator and identification against the truth
  campaign::FdiReport fdi;                // fault detection
  campaign::ReplanReport replan;          // the re-planner's plans (replan strategies)
};

struct DrawResult {
  int index{0};
  DrawParams sampled;
  std::optional<Readback> flown;  // absent when nothing flew
  double eps_trans_rad_s{0.0};
  bool planned{false};  // a plan was needed
  bool have_plan{false};
  std::string plan_note;
  std::vector<StrategyOutcome> runs;  // in the spec's order
  double wall_s{0.0};
  double plan_wall_s{0.0};
};

// The run setup of one draw: the mission's truth, the draw's errors applied to the estimate (Eq.
// 6). Throws config::ConfigError when the draw gives an invalid model.
config::RunSetup make_setup(const config::MissionConfig& mission, const config::GncConfig& gnc,
                            const DispersionSpec& spec, const DrawParams& d);

struct FlyOptions {
  double log_interval_s{0.0};  // > 0: keep time series (re-fly of one draw)
  std::vector<campaign::RunResult>* full_runs{nullptr};  // the runner's results with series
};

DrawResult fly_draw(const config::MissionConfig& mission, const config::GncConfig& gnc,
                    const DispersionSpec& spec, const Sampler& sampler, int index,
                    campaign::TrajectorySource& planner, const FlyOptions& options = {});

// The fault-free reference of a fault dispersion over study cases (`faults: cases`): case
// `case_index` of the plan flown as the draws fly it (the case file, every strategy, the same
// noise), without a thruster fault. The draws' fuel penalty is measured against it. nullopt when
// the spec has no such case or no draw flies it. Its index is -1.
std::optional<DrawParams> reference_params(const DispersionSpec& spec, const Sampler& sampler,
                                           std::size_t case_index);
DrawResult fly_reference(const config::MissionConfig& mission, const config::GncConfig& gnc,
                         const DispersionSpec& spec, const DrawParams& reference,
                         campaign::TrajectorySource& planner);

// A result for a draw whose process died (the reason says how).
DrawResult crashed_draw(const DispersionSpec& spec, const Sampler& sampler, int index,
                        const std::string& reason);

// JSON: "result" (sampled, flown, runs without timing) and "timing". Doubles round-trip exactly.
nlohmann::json to_json(const DrawResult& r, bool with_timing = true);
DrawResult draw_from_json(const nlohmann::json& j);

// Writes <dir>/draws/<index>.json atomically (temporary file + rename).
std::string draw_path(const std::string& dir, int index);
void write_draw(const std::string& dir, const DrawResult& r);
std::optional<DrawResult> read_draw(const std::string& dir, int index);
// <dir>/reference/case<N>.json: the fault-free reference of study case N (same format as a draw).
std::string reference_path(const std::string& dir, int case_number);
void write_reference(const std::string& dir, const DrawResult& r);
std::optional<DrawResult> read_reference(const std::string& dir, int case_number);

}  // namespace rocksteady::dispersion
