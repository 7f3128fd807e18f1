// rocksteady-campaign: closed-loop runs of the study's cases in one process.
//   rocksteady-campaign run --case 1 --strategy ntcl+dpd_ref
//   rocksteady-campaign campaign [--cases 1-7] [--strategies study|all|a,b,...] [--jobs 2]
//   rocksteady-campaign dispersion configs/dispersions/FILE.yaml [--draw N] [--backend local|slurm]
//   rocksteady-campaign collect DIR
// Exit status: 0 done (NC is a result, not a failure); 1 a run failed; 2 bad configuration or
// command line (also for CLI11's own parse errors). Configs are found from any directory
// (ground/config/config_dir.hpp); the plan cache lives under -o unless --plan-cache says otherwise.
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "ground/campaign/campaign.hpp"
#include "ground/config/config_dir.hpp"
#include "config/config_error.hpp"
#include "ground/dispersion/cli.hpp"

namespace {

using namespace rocksteady;
using campaign::Strategy;

std::vector<std::string> split(const std::string& s, char sep) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, sep)) {
    if (!item.empty()) out.push_back(item);
  }
  return out;
}

// "1-7", "1,4,7", or file paths (anything ending in .yaml). `option` is the option as the user
// typed it (--case or --cases), named in every error.
std::vector<std::string> case_files(const std::string& spec, const std::string& config_dir,
                                    const std::string& option) {
  std::vector<std::string> files;
  for (const std::string& item : split(spec, ',')) {
    if (item.size() > 5 && item.substr(item.size() - 5) == ".yaml") {
      files.push_back(item);
      continue;
    }
    const std::size_t dash = item.find('-');
    int lo = 0, hi = 0;
    try {
      lo = std::stoi(item.substr(0, dash));
      hi = dash == std::string::npos ? lo : std::stoi(item.substr(dash + 1));
    } catch (const std::exception&) {
      throw CLI::ValidationError(option, "'" + item + "' is not a case number, range or file");
    }
    if (lo < 1 || hi < lo) throw CLI::ValidationError(option, "bad case number or range '" + item + "'");
    for (int n = lo; n <= hi; ++n) {
      try {
        files.push_back(config::case_file(config_dir, std::to_string(n), option));
      } catch (const std::exception& e) {
        throw CLI::ValidationError(option, e.what());
      }
    }
  }
  return files;
}

std::vector<Strategy> strategies(const std::string& spec) {
  std::vector<std::string> names;
  if (spec == "study") {
    names = campaign::study_strategy_names();
  } else if (spec == "all") {
    names = campaign::all_strategy_names();
  } else {
    names = split(spec, ',');
  }
  std::vector<Strategy> out;
  for (const std::string& n : names) {
    const auto s = campaign::parse_strategy(n);
    if (!s) {
      std::string known;
      for (const std::string& k : campaign::all_strategy_names()) known += " " + k;
      throw CLI::ValidationError("--strategy", "unknown strategy '" + n + "' (known:" + known +
                                                   ", or <law>+dpd_ref|fuel_optimal|fuel_optimal_study)");
    }
    out.push_back(*s);
  }
  return out;
}

// A number > 0 (CLI11's PositiveNumber names the whole double range in its message).
const CLI::Validator kPositive(
    [](std::string& v) -> std::string {
      try {
        std::size_t used = 0;
        const double x = std::stod(v, &used);
        if (used == v.size() && x > 0.0 && x < 1e300) return "";
      } catch (const std::exception&) {
      }
      return "must be a number > 0, got '" + v + "'";
    },
    "POSITIVE");

