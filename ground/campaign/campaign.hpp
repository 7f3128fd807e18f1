// The campaign: any set of cases x strategies, run in parallel on the machine's cores, with a
// progress display on a terminal (quiet in CI), and its outputs:
//   <out>/results.csv   the study's figures of merit, one row per run (empty field = NC)
//   <out>/results.md    the study's results-table layout (cases as row groups, strategies as columns)
//   <out>/runs.csv      per run: status, note, wall time, saturation counts, output paths
//   <out>/runs/<case>_<strategy>/timeseries.csv and plot.png (the study's Figure 3 layout)
#pragma once

#include <iosfwd>
#include <string>
#include <vector>

#include "ground/campaign/runner.hpp"
#include "ground/campaign/strategy.hpp"
#include "ground/campaign/trajectory_source.hpp"

namespace rocksteady::campaign {

enum class ProgressMode { kAuto, kOn, kOff };  // auto: on when stderr is a terminal and CI is unset

struct CampaignSpec {
  std::string mission_file;
  std::string gnc_file;
  std::vector<std::string> case_files;
  std::vector<Strategy> strategies;
  std::string out_dir{"out/campaign"};
  int jobs{0};  // 0: one per hardware thread
  bool write_timeseries{true};
  bool write_plots{true};
  ProgressMode progress{ProgressMode::kAuto};
  double duration_s{-1.0};      // < 0: each case's own duration
  double log_interval_s{-1.0};  // < 0: duration / 5000
  // The flight side: the flight application through the in-process HAL (the code that flies), or the
  // bare flight core (for comparison).
  bool use_flight_app{true};
  ReplanOptions replan;  // the replan strategies' policy and planning latency
};

struct CampaignReport {
  std::vector<RunResult> results;  // case-major, in the spec's order
  std::vector<std::string> cases;  // case names in order
  std::vector<std::string> strategies;
  int threads{1};
  double plan_wall_s{0.0};      // trajectory planning (excluded from the benchmark)
  double sim_wall_s{0.0};       // wall time of the closed-loop runs (the benchmark)
  double output_wall_s{0.0};    // writing series and plots (per worker)
  double run_phase_wall_s{0.0}; // closed loop + outputs, wall
  double simulated_s{0.0};      // sum of simulated seconds
  double cpu_s{0.0};            // process CPU time of the run phase (all threads)
  std::string results_csv;
  std::string results_md;
  std::string runs_csv;
  std::string results_json;  // the same results (and run details) as JSON
};

// Loads every file first (a ConfigError stops the campaign before any run), plans the trajectories
// the fuel_optimal strategies need, runs everything, writes the outputs. `log` gets the progress
// display and the benchmark line.
CampaignReport run_campaign(const CampaignSpec& spec, TrajectorySource& source, std::ostream& log);

// results.csv header (exactly the study's figures of merit).
extern const char* const kResultsHeader;
void write_results_csv(const std::string& path, const std::vector<RunResult>& results);
void write_results_markdown(const std::string& path, const std::vector<RunResult>& results,
                            const std::vector<std::string>& cases,
                            const std::vector<std::string>& strategies,
                            const std::string& preamble);
void write_runs_csv(const std::string& path, const std::vector<RunResult>& results);
// results.csv and runs.csv together as one JSON document (nlohmann-json); NC is null.
void write_results_json(const std::string& path, const CampaignReport& rep);
void write_timeseries_csv(const std::string& path, const RunResult& result);
// gnuplot script + PNG next to the series; returns false (with the reason) if gnuplot failed.
bool write_plot(const std::string& dir, const RunResult& result, std::string& error);

// "1234.5" or "" (NC) for the CSV; "NC" for the table.
std::string csv_field(const std::optional<double>& v, int decimals);
std::string benchmark_line(const CampaignReport& r);

}  // namespace rocksteady::campaign
