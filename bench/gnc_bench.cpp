// GNC tick benchmark: one full Gnc::step (filter + NTCL + D+PD-based reference + pseudoinverse),
// and each control law alone. Measures and prints; never asserts a time.
#include <benchmark/benchmark.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <random>
#include <vector>

#include "gnc/control/laws.hpp"
#include "gnc/gnc.hpp"
#include "gnc/math/rotation.hpp"

namespace {

using namespace rocksteady::gnc;

SensorSample study_sample(double t) {
  SensorSample s;
  s.t = t;
  s.gyro_rate = Vec3(0.01, 0.02, 0.03);  // SPEC §5 initial rate
  s.gyro_valid = true;
  s.star_quat = mrp::to_quaternion(Vec3(0.05, 0.04, 0.03));
  s.star_valid = true;
  return s;
}

// Initialise the flight core (or mark the benchmark failed) and fly its first tick in `mode`.
bool start(benchmark::State& state, Gnc& gnc, const GncParams& p, Mode mode,
           const SensorSample& first, GncOutput& out) {
  if (!gnc.init(p).ok) {
    state.SkipWithError("parameters rejected");
    return false;
  }
  GncCommands c;
  c.has_mode_request = true;
  c.mode_request = mode;
  gnc.step(first, c, out);
  return true;
}

void BM_GncTick(benchmark::State& state, LawId law, Mode mode) {
  GncParams p = study_gnc_params(200.0);
  p.law = law;
  p.estimator.kind = EstimatorKind::kFilter;
  p.mode.auto_hold = false;
  Gnc gnc;
  GncOutput out;
  double t = 0.0;
  if (!start(state, gnc, p, mode, study_sample(t), out)) return;
  const GncCommands c{};
  for (auto _ : state) {
    t += p.dt;
    gnc.step(study_sample(t), c, out);
    benchmark::DoNotOptimize(out);
  }
  state.SetLabel(to_string(gnc.mode()));
}

// The reference tick: filter + NTCL + D+PD-based reference (both phases) + pseudoinverse.
BENCHMARK_CAPTURE(BM_GncTick, ntcl_dpd_ref_damping, LawId::kNtcl, Mode::kDetumble);
BENCHMARK_CAPTURE(BM_GncTick, ntcl_dpd_ref_hold, LawId::kNtcl, Mode::kHold);
BENCHMARK_CAPTURE(BM_GncTick, so3_hold, LawId::kSo3, Mode::kHold);
BENCHMARK_CAPTURE(BM_GncTick, adaptive_hold, LawId::kAdaptive, Mode::kHold);

// The TRACK benchmarks' table: the study's vehicle, SPEC §6 filter, NTCL, pseudoinverse, no
// automatic HOLD.
GncParams track_params() {
  GncParams p = study_gnc_params(200.0);
  p.law = LawId::kNtcl;
  p.estimator.kind = EstimatorKind::kFilter;
  p.mode.auto_hold = false;
  return p;
}

// Load `table` and fly one tick that requests TRACK (or mark the benchmark failed).
bool enter_track(benchmark::State& state, Gnc& gnc, const TrajectoryTable& table,
                 const SensorSample& sample, GncOutput& out) {
  if (gnc.load_trajectory(table) != TrajectoryError::kOk) {
    state.SkipWithError("trajectory refused");
    return false;
  }
  GncCommands c;
  c.has_mode_request = true;
  c.mode_request = Mode::kTrack;
  gnc.step(sample, c, out);
  return true;
}

// TRACK after the plan with the acquisition slew (guidance.slew_s, the replan strategies): the
// eigenaxis turn's closed-form reference every tick (SPEC §6 filter, NTCL, pseudoinverse).
void BM_GncTickSlew(benchmark::State& state) {
  GncParams p = track_params();
  p.guidance.slew_s = 40000.0;
  Gnc gnc;
  std::vector<TrajectoryTable> table(1);  // a plan already at rest: the slew starts at once
  table[0].count = 2;
  table[0].samples[1].t = 10.0;
  table[0].checksum = trajectory_checksum(table[0]);
  const auto at_rest = [](double t) {
    SensorSample s = study_sample(t);
    s.gyro_rate = Vec3::Zero();
    return s;
  };
  GncOutput out;
  double t = 0.0;
  if (!start(state, gnc, p, Mode::kIdle, at_rest(t), out)) return;
  if (!enter_track(state, gnc, table[0], at_rest(t += p.dt), out)) return;
  const GncCommands c{};
  for (int i = 0; i < 200; ++i) gnc.step(at_rest(t += p.dt), c, out);  // past the plan's end
  for (auto _ : state) {
    t += p.dt;
    gnc.step(at_rest(t), c, out);
    benchmark::DoNotOptimize(out);
  }
  state.SetLabel(to_string(out.telemetry.phase));
}
BENCHMARK(BM_GncTickSlew);

// TRACK on a plan (SPEC §6 filter, pseudoinverse): the NTCL on the plan's rates (k = 0), or
// momentum tracking (guidance.track_momentum_k, the replan strategies), the plan's torque turned
// into the body frame plus the momentum feedback every tick in place of the law. The body tumbles
// at the study's rate; the plan despins it.
void BM_GncTickTrack(benchmark::State& state, double momentum_k) {
  GncParams p = track_params();
  p.guidance.track_momentum_k = momentum_k;
  Gnc gnc;
  std::vector<TrajectoryTable> table(1);
  const Vec3 w0 = study_sample(0.0).gyro_rate;
  table[0].count = 101;
  for (int i = 0; i < table[0].count; ++i) {  // omega_d decays linearly to rest over 10^5 s
    const double s = static_cast<double>(i) / (table[0].count - 1);
    table[0].samples[i].t = s * 1e5;
    table[0].samples[i].omega_d = (1.0 - s) * w0;
    table[0].samples[i].omega_d_dot = -w0 / 1e5;
  }
  table[0].samples[table[0].count - 1].omega_d_dot.setZero();
  table[0].checksum = trajectory_checksum(table[0]);
  GncOutput out;
  double t = 0.0;
  if (!start(state, gnc, p, Mode::kIdle, study_sample(t), out)) return;
  if (!enter_track(state, gnc, table[0], study_sample(t += p.dt), out)) return;
  const GncCommands c{};
  for (auto _ : state) {
    t += p.dt;
    gnc.step(study_sample(t), c, out);
    benchmark::DoNotOptimize(out);
  }
  state.SetLabel(to_string(out.telemetry.phase));
}
BENCHMARK_CAPTURE(BM_GncTickTrack, rates, 0.0);
BENCHMARK_CAPTURE(BM_GncTickTrack, momentum, 1e-3);

// Every module on (the flight-core budget of DEVELOPERS.md): MEKF, identification (gnc.yaml's
// flight settings for this gyro: 60 s windows, the second-order term, the gate, the gyro bias;
// study priors, automatic adoption), fault detection, L1 allocation under limits, NTCL in DETUMBLE. The rate
// changes every tick so the identifier cycles through its windows. Reports the loop's mean per
// tick and, as counters, the mean of the timed steps alone (mean_tick_us, the budget's figure),
// the median, 99.9th percentile and maximum single tick over the run.
void BM_GncTickAllModules(benchmark::State& state, bool fdi, AllocatorKind alloc) {
  GncParams p = study_gnc_params(200.0);
  p.law = LawId::kNtcl;
  p.allocator = alloc;
  p.estimator.kind = EstimatorKind::kMekf;
  p.mekf.gyro_arw = 1e-6;
  p.mekf.star_sigma = 4e-4;
  p.mekf.rate_cutoff = 0.02 * 3.14159265358979323846;  // the rate stage (M8), as flown
  p.identification.enabled = true;
  p.identification.adopt = ModelAdoption::kAuto;
  apply_flight_identification_settings(p, p.mekf.gyro_arw / std::sqrt(p.dt));
  p.fdi.enabled = fdi;
  p.fdi.identified_isolation = fdi;  // (F14) the identifier's fault torque, as flown
  p.fdi.degraded_min_loss = fdi ? 0.1 : 0.0;  // (F18) partial losses of thrust, as flown
  p.fdi.degraded_loss_projection = true;  // (F51) the loss beyond the signature's error along itself
  p.fdi.check_llr = fdi ? 5.0 : 0.0;          // (F19) jet checks, as flown
  p.fdi.check_max_model_error = 0.5;          // ... against the model's stated 1 sigma, as flown
  p.fdi.check_min_llr = 5.0;                  // (F24) ... when the check can move the evidence
  p.fdi.check_fit_on_suspicion = fdi;         // (F31) ... and not for an evident fault elsewhere
  p.fdi.check_quiet_start = fdi;              // (F34) ... nor on a suspicious window
  p.fdi.check_score_unfit = fdi;              // (F35) an unfit check window is scored
  p.fdi.check_blocker = fdi;                  // (F37) the jet blocking a stuck-off leader checked
  p.fdi.episode_restart_stale = fdi;          // (F38) a stale episode restarted
  p.fdi.episode_restart_leader = fdi;         // (F41) ... and one a new leader's fault postdates
  p.fdi.model_rel_floor = 0.005;              // the model's relative error floor, as flown
  p.fdi.model_floor_gyroscopic = true;        // (F22) ... on both terms, as flown
  p.fdi.probe_windows = 1;                    // isolation tests of one window ...
  p.fdi.probe_aligned = true;                 // (F27) ... flown closed throughout, as flown
  p.fdi.probe_partial_rival = true;           // (F29) ... read against partial losses
  p.fdi.probe_read_closed = true;             // (F32) ... and first on the closed window
  p.fdi.probe_read_elsewhere = true;          // (F40) ... which may name another pod's jet
  p.fdi.probe_start_llr = 8.0;                // (F52) ... and may start below confirm_llr
  p.fdi.check_model_null_space = true;        // (F42) checks in the identified model's null space
  p.fdi.survey_interval_s = fdi ? 20000.0 : 0.0;  // (F36) the survey as flown: its bookkeeping
  p.fdi.survey_hold_only = true;              // (F43) the survey in HOLD only
  p.fdi.survey_max_kick_rad_s = 5.0e-5;       // (F44) ... and no survey check that may kick the rate
  p.fdi.survey_noise_kick = true;             // (F48) ... nor where the gyro is too noisy for one
  p.fdi.check_long_ticks = 1000;  // (F49) ... where it is, every check in HOLD one long window
  p.fdi.check_long_energy = 80.0;
  p.fdi.check_long_evidence_energy = 320.0;
  p.fdi.check_long_reach = 0.8;  // (F50) ... or this fraction of the energy the centre of mass caps
  p.fdi.check_kick_after_fault = true;  // (F56) after a fault, evidence checks in the kick bound
  p.fdi.survey_loss_llr = 2.5;  // (F57) a jet with partial-loss evidence is not verified by its energy
  p.fdi.total_loss_sigmas = 2.0;  // (F58) a loss 2 sigma below the total-loss floor is partial
  p.fdi.after_fault_max_j_rel = 0.01;  // (F59) after a fault, losses and checks on a confident model
  p.fdi.balance.kick_rad_s = 0.0;  // (F61) channel balance tests off, as gnc.yaml (HOLD only when on)
  p.fdi.balance.quiet_ticks = 300;
  p.fdi.centred_gyro_noise = true;            // (F28) the gyro's variance sigma_g^2, as flown
  p.fdi.suspect_chi2 = 30.66;                 // ... and the suspicion at 1 - 1e-6, as flown
  p.fdi.detect_early_ticks = fdi ? 3 : 0;     // (F33) early detection, as flown
  p.fdi.skip_onset_window = true;             // (F21) the onset window not scored: 5-tick windows
  p.fdi.onset_restart = fdi;                  // (F45) ... ended at its early suspicion, as flown
  p.fdi.episode_restart = true;               // (F25) the episode since the fault showed, as flown
  p.mode.auto_hold = false;
  Gnc gnc;
  GncOutput out;
  double t = 0.0;
  if (!start(state, gnc, p, Mode::kDetumble, study_sample(t), out)) return;
  GncCommands c;
  // The samples are made before the timed loop: the loop times Gnc::step and the clock reads
  // around it, not the test's own sample synthesis.
  const auto n = static_cast<std::size_t>(state.max_iterations);
  std::vector<SensorSample> samples(n);
  for (std::size_t k = 0; k < n; ++k) {
    t += p.dt;
    samples[k] = study_sample(t);
    samples[k].gyro_rate *= 1.0 - 1e-5 * static_cast<double>(k % 10000);
  }
  std::vector<double> tick_ns;
  tick_ns.reserve(n);
  std::size_t k = 0;
  for (auto _ : state) {
    const SensorSample& s = samples[k++ % n];
    const auto t0 = std::chrono::steady_clock::now();
    gnc.step(s, c, out);
    const auto t1 = std::chrono::steady_clock::now();
    benchmark::DoNotOptimize(out);
    tick_ns.push_back(static_cast<double>(
        std::chrono::duration_cast<std::chrono::nanoseconds>(t1 - t0).count()));
  }
  // Wall-clock per tick: the 99.9th percentile is the identifier's heaviest phase; the maximum
  // also holds whatever preemption the machine did, so it is reported but not the figure to quote.
  std::sort(tick_ns.begin(), tick_ns.end());
  if (!tick_ns.empty()) {
    double sum = 0.0;
    for (double v : tick_ns) sum += v;
    // The mean of the timed steps alone (one clock read's cost included), beside the loop's.
    state.counters["mean_tick_us"] = sum / static_cast<double>(tick_ns.size()) * 1e-3;
    state.counters["p50_tick_us"] = tick_ns[tick_ns.size() / 2] * 1e-3;
    state.counters["p999_tick_us"] = tick_ns[tick_ns.size() * 999 / 1000] * 1e-3;
    state.counters["max_tick_us"] = tick_ns.back() * 1e-3;
  }
  state.counters["id_windows"] = gnc.identifier().counters().windows;
  state.SetLabel(to_string(gnc.mode()));
}
// Ten runs of 5000 s each (83 identification windows), each from the same start. A shared
// machine's speed wanders between runs (on the 2-core VM of 2026-11-27, by up to a factor of two
// within a minute), so besides the mean and median over the runs the bench reports the minimum:
// the run least disturbed by the machine's other work.
double min_of(const std::vector<double>& v) { return *std::min_element(v.begin(), v.end()); }
void all_modules_runs(benchmark::internal::Benchmark* b) {
  b->Iterations(50000)->Repetitions(10)->ReportAggregatesOnly(true)->ComputeStatistics("min",
                                                                                       min_of);
}
BENCHMARK_CAPTURE(BM_GncTickAllModules, mekf_id_fdi_l1, true, AllocatorKind::kL1)
    ->Apply(all_modules_runs);
BENCHMARK_CAPTURE(BM_GncTickAllModules, mekf_id_fdi_pinv, true, AllocatorKind::kPseudoInverse)
    ->Apply(all_modules_runs);
BENCHMARK_CAPTURE(BM_GncTickAllModules, mekf_id_l1, false, AllocatorKind::kL1)
    ->Apply(all_modules_runs);

void BM_LawAlone(benchmark::State& state, LawId law) {
  const GncParams p = study_gnc_params(200.0);
  ControlLaws laws;
  laws.configure(law_gains(p), total_inertia(p.mass_hat), p.dt);
  laws.reset_state();
  LawInput in;
  in.omega = Vec3(1e-3, -2e-3, 5e-4);
  in.q = Vec3(0.05, 0.04, 0.03);
  in.ref.phase = ReferencePhase::kTrack;
  in.ref.q = {Vec3(0.04, 0.05, 0.02), Vec3(1e-4, -2e-4, 1e-4), Vec3(1e-7, 2e-7, -1e-7)};
  RateReference rr;
  for (auto _ : state) {
    benchmark::DoNotOptimize(in);
    Vec3 u = laws.compute(law, in, rr);
    benchmark::DoNotOptimize(u);
  }
}

BENCHMARK_CAPTURE(BM_LawAlone, ntcl, LawId::kNtcl);
BENCHMARK_CAPTURE(BM_LawAlone, el, LawId::kNtclEl);
BENCHMARK_CAPTURE(BM_LawAlone, integral, LawId::kIntegral);
BENCHMARK_CAPTURE(BM_LawAlone, adaptive, LawId::kAdaptive);
BENCHMARK_CAPTURE(BM_LawAlone, so3, LawId::kSo3);
BENCHMARK_CAPTURE(BM_LawAlone, dpd, LawId::kDpd);
BENCHMARK_CAPTURE(BM_LawAlone, feedforward, LawId::kFeedforward);

void BM_Allocate(benchmark::State& state) {
  const GncParams p = study_gnc_params(200.0);
  Allocator a;
  a.configure(torque_matrix(p.rcs, p.mass_hat.r_so_bcm), p.rcs.u_max);
  Vec3 uc(300.0, -150.0, 800.0);
  Vec8 u;
  AllocatorStatus st;
  for (auto _ : state) {
    benchmark::DoNotOptimize(uc);
    a.allocate(uc, u, st);
    benchmark::DoNotOptimize(u);
  }
}
BENCHMARK(BM_Allocate);

// The fuel-optimal allocation, Eq. (52), of the same request (pinv first, then the simplex).
void BM_AllocateL1(benchmark::State& state) {
  const GncParams p = study_gnc_params(200.0);
  Allocator a;
  a.configure(torque_matrix(p.rcs, p.mass_hat.r_so_bcm), p.rcs.u_max, AllocatorKind::kL1);
  Vec3 uc(300.0, -150.0, 800.0);
  Vec8 u;
  AllocatorStatus st;
  for (auto _ : state) {
    benchmark::DoNotOptimize(uc);
    a.allocate(uc, u, st);
    benchmark::DoNotOptimize(u);
  }
  state.counters["simplex_iterations"] = st.l1_iterations;
}
BENCHMARK(BM_AllocateL1);

// The L1 solve over a torque history, cold (every solve from u = 0) or warm (from the previous
// basis): arg 0 warm 0/1, arg 1 history 0 random directions and magnitudes (HOLD answering noise),
// 1 a request turning by 1 degree per tick (a despin).
void BM_L1Sequence(benchmark::State& state) {
  const GncParams p = study_gnc_params(200.0);
  const Mat38 b = torque_matrix(p.rcs, p.mass_hat.r_so_bcm);
  L1Allocation l1;
  l1.configure(b, p.rcs.u_max);
  l1.set_warm_start(state.range(0) != 0);
  std::vector<Vec3> taus;
  std::mt19937 rng(5);
  std::normal_distribution<double> n(0.0, 1.0);
  const Eigen::AngleAxisd step(M_PI / 180.0, Vec3(0.3, -0.5, 0.8).normalized());
  Vec3 turning = Vec3(300.0, -150.0, 800.0);
  for (int k = 0; k < 1024; ++k) {
    if (state.range(1) == 0) {
      Vec8 f;
      for (int i = 0; i < 8; ++i) f(i) = 0.3 * p.rcs.u_max * std::tanh(n(rng));
      taus.push_back(b * f);
    } else {
      turning = step * turning;
      taus.push_back(turning);
    }
  }
  std::size_t k = 0;
  long iterations = 0;
  long solves = 0;
  for (auto _ : state) {
    const L1Solution s = l1.solve(taus[k]);
    benchmark::DoNotOptimize(s.u);
    iterations += s.iterations;
    ++solves;
    k = (k + 1) % taus.size();
  }
  state.counters["mean_iterations"] = static_cast<double>(iterations) / static_cast<double>(solves);
  state.counters["warm_share"] =
      static_cast<double>(l1.start_counts().warm) /
      static_cast<double>(l1.start_counts().warm + l1.start_counts().cold);
}
BENCHMARK(BM_L1Sequence)->Args({0, 0})->Args({1, 0})->Args({0, 1})->Args({1, 1});

// Allocation under failure limits (arg 0: pinv, 1: L1): thruster 2 (channel 1 "+") stuck on with
// its bias torque, and pod 3's latch valve closed.
void BM_AllocateUnderLimits(benchmark::State& state) {
  const GncParams p = study_gnc_params(200.0);
  const Mat38 b = torque_matrix(p.rcs, p.mass_hat.r_so_bcm);
  Allocator a;
  a.configure(b, p.rcs.u_max,
              state.range(0) == 0 ? AllocatorKind::kPseudoInverse : AllocatorKind::kL1);
  AllocatorLimits lim = nominal_limits(p.rcs.u_max);
  lim.hi(1) = 0.0;
  lim.bias = p.rcs.u_max * b.col(1);
  lim.lo(6) = lim.hi(6) = lim.lo(7) = lim.hi(7) = 0.0;
  Vec3 uc(300.0, -150.0, 800.0);
  Vec8 u;
  AllocatorStatus st;
  for (auto _ : state) {
    benchmark::DoNotOptimize(uc);
    a.allocate(uc, lim, u, st);
    benchmark::DoNotOptimize(u);
  }
  state.counters["simplex_iterations"] = st.l1_iterations;
}
BENCHMARK(BM_AllocateUnderLimits)->Arg(0)->Arg(1);

}  // namespace

BENCHMARK_MAIN();
