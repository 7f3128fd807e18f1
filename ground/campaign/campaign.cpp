#include "ground/campaign/campaign.hpp"

#include <nlohmann/json.hpp>
#include "ground/campaign/estimation_report.hpp"
#include "ground/campaign/fsw_flight_side.hpp"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <ctime>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <mutex>
#include <ostream>
#include <sstream>
#include <stdexcept>
#include <thread>

#include "ground/config/config.hpp"
#include "ground/plant/plant.hpp"

namespace rocksteady::campaign {

namespace fs = std::filesystem;

const char* const kResultsHeader =
    "case,strategy,t_omega_conv_s,fuel_at_t_omega_kg,t_q_conv_s,fuel_at_t_q_kg,total_fuel_kg,"
    "max_rate_rad_s";

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

std::string fmt(double v, int decimals) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  return buf;
}

std::string fmt_g(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

std::string run_dir_name(const RunResult& r) { return r.case_name + "_" + r.strategy; }

void ensure_parent(const std::string& path) {
  const fs::path parent = fs::path(path).parent_path();
  if (!parent.empty()) fs::create_directories(parent);
}

std::ofstream open_out(const std::string& path) {
  ensure_parent(path);
  std::ofstream out(path);
  if (!out) throw std::runtime_error("cannot write " + path);
  return out;
}

bool progress_enabled(ProgressMode m) {
  if (m == ProgressMode::kOn) return true;
  if (m == ProgressMode::kOff) return false;
  const char* ci = std::getenv("CI");
  return isatty(STDERR_FILENO) != 0 && (ci == nullptr || *ci == '\0');
}

}  // namespace

std::string csv_field(const std::optional<double>& v, int decimals) {
  return v ? fmt(*v, decimals) : std::string();
}

void write_results_csv(const std::string& path, const std::vector<RunResult>& results) {
  std::ofstream out = open_out(path);
  out << kResultsHeader << "\n";
  for (const RunResult& r : results) {
    const bool ran = r.status == RunStatus::kOk;
    out << r.case_name << "," << r.strategy << "," << csv_field(r.t_omega_conv_s, 1) << ","
        << csv_field(r.fuel_at_t_omega_kg, 4) << "," << csv_field(r.t_q_conv_s, 1) << ","
        << csv_field(r.fuel_at_t_q_kg, 4) << "," << (ran ? fmt(r.total_fuel_kg, 4) : "") << ","
        << (ran ? fmt_g(r.max_rate_rad_s) : "") << "\n";
  }
}

void write_results_json(const std::string& path, const CampaignReport& rep) {
  auto opt = [](const std::optional<double>& v) {
    return v ? nlohmann::json(*v) : nlohmann::json(nullptr);
  };
  nlohmann::json runs = nlohmann::json::array();
  for (const RunResult& r : rep.results) {
    const bool ran = r.status == RunStatus::kOk;
    runs.push_back({{"case", r.case_name},
                    {"case_number", r.case_number},
                    {"strategy", r.strategy},
                    {"status", to_string(r.status)},
                    {"note", r.note},
                    {"faults", r.faults},
                    {"t_omega_conv_s", opt(r.t_omega_conv_s)},
                    {"fuel_at_t_omega_kg", opt(r.fuel_at_t_omega_kg)},
                    {"t_q_conv_s", opt(r.t_q_conv_s)},
                    {"fuel_at_t_q_kg", opt(r.fuel_at_t_q_kg)},
                    {"total_fuel_kg", ran ? nlohmann::json(r.total_fuel_kg) : nlohmann::json(nullptr)},
                    {"max_rate_rad_s", ran ? nlohmann::json(r.max_rate_rad_s) : nlohmann::json(nullptr)},
                    {"final_mode", r.final_mode},
                    {"final_rate_rad_s", r.final_rate_rad_s},
                    {"final_q_error", r.final_q_error},
                    {"fuel_estimate_kg", r.fuel_hat_kg},
                    {"ticks", r.ticks},
                    {"allocator_saturated_ticks", r.saturated_ticks},
                    {"plant_clipped_ticks", r.clipped_ticks},
                    {"simulated_s", r.sim_s},
                    {"wall_s", r.wall_s},
                    {"plan_wall_s", r.plan_wall_s},
                    {"estimation", estimation_json(r.estimation)},
                    {"fdi", fdi_json(r.fdi)},
                    {"replan", replan_json(r.replan)},
                    {"timeseries", r.timeseries_path},
                    {"plot", r.plot_path}});
  }
  const nlohmann::json doc{{"cases", rep.cases},
                           {"strategies", rep.strategies},
                           {"threads", rep.threads},
                           {"plan_wall_s", rep.plan_wall_s},
                           {"closed_loop_wall_s", rep.sim_wall_s},
                           {"simulated_s", rep.simulated_s},
                           {"runs", runs}};
  std::ofstream out = open_out(path);
  out << doc.dump(2) << "\n";
}

