// rocksteady-plan: plans the fuel-optimal despin (SPEC Eq. 44) for a study case's estimated model
// and writes the reference-trajectory file. Failure to converge or to verify is an error exit,
// never a file.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cstdio>
#include <exception>
#include <string>

#include "gnc/model/mass_properties.hpp"
#include "gnc/model/rcs.hpp"
#include "ground/planner/cache.hpp"
#include "ground/planner/planner.hpp"
#include "ground/planner/trajectory_file.hpp"
#ifdef ROCKSTEADY_PLANNER_WITH_CONFIG
#include "ground/config/config.hpp"
#include "ground/config/config_dir.hpp"
#endif

namespace planner = rocksteady::ground::planner;

namespace {

void report(const planner::PlanResult& r) {
  const planner::Verification& v = r.verification;
  std::printf("fuel            %.4f kg  (int |u|_1 dt = %.1f N s)\n", r.fuel_kg, r.cost_ns);
  std::printf("t_final         %.2f s  (range [%.2f, %.2f] s)\n", r.t_final, r.t_final_min,
              r.t_final_max);
  std::printf("grid            %d nodes, %zu samples (Hermite-Simpson)\n", r.nodes,
              r.samples.size());
  if (r.t_active < r.t_final) {
    std::printf("despin          until %.2f s, at rest after it\n", r.t_active);
  }
  std::printf("iterations      %d\n", r.iterations);
  std::printf("solve time      %.3f s\n", r.solve_seconds);
  std::printf("max defect      %.3g rad/s\n", v.max_defect);
  std::printf("open loop       max error %.3g rad/s, final rate %.3g rad/s\n", v.propagation_error,
              v.propagated_final_rate);
  if (v.refinement_checked) {
    std::printf("grid check      %.4f kg on %d nodes (change %.4f %%), %d iterations, %.3f s\n",
                v.refined_fuel_kg, v.refined_nodes, 100.0 * v.refinement_change,
                v.refined_iterations, v.refined_seconds);
  }
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "Plan the fuel-optimal despin (SPEC Eq. 44) for the estimated model of a study case"};
  double u_max = 200.0;
  double delta_j = 0.0;
  double delta_r = 0.0;
  std::string case_name = "custom";
  std::string output;
  std::string cache_dir;
  std::string check_file;
  std::string mission_file;
  std::string gnc_file;
  std::string case_file;
  std::string config_dir;
  bool no_refinement = false;
  bool tumble_grid = false;
  bool verbose = false;
  planner::PlanSettings settings;
  app.add_option("--u-max", u_max, "per-channel force limit u_max (N), SPEC Table 3")
      ->check(CLI::PositiveNumber);
  app.add_option("--delta-j", delta_j,
                 "||dJ_ast||_2 (kg m^2): J_ast_hat = J_ast - dJ diag(-1,1,0.5)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--delta-r", delta_r, "||dr_SO/BCM||_2 (m): r_hat = r - dr [1,1,1]/sqrt(3)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--case-name", case_name, "case name recorded in the file");
  app.add_flag("--tumble-grid", tumble_grid,
               "tumble-following grid with mesh refinement instead of the uniform one");
  app.add_option("--intervals-per-turn", settings.intervals_per_turn,
                 "tumble grid: intervals per turn of the body")
      ->check(CLI::PositiveNumber);
  app.add_option("--nodes", settings.nodes, "grid nodes N (2N-1 samples; 0 = automatic)")
      ->check(CLI::Validator(
          [](std::string& v) -> std::string {
            try {
              const int n = std::stoi(v);
              if (n == 0 || (n >= 3 && n <= 512)) return "";
            } catch (const std::exception&) {
            }
            return "must be 0 (automatic) or in [3, 512]";
          },
          "0|3..512"));
  app.add_option("--t-final-max", settings.t_final_max,
                 "final time (fixed) or its upper bound (free), s; default 8x the shortest despin");
  app.add_option("--t-final-min", settings.t_final_min, "lower bound of a free final time, s");
  bool study_horizon = false;
  app.add_flag("--study-horizon", study_horizon,
               "final time like the study's fuel-optimal trackers (44000 s)");
  app.add_option("--active-horizon", settings.active_horizon_max,
                 "longest despin, s: a longer final time rests after it (0 = automatic, "
                 "max(5600 s, the automatic horizon); < 0 = plan every horizon in full)");
  app.add_flag("--free-final-time", settings.free_final_time, "let t_f float in [min, max]");
  app.add_option("--tolerance", settings.tolerance, "IPOPT convergence tolerance (scaled NLP)")
      ->check(CLI::PositiveNumber);
  app.add_flag("--no-refinement", no_refinement, "skip the grid-convergence check");
  std::string refinement_check = "coarsen";
  app.add_option("--refinement-check", refinement_check,
                 "grid-convergence check: coarsen (re-solve on every other node) or bisect "
                 "(every interval halved)")
      ->check(CLI::IsMember({"coarsen", "bisect"}));
  settings.jobs = 0;
  app.add_option("--jobs", settings.jobs,
                 "long horizons: candidate despins solved in this many worker processes at once "
                 "(0 = one per hardware thread, 1 = in this process)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("-o,--output", output, "trajectory file to write");
  app.add_option("--cache-dir", cache_dir,
                 "plan-once cache directory (file named by problem hash)");
  app.add_option("--check", check_file, "load and verify an existing trajectory file instead");
  app.add_flag("-v,--verbose", verbose, "IPOPT iteration log");
#ifdef ROCKSTEADY_PLANNER_WITH_CONFIG
  app.add_option(
      "--case", case_file,
      "study case N (<config dir>/cases/caseN.yaml) or a case file: the model comes from "
      "the configuration");
  app.add_option("--config-dir", config_dir,
                 "folder with mission.yaml, gnc.yaml, cases/ (default: $ROCKSTEADY_CONFIG_DIR, "
                 "else next to this program, else ./configs)");
  app.add_option("--mission", mission_file, "mission YAML (default: <config dir>/mission.yaml)");
  app.add_option("--gnc", gnc_file, "GNC YAML (default: <config dir>/gnc.yaml)");
#endif
  app.footer(
      "Exit status: 0 planned (or --check: valid), 1 the run failed (no converged, verified plan; "
      "--check: rejected), 2 usage or configuration error.");
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    app.exit(e);
    return 2;
  }
  settings.verify_refinement = !no_refinement;
  settings.refinement_check = refinement_check == "bisect"
                                  ? planner::PlanSettings::RefinementCheck::kBisect
                                  : planner::PlanSettings::RefinementCheck::kCoarsen;
  settings.tumble_grid = tumble_grid;
  if (study_horizon) {
    if (settings.t_final_max > 0.0) {
      std::fprintf(stderr, "error: --study-horizon and --t-final-max both set the final time\n");
      return 2;
    }
    settings.t_final_max = planner::kStudyHorizon;
  }
  if (verbose) settings.print_level = 5;

