// Statistics of a dispersion: per strategy success rate with its 95 % Wilson interval, percentiles
// of the figures of merit, the worst draws, paired fuel differences between strategies on the same
// draws; and the outputs (per-draw CSV, JSON summary, Markdown report, gnuplot plots).
#pragma once

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "ground/campaign/estimation_report.hpp"
#include "ground/dispersion/draw.hpp"
#include "ground/dispersion/spec.hpp"

namespace rocksteady::dispersion {

constexpr double kZ95 = 1.959963984540054;  // the standard normal's 97.5 % quantile

// Wilson score interval for k successes in n trials (n > 0).
std::pair<double, double> wilson_interval(int k, int n, double z = kZ95);
// The p-quantile (p in [0, 1]) with linear interpolation between order statistics (Hyndman & Fan
// type 7: h = (n - 1) p). `values` need not be sorted; empty gives nullopt.
std::optional<double> percentile(std::vector<double> values, double p);

struct Percentiles {
  int n{0};
  std::optional<double> p5, p50, p95, p99;
};
Percentiles percentiles(const std::vector<double>& v);

struct WorstDraw {
  int draw{0};
  std::string why;  // status / not converged / rate bound / fuel
  std::optional<double> fuel_kg;
};

// Identification against the truth at one mark over the draws that reached it.
struct IdentificationStats {
  double t_s{0.0};
  int n{0};
  Percentiles j_rel, r_err_m, k_max_err;
  // Fraction of draws whose normalised error lies inside the chi-square 95 % bound (6 dof for J,
  // 3 for r): about 0.95 when the reported 1 sigma is consistent with the errors.
  double j_nees_in95{0.0};
  double r_nees_in95{0.0};
  int inertia_confident{0};
  int offset_confident{0};
};

// Thruster strengths kStrengthMarkAfterFiringS (600 s) after each thruster's first commanded firing
// (issue 18's target), over the (draw, thruster) pairs whose mark the run reached.
struct StrengthStats {
  int draws{0};                 // draws with at least one thruster's mark reached
  int pairs{0};                 // (draw, thruster) pairs with the mark reached
  int never_fired{0};           // pairs the flight never commanded
  Percentiles worst;            // per draw, the largest |k_hat - k| over its reached thrusters
  Percentiles all;              // every reached pair
  double within_2pct{0.0};      // fraction of the reached pairs with |k_hat - k| <= 0.02
  double nees_in95{0.0};        // fraction with (err / sigma)^2 inside the chi-square (1 dof) 95 %
  int confident{0};             // reached pairs the identifier called confident
  Percentiles worst_confident;  // per draw, the largest error over its confident thrusters
};

struct StrategyStats {
  std::string strategy;
  int draws{0};
  int flown{0};
  int successes{0};
  int no_plan{0};
  int errors{0};  // error or crashed
  double success_rate{0.0};
  std::pair<double, double> wilson{0.0, 0.0};
  Percentiles t_omega, t_q, fuel;
  std::vector<WorstDraw> worst;  // five
  // Estimation against the truth (draws that flew): attitude and rate error RMS of the estimator,
  // and the identification marks when the strategy identifies.
  Percentiles attitude_rms_rad, rate_rms_rad_s;
  std::vector<IdentificationStats> identification;
  StrengthStats strengths;
};

struct PairedStats {
  std::string a, b;
  int n{0};                  // draws where both flew
  double mean_diff_kg{0.0};  // fuel(a) - fuel(b)
  Percentiles diff;
  double frac_a_less{0.0};
};

// Where law+fuel_optimal stops beating law+dpd_ref in fuel as ||dJ|| grows (SPEC Prop. 5).
struct Crossover {
  std::string a, b;
  std::vector<double> bin_lo, bin_hi;  // ||dJ|| bins (log-spaced)
  std::vector<int> bin_n;
  std::vector<double> bin_median_diff;    // fuel(a) - fuel(b), NaN when empty
  std::optional<double> crossover_kg_m2;  // first sign change of the median, log-interpolated
};

// A fault dispersion (`faults:`): per strategy, fault kind and onset (case 0), and per study case
// as well, what the fault detector made of the draw's fault and what the fault cost against the
// case's fault-free reference flown by the same strategy (read_reference).
struct FaultGroupStats {
  std::string strategy;
  std::string kind;  // stuck_off | stuck_on | degraded (plant::to_string)
  double onset_s{0.0};
  int case_number{0};  // 0: every case
  int runs{0};         // flown (status ok)
  int goals_met{0};    // both SPEC §7 goals (t_omega,conv and t_q,conv reached in the run)
  int successes{0};    // both SPEC §7 goals and |omega| <= eps_trans throughout
  int isolated{0};     // exactly one confirmation, naming the draw's thruster and kind
  int wrong{0};        // some confirmation, not that one
  int none{0};         // no confirmation
  Percentiles latency_s;  // isolated runs: first confirmation minus onset
  std::optional<double> latency_max_s;
  int detected{0};           // runs with a window above the no-fault bound at or after onset,
                             // or a confirmation after onset
  Percentiles detection_s;   // ... the first of them minus onset
  std::optional<double> detection_max_s;
  Percentiles valve_s;       // isolated stuck-on runs: the pod's valve closed, minus onset
  std::optional<double> valve_max_s;
  Percentiles penalty_kg;  // total fuel minus the reference's (draws and reference both flew)
  std::optional<double> penalty_max_kg;
  // The faulty jet as the flight commanded it after onset (campaign FdiReport): runs in which it
  // was never commanded (a stuck-off or degraded jet then has nothing to show), and over the
  // isolated runs the time it was commanded from onset to the confirmation (the issue's "seconds
  // of commanded firing").
  int not_commanded{0};
  Percentiles commanded_to_isolation_s;
  std::optional<double> commanded_to_isolation_max_s;
  Percentiles commanded_impulse_to_isolation_ns;  // the same, as commanded impulse (N s)
  // ... and as firing at full thrust: that impulse over the draw's true u_max (s). A jet commanded
  // at a few newtons for seconds shows nothing; this is the "seconds of commanded firing" of an
  // on/off thruster.
  Percentiles firing_to_isolation_s;
  std::optional<double> firing_to_isolation_max_s;
};

struct ReferenceRow {
  int case_number{0};
  std::string strategy;
  std::string status;
  bool success{false};
  std::optional<double> fuel_kg;
};

struct Summary {
  std::string name;
  int draws_expected{0};
  int draws_present{0};
  std::vector<StrategyStats> strategies;
  std::vector<PairedStats> paired;
  std::vector<Crossover> crossovers;
  std::vector<FaultGroupStats> faults;    // a fault dispersion only
  std::vector<ReferenceRow> references;   // its fault-free references
  double draw_wall_s_sum{0.0};
  double simulated_s{0.0};
  double closed_loop_wall_s_sum{0.0};
  double plan_wall_s_sum{0.0};
};

// `references`: the fault-free references of a fault dispersion over study cases (may be empty:
// then no fuel penalty is given).
Summary summarize(const DispersionSpec& spec, const std::vector<DrawResult>& draws,
                  const std::vector<DrawResult>& references = {});
// The kind the flight software declares for a plant fault kind (stuck-on, stuck-off, degraded).
std::string declared_kind(plant::FaultKind k);

struct OutputPaths {
  std::string results_csv, summary_json, report_md;
  std::vector<std::string> plots;
};
// Writes results.csv, summary.json, report.md and the plots into `dir`. `reproduce` is the command
// prefix that re-flies one draw (the draw's index is appended).
OutputPaths write_outputs(const std::string& dir, const DispersionSpec& spec,
                          const std::vector<DrawResult>& draws, const Summary& s,
                          const std::string& reproduce, bool plots);
void write_results_csv(const std::string& path, const DispersionSpec& spec,
                       const std::vector<DrawResult>& draws);
nlohmann::json summary_json(const Summary& s, const std::string& reproduce);

}  // namespace rocksteady::dispersion