void write_runs_csv(const std::string& path, const std::vector<RunResult>& results) {
  std::ofstream out = open_out(path);
  out << "case,strategy,status,note,final_mode,final_rate_rad_s,final_q_error,fuel_estimate_kg,"
         "ticks,allocator_saturated_ticks,plant_clipped_ticks,simulated_s,wall_s,plan_wall_s,"
         "timeseries,plot,faults\n";
  for (const RunResult& r : results) {
    std::string note = r.note;
    std::replace(note.begin(), note.end(), ',', ';');
    std::replace(note.begin(), note.end(), '\n', ' ');
    out << r.case_name << "," << r.strategy << "," << to_string(r.status) << "," << note << ","
        << r.final_mode << "," << fmt_g(r.final_rate_rad_s) << "," << fmt_g(r.final_q_error) << ","
        << fmt(r.fuel_hat_kg, 4) << "," << r.ticks << "," << r.saturated_ticks << ","
        << r.clipped_ticks << "," << fmt(r.sim_s, 1) << "," << fmt(r.wall_s, 3) << ","
        << fmt(r.plan_wall_s, 3) << "," << r.timeseries_path << "," << r.plot_path << ","
        << r.faults << "\n";
  }
}

void write_results_markdown(const std::string& path, const std::vector<RunResult>& results,
                            const std::vector<std::string>& cases,
                            const std::vector<std::string>& strategies,
                            const std::string& preamble) {
  std::map<std::pair<std::string, std::string>, const RunResult*> by;
  for (const RunResult& r : results) by[{r.case_name, r.strategy}] = &r;
  std::ofstream out = open_out(path);
  out << "# Rocksteady campaign results\n\n" << preamble << "\n\n";
  out << "| case | figure of merit |";
  for (const std::string& s : strategies) out << " `" << s << "` |";
  out << "\n|---|---|";
  for (std::size_t i = 0; i < strategies.size(); ++i) out << "---:|";
  out << "\n";
  struct Row {
    const char* label;
    int which;
  };
  const Row rows[] = {{"t_ω,conv (s)", 0},         {"fuel at t_ω,conv (kg)", 1},
                      {"t_q,conv (s)", 2},         {"fuel at t_q,conv (kg)", 3},
                      {"total fuel (kg)", 4},      {"max ‖ω‖ (rad/s)", 5}};
  std::vector<std::string> notes;
  for (const std::string& c : cases) {
    bool first = true;
    for (const Row& row : rows) {
      out << "| " << (first ? "**" + c + "**" : std::string()) << " | " << row.label << " |";
      first = false;
      for (const std::string& s : strategies) {
        auto it = by.find({c, s});
        std::string cell = "—";
        if (it != by.end()) {
          const RunResult& r = *it->second;
          if (r.status == RunStatus::kNoReference) {
            cell = "no ref.";
          } else if (r.status == RunStatus::kError) {
            cell = "error";
          } else {
            auto nc = [](const std::optional<double>& v, int d) {
              return v ? fmt(*v, d) : std::string("NC");
            };
            switch (row.which) {
              case 0: cell = nc(r.t_omega_conv_s, 0); break;
              case 1: cell = nc(r.fuel_at_t_omega_kg, 2); break;
              case 2: cell = nc(r.t_q_conv_s, 0); break;
              case 3: cell = nc(r.fuel_at_t_q_kg, 2); break;
              case 4: cell = fmt(r.total_fuel_kg, 2); break;
              default: cell = fmt_g(r.max_rate_rad_s); break;
            }
          }
        }
        out << " " << cell << " |";
      }
      out << "\n";
    }
  }
  for (const RunResult& r : results) {
    if (!r.note.empty()) notes.push_back("- " + r.case_name + " `" + r.strategy + "`: " + r.note);
  }
  out << "\nNC: not converged within the run (SPEC §7). no ref.: no fuel-optimal reference.\n";
  if (!notes.empty()) {
    out << "\n## Notes\n\n";
    for (const std::string& n : notes) out << n << "\n";
  }
}

