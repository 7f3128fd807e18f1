#include "ground/dispersion/backend.hpp"

#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <ostream>
#include <sstream>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "ground/campaign/trajectory_source.hpp"
#include "ground/dispersion/draw.hpp"
#include "ground/dispersion/stats.hpp"

namespace rocksteady::dispersion {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

using Clock = std::chrono::steady_clock;

std::string read_all(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw config::ConfigError(path, "", "cannot read file");
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::string fnv1a(const std::string& s) {
  std::uint64_t h = 0xcbf29ce484222325ULL;
  for (unsigned char c : s) {
    h ^= c;
    h *= 0x100000001b3ULL;
  }
  char buf[20];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h));
  return buf;
}

std::string quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) {
    if (c == '\'') {
      q += "'\\''";
    } else {
      q += c;
    }
  }
  return q + "'";
}

// One draw in this process: fly, write atomically.
void fly_and_write(const Inputs& in, const Sampler& sampler, const std::string& dir, int index) {
  const auto planner = campaign::make_default_trajectory_source("");
  DrawResult r;
  try {
    r = fly_draw(in.mission, in.gnc, in.spec, sampler, index, *planner);
  } catch (const std::exception& e) {
    r = crashed_draw(in.spec, sampler, index, std::string("exception: ") + e.what());
  }
  write_draw(dir, r);
}

}  // namespace

std::string self_exe() {
  return fs::read_symlink("/proc/self/exe").string();
}

Inputs load_inputs(const std::string& spec_file, const std::string& mission_file,
                   const std::string& gnc_file) {
  Inputs in;
  in.spec_file = fs::absolute(spec_file).lexically_normal().string();
  in.mission_file = fs::absolute(mission_file).lexically_normal().string();
  in.gnc_file = fs::absolute(gnc_file).lexically_normal().string();
  in.spec = load_spec(spec_file);
  in.mission = config::load_mission(mission_file);
  in.gnc = config::load_gnc(gnc_file);
  in.fingerprint =
      fnv1a(read_all(spec_file) + "\x1f" + read_all(mission_file) + "\x1f" + read_all(gnc_file));
  return in;
}

void write_or_check_manifest(const std::string& dir, const Inputs& in) {
  const fs::path p = fs::path(dir) / "manifest.json";
  if (fs::exists(p)) {
    std::ifstream f(p);
    json j;
    try {
      j = json::parse(f);
    } catch (const std::exception& e) {
      throw std::runtime_error(p.string() + ": unreadable manifest: " + e.what());
    }
    if (j.value("fingerprint", "") != in.fingerprint) {
      throw std::runtime_error(dir + " holds the results of another dispersion (" +
                               j.value("spec_file", "?") +
                               ", or its files changed); use another -o folder");
    }
    return;
  }
  fs::create_directories(dir);
  json j = {
      {"name", in.spec.name},    {"spec_file", in.spec_file},     {"mission_file", in.mission_file},
      {"gnc_file", in.gnc_file}, {"fingerprint", in.fingerprint}, {"draws", in.spec.draws}};
  const std::string tmp = p.string() + ".tmp";
  {
    std::ofstream out(tmp);
    out << j.dump(2) << "\n";
  }
  fs::rename(tmp, p);
  fs::copy_file(in.spec_file, fs::path(dir) / "dispersion.yaml",
                fs::copy_options::overwrite_existing);
}

Inputs inputs_from_manifest(const std::string& dir) {
  const fs::path p = fs::path(dir) / "manifest.json";
  std::ifstream f(p);
  if (!f) throw std::runtime_error(p.string() + ": no manifest (not a dispersion output folder)");
  const json j = json::parse(f);
  Inputs in =
      load_inputs(j.at("spec_file").get<std::string>(), j.at("mission_file").get<std::string>(),
                  j.at("gnc_file").get<std::string>());
  if (in.fingerprint != j.at("fingerprint").get<std::string>()) {
    throw std::runtime_error(p.string() + ": the dispersion's input files changed since the run");
  }
  return in;
}

std::vector<int> missing_draws(const std::string& dir, int draws) {
  std::vector<int> out;
  for (int i = 0; i < draws; ++i) {
    if (!fs::exists(draw_path(dir, i))) out.push_back(i);
  }
  return out;
}

