// Planning time per study case at the default grid (SPEC Table 3 estimated models). Cases 5 and 6
// share case 1's model. Reports IPOPT iterations and fuel as counters; run by hand:
//   planner_bench [--benchmark_filter=...]
#include <benchmark/benchmark.h>

#include "ground/planner/planner.hpp"

namespace {

using rocksteady::ground::planner::plan;
using rocksteady::ground::planner::PlanProblem;
using rocksteady::ground::planner::PlanResult;
using rocksteady::ground::planner::study_case_model;

void plan_case(benchmark::State& state, double u_max, double delta_j, double delta_r,
               bool refinement) {
  PlanProblem p;
  p.model = study_case_model(u_max, delta_j, delta_r);
  p.settings.verify_refinement = refinement;
  PlanResult r;
  for (auto _ : state) {
    r = plan(p);
    benchmark::DoNotOptimize(r.samples.data());
  }
  if (!r.ok) state.SkipWithError(r.error.c_str());
  state.counters["fuel_kg"] = r.fuel_kg;
  state.counters["t_final_s"] = r.t_final;
  state.counters["iterations"] = r.iterations;
  state.counters["refined_iterations"] = r.verification.refined_iterations;
}

}  // namespace

// Whole plan() including the grid-refinement re-solve, and the main solve alone.
BENCHMARK_CAPTURE(plan_case, case1, 200.0, 0.0, 0.0, true)->Unit(benchmark::kSecond)->Iterations(1);
BENCHMARK_CAPTURE(plan_case, case2, 200.0, 1e5, 0.01, true)->Unit(benchmark::kSecond)->Iterations(1);
BENCHMARK_CAPTURE(plan_case, case3, 200.0, 1e6, 0.1, true)->Unit(benchmark::kSecond)->Iterations(1);
BENCHMARK_CAPTURE(plan_case, case4, 1000.0, 1e7, 1.0, true)->Unit(benchmark::kSecond)->Iterations(1);
BENCHMARK_CAPTURE(plan_case, case7, 200.0, 1e7, 1.0, true)->Unit(benchmark::kSecond)->Iterations(1);
BENCHMARK_CAPTURE(plan_case, case1_no_refinement, 200.0, 0.0, 0.0, false)
    ->Unit(benchmark::kSecond)
    ->Iterations(1);

BENCHMARK_MAIN();
