// Planner time and fuel per study case and per horizon (SPEC Eq. 44; the estimated models of SPEC
// Table 3; cases 5 and 6 share case 1's model). One plan per benchmark (Iterations(1)), including
// the self-verification and the grid-refinement re-solve. Counters: fuel_kg (0 when the plan
// failed), ok (1/0), cpu_s (process CPU time, the figure to compare on a shared machine), nodes,
// samples, t_active (end of the despin: beyond the active horizon the plan rests after it),
// cpu_s includes the candidate workers' CPU time (PlanSettings::jobs),
// iterations (all solves), solve_s and refine_s (wall seconds of the solves and of the
// grid-refinement re-solve), refine_iter; the label says why a plan failed.
//   planner_horizon_bench [--benchmark_filter=case1/] [--benchmark_format=console]
// Arguments: case (1 2 3 4 7), horizon (s), grid (0 uniform, 1 tumble-following), jobs (worker
// processes for a long horizon's candidates: 1 in process, 0 one per hardware thread), check (0 the
// coarsening grid check, the default; 1 the bisection).
#include <benchmark/benchmark.h>

#include <sys/resource.h>

#include <string>

#include "ground/planner/planner.hpp"

namespace {

namespace pl = rocksteady::ground::planner;

pl::PlanModel case_model(int c) {
  switch (c) {
    case 2: return pl::study_case_model(200.0, 1e5, 0.01);
    case 3: return pl::study_case_model(200.0, 1e6, 0.1);
    case 4: return pl::study_case_model(1000.0, 1e7, 1.0);
    case 7: return pl::study_case_model(200.0, 1e7, 1.0);
    default: return pl::study_case_model(200.0, 0.0, 0.0);  // cases 1, 5, 6
  }
}

void plan_horizon(benchmark::State& state) {
  const int c = static_cast<int>(state.range(0));
  pl::PlanProblem p;
  p.case_name = "case" + std::to_string(c);
  p.model = case_model(c);
  p.settings.t_final_max = static_cast<double>(state.range(1));
  p.settings.tumble_grid = state.range(2) != 0;
  p.settings.jobs = static_cast<int>(state.range(3));
  p.settings.refinement_check = state.range(4) != 0 ? pl::PlanSettings::RefinementCheck::kBisect
                                                    : pl::PlanSettings::RefinementCheck::kCoarsen;
  pl::PlanResult r;
  double cpu = 0.0;
  // CPU seconds of this process and of its finished children (the candidate workers).
  const auto cpu_now = [] {
    double s = 0.0;
    for (const int who : {RUSAGE_SELF, RUSAGE_CHILDREN}) {
      rusage u{};
      getrusage(who, &u);
      s += static_cast<double>(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
           1e-6 * static_cast<double>(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
    }
    return s;
  };
  for (auto _ : state) {
    const double c0 = cpu_now();
    r = pl::plan(p);
    cpu = cpu_now() - c0;
    benchmark::DoNotOptimize(r.samples.data());
  }
  state.counters["fuel_kg"] = r.ok ? r.fuel_kg : 0.0;
  state.counters["ok"] = r.ok ? 1.0 : 0.0;
  state.counters["cpu_s"] = cpu;
  state.counters["nodes"] = r.nodes;
  state.counters["t_active"] = r.ok ? r.t_active : 0.0;  // end of the despin (rest after it)
  state.counters["samples"] = static_cast<double>(r.samples.size());
  state.counters["iterations"] = r.iterations + r.verification.refined_iterations;
  // Where the time goes: the candidates' solves (and their open-loop checks) against the
  // grid-refinement re-solve of the chosen despin (wall seconds of each).
  state.counters["solve_s"] = r.solve_seconds;
  state.counters["refine_s"] = r.verification.refined_seconds;
  state.counters["refine_iter"] = r.verification.refined_iterations;
  if (!r.ok) state.SetLabel(r.error.substr(0, 90));
}

void horizons(benchmark::internal::Benchmark* b) {
  for (int c : {1, 2, 3, 4, 7}) {
    for (long t : {1390L, 2780L, 5560L, 11000L, 22000L, 44000L, 50000L}) {
      b->Args({c, t, 0, 0, 0});
    }
    // The same plan with its candidates solved in this process, and with the bisection check.
    b->Args({c, 50000L, 0, 1, 0});
    b->Args({c, 50000L, 0, 0, 1});
    for (long t : {1390L, 11000L, 44000L}) b->Args({c, t, 1, 0, 0});
  }
}

}  // namespace

BENCHMARK(plan_horizon)
    ->ArgNames({"case", "t_f", "tumble", "jobs", "bisect"})
    ->Apply(horizons)
    ->Unit(benchmark::kSecond)
    ->Iterations(1)
    ->UseRealTime();

BENCHMARK_MAIN();