void write_timeseries_csv(const std::string& path, const RunResult& r) {
  std::ofstream out = open_out(path);
  // Identification and fault-detection columns only for runs that fly those modules.
  const bool id = r.estimation.identifying;
  const bool fdi = r.fdi.enabled;
  out << "t_s,omega_x,omega_y,omega_z,omega_hat_x,omega_hat_y,omega_hat_z,q_x,q_y,q_z,"
         "q_hat_x,q_hat_y,q_hat_z,torque_cmd_x,torque_cmd_y,torque_cmd_z,"
         "u0,u1,u2,u3,u4,u5,u6,u7,fuel_kg,fuel_hat_kg,mode";
  if (id) {
    out << ",id_j_rel,id_r_err_m,id_k_max_err,id_j_nees,id_r_nees,id_r_sigma_max_m,"
           "id_windows_gated,id_gate_reinflations,id_windows,id_guard_refusals,id_excited_inertia";
  }
  if (fdi) out << ",fdi_chi2,fdi_best,fdi_best_llr,fdi_confirmed,fdi_check_jet";
  out << "\n";
  char buf[64];
  auto put = [&](double v) {
    std::snprintf(buf, sizeof buf, "%.9g", v);
    out << buf << ",";
  };
  for (const TimeRow& row : r.series) {
    put(row.t);
    for (int i = 0; i < 3; ++i) put(row.omega(i));
    for (int i = 0; i < 3; ++i) put(row.omega_hat(i));
    for (int i = 0; i < 3; ++i) put(row.q(i));
    for (int i = 0; i < 3; ++i) put(row.q_hat(i));
    for (int i = 0; i < 3; ++i) put(row.torque_cmd(i));
    for (int i = 0; i < 8; ++i) put(row.force(i));
    put(row.fuel_kg);
    put(row.fuel_hat_kg);
    out << gnc::to_string(row.mode);
    if (id) {
      for (double v : {row.j_rel, row.r_err_m, row.k_max_err, row.j_nees, row.r_nees,
                       row.r_sigma_max_m}) {
        std::snprintf(buf, sizeof buf, ",%.9g", v);
        out << buf;
      }
      out << "," << row.windows_gated << "," << row.gate_reinflations << "," << row.windows << ","
          << row.guard_refusals << "," << (row.excited_inertia ? 1 : 0);
    }
    if (fdi) {
      std::snprintf(buf, sizeof buf, ",%.9g,%d,%.9g,%u,%d", row.fdi_chi2, row.fdi_best,
                    row.fdi_best_llr, static_cast<unsigned>(row.fdi_confirmed), row.fdi_check_jet);
      out << buf;
    }
    out << "\n";
  }
}

