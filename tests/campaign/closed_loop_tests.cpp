// The in-process closed loop: plant + flight core in lockstep over the study's cases.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <optional>
#include <string>
#include <utility>

#include <gtest/gtest.h>

#include "gnc/fdi/fault_detector.hpp"
#include "ground/campaign/estimation_report.hpp"
#include "ground/campaign/fsw_flight_side.hpp"
#include "ground/campaign/runner.hpp"
#include "ground/config/config.hpp"
#include "ground/plant/plant.hpp"

namespace rocksteady::campaign {
namespace {

const std::string kConfigs = std::string(ROCKSTEADY_SOURCE_DIR) + "/configs";

config::RunSetup load(int n) {
  return config::load_run(kConfigs + "/mission.yaml", kConfigs + "/gnc.yaml",
                          kConfigs + "/cases/case" + std::to_string(n) + ".yaml");
}

// Adds a thruster fault to the truth of s (the flight never sees it) and returns it.
plant::ThrusterFault inject(config::RunSetup& s, int thruster, plant::FaultKind kind, double onset_s) {
  plant::ThrusterFault f;
  f.thruster = thruster;
  f.kind = kind;
  f.onset_s = onset_s;
  s.truth.faults.push_back(f);
  return f;
}

RunResult run(const config::RunSetup& s, const std::string& strategy, double log_interval = 0.0,
              double duration = -1.0) {
  GncFlightSide flight;
  RunOptions opt;
  opt.log_interval_s = log_interval;
  opt.duration_s = duration;
  return run_closed_loop(s, *parse_strategy(strategy), flight, nullptr, opt);
}

TEST(ClosedLoop, DpdDespinsAndReachesTheAttitudeGoalInCase1) {
  const config::RunSetup s = load(1);
  const RunResult r = run(s, "dpd");
  ASSERT_EQ(r.status, RunStatus::kOk) << r.note;
  EXPECT_EQ(r.sim_s, s.duration_s);
  // SPEC §5 goals at the end of the run, on the TRUE state.
  EXPECT_LE(r.final_rate_rad_s, 1e-4);
  EXPECT_LE(r.final_q_error, 1e-2);
  ASSERT_TRUE(r.t_omega_conv_s.has_value());
  ASSERT_TRUE(r.t_q_conv_s.has_value());
  EXPECT_GT(*r.t_omega_conv_s, 0.0);
  EXPECT_LT(*r.t_q_conv_s, s.duration_s);
  // Despin burns fuel; the attitude is reached after (or with) the despin in this case.
  EXPECT_GT(*r.fuel_at_t_omega_kg, 0.0);
  EXPECT_LE(*r.fuel_at_t_omega_kg, r.total_fuel_kg);
  EXPECT_LE(*r.fuel_at_t_q_kg, r.total_fuel_kg);
  EXPECT_EQ(r.final_mode, "HOLD");  // the core switched DETUMBLE -> HOLD (Eq. 51)
  // Perfect model: B_hat = B, the allocator stays within u_max, so the flight software's fuel
  // estimate (Eq. 54 on its commands) equals the plant's fuel (Eq. 54 on the applied forces).
  EXPECT_EQ(r.clipped_ticks, 0u);
  EXPECT_NEAR(r.fuel_hat_kg, r.total_fuel_kg, 1e-9 * r.total_fuel_kg);
  // The initial rate is the largest a damping law ever sees.
  EXPECT_NEAR(r.max_rate_rad_s, s.truth.omega0.norm(), 1e-9);
}

TEST(ClosedLoop, FeedforwardCancellationCostsMoreThanNtclInCase4) {
  // The study's Example 1: with a 10 % inertia error, cancelling S(J_hat w) w turns dJ w x w into
  // a disturbance; the robust NTCL does not cancel it.
  const config::RunSetup s = load(4);
  const RunResult ntcl = run(s, "ntcl+dpd_ref");
  const RunResult ff = run(s, "feedforward+dpd_ref");
  ASSERT_EQ(ntcl.status, RunStatus::kOk);
  ASSERT_EQ(ff.status, RunStatus::kOk);
  EXPECT_TRUE(ff.total_fuel_kg > ntcl.total_fuel_kg || ff.saturated_ticks > ntcl.saturated_ticks)
      << "feed-forward " << ff.total_fuel_kg << " kg, NTCL " << ntcl.total_fuel_kg << " kg";
  EXPECT_GT(ff.total_fuel_kg, ntcl.total_fuel_kg);
  // NTCL tracking the D+PD-based reference still meets both goals in case 4.
  EXPECT_TRUE(ntcl.t_omega_conv_s.has_value());
  EXPECT_TRUE(ntcl.t_q_conv_s.has_value());
}

TEST(ClosedLoop, FuelOptimalWithoutATrajectoryReportsNoReference) {
  const config::RunSetup s = load(1);
  const RunResult r = run(s, "ntcl+fuel_optimal");
  EXPECT_EQ(r.status, RunStatus::kNoReference);
  EXPECT_FALSE(r.note.empty());
  EXPECT_EQ(r.ticks, 0u);
  EXPECT_FALSE(r.t_omega_conv_s.has_value());
  EXPECT_FALSE(r.t_q_conv_s.has_value());
  EXPECT_EQ(r.total_fuel_kg, 0.0);
}

// A simple uplinkable rate profile: omega_d decays linearly from the initial rate to rest.
gnc::TrajectoryTable linear_despin(const Eigen::Vector3d& omega0, double t_final) {
  gnc::TrajectoryTable table;
  table.count = 201;
  for (int i = 0; i < table.count; ++i) {
    gnc::TrajectorySample& s = table.samples[static_cast<std::size_t>(i)];
    s.t = t_final * i / (table.count - 1);
    s.omega_d = omega0 * (1.0 - s.t / t_final);
    s.omega_d_dot = -omega0 / t_final;
  }
  table.samples[static_cast<std::size_t>(table.count - 1)].omega_d.setZero();
  table.checksum = gnc::trajectory_checksum(table);
  return table;
}

TEST(ClosedLoop, FuelOptimalStrategyFollowsAnUplinkedTrajectoryInTrack) {
  const config::RunSetup s = load(1);
  const gnc::TrajectoryTable table = linear_despin(s.truth.omega0, 5000.0);
  ASSERT_EQ(gnc::validate_trajectory(table, s.flight.guidance.eps_trans), gnc::TrajectoryError::kOk);
  GncFlightSide flight;
  RunOptions opt;
  opt.log_interval_s = 100.0;
  const RunResult r =
      run_closed_loop(s, *parse_strategy("ntcl+fuel_optimal"), flight, &table, opt);
  ASSERT_EQ(r.status, RunStatus::kOk) << r.note;
  EXPECT_EQ(r.final_mode, "TRACK");
  EXPECT_EQ(r.series.front().mode, gnc::Mode::kTrack);  // entered on the first tick
  // The body follows the decaying profile (with the law's lag): slower half-way, at rest later.
  const TimeRow& mid = r.series[25];
  ASSERT_NEAR(mid.t, 2500.0, 1e-9);
  EXPECT_LT(mid.omega.norm(), 0.75 * s.truth.omega0.norm());
  for (const TimeRow& row : r.series) EXPECT_EQ(row.mode, gnc::Mode::kTrack);
  ASSERT_TRUE(r.t_omega_conv_s.has_value());
  EXPECT_LE(r.final_rate_rad_s, 1e-4);
  EXPECT_GT(r.total_fuel_kg, 0.0);
}

TEST(ClosedLoop, SameSeedSameBits) {
  const config::RunSetup s = load(7);  // noise, disturbance, model error: every stream in play
  const RunResult a = run(s, "ntcl+dpd_ref", 1.0, 600.0);
  const RunResult b = run(s, "ntcl+dpd_ref", 1.0, 600.0);
  ASSERT_EQ(a.series.size(), b.series.size());
  ASSERT_GT(a.series.size(), 500u);
  for (std::size_t i = 0; i < a.series.size(); ++i) {
    ASSERT_EQ(std::memcmp(a.series[i].omega.data(), b.series[i].omega.data(), 3 * sizeof(double)), 0);
    ASSERT_EQ(std::memcmp(a.series[i].q_hat.data(), b.series[i].q_hat.data(), 3 * sizeof(double)), 0);
    ASSERT_EQ(std::memcmp(a.series[i].force.data(), b.series[i].force.data(), 8 * sizeof(double)), 0);
  }
  EXPECT_EQ(a.total_fuel_kg, b.total_fuel_kg);
  // A different seed gives a different noisy run.
  config::RunSetup other = s;
  other.truth.seed += 1;
  const RunResult c = run(other, "ntcl+dpd_ref", 1.0, 600.0);
  EXPECT_NE(c.total_fuel_kg, a.total_fuel_kg);
}

// A flight side that never fires: the plant coasts torque-free (no disturbance in this setup). It
// sees the plant only through the harness's ports.
class SilentFlight final : public FlightSide {
 public:
  void setup(const FlightSetup& s, hal::SensorSource& sensors, hal::ThrusterSink& thrusters) override {
    ++setups;
    start = s.start_mode;
    sensors_ = &sensors;
    thrusters_ = &thrusters;
  }
  void step() override {
    hal::RawSensors frame;
    EXPECT_TRUE(sensors_->poll(frame));  // one frame per tick, in lockstep
    EXPECT_FALSE(sensors_->poll(frame));  // and only one
    EXPECT_EQ(frame.seq, steps);
    EXPECT_NEAR(frame.t, 0.1 * steps, 1e-9);
    ++steps;
    hal::ThrusterOutputs o;
    o.on.fill(true);
    o.force.fill(50.0);
    o.enabled = false;  // inhibited: the plant must not fire
    thrusters_->write(o, frame.seq, frame.t);
  }
  const gnc::GncOutput& output() const override { return out_; }
  std::string name() const override { return "silent"; }
  int setups{0};
  int steps{0};
  gnc::Mode start{gnc::Mode::kIdle};

