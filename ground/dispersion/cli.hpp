// The dispersion subcommands of rocksteady-campaign: `dispersion`, `collect` and the Slurm array
// task's `dispersion-worker` (hidden).
#pragma once

#include <string>

#include <CLI/CLI.hpp>

namespace rocksteady::dispersion {

struct CliState {
  CLI::App* dispersion{nullptr};
  CLI::App* collect{nullptr};
  CLI::App* worker{nullptr};
  std::string file;
  std::string out_dir;
  int draw{-1};
  std::string backend{"local"};
  int jobs{0};
  int shards{0};
  int max_parallel{0};
  std::string partition, account, time_limit, sbatch_extra;
  bool no_wait{false};
  bool no_plots{false};
  int shard{0};
};

void add_commands(CLI::App& app, CliState& s);
bool parsed(const CliState& s);
// Runs the parsed subcommand. Exit status: 0 done; 1 a run failed or draws are missing; 2 bad
// input.
int run(const CliState& s, const std::string& mission_file, const std::string& gnc_file);

}  // namespace rocksteady::dispersion