  planner::PlanProblem problem;
  problem.case_name = case_name;
  problem.settings = settings;
  try {
    if (!case_file.empty() || !mission_file.empty() || !gnc_file.empty()) {
#ifdef ROCKSTEADY_PLANNER_WITH_CONFIG
      if (case_file.empty()) {
        std::fprintf(stderr, "error: %s needs --case (the case whose model is planned)\n",
                     mission_file.empty() ? "--gnc" : "--mission");
        return 2;
      }
      const bool need_dir = mission_file.empty() || gnc_file.empty() ||
                            std::all_of(case_file.begin(), case_file.end(), ::isdigit);
      std::string dir;
      if (need_dir) {
        const rocksteady::config::ConfigDir d = rocksteady::config::find_config_dir(config_dir);
        if (d.path.empty()) {
          std::fprintf(stderr, "error: %s\n", d.error.c_str());
          return 2;
        }
        dir = d.path;
      }
      case_file = rocksteady::config::case_file(dir, case_file, "--case");
      if (mission_file.empty()) mission_file = rocksteady::config::mission_file(dir);
      if (gnc_file.empty()) gnc_file = rocksteady::config::gnc_file(dir);
      const auto mission = rocksteady::config::load_mission(mission_file);
      const auto run = rocksteady::config::assemble(mission, rocksteady::config::load_gnc(gnc_file),
                                                    rocksteady::config::load_case(case_file));
      problem.case_name = run.case_name;
      problem.model.j_hat = rocksteady::gnc::total_inertia(run.flight.mass_hat);
      problem.model.b_hat =
          rocksteady::gnc::torque_matrix(run.flight.rcs, run.flight.mass_hat.r_so_bcm);
      problem.model.u_max = run.flight.rcs.u_max;
      problem.model.eps_trans = run.flight.guidance.eps_trans;
      problem.model.omega_init = mission.initial_omega;
#endif
    } else {
      problem.model = planner::study_case_model(u_max, delta_j, delta_r);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 2;
  }

  if (!check_file.empty()) {
    const planner::LoadResult loaded = planner::load_trajectory_file(check_file, problem.model);
    if (!loaded.ok) {
      std::fprintf(stderr, "rejected: %s\n", loaded.error.c_str());
      return 1;
    }
    std::printf("%s: valid plan for case '%s': fuel %.4f kg, t_final %.2f s, %zu samples\n",
                check_file.c_str(), loaded.file.case_name.c_str(), loaded.file.fuel_kg,
                loaded.file.t_final, loaded.file.samples.size());
    return 0;
  }

  if (!cache_dir.empty()) {
    const planner::CachedPlan c = planner::plan_cached(problem, cache_dir);
    if (!c.note.empty()) std::printf("note: %s\n", c.note.c_str());
    if (!c.ok) {
      std::fprintf(stderr, "error: %s\n", c.error.c_str());
      return 1;
    }
    std::printf("%s %s: fuel %.4f kg, t_final %.2f s, %d iterations, %.3f s\n",
                c.from_cache ? "cached" : "planned", c.path.c_str(), c.file.fuel_kg, c.file.t_final,
                c.file.iterations, c.file.solve_seconds);
    return 0;
  }
  if (output.empty()) {
    std::fprintf(stderr, "error: give -o FILE or --cache-dir DIR\n");
    return 2;
  }
  const planner::PlanResult result = planner::plan(problem);
  if (!result.ok) {
    std::fprintf(stderr, "error: case '%s': %s (no file written)\n", problem.case_name.c_str(),
                 result.error.c_str());
    return 1;
  }
  report(result);
  try {
    planner::write_trajectory_file(output, problem, result);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  }
  std::printf("wrote %s\n", output.c_str());
  return 0;
}