 private:
  hal::SensorSource* sensors_{nullptr};
  hal::ThrusterSink* thrusters_{nullptr};
  gnc::GncOutput out_{};
};

TEST(ClosedLoop, RunnerDrivesAnyFlightSideInLockstep) {
  config::RunSetup s = load(1);
  s.truth.disturbance.sigma_nm = 0.0;
  SilentFlight flight;
  RunOptions opt;
  opt.duration_s = 100.0;
  opt.log_interval_s = 10.0;
  const RunResult r = run_closed_loop(s, *parse_strategy("ntcl+dpd_ref"), flight, nullptr, opt);
  EXPECT_EQ(flight.setups, 1);
  EXPECT_EQ(flight.steps, 1000);
  EXPECT_EQ(flight.start, gnc::Mode::kDetumble);
  EXPECT_EQ(r.ticks, 1000u);
  EXPECT_EQ(r.total_fuel_kg, 0.0);
  EXPECT_FALSE(r.t_omega_conv_s.has_value());  // still tumbling
  EXPECT_EQ(r.series.size(), 11u);             // t = 0, 10, ..., 90 and the final state
  // Torque-free: |H| and energy kept (the plant's own check, seen through the runner).
  const Eigen::Matrix3d j = gnc::total_inertia(s.truth.mass);
  const Eigen::Vector3d w0 = s.truth.omega0, w1 = r.series.back().omega;
  EXPECT_NEAR(w1.dot(j * w1), w0.dot(j * w0), 1e-9 * w0.dot(j * w0));
}

// Issue 18's strength target is counted from each thruster's first firing: the campaign's first
// firing, reached flag and impulse to the mark are recounted here from the per-tick series (the
// commanded channel forces; no fault, every valve open) in case 1 with a 2 % strength spread.
TEST(ClosedLoop, EachThrustersStrengthIsScored600sAfterItsFirstCommandedFiring) {
  config::RunSetup s = load(1);
  for (int i = 0; i < 16; ++i) s.truth.thruster_strength(i) = 1.0 + 0.02 * ((i % 3) - 1);
  const double dt = s.flight.dt;
  const RunResult r = run(s, "ntcl+dpd_ref:id", dt, 1200.0);
  ASSERT_EQ(r.status, RunStatus::kOk) << r.note;
  ASSERT_EQ(r.estimation.strengths.size(), 16u);
  const double t_last = r.series.back().t;
  int reached = 0;
  for (int i = 0; i < 16; ++i) {
    const int c = i / 2;
    std::optional<double> first;
    double impulse = 0.0;
    for (const TimeRow& row : r.series) {
      const double half = i % 2 == 0 ? std::max(row.force(c), 0.0) : std::max(-row.force(c), 0.0);
      if (!first && half > 0.0) first = row.t;
      if (first && row.t < *first + kStrengthMarkAfterFiringS - 1e-9) impulse += half * dt;
    }
    const StrengthMark& m = r.estimation.strengths[static_cast<std::size_t>(i)];
    ASSERT_EQ(m.first_fired_s.has_value(), first.has_value()) << "thruster " << i;
    if (!first) {
      EXPECT_FALSE(m.reached);
      continue;
    }
    EXPECT_NEAR(*m.first_fired_s, *first, 1e-6) << "thruster " << i;
    EXPECT_EQ(m.reached, *first + kStrengthMarkAfterFiringS <= t_last + 1e-6) << "thruster " << i;
    if (!m.reached) continue;
    ++reached;
    EXPECT_NEAR(m.impulse_ns, impulse, 1e-6 * impulse + 1e-9) << "thruster " << i;
    EXPECT_GT(m.sigma, 0.0);
    EXPECT_TRUE(std::isfinite(m.err));
    std::printf("thruster %2d: first fired %6.1f s, %8.0f N s to its mark, |k^-k| %.4f (1 sigma "
                "%.4f)%s\n",
                i, *first, m.impulse_ns, m.err, m.sigma, m.confident ? ", confident" : "");
  }
  EXPECT_GT(reached, 0) << "no thruster reached its mark in 1200 s";
  // A restarted dispersion reads them back from the draw's JSON.
  const EstimationReport back = estimation_from_json(estimation_json(r.estimation));
  ASSERT_EQ(back.strengths.size(), 16u);
  for (std::size_t i = 0; i < 16; ++i) {
    EXPECT_EQ(back.strengths[i].first_fired_s, r.estimation.strengths[i].first_fired_s);
    EXPECT_EQ(back.strengths[i].reached, r.estimation.strengths[i].reached);
    EXPECT_EQ(back.strengths[i].err, r.estimation.strengths[i].err);
    EXPECT_EQ(back.strengths[i].sigma, r.estimation.strengths[i].sigma);
    EXPECT_EQ(back.strengths[i].confident, r.estimation.strengths[i].confident);
    EXPECT_EQ(back.strengths[i].impulse_ns, r.estimation.strengths[i].impulse_ns);
  }
}

// The detection the dispersion report gives for a stuck-on jet (the first window above the no-fault
// bound at or after onset), against the per-tick series: thruster 0 stuck on at 3000 s in case 1.
// With the window's own test only (F33 off), the window's chi-square shows in the telemetry on the
// first of its evaluation steps and the suspicion is counted on its decision, kEvaluationSteps - 1
// updates later. With gnc.yaml's early detection, sooner: within the window the fault starts in.
TEST(ClosedLoop, AStuckOnJetsDetectionIsTheFirstWindowAboveTheBoundAfterOnset) {
  std::optional<double> detected[2];
  for (int early = 0; early < 2; ++early) {
    config::RunSetup s = load(1);
    ASSERT_GT(s.flight.fdi.detect_early_ticks, 0) << "gnc.yaml's early detection";
    if (early == 0) s.flight.fdi.detect_early_ticks = 0;
    const plant::ThrusterFault f = inject(s, 0, plant::FaultKind::kStuckOn, 3000.0);
    const double dt = s.flight.dt;
    const RunResult r = run(s, "ntcl+dpd_ref:id:fdi", dt, 3060.0);
    ASSERT_EQ(r.status, RunStatus::kOk) << r.note;
    ASSERT_TRUE(r.fdi.fault_detected_s.has_value());
    ASSERT_TRUE(r.fdi.first_confirmation_s.has_value());
    EXPECT_EQ(r.fdi.thruster, 0);
    EXPECT_LE(*r.fdi.fault_detected_s, *r.fdi.first_confirmation_s);
    EXPECT_GE(*r.fdi.fault_detected_s, f.onset_s);
    detected[early] = r.fdi.fault_detected_s;
    if (early == 0) {
      std::optional<double> shown;
      for (const TimeRow& row : r.series) {
        if (row.t >= f.onset_s - 1e-9 && row.fdi_chi2 > s.flight.fdi.suspect_chi2) {
          shown = row.t;
          break;
        }
      }
      ASSERT_TRUE(shown.has_value()) << "no window above the bound after onset";
      EXPECT_GE(*r.fdi.fault_detected_s, *shown - 1e-9);
      EXPECT_LE(*r.fdi.fault_detected_s,
                *shown + (gnc::FaultDetector::kEvaluationSteps - 1) * dt + 1e-9);
    } else {
      EXPECT_LT(*r.fdi.fault_detected_s - f.onset_s, s.flight.fdi.window_ticks * dt);
    }
    const FdiReport back = fdi_from_json(fdi_json(r.fdi));
    EXPECT_EQ(back.fault_detected_s, r.fdi.fault_detected_s);
  }
  EXPECT_LT(*detected[1], *detected[0]);
}

}  // namespace
}  // namespace rocksteady::campaign