LocalStats run_local(const Inputs& in, const std::string& dir, const std::vector<int>& draws,
                     int jobs, std::ostream& log) {
  LocalStats st;
  const Sampler sampler(in.spec, in.mission);
  if (jobs <= 0) {
    const long n = sysconf(_SC_NPROCESSORS_ONLN);
    jobs = n > 0 ? static_cast<int>(n) : 1;
  }
  st.jobs = jobs;
  const auto t0 = Clock::now();
  std::map<pid_t, int> running;
  std::size_t next = 0;
  int done = 0;
  log.flush();
  auto reap = [&](pid_t pid, int status) {
    const int index = running.at(pid);
    running.erase(pid);
    ++done;
    if (!fs::exists(draw_path(dir, index))) {
      std::string why = WIFSIGNALED(status)
                            ? "process killed by signal " + std::to_string(WTERMSIG(status))
                            : "process exited with status " + std::to_string(WEXITSTATUS(status)) +
                                  " without a result";
      write_draw(dir, crashed_draw(in.spec, sampler, index, why));
      ++st.crashed;
    }
    if (auto r = read_draw(dir, index)) {
      for (const StrategyOutcome& o : r->runs) {
        st.simulated_s += o.sim_s;
        st.closed_loop_s += o.wall_s;
      }
      st.plan_s += r->plan_wall_s;
    }
    log << "[dispersion] " << done << "/" << draws.size() << " draws\n" << std::flush;
  };
  while (next < draws.size() || !running.empty()) {
    while (next < draws.size() && static_cast<int>(running.size()) < jobs) {
      const int index = draws[next++];
      std::fflush(nullptr);
      const pid_t pid = fork();
      if (pid < 0) throw std::runtime_error("fork failed");
      if (pid == 0) {
        int rc = 0;
        try {
          fly_and_write(in, sampler, dir, index);
        } catch (...) {
          rc = 3;
        }
        std::fflush(nullptr);
        _exit(rc);
      }
      running[pid] = index;
      ++st.ran;
    }
    int status = 0;
    const pid_t pid = waitpid(-1, &status, 0);
    if (pid < 0) break;
    if (running.count(pid) != 0) reap(pid, status);
  }
  st.wall_s = std::chrono::duration<double>(Clock::now() - t0).count();
  return st;
}

int submit_slurm(const Inputs& in, const std::string& dir, const std::vector<int>& draws,
                 const SlurmOptions& o, std::ostream& log) {
  const fs::path sd = fs::absolute(fs::path(dir) / "slurm");
  fs::create_directories(sd);
  if (draws.empty()) return 0;
  int shards = o.shards > 0 ? o.shards : std::min<int>(static_cast<int>(draws.size()), 64);
  shards = std::min<int>(shards, static_cast<int>(draws.size()));
  {
    std::ofstream f(sd / "draws.txt");
    for (int d : draws) f << d << "\n";
  }
  const std::string exe = self_exe();
  const std::string adir = fs::absolute(dir).string();
  std::ostringstream script;
  script << "#!/bin/bash\n"
         << "# Rocksteady dispersion '" << in.spec.name << "': one array task per shard.\n"
         << "#SBATCH --job-name=rs-" << in.spec.name << "\n"
         << "#SBATCH --output=" << (sd / "task-%A_%a.out").string() << "\n"
         << "#SBATCH --array=0-" << (shards - 1)
         << (o.max_parallel > 0 ? "%" + std::to_string(o.max_parallel) : "") << "\n"
         << "#SBATCH --ntasks=1\n#SBATCH --cpus-per-task=1\n";
  if (!o.partition.empty()) script << "#SBATCH --partition=" << o.partition << "\n";
  if (!o.account.empty()) script << "#SBATCH --account=" << o.account << "\n";
  if (!o.time_limit.empty()) script << "#SBATCH --time=" << o.time_limit << "\n";
  script << "exec " << quote(exe) << " dispersion-worker " << quote(adir)
         << " --shard \"$SLURM_ARRAY_TASK_ID\" --shards " << shards << "\n";
  const fs::path sp = sd / "array.sbatch";
  {
    std::ofstream f(sp);
    f << script.str();
  }
  std::string cmd = "sbatch --parsable " + std::string(o.wait ? "--wait " : "") + o.extra + " " +
                    quote(sp.string());
  log << "[dispersion] " << draws.size() << " draws in " << shards << " array tasks: " << cmd
      << "\n"
      << std::flush;
  const auto t0 = Clock::now();
  FILE* p = popen(cmd.c_str(), "r");
  if (p == nullptr) throw std::runtime_error("cannot run sbatch");
  std::string job;
  char buf[256];
  while (std::fgets(buf, sizeof buf, p) != nullptr) job += buf;
  const int status = pclose(p);
  while (!job.empty() && (job.back() == '\n' || job.back() == '\r')) job.pop_back();
  const double wall = std::chrono::duration<double>(Clock::now() - t0).count();
  const int rc = WIFEXITED(status) ? WEXITSTATUS(status) : 1;
  log << "[dispersion] slurm job " << job << (o.wait ? " finished" : " submitted")
      << " (sbatch exit " << rc << ", " << wall << " s)\n";
  if (!o.wait && rc == 0) {
    const std::string dep =
        "sbatch --parsable --dependency=afterany:" + job.substr(0, job.find(';')) +
        " --job-name=rs-collect --output=" + quote((sd / "collect-%j.out").string()) +
        (o.partition.empty() ? "" : " --partition=" + o.partition) +
        (o.account.empty() ? "" : " --account=" + o.account) + " --wrap " +
        quote(quote(exe) + " collect " + quote(adir));
    log << "[dispersion] collect after the array: " << dep << "\n";
    return std::system(dep.c_str()) == 0 ? 0 : 1;
  }
  return rc;
}