std::string opt_s(const std::optional<double>& v, const char* unit, int d) {
  if (!v) return "NC";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f %s", d, *v, unit);
  return buf;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Rocksteady closed-loop runs and campaigns (plant + flight core in one process)"};
  app.require_subcommand(1);
  app.footer("Exit status (every subcommand): 0 done (NC is a result, not a failure), 1 a run "
             "failed, 2 usage or configuration error.");
  app.fallthrough();  // --config-dir, --mission, --gnc also after the subcommand
  std::string config_dir_arg;
  std::string mission, gnc_file;
  app.add_option("--config-dir", config_dir_arg,
                 "folder with mission.yaml, gnc.yaml, cases/ (default: $ROCKSTEADY_CONFIG_DIR, "
                 "next to the program, or ./configs)");
  app.add_option("--mission", mission, "mission file (default <config-dir>/mission.yaml)");
  app.add_option("--gnc", gnc_file, "GNC file (default <config-dir>/gnc.yaml)");

  campaign::CampaignSpec spec;
  std::string cases_arg = "1-7";
  std::string strategies_arg = "study";
  std::string case_arg = "1";
  std::string strategy_arg = "ntcl+dpd_ref";
  bool no_plots = false, no_series = false, quiet = false, progress = false;
  std::string flight_arg = "app";
  std::string plan_cache = "\x01";  // not given: <out>/plans

  CLI::App* run = app.add_subcommand("run", "one case with one strategy");
  run->add_option("--case", case_arg, "case number or case file")->capture_default_str();
  run->add_option("--strategy", strategy_arg, "e.g. ntcl+dpd_ref, dpd, ntcl+fuel_optimal, ntcl+fuel_optimal_study (study-horizon plan)")
      ->capture_default_str();
  CLI::App* camp = app.add_subcommand("campaign", "cases x strategies, in parallel");
  camp->add_option("--cases", cases_arg, "case numbers, ranges or files: 1-7, 1,4, x.yaml")
      ->capture_default_str();
  camp->add_option("--strategies", strategies_arg, "study (the six), all, or a comma list")
      ->capture_default_str();
  camp->add_option("--jobs,-j", spec.jobs, "worker threads (0: one per core)")->capture_default_str();
  for (CLI::App* sub : {run, camp}) {
    sub->add_option("--out,-o", spec.out_dir, "output folder");
    sub->add_option("--duration", spec.duration_s, "simulated seconds (default: the case's)")
        ->check(kPositive);
    sub->add_option("--log-interval", spec.log_interval_s,
                    "time-series interval, s (default: duration / 5000)")
        ->check(kPositive);
    sub->add_flag("--no-plots", no_plots, "skip the PNG plots");
    sub->add_flag("--no-timeseries", no_series, "skip the time series (and the plots)");
    sub->add_flag("--quiet,-q", quiet, "no progress display");
    sub->add_flag("--progress", progress, "progress display even when not on a terminal");
    sub->add_option("--flight", flight_arg,
                    "app: the flight application through the in-process HAL; core: gnc::Gnc alone")
        ->check(CLI::IsMember({"app", "core"}))
        ->capture_default_str();
    sub->add_option("--replan-latency", spec.replan.latency_s,
                    "replan strategies: planning latency, s (a plan from the state at t is "
                    "activated no earlier than t + latency)")
        ->capture_default_str();
    sub->add_option("--replan-period", spec.replan.period_s,
                    "replan strategies: periodic re-plan, s (0: off)")
        ->capture_default_str();
    sub->add_option("--replan-first", spec.replan.first_plan_s,
                    "replan strategies: identify on the D+PD reference at least this long, s")
        ->capture_default_str();
    sub->add_option("--replan-first-max", spec.replan.first_plan_max_s,
                    "replan strategies: first plan by then even without a confident model, s")
        ->capture_default_str();
    sub->add_option("--replan-horizon", spec.replan.horizon_factor,
                    "replan strategies: plan horizon in shortest despins from the current state (0: "
                    "automatic, 16 when the flight tracks the plan's momentum, 8 on the law's rates)")
        ->capture_default_str();
    sub->add_option("--replan-min-horizon", spec.replan.min_horizon_s,
                    "replan strategies: shortest plan horizon, s")
        ->capture_default_str();
    sub->add_option("--replan-early", spec.replan.early_plan_s,
                    "replan strategies: from then on, plan for the a-priori model as soon as the "
                    "identifier's estimate confirms it, s (0: off)")
        ->capture_default_str();
    sub->add_option("--replan-early-sigmas", spec.replan.early_sigmas,
                    "replan strategies: the early plan's confirmation: within this many 1 sigma")
        ->capture_default_str();
    sub->add_option("--replan-early-j-rel", spec.replan.early_j_rel,
                    "replan strategies: ... with each inertia 1 sigma at most this x |J_hat|")
        ->capture_default_str();
    sub->add_option("--replan-early-r", spec.replan.early_r_m,
                    "replan strategies: ... and each offset 1 sigma at most this, m")
        ->capture_default_str();
    sub->add_option("--replan-refuted-max", spec.replan.refuted_max_s,
                    "replan strategies: when the identifier refutes the a-priori model at "
                    "--replan-first-max, wait for the identified model until then, s")
        ->capture_default_str();
    sub->add_option("--replan-on-identified", spec.replan.on_identified,
                    "replan strategies: re-plan when the identifier's model becomes confident "
                    "(true/false)")
        ->capture_default_str();
    sub->add_option("--replan-adopt-sigmas", spec.replan.adopt_sigmas,
                    "replan strategies: the flight adopts a confident identified model this many "
                    "of its 1 sigma from its table (0: only beyond the confidence bounds)")
        ->capture_default_str();
    sub->add_option("--replan-adopt-wait", spec.replan.adopt_wait_s,
                    "replan strategies: a confident identified model that the flight does not fly "
                    "yet is planned for after its adoption, waiting at most this long, s (0: off)")
        ->capture_default_str();
    sub->add_option("--replan-offset-confident", spec.replan.offset_confident_m,
                    "replan strategies: the flight's offset confidence bound, m (adoption and "
                    "planning once every observable offset direction is within it; 0: the "
                    "flight's identification.offset_confident_m)")
        ->capture_default_str();
    sub->add_option("--replan-slew", spec.replan.slew_s,
                    "replan strategies: after the last plan, the flight turns to q_final rest to "
                    "rest in this time, s (guidance.slew_s; 0: the flight's own setting)")
        ->capture_default_str();
    sub->add_option("--replan-momentum", spec.replan.momentum_k,
                    "replan strategies: the flight tracks the plan's inertial angular momentum "
                    "with this feedback gain, 1/s (guidance.track_momentum_k; 0: the flight's own "
                    "setting)")
        ->capture_default_str();
    sub->add_option("--replan-adopt-settle", spec.replan.adopt_settle_tau,
                    "replan strategies: after the flight adopts a model, no plan for this many "
                    "time constants of its rate stage (the rate estimate relaxes to the new "
                    "model; noisy sensors only; 0: off)")
        ->capture_default_str();
    sub->add_option("--plan-cache", plan_cache,
                    "folder of verified trajectory files reused per model and case (default "
                    "<out>/plans; '' to replan)");
  }
  rocksteady::dispersion::CliState disp;
  rocksteady::dispersion::add_commands(app, disp);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int rc = app.exit(e);
    return rc == 0 ? 0 : 2;  // one convention for every tool: 2 = usage or configuration
  }
  const config::ConfigDir dir = config::find_config_dir(config_dir_arg);
  if (dir.path.empty() && (mission.empty() || gnc_file.empty())) {
    std::cerr << "rocksteady-campaign: " << dir.error << "\n";
    return 2;
  }
  const std::string config_dir = dir.path;
  if (mission.empty()) mission = config_dir + "/mission.yaml";
  if (gnc_file.empty()) gnc_file = config_dir + "/gnc.yaml";
  if (rocksteady::dispersion::parsed(disp)) return rocksteady::dispersion::run(disp, mission, gnc_file);

  spec.use_flight_app = flight_arg == "app";
  spec.mission_file = mission;
  spec.gnc_file = gnc_file;
  spec.write_plots = !no_plots && !no_series;
  spec.write_timeseries = !no_series;
  spec.progress = quiet ? campaign::ProgressMode::kOff
                        : (progress ? campaign::ProgressMode::kOn : campaign::ProgressMode::kAuto);
  const bool single = run->parsed();
  try {
    if (single) {
      spec.case_files = case_files(case_arg, config_dir, "--case");
      spec.strategies = strategies(strategy_arg);
      if (spec.out_dir == "out/campaign") spec.out_dir = "out/run";
      spec.jobs = 1;
    } else {
      spec.case_files = case_files(cases_arg, config_dir, "--cases");
      spec.strategies = strategies(strategies_arg);
    }
  } catch (const CLI::Error& e) {
    app.exit(e);
    return 2;
  }
  if (plan_cache == "\x01") plan_cache = (std::filesystem::path(spec.out_dir) / "plans").string();

  const auto source = campaign::make_default_trajectory_source(plan_cache);
  campaign::CampaignReport rep;
  try {
    rep = campaign::run_campaign(spec, *source, std::cerr);
  } catch (const config::ConfigError& e) {
    std::cerr << "rocksteady-campaign: configuration error: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "rocksteady-campaign: " << e.what() << "\n";
    return 1;
  }

  int failed = 0;
  for (const campaign::RunResult& r : rep.results) {
    if (r.status == campaign::RunStatus::kError) {
      ++failed;
      std::cerr << "run failed: " << r.case_name << " " << r.strategy << ": " << r.note << "\n";
    }
  }
  if (single) {
    const campaign::RunResult& r = rep.results.front();
    std::cout << r.case_name << "  " << r.strategy << "  (" << campaign::to_string(r.status)
              << ")\n";
    if (r.status == campaign::RunStatus::kOk) {
      std::cout << "  t_omega,conv        " << opt_s(r.t_omega_conv_s, "s", 1) << "\n"
                << "  fuel at t_omega     " << opt_s(r.fuel_at_t_omega_kg, "kg", 3) << "\n"
                << "  t_q,conv            " << opt_s(r.t_q_conv_s, "s", 1) << "\n"
                << "  fuel at t_q         " << opt_s(r.fuel_at_t_q_kg, "kg", 3) << "\n"
                << "  total fuel          " << opt_s(r.total_fuel_kg, "kg", 3) << "\n"
                << "  max |omega|         " << opt_s(r.max_rate_rad_s, "rad/s", 5) << "\n"
                << "  final mode          " << r.final_mode << "\n"
                << "  simulated " << r.sim_s << " s in " << opt_s(r.wall_s, "s wall", 2) << "\n";
      if (!r.plot_path.empty()) std::cout << "  plot                " << r.plot_path << "\n";
      if (!r.timeseries_path.empty()) std::cout << "  time series         " << r.timeseries_path << "\n";
    }
    if (!r.note.empty()) std::cout << "  note: " << r.note << "\n";
    for (const campaign::ReplanEvent& e : r.replan.events) {
      std::printf("  plan %-14s from t=%8.1f s, due %8.1f s, delivered %8.1f s: %s%s, %.3f kg over "
                  "%.0f s, %d nodes, %.2f s to solve\n",
                  e.trigger.c_str(), e.t_state_s, e.t_due_s, e.t_delivered_s,
                  e.ok ? "ok" : "failed: ", e.ok ? "" : e.error.c_str(), e.planned_fuel_kg,
                  e.t_final_s, e.nodes, e.wall_s);
    }
  } else {
    std::ifstream table(rep.results_md);
    std::cout << table.rdbuf() << "\n";
    std::cout << "results: " << rep.results_csv << " (and " << rep.results_json << ")\n"
              << "table:   " << rep.results_md << "\n"
              << "runs:    " << rep.runs_csv << "\n";
  }
  std::cout << campaign::benchmark_line(rep) << "\n";
  return failed > 0 ? 1 : 0;
}