namespace rocksteady::campaign {
namespace {

// The campaign flies the flight application (executive, commanding, uplink) through the in-process
// HAL. It must reproduce the bare core's closed loop: the only difference is that the start mode is a
// ground command, applied one tick (0.1 s) later than the core-only harness requests it.
TEST(ClosedLoop, FlightApplicationThroughHalMatchesTheCoreAlone) {
  const config::RunSetup s = config::load_run(
      std::string(ROCKSTEADY_SOURCE_DIR) + "/configs/mission.yaml",
      std::string(ROCKSTEADY_SOURCE_DIR) + "/configs/gnc.yaml",
      std::string(ROCKSTEADY_SOURCE_DIR) + "/configs/cases/case1.yaml");
  RunOptions opt;
  opt.duration_s = 40000.0;
  GncFlightSide core;
  FswFlightSide app;
  const RunResult a = run_closed_loop(s, *parse_strategy("ntcl+dpd_ref"), core, nullptr, opt);
  const RunResult b = run_closed_loop(s, *parse_strategy("ntcl+dpd_ref"), app, nullptr, opt);
  ASSERT_EQ(a.status, RunStatus::kOk) << a.note;
  ASSERT_EQ(b.status, RunStatus::kOk) << b.note;
  ASSERT_TRUE(a.t_omega_conv_s.has_value() && b.t_omega_conv_s.has_value());
  EXPECT_NEAR(*b.t_omega_conv_s, *a.t_omega_conv_s, 0.002 * *a.t_omega_conv_s);
  EXPECT_NEAR(b.total_fuel_kg, a.total_fuel_kg, 0.002 * a.total_fuel_kg);
  EXPECT_EQ(b.final_mode, "HOLD");
}

}  // namespace
}  // namespace rocksteady::campaign