bool write_plot(const std::string& dir, const RunResult& r, std::string& error) {
  const std::string script = (fs::path(dir) / "plot.gp").string();
  {
    std::ofstream gp = open_out(script);
    gp << "# Rocksteady run plot (the study's Figure 3 layout), generated by rocksteady-campaign.\n"
       << "set terminal pngcairo size 1000,1100 noenhanced font ',10'\n"
       << "set output 'plot.png'\n"
       << "set datafile separator ','\n"
       << "set grid\nset key right top\nset xlabel 't (s)'\n"
       << "set multiplot layout 3,1 title '" << r.case_name << "   " << r.strategy << "'\n";
    int n = 1;
    auto mark = [&](const std::optional<double>& t, const char* name, const char* color) {
      if (!t) return;
      gp << "set arrow " << n << " from " << *t << ", graph 0 to " << *t
         << ", graph 1 nohead dt 2 lw 1.5 lc rgb '" << color << "'\n";
      gp << "set label " << n << " '" << name << " = " << fmt(*t, 0) << " s' at " << *t
         << ", graph " << (n == 1 ? 0.92 : 0.80) << " offset 0.5,0 tc rgb '" << color << "'\n";
      ++n;
    };
    mark(r.t_omega_conv_s, "t_omega,conv", "red");
    mark(r.t_q_conv_s, "t_q,conv", "blue");
    const std::string f = "'timeseries.csv' skip 1";
    gp << "set ylabel 'omega (rad/s)'\n"
       << "plot " << f << " using 1:2 with lines title 'omega_x', '' skip 1 using 1:3 with lines "
       << "title 'omega_y', '' skip 1 using 1:4 with lines title 'omega_z'\n"
       << "set ylabel 'q (MRP)'\n"
       << "plot " << f << " using 1:8 with lines title 'q_x', '' skip 1 using 1:9 with lines "
       << "title 'q_y', '' skip 1 using 1:10 with lines title 'q_z'\n"
       << "set ylabel 'fuel (kg)'\n"
       << "plot " << f << " using 1:25 with lines lw 2 title 'fuel consumed'\n"
       << "unset multiplot\n";
  }
  const std::string cmd = "cd '" + dir + "' && gnuplot plot.gp > plot.log 2>&1";
  const int rc = std::system(cmd.c_str());
  if (rc != 0) {
    error = "gnuplot failed (see " + (fs::path(dir) / "plot.log").string() + ")";
    return false;
  }
  return true;
}

std::string benchmark_line(const CampaignReport& r) {
  int simulated = 0;
  for (const RunResult& x : r.results) simulated += x.status == RunStatus::kOk ? 1 : 0;
  std::ostringstream s;
  s << "campaign: " << r.results.size() << " runs (" << simulated << " simulated, "
    << (r.results.size() - static_cast<std::size_t>(simulated)) << " without a run) on "
    << r.threads << " threads: closed loop " << fmt(r.sim_wall_s, 2) << " s wall, "
    << fmt_g(r.sim_wall_s > 0 ? r.simulated_s / r.sim_wall_s : 0.0) << " sim-s per wall-s; "
    << "outputs " << fmt(r.output_wall_s, 2) << " s (run phase " << fmt(r.run_phase_wall_s, 2)
    << " s wall, " << fmt(r.cpu_s, 2) << " s CPU); planning " << fmt(r.plan_wall_s, 2) << " s (excluded)";
  return s.str();
}