int run_shard(const std::string& dir, int shard, int shards, std::ostream& log) {
  const Inputs in = inputs_from_manifest(dir);
  std::ifstream f(fs::path(dir) / "slurm" / "draws.txt");
  if (!f) throw std::runtime_error(dir + "/slurm/draws.txt: missing");
  std::vector<int> mine;
  int d = 0;
  for (int i = 0; f >> d; ++i) {
    if (i % shards == shard && !fs::exists(draw_path(dir, d))) mine.push_back(d);
  }
  log << "[dispersion] shard " << shard << "/" << shards << ": " << mine.size() << " draws\n";
  const LocalStats st = run_local(in, dir, mine, 1, log);
  return st.crashed > 0 ? 1 : 0;
}

std::string reproduce_command(const Inputs& in, const std::string& dir) {
  std::string c = "rocksteady-campaign dispersion " + in.spec_file + " --mission " +
                  in.mission_file + " --gnc " + in.gnc_file + " -o " +
                  fs::absolute(dir).lexically_normal().string();
  return c;
}

std::vector<DrawResult> references(const Inputs& in, const std::string& dir, std::ostream& log) {
  std::vector<DrawResult> refs;
  const FaultPlan& fp = in.spec.faults;
  if (!fp.enabled || fp.case_files.empty()) return refs;
  const Sampler sampler(in.spec, in.mission);
  for (std::size_t c = 0; c < fp.case_files.size(); ++c) {
    if (auto stored = read_reference(dir, fp.case_numbers[c])) {
      refs.push_back(std::move(*stored));
      continue;
    }
    const std::optional<DrawParams> p = reference_params(in.spec, sampler, c);
    if (!p) continue;  // no draw flies this case (fewer draws than the grid)
    log << "[dispersion] fault-free reference of case " << fp.case_numbers[c] << "\n";
    const auto planner = campaign::make_default_trajectory_source("");
    DrawResult r = fly_reference(in.mission, in.gnc, in.spec, *p, *planner);
    write_reference(dir, r);
    refs.push_back(std::move(r));
  }
  return refs;
}

int collect(const std::string& dir, std::ostream& out, bool plots) {
  const Inputs in = inputs_from_manifest(dir);
  std::vector<DrawResult> draws;
  int missing = 0;
  for (int i = 0; i < in.spec.draws; ++i) {
    auto r = read_draw(dir, i);
    if (r) {
      draws.push_back(std::move(*r));
    } else {
      ++missing;
    }
  }
  const Summary s = summarize(in.spec, draws, references(in, dir, out));
  const OutputPaths p = write_outputs(dir, in.spec, draws, s, reproduce_command(in, dir), plots);
  out << "results: " << p.results_csv << "\nsummary: " << p.summary_json
      << "\nreport:  " << p.report_md << "\n";
  for (const StrategyStats& st : s.strategies) {
    char buf[256];
    std::snprintf(
        buf, sizeof buf,
        "  %-24s success %3d/%-3d (%5.1f %%, 95%% CI %.1f-%.1f %%)  fuel p50 %s p95 %s kg\n",
        st.strategy.c_str(), st.successes, st.draws, 100.0 * st.success_rate,
        100.0 * st.wilson.first, 100.0 * st.wilson.second,
        st.fuel.p50 ? std::to_string(*st.fuel.p50).c_str() : "-",
        st.fuel.p95 ? std::to_string(*st.fuel.p95).c_str() : "-");
    out << buf;
  }
  for (const Crossover& c : s.crossovers) {
    out << "  crossover " << c.a << " vs " << c.b << ": "
        << (c.crossover_kg_m2 ? std::to_string(*c.crossover_kg_m2) + " kg m^2" : "none in range")
        << "\n";
  }
  if (missing > 0)
    out << "missing draws: " << missing << " (run the dispersion again to fill them)\n";
  return missing;
}

}  // namespace rocksteady::dispersion