#include "ground/campaign/trajectory_source.hpp"

namespace rocksteady::campaign {
namespace {

// Issue: the fuel-optimal reference end to end. Case 1 is planned (Eq. 44) for the flight software's
// model, uplinked in chunks to the flight application and flown in TRACK (Eqs. 45-48): it despins
// and reaches the attitude goal, and the plan's fuel is below what plain D+PD burns on the same case.
TEST(ClosedLoop, PlannedCase1TrackDespinsReachesTheGoalAndPlansLessFuelThanDpd) {
  ASSERT_TRUE(have_planner()) << "this build has no ground/planner";
  const config::RunSetup s = config::load_run(
      std::string(ROCKSTEADY_SOURCE_DIR) + "/configs/mission.yaml",
      std::string(ROCKSTEADY_SOURCE_DIR) + "/configs/gnc.yaml",
      std::string(ROCKSTEADY_SOURCE_DIR) + "/configs/cases/case1.yaml");
  auto source = make_default_trajectory_source();
  PlanRequest req;
  req.setup = &s;
  req.model = s.flight;
  req.omega_init = s.truth.omega0;  // case 1: perfect gyro, so this is the first measurement
  const PlanOutcome plan = source->plan(req);
  ASSERT_NE(plan.table, nullptr) << plan.note;
  const double planned_fuel = std::stod(plan.note.substr(plan.note.find("planned fuel ") + 13));

  RunOptions opt;
  FswFlightSide app;
  const RunResult track =
      run_closed_loop(s, *parse_strategy("ntcl+fuel_optimal"), app, plan.table.get(), opt);
  ASSERT_EQ(track.status, RunStatus::kOk) << track.note;
  EXPECT_EQ(track.final_mode, "TRACK");
  ASSERT_TRUE(track.t_omega_conv_s.has_value());
  ASSERT_TRUE(track.t_q_conv_s.has_value());
  EXPECT_LE(track.final_rate_rad_s, 1e-4);  // SPEC §5 goals on the true state
  EXPECT_LE(track.final_q_error, 1e-2);
  EXPECT_LE(track.max_rate_rad_s, s.flight.guidance.eps_trans);

  GncFlightSide core;
  const RunResult dpd = run_closed_loop(s, *parse_strategy("dpd"), core, nullptr, opt);
  ASSERT_EQ(dpd.status, RunStatus::kOk) << dpd.note;
  EXPECT_LT(planned_fuel, dpd.total_fuel_kg);
}

// gnc/fdi/README.md (F9, F15): a thruster stuck on in HOLD (case 1, thruster 0 at 50 000 s), with
// the flight's identification and fault detection. In HOLD the scores alone leave it ambiguous
// against a stuck-off jet on another pod; the isolation test closes pod 0, the motion stops, and
// it comes back when the valve reopens: confirmed to thruster 0 within seconds, and the fuel of
// the fault-free run within 2 kg. (Before F15 the test restarted before the valve reopened, so it
// never ended and nothing was confirmed; with the valve reopened but no verdict, the scores took
// 1 061 s and 50 kg.)
TEST(ClosedLoop, AThrusterStuckOnInHoldIsConfirmedByTheIsolationTest) {
  config::RunSetup s = load(1);
  s.duration_s = 50200.0;
  const RunResult healthy = run(s, "ntcl+dpd_ref:id:fdi");
  ASSERT_EQ(healthy.status, RunStatus::kOk) << healthy.note;
  EXPECT_EQ(healthy.fdi.confirmations, 0);
  EXPECT_EQ(healthy.final_mode, std::string("HOLD"));
  const plant::ThrusterFault f = inject(s, 0, plant::FaultKind::kStuckOn, 50000.0);
  const RunResult r = run(s, "ntcl+dpd_ref:id:fdi");
  ASSERT_EQ(r.status, RunStatus::kOk) << r.note;
  ASSERT_TRUE(r.fdi.first_confirmation_s.has_value()) << "never confirmed";
  EXPECT_EQ(r.fdi.thruster, 0);
  EXPECT_EQ(r.fdi.kind, "stuck-on");
  EXPECT_EQ(r.fdi.confirmations, 1);
  EXPECT_LE(*r.fdi.first_confirmation_s - f.onset_s, 20.0);
  EXPECT_LT(r.total_fuel_kg - healthy.total_fuel_kg, 2.0);
}

// A study case with `thruster` stuck on at 10 000 s and the onset window scored (F21 off), flown
// 20 s with one detector switch on (gnc.yaml) and off: each run confirms that jet stuck on, once;
// returns the two latencies from onset (switch on, switch off).
std::pair<double, double> stuck_on_latency_with_and_without(int case_number, int thruster,
                                                            bool gnc::FaultDetectorParams::*sw) {
  config::RunSetup s = load(case_number);
  EXPECT_TRUE(s.flight.fdi.*sw) << "gnc.yaml flies it";
  s.flight.fdi.skip_onset_window = false;
  const plant::ThrusterFault f = inject(s, thruster, plant::FaultKind::kStuckOn, 10000.0);
  s.flight.fdi.*sw = true;
  const RunResult on = run(s, "ntcl+dpd_ref:id:fdi", 0.0, 10020.0);
  s.flight.fdi.*sw = false;
  const RunResult off = run(s, "ntcl+dpd_ref:id:fdi", 0.0, 10020.0);
  double latency[2] = {1e9, 1e9};
  int i = 0;
  for (const RunResult* r : {&on, &off}) {
    EXPECT_EQ(r->status, RunStatus::kOk) << r->note;
    EXPECT_TRUE(r->fdi.first_confirmation_s.has_value()) << "never confirmed";
    EXPECT_EQ(r->fdi.thruster, thruster);
    EXPECT_EQ(r->fdi.kind, "stuck-on");
    EXPECT_EQ(r->fdi.confirmations, 1);
    if (r->fdi.first_confirmation_s) latency[i] = *r->fdi.first_confirmation_s - f.onset_s;
    ++i;
  }
  return {latency[0], latency[1]};
}

// (F40) Case 5, thruster 2 (pod 0, +z) stuck on mid-despin. Its mirror on the opposite pod,
// thruster 11 (pod 2, -z), pushes the body the same way up to the centre of mass's xy offset, and
// the first window after onset leads with the mirror: the isolation test closes pod 2. Thruster
// 2 fires on through pod 0's open valve, and that closed window names it (F40): confirmed on
// the update the test's closure ends, within the 3 s. Read only on the reopened window
// (F40 off), the test is followed by a test of pod 0 and the confirmation comes seconds later.
// The onset window scored (F21 off), as the dispersion measured it; with gnc.yaml's F21 the first
// test starts a window later and (F40) saves the same reopened window (3.8 s against 4.8).
TEST(ClosedLoop, AStuckOnJetSeenFiringBehindAnotherPodsClosedValveIsNamedByThatTest) {
  const auto [named, reopened] =
      stuck_on_latency_with_and_without(5, 2, &gnc::FaultDetectorParams::probe_read_elsewhere);
  EXPECT_LE(named, 3.0);
  EXPECT_GT(reopened, named + 1.0) << "the trap: without (F40) pod 0 is tested too";
}

// (F41) Case 4, thruster 7 (pod 1, -z) stuck on at 10 000 s, one tick before a window closes, the
// onset window scored (F21 off; with it, the one-tick window starts no episode at all). That
// window is suspicious with a stuck-off jet leading, and the episode (F25) starts with it; the jet
// leads the next window, but its episode sum carries the one-tick window's loss and (F8) finds it
// blocked by a stuck-off jet of its own pod, which no test separates. With the episode restarted
// for the new leader the next decision tests pod 1 and the closed window names the jet within the
// issue's 3 s; without, a window later.
TEST(ClosedLoop, AJetStuckOnJustBeforeAWindowClosesIsIsolatedWithinThreeSeconds) {
  const auto [restarted, kept] =
      stuck_on_latency_with_and_without(4, 7, &gnc::FaultDetectorParams::episode_restart_leader);
  EXPECT_LE(restarted, 3.0);
  EXPECT_GT(kept, restarted + 0.5)
      << "the trap: the episode kept, the confirmation comes a window later";
}

// The detector's counts are the whole flight's. The flight reconfigures the detector at every
// model adoption, which restarts its state; its counters go on (Gnc::apply_params carries them;
// before, they started again from zero and a run reported only its last adoption's share, here
// 10 of the 12 checks). Case 4, jet 1 stuck on from 60 s (its pod closed at 250 s), flown to
// 45 000 s and logged every second: the jet checks reported are the checks the log shows
// starting (a change of fdi_check_jet to a jet; a check lasts at least three 1 s windows, so
// every one is seen), across the run's model adoptions.
TEST(ClosedLoop, TheDetectorCountsEveryJetCheckOfTheFlightAcrossModelAdoptions) {
  config::RunSetup s = load(4);
  inject(s, 1, plant::FaultKind::kStuckOn, 60.0);
  const RunResult r = run(s, "ntcl+dpd_ref:id:fdi", 1.0, 45000.0);
  ASSERT_EQ(r.status, RunStatus::kOk) << r.note;
  ASSERT_EQ(r.fdi.thruster, 1);
  std::uint32_t starts = 0;
  double last_start = 0.0;
  int prev = -1;
  for (const TimeRow& row : r.series) {
    if (row.fdi_check_jet >= 0 && row.fdi_check_jet != prev) {
      ++starts;
      last_start = row.t;
    }
    prev = row.fdi_check_jet;
  }
  ASSERT_GE(starts, 2u) << "the premise: checks flown after the confirmation";
  EXPECT_GT(r.estimation.model_adoptions, 0u) << "the premise: the detector reconfigured";
  EXPECT_EQ(r.fdi.checks, starts) << "last check started at " << last_start << " s";
  EXPECT_LE(r.fdi.surveys, r.fdi.checks);
  std::printf("case 4, jet 1 stuck on from 60 s, 45 000 s: %u checks (%u surveys), %u model "
              "adoptions\n",
              r.fdi.checks, r.fdi.surveys, r.estimation.model_adoptions);
}

// (F42) Case 7 (the a-priori centre of mass 1 m off) in HOLD with the jet survey every 20 000 s
// (F36, in HOLD only, F43), flown to 45 000 s: its second round of survey checks, at about
// 40 000 s, fires jets at 100 N with a net force of up to 107 N (the axial jets) in the null space
// of some model of B. In the null space of the active table's B_hat (F42 off), whose centre of
// mass is the prior's, each check puts about 1 m x 107 N on the body and the rate, settled below
// 10^-5 rad/s, is kicked to most of the SPEC §7 bound (10^-4 rad/s). In the null space of the
// detector's model (the identified centre of mass, about 0.1 m off) the kick stays a fraction of
// it. The peak of |omega| (true) from 38 000 s on, against the same flight without a survey.
// (F49) gnc.yaml's survey there, whose checks are long windows at a few newtons (the gyro too
// noisy for 100 N checks within the kick bound, F48), stays as settled as no survey at all.
TEST(ClosedLoop, SurveyChecksInTheIdentifiedModelsNullSpaceDoNotKickTheRate) {
  config::RunSetup s = load(7);
  EXPECT_TRUE(s.flight.fdi.check_model_null_space) << "gnc.yaml flies it";
  EXPECT_TRUE(s.flight.fdi.survey_hold_only) << "gnc.yaml flies it";
  const double bound = 1e-4;  // mission.yaml goals.omega_tol_rad_s
  const auto peak = [](const RunResult& r) {
    double m = 0.0;
    for (const TimeRow& row : r.series) {
      if (row.t >= 38000.0) m = std::max(m, row.omega.norm());
    }
    return m;
  };
  EXPECT_GT(s.flight.fdi.check_long_ticks, 0) << "gnc.yaml flies it";
  const RunResult longs = run(s, "ntcl+dpd_ref:id:fdi", 1.0, 45000.0);
  s.flight.fdi.survey_interval_s = 0.0;
  const RunResult quiet = run(s, "ntcl+dpd_ref:id:fdi", 1.0, 45000.0);
  s.flight.fdi.survey_interval_s = 20000.0;
  s.flight.fdi.survey_max_kick_rad_s = 0.0;  // (F44) off: the move alone
  const RunResult model = run(s, "ntcl+dpd_ref:id:fdi", 1.0, 45000.0);
  s.flight.fdi.check_model_null_space = false;
  const RunResult table = run(s, "ntcl+dpd_ref:id:fdi", 1.0, 45000.0);
  for (const RunResult* r : {&longs, &quiet, &model, &table}) {
    ASSERT_EQ(r->status, RunStatus::kOk) << r->note;
    EXPECT_EQ(r->fdi.confirmations, 0);
    EXPECT_EQ(r->final_mode, "HOLD");
  }
  EXPECT_EQ(quiet.fdi.surveys, 0u);
  EXPECT_GE(longs.fdi.surveys, 16u) << "long checks";
  EXPECT_GE(model.fdi.surveys, 16u) << "two rounds, each jet at most once a round";
  EXPECT_GE(table.fdi.surveys, 16u);
  std::printf("case 7, peak |omega| from 38 000 s: no survey %.3g, long checks %.3g, survey in the "
              "model's null space %.3g, in the table's %.3g rad/s\n",
              peak(quiet), peak(longs), peak(model), peak(table));
  EXPECT_LT(peak(quiet), 0.15 * bound) << "the premise: settled well inside the bound";
  EXPECT_LT(peak(longs), 0.15 * bound);
  EXPECT_LT(peak(model), 0.25 * bound);
  EXPECT_GT(peak(table), 0.5 * bound)
      << "the trap: checks against the prior's centre of mass kick the rate";
}

// (F44) Case 1, thruster 4 stuck off at 10 000 s, the jet survey every 20 000 s in HOLD. The fault
// is confirmed in the despin, and the identifier restarts from its prior (I27 off): in HOLD its
// centre of mass is metres off. A survey check in that model's null space then puts its error
// times the check's net force on the body: the rate leaves the SPEC §7 bound late in the flight
// and converges again only after 80 000 s (before F55, whose move holds the latched channel
// still, never: the attitude goal was missed too). With the check held back while 3 sigma of its
// kick exceeds half the rate bound (gnc.yaml: 5e-5 rad/s), both goals are met as without a
// survey, t_omega,conv before 30 000 s. (F59) holds every check back after a fault while the
// model's J is not known to 1 % again: with it alone (no kick bound) the goals are met too, and
// the trap needs both off.
TEST(ClosedLoop, NoSurveyCheckKicksTheRateAgainstAModelRestartedByAFault) {
  config::RunSetup s = load(1);
  EXPECT_GT(s.flight.fdi.survey_max_kick_rad_s, 0.0) << "gnc.yaml flies it";
  EXPECT_GT(s.flight.fdi.after_fault_max_j_rel, 0.0) << "gnc.yaml flies it";
  inject(s, 4, plant::FaultKind::kStuckOff, 10000.0);
  s.flight.fdi.survey_interval_s = 20000.0;
  const RunResult gated = run(s, "ntcl+dpd_ref:id:fdi");
  s.flight.fdi.survey_max_kick_rad_s = 0.0;
  const RunResult unconfident = run(s, "ntcl+dpd_ref:id:fdi");
  s.flight.fdi.after_fault_max_j_rel = 0.0;
  const RunResult open = run(s, "ntcl+dpd_ref:id:fdi");
  std::printf("surveys: kick bound %u, (F59) alone %u, neither %u\n", gated.fdi.surveys,
              unconfident.fdi.surveys, open.fdi.surveys);
  for (const RunResult* r : {&gated, &unconfident, &open}) {
    ASSERT_EQ(r->status, RunStatus::kOk) << r->note;
    EXPECT_EQ(r->fdi.thruster, 4);
    EXPECT_EQ(r->fdi.kind, "stuck-off");
    EXPECT_EQ(r->fdi.confirmations, 1);
    ASSERT_TRUE(r->fdi.first_confirmation_s.has_value());
    EXPECT_LT(*r->fdi.first_confirmation_s, 20000.0) << "confirmed in the despin";
    ASSERT_TRUE(r->t_omega_conv_s.has_value());
  }
  for (const RunResult* r : {&gated, &unconfident}) {
    EXPECT_TRUE(r->t_q_conv_s.has_value());
    EXPECT_LT(*r->t_omega_conv_s, 30000.0);
  }
  EXPECT_EQ(unconfident.fdi.surveys, 0u) << "(F59): no survey on the model restarted from its prior";
  EXPECT_GT(open.fdi.surveys, 0u);
  EXPECT_GT(*open.t_omega_conv_s, 60000.0) << "the trap: a late check kicks the rate out";
}

// The campaign's measure of how much a stuck-off jet was asked to fire after onset (the issue's
// latency "of commanded firing"): recomputed here from the run's per-tick time series (the
// commanded channel forces) for thruster 4 ("+" of channel 2, a jet the despin commands), stuck
// off at 3000 s in case 1.
TEST(ClosedLoop, TheFaultyJetsCommandedFiringIsMeasuredFromOnsetToTheConfirmation) {
  config::RunSetup s = load(1);
  const plant::ThrusterFault f = inject(s, 4, plant::FaultKind::kStuckOff, 3000.0);
  const double dt = s.flight.dt;
  const RunResult r = run(s, "ntcl+dpd_ref:id:fdi", dt, 5000.0);
  ASSERT_EQ(r.status, RunStatus::kOk) << r.note;
  ASSERT_FALSE(r.fdi.valve_closed_s.has_value()) << "a valve closed: the recount below assumes open";
  const double end =
      r.fdi.first_confirmation_s ? *r.fdi.first_confirmation_s : r.series.back().t + 1.0;
  std::optional<double> first;
  double seconds = 0.0, impulse = 0.0;
  // Every tick flown has a row; the series' last row is the final state after the last tick
  // (its command is the last tick's, already counted), so it is not a tick of its own.
  ASSERT_GE(r.series.size(), 2u);
  for (std::size_t i = 0; i + 1 < r.series.size(); ++i) {
    const TimeRow& row = r.series[i];
    const double half = std::max(row.force(2), 0.0);
    if (row.t < f.onset_s - 1e-9 || !(half > 0.0)) continue;
    if (!first) first = row.t;
    if (row.t <= end + 1e-9) {
      seconds += dt;
      impulse += half * dt;
    }
  }
  ASSERT_TRUE(first.has_value()) << "the despin never asked for thruster 4 after onset";
  std::printf("thruster 4 stuck off at 3000 s: first commanded at %.1f s, commanded %.1f s "
              "(%.1f N s) until %s %.1f s\n",
              *first, seconds, impulse, r.fdi.first_confirmation_s ? "confirmation at" : "the end,",
              end);
  ASSERT_TRUE(r.fdi.fault_first_commanded_s.has_value());
  EXPECT_NEAR(*r.fdi.fault_first_commanded_s, *first, 1e-6);
  EXPECT_NEAR(r.fdi.fault_commanded_s, seconds, 1e-6);
  EXPECT_NEAR(r.fdi.fault_commanded_impulse_ns, impulse, 1e-6 * impulse + 1e-9);
  EXPECT_GT(r.fdi.fault_commanded_impulse_ns, 0.0);
  // The JSON of a draw carries them (a restarted dispersion reads them back).
  const FdiReport back = fdi_from_json(fdi_json(r.fdi));
  EXPECT_EQ(back.fault_first_commanded_s, r.fdi.fault_first_commanded_s);
  EXPECT_EQ(back.fault_commanded_s, r.fdi.fault_commanded_s);
  EXPECT_EQ(back.fault_commanded_impulse_ns, r.fdi.fault_commanded_impulse_ns);
}

}  // namespace
}  // namespace rocksteady::campaign