CampaignReport run_campaign(const CampaignSpec& spec, TrajectorySource& source, std::ostream& log) {
  CampaignReport rep;
  // 1. Load everything first: a bad file stops the campaign before any run.
  const config::MissionConfig mission = config::load_mission(spec.mission_file);
  const config::GncConfig gnc_cfg = config::load_gnc(spec.gnc_file);
  std::vector<config::RunSetup> setups;
  for (const std::string& f : spec.case_files) {
    setups.push_back(config::load_case_run(mission, gnc_cfg, f));
    rep.cases.push_back(setups.back().case_name);
  }
  for (const Strategy& s : spec.strategies) rep.strategies.push_back(s.name);

  // 2. Trajectories for the fuel_optimal strategies: one per case (the model is the case's).
  struct Plan {
    std::shared_ptr<const gnc::TrajectoryTable> table;
    std::string note;
    double wall_s{0.0};
  };
  // plans[c * kPlanHorizons + h]: case c, horizon h (only the horizons some strategy uses).
  std::vector<Plan> plans(setups.size() * kPlanHorizons);
  bool horizon_used[kPlanHorizons] = {false, false};
  for (const Strategy& s : spec.strategies) {
    if (s.needs_trajectory()) horizon_used[static_cast<int>(s.horizon)] = true;
  }
  const auto plan_of = [&](std::size_t c, const Strategy& s) -> Plan& {
    return plans[c * kPlanHorizons + static_cast<std::size_t>(s.horizon)];
  };
  const bool any_fuel_optimal =
      std::any_of(spec.strategies.begin(), spec.strategies.end(),
                  [](const Strategy& s) { return s.needs_trajectory(); });
  const auto plan0 = Clock::now();
  if (any_fuel_optimal) {
    for (std::size_t c = 0; c < setups.size(); ++c) {
     for (int h = 0; h < kPlanHorizons; ++h) {
      if (!horizon_used[h]) continue;
      PlanRequest req;
      req.study_horizon = h == static_cast<int>(PlanHorizon::kStudy);
      req.setup = &setups[c];
      req.model = setups[c].flight;
      plant::Plant probe(setups[c].truth);  // the flight software's first measurement
      req.omega_init = probe.read_sensors().gyro.rate;
      if (spec.progress != ProgressMode::kOff) {
        log << "planning " << (c + 1) << "/" << setups.size() << ": " << setups[c].case_name
            << (req.study_horizon ? " (study horizon)" : "") << " ..." << std::flush;
      }
      const PlanOutcome o = source.plan(req);
      plans[c * kPlanHorizons + h] = Plan{o.table, o.note, o.wall_s};
      if (spec.progress != ProgressMode::kOff) {
        log << " " << (o.table ? "done" : "no plan") << " (" << fmt(o.wall_s, 1) << " s"
            << (o.note.empty() ? "" : ": " + o.note) << ")\n";
      }
     }
    }
  }
  rep.plan_wall_s = seconds_since(plan0);

  // 3. The runs, case-major, on `threads` workers.
  struct Job {
    std::size_t c;
    std::size_t s;
  };
  std::vector<Job> jobs;
  for (std::size_t c = 0; c < setups.size(); ++c) {
    for (std::size_t s = 0; s < spec.strategies.size(); ++s) jobs.push_back({c, s});
  }
  rep.results.resize(jobs.size());
  unsigned hw = std::thread::hardware_concurrency();
  int threads = spec.jobs > 0 ? spec.jobs : static_cast<int>(hw == 0 ? 1 : hw);
  threads = std::max(1, std::min<int>(threads, static_cast<int>(std::max<std::size_t>(jobs.size(), 1))));
  rep.threads = threads;

  std::uint64_t total_ticks = 0;
  for (const Job& j : jobs) {
    const Strategy& st = spec.strategies[j.s];
    if (st.needs_trajectory() && !plan_of(j.c, st).table) continue;
    const double d = spec.duration_s >= 0 ? spec.duration_s : setups[j.c].duration_s;
    total_ticks += static_cast<std::uint64_t>(std::llround(d / setups[j.c].truth.control_period_s));
  }

  std::atomic<std::size_t> next{0};
  std::atomic<std::size_t> done{0};
  std::atomic<std::uint64_t> ticks{0};
  std::atomic<double> sim_busy_s{0.0};
  std::mutex err_mutex;
  const fs::path out_dir(spec.out_dir);
  fs::create_directories(out_dir);

  const auto sim0 = Clock::now();
  const std::clock_t cpu0 = std::clock();
  std::atomic<double> output_s{0.0};
  auto worker = [&]() {
    for (;;) {
      const std::size_t i = next.fetch_add(1);
      if (i >= jobs.size()) return;
      const Job& j = jobs[i];
      const config::RunSetup& setup = setups[j.c];
      const Strategy& st = spec.strategies[j.s];
      RunOptions opt;
      opt.duration_s = spec.duration_s;
      const double d = spec.duration_s >= 0 ? spec.duration_s : setup.duration_s;
      opt.log_interval_s = spec.log_interval_s >= 0 ? spec.log_interval_s : d / 5000.0;
      if (!spec.write_timeseries && !spec.write_plots) opt.log_interval_s = 0.0;
      opt.progress_ticks = &ticks;
      opt.replan = spec.replan;
      RunResult r;
      try {
        GncFlightSide core_only;
        FswFlightSide app;
        FlightSide& flight = spec.use_flight_app ? static_cast<FlightSide&>(app) : core_only;
        const Plan& pl = plan_of(j.c, st);
        const gnc::TrajectoryTable* traj = st.needs_trajectory() ? pl.table.get() : nullptr;
        r = run_closed_loop(setup, st, flight, traj, opt, pl.note);
        if (st.needs_trajectory()) {
          r.plan_wall_s = pl.wall_s;
          if (traj != nullptr && r.note.empty()) r.note = pl.note;
        }
      } catch (const std::exception& e) {
        r.case_name = setup.case_name;
        r.case_number = setup.case_number;
        r.strategy = st.name;
        r.status = RunStatus::kError;
        r.note = e.what();
      }
      // Outputs (timed separately from the closed loop).
      const auto o0 = Clock::now();
      if (r.status == RunStatus::kOk && (spec.write_timeseries || spec.write_plots)) {
        const fs::path dir = out_dir / "runs" / run_dir_name(r);
        try {
          r.timeseries_path = (dir / "timeseries.csv").string();
          write_timeseries_csv(r.timeseries_path, r);
          if (spec.write_plots) {
            std::string err;
            if (write_plot(dir.string(), r, err)) {
              r.plot_path = (dir / "plot.png").string();
            } else {
              r.note += (r.note.empty() ? "" : "; ") + err;
            }
          }
        } catch (const std::exception& e) {
          std::lock_guard<std::mutex> lock(err_mutex);
          r.note += (r.note.empty() ? "" : "; ") + std::string(e.what());
        }
      }
      r.series.shrink_to_fit();
      double prev = output_s.load();
      while (!output_s.compare_exchange_weak(prev, prev + seconds_since(o0))) {
      }
      double busy = sim_busy_s.load();
      while (!sim_busy_s.compare_exchange_weak(busy, busy + r.wall_s)) {
      }
      rep.results[i] = std::move(r);
      done.fetch_add(1);
    }
  };

  const bool show = progress_enabled(spec.progress);
  std::mutex mon_mutex;
  std::condition_variable mon_cv;
  bool finished = false;
  std::thread monitor;
  if (show) {
    monitor = std::thread([&]() {
      std::unique_lock<std::mutex> lock(mon_mutex);
      while (!mon_cv.wait_for(lock, std::chrono::milliseconds(250), [&] { return finished; })) {
        const double frac = total_ticks > 0 ? static_cast<double>(ticks.load()) /
                                                  static_cast<double>(total_ticks)
                                            : 1.0;
        const double el = seconds_since(sim0);
        char buf[200];
        std::snprintf(buf, sizeof buf, "\r[campaign] %zu/%zu runs  %5.1f%% of simulated time  %.1f s",
                      done.load(), jobs.size(), 100.0 * std::min(frac, 1.0), el);
        log << buf << std::flush;
      }
      log << "\r" << std::string(72, ' ') << "\r" << std::flush;
    });
  }
  std::vector<std::thread> pool;
  for (int t = 0; t < threads; ++t) pool.emplace_back(worker);
  for (std::thread& t : pool) t.join();
  {
    std::lock_guard<std::mutex> lock(mon_mutex);
    finished = true;
  }
  mon_cv.notify_all();
  if (monitor.joinable()) monitor.join();
  const double all_wall = seconds_since(sim0);
  rep.run_phase_wall_s = all_wall;
  rep.cpu_s = static_cast<double>(std::clock() - cpu0) / CLOCKS_PER_SEC;
  rep.output_wall_s = output_s.load() / threads;  // spread over the workers
  rep.sim_wall_s = std::max(0.0, all_wall - rep.output_wall_s);
  for (const RunResult& r : rep.results) rep.simulated_s += r.sim_s;

  // 4. Tables.
  rep.results_csv = (out_dir / "results.csv").string();
  rep.results_md = (out_dir / "results.md").string();
  rep.runs_csv = (out_dir / "runs.csv").string();
  rep.results_json = (out_dir / "results.json").string();
  write_results_csv(rep.results_csv, rep.results);
  write_runs_csv(rep.runs_csv, rep.results);
  write_results_json(rep.results_json, rep);
  std::ostringstream pre;
  pre << "Mission `" << spec.mission_file << "`, GNC `" << spec.gnc_file
      << "`. Trajectory source: " << source.name() << ".  \n" << benchmark_line(rep) << ".";
  write_results_markdown(rep.results_md, rep.results, rep.cases, rep.strategies, pre.str());
  return rep;
}

}  // namespace rocksteady::campaign
