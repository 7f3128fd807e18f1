// Estimation benchmarks: one MEKF update, and the identifier's per-tick cost in each phase of its
// window cycle (accumulate only; the window-end group updates; the report). Measures and prints;
// never asserts a time.
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdint>

#include "gnc/estimation/identifier.hpp"
#include "gnc/estimation/mekf.hpp"
#include "gnc/math/rotation.hpp"
#include "gnc/model/mass_properties.hpp"

namespace {

using namespace rocksteady::gnc;

void BM_MekfUpdate(benchmark::State& state) {
  MekfConfig c;
  c.gyro_arw = 1e-6;
  c.star_sigma = 4.0 * std::sqrt(1e-8 / 0.1);
  Mekf f;
  f.configure(c);
  MekfInput in;
  in.gyro_valid = in.star_valid = true;
  in.gyro_rate = Vec3(0.01, 0.02, 0.03);
  in.star_quat = mrp::to_quaternion(Vec3(0.05, 0.04, 0.03));
  double t = 0.0;
  f.update(in);
  for (auto _ : state) {
    t += 0.1;
    in.t = t;
    f.update(in);
    benchmark::DoNotOptimize(f.quaternion());
  }
}
BENCHMARK(BM_MekfUpdate);

// The identifier's tick: phase 0 = every tick in turn (the average over a 20-tick window cycle);
// phase n > 0 = the n-th tick after a window closes (joint: 1, 2 gain halves, 3, 4 apply halves,
// 5 scale anchor, 6 report; concurrent: 1 J group, 3 r group, 5 k group), timed on a copy of the
// identifier taken just before that tick (the copy is timed too: see BM_IdentifierCopy, subtract
// it).
struct IdentifierRig {
  explicit IdentifierRig(IdentifierMode mode, double fault_torque_sigma = 0.0) {
    IdentifierConfig c;
    c.mode = mode;
    c.fault_torque_sigma = fault_torque_sigma;  // (I22)-(I24) the fault torque and its scores
    c.rcs = study_rcs_layout(200.0);
    c.j0 = total_inertia(study_true_mass_properties());
    c.window_s = 2.0;  // 20 ticks
    // The rig's data are not a physical trajectory: a tight inertia prior keeps the guards from
    // refusing the update, so every phase does its full work.
    c.j_prior_sigma = 1e3;
    c.r_max_offset = 1e6;
    id.configure(c);
    in.omega_valid = true;
  }
  void next() {
    in.omega = Vec3(0.01, 0.02, 0.03) + 1e-6 * static_cast<double>(k % 1000) * Vec3(1, -1, 0.5);
    for (int ch = 0; ch < kChannels; ++ch) {
      in.force(ch) = 150.0 * std::sin(0.1 * static_cast<double>(k) + ch);
    }
    ++k;
  }
  // Advance until the next tick is the phase-th after a window closes.
  void to_phase(int phase) {
    const std::uint32_t windows = id.counters().windows;
    while (id.counters().windows == windows) {
      next();
      id.update(in);
    }
    for (int p = 1; p < phase; ++p) {
      next();
      id.update(in);
    }
    next();
  }
  Identifier id;
  IdentifierInput in;
  long k{0};
};

void BM_IdentifierTick(benchmark::State& state, IdentifierMode mode, int phase,
                       double fault_torque_sigma = 0.0) {
  IdentifierRig rig(mode, fault_torque_sigma);
  for (int w = 0; w < 5; ++w) rig.to_phase(8);  // a few windows in
  if (phase == 0) {
    for (auto _ : state) {
      rig.next();
      rig.id.update(rig.in);
      benchmark::DoNotOptimize(rig.id.estimate());
    }
    return;
  }
  rig.to_phase(phase);
  const Identifier saved = rig.id;
  for (auto _ : state) {
    Identifier copy = saved;
    copy.update(rig.in);
    benchmark::DoNotOptimize(copy.estimate());
  }
}
BENCHMARK_CAPTURE(BM_IdentifierTick, joint_average, IdentifierMode::kJoint, 0);
BENCHMARK_CAPTURE(BM_IdentifierTick, joint_gain_tick, IdentifierMode::kJoint, 1);
BENCHMARK_CAPTURE(BM_IdentifierTick, joint_gain_finish_tick, IdentifierMode::kJoint, 2);
BENCHMARK_CAPTURE(BM_IdentifierTick, joint_apply_tick, IdentifierMode::kJoint, 3);
BENCHMARK_CAPTURE(BM_IdentifierTick, joint_apply_finish_tick, IdentifierMode::kJoint, 4);
BENCHMARK_CAPTURE(BM_IdentifierTick, joint_anchor_tick, IdentifierMode::kJoint, 5);
BENCHMARK_CAPTURE(BM_IdentifierTick, joint_report_tick, IdentifierMode::kJoint, 6);
BENCHMARK_CAPTURE(BM_IdentifierTick, joint_accumulate_tick, IdentifierMode::kJoint, 8);
// With the fault torque d (I22): every tick of the window cycle (the scores of I23 are the last
// ticks; the 20-tick rig's window takes bigger row blocks than the flight's 200-tick one).
BENCHMARK_CAPTURE(BM_IdentifierTick, fault_joint_average, IdentifierMode::kJoint, 0, 2000.0);
BENCHMARK_CAPTURE(BM_IdentifierTick, fault_tick_1, IdentifierMode::kJoint, 1, 2000.0);
BENCHMARK_CAPTURE(BM_IdentifierTick, fault_tick_2, IdentifierMode::kJoint, 2, 2000.0);
BENCHMARK_CAPTURE(BM_IdentifierTick, fault_tick_3, IdentifierMode::kJoint, 3, 2000.0);
BENCHMARK_CAPTURE(BM_IdentifierTick, fault_tick_4, IdentifierMode::kJoint, 4, 2000.0);
BENCHMARK_CAPTURE(BM_IdentifierTick, fault_tick_5, IdentifierMode::kJoint, 5, 2000.0);
BENCHMARK_CAPTURE(BM_IdentifierTick, fault_tick_6, IdentifierMode::kJoint, 6, 2000.0);
BENCHMARK_CAPTURE(BM_IdentifierTick, fault_tick_7, IdentifierMode::kJoint, 7, 2000.0);
BENCHMARK_CAPTURE(BM_IdentifierTick, fault_tick_8, IdentifierMode::kJoint, 8, 2000.0);
BENCHMARK_CAPTURE(BM_IdentifierTick, fault_tick_9, IdentifierMode::kJoint, 9, 2000.0);
BENCHMARK_CAPTURE(BM_IdentifierTick, fault_tick_10, IdentifierMode::kJoint, 10, 2000.0);
BENCHMARK_CAPTURE(BM_IdentifierTick, fault_tick_11, IdentifierMode::kJoint, 11, 2000.0);
BENCHMARK_CAPTURE(BM_IdentifierTick, fault_tick_12, IdentifierMode::kJoint, 12, 2000.0);
BENCHMARK_CAPTURE(BM_IdentifierTick, fault_tick_13, IdentifierMode::kJoint, 13, 2000.0);
BENCHMARK_CAPTURE(BM_IdentifierTick, fault_tick_14, IdentifierMode::kJoint, 14, 2000.0);
BENCHMARK_CAPTURE(BM_IdentifierTick, concurrent_average, IdentifierMode::kConcurrent, 0);
BENCHMARK_CAPTURE(BM_IdentifierTick, concurrent_j_tick, IdentifierMode::kConcurrent, 1);
BENCHMARK_CAPTURE(BM_IdentifierTick, concurrent_r_tick, IdentifierMode::kConcurrent, 3);
BENCHMARK_CAPTURE(BM_IdentifierTick, concurrent_k_tick, IdentifierMode::kConcurrent, 5);

void BM_IdentifierCopy(benchmark::State& state) {
  IdentifierRig rig(IdentifierMode::kJoint);
  const Identifier saved = rig.id;
  for (auto _ : state) {
    Identifier copy = saved;
    benchmark::DoNotOptimize(copy);
  }
}
BENCHMARK(BM_IdentifierCopy);

}  // namespace

BENCHMARK_MAIN();
