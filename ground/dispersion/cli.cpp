#include "ground/dispersion/cli.hpp"

#include <filesystem>
#include <fstream>
#include <iostream>

#include "ground/campaign/campaign.hpp"
#include "ground/dispersion/backend.hpp"
#include "ground/dispersion/draw.hpp"

namespace rocksteady::dispersion {

namespace fs = std::filesystem;

void add_commands(CLI::App& app, CliState& s) {
  s.dispersion = app.add_subcommand(
      "dispersion",
      "Monte Carlo over a dispersion file (configs/dispersions/*.yaml): each draw a pure function "
      "of (master seed, draw index); all strategies flown through the flight application; plans "
      "shared per draw. Writes <out>/draws/NNNNNN.json (one per draw, atomically; a restart runs "
      "only the missing draws), then results.csv, summary.json, report.md and plots/. "
      "--draw N re-flies one draw bit for bit with its time series and plots.");
  s.dispersion->footer(
      "Mission and GNC files: --config-dir, --mission, --gnc (as for `campaign`). Slurm: sbatch "
      "must "
      "reach the cluster (SLURM_CONF); the output folder, the files and this binary must be on a "
      "file system the nodes share. Exit status: 0 done, 1 failed or missing draws, 2 bad input. "
      "Details: ground/dispersion/README.md.");
  s.dispersion->add_option("file", s.file, "dispersion file")->required()->check(CLI::ExistingFile);
  s.dispersion->add_option("--out,-o", s.out_dir, "output folder (default out/dispersion/<name>)");
  s.dispersion->add_option("--draw", s.draw, "re-fly this draw only, with time series and plots");
  s.dispersion
      ->add_option("--backend", s.backend,
                   "local: forked processes on this machine; "
                   "slurm: an sbatch --array job")
      ->check(CLI::IsMember({"local", "slurm"}))
      ->capture_default_str();
  s.dispersion->add_option("--jobs,-j", s.jobs, "local: parallel draws (0: one per core)")
      ->capture_default_str();
  s.dispersion->add_option("--shards", s.shards, "slurm: array tasks (0: min(draws, 64))");
  s.dispersion->add_option("--max-parallel", s.max_parallel,
                           "slurm: array throttle, at most N tasks at once (0: no limit)");
  s.dispersion->add_option("--partition", s.partition, "slurm: partition");
  s.dispersion->add_option("--account", s.account, "slurm: account");
  s.dispersion->add_option("--time", s.time_limit, "slurm: time limit per task, e.g. 02:00:00");
  s.dispersion->add_option("--sbatch-args", s.sbatch_extra, "slurm: more sbatch options, verbatim");
  s.dispersion->add_flag("--no-wait", s.no_wait,
                         "slurm: submit and return; a dependent job runs `collect`");
  s.dispersion->add_flag("--no-plots", s.no_plots, "skip the gnuplot plots");

  s.collect = app.add_subcommand("collect",
                                 "merge a dispersion folder's draws and write the "
                                 "statistics (results.csv, summary.json, report.md, plots)");
  s.collect->add_option("dir", s.out_dir, "dispersion output folder")->required();
  s.collect->add_flag("--no-plots", s.no_plots, "skip the gnuplot plots");

  s.worker = app.add_subcommand("dispersion-worker", "");  // hidden: one Slurm array task
  s.worker->group("");
  s.worker->add_option("dir", s.out_dir, "dispersion output folder")->required();
  s.worker->add_option("--shard", s.shard, "this task's shard")->required();
  s.worker->add_option("--shards", s.shards, "number of shards")->required();
}

bool parsed(const CliState& s) {
  return (s.dispersion != nullptr && s.dispersion->parsed()) ||
         (s.collect != nullptr && s.collect->parsed()) ||
         (s.worker != nullptr && s.worker->parsed());
}

namespace {

int refly(const Inputs& in, const std::string& dir, int index) {
  if (index < 0 || index >= in.spec.draws) {
    std::cerr << "rocksteady-campaign: --draw " << index << ": the dispersion has draws 0.."
              << in.spec.draws - 1 << "\n";
    return 2;
  }
  const Sampler sampler(in.spec, in.mission);
  const auto planner = campaign::make_default_trajectory_source("");
  std::vector<campaign::RunResult> runs;
  FlyOptions opt;
  opt.log_interval_s = in.spec.duration_s / 5000.0;
  opt.full_runs = &runs;
  const DrawResult r = fly_draw(in.mission, in.gnc, in.spec, sampler, index, *planner, opt);
  const fs::path out = fs::path(dir) / ("draw-" + std::to_string(index));
  fs::create_directories(out);
  {
    std::ofstream f(out / "result.json");
    f << to_json(r).dump(1) << "\n";
  }
  std::cout << "draw " << index << " of " << in.spec.name << " (seed " << r.sampled.seed
            << "), ||dJ|| " << r.sampled.delta_j_norm << " kg m^2, ||dr|| "
            << r.sampled.delta_r_norm << " m, |omega0| " << r.sampled.initial_rate_norm
            << " rad/s, u_max " << r.sampled.u_max_n << " N\n";
  if (r.planned) std::cout << "  plan: " << r.plan_note << "\n";
  for (std::size_t k = 0; k < r.runs.size(); ++k) {
    const StrategyOutcome& o = r.runs[k];
    std::cout << "  " << o.strategy << ": " << o.status << (o.success ? " success" : "");
    if (o.total_fuel_kg) std::cout << ", fuel " << *o.total_fuel_kg << " kg";
    std::cout << ", t_omega " << (o.t_omega_conv_s ? std::to_string(*o.t_omega_conv_s) : "NC")
              << ", t_q " << (o.t_q_conv_s ? std::to_string(*o.t_q_conv_s) : "NC");
    if (!o.note.empty()) std::cout << "  (" << o.note << ")";
    std::cout << "\n";
    if (k < runs.size() && runs[k].status == campaign::RunStatus::kOk) {
      const fs::path rd = out / o.strategy;
      campaign::write_timeseries_csv((rd / "timeseries.csv").string(), runs[k]);
      std::string err;
      if (campaign::write_plot(rd.string(), runs[k], err)) {
        std::cout << "    " << (rd / "plot.png").string() << "\n";
      } else {
        std::cout << "    " << err << "\n";
      }
    }
  }
  if (const auto stored = read_draw(dir, index)) {
    const bool same = to_json(*stored, false) == to_json(r, false);
    std::cout << "stored result " << draw_path(dir, index) << ": "
              << (same ? "identical (bit for bit)" : "DIFFERENT") << "\n";
    if (!same) return 1;
  }
  return 0;
}

}  // namespace

int run(const CliState& s, const std::string& mission_file, const std::string& gnc_file) {
  try {
    if (s.worker->parsed()) return run_shard(s.out_dir, s.shard, s.shards, std::cerr);
    if (s.collect->parsed()) return collect(s.out_dir, std::cout, !s.no_plots) > 0 ? 1 : 0;
    const Inputs in = load_inputs(s.file, mission_file, gnc_file);
    const std::string dir = s.out_dir.empty() ? "out/dispersion/" + in.spec.name : s.out_dir;
    write_or_check_manifest(dir, in);
    if (s.draw >= 0) return refly(in, dir, s.draw);
    const std::vector<int> todo = missing_draws(dir, in.spec.draws);
    std::cerr << "[dispersion] " << in.spec.name << ": " << in.spec.draws << " draws, "
              << (in.spec.draws - static_cast<int>(todo.size())) << " already done, running "
              << todo.size() << " (" << s.backend << ")\n";
    if (s.backend == "slurm") {
      SlurmOptions o;
      o.shards = s.shards;
      o.max_parallel = s.max_parallel;
      o.partition = s.partition;
      o.account = s.account;
      o.time_limit = s.time_limit;
      o.extra = s.sbatch_extra;
      o.wait = !s.no_wait;
      const int rc = submit_slurm(in, dir, todo, o, std::cerr);
      if (rc != 0 || !o.wait) return rc == 0 ? 0 : 1;
    } else {
      const LocalStats st = run_local(in, dir, todo, s.jobs, std::cerr);
      if (st.ran > 0) {
        std::cerr << "[dispersion] ran " << st.ran << " draws in " << st.wall_s
                  << " s wall: " << st.simulated_s << " simulated s, "
                  << (st.wall_s > 0 ? st.simulated_s / st.wall_s : 0.0)
                  << " simulated s per wall s (planning included); closed loops alone "
                  << (st.closed_loop_s > 0 ? st.simulated_s / st.closed_loop_s * st.jobs : 0.0)
                  << " simulated s per wall s on " << st.jobs << " workers; planning " << st.plan_s
                  << " worker-s"
                  << (st.crashed > 0 ? ", " + std::to_string(st.crashed) + " crashed" : "") << "\n";
      }
    }
    return collect(dir, std::cout, !s.no_plots) > 0 ? 1 : 0;
  } catch (const config::ConfigError& e) {
    std::cerr << "rocksteady-campaign: configuration error: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "rocksteady-campaign: " << e.what() << "\n";
    return 1;
  }
}

}  // namespace rocksteady::dispersion
