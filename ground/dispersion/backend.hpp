// Where the draws run. Local: every draw in its own forked process, `jobs` at a time, each result
// written atomically, so a killed campaign restarts with only the missing draws (and a process that
// dies is a recorded "crashed" result, never a lost one). Slurm: the missing draws are sharded over
// an `sbatch --array` job whose tasks run the same worker; `collect` merges. Both back ends write
// the same per-draw files, so their merged results are identical byte for byte.
#pragma once

#include <iosfwd>
#include <string>
#include <vector>

#include "config/config_files.hpp"
#include "ground/dispersion/draw.hpp"
#include "ground/dispersion/spec.hpp"

namespace rocksteady::dispersion {

struct Inputs {
  std::string spec_file, mission_file, gnc_file;  // absolute
  DispersionSpec spec;
  config::MissionConfig mission;
  config::GncConfig gnc;
  std::string fingerprint;  // of the three files' contents
};
Inputs load_inputs(const std::string& spec_file, const std::string& mission_file,
                   const std::string& gnc_file);

// <dir>/manifest.json names the inputs; a folder holding another dispersion is refused.
void write_or_check_manifest(const std::string& dir, const Inputs& in);
Inputs inputs_from_manifest(const std::string& dir);

std::vector<int> missing_draws(const std::string& dir, int draws);

struct LocalStats {
  int ran{0};
  int crashed{0};
  double wall_s{0.0};
  double simulated_s{0.0};
  double closed_loop_s{0.0};  // summed over the workers: the closed loops alone
  double plan_s{0.0};         // summed over the workers: planning
  int jobs{1};
};
LocalStats run_local(const Inputs& in, const std::string& dir, const std::vector<int>& draws,
                     int jobs, std::ostream& log);

struct SlurmOptions {
  int shards{0};        // array tasks (0: min(draws, 64))
  int max_parallel{0};  // "%N" array throttle (0: none)
  std::string partition;
  std::string account;
  std::string time_limit;  // e.g. 02:00:00
  std::string extra;       // more sbatch options, verbatim
  bool wait{true};         // sbatch --wait, then collect here
};
// Submits the array job (and, without wait, a dependent collect job). Returns sbatch's exit status.
int submit_slurm(const Inputs& in, const std::string& dir, const std::vector<int>& draws,
                 const SlurmOptions& o, std::ostream& log);
// One array task: the draws listed for `shard` in <dir>/slurm/draws.txt.
int run_shard(const std::string& dir, int shard, int shards, std::ostream& log);

// The fault-free references of a fault dispersion over study cases (one per case, read from
// <dir>/reference/, flown here when missing); empty for any other dispersion.
std::vector<DrawResult> references(const Inputs& in, const std::string& dir, std::ostream& log);

// Merges every draw file (and the fault-free references) and writes the outputs; returns the
// number of draws missing.
int collect(const std::string& dir, std::ostream& out, bool plots = true);

std::string self_exe();
std::string reproduce_command(const Inputs& in, const std::string& dir);

}  // namespace rocksteady::dispersion
