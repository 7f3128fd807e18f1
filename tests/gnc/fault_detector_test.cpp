// The thruster fault detector (gnc/fdi) against a separately written truth: the rigid body of
// tests/common driven by sixteen physical thrusters whose torques are written out here from the
// SPEC §4 geometry (not gnc/model), with stuck-on / stuck-off faults, a latch valve per pod and a
// noisy gyro. Every thruster and kind is isolated to the right one; healthy runs never confirm.
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <Eigen/SVD>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "gnc/fdi/fault_detector.hpp"
#include "gnc/model/mass_properties.hpp"
#include "rigid_body.hpp"

namespace rocksteady::gnc {
namespace {

using test::M3;
using test::V3;

constexpr double kUmax = 200.0;
constexpr double kDt = 0.1;

// SPEC §4 geometry written out: pod k at azimuth 45 + 90 k deg, radius 2.5 m, z = 3 m; thruster
// 4k fires +tangential, 4k+1 -tangential, 4k+2 +z, 4k+3 -z (channel c: thrusters 2c, 2c+1).
struct Truth {
  std::array<V3, 16> pos{};
  std::array<V3, 16> dir{};
  V3 r{0.3, -0.2, 0.1};  // r_SO/BCM
  test::RigidBody body;
  std::mt19937_64 rng{7};
  double gyro_sigma{3.1623e-6};  // case 5: sqrt(1e-12 / 0.1)
  int stuck_on{-1};
  int stuck_off{-1};
  int degraded{-1};  // this thruster produces degraded_factor of its commanded thrust
  double degraded_factor{0.5};
  std::array<bool, 4> valve{{true, true, true, true}};

  Truth() {
    for (int k = 0; k < 4; ++k) {
      const double th = M_PI / 4 + M_PI / 2 * k;
      const V3 p(2.5 * std::cos(th), 2.5 * std::sin(th), 3.0);
      const V3 tang(-std::sin(th), std::cos(th), 0.0);
      for (int q = 0; q < 4; ++q) pos[4 * k + q] = p;
      dir[4 * k] = tang;
      dir[4 * k + 1] = -tang;
      dir[4 * k + 2] = V3(0, 0, 1);
      dir[4 * k + 3] = V3(0, 0, -1);
    }
    body.j = total_inertia(study_true_mass_properties());
    body.omega = V3(0.01, 0.02, 0.03);
  }
  // Applies the commanded thrust for one tick, faults included; returns the thrust applied.
  void advance(const Vec16& cmd) {
    V3 tau = V3::Zero();
    for (int i = 0; i < 16; ++i) {
      if (!valve[static_cast<std::size_t>(i / 4)]) continue;
      double f = cmd(i);
      if (i == stuck_on) f = kUmax;
      if (i == stuck_off) f = 0.0;
      if (i == degraded) f *= degraded_factor;
      tau += (pos[static_cast<std::size_t>(i)] + r).cross(f * dir[static_cast<std::size_t>(i)]);
    }
    body.step(kDt, tau);
  }
  V3 gyro() {
    std::normal_distribution<double> n(0.0, gyro_sigma);
    return body.omega + V3(n(rng), n(rng), n(rng));
  }
};

// The truth's J and r as an identified model gives them (case 1 reaches ~3e-5 in J by 300 s).
FaultModel identified_model(const Truth& t) {
  FaultModel m;
  m.j = t.body.j;
  m.r = t.r;
  m.j_rel_sigma = 1e-4;
  m.r_cov = Mat3::Identity() * 1e-6;  // 1 mm
  m.k_sigma = 1e-3;
  return m;
}

// The detector as these tests fly it: on, windows of `window_ticks`, the truth's gyro noise and no
// external disturbance; each test sets what it is about on top.
FaultDetectorParams bank_params(double gyro_sigma, int window_ticks = 10) {
  FaultDetectorParams p;
  p.enabled = true;
  p.window_ticks = window_ticks;
  p.gyro_sigma = gyro_sigma;
  p.disturbance_sigma = 0.0;
  return p;
}

FaultDetector make_detector(const Truth& t, const FaultDetectorParams& p) {
  FaultDetector d;
  d.configure(p, study_rcs_layout(kUmax), kUmax, kDt);
  d.set_model(identified_model(t));
  return d;
}

// The check rig of (F31), (F34), (F35): partial losses on, and a check level low enough that the
// weak firing's noise starts checks of healthy jets.
FaultDetectorParams check_rig_params(const Truth& t) {
  FaultDetectorParams p = bank_params(t.gyro_sigma);
  p.degraded_min_loss = 0.1;
  p.check_llr = 0.5;
  return p;
}

FaultDetector make_detector(const Truth& t, double gyro_sigma, double degraded_min_loss = 0.0,
                            double check_llr = 0.0) {
  FaultDetectorParams p = bank_params(gyro_sigma);
  p.degraded_min_loss = degraded_min_loss;
  p.check_llr = check_llr;  // (F19) jet checks, off unless asked
  return make_detector(t, p);
}

// A firing pattern that keeps every thruster busy part of the time (as a despin does): each
// thruster on at 0..200 N with probability 0.5 per tick, the pair of a channel never both.
Vec16 random_firing(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Vec16 f = Vec16::Zero();
  for (int c = 0; c < 8; ++c) {
    const double x = u(rng);
    if (x < 0.25) f(2 * c) = kUmax * u(rng);
    else if (x < 0.5) f(2 * c + 1) = kUmax * u(rng);
  }
  return f;
}

struct RunResult {
  int confirmed_at{-1};  // tick
  int thruster{-1};
  FaultKind kind{FaultKind::kNone};
};

RunResult fly(Truth& t, FaultDetector& d, int ticks, int onset, int fault_on, int fault_off) {
  std::mt19937_64 cmd_rng(11);
  Vec16 prev = Vec16::Zero();
  RunResult r;
  for (int k = 0; k < ticks; ++k) {
    if (k == onset) {
      t.stuck_on = fault_on;
      t.stuck_off = fault_off;
    }
    FaultDetectorInput in;
    in.omega = t.gyro();
    in.omega_valid = true;
    in.thrust = prev;
    in.valve_open = t.valve;
    const FaultEvents e = d.update(in);
    if (e.confirmed && r.confirmed_at < 0) {
      r.confirmed_at = k;
      r.thruster = e.thruster;
      r.kind = e.kind;
    }
    const Vec16 cmd = random_firing(cmd_rng);
    t.advance(cmd);
    prev = cmd;
  }
  return r;
}

TEST(FaultDetector, HealthyFiringNeverConfirmsAFault) {
  for (double sigma : {3.1623e-6, 3.1623e-5}) {
    Truth t;
    t.gyro_sigma = sigma;
    FaultDetector d = make_detector(t, sigma);
    const RunResult r = fly(t, d, 20000, -1, -1, -1);  // 2000 s
    EXPECT_LT(r.confirmed_at, 0) << "false alarm: thruster " << r.thruster << " "
                                 << to_string(r.kind) << " at tick " << r.confirmed_at;
    EXPECT_EQ(d.confirmed_on() | d.confirmed_off(), 0);
    EXPECT_GT(d.status().windows, 1900u);
  }
}

TEST(FaultDetector, EveryStuckOnThrusterIsIsolatedToItself) {
  for (int i = 0; i < 16; ++i) {
    Truth t;
    FaultDetector d = make_detector(t, t.gyro_sigma);
    const RunResult r = fly(t, d, 250, 50, i, -1);  // isolated within 20 s of onset
    ASSERT_GE(r.confirmed_at, 0) << "thruster " << i;
    EXPECT_EQ(r.thruster, i);
    EXPECT_EQ(r.kind, FaultKind::kStuckOn) << "thruster " << i;
    EXPECT_EQ(d.confirmed_on(), 1u << i);
  }
}

TEST(FaultDetector, EveryStuckOffThrusterIsIsolatedToItselfWhileCommanded) {
  // A stuck-off jet shows only while commanded (a quarter of the ticks here, at half thrust on
  // average): the quieter gyro of the noise-free cases' floor (1e-6 rad/s per sample).
  for (int i = 0; i < 16; ++i) {
    Truth t;
    t.gyro_sigma = 1e-6;
    FaultDetector d = make_detector(t, t.gyro_sigma);
    const RunResult r = fly(t, d, 2050, 50, -1, i);  // isolated within 200 s of onset
    ASSERT_GE(r.confirmed_at, 0) << "thruster " << i << " best " << d.status().best << " llr "
                                 << d.status().best_llr << " runner-up " << d.status().runner_up_llr;
    EXPECT_EQ(r.thruster, i);
    EXPECT_EQ(r.kind, FaultKind::kStuckOff) << "thruster " << i;
    EXPECT_EQ(d.confirmed_off(), 1u << i);
  }
}

// A despin by D+PD commands every channel continuously at a few percent of u_max (4-15 N here,
// its sign and size held for 20 s, as the slowly turning torque command does). A stuck-off jet's
// signature in one 1 s window is then far below min_signature: the detector without (F11) never
// scores it. Pooled over windows (F11) it is isolated to itself; healthy, nothing is confirmed.
struct WeakFiring {
  std::mt19937_64 rng;
  Vec16 phase{Vec16::Zero()};
  explicit WeakFiring(std::uint64_t seed) : rng(seed) {}
  Vec16 next(int tick) {
    std::uniform_real_distribution<double> u(0.0, 1.0);
    if (tick % 200 == 0) {
      phase.setZero();
      for (int c = 0; c < 8; ++c) phase(2 * c + (u(rng) < 0.5 ? 0 : 1)) = 4.0 + 11.0 * u(rng);
    }
    Vec16 f = phase;
    for (int i = 0; i < 16; ++i) {
      if (f(i) > 0.0) f(i) *= 0.9 + 0.2 * u(rng);
    }
    return f;
  }
};

RunResult fly_weak(Truth& t, FaultDetector& d, int ticks, int onset, int fault_off,
                   std::uint64_t seed, int fault_on = -1) {
  WeakFiring firing(seed);
  Vec16 prev = Vec16::Zero();
  RunResult r;
  for (int k = 0; k < ticks; ++k) {
    if (k == onset) {
      t.stuck_off = fault_off;
      t.stuck_on = fault_on;
    }
    FaultDetectorInput in;
    in.omega = t.gyro();
    in.omega_valid = true;
    in.thrust = prev;
    const FaultEvents e = d.update(in);
    if (e.confirmed && r.confirmed_at < 0) {
      r.confirmed_at = k;
      r.thruster = e.thruster;
      r.kind = e.kind;
    }
    const Vec16 cmd = firing.next(k);
    t.advance(cmd);
    prev = cmd;
  }
  return r;
}

// (F21) A jet stuck on from inside a window: every jet, every onset phase of a 5-tick window,
// under the few-newton firing of HOLD (WeakFiring) and a quiet gyro. The window the fault starts
// in carries it for part of its ticks only, while every signature (F4) spans the whole window.
// Scored, that window makes some confirmations name a jet of another pod; not scored, every jet
// is confirmed to itself, one window later at most.
RunResult fly_onset_inside_window(int jet, int phase, bool skip_onset_window) {
  Truth t;
  t.gyro_sigma = 1e-7;  // the noise-free cases' floor (config: at least 1e-7 rad/s per sample)
  FaultDetectorParams p = bank_params(t.gyro_sigma, 5);
  p.skip_onset_window = skip_onset_window;
  FaultDetector d;
  d.configure(p, study_rcs_layout(kUmax), kUmax, kDt);
  d.set_model(identified_model(t));
  const int onset = 500 + phase;
  RunResult r = fly_weak(t, d, onset + 100, onset, -1, 31, jet);
  if (r.confirmed_at >= 0) r.confirmed_at -= onset;  // ticks after onset
  return r;
}

TEST(FaultDetector, TheWindowAFaultStartsInIsNotScoredAndNoJetOfAnotherPodIsConfirmed) {
  int wrong_scored = 0;
  double latency_scored = 0.0;
  double latency_skipped = 0.0;
  for (int jet = 0; jet < 16; ++jet) {
    for (int phase = 0; phase < 5; ++phase) {
      const RunResult scored = fly_onset_inside_window(jet, phase, false);
      ASSERT_GE(scored.confirmed_at, 0) << "jet " << jet << " phase " << phase;
      if (scored.thruster != jet) ++wrong_scored;
      latency_scored += scored.confirmed_at;
      const RunResult skipped = fly_onset_inside_window(jet, phase, true);
      ASSERT_GE(skipped.confirmed_at, 0) << "jet " << jet << " phase " << phase;
      EXPECT_EQ(skipped.thruster, jet) << "phase " << phase;
      EXPECT_EQ(skipped.kind, FaultKind::kStuckOn) << "jet " << jet << " phase " << phase;
      EXPECT_LE(skipped.confirmed_at, 30) << "jet " << jet << " phase " << phase;  // 3 s
      latency_skipped += skipped.confirmed_at;
    }
  }
  EXPECT_GT(wrong_scored, 0);  // the trap is there without (F21)
  // One window (5 ticks) later at most, on average over the 80 runs.
  EXPECT_LE(latency_skipped, latency_scored + 5.0 * 80.0);
  std::printf("onset inside a window: %d of 80 wrong when scored; mean latency %.1f -> %.1f ticks\n",
              wrong_scored, latency_scored / 80.0, latency_skipped / 80.0);
}

// (F41) A jet stuck on at the last tick of a 10-tick window, under HOLD's few-newton firing
// (WeakFiring), a quiet gyro and a model known as the identifier knows it mid-flight (its centre
// of mass to 3 cm, its strengths to 1 %). The window that closes one tick after onset carries a
// one-tick ramp; every signature (F4) spans the window, so the faulty jet's hypothesis loses
// almost what the next window gives it, and another hypothesis leads the suspicion that this
// window starts, with the episode (F25). In the next window the jet leads, with an episode sum
// that trails its score by that loss.
struct OnsetLeaderRun {
  RunResult r;
  std::uint32_t restarts{0};
  std::uint32_t probes{0};
};

// The rig's detector: gnc.yaml's one-window aligned tests, read on their closed window, against
// every jet's partial loss and naming another pod's jet; the episode restarts of (F25), (F38)
// and (F41); the centred gyro noise.
FaultDetectorParams onset_rig_params(double gyro_sigma) {
  FaultDetectorParams p = bank_params(gyro_sigma);
  p.episode_restart = true;
  p.episode_restart_stale = true;
  p.episode_restart_leader = true;
  p.probe_windows = 1;
  p.probe_aligned = true;
  p.probe_read_closed = true;
  p.probe_partial_rival = true;
  p.probe_read_elsewhere = true;
  p.centred_gyro_noise = true;
  return p;
}

// `jet` stuck on at update `onset`, flown 200 updates on; the latency counts from onset.
RunResult fly_onset_rig(const FaultDetectorParams& p, int jet, int onset,
                        FaultDetectorStatus* status, double r_sigma = 0.03,
                        const Vec3& r_error = Vec3::Zero()) {
  Truth t;
  t.gyro_sigma = p.gyro_sigma;
  FaultDetector d;
  d.configure(p, study_rcs_layout(kUmax), kUmax, kDt);
  FaultModel m = identified_model(t);
  m.r_cov = Mat3::Identity() * (r_sigma * r_sigma);
  m.r += r_error;
  m.k_sigma = 0.01;
  d.set_model(m);
  RunResult r = fly_weak(t, d, onset + 200, onset, -1, 31, jet);
  if (r.confirmed_at >= 0) r.confirmed_at -= onset;
  *status = d.status();
  return r;
}

OnsetLeaderRun fly_onset_leader(int jet, bool restart_leader, int onset = 509) {
  FaultDetectorParams p = onset_rig_params(1e-7);
  p.episode_restart_leader = restart_leader;
  FaultDetectorStatus st;
  OnsetLeaderRun out;
  out.r = fly_onset_rig(p, jet, onset, &st);
  out.restarts = st.episode_restarts;
  out.probes = st.probes;
  return out;
}

TEST(FaultDetector, ANewLeaderWhoseFaultBeganAfterTheEpisodeStartedRestartsIt) {
  int confirmed_before = 0, confirmed_now = 0, changed = 0, wrong_before = 0, wrong_now = 0;
  double latency_before = 0.0, latency_now = 0.0;  // over the runs right in both
  for (int jet = 0; jet < 16; ++jet) {
    for (int onset = 500; onset < 510; ++onset) {  // every phase of the window
      const OnsetLeaderRun before = fly_onset_leader(jet, false, onset);
      const OnsetLeaderRun now = fly_onset_leader(jet, true, onset);
      const bool right_before = before.r.confirmed_at >= 0 && before.r.thruster == jet &&
                                before.r.kind == FaultKind::kStuckOn;
      const bool right_now = now.r.confirmed_at >= 0 && now.r.thruster == jet &&
                             now.r.kind == FaultKind::kStuckOn;
      if (before.r.confirmed_at >= 0) ++confirmed_before;
      if (now.r.confirmed_at >= 0) ++confirmed_now;
      wrong_before += before.r.confirmed_at >= 0 && !right_before ? 1 : 0;
      wrong_now += now.r.confirmed_at >= 0 && !right_now ? 1 : 0;
      // The restart never turns a right isolation wrong, nor loses one.
      if (right_before) {
        EXPECT_TRUE(right_now) << "jet " << jet << " onset " << onset << ": thruster "
                               << now.r.thruster << " at " << now.r.confirmed_at;
      }
      if (right_before && right_now) {
        latency_before += before.r.confirmed_at;
        latency_now += now.r.confirmed_at;
      }
      // Only a run whose episode (F41) restarted flies differently.
      if (now.r.confirmed_at != before.r.confirmed_at) {
        ++changed;
        EXPECT_GT(now.restarts, before.restarts) << "jet " << jet << " onset " << onset;
      }
    }
  }
  std::printf("stuck on at every phase of a window: confirmed %d -> %d of 160 (wrong %d -> %d), "
              "%d changed, latency %.0f -> %.0f ticks over the runs right in both\n",
              confirmed_before, confirmed_now, wrong_before, wrong_now, changed, latency_before,
              latency_now);
  // Wrong isolations of the onset window scored (F21's trap, gnc.yaml scores it) are not F41's.
  EXPECT_LE(wrong_now, wrong_before);
  EXPECT_GT(changed, 0) << "the trap: no leader changed after the onset window";
  EXPECT_LT(confirmed_before, confirmed_now) << "the trap: runs never confirmed in 200 ticks";
  EXPECT_LT(latency_now, latency_before);
}

// (F45) The onset window ended at its early suspicion. The rig of (F41) as gnc.yaml flies it
// (10-tick windows, F21, F33's early test from 3 samples, F41), every jet stuck on at every phase of
// the window, with and without (F45). Without it, the first window scored is the one after the
// onset window's close; with it, the window that starts on the early suspicion, which the fault
// fills: every jet is still named right, none later, and on average sooner by what is left of the
// onset window after its early suspicion.
struct OnsetRestartRun {
  RunResult r;
  std::uint32_t onset_restarts{0};
  std::uint32_t early{0};
  std::uint32_t probes{0};
  std::uint32_t probe_whole{0};  // (F47) tests flown on a whole window
};

OnsetRestartRun fly_onset_restart(int jet, int onset, bool onset_restart,
                                  int probe_window_ticks = 0, double probe_short_min_llr = 0.0,
                                  double r_sigma = 0.03, const Vec3& r_error = Vec3::Zero()) {
  FaultDetectorParams p = onset_rig_params(1e-7);
  p.skip_onset_window = true;
  p.detect_early_ticks = 3;
  p.detect_early_chi2 = 35.41;
  p.onset_restart = onset_restart;
  p.probe_window_ticks = probe_window_ticks;
  p.probe_short_min_llr = probe_short_min_llr;
  FaultDetectorStatus st;
  OnsetRestartRun out;
  out.r = fly_onset_rig(p, jet, onset, &st, r_sigma, r_error);
  out.onset_restarts = st.onset_restarts;
  out.early = st.early_detections;
  out.probes = st.probes;
  out.probe_whole = st.probe_whole_windows;
  return out;
}

TEST(FaultDetector, AnOnsetWindowEndedAtItsEarlySuspicionNamesEveryJetSooner) {
  double latency_before = 0.0, latency_now = 0.0;
  int sooner = 0, later = 0, worst_before = 0, worst_now = 0;
  for (int jet = 0; jet < 16; ++jet) {
    for (int onset = 500; onset < 510; ++onset) {  // every phase of the window
      const OnsetRestartRun before = fly_onset_restart(jet, onset, false);
      const OnsetRestartRun now = fly_onset_restart(jet, onset, true);
      const std::string what = "jet " + std::to_string(jet) + " onset " + std::to_string(onset);
      ASSERT_GE(before.r.confirmed_at, 0) << what;
      ASSERT_GE(now.r.confirmed_at, 0) << what;
      EXPECT_EQ(before.r.thruster, jet) << what;
      EXPECT_EQ(now.r.thruster, jet) << what;
      EXPECT_EQ(now.r.kind, FaultKind::kStuckOn) << what;
      EXPECT_EQ(before.onset_restarts, 0u) << what;
      // One early suspicion, and the onset window ended there: the healthy flight before it has
      // none.
      EXPECT_GE(now.early, 1u) << what;
      // The onset window ends at its early suspicion once, whenever its early test can fire: the
      // fault shows from the sample after onset, and the test needs 3 samples of the window.
      EXPECT_LE(now.onset_restarts, 1u) << what;
      if (onset <= 506) {
        EXPECT_EQ(now.onset_restarts, 1u) << what;
      }
      // The windows move by less than one: a run can lose at most that (its first scored window
      // decided with another firing, an isolation test the other did not need).
      EXPECT_LE(now.r.confirmed_at, before.r.confirmed_at + 10) << what;
      if (now.r.confirmed_at < before.r.confirmed_at) ++sooner;
      if (now.r.confirmed_at > before.r.confirmed_at) ++later;
      latency_before += before.r.confirmed_at;
      latency_now += now.r.confirmed_at;
      worst_before = std::max(worst_before, before.r.confirmed_at);
      worst_now = std::max(worst_now, now.r.confirmed_at);
    }
  }
  std::printf("onset window ended at its early suspicion: latency mean %.1f -> %.1f ticks, worst "
              "%d -> %d, %d of 160 sooner, %d later\n",
              latency_before / 160.0, latency_now / 160.0, worst_before, worst_now, sooner, later);
  EXPECT_LT(worst_now, worst_before);
  EXPECT_GT(sooner, 8 * later);
  // Sooner on average by at least a third of a window: the onset window's rest after its early
  // suspicion, 3 samples in or 1-2 after the onset, whichever is later (none at the last phases).
  EXPECT_LE(latency_now, latency_before - 3.0 * 160.0);
}

// (F46) The isolation test on a 5-sample window instead of the bank's 10, in the rig above with
// (F45): every jet stuck on at every phase of the window. A closed valve removes the whole torque
// of a stuck-on jet on the tested pod: every run names its jet as with the whole window, and the
// runs the bank decides alone are unchanged. A test's evidence grows with the cube of its samples
// (a ramp), and against this rig's model (3 cm, 1 %) the short test of an axial jet can leave the
// verdict to the reopened window or a second test: some runs are later, by 4-9 updates, more are
// 5 sooner, and the mean over the tested runs is not worse.
TEST(FaultDetector, AnIsolationTestOnAShortWindowNamesTheSameJet) {
  int tested = 0, sooner = 0, later = 0;
  double latency_whole = 0.0, latency_short = 0.0;  // over the runs decided by a test
  for (int jet = 0; jet < 16; ++jet) {
    for (int onset = 500; onset < 510; ++onset) {
      const OnsetRestartRun whole = fly_onset_restart(jet, onset, true, 0);
      const OnsetRestartRun shortened = fly_onset_restart(jet, onset, true, 5);
      const std::string what = "jet " + std::to_string(jet) + " onset " + std::to_string(onset);
      ASSERT_GE(whole.r.confirmed_at, 0) << what;
      ASSERT_GE(shortened.r.confirmed_at, 0) << what;
      EXPECT_EQ(whole.r.thruster, jet) << what;
      EXPECT_EQ(shortened.r.thruster, jet) << what;
      EXPECT_EQ(shortened.r.kind, FaultKind::kStuckOn) << what;
      if (whole.probes == 0) {  // decided by the bank alone: no test, no change
        EXPECT_EQ(shortened.probes, 0u) << what;
        EXPECT_EQ(shortened.r.confirmed_at, whole.r.confirmed_at) << what;
        continue;
      }
      ++tested;
      EXPECT_GE(shortened.probes, whole.probes) << what;
      sooner += shortened.r.confirmed_at < whole.r.confirmed_at ? 1 : 0;
      later += shortened.r.confirmed_at > whole.r.confirmed_at ? 1 : 0;
      latency_whole += whole.r.confirmed_at;
      latency_short += shortened.r.confirmed_at;
    }
  }
  std::printf("isolation tests on 5 samples: %d of 160 runs decided by a test, %d sooner, %d "
              "later, mean %.1f -> %.1f ticks\n",
              tested, sooner, later, latency_whole / std::max(tested, 1),
              latency_short / std::max(tested, 1));
  EXPECT_GT(tested, 40);  // the twin jets of other pods (F9): about half of the runs
  EXPECT_GT(sooner, later);
  EXPECT_LE(latency_short, latency_whole);
}

// (F47) The short test (F46) gated by the evidence of the window that started it, in the same rig:
// a test whose leader showed less than the gate, scaled to 5 samples by the cube of the lengths'
// ratio, flies the whole window. A run whose every test was short flies as with every test short,
// a run whose every test was whole as with the whole window, tick for tick; a gate no evidence
// reaches gives the whole window's flight in every run. A higher gate sends every run a lower one
// sent to the whole window there too (one evidence per test, compared with the gate). The weaker
// the model (the centre of mass 30 cm off, its 1 sigma 30 cm, as before identification), the
// weaker the evidence that starts a test, and the more tests fly a whole window at gnc.yaml's 10.
struct GateCount {
  int tested{0}, gated{0}, sooner{0}, later{0};
};

GateCount fly_gated(double gate, double r_sigma, std::vector<bool>* gated_runs) {
  GateCount c;
  const Vec3 r_error = Vec3(0.6, -0.6, 0.4) * r_sigma;
  for (int jet = 0; jet < 16; ++jet) {
    for (int onset = 500; onset < 510; ++onset) {
      const OnsetRestartRun whole = fly_onset_restart(jet, onset, true, 0, 0.0, r_sigma, r_error);
      const OnsetRestartRun shortened = fly_onset_restart(jet, onset, true, 5, 0.0, r_sigma, r_error);
      const OnsetRestartRun gated = fly_onset_restart(jet, onset, true, 5, gate, r_sigma, r_error);
      const std::string what = "gate " + std::to_string(gate) + " jet " + std::to_string(jet) +
                               " onset " + std::to_string(onset);
      EXPECT_EQ(shortened.probe_whole, 0u) << what;  // no gate: every test short
      EXPECT_LE(gated.probe_whole, gated.probes) << what;
      if (gated.r.confirmed_at >= 0) {
        EXPECT_EQ(gated.r.thruster, jet) << what;
        EXPECT_EQ(gated.r.kind, FaultKind::kStuckOn) << what;
      }
      if (gated.probe_whole == 0) {
        EXPECT_EQ(gated.r.confirmed_at, shortened.r.confirmed_at) << what;
        EXPECT_EQ(gated.r.thruster, shortened.r.thruster) << what;
      } else if (gated.probe_whole == gated.probes) {
        EXPECT_EQ(gated.r.confirmed_at, whole.r.confirmed_at) << what;
        EXPECT_EQ(gated.r.thruster, whole.r.thruster) << what;
      }
      if (gated_runs != nullptr) gated_runs->push_back(gated.probes > 0 && gated.probe_whole > 0);
      if (gated.probes == 0) continue;
      ++c.tested;
      c.gated += gated.probe_whole == gated.probes ? 1 : 0;
      c.sooner += gated.r.confirmed_at < whole.r.confirmed_at ? 1 : 0;
      c.later += gated.r.confirmed_at > whole.r.confirmed_at ? 1 : 0;
    }
  }
  std::printf("short tests gated at %g (model 1 sigma %.2f m): %d runs tested, %d on whole "
              "windows, against the whole window %d sooner, %d later\n",
              gate, r_sigma, c.tested, c.gated, c.sooner, c.later);
  return c;
}

TEST(FaultDetector, AShortIsolationTestIsFlownOnlyOnStrongEvidence) {
  std::vector<bool> at35, at50;
  const GateCount none = fly_gated(0.0, 0.03, nullptr);
  const GateCount low = fly_gated(35.0, 0.03, &at35);
  const GateCount high = fly_gated(50.0, 0.03, &at50);
  const GateCount never = fly_gated(1e12, 0.03, nullptr);
  EXPECT_EQ(none.gated, 0);
  EXPECT_EQ(never.gated, never.tested);  // every test whole: the whole window's flight
  EXPECT_EQ(never.sooner + never.later, 0);
  ASSERT_EQ(at35.size(), at50.size());
  for (std::size_t i = 0; i < at35.size(); ++i) {
    if (at35[i]) {
      EXPECT_TRUE(at50[i]) << "run " << i;
    }
  }
  EXPECT_GT(low.gated, 0);
  EXPECT_GT(high.gated, low.gated);
  EXPECT_LT(high.gated, high.tested);
  // A gated test flies as without F46: fewer runs later than the whole window than with every
  // test short.
  EXPECT_LT(high.later, none.later);
  // The weaker model: at gnc.yaml's gate some tests fly whole windows, none in the rig's model.
  const GateCount coarse = fly_gated(10.0, 0.3, nullptr);
  EXPECT_EQ(fly_gated(10.0, 0.03, nullptr).gated, 0);
  EXPECT_GT(coarse.gated, 0);
}

// (F33) Early detection. Every jet stuck on at every phase of a 10-tick window, under HOLD's
// few-newton firing (WeakFiring) with case 5's gyro: the first suspicion after onset with the window so far tested each
// update, against the same flight with the window's own test only. Scores and decisions are the
// window's in both, so every confirmation is the same thruster on the same tick.
struct Detection {
  int detected_at{-1};  // first update after onset raising a suspicion
  RunResult r;
  std::uint32_t early{0};
};

Detection fly_detection(int jet, int onset, int early_ticks) {
  Truth t;
  FaultDetectorParams p = bank_params(t.gyro_sigma);
  p.detect_early_ticks = early_ticks;
  FaultDetector d;
  d.configure(p, study_rcs_layout(kUmax), kUmax, kDt);
  d.set_model(identified_model(t));
  WeakFiring firing(11);
  Vec16 prev = Vec16::Zero();
  Detection out;
  for (int k = 0; k < onset + 100; ++k) {
    if (k == onset) t.stuck_on = jet;
    FaultDetectorInput in;
    in.omega = t.gyro();
    in.omega_valid = true;
    in.thrust = prev;
    in.valve_open = t.valve;
    const FaultEvents e = d.update(in);
    if (e.suspected && k >= onset && out.detected_at < 0) out.detected_at = k;
    if (e.confirmed && out.r.confirmed_at < 0) {
      out.r.confirmed_at = k;
      out.r.thruster = e.thruster;
      out.r.kind = e.kind;
    }
    if (d.confirmed_on() != 0) t.valve[static_cast<std::size_t>(jet / 4)] = false;
    const Vec16 cmd = firing.next(k);
    t.advance(cmd);
    prev = cmd;
  }
  out.early = d.status().early_detections;
  return out;
}

TEST(FaultDetector, AStuckOnJetIsDetectedBeforeItsWindowCloses) {
  int sooner = 0, runs = 0;
  double sum_early = 0.0, sum_window = 0.0;
  for (int jet = 0; jet < 16; ++jet) {
    for (int phase = 0; phase < 10; ++phase) {
      const int onset = 200 + phase;
      const Detection window = fly_detection(jet, onset, 0);
      const Detection early = fly_detection(jet, onset, 3);
      ++runs;
      ASSERT_GE(window.detected_at, 0) << "jet " << jet << " phase " << phase;
      ASSERT_GE(early.detected_at, 0) << "jet " << jet << " phase " << phase;
      EXPECT_LE(early.detected_at, window.detected_at) << "jet " << jet << " phase " << phase;
      if (early.detected_at < window.detected_at) {
        ++sooner;
        EXPECT_GE(early.early, 1u) << "sooner without an early detection";
      }
      sum_early += early.detected_at - onset;
      sum_window += window.detected_at - onset;
      // The isolation is the window's: the same thruster and kind on the same update.
      EXPECT_EQ(early.r.confirmed_at, window.r.confirmed_at) << "jet " << jet << " phase " << phase;
      EXPECT_EQ(early.r.thruster, window.r.thruster);
      EXPECT_EQ(early.r.kind, window.r.kind);
      EXPECT_EQ(window.early, 0u);
    }
  }
  std::printf("early detection: %d of %d runs sooner; mean %.1f ticks after onset (window's test "
              "only: %.1f)\n", sooner, runs, sum_early / runs, sum_window / runs);
  EXPECT_GT(sooner, runs / 2);
  EXPECT_LT(sum_early, 0.8 * sum_window);
}

// (F33) Healthy random firing at two noise levels, 2000 s each: no suspicion, early or not.
TEST(FaultDetector, HealthyFiringRaisesNoEarlyDetection) {
  for (const double sigma : {3.1623e-6, 3.1623e-5}) {
    Truth t;
    t.gyro_sigma = sigma;
    FaultDetectorParams p = bank_params(sigma);
    p.detect_early_ticks = 3;
    FaultDetector d;
    d.configure(p, study_rcs_layout(kUmax), kUmax, kDt);
    d.set_model(identified_model(t));
    const RunResult r = fly(t, d, 20000, -1, -1, -1);
    EXPECT_LT(r.confirmed_at, 0);
    EXPECT_EQ(d.status().suspicions, 0u) << "gyro sigma " << sigma;
    EXPECT_EQ(d.status().early_detections, 0u);
  }
}

TEST(FaultDetector, AStuckOffJetCommandedAtAFewPercentIsIsolatedFromPooledWindows) {
  for (int i : {1, 6, 11, 13}) {  // tangential and axial jets on every pod
    Truth t;
    FaultDetector d = make_detector(t, t.gyro_sigma);
    // Each 1 s window alone is below the observability threshold for the fault's signature.
    const RunResult r = fly_weak(t, d, 30050, 50, i, 100 + static_cast<std::uint64_t>(i));
    ASSERT_GE(r.confirmed_at, 0) << "thruster " << i << " best " << d.status().best << " llr "
                                 << d.status().best_llr;
    EXPECT_EQ(r.thruster, i);
    EXPECT_EQ(r.kind, FaultKind::kStuckOff) << "thruster " << i;
    EXPECT_EQ(d.confirmed_off(), 1u << i);
  }
  for (std::uint64_t seed : {5u, 6u}) {
    Truth t;
    FaultDetector d = make_detector(t, t.gyro_sigma);
    const RunResult r = fly_weak(t, d, 20000, -1, -1, seed);  // 2000 s healthy
    EXPECT_LT(r.confirmed_at, 0) << "false alarm: thruster " << r.thruster << " "
                                 << to_string(r.kind) << " at tick " << r.confirmed_at;
  }
}

// With the partial-loss confirmation (F18) off: a thruster at half strength leaves its own
// stuck-off hypothesis with no evidence (the residual is half its signature: S.r - |S|^2/2 = 0)
// and gives positive evidence to any smaller, nearly parallel stuck-off signature of another jet.
// (F13): a stuck-off is confirmed only when it beats a fitted partial loss of every other jet and
// its own amplitude is that of a jet producing nothing: neither it nor another jet is confirmed
// (without (F13) the half-strength jet itself drifts to a stuck-off confirmation: a wrong kind).
TEST(FaultDetector, AHalfStrengthThrusterIsNeverConfirmedStuckOff) {
  for (int i : {0, 4, 9, 13}) {
    for (bool weak : {true, false}) {
      Truth t;
      FaultDetector d = make_detector(t, t.gyro_sigma);
      t.degraded = i;
      const RunResult r = weak ? fly_weak(t, d, 30000, -1, -1, 200 + static_cast<std::uint64_t>(i))
                               : fly(t, d, 30000, -1, -1, -1);
      EXPECT_LT(r.confirmed_at, 0) << "thruster " << i << (weak ? " weak" : " strong")
                                   << " firing: confirmed " << r.thruster << " "
                                   << to_string(r.kind) << " at tick " << r.confirmed_at;
    }
  }
}

// (F18) A partial loss of thrust is confirmed as such: the thruster itself, kind degraded, with
// its fitted factor and that factor's 1 sigma. Against the truth's factor for a half-strength and a 20 % loss with strong
// (random) firing, and the half loss with weak (D+PD-like) firing; a 5 % loss, below degraded_min_loss, is left to
// the identifier's strengths (nothing confirmed). After the confirmation the detector predicts
// the jet at its factor: nothing else is confirmed in the 1000 s that follow.
struct DegradedRun {
  RunResult r;
  double factor{1.0};
  double factor_sigma{0.0};
  int confirmations{0};
  // Counts a confirmation at tick k; true for the run's first.
  bool note(const FaultEvents& e, int k) {
    if (!e.confirmed) return false;
    ++confirmations;
    if (r.confirmed_at >= 0) return false;
    r.confirmed_at = k;
    r.thruster = e.thruster;
    r.kind = e.kind;
    factor = e.factor;
    factor_sigma = e.factor_sigma;
    return true;
  }
};

DegradedRun fly_degraded(int i, double truth_factor, bool weak, int ticks) {
  Truth t;
  FaultDetector d = make_detector(t, t.gyro_sigma, 0.1);
  t.degraded = i;
  t.degraded_factor = truth_factor;
  WeakFiring firing(300 + static_cast<std::uint64_t>(i));
  std::mt19937_64 cmd_rng(11);
  Vec16 prev = Vec16::Zero();
  DegradedRun run;
  for (int k = 0; k < ticks; ++k) {
    FaultDetectorInput in;
    in.omega = t.gyro();
    in.omega_valid = true;
    in.thrust = prev;
    const FaultEvents e = d.update(in);
    if (run.note(e, k)) {
      EXPECT_DOUBLE_EQ(d.strength_factor(e.thruster), e.factor);
      ticks = std::min(ticks, k + 10000);  // 1000 s more with the factor latched
    }
    const Vec16 cmd = weak ? firing.next(k) : random_firing(cmd_rng);
    t.advance(cmd);
    prev = cmd;
  }
  return run;
}

TEST(FaultDetector, APartialLossOfThrustIsConfirmedDegradedWithItsFactor) {
  for (int i : {0, 4, 9, 13}) {
    for (bool weak : {false, true}) {
      for (double truth : {0.5, 0.8}) {
        // A 20 % loss of a jet commanded at 4-15 N is 1-3 N: with weak firing only the half loss
        // is decided within the run (its evidence grows with the square of the loss).
        if (weak && truth > 0.6) continue;
        const DegradedRun run = fly_degraded(i, truth, weak, 60000);
        const std::string what = "thruster " + std::to_string(i) + " x" + std::to_string(truth) +
                                 (weak ? " weak" : " strong") + " firing";
        ASSERT_GE(run.r.confirmed_at, 0) << what << ": never confirmed";
        EXPECT_EQ(run.r.thruster, i) << what;
        EXPECT_EQ(run.r.kind, FaultKind::kDegraded) << what;
        // The fitted factor against the truth, within 3 of its reported 1 sigma, which is that of
        // a useful estimate.
        EXPECT_NEAR(run.factor, truth, 3.0 * run.factor_sigma) << what;
        EXPECT_GT(run.factor_sigma, 0.0) << what;
        EXPECT_LT(run.factor_sigma, 0.1) << what;
        EXPECT_EQ(run.confirmations, 1) << what << ": a later confirmation";
      }
    }
  }
  for (int i : {4, 13}) {
    const DegradedRun small = fly_degraded(i, 0.95, false, 30000);
    EXPECT_LT(small.r.confirmed_at, 0) << "a 5 % loss of thruster " << i << " confirmed "
                                        << small.r.thruster << " " << to_string(small.r.kind);
  }
}

// (F23) A jet that produces nothing leaves the residual of its whole signature, which the model
// knows to its relative error eps only; so the fitted loss of a dead jet scatters below 1 by up to
// model_sigmas eps. Under a long, firm firing (E of the order of 1e8 here: a quiet gyro, as in
// HOLD's hours) a fitted loss a few percent below 1 gains far more than margin_llr over a total
// loss, and without (F23) such a jet was held as a partial loss for the rest of the flight (case 1,
// a jet stuck off in HOLD, held by another alternative until its LLR was past 1e5, then never
// isolated). Here the confirmation level is 2e4, so that the decision is taken under that much
// evidence. The truth's jet gives 3 % of its thrust (a jet that failed shut and leaks, or a model
// whose strength is a few percent off). With a model whose strength 1 sigma is 1.5 % (3 sigma:
// 4.6 % of the signature) that is a total loss: confirmed stuck off (without F23: degraded, at
// 3 %). With a model certain to 0.1 % the same data are a partial loss: confirmed degraded
// with its fitted factor. The floor follows the model's stated error.
FaultEvents fly_leaking(int i, double k_sigma) {
  Truth t;
  t.gyro_sigma = 1e-8;
  FaultDetectorParams p;
  p.enabled = true;
  p.degraded_min_loss = 0.1;
  p.confirm_llr = 2e4;
  p.window_ticks = 10;
  p.gyro_sigma = t.gyro_sigma;
  p.disturbance_sigma = 0.0;
  FaultDetector d;
  d.configure(p, study_rcs_layout(kUmax), kUmax, kDt);
  FaultModel m = identified_model(t);
  m.k_sigma = k_sigma;
  d.set_model(m);
  std::mt19937_64 cmd_rng(11);
  Vec16 prev = Vec16::Zero();
  for (int k = 0; k < 200000; ++k) {
    if (k == 50) {
      t.degraded = i;
      t.degraded_factor = 0.03;
    }
    FaultDetectorInput in;
    in.omega = t.gyro();
    in.omega_valid = true;
    in.thrust = prev;
    const FaultEvents e = d.update(in);
    if (e.confirmed) return e;
    const Vec16 cmd = random_firing(cmd_rng);
    t.advance(cmd);
    prev = cmd;
  }
  return FaultEvents{};
}

TEST(FaultDetector, ALossOfThrustWithinTheModelsErrorOfTotalIsConfirmedStuckOff) {
  for (int i : {0, 5, 10, 15}) {
    const FaultEvents off = fly_leaking(i, 0.015);
    ASSERT_TRUE(off.confirmed) << "thruster " << i << " (model 1 sigma 1.5 %): never confirmed";
    EXPECT_EQ(off.thruster, i);
    EXPECT_EQ(off.kind, FaultKind::kStuckOff)
        << "thruster " << i << " (model 1 sigma 1.5 %): confirmed " << to_string(off.kind);
    const FaultEvents partial = fly_leaking(i, 0.001);
    ASSERT_TRUE(partial.confirmed) << "thruster " << i << " (model 1 sigma 0.1 %): never confirmed";
    EXPECT_EQ(partial.thruster, i);
    EXPECT_EQ(partial.kind, FaultKind::kDegraded)
        << "thruster " << i << " (model 1 sigma 0.1 %): confirmed " << to_string(partial.kind);
    EXPECT_NEAR(partial.factor, 0.03, 3.0 * partial.factor_sigma + 0.01) << "thruster " << i;
  }
}

// (F18) With 5-tick windows (the study table's) the four evaluation steps and the partial-loss
// step leave no update free of an evaluation step inside a window: a model given during an
// evaluation must still be taken (at the update after the decision, before the partial-loss step
// runs there, or at the close). The detector starts from a model 30 % wrong in J and gets the
// right one on every tick from tick 100, as the flight's identifier refresh does; a stuck-on jet
// from tick 300 is isolated to itself. (When the staged model was never taken, nothing was.)
TEST(FaultDetector, AModelGivenDuringTheEvaluationIsTakenWithFiveTickWindowsAndPartialLossesOn) {
  for (int i : {0, 6, 11}) {
    Truth t;
    FaultDetectorParams p = bank_params(t.gyro_sigma, 5);
    p.degraded_min_loss = 0.1;
    FaultDetector d;
    d.configure(p, study_rcs_layout(kUmax), kUmax, kDt);
    const FaultModel right = identified_model(t);
    FaultModel wrong = right;  // an unidentified model, honestly uncertain
    wrong.j *= 1.3;
    wrong.j_rel_sigma = 0.3;
    wrong.r_cov = Mat3::Identity() * 0.25;
    wrong.k_sigma = 0.05;
    d.set_model(wrong);
    std::mt19937_64 cmd_rng(11);
    Vec16 prev = Vec16::Zero();
    RunResult r;
    for (int k = 0; k < 1000 && r.confirmed_at < 0; ++k) {
      if (k == 300) t.stuck_on = i;
      FaultDetectorInput in;
      in.omega = t.gyro();
      in.omega_valid = true;
      in.thrust = prev;
      const FaultEvents e = d.update(in);
      if (k >= 100) d.set_model(right);  // after the update, as Gnc::step refreshes it
      if (e.confirmed) {
        r.confirmed_at = k;
        r.thruster = e.thruster;
        r.kind = e.kind;
      }
      const Vec16 cmd = random_firing(cmd_rng);
      t.advance(cmd);
      prev = cmd;
    }
    ASSERT_GE(r.confirmed_at, 300) << "thruster " << i;
    EXPECT_EQ(r.thruster, i);
    EXPECT_EQ(r.kind, FaultKind::kStuckOn);
  }
}

TEST(FaultDetector, HealthyFiringNeverConfirmsAPartialLoss) {
  for (double sigma : {3.1623e-6, 3.1623e-5}) {
    Truth t;
    t.gyro_sigma = sigma;
    FaultDetector d = make_detector(t, sigma, 0.1);
    const RunResult r = fly(t, d, 20000, -1, -1, -1);  // 2000 s
    EXPECT_LT(r.confirmed_at, 0) << "false alarm: thruster " << r.thruster << " "
                                 << to_string(r.kind) << " at tick " << r.confirmed_at;
  }
  for (std::uint64_t seed : {5u, 6u}) {
    Truth t;
    FaultDetector d = make_detector(t, t.gyro_sigma, 0.1);
    const RunResult r = fly_weak(t, d, 20000, -1, -1, seed);
    EXPECT_LT(r.confirmed_at, 0) << "false alarm: thruster " << r.thruster << " "
                                 << to_string(r.kind) << " at tick " << r.confirmed_at;
  }
}

TEST(FaultDetector, AStuckOffThrusterNeverCommandedGathersNoEvidence) {
  Truth t;
  FaultDetector d = make_detector(t, t.gyro_sigma);
  t.stuck_off = 5;
  Vec16 prev = Vec16::Zero();
  std::mt19937_64 rng(3);
  for (int k = 0; k < 3000; ++k) {
    FaultDetectorInput in;
    in.omega = t.gyro();
    in.omega_valid = true;
    in.thrust = prev;
    const FaultEvents e = d.update(in);
    EXPECT_FALSE(e.confirmed) << "tick " << k;
    Vec16 cmd = random_firing(rng);
    cmd(5) = 0.0;  // the flight never fires thruster 5
    t.advance(cmd);
    prev = cmd;
  }
  EXPECT_EQ(d.status().best == 16 + 5 ? d.status().best_llr : 0.0, 0.0);
}

TEST(FaultDetector, AClosedPodShowsNoStuckOnAndALatchedFaultIsPredicted) {
  Truth t;
  FaultDetector d = make_detector(t, t.gyro_sigma);
  // Pod 1's valve closed with its thruster 6 stuck on: nothing fires there, nothing to detect.
  t.valve[1] = false;
  const RunResult closed = fly(t, d, 1000, 0, 6, -1);
  EXPECT_LT(closed.confirmed_at, 0);
  // Valve open, stuck on, and the fault already declared by the ground: the detector predicts
  // it, so it does not confirm anything else.
  Truth u;
  FaultDetector e = make_detector(u, u.gyro_sigma);
  e.declare(6, FaultKind::kStuckOn);
  const RunResult declared = fly(u, e, 1000, 0, 6, -1);
  EXPECT_LT(declared.confirmed_at, 0) << "confirmed " << declared.thruster;
  EXPECT_EQ(e.confirmed_on(), 1u << 6);
  e.clear(-1);
  EXPECT_EQ(e.confirmed_on(), 0);
}

TEST(FaultDetector, ScoresAreTheLikelihoodRatioOfTheSignatures) {
  // One window with the truth exactly at hypothesis h's signature (noise-free): its LLR is
  // +||S~||^2 / (2 var) and every other hypothesis scores less.
  Truth t;
  t.gyro_sigma = 0.0;
  FaultDetectorParams p = bank_params(1e-6);
  p.model_rel_floor = 0.0;
  p.confirm_llr = 1e30;  // never confirm: look at the scores
  FaultDetector d;
  d.configure(p, study_rcs_layout(kUmax), kUmax, kDt);
  FaultModel m;
  m.j = t.body.j;
  m.r = t.r;
  m.j_rel_sigma = 0.0;
  m.r_cov = Mat3::Zero();
  m.k_sigma = 0.0;
  d.set_model(m);
  // One window (11 samples) and its evaluation (F10), thruster 9 stuck on from the start.
  fly(t, d, 11 + FaultDetector::kEvaluationSteps, 0, 9, -1);
  EXPECT_EQ(d.status().windows, 1u);
  EXPECT_EQ(d.status().best, 9);
  EXPECT_GT(d.status().best_llr, 100.0);
  EXPECT_GT(d.status().chi2, p.suspect_chi2);
}


// (F22) The model's error in the detector's noise (F5): rel ||J^-1 B u|| for the commanded thrust
// and rel 2 ||J^-1|| ||J|| |w|^2 for the gyroscopic term, rel = max(model_rel_floor, the model's J
// 1 sigma). With model_floor_gyroscopic false the floor applies to the thrust's term only: a
// torque-free window has the identifier's 1 sigma, a window of thrust at rest the floor, as before.
double window_sigma(bool floor_gyroscopic, bool thrust, double* expected) {
  Truth t;
  if (thrust) t.body.omega = V3::Zero();
  FaultDetectorParams p = bank_params(1e-7);
  p.model_rel_floor = 0.01;
  p.model_floor_gyroscopic = floor_gyroscopic;
  p.confirm_llr = 1e30;  // never confirm: look at the noise
  FaultDetector d;
  d.configure(p, study_rcs_layout(kUmax), kUmax, kDt);
  FaultModel m;
  m.j = t.body.j;
  m.r = t.r;
  m.j_rel_sigma = 1e-4;
  m.r_cov = Mat3::Zero();
  m.k_sigma = 0.0;
  d.set_model(m);
  const Eigen::SelfAdjointEigenSolver<Mat3> es(t.body.j);
  const double j_norm = es.eigenvalues().maxCoeff();
  const double j_inv_norm = 1.0 / es.eigenvalues().minCoeff();
  const Mat3 j_inv = t.body.j.inverse();
  Vec16 cmd = Vec16::Zero();
  if (thrust) cmd << 150, 0, 0, 80, 0, 0, 60, 0, 0, 120, 0, 40, 0, 0, 0, 90;
  double gyro_motion = 0.0;    // sum of 2 ||J^-1|| ||J|| |w_mid|^2 dt
  double thrust_motion = 0.0;  // sum of |J^-1 sum (p_i + r) x f_i d_i| dt
  V3 prev = t.body.omega;
  for (int k = 0; k < 11 + FaultDetector::kEvaluationSteps; ++k) {
    FaultDetectorInput in;
    in.omega = t.body.omega;
    in.omega_valid = true;
    in.thrust = k == 0 ? Vec16::Zero() : cmd;
    in.valve_open = t.valve;
    d.update(in);
    if (k >= 1 && k <= 10) {
      const V3 w = 0.5 * (prev + t.body.omega);
      gyro_motion += 2.0 * j_inv_norm * j_norm * w.squaredNorm() * kDt;
      V3 tau = V3::Zero();
      for (int i = 0; i < 16; ++i) {
        tau += (t.pos[static_cast<std::size_t>(i)] + t.r)
                   .cross(cmd(i) * t.dir[static_cast<std::size_t>(i)]);
      }
      thrust_motion += (j_inv * tau).norm() * kDt;
    }
    prev = t.body.omega;
    t.advance(cmd);
  }
  const double model = floor_gyroscopic ? 0.01 * (thrust_motion + gyro_motion)
                                        : 0.01 * thrust_motion + 1e-4 * gyro_motion;
  *expected = std::sqrt(2.0 * p.gyro_sigma * p.gyro_sigma + model * model + 1e-30);
  EXPECT_EQ(d.status().windows, 1u);
  return d.status().noise_sigma;
}

TEST(FaultDetector, TheFloorOnTheThrustTermOnlyLeavesTheGyroscopicTermToTheModelsSigma) {
  double e_on = 0.0, e_off = 0.0;
  const double tumbling_on = window_sigma(true, false, &e_on);
  const double tumbling_off = window_sigma(false, false, &e_off);
  EXPECT_NEAR(tumbling_on, e_on, 1e-9 * e_on);
  EXPECT_NEAR(tumbling_off, e_off, 1e-9 * e_off);
  EXPECT_GT(tumbling_on, 50.0 * tumbling_off);  // the floor (0.01) against the model's 1e-4
  const double firing_on = window_sigma(true, true, &e_on);
  const double firing_off = window_sigma(false, true, &e_off);
  EXPECT_NEAR(firing_on, e_on, 1e-6 * e_on);
  EXPECT_NEAR(firing_off, e_off, 1e-6 * e_off);
  // From rest the window's gyroscopic term is only the firing's own spin-up (1e-4 of the thrust's
  // term here): both settings floor the thrust's term alike.
  EXPECT_NEAR(firing_off, firing_on, 1e-3 * firing_on);
}

// Two axial jets of opposite pods (thruster 2: pod 0 +z; thruster 11: pod 2 -z) push the body the
// same way up to the centre of mass's xy offset r_xy: their signatures differ by 2 |r_xy| over
// the 2.5 m arm (4 % with the mission's r_SO/BCM; 29 % with r_xy = (-0.3, 0.2) m here). The
// model's r has its xy part mirrored, an error of 0.72 m at 2 sigma of what the model states, so
// its signature of 11 is exactly the truth's of 2; neither jet's channel is ever commanded
// (nothing else tells them apart). The former rule
// (CUSUM lead over the runner-up only, no test) confirms the wrong jet; the bias bound (F8) holds
// the decision and the isolation test (F9), closing pod 0 for a few windows, settles it.
struct AmbiguousRun {
  RunResult r;
  std::uint32_t probes{0};
  int probe_windows_closed{0};  // ticks with a pod closed for the test
  std::vector<int> probe_ends;  // ticks at which an isolation test reopened its pod
  std::vector<int> probe_pods;  // the pod of each test
  std::vector<int> probe_starts;  // the tick each test closed its pod
  std::vector<double> probe_start_scores;  // the leader's score on the update each test started
  double score_before_confirmation{0.0};   // the leader's score on the update before it
};

// The trap's truth r and the detector flying against its mirror: the model's r has its xy part
// mirrored, an error of 0.72 m at 2 sigma of what the model states.
void mirror_trap(Truth& t, FaultDetectorParams p, FaultDetector& d) {
  t.r = V3(-0.3, 0.2, 3.5456);
  p.enabled = true;
  p.window_ticks = 10;
  p.gyro_sigma = t.gyro_sigma;
  p.disturbance_sigma = 0.0;
  d.configure(p, study_rcs_layout(kUmax), kUmax, kDt);
  FaultModel m;
  m.j = t.body.j;
  m.r = V3(-t.r.x(), -t.r.y(), t.r.z());
  m.j_rel_sigma = 1e-4;
  m.r_cov = Mat3::Identity() * 0.13;  // 1 sigma 0.36 m: the 0.72 m error is at 2 sigma
  m.k_sigma = 1e-3;
  d.set_model(m);
}

AmbiguousRun fly_ambiguous(FaultDetectorParams p, double firing_scale = 1.0) {
  Truth t;
  FaultDetector d;
  mirror_trap(t, p, d);
  std::mt19937_64 rng(5);
  Vec16 prev = Vec16::Zero();
  std::array<bool, 4> prev_valve = t.valve;
  AmbiguousRun out;
  int last_pod = -1;
  for (int k = 0; k < 2000; ++k) {
    if (k == 50) t.stuck_on = 2;
    FaultDetectorInput in;
    in.omega = t.gyro();
    in.omega_valid = true;
    in.thrust = prev;
    in.valve_open = prev_valve;
    const double score_before = d.status().best_llr;
    const FaultEvents e = d.update(in);
    if (e.confirmed && out.r.confirmed_at < 0) {
      out.r.confirmed_at = k;
      out.r.thruster = e.thruster;
      out.r.kind = e.kind;
      out.score_before_confirmation = score_before;
    }
    // The flight's reaction: a confirmed stuck-on closes its pod; the test closes the pod asked.
    t.valve = {{true, true, true, true}};
    if (d.confirmed_on() != 0) {
      for (int i = 0; i < 16; ++i) {
        if ((d.confirmed_on() >> i) & 1u) t.valve[static_cast<std::size_t>(i / 4)] = false;
      }
    }
    // A test ends when its pod reopens or another test closes another pod on the same update.
    const int pp = d.probe_pod();
    if (pp != last_pod) {
      if (last_pod >= 0) out.probe_ends.push_back(k);
      if (pp >= 0) {
        out.probe_pods.push_back(pp);
        out.probe_starts.push_back(k);
        out.probe_start_scores.push_back(d.status().best_llr);
      }
      last_pod = pp;
    }
    if (pp >= 0) {
      t.valve[static_cast<std::size_t>(pp)] = false;
      ++out.probe_windows_closed;
    }
    Vec16 cmd = random_firing(rng) * firing_scale;
    cmd(2) = cmd(3) = cmd(10) = cmd(11) = 0.0;  // channels 1 and 5 never commanded
    t.advance(cmd);
    prev = cmd;
    prev_valve = t.valve;
  }
  out.probes = d.status().probes;
  return out;
}

// Confirmed by a test of pod 0: in the 10-tick window that reopens it or its evaluation.
bool confirmed_by_a_test_of_pod_0(const AmbiguousRun& run) {
  for (std::size_t i = 0; i < run.probe_ends.size(); ++i) {
    const int end = run.probe_ends[i];
    if (run.probe_pods[i] == 0 && run.r.confirmed_at >= end &&
        run.r.confirmed_at <= end + 10 + FaultDetector::kEvaluationSteps + 1) {
      return true;
    }
  }
  return false;
}

TEST(FaultDetector, OppositePodAxialJetsAreNotConfusedWhenOnlyTheModelErrorSeparatesThem) {
  FaultDetectorParams former;
  former.model_sigmas = 0.0;
  former.probe_windows = 0;
  const AmbiguousRun old_rule = fly_ambiguous(former);
  ASSERT_GE(old_rule.r.confirmed_at, 0);
  EXPECT_EQ(old_rule.r.thruster, 11) << "the trap: the former rule confirms the mirror jet";

  const AmbiguousRun now = fly_ambiguous(FaultDetectorParams{});
  ASSERT_GE(now.r.confirmed_at, 0) << "not isolated";
  EXPECT_EQ(now.r.thruster, 2);
  EXPECT_EQ(now.r.kind, FaultKind::kStuckOn);
  EXPECT_GE(now.probes, 1u);
  EXPECT_GT(now.probe_windows_closed, 0);
}

// (F39) The trap's first test closes the mirror jet's pod (2): jet 2 goes on firing behind pod 0's
// open valve, and the closed window shows it, led by a stuck-on jet off pod 2. The reopened window
// could not name a jet of pod 2 then; with (F39) the test of pod 0 starts on the update the first
// test's closure ends, not a window later. Jet 2 is confirmed either way.
TEST(FaultDetector, ATestWhoseClosedWindowShowsTheMotionIsFollowedAtOnceByTheNext) {
  FaultDetectorParams p;
  p.probe_windows = 1;  // gnc.yaml's
  p.probe_aligned = true;
  p.probe_read_closed = true;
  p.probe_partial_rival = true;
  p.centred_gyro_noise = true;
  const AmbiguousRun wait = fly_ambiguous(p);
  p.probe_chain = true;
  const AmbiguousRun chain = fly_ambiguous(p);
  for (const AmbiguousRun* run : {&wait, &chain}) {
    ASSERT_GE(run->r.confirmed_at, 0);
    EXPECT_EQ(run->r.thruster, 2);
    EXPECT_EQ(run->r.kind, FaultKind::kStuckOn);
  }
  ASSERT_GE(wait.probe_pods.size(), 2u);
  ASSERT_GE(chain.probe_pods.size(), 2u);
  EXPECT_EQ(wait.probe_pods[0], 2) << "the trap: the first test is of the mirror jet's pod";
  EXPECT_EQ(chain.probe_pods[0], 2);
  EXPECT_EQ(chain.probe_pods[1], 0);
  // Without (F39) the next test waits for the reopened window (10 ticks and its evaluation); with
  // it the pod is closed again on the update the first closure ended.
  EXPECT_GE(wait.probe_starts[1] - wait.probe_ends[0], 10);
  EXPECT_LE(chain.probe_starts[1] - chain.probe_ends[0], 1);
  // Not asserted: that the confirmation comes sooner. It does on x86-64 (tick 272 against 282);
  // on the aarch64 build the test of pod 0 started a window sooner is read differently and jet 2
  // is confirmed later (272 against 234), as 9 of the 33 stuck-on runs the dispersion moved.
}

// (F52) A test may start on a stuck-on leader whose score is past probe_start_llr, below
// confirm_llr. In the mirror trap the first test then starts sooner, on a score below the
// confirmation level (without F52 every test starts past it), and jet 2 is confirmed stuck on
// either way; the early test's verdict names it only once its own score is past confirm_llr.
TEST(FaultDetector, AnIsolationTestMayStartOnAStuckOnLeaderBelowTheConfirmationLevel) {
  FaultDetectorParams p;  // gnc.yaml's isolation tests
  p.probe_windows = 1;
  p.probe_aligned = true;
  p.probe_read_closed = true;
  p.probe_partial_rival = true;
  p.centred_gyro_noise = true;
  ASSERT_TRUE(validate(p).ok);
  const AmbiguousRun late = fly_ambiguous(p);
  p.probe_start_llr = 8.0;
  ASSERT_TRUE(validate(p).ok);
  const AmbiguousRun early = fly_ambiguous(p);
  for (const AmbiguousRun* run : {&late, &early}) {
    ASSERT_GE(run->r.confirmed_at, 0) << "not isolated";
    EXPECT_EQ(run->r.thruster, 2);
    EXPECT_EQ(run->r.kind, FaultKind::kStuckOn);
    ASSERT_FALSE(run->probe_starts.empty());
    EXPECT_GT(run->score_before_confirmation, p.confirm_llr);
  }
  for (double s : late.probe_start_scores) EXPECT_GT(s, p.confirm_llr);
  EXPECT_GT(early.probe_start_scores[0], p.probe_start_llr);
  EXPECT_LE(early.probe_start_scores[0], p.confirm_llr);
  EXPECT_LT(early.probe_starts[0], late.probe_starts[0]);
  EXPECT_GT(early.probe_starts[0], 50) << "a test before the fault";
}

// (F52) Healthy firing at both gyro noise levels with early tests from 8: whatever tests start,
// none names a jet, as no healthy score reaches confirm_llr.
TEST(FaultDetector, HealthyFiringConfirmsNothingWithEarlyIsolationTests) {
  for (double sigma : {3.1623e-6, 3.1623e-5}) {
    Truth t;
    t.gyro_sigma = sigma;
    FaultDetectorParams p = bank_params(sigma);
    p.probe_windows = 1;
    p.probe_aligned = true;
    p.probe_read_closed = true;
    p.probe_read_elsewhere = true;
    p.probe_start_llr = 8.0;
    FaultDetector d = make_detector(t, p);
    const RunResult r = fly(t, d, 20000, -1, -1, -1);  // 2000 s
    EXPECT_LT(r.confirmed_at, 0) << "false alarm: thruster " << r.thruster << " after "
                                 << d.status().probes << " tests";
    EXPECT_EQ(d.confirmed_on() | d.confirmed_off(), 0);
  }
}

// (F16) The tests are read on the likelihood of all their windows. In a reopened window alone the
// model's signature of the mirror jet 11 is exactly the truth's of 2 (the trap above), and the
// window is a few sigma at most: the window-alone verdict (F15) never names 2, and the scores
// settle it only after many tests. Over the closed windows 11, behind an open valve, would have
// fired and did not: the sum over consecutive tests of pod 0 confirms 2 in a reopened window.
TEST(FaultDetector, TheIsolationTestIsReadOverAllItsWindows) {
  const AmbiguousRun run = fly_ambiguous(FaultDetectorParams{});
  ASSERT_GE(run.r.confirmed_at, 0) << "not isolated";
  EXPECT_EQ(run.r.thruster, 2);
  EXPECT_EQ(run.r.kind, FaultKind::kStuckOn);
  EXPECT_TRUE(confirmed_by_a_test_of_pod_0(run))
      << "confirmed at tick " << run.r.confirmed_at << " after " << run.probe_ends.size()
      << " tests, not by a test's outcome";
}

// (F27) A test of one window. The decision that starts a test comes kEvaluationSteps updates into
// the next window, so without the alignment that window is flown partly open, the test ends in its
// decision with no window flown closed throughout (F15) and nothing to read. Aligned, the closure
// starts a window: each test is closed for exactly one window and its evaluation, and the trap's
// jet is confirmed by a test of its pod.
TEST(FaultDetector, AnAlignedTestOfOneWindowIsFlownClosedThroughoutAndRead) {
  FaultDetectorParams unaligned;
  unaligned.probe_windows = 1;
  const AmbiguousRun before = fly_ambiguous(unaligned);
  EXPECT_GE(before.probes, 1u);
  ASSERT_FALSE(before.probe_ends.empty());
  for (std::size_t i = 0; i < before.probe_ends.size(); ++i) {
    EXPECT_NE(before.r.confirmed_at, before.probe_ends[i] + 10 + FaultDetector::kEvaluationSteps)
        << "an unaligned one-window test has no closed window to read";
  }
  EXPECT_NE(before.r.thruster, 11);

  FaultDetectorParams aligned = unaligned;
  aligned.probe_aligned = true;
  const AmbiguousRun run = fly_ambiguous(aligned);
  ASSERT_GE(run.r.confirmed_at, 0) << "not isolated";
  EXPECT_EQ(run.r.thruster, 2);
  EXPECT_EQ(run.r.kind, FaultKind::kStuckOn);
  ASSERT_FALSE(run.probe_ends.empty());
  // Each test: one window of 10 ticks from its closure, plus the evaluation that ends it.
  const int per_test = 10 + FaultDetector::kEvaluationSteps;
  EXPECT_EQ(run.probe_windows_closed, per_test * static_cast<int>(run.probe_ends.size()));
  EXPECT_TRUE(confirmed_by_a_test_of_pod_0(run))
      << "confirmed at tick " << run.r.confirmed_at << " after " << run.probe_ends.size()
      << " tests, not by a test's outcome";
  // The first aligned test is read one window sooner than the first unaligned two-window test.
  FaultDetectorParams two_windows;
  two_windows.probe_windows = 2;
  const AmbiguousRun two = fly_ambiguous(two_windows);
  ASSERT_FALSE(two.probe_ends.empty());
  EXPECT_LT(run.probe_ends.front(), two.probe_ends.front());
}

// (F32) The trap's test read on the window that started it and the closed one. With the other jets
// at a tenth of their firing (the model's noise, F5, charges the centre of mass's 1 sigma against
// their force) one window of the stuck jet stands far above the noise, but the mirror jet 11 still
// explains it within the model's error (F8), so a test closes pod 0. The motion was there before
// the closure and gone behind it, where 11, behind its open valve, would have fired: the trap's
// jet is confirmed when the deciding test's closed window ends (the first test on x86-64; under
// aarch64's rounding a test of the mirror's pod 2 comes first, as with the reopened window's
// verdict), pod 0 is not reopened
// after it, and the confirmation comes at least one window before the reopened window's (F15).
TEST(FaultDetector, AStuckOnJetDecidedBehindItsClosedValveNeverFiresAgain) {
  constexpr double kLightFiring = 0.1;
  FaultDetectorParams p;
  p.probe_windows = 1;
  p.probe_aligned = true;
  const AmbiguousRun reopened = fly_ambiguous(p, kLightFiring);
  ASSERT_GE(reopened.r.confirmed_at, 0) << "not isolated";
  ASSERT_FALSE(reopened.probe_ends.empty()) << "the trap needs a test";
  EXPECT_EQ(reopened.r.thruster, 2);

  p.probe_read_closed = true;
  const AmbiguousRun run = fly_ambiguous(p, kLightFiring);
  ASSERT_GE(run.r.confirmed_at, 0) << "not isolated";
  EXPECT_EQ(run.r.thruster, 2);
  EXPECT_EQ(run.r.kind, FaultKind::kStuckOn);
  std::printf("closed-window verdict: confirmed at tick %d after %zu tests (reopened window's: %d "
              "after %zu)\n", run.r.confirmed_at, run.probe_ends.size(), reopened.r.confirmed_at,
              reopened.probe_ends.size());
  ASSERT_FALSE(run.probe_ends.empty());
  EXPECT_EQ(run.probe_pods.back(), 0) << "decided by a test of the stuck jet's pod";
  EXPECT_LE(run.probe_ends.size(), reopened.probe_ends.size());
  // The deciding test ends on the update that confirms: the confirmation's valve takes over from
  // the test's, so the pod is not reopened after it.
  EXPECT_EQ(run.r.confirmed_at, run.probe_ends.back());
  EXPECT_EQ(run.probe_windows_closed,
            (10 + FaultDetector::kEvaluationSteps) * static_cast<int>(run.probe_ends.size()));
  EXPECT_LE(run.r.confirmed_at + 10, reopened.r.confirmed_at)
      << "read on the closed window, at least one window before the reopened one";
}

TEST(FaultDetector, WithoutTheIsolationTestAnAmbiguousPairIsNeverDecided) {
  FaultDetectorParams p;
  p.probe_windows = 0;  // (F8) alone: a later correct decision or none, never the wrong one
  const AmbiguousRun run = fly_ambiguous(p);
  EXPECT_NE(run.r.thruster, 11);
  EXPECT_EQ(run.probes, 0u);
  EXPECT_EQ(run.probe_windows_closed, 0);
}

// (F17) Pod sweep before the model is identified: J 10 % off about two axes and r 0.54 m off (its
// 1 sigma 0.5 m), so the bank's residual noise (F5) hides any jet. The identifier's fault torque
// (I22) stands out from zero every 20 s but matches no jet (chi-square 50 against each): each pod
// is closed in turn and the step of the unexplained acceleration names the stuck jet.
struct SweepRun {
  RunResult r;
  std::uint32_t sweeps{0};
  std::uint32_t sweep_confirmations{0};
  int ticks_closed{0};
};

SweepRun fly_sweep(bool sweep, int stuck, std::uint64_t seed, int stuck_off = -1) {
  Truth t;
  t.rng.seed(seed);
  FaultDetectorParams p = bank_params(t.gyro_sigma);
  p.identified_isolation = true;
  p.identified_sweep = sweep;
  FaultDetector d;
  d.configure(p, study_rcs_layout(kUmax), kUmax, kDt);
  FaultModel m;
  m.j = t.body.j;
  m.j(0, 0) *= 1.1;
  m.j(1, 1) *= 0.9;
  m.r = t.r + V3(0.4, -0.3, 0.2);
  m.j_rel_sigma = 0.1;
  m.r_cov = Mat3::Identity() * 0.25;
  m.k_sigma = 0.01;
  d.set_model(m);
  std::mt19937_64 rng(seed + 1);
  Vec16 prev = Vec16::Zero();
  std::array<bool, 4> prev_valve = t.valve;
  SweepRun out;
  for (int k = 0; k < 6000; ++k) {
    if (k == 50) {
      t.stuck_on = stuck;
      t.stuck_off = stuck_off;
    }
    if (k > 0 && k % 200 == 0) {  // an identifier window: the fault torque off zero, unmatched
      StuckOnEvidence e;
      e.fitted = true;
      e.chi2_zero = 400.0;
      e.chi2_jet.fill(50.0);
      e.chi2_column.fill(400.0);
      d.identified_evidence(e);
    }
    FaultDetectorInput in;
    in.omega = t.gyro();
    in.omega_valid = true;
    in.thrust = prev;
    in.valve_open = prev_valve;
    const FaultEvents e = d.update(in);
    if (e.confirmed && out.r.confirmed_at < 0) {
      out.r.confirmed_at = k;
      out.r.thruster = e.thruster;
      out.r.kind = e.kind;
    }
    t.valve = {{true, true, true, true}};
    for (int i = 0; i < 16; ++i) {
      if ((d.confirmed_on() >> i) & 1u) t.valve[static_cast<std::size_t>(i / 4)] = false;
    }
    if (d.probe_pod() >= 0) {
      t.valve[static_cast<std::size_t>(d.probe_pod())] = false;
      ++out.ticks_closed;
    }
    Vec16 cmd = 0.1 * random_firing(rng);  // a despin's few percent of u_max
    if (stuck_off >= 0 && k >= 50) {
      // The controller, short of that jet's torque, commands it hard (and not its opposite).
      cmd(stuck_off) = 150.0;
      cmd(stuck_off ^ 1) = 0.0;
    }
    t.advance(cmd);
    prev = cmd;
    prev_valve = t.valve;
  }
  out.sweeps = d.status().sweeps;
  out.sweep_confirmations = d.status().sweep_confirmations;
  return out;
}

TEST(FaultDetector, APodSweepIsolatesAStuckOnJetBeforeTheModelIsIdentified) {
  for (const int jet : {0, 6, 9, 15}) {
    SCOPED_TRACE(jet);
    const SweepRun without = fly_sweep(false, jet, 3);
    EXPECT_LT(without.r.confirmed_at, 0) << "the bank alone should be blind with this model";
    EXPECT_EQ(without.ticks_closed, 0);
    const SweepRun with = fly_sweep(true, jet, 3);
    ASSERT_GE(with.r.confirmed_at, 0) << "not isolated";
    EXPECT_EQ(with.r.thruster, jet);
    EXPECT_EQ(with.r.kind, FaultKind::kStuckOn);
    EXPECT_EQ(with.sweep_confirmations, 1u);
    EXPECT_GE(with.sweeps, 1u);
  }
}

// A jet stuck off and commanded hard leaves a step when its pod closes (the prediction drops the
// thrust the truth never had): the sweep scores it as a stuck-off alternative and confirms no
// stuck-on jet in its place.
TEST(FaultDetector, APodSweepDoesNotTakeAStuckOffJetForAStuckOnOne) {
  for (const int jet : {4, 12}) {
    SCOPED_TRACE(jet);
    const SweepRun run = fly_sweep(true, -1, 3, jet);
    EXPECT_GE(run.sweeps, 1u);
    EXPECT_EQ(run.sweep_confirmations, 0u) << "confirmed thruster " << run.r.thruster;
    if (run.r.confirmed_at >= 0) {
      EXPECT_EQ(run.r.thruster, jet);
      EXPECT_EQ(run.r.kind, FaultKind::kStuckOff);
    }
  }
}

TEST(FaultDetector, APodSweepInAHealthyFlightConfirmsNothing) {
  for (const std::uint64_t seed : {3u, 4u, 5u, 6u}) {
    SCOPED_TRACE(seed);
    const SweepRun run = fly_sweep(true, -1, seed);
    EXPECT_LT(run.r.confirmed_at, 0) << "confirmed thruster " << run.r.thruster;
    EXPECT_GE(run.sweeps, 3u);  // swept again and again: every pod closed, nothing confirmed
    EXPECT_GT(run.ticks_closed, 0);
  }
}

TEST(FaultDetector, TheModelIsHeldWhileAFaultIsSuspected) {
  Truth t;
  FaultDetector d = make_detector(t, t.gyro_sigma);
  std::mt19937_64 rng(9);
  Vec16 prev = Vec16::Zero();
  t.stuck_on = 5;
  int k = 0;
  for (; k < 400 && !d.suspecting(); ++k) {
    FaultDetectorInput in;
    in.omega = t.gyro();
    in.omega_valid = true;
    in.thrust = prev;
    d.update(in);
    const Vec16 cmd = random_firing(rng);
    t.advance(cmd);
    prev = cmd;
  }
  ASSERT_TRUE(d.suspecting());
  ASSERT_EQ(d.confirmed_on(), 0) << "confirmed before the hold could be seen";
  // A model that has absorbed the fault (r moved by a metre) is not taken while suspected.
  FaultModel absorbed;
  absorbed.j = t.body.j;
  absorbed.r = t.r + V3(1.0, 0.0, 0.0);
  d.set_model(absorbed);
  EXPECT_EQ(d.status().models_held, 1u);
  d.clear(-1);  // nothing suspected any more: the next model is taken
  d.set_model(absorbed);
  EXPECT_EQ(d.status().models_held, 1u);
  EXPECT_FALSE(d.suspecting());
}

// (F10) A closed window is scored over the next kEvaluationSteps updates from its own set of sums,
// while the next window accumulates in the other: the scores of that window do not depend on what
// arrives during its evaluation (a gap in the gyro, a new model), a model that arrives then is
// taken exactly when the evaluation ends, and nothing is lost or double counted.
TEST(FaultDetector, AClosedWindowIsScoredOverTheNextTicksWithTheModelItWasPredictedWith) {
  Truth t;
  t.stuck_on = 6;  // a fault, so the scores carry information
  std::vector<FaultDetectorInput> inputs;
  {
    std::mt19937_64 rng(3);
    Vec16 prev = Vec16::Zero();
    for (int k = 0; k < 60; ++k) {
      FaultDetectorInput in;
      in.omega = t.gyro();
      in.omega_valid = true;
      in.thrust = prev;
      inputs.push_back(in);
      const Vec16 cmd = random_firing(rng);
      t.advance(cmd);
      prev = cmd;
    }
  }
  FaultDetectorParams p = bank_params(t.gyro_sigma);
  p.confirm_llr = 1e30;  // never confirm: compare the scores
  const FaultModel m = identified_model(t);
  FaultModel other = m;
  other.r += V3(0.05, -0.02, 0.03);
  other.k(6) = 0.9;
  auto make = [&] {
    FaultDetector d;
    d.configure(p, study_rcs_layout(kUmax), kUmax, kDt);
    d.set_model(m);
    return d;
  };
  // The first window closes on update 10 (samples 1..10 after the start at update 0); its
  // evaluation runs on updates 11, 12, 13.
  const int close = 10;
  FaultDetector plain = make();
  FaultDetector staged = make();   // the other model arrives during the evaluation
  FaultDetector later = make();    // the other model arrives right after it
  FaultDetector gap = make();      // the gyro drops out right after the close
  for (int k = 0; k < static_cast<int>(inputs.size()); ++k) {
    if (k == close + 1) {
      staged.set_model(other);
      EXPECT_TRUE(staged.evaluating());
    }
    if (k == close + 1 + FaultDetector::kEvaluationSteps) later.set_model(other);
    plain.update(inputs[static_cast<std::size_t>(k)]);
    staged.update(inputs[static_cast<std::size_t>(k)]);
    later.update(inputs[static_cast<std::size_t>(k)]);
    FaultDetectorInput g = inputs[static_cast<std::size_t>(k)];
    if (k == close + 1) g.omega_valid = false;
    gap.update(g);
    if (k == close) {
      EXPECT_TRUE(plain.evaluating());
      EXPECT_EQ(plain.status().windows, 0u);  // nothing scored on the close itself
    }
    if (k == close + FaultDetector::kEvaluationSteps) {
      EXPECT_FALSE(plain.evaluating());
      ASSERT_EQ(plain.status().windows, 1u);
      // The same scores whatever arrived during the evaluation.
      for (const FaultDetector* d : {&staged, &later, &gap}) {
        EXPECT_EQ(d->status().windows, 1u);
        EXPECT_EQ(d->status().best, plain.status().best);
        EXPECT_EQ(d->status().best_llr, plain.status().best_llr);
        EXPECT_EQ(d->status().chi2, plain.status().chi2);
        EXPECT_EQ(d->status().residual, plain.status().residual);
        for (int h = 0; h < FaultDetector::kHypotheses; ++h) {
          EXPECT_EQ(d->signature(h), plain.signature(h)) << h;
        }
      }
      EXPECT_GT(plain.status().best_llr, 0.0);
    }
  }
  // The staged model was taken on the first update after the evaluation: from then on the run is
  // the one that received it then, bit for bit; and it differs from the run that never did.
  EXPECT_EQ(staged.status().windows, later.status().windows);
  EXPECT_EQ(staged.status().best_llr, later.status().best_llr);
  EXPECT_EQ(staged.status().chi2, later.status().chi2);
  EXPECT_EQ(staged.status().residual, later.status().residual);
  EXPECT_NE(staged.status().chi2, plain.status().chi2);
  // The gap broke only the open window, which restarted on the next sample: windows closed on
  // updates 10, 22, 32, 42, 52 against 10, 20, ..., 50.
  EXPECT_EQ(gap.status().windows, plain.status().windows);
  EXPECT_NE(gap.status().chi2, plain.status().chi2);
}

// (F19) Jet checks. The detector asks for a jet whose stuck-off or partial-loss evidence reaches
// check_llr to be fired at check_force_n for check_windows windows; the flight adds it in the
// null space of B_hat. Here the harness adds it to the command of that jet alone (the truth is
// the detector's model, so the extra torque is predicted). Weak firing as the D+PD despin's
// (4-15 N per jet): each window alone is far below the observability threshold.
struct CheckRun : DegradedRun {
  std::vector<int> checked;       // the jet of each check, in order
  std::vector<int> check_ticks;   // the tick each check started
  std::vector<bool> surveyed;     // per check: started by the survey (F36)
  int checked_ticks{0};           // ticks flown with a check
};

// Flies the detector's checks on top of `firing` (its next(tick) gives the commanded thrust);
// thruster stuck_off dies at tick onset (-1: as the truth was given).
template <class Firing>
CheckRun fly_checks(Truth& t, FaultDetector& d, Firing firing, int ticks, int onset = -1,
                    int stuck_off = -1, int survey_from = 0, bool stop_at_confirmation = false) {
  Vec16 prev = Vec16::Zero();
  CheckRun run;
  for (int k = 0; k < ticks; ++k) {
    if (k == onset) t.stuck_off = stuck_off;
    FaultDetectorInput in;
    in.omega = t.gyro();
    in.omega_valid = true;
    in.thrust = prev;
    in.valve_open = t.valve;
    in.survey_allowed = k >= survey_from;  // (F43) the GNC's mode gate
    const int before = d.check_jet();
    const std::uint32_t surveys = d.status().surveys;
    run.note(d.update(in), k);
    if (stop_at_confirmation && run.confirmations > 0) break;
    if (d.check_jet() >= 0 && d.check_jet() != before) {
      run.checked.push_back(d.check_jet());
      run.check_ticks.push_back(k);
      run.surveyed.push_back(d.status().surveys == surveys + 1);
    }
    Vec16 cmd = firing.next(k);
    if (d.check_jet() >= 0) {
      cmd(d.check_jet()) += d.check_force();
      ++run.checked_ticks;
    }
    t.advance(cmd);
    prev = cmd;
  }
  return run;
}

CheckRun fly_checked(Truth& t, FaultDetector& d, int ticks, std::uint64_t seed) {
  return fly_checks(t, d, WeakFiring(seed), ticks);
}

FaultDetector make_checking_detector(const Truth& t, double check_llr) {
  return make_detector(t, t.gyro_sigma, 0.1, check_llr);
}

TEST(FaultDetector, AJetCheckIsolatesAWeaklyCommandedStuckOffJetWithinItsWindows) {
  int within_20s = 0;
  for (int i : {1, 6, 11, 13}) {
    const std::string what = "thruster " + std::to_string(i);
    // Without checks: the pooled windows (F11) confirm it, late.
    Truth t0;
    t0.stuck_off = i;
    FaultDetector passive = make_checking_detector(t0, 0.0);
    const CheckRun slow = fly_checked(t0, passive, 30000, 100 + static_cast<std::uint64_t>(i));
    ASSERT_GE(slow.r.confirmed_at, 0) << what;
    EXPECT_TRUE(slow.checked.empty());
    EXPECT_EQ(passive.status().checks, 0u);
    // With checks at 5: the jet's evidence reaches 5 long before 25 and it is checked.
    Truth t;
    t.stuck_off = i;
    FaultDetector d = make_checking_detector(t, 5.0);
    const CheckRun fast = fly_checked(t, d, 30000, 100 + static_cast<std::uint64_t>(i));
    ASSERT_GE(fast.r.confirmed_at, 0) << what;
    EXPECT_EQ(fast.r.thruster, i) << what;
    EXPECT_EQ(fast.r.kind, FaultKind::kStuckOff) << what;
    EXPECT_EQ(fast.confirmations, 1) << what;
    // The jet was checked before its confirmation (a check of another jet that also had
    // evidence may come between), and mostly confirmed within 20 s of that check (below).
    const auto own = std::find(fast.checked.begin(), fast.checked.end(), i);
    ASSERT_NE(own, fast.checked.end()) << what << ": never checked";
    const int own_tick = fast.check_ticks[static_cast<std::size_t>(own - fast.checked.begin())];
    EXPECT_GE(fast.r.confirmed_at, own_tick) << what;
    within_20s += fast.r.confirmed_at - own_tick <= 200 ? 1 : 0;
    EXPECT_LT(fast.r.confirmed_at, slow.r.confirmed_at) << what;
    // The check ends with the confirmation: the jet is latched and no longer fired for it.
    EXPECT_EQ(d.check_jet(), -1) << what;
    EXPECT_EQ(d.status().check_jet, -1) << what;
  }
  // Three of the four within 20 s of the jet's check (x86-64: all four, 2-16 s; the aarch64
  // build's run of thruster 6 is confirmed 117 s after its check, still before the pooled
  // windows alone).
  EXPECT_GE(within_20s, 3);
}

TEST(FaultDetector, AJetCheckConfirmsAPartialLossWithItsFactor) {
  for (int i : {4, 9}) {
    const std::string what = "thruster " + std::to_string(i);
    Truth t;
    t.degraded = i;
    t.degraded_factor = 0.5;
    FaultDetector d = make_checking_detector(t, 5.0);
    const CheckRun run = fly_checked(t, d, 30000, 300 + static_cast<std::uint64_t>(i));
    ASSERT_GE(run.r.confirmed_at, 0) << what;
    EXPECT_EQ(run.r.thruster, i) << what;
    EXPECT_EQ(run.r.kind, FaultKind::kDegraded) << what;
    EXPECT_NEAR(run.factor, 0.5, 3.0 * run.factor_sigma) << what;
    EXPECT_LT(run.factor_sigma, 0.1) << what;
    const auto own = std::find(run.checked.begin(), run.checked.end(), i);
    ASSERT_NE(own, run.checked.end()) << what << ": never checked";
    EXPECT_GE(run.r.confirmed_at, run.check_ticks[static_cast<std::size_t>(own - run.checked.begin())]);
    EXPECT_EQ(run.confirmations, 1) << what;
    // Without checks the same weak firing has not decided it by the time the check has.
    Truth t0;
    t0.degraded = i;
    t0.degraded_factor = 0.5;
    FaultDetector passive = make_checking_detector(t0, 0.0);
    const CheckRun slow = fly_checked(t0, passive, run.r.confirmed_at + 1, 300 + static_cast<std::uint64_t>(i));
    EXPECT_LT(slow.r.confirmed_at, 0) << what;
  }
}

// (F31) A jet stuck on near a check of a healthy jet, every jet at onsets before, inside and after
// that check. A check's windows are not scored when they show motion that is not the checked
// jet's (F19), so a check started on the stuck-off evidence that the stuck jet's first window
// raised in another jet kept the bank from scoring the stuck jet. With (F31) no check starts after
// a suspicious window for a jet that window's motion is not along. The harness honours the
// detector's isolation tests (F9: the tested pod's valve closed) as the Gnc does. Check level low,
// as in the healthy-check test below, so that checks are flown around the onsets.
struct StuckDuringCheck {
  DegradedRun run;
  int checked_ticks_to_confirmation{0};  // ticks flown with any check from the onset to the confirmation
  // Checks started on the decision after a suspicious window (the evaluated window's chi-square
  // above suspect_chi2) for a jet whose signature (the truth's b_i = J^-1 (p_i + r) x e_i) is more
  // than 30 degrees off that window's unexplained rate change.
  int misaligned_starts{0};
  int suspicious_starts{0};  // (F34) checks started on the decision after a suspicious window
};
StuckDuringCheck fly_stuck_during_check(bool fit_on_suspicion, int stuck, int onset,
                                        std::uint64_t seed, bool quiet_start = false) {
  Truth t;
  FaultDetectorParams p = check_rig_params(t);
  p.check_fit_on_suspicion = fit_on_suspicion;
  p.check_quiet_start = quiet_start;
  FaultDetector d = make_detector(t, p);
  WeakFiring firing(seed);
  Vec16 prev = Vec16::Zero();
  StuckDuringCheck out;
  for (int k = 0; k < onset + 2000 && out.run.r.confirmed_at < 0; ++k) {
    if (k == onset) t.stuck_on = stuck;
    for (int q = 0; q < 4; ++q) t.valve[static_cast<std::size_t>(q)] = d.probe_pod() != q;
    FaultDetectorInput in;
    in.omega = t.gyro();
    in.omega_valid = true;
    in.thrust = prev;
    in.valve_open = t.valve;
    const int checking = d.check_jet();
    out.run.note(d.update(in), k);
    const int jet = d.check_jet();
    if (jet >= 0 && jet != checking && d.status().chi2 > p.suspect_chi2) {
      ++out.suspicious_starts;
      const auto i = static_cast<std::size_t>(jet);
      const V3 b = t.body.j.inverse() * (t.pos[i] + t.r).cross(t.dir[i]);
      const V3 m = d.status().residual;
      const double c = std::fabs(b.dot(m)) / (b.norm() * m.norm());
      if (c < std::cos(30.0 * M_PI / 180.0)) ++out.misaligned_starts;
    }
    Vec16 cmd = firing.next(k);
    if (jet >= 0) {
      cmd(jet) += d.check_force();
      if (k >= onset && out.run.r.confirmed_at < 0) ++out.checked_ticks_to_confirmation;
    }
    t.advance(cmd);
    prev = cmd;
  }
  return out;
}

TEST(FaultDetector, NoCheckStartsForAnEvidentFaultThatIsNotItsJet) {
  // Where the first check of a healthy jet starts under this firing.
  Truth t0;
  FaultDetector d0 = make_checking_detector(t0, 0.5);
  const CheckRun healthy = fly_checked(t0, d0, 40000, 5);
  ASSERT_FALSE(healthy.checked.empty());
  const int start = healthy.check_ticks[0];
  int given_way = 0;
  int misaligned_before = 0;
  int misaligned_after = 0;
  for (int stuck = 0; stuck < 16; ++stuck) {
    for (int off : {-200, -50, 1, 3, 5, 7, 9, 100, 400, 1000}) {
      const int onset = start + off;
      const std::string what = "thruster " + std::to_string(stuck) + " stuck on at tick " +
                               std::to_string(onset);
      const StuckDuringCheck before = fly_stuck_during_check(false, stuck, onset, 5);
      const StuckDuringCheck after = fly_stuck_during_check(true, stuck, onset, 5);
      for (const StuckDuringCheck* r : {&before, &after}) {
        ASSERT_GE(r->run.r.confirmed_at, onset) << what;
        EXPECT_EQ(r->run.r.thruster, stuck) << what;
        EXPECT_EQ(r->run.r.kind, FaultKind::kStuckOn) << what;
        EXPECT_EQ(r->run.confirmations, 1) << what;
      }
      // (F31) never later, never more check firing between the onset and the confirmation.
      EXPECT_LE(after.run.r.confirmed_at, before.run.r.confirmed_at) << what;
      EXPECT_LE(after.checked_ticks_to_confirmation, before.checked_ticks_to_confirmation) << what;
      misaligned_before += before.misaligned_starts;
      misaligned_after += after.misaligned_starts;
      if (after.checked_ticks_to_confirmation < before.checked_ticks_to_confirmation &&
          after.run.r.confirmed_at + 10 <= before.run.r.confirmed_at) {
        ++given_way;
        RecordProperty("given_way_" + std::to_string(stuck) + "_" + std::to_string(off),
                       std::to_string(before.run.r.confirmed_at - onset) + " -> " +
                           std::to_string(after.run.r.confirmed_at - onset) + " ticks");
      }
    }
  }
  RecordProperty("misaligned_starts_without", misaligned_before);
  RecordProperty("given_way", given_way);
  // With (F31) no check starts after a suspicious window for a jet that window's motion is not
  // along (checked here against the truth's signatures, independently of the detector's fit).
  EXPECT_EQ(misaligned_after, 0);
  // Where such a check started without (F31), the stuck jet was confirmed at least a window
  // sooner with it. The chaotic rig makes that happen on x86-64 (jet 4 at +3 and one more run:
  // 127 -> 97 ticks), not under aarch64's rounding, where no misaligned check starts either way.
  if (misaligned_before > 0) {
    EXPECT_GE(given_way, 1) << "a misaligned check started and held the confirmation back";
  }
}

// (F34) The same 160 runs with checks started only on quiet windows (F31 on in both): no check
// starts after a suspicious window at all, and every stuck jet is confirmed to itself, never later
// and with no more check firing than with (F31) alone. Where (F31) started one (a jet the
// suspicious window's motion lies along: the stuck jet's channel partner, whose stuck-off has the
// same direction), the stuck jet is confirmed at least a window sooner without it.
TEST(FaultDetector, NoCheckStartsOnASuspiciousWindow) {
  Truth t0;
  FaultDetector d0 = make_checking_detector(t0, 0.5);
  const CheckRun healthy = fly_checked(t0, d0, 40000, 5);
  ASSERT_FALSE(healthy.checked.empty());
  const int start = healthy.check_ticks[0];
  int suspicious_before = 0, suspicious_after = 0, sooner = 0;
  for (int stuck = 0; stuck < 16; ++stuck) {
    for (int off : {-200, -50, 1, 3, 5, 7, 9, 100, 400, 1000}) {
      const int onset = start + off;
      const std::string what = "thruster " + std::to_string(stuck) + " stuck on at tick " +
                               std::to_string(onset);
      const StuckDuringCheck before = fly_stuck_during_check(true, stuck, onset, 5, false);
      const StuckDuringCheck after = fly_stuck_during_check(true, stuck, onset, 5, true);
      ASSERT_GE(after.run.r.confirmed_at, onset) << what;
      EXPECT_EQ(after.run.r.thruster, stuck) << what;
      EXPECT_EQ(after.run.r.kind, FaultKind::kStuckOn) << what;
      EXPECT_EQ(after.run.confirmations, 1) << what;
      EXPECT_LE(after.run.r.confirmed_at, before.run.r.confirmed_at) << what;
      EXPECT_LE(after.checked_ticks_to_confirmation, before.checked_ticks_to_confirmation) << what;
      suspicious_before += before.suspicious_starts;
      suspicious_after += after.suspicious_starts;
      if (before.suspicious_starts > 0 &&
          after.run.r.confirmed_at + 10 <= before.run.r.confirmed_at) {
        ++sooner;
      }
    }
  }
  std::printf("checks started on a suspicious window: %d with F31 alone, %d with F34; %d stuck "
              "jets confirmed a window or more sooner\n", suspicious_before, suspicious_after, sooner);
  EXPECT_EQ(suspicious_after, 0);
  if (suspicious_before > 0) {
    EXPECT_GE(sooner, 1);
  }
}

// (F35) The flight fires a check in the null space of B_hat, so jets beside the checked one fire
// firmly too. Here every check of a jet also fires `partner` at the check force (the truth is the
// detector's model, so the extra torque is predicted). The partner is stuck off from shortly
// before the first check: the check window's motion is the partner's missing torque, normal to
// the checked jet's signature, so the window is unfit (F19). Unscored (F35 off), it teaches the
// bank nothing and the partner waits for its own evidence; scored with the model's error of every
// jet fired (F35 on), it confirms the partner stuck off from the check's windows.
struct PartnerRun {
  DegradedRun run;
  int first_check{-1};  // tick the first check started
  int first_checked{-1};
  std::uint32_t unfit{0};
};

PartnerRun fly_check_with_partner(bool score_unfit, int partner, int onset, std::uint64_t seed,
                                  int ticks) {
  Truth t;
  FaultDetectorParams p = check_rig_params(t);
  p.check_force_n = kUmax;  // the partner's missing torque well above the gyro's noise
  p.check_score_unfit = score_unfit;
  FaultDetector d = make_detector(t, p);
  WeakFiring firing(seed);
  Vec16 prev = Vec16::Zero();
  PartnerRun out;
  for (int k = 0; k < ticks; ++k) {
    if (k == onset) t.stuck_off = partner;
    FaultDetectorInput in;
    in.omega = t.gyro();
    in.omega_valid = true;
    in.thrust = prev;
    in.valve_open = t.valve;
    const int before = d.check_jet();
    out.run.note(d.update(in), k);
    if (d.check_jet() >= 0 && d.check_jet() != before && out.first_check < 0) {
      out.first_check = k;
      out.first_checked = d.check_jet();
    }
    Vec16 cmd = firing.next(k);
    if (d.check_jet() >= 0) {
      cmd(d.check_jet()) += d.check_force();
      if (d.check_jet() != partner) cmd(partner) += d.check_force();
    }
    t.advance(cmd);
    prev = cmd;
  }
  out.unfit = d.status().checks_unfit;
  return out;
}

TEST(FaultDetector, AStuckOffJetFiredBesideACheckedJetIsConfirmedFromTheCheckWindow) {
  // Where the first check starts in this healthy firing, and of which jet.
  const PartnerRun healthy = fly_check_with_partner(true, 0, 1 << 30, 5, 40000);
  ASSERT_GE(healthy.first_check, 0);
  EXPECT_EQ(healthy.run.confirmations, 0);  // a healthy partner: nothing confirmed
  const int start = healthy.first_check;
  const FaultDetectorParams defaults;
  // The check's windows, the one after (the first may start mid-window) and the evaluation.
  const int bound = start + (defaults.check_windows + 2) * 10 + FaultDetector::kEvaluationSteps;
  int tested = 0;
  int sooner = 0;
  for (int partner = 0; partner < 16; ++partner) {
    if (partner == healthy.first_checked) continue;
    const std::string what = "partner " + std::to_string(partner);
    // Stuck off 5 s before the first check: its weak firing meanwhile (4-15 N) does not reach the
    // check level, so the same jet is checked first.
    const PartnerRun with = fly_check_with_partner(true, partner, start - 50, 5, start + 3000);
    const PartnerRun without = fly_check_with_partner(false, partner, start - 50, 5, start + 3000);
    // The same check first, and a window it made unfit (a partner whose signature is nearly
    // along the checked jet's leaves fit windows, scored either way).
    if (with.first_check != start || without.first_check != start || without.unfit == 0) continue;
    ++tested;
    EXPECT_GE(with.unfit, 1u) << what;
    ASSERT_GE(with.run.r.confirmed_at, start) << what;
    EXPECT_LE(with.run.r.confirmed_at, bound) << what;
    EXPECT_EQ(with.run.r.thruster, partner) << what;
    EXPECT_EQ(with.run.r.kind, FaultKind::kStuckOff) << what;
    EXPECT_EQ(with.run.confirmations, 1) << what;
    // Without (F35) only the check's fit windows teach the bank: never sooner.
    ASSERT_GE(without.run.r.confirmed_at, start) << what;
    EXPECT_EQ(without.run.r.thruster, partner) << what;
    EXPECT_LE(with.run.r.confirmed_at, without.run.r.confirmed_at) << what;
    if (with.run.r.confirmed_at + 10 <= without.run.r.confirmed_at) ++sooner;
  }
  std::printf("partners stuck off behind an unfit check window: %d, confirmed a window or more "
              "sooner with F35: %d\n", tested, sooner);
  EXPECT_GE(tested, 5);
  EXPECT_GE(2 * sooner, tested);
}

// Healthy jets checked (the check level set low enough that weak firing's noise starts checks):
// each check exonerates the jet and nothing is confirmed; a jet is checked again only after
// check_interval_s, and its third check only after twice that.
TEST(FaultDetector, JetChecksOfHealthyJetsConfirmNothingAndRespectTheInterval) {
  for (std::uint64_t seed : {5u, 6u, 7u}) {
    Truth t;
    FaultDetector d = make_checking_detector(t, 0.5);
    const CheckRun run = fly_checked(t, d, 40000, seed);  // 4000 s
    EXPECT_LT(run.r.confirmed_at, 0) << "false alarm: thruster " << run.r.thruster << " "
                                     << to_string(run.r.kind) << " at tick " << run.r.confirmed_at;
    EXPECT_GE(run.checked.size(), 3u) << "seed " << seed;
    EXPECT_EQ(d.status().checks, run.checked.size());
    EXPECT_EQ(d.status().checks_unfit, 0u) << "seed " << seed;
    std::array<std::vector<int>, 16> per_jet{};
    std::size_t most = 0;
    for (std::size_t a = 0; a < run.checked.size(); ++a) {
      per_jet[static_cast<std::size_t>(run.checked[a])].push_back(run.check_ticks[a]);
    }
    for (int jet = 0; jet < 16; ++jet) {
      const std::vector<int>& ticks = per_jet[static_cast<std::size_t>(jet)];
      for (std::size_t n = 1; n < ticks.size(); ++n) {
        // 600 s after the first check, 1200 s after the second, 2400 s after any later one.
        const int wait = 6000 << std::min<std::size_t>(n - 1, 2);
        EXPECT_GE(ticks[n] - ticks[n - 1], wait - 10) << "jet " << jet << " check " << n + 1;
      }
      most = std::max(most, ticks.size());
    }
    EXPECT_GE(most, 3u) << "seed " << seed << ": no jet checked a third time (the back-off untested)";
    // Three windows a check (the first partly), no more.
    EXPECT_LE(run.checked_ticks, static_cast<int>(run.checked.size()) * 3 * 10);
    EXPECT_GE(run.checked_ticks, static_cast<int>(run.checked.size()) * 2 * 10);
  }
}

// (F36) The jet survey. HOLD asks the jets for milli-newtons: HoldFiring commands one half of
// each channel at 2-20 mN (a new draw every 20 s), so a jet's loss moves the rate by less than
// the gyro's noise over hours, and no evidence ever reaches check_llr. Jet 0 is fired firmly
// (20-60 N, the rate a despin asks), so its stuck-off energy verifies it without a check.
struct HoldFiring {
  std::mt19937_64 rng;
  Vec16 phase{Vec16::Zero()};
  explicit HoldFiring(std::uint64_t seed) : rng(seed) {}
  Vec16 next(int tick) {
    std::uniform_real_distribution<double> u(0.0, 1.0);
    if (tick % 200 == 0) {
      phase.setZero();
      for (int c = 0; c < 8; ++c) phase(2 * c + (u(rng) < 0.5 ? 0 : 1)) = 0.002 + 0.018 * u(rng);
      phase(1) = 0.0;
      phase(0) = 20.0 + 40.0 * u(rng);
    }
    return phase;
  }
};

// HOLD's firing without HoldFiring's firm jet 0 (which would spin the body up over the hours the
// long-check tests fly): every channel's one half at milli-newtons, a fresh draw every 200 ticks.
struct MilliNewtonHold {
  std::mt19937_64 rng;
  Vec16 phase{Vec16::Zero()};
  explicit MilliNewtonHold(std::uint64_t seed) : rng(seed) {}
  Vec16 next(int tick) {
    if (tick % 200 == 0) {
      std::uniform_real_distribution<double> u(0.0, 1.0);
      phase.setZero();
      for (int c = 0; c < 8; ++c) phase(2 * c + (u(rng) < 0.5 ? 0 : 1)) = 0.002 + 0.018 * u(rng);
    }
    return phase;
  }
};

using SurveyRun = CheckRun;

SurveyRun fly_hold(Truth& t, FaultDetector& d, int ticks, int onset, int stuck_off,
                   std::uint64_t seed) {
  return fly_checks(t, d, HoldFiring(seed), ticks, onset, stuck_off);
}

FaultDetectorParams survey_params(const Truth& t, double interval_s) {
  FaultDetectorParams p = check_rig_params(t);
  p.check_llr = 5.0;
  p.check_min_llr = 5.0;
  p.survey_interval_s = interval_s;
  p.survey_energy = 10.0;
  p.episode_restart = true;
  p.episode_restart_stale = true;
  return p;
}

TEST(FaultDetector, ASurveyChecksAJetTheFlightBarelyCommandsAndIsolatesItStuckOff) {
  for (int i : {3, 6, 13}) {
    const std::string what = "thruster " + std::to_string(i);
    // Without the survey: 1 500 s of milli-newton firing of the dead jet, nothing to see.
    Truth t0;
    t0.stuck_off = i;
    FaultDetector quiet = make_detector(t0, survey_params(t0, 0.0));
    const SurveyRun none = fly_hold(t0, quiet, 15000, 0, i, 40 + static_cast<std::uint64_t>(i));
    EXPECT_LT(none.r.confirmed_at, 0) << what;
    EXPECT_EQ(quiet.status().surveys, 0u) << what;
    EXPECT_EQ(quiet.status().unverified, 0) << what << ": no bookkeeping with the survey off";
    // With a survey every 300 s: the jet is checked within its first interval and confirmed.
    Truth t;
    t.stuck_off = i;
    FaultDetector d = make_detector(t, survey_params(t, 300.0));
    const SurveyRun run = fly_hold(t, d, 15000, 0, i, 40 + static_cast<std::uint64_t>(i));
    ASSERT_GE(run.r.confirmed_at, 0) << what;
    EXPECT_EQ(run.r.thruster, i) << what;
    EXPECT_EQ(run.r.kind, FaultKind::kStuckOff) << what;
    EXPECT_EQ(run.confirmations, 1) << what;
    const auto own = std::find(run.checked.begin(), run.checked.end(), i);
    ASSERT_NE(own, run.checked.end()) << what << ": never checked";
    const auto a = static_cast<std::size_t>(own - run.checked.begin());
    EXPECT_TRUE(run.surveyed[a]) << what << ": its first check was not the survey's";
    EXPECT_GE(run.check_ticks[a], 3000) << what << ": surveyed before its interval";
    EXPECT_LE(run.check_ticks[a], 3000 + 16 * 80) << what << ": not surveyed in its round";
    EXPECT_GE(run.r.confirmed_at, run.check_ticks[a]) << what;
    EXPECT_EQ(d.status().unverified & (1u << i), 0u) << what << ": latched, not unverified";
  }
}

// (F43) The GNC allows a survey check only in HOLD (survey_hold_only): while the input says no,
// no survey check starts, whatever is due; the bookkeeping goes on, and once allowed the jets
// that came due meanwhile are surveyed, the one unverified longest first.
TEST(FaultDetector, NoSurveyCheckStartsWhileTheFlightDisallowsIt) {
  Truth t;
  FaultDetector d = make_detector(t, survey_params(t, 300.0));
  const int allowed_from = 8000;  // 800 s: every jet the firing commands is due from 300 s
  const SurveyRun run = fly_checks(t, d, HoldFiring(21), 12000, -1, -1, allowed_from);
  EXPECT_LT(run.r.confirmed_at, 0) << "false alarm: thruster " << run.r.thruster;
  int surveys = 0;
  int first = -1;
  for (std::size_t a = 0; a < run.checked.size(); ++a) {
    if (!run.surveyed[a]) continue;
    ++surveys;
    EXPECT_GE(run.check_ticks[a], allowed_from) << "jet " << run.checked[a] << " surveyed";
    if (first < 0) first = run.check_ticks[a];
  }
  EXPECT_GE(surveys, 10) << "the due jets surveyed once allowed";
  EXPECT_LE(first, allowed_from + 20) << "the first due jet waits no longer than a decision";
  EXPECT_EQ(d.status().surveys, static_cast<std::uint32_t>(surveys));
}

// The detector on the identified model with its centre of mass known to r_sigma (1 sigma, m).
FaultDetector make_detector_r(const Truth& t, const FaultDetectorParams& p, double r_sigma) {
  FaultDetector d;
  d.configure(p, study_rcs_layout(kUmax), kUmax, kDt);
  FaultModel m = identified_model(t);
  m.r_cov = Mat3::Identity() * r_sigma * r_sigma;
  d.set_model(m);
  return d;
}

// (F44) A survey check whose firing, against the model's error, may put more than
// survey_max_kick_rad_s (3 sigma) of rate on the body is not flown. At a bound of 2e-6 rad/s: with
// the centre of mass known to 1 mm the jets the firing commands are surveyed as without the gate;
// known to 5 cm (the check's net force of about 100 N then leaves 5 N m unknown) none is, each
// refusal counted. Without the bound both are surveyed; nothing is confirmed in any run.
TEST(FaultDetector, ASurveyCheckThatMayKickTheRateBeyondItsBoundIsNotFlown) {
  for (const double r_sigma : {1e-3, 0.05}) {
    for (const double bound : {0.0, 2e-6}) {
      Truth t;
      FaultDetectorParams p = survey_params(t, 300.0);
      p.survey_max_kick_rad_s = bound;
      FaultDetector d = make_detector_r(t, p, r_sigma);
      const SurveyRun run = fly_hold(t, d, 12000, -1, -1, 21);
      const std::string what =
          "r 1 sigma " + std::to_string(r_sigma) + " m, bound " + std::to_string(bound);
      EXPECT_LT(run.r.confirmed_at, 0) << what;
      const bool gated = bound > 0.0 && r_sigma > 0.01;
      if (gated) {
        EXPECT_EQ(d.status().surveys, 0u) << what;
        EXPECT_GT(d.status().survey_kick_refusals, 0u) << what;
      } else {
        EXPECT_GE(d.status().surveys, 10u) << what;
        EXPECT_EQ(d.status().survey_kick_refusals, 0u) << what;
      }
    }
  }
}

// (F56) After a confirmed fault, an evidence check is flown only within the survey's kick bound
// (F44). Jet 14 is latched stuck off (declared; the firing no longer commands it) and jet 6 dies
// at the start, under weak firing, so jet 6's evidence reaches check_llr. With the centre of mass
// known to 1 mm, its check kicks the rate by less than 2e-6 rad/s: it is flown and confirms jet 6
// stuck off, nothing refused. Known to 5 cm (about 100 N of check force then leaves 5 N m
// unknown), no check is flown and each refusal is counted. Without the latch, or with the gate
// off, the 5 cm model checks jet 6 as before: the gate applies only after a fault.
TEST(FaultDetector, AfterAConfirmedFaultAnEvidenceCheckBeyondTheKickBoundIsNotFlown) {
  struct WithoutJet {
    WeakFiring firing;
    int jet;
    Vec16 next(int tick) {
      Vec16 f = firing.next(tick);
      if (jet >= 0) f(jet) = 0.0;  // a latched jet is not allocated
      return f;
    }
  };
  constexpr int kDead = 6;
  constexpr int kLatched = 14;
  for (const double r_sigma : {1e-3, 0.05}) {
    for (const bool latch : {true, false}) {
      for (const bool gate : {true, false}) {
        if (r_sigma < 0.01 && !(latch && gate)) continue;  // the 1 mm model is never gated
        Truth t;
        t.stuck_off = kDead;
        FaultDetectorParams p = bank_params(t.gyro_sigma);
        p.degraded_min_loss = 0.1;
        p.check_llr = 5.0;
        p.survey_max_kick_rad_s = 2e-6;
        p.check_kick_after_fault = gate;
        FaultDetector d = make_detector_r(t, p, r_sigma);
        if (latch) d.declare(kLatched, FaultKind::kStuckOff);
        const CheckRun run =
            fly_checks(t, d, WithoutJet{WeakFiring(106), latch ? kLatched : -1}, 30000);
        const std::string what = "r 1 sigma " + std::to_string(r_sigma) + " m, latch " +
                                 std::to_string(latch) + ", gate " + std::to_string(gate);
        const bool gated = latch && gate && r_sigma > 0.01;
        const bool dead_checked =
            std::find(run.checked.begin(), run.checked.end(), kDead) != run.checked.end();
        EXPECT_EQ(d.status().checks, run.checked.size()) << what;
        if (gated) {
          EXPECT_EQ(d.status().checks, 0u) << what;
          EXPECT_GT(d.status().evidence_kick_refusals, 0u) << what;
        } else {
          EXPECT_TRUE(dead_checked) << what;
          EXPECT_EQ(d.status().evidence_kick_refusals, 0u) << what;
        }
        if (r_sigma < 0.01) {
          ASSERT_GE(run.r.confirmed_at, 0) << what;
          EXPECT_EQ(run.r.thruster, kDead) << what;
          EXPECT_EQ(run.r.kind, FaultKind::kStuckOff) << what;
        }
        EXPECT_TRUE(run.r.confirmed_at < 0 || run.r.thruster == kDead) << what;
      }
    }
  }
}

// (F48) No survey check where the gyro is too noisy for one window to show a dead jet within the
// kick bound. The least kick K that gives a total loss survey_energy over one window is found here
// by summing the mean-centred ramp sample by sample (the rate K j / n at sample j), and the
// gyro's noise sigma* at which K reaches the bound: just below it the due jets are surveyed as
// without the gate, just above it none is and each refusal is counted; with the gate off the
// noisier rig surveys them too. Nothing is confirmed in any run.
TEST(FaultDetector, NoSurveyCheckWhereTheGyroIsTooNoisyToSeeALossWithinTheKickBound) {
  constexpr double kBound = 1e-5;
  constexpr double kEnergy = 10.0;
  const int n = bank_params(1e-6).window_ticks;
  double centred = 0.0;  // sum over the window of (j / n - mean)^2
  for (int j = 0; j < n; ++j) {
    const double mean = 0.5 * (n - 1) / n;
    centred += (static_cast<double>(j) / n - mean) * (static_cast<double>(j) / n - mean);
  }
  // E = K^2 centred / sigma^2 = kEnergy at K = kBound:
  const double sigma_star = kBound * std::sqrt(centred / kEnergy);
  for (const double scale : {0.9, 1.1}) {
    for (const bool gate : {true, false}) {
      Truth t;
      t.gyro_sigma = scale * sigma_star;
      FaultDetectorParams p = survey_params(t, 300.0);
      p.survey_max_kick_rad_s = kBound;
      p.survey_energy = kEnergy;
      p.survey_noise_kick = gate;
      FaultDetector d = make_detector(t, p);
      const SurveyRun run = fly_hold(t, d, 12000, -1, -1, 21);
      const std::string what = "gyro " + std::to_string(scale) + " sigma*, gate " +
                               std::to_string(gate) + ", surveys " +
                               std::to_string(d.status().surveys) + ", F44 refusals " +
                               std::to_string(d.status().survey_kick_refusals);
      EXPECT_LT(run.r.confirmed_at, 0) << what;
      if (gate && scale > 1.0) {
        EXPECT_EQ(d.status().surveys, 0u) << what;
        EXPECT_GT(d.status().survey_noise_refusals, 0u) << what;
      } else {
        EXPECT_GE(d.status().surveys, 5u) << what;
        EXPECT_EQ(d.status().survey_noise_refusals, 0u) << what;
      }
    }
  }
}

// (F49) With case 7's gyro (3.2e-5 rad/s a sample) and 2.5 s windows, no check of the bank's
// windows can show a jet's loss within a 5e-5 rad/s kick (F48 refuses the survey). Flown as one
// window of 1 000 samples, a check whose expected stuck-off energy is 80 needs a kick of about
// 3e-5 rad/s: a dead jet is surveyed, confirmed stuck off (the right jet), and the kick its
// missing thrust put on the body over each of its long checks, b_i f T from the truth's geometry,
// stays within the bound; the force is the least that reaches the energy against the gyro's noise
// (computed here from the truth: at least 80, and not twice it). A healthy flight surveys its jets
// the same way and confirms nothing; with the long checks off, nothing is surveyed at all.
TEST(FaultDetector, WhereTheGyroIsTooNoisyTheSurveyFliesOneLongWindowWithinTheKickBound) {
  constexpr double kBound = 5e-5;
  constexpr int kLong = 1000;
  constexpr double kEnergy = 80.0;
  const auto params = [&](const Truth& t, int long_ticks) {
    FaultDetectorParams p = survey_params(t, 300.0);
    p.window_ticks = 25;
    p.centred_gyro_noise = true;
    p.survey_max_kick_rad_s = kBound;
    p.survey_noise_kick = true;
    p.check_long_ticks = long_ticks;
    p.check_long_energy = kEnergy;
    return p;
  };
  for (const int dead : {-1, 3, 6, 13}) {
    for (const int long_ticks : {0, kLong}) {
      const std::string what = "dead jet " + std::to_string(dead) + ", long window " +
                               std::to_string(long_ticks);
      Truth t;
      t.gyro_sigma = 3.1623e-5;  // case 7: sqrt(1e-10 / 0.1)
      t.stuck_off = dead;
      t.body.omega = V3(1e-6, -2e-6, 1e-6);  // HOLD: the gyroscopic term's error is negligible
      FaultDetector d = make_detector(t, params(t, long_ticks));
      const Mat3 j_inv = t.body.j.inverse();
      MilliNewtonHold firing(60 + static_cast<std::uint64_t>(dead + 1));
      Vec16 prev = Vec16::Zero();
      RunResult first;
      int long_started = 0;
      int check_start = -1;
      double impulse = 0.0;  // the checked jet's check impulse over the check under way, N s
      double worst_kick = 0.0;
      double least_energy = 1e300;
      double most_energy = 0.0;
      for (int k = 0; k < 60000 && first.confirmed_at < 0; ++k) {
        FaultDetectorInput in;
        in.omega = t.gyro();
        in.omega_valid = true;
        in.thrust = prev;
        in.valve_open = t.valve;
        const int before = d.check_jet();
        const std::uint32_t dropped = d.status().long_checks_dropped;
        const FaultEvents e = d.update(in);
        if (e.confirmed) {
          first.confirmed_at = k;
          first.thruster = e.thruster;
          first.kind = e.kind;
        }
        const int now = d.check_jet();
        if (before >= 0 && now != before && check_start >= 0) {
          // A check of `before` ended: its length and the dead jet's kick.
          const int ticks = k - check_start;
          // A long check lasts its window, unless an early suspicion off its jet ended it.
          if (long_ticks > 0 && d.status().long_checks_dropped == dropped) {
            EXPECT_EQ(ticks, kLong) << what;
          }
          EXPECT_LE(ticks, long_ticks > 0 ? kLong : 3 * 25 + 5) << what;
          if (before == dead) {
            const auto b = static_cast<std::size_t>(before);
            const V3 rate = j_inv * (t.pos[b] + t.r).cross(t.dir[b]);
            worst_kick = std::max(worst_kick, rate.norm() * impulse);
          }
          check_start = -1;
        }
        if (now >= 0 && now != before) {
          check_start = k;
          impulse = 0.0;
          if (d.status().long_checks > static_cast<std::uint32_t>(long_started)) {
            ++long_started;
            const auto b = static_cast<std::size_t>(now);
            const V3 rate = j_inv * (t.pos[b] + t.r).cross(t.dir[b]);
            const double step = rate.norm() * d.check_force() * kDt;
            const double n = kLong;
            const double energy =
                step * step * n * (n * n - 1.0) / 12.0 / (t.gyro_sigma * t.gyro_sigma);
            least_energy = std::min(least_energy, energy);
            most_energy = std::max(most_energy, energy);
            EXPECT_LE(d.check_force(), 100.0) << what;
          }
        }
        Vec16 cmd = firing.next(k);
        if (now >= 0) {
          cmd(now) += d.check_force();
          impulse += d.check_force() * kDt;
        }
        t.advance(cmd);
        prev = cmd;
      }
      if (long_ticks == 0) {
        EXPECT_EQ(d.status().surveys, 0u) << what;
        EXPECT_GT(d.status().survey_noise_refusals, 0u) << what;
        EXPECT_EQ(d.status().long_checks, 0u) << what;
        EXPECT_LT(first.confirmed_at, 0) << what;
        continue;
      }
      EXPECT_GT(long_started, 0) << what;
      EXPECT_EQ(d.status().long_checks, static_cast<std::uint32_t>(long_started)) << what;
      EXPECT_EQ(d.status().checks, d.status().long_checks) << what << ": every check long";
      EXPECT_GE(least_energy, 0.9 * kEnergy) << what;
      EXPECT_LE(most_energy, 2.0 * kEnergy) << what;
      if (dead < 0) {
        EXPECT_LT(first.confirmed_at, 0) << what << ": false alarm, thruster " << first.thruster;
        EXPECT_GE(d.status().surveys, 10u) << what;
      } else {
        ASSERT_GE(first.confirmed_at, 0) << what;
        EXPECT_EQ(first.thruster, dead) << what;
        EXPECT_EQ(first.kind, FaultKind::kStuckOff) << what;
        EXPECT_GT(worst_kick, 0.2 * kBound) << what << ": the dead jet's check kicked nothing";
        EXPECT_EQ(d.status().long_checks_dropped, 0u) << what;
        EXPECT_LE(worst_kick, kBound) << what;
      }
    }
  }
}

// (F49) A jet stuck on 30 s into a long check of another jet: the early test (F33) shows motion
// off the checked jet's signature, and the check ends within seconds of the onset, its window
// dropped (not after the 70 s left of it), so that the bank's windows of their own length follow.
// (A dead checked jet's motion lies along its signature: WhereTheGyroIsTooNoisy... above flies its
// checks whole.)
TEST(FaultDetector, AJetStuckOnDuringALongCheckEndsIt) {
  for (const int stuck : {2, 5, 11}) {
    const std::string what = "thruster " + std::to_string(stuck) + " stuck on";
    Truth t;
    t.gyro_sigma = 3.1623e-5;
    t.body.omega = V3(1e-6, -2e-6, 1e-6);
    FaultDetectorParams p = survey_params(t, 300.0);
    p.window_ticks = 25;
    p.centred_gyro_noise = true;
    p.survey_max_kick_rad_s = 5e-5;
    p.survey_noise_kick = true;
    p.check_long_ticks = 1000;
    p.detect_early_ticks = 3;
    p.skip_onset_window = true;
    p.onset_restart = true;
    FaultDetector d = make_detector(t, p);
    MilliNewtonHold firing(80 + static_cast<std::uint64_t>(stuck));
    Vec16 prev = Vec16::Zero();
    int onset = -1;
    int checked = -1;
    int ended = -1;
    for (int k = 0; k < 20000 && ended < 0; ++k) {
      const Vec16 phase = firing.next(k);
      FaultDetectorInput in;
      in.omega = t.gyro();
      in.omega_valid = true;
      in.thrust = prev;
      in.valve_open = t.valve;
      d.update(in);
      if (onset >= 0 && d.check_jet() < 0) ended = k;
      // 300 ticks into the first long check of a jet other than the one to stick.
      // (A checked jet whose torque is nearly parallel to the stuck one's, its channel partner or
      // another pod's mirror, cannot tell the two apart: not that check.)
      const auto torque = [&t](int i) {
        const auto b = static_cast<std::size_t>(i);
        return V3((t.pos[b] + t.r).cross(t.dir[b]).normalized());
      };
      if (onset < 0 && d.check_jet() >= 0 && d.check_jet() != stuck &&
          d.status().long_checks > 0 && std::fabs(torque(d.check_jet()).dot(torque(stuck))) < 0.8) {
        if (checked < 0) checked = k;
        if (k - checked == 300) {
          onset = k;
          t.stuck_on = stuck;
        }
      }
      Vec16 cmd = phase;
      if (d.check_jet() >= 0) cmd(d.check_jet()) += d.check_force();
      t.advance(cmd);
      prev = cmd;
    }
    ASSERT_GE(onset, 0) << what << ": no long check flown";
    ASSERT_GE(ended, 0) << what;
    EXPECT_EQ(d.status().long_checks_dropped, 1u) << what;
    EXPECT_LE(ended - onset, 50) << what << ": the check ran on";
    EXPECT_GE(ended - onset, 3) << what << ": ended before the early test could see it";
  }
}

// (F51) The model's error of a fitted loss, against a Monte-Carlo of the truth's geometry: draws of
// the centre of mass from an anisotropic covariance, each jet's signature b_i = J^-1 (p_i + r + dr)
// x e_i recomputed, its change along b_i as a fraction of |b_i|^2, alone and for its check's move
// (the kernel of the channels' torque matrix, here from an SVD pseudo-inverse); the larger 1 sigma
// of the two, plus the strength and inertia terms.
TEST(FaultDetector, TheLossGatesModelErrorIsTheSignaturesErrorAlongItself) {
  Truth t;
  FaultDetectorParams p = check_rig_params(t);
  p.degraded_loss_projection = true;
  FaultDetector d;
  ASSERT_TRUE(validate(p).ok);
  d.configure(p, study_rcs_layout(kUmax), kUmax, kDt);
  FaultModel m = identified_model(t);
  const Mat3 rot = Eigen::AngleAxisd(0.7, V3(1.0, -2.0, 0.5).normalized()).toRotationMatrix();
  m.r_cov = rot * V3(0.04, 0.01, 0.25).asDiagonal() * rot.transpose();
  m.k_sigma = 0.01;
  m.j_rel_sigma = 0.002;
  d.set_model(m);
  const Mat3 j_inv = t.body.j.inverse();
  const Eigen::LLT<Mat3> chol(m.r_cov);
  const Mat3 l = chol.matrixL();
  // The channels' torque matrix (each channel's "+" jet, 2c) and the kernel projector.
  Eigen::Matrix<double, 3, 8> b;
  for (int c = 0; c < 8; ++c) {
    const auto k = static_cast<std::size_t>(2 * c);
    b.col(c) = (t.pos[k] + t.r).cross(t.dir[k]);
  }
  const Eigen::Matrix<double, 8, 3> b_pinv =
      b.jacobiSvd(Eigen::ComputeFullU | Eigen::ComputeFullV).solve(Mat3::Identity());
  const Eigen::Matrix<double, 8, 8> kernel = Eigen::Matrix<double, 8, 8>::Identity() - b_pinv * b;
  std::mt19937_64 rng(51);
  std::normal_distribution<double> n(0.0, 1.0);
  constexpr int kDraws = 40000;
  for (int i = 0; i < 16; ++i) {
    const auto k = static_cast<std::size_t>(i);
    const int c = i / 2;
    const V3 bi = j_inv * (t.pos[k] + t.r).cross(t.dir[k]);
    const Eigen::Matrix<double, 8, 1> du = kernel.col(c);
    V3 force = V3::Zero();
    for (int q = 0; q < 8; ++q) force += du(q) * t.dir[static_cast<std::size_t>(2 * q)];
    double alone2 = 0.0;
    double move2 = 0.0;
    for (int s = 0; s < kDraws; ++s) {
      const V3 dr = l * V3(n(rng), n(rng), n(rng));
      const V3 db = j_inv * (t.pos[k] + t.r + dr).cross(t.dir[k]) - bi;
      const double alone = db.dot(bi) / bi.squaredNorm();
      // The move's torque error per unit of the checked jet's force, its share along b_i (the
      // "-" jet is checked with the move reversed and its signature reversed: the same share).
      const double move = (j_inv * dr.cross(force)).dot(bi) / (du(c) * bi.squaredNorm());
      alone2 += alone * alone;
      move2 += move * move;
    }
    const double r_share = std::sqrt(std::max(alone2, move2) / kDraws);
    const double expected = m.k_sigma + m.j_rel_sigma + r_share;
    EXPECT_NEAR(d.loss_rel_error(i), expected, 0.02 * expected) << "thruster " << i;
  }
}

// (F50, F51) Case 6's HOLD: the gyro too noisy for the bank's windows, the centre of mass known to
// 0.56 m along one direction (the identified model's covariance there). A half-strength jet of
// those the survey checks (jets 0, 1, 8, 9 are verified by the other checks' moves here). A long evidence check's
// energy cannot reach check_long_evidence_energy (320) for the jets whose cap s^2 g / a^2 is
// below it, and the former loss gate (degraded_min_loss + 3 r_sigma / arm) lies above 0.5 for
// them: the half loss is never confirmed. With the checks at 0.8 of their cap within the kick
// bound, and the gate on the signature's error along itself, it is confirmed degraded, to
// itself, at 0.5 within 3 of its reported 1 sigma; each capped check's dead-jet kick stays within
// the bound; healthy, nothing is confirmed.
TEST(FaultDetector, AHalfLossWhereTheCentreOfMassCapsTheCheckIsConfirmedDegraded) {
  constexpr double kBound = 5e-5;
  const double kRSigma = std::sqrt(0.3108);
  for (const int half : {-1, 3, 6, 11, 14}) {
    for (const bool on : {false, true}) {
      const std::string what = "half-strength jet " + std::to_string(half) +
                               (on ? ", F50 and F51" : ", without them");
      Truth t;
      t.gyro_sigma = 3.1623e-5;  // cases 6-7: sqrt(1e-10 / 0.1)
      t.degraded = half;
      t.degraded_factor = 0.5;
      t.body.omega = V3(1e-6, -2e-6, 1e-6);
      FaultDetectorParams p = survey_params(t, 3000.0);
      p.window_ticks = 25;
      p.centred_gyro_noise = true;
      p.survey_max_kick_rad_s = kBound;
      p.survey_noise_kick = true;
      p.check_long_ticks = 1000;
      p.check_long_energy = 80.0;
      p.check_long_evidence_energy = 320.0;
      p.check_interval_s = 600.0;
      p.check_max_model_error = 0.5;
      p.model_sigmas = 3.0;
      p.margin_llr = 10.0;
      p.confirm_llr = 25.0;
      p.check_long_reach = on ? 0.8 : 0.0;
      p.degraded_loss_projection = on;
      FaultDetector d;
      ASSERT_TRUE(validate(p).ok) << what << ": " << validate(p).field;
      d.configure(p, study_rcs_layout(kUmax), kUmax, kDt);
      // The identified model's 1 sigma in case 6's HOLD (the degraded dispersion's draw 0): the
      // centre of mass known to 0.56 m along one direction, 0.08-0.13 m across it.
      FaultModel m = identified_model(t);
      m.r_cov << 0.3108, -0.0504, 0.0041, -0.0504, 0.0176, -0.0001, 0.0041, -0.0001, 0.0059;
      m.k_sigma = 0.0097;
      m.j_rel_sigma = 0.0064;
      d.set_model(m);
      const Mat3 j_inv = t.body.j.inverse();
      if (half >= 0) {
        // The former gate refuses a half loss of this jet.
        const auto b = static_cast<std::size_t>(half);
        const double arm = (t.pos[b] + t.r).cross(t.dir[b]).norm();
        ASSERT_GT(0.1 + 3.0 * (m.k_sigma + m.j_rel_sigma + kRSigma / arm), 0.5) << what;
      }
      MilliNewtonHold firing(500 + static_cast<std::uint64_t>(half + 1));
      Vec16 prev = Vec16::Zero();
      RunResult first;
      double factor = 0.0;
      double factor_sigma = 0.0;
      std::uint32_t capped = 0;
      double worst_capped_kick = 0.0;
      for (int k = 0; k < 400000 && first.confirmed_at < 0; ++k) {  // 40 000 s
        const Vec16 phase = firing.next(k);
        FaultDetectorInput in;
        in.omega = t.gyro();
        in.omega_valid = true;
        in.thrust = prev;
        in.valve_open = t.valve;
        const FaultEvents e = d.update(in);
        if (e.confirmed) {
          first.confirmed_at = k;
          first.thruster = e.thruster;
          first.kind = e.kind;
          factor = e.factor;
          factor_sigma = e.factor_sigma;
        }
        if (d.status().long_checks_capped > capped) {
          capped = d.status().long_checks_capped;
          // The dead-jet kick of this check over its 1 000 samples, from the truth's geometry.
          const auto b = static_cast<std::size_t>(d.check_jet());
          const V3 rate = j_inv * (t.pos[b] + t.r).cross(t.dir[b]);
          worst_capped_kick = std::max(worst_capped_kick, rate.norm() * d.check_force() * 100.0);
        }
        Vec16 cmd = phase;
        if (d.check_jet() >= 0) cmd(d.check_jet()) += d.check_force();
        t.advance(cmd);
        prev = cmd;
      }
      EXPECT_LE(worst_capped_kick, kBound * (1.0 + 1e-9)) << what;
      if (!on) {
        EXPECT_EQ(capped, 0u) << what;
      }
      if (half < 0 || !on) {
        EXPECT_LT(first.confirmed_at, 0) << what << ": confirmed thruster " << first.thruster;
        continue;
      }
      EXPECT_GT(capped, 0u) << what << ": no evidence check at its cap";
      ASSERT_GE(first.confirmed_at, 0) << what;
      EXPECT_EQ(first.thruster, half) << what;
      EXPECT_EQ(first.kind, FaultKind::kDegraded) << what;
      EXPECT_NEAR(factor, 0.5, 3.0 * factor_sigma) << what;
      EXPECT_LT(factor_sigma, 0.1) << what;
    }
  }
}

TEST(FaultDetector, TheSurveyChecksEachUnverifiedJetOncePerIntervalAndConfirmsNothingWhenHealthy) {
  for (std::uint64_t seed : {21u, 22u}) {
    Truth t;
    FaultDetector d = make_detector(t, survey_params(t, 300.0));
    const SurveyRun run = fly_hold(t, d, 12000, -1, -1, seed);  // 1 200 s
    EXPECT_LT(run.r.confirmed_at, 0) << "false alarm: thruster " << run.r.thruster << " "
                                     << to_string(run.r.kind) << " at tick " << run.r.confirmed_at;
    std::array<std::vector<int>, 16> per_jet{};
    std::uint32_t surveys = 0;
    for (std::size_t a = 0; a < run.checked.size(); ++a) {
      if (!run.surveyed[a]) continue;
      ++surveys;
      per_jet[static_cast<std::size_t>(run.checked[a])].push_back(run.check_ticks[a]);
    }
    EXPECT_EQ(d.status().surveys, surveys) << "seed " << seed;
    // Jet 0, fired firmly, is verified by its own firing; jet 1 (its channel's other half) is
    // never commanded. Every other jet the firing commanded is surveyed, at 300 s intervals.
    EXPECT_TRUE(per_jet[0].empty()) << "seed " << seed << ": a firmly fired jet surveyed";
    EXPECT_TRUE(per_jet[1].empty()) << "seed " << seed << ": a jet never commanded surveyed";
    int surveyed_jets = 0;
    for (int jet = 2; jet < 16; ++jet) {
      const std::vector<int>& ticks = per_jet[static_cast<std::size_t>(jet)];
      surveyed_jets += ticks.empty() ? 0 : 1;
      for (std::size_t n = 0; n < ticks.size(); ++n) {
        EXPECT_GE(ticks[n], 3000) << "jet " << jet;
        if (n > 0) {
          EXPECT_GE(ticks[n] - ticks[n - 1], 3000 - 10) << "jet " << jet;
        }
      }
    }
    EXPECT_GE(surveyed_jets, 12) << "seed " << seed;
  }
}

// (F36) A due jet the survey cannot check (here: every jet, the check gate on the model's error
// closed) is rated once and put back by check_interval_s, so each decision rates at most one jet:
// rating every due jet on every decision took the decision's tick over the Cortex-M7 budget
// (gnc/fdi/README.md "The jet survey"). Counted: the ratings, against the windows and against
// once per due jet per check interval.
TEST(FaultDetector, ADueJetTheSurveyCannotCheckIsRatedOncePerCheckInterval) {
  Truth t;
  FaultDetectorParams p = survey_params(t, 300.0);
  p.check_interval_s = 100.0;
  p.check_max_model_error = 1e-9;  // no jet's signature is known that well: nothing is checkable
  FaultDetector d = make_detector(t, p);
  const SurveyRun run = fly_hold(t, d, 12000, -1, -1, 23);  // 1 200 s of 1 s windows
  EXPECT_LT(run.r.confirmed_at, 0);
  EXPECT_TRUE(run.checked.empty());
  EXPECT_EQ(d.status().checks, 0u);
  EXPECT_EQ(d.status().surveys, 0u);
  // Jets 2-15 are commanded and unverified (TheSurveyChecksEachUnverifiedJet... above): each is
  // due from 300 s and then rated at most once per 100 s, ten times in the 900 s after.
  const std::uint32_t ratings = d.status().survey_ratings;
  EXPECT_GE(ratings, 12u) << "the due jets were not rated";
  EXPECT_LE(ratings, 14u * 10u) << "a jet rated more than once per check interval";
  EXPECT_LT(ratings, d.status().windows - 300u) << "more than one rating per decision";
  // With the gate open the same flight checks them (the ratings were the survey's, not idle).
  Truth t2;
  FaultDetector open = make_detector(t2, survey_params(t2, 300.0));
  const SurveyRun checked = fly_hold(t2, open, 12000, -1, -1, 23);
  EXPECT_GE(open.status().surveys, 12u);
  EXPECT_EQ(checked.checked.size(), open.status().checks);
  EXPECT_GE(open.status().survey_ratings, open.status().surveys);
}

// (F38) A jet surveyed healthy, then dead. The survey's first check of it put its stuck-off
// evidence well below zero in the episode's sums (F8), and in HOLD no window is suspicious, so
// the episode still starts before the fault when the next survey raises the jet's score past
// confirm_llr: its loss fitted over the episode is a partial one (F13) and nothing is confirmed.
// Restarting the episode when the leader's episode sum trails its score by margin_llr confirms
// it stuck off on that survey's evidence. Whether the rig's episode is stale at the suspicion
// depends on the run (x86-64: jet 13 at 652 s instead of 1 258 s, jets 3 and 6 at the same time
// either way, their episodes restarted by a new leader, F25; the aarch64 build: all three at the
// same time), so the sooner confirmation is asserted to come with a restart of its own, not to
// happen; the dispersion measures how often it does (README "The jet survey").
TEST(FaultDetector, AJetSurveyedHealthyThenDeadIsConfirmedStuckOffWithTheStaleEpisodeRestart) {
  for (int i : {3, 6, 13}) {
    const std::string what = "thruster " + std::to_string(i);
    const auto fly = [&](bool stale, SurveyRun& run) {
      Truth t;
      FaultDetectorParams p = survey_params(t, 300.0);
      p.episode_restart_stale = stale;
      FaultDetector d = make_detector(t, p);
      run = fly_hold(t, d, 40000, 4500, i, 60 + static_cast<std::uint64_t>(i));
      return d.status().episode_restarts;
    };
    SurveyRun old_run;
    SurveyRun run;
    const std::uint32_t before = fly(false, old_run);
    const std::uint32_t after = fly(true, run);
    // Surveyed healthy before the onset, in both runs.
    ASSERT_FALSE(run.checked.empty()) << what;
    const auto own = std::find(run.checked.begin(), run.checked.end(), i);
    ASSERT_NE(own, run.checked.end()) << what;
    EXPECT_LT(run.check_ticks[static_cast<std::size_t>(own - run.checked.begin())], 4500) << what;
    ASSERT_GE(run.r.confirmed_at, 4500) << what;
    EXPECT_EQ(run.r.thruster, i) << what;
    EXPECT_EQ(run.r.kind, FaultKind::kStuckOff) << what;
    EXPECT_EQ(run.confirmations, 1) << what;
    if (old_run.r.confirmed_at < 0 || old_run.r.confirmed_at > run.r.confirmed_at) {
      EXPECT_GT(after, before) << what << ": sooner without a restart of its own";
    }
    EXPECT_FALSE(old_run.r.confirmed_at >= 0 && old_run.r.confirmed_at < run.r.confirmed_at)
        << what << ": the restart delayed the confirmation";
  }
}

// A check is only as good as the model it is flown against: with the inertia known to 10 %
// (the table's, before identification) no jet is checked, whatever the evidence.
// (F24) A check is flown only when it can move the evidence: a model whose centre of mass is
// known to 0.3 m makes the check's own torque (its force against that offset) about as uncertain
// as the signature it fires, and the expected LLR of a check falls below check_llr. The guard of
// F19 on the signature's error is opened wide here, so only (F24) decides. A tangential jet
// stuck off under the weak firing: without (F24) it is checked against the 0.3 m model; with it,
// not; with the centre of mass known to 1 mm it is checked and confirmed stuck off to itself.
CheckRun fly_check_gated(Truth& t, double r_sigma, double check_min_llr, FaultDetector& d) {
  FaultDetectorParams p;
  p.enabled = true;
  p.degraded_min_loss = 0.1;
  p.check_llr = 5.0;
  p.check_max_model_error = 1.0;
  p.check_min_llr = check_min_llr;
  p.window_ticks = 10;
  p.gyro_sigma = t.gyro_sigma;
  p.disturbance_sigma = 0.0;
  d.configure(p, study_rcs_layout(kUmax), kUmax, kDt);
  FaultModel m = identified_model(t);
  m.r_cov = Mat3::Identity() * r_sigma * r_sigma;
  d.set_model(m);
  return fly_checked(t, d, 20000, 141);
}

TEST(FaultDetector, ACheckThatCannotMoveTheEvidenceIsNotFlown) {
  Truth loose;
  loose.stuck_off = 4;
  FaultDetector ungated;
  const CheckRun a = fly_check_gated(loose, 0.6, 0.0, ungated);
  EXPECT_FALSE(a.checked.empty()) << "no check without (F24): the case below tests nothing";
  Truth loose2;
  loose2.stuck_off = 4;
  FaultDetector gated;
  const CheckRun b = fly_check_gated(loose2, 0.6, 5.0, gated);
  EXPECT_TRUE(b.checked.empty()) << b.checked.size() << " checks, the first of thruster "
                                 << (b.checked.empty() ? -1 : b.checked.front());
  EXPECT_EQ(gated.status().checks, 0u);
  Truth known;
  known.stuck_off = 4;
  FaultDetector d;
  const CheckRun c = fly_check_gated(known, 1e-3, 5.0, d);
  const auto own = std::find(c.checked.begin(), c.checked.end(), 4);
  ASSERT_NE(own, c.checked.end()) << "the jet was never checked with the centre of mass known";
  ASSERT_GE(c.r.confirmed_at, 0);
  EXPECT_EQ(c.r.thruster, 4);
  EXPECT_EQ(c.r.kind, FaultKind::kStuckOff);
}

TEST(FaultDetector, NoJetCheckWithAModelThatDoesNotKnowTheJetsSignature) {
  Truth t;
  t.stuck_off = 13;
  FaultDetector d = make_checking_detector(t, 5.0);
  FaultModel m;
  m.j = t.body.j;
  m.r = t.r;
  m.j_rel_sigma = 0.1;
  m.r_cov = Mat3::Identity() * 1e-6;
  m.k_sigma = 1e-3;
  d.set_model(m);
  const CheckRun run = fly_checked(t, d, 20000, 113);
  EXPECT_TRUE(run.checked.empty());
  EXPECT_EQ(d.status().checks, 0u);
  // The centre of mass known to 0.5 m (arm of an axial jet 1.8 m): the same.
  Truth t2;
  t2.stuck_off = 13;
  FaultDetector d2 = make_checking_detector(t2, 5.0);
  m.j_rel_sigma = 1e-4;
  m.r_cov = Mat3::Identity() * 0.25;
  d2.set_model(m);
  const CheckRun run2 = fly_checked(t2, d2, 20000, 113);
  for (int jet : run2.checked) {
    const bool axial = jet % 4 >= 2;
    EXPECT_FALSE(axial) << "axial jet " << jet << " checked against a 0.5 m centre of mass";
  }
}

// The fit of a check window (F19): the part of the window's unexplained slope normal to the
// checked jet's signature, against an explicit projection.
TEST(FaultDetector, ACheckWindowsNormalChiSquareIsTheResidualOffTheJetsSignature) {
  const Vec3 b(1.0, 2.0, -0.5);
  const double stt = 82.5;  // sum of squared offsets of 10 samples
  const double var = 4e-12;
  // Along b: nothing normal.
  EXPECT_NEAR(check_normal_chi2(b, -3e-7 * b, stt, var), 0.0, 1e-9);
  // An explicit orthogonal decomposition.
  const Vec3 n = b.cross(Vec3(0.0, 0.0, 1.0)).normalized();
  for (double along : {0.0, 2e-7, -5e-7}) {
    for (double normal : {1e-8, 1e-7, 4e-7}) {
      const Vec3 slope = along * b.normalized() + normal * n;
      const double expected = normal * normal * stt / var;
      EXPECT_NEAR(check_normal_chi2(b, slope, stt, var), expected, 1e-9 * expected);
    }
  }
  // At the bound (chi-square(2) 0.999 = 13.82) either side.
  const double edge = std::sqrt(13.82 * var / stt);
  EXPECT_LT(check_normal_chi2(b, 0.999 * edge * n + 1e-7 * b, stt, var), 13.82);
  EXPECT_GT(check_normal_chi2(b, 1.001 * edge * n + 1e-7 * b, stt, var), 13.82);
  // Degenerate inputs give 0 (the window is scored).
  EXPECT_EQ(check_normal_chi2(Vec3::Zero(), n, stt, var), 0.0);
  EXPECT_EQ(check_normal_chi2(b, n, 0.0, var), 0.0);
}

TEST(FaultDetector, JetCheckParametersAreValidated) {
  FaultDetectorParams p;
  p.check_llr = -1.0;
  EXPECT_STREQ(validate(p).field, "fdi.check_llr");
  p = FaultDetectorParams{};
  p.check_force_n = 0.0;
  EXPECT_STREQ(validate(p).field, "fdi.check_force_n");
  p = FaultDetectorParams{};
  p.check_windows = 0;
  EXPECT_STREQ(validate(p).field, "fdi.check_windows");
  p = FaultDetectorParams{};
  p.check_interval_s = std::nan("");
  EXPECT_STREQ(validate(p).field, "fdi.check_interval_s");
  p = FaultDetectorParams{};
  p.check_fit_chi2 = 0.0;
  EXPECT_STREQ(validate(p).field, "fdi.check_fit_chi2");
  p = FaultDetectorParams{};
  p.check_max_model_error = -0.1;
  EXPECT_STREQ(validate(p).field, "fdi.check_max_model_error");
  p.check_max_model_error = 0.05;
  p.check_min_llr = -1.0;  // (F24)
  EXPECT_STREQ(validate(p).field, "fdi.check_min_llr");
  p = FaultDetectorParams{};
  p.survey_interval_s = -1.0;  // (F36)
  EXPECT_STREQ(validate(p).field, "fdi.survey_interval_s");
  p = FaultDetectorParams{};
  p.survey_max_kick_rad_s = -1e-5;  // (F44)
  EXPECT_STREQ(validate(p).field, "fdi.survey_max_kick_rad_s");
  p = FaultDetectorParams{};
  p.survey_energy = 0.0;
  EXPECT_STREQ(validate(p).field, "fdi.survey_energy");
  for (const double llr : {-1.0, std::numeric_limits<double>::infinity(), std::nan("")}) {  // (F57)
    p = FaultDetectorParams{};
    p.survey_loss_llr = llr;
    EXPECT_STREQ(validate(p).field, "fdi.survey_loss_llr") << llr;
  }
  for (const double s : {-1.0, std::numeric_limits<double>::infinity(), std::nan("")}) {  // (F58)
    p = FaultDetectorParams{};
    p.total_loss_sigmas = s;
    EXPECT_STREQ(validate(p).field, "fdi.total_loss_sigmas") << s;
  }
  for (const double s : {-0.01, std::numeric_limits<double>::infinity(), std::nan("")}) {  // (F59)
    p = FaultDetectorParams{};
    p.after_fault_max_j_rel = s;
    EXPECT_STREQ(validate(p).field, "fdi.after_fault_max_j_rel") << s;
  }
  p = FaultDetectorParams{};
  p.survey_max_windows = 0;
  EXPECT_STREQ(validate(p).field, "fdi.survey_max_windows");
  for (const int ticks : {-1, 3, 1001}) {  // (F49)
    p = FaultDetectorParams{};
    p.check_long_ticks = ticks;
    EXPECT_STREQ(validate(p).field, "fdi.check_long_ticks") << ticks;
  }
  for (const int ticks : {0, 4, 1000}) {
    p = FaultDetectorParams{};
    p.check_long_ticks = ticks;
    EXPECT_TRUE(validate(p).ok) << ticks;
  }
  p = FaultDetectorParams{};
  p.check_long_energy = 0.0;
  EXPECT_STREQ(validate(p).field, "fdi.check_long_energy");
  p = FaultDetectorParams{};
  p.check_long_evidence_energy = std::nan("");
  EXPECT_STREQ(validate(p).field, "fdi.check_long_evidence_energy");
  for (const double reach : {-0.1, 0.96, std::nan("")}) {  // (F50)
    p = FaultDetectorParams{};
    p.check_long_reach = reach;
    EXPECT_STREQ(validate(p).field, "fdi.check_long_reach") << reach;
  }
  p.check_long_reach = 0.95;
  EXPECT_TRUE(validate(p).ok);
  for (double level : {-1.0, 25.0, 30.0, std::nan("")}) {  // (F52) below confirm_llr
    FaultDetectorParams q;
    q.probe_start_llr = level;
    EXPECT_STREQ(validate(q).field, "fdi.probe_start_llr") << level;
  }
  {
    FaultDetectorParams q;
    q.probe_start_llr = 8.0;
    EXPECT_TRUE(validate(q).ok);
  }
  EXPECT_TRUE(validate(FaultDetectorParams{}).ok);
}

// (F18) Twin jets. The model's r has its xy part mirrored (the trap of the (F8) test above, an
// error at 2 of its stated sigma), so the model's signature of thruster 11 is the truth's of 2;
// 2 and 11 are commanded alike, and 2 delivers 30 % of its thrust. Jet 11 fitted as degraded
// explains the data exactly and 2 only along its model's signature, turned by the model's error:
// with the model taken as exact (model_sigmas = 0) the twin is confirmed degraded. With the
// model's error, the runner-up's fit (2) is within the turn the model's error allows, and the twin
// is never confirmed.
FaultEvents fly_twin(const FaultDetectorParams& base, int ticks, int& confirmations) {
  Truth t;
  t.degraded = 2;
  t.degraded_factor = 0.3;
  FaultDetectorParams p = base;
  p.degraded_min_loss = 0.1;
  FaultDetector d;
  mirror_trap(t, p, d);
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Vec16 prev = Vec16::Zero();
  FaultEvents first;
  confirmations = 0;
  for (int k = 0; k < ticks; ++k) {
    FaultDetectorInput in;
    in.omega = t.gyro();
    in.omega_valid = true;
    in.thrust = prev;
    const FaultEvents e = d.update(in);
    if (e.confirmed && confirmations++ == 0) first = e;
    Vec16 cmd = random_firing(rng);
    cmd(3) = cmd(10) = 0.0;
    cmd(2) = cmd(11) = u(rng) < 0.5 ? kUmax * u(rng) : 0.0;  // the twins, commanded alike
    t.advance(cmd);
    prev = cmd;
  }
  return first;
}

// (F37) Twin jets stuck off: the mirror trap, jets 2 and 11 commanded alike, jet 2 dead. (F8)
// cannot tell "2 stuck off" from "11 stuck off" within the model's error, whatever more of the same
// firing adds. With check_blocker, a check of the jet that blocks the leader is flown while it
// blocks it, and jet 2 is confirmed sooner; without, the checks go by evidence alone. No run
// confirms the twin.
struct BlockerRun {
  int blocker_checks{0};   // checks of the jet blocking a stuck-off leader past confirm_llr
  int checks{0};
  int confirmations{0};
  int confirmed_at{-1};
  FaultEvents first;
};

BlockerRun fly_twin_off(bool check_blocker) {
  Truth t;
  t.stuck_off = 2;
  FaultDetectorParams p;
  p.check_llr = 5.0;
  p.check_force_n = 100.0;
  p.check_max_model_error = 0.5;
  p.check_blocker = check_blocker;
  FaultDetector d;
  mirror_trap(t, p, d);
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Vec16 prev = Vec16::Zero();
  BlockerRun out;
  for (int k = 0; k < 60000; ++k) {
    FaultDetectorInput in;
    in.omega = t.gyro();
    in.omega_valid = true;
    in.thrust = prev;
    const FaultDetectorStatus before = d.status();
    const FaultEvents e = d.update(in);
    if (e.confirmed && out.confirmations++ == 0) {
      out.first = e;
      out.confirmed_at = k;
    }
    if (d.check_jet() >= 0 && d.check_jet() != before.check_jet) {
      ++out.checks;
      const FaultDetectorStatus& st = d.status();
      if (st.best >= 16 && st.best_llr > p.confirm_llr && st.ambiguous_with >= 16 &&
          d.check_jet() == st.ambiguous_with - 16) {
        ++out.blocker_checks;
      }
    }
    Vec16 cmd = random_firing(rng) * 0.1;
    cmd(3) = cmd(10) = 0.0;
    cmd(2) = cmd(11) = u(rng) < 0.5 ? 20.0 * u(rng) : 0.0;  // the twins, commanded alike
    if (d.check_jet() >= 0) cmd(d.check_jet()) += d.check_force();
    t.advance(cmd);
    prev = cmd;
  }
  return out;
}

TEST(FaultDetector, TheJetBlockingAStuckOffLeaderIsChecked) {
  const BlockerRun without = fly_twin_off(false);
  const BlockerRun with = fly_twin_off(true);
  // x86-64: 7 checks of the blocking jet against 1 (an evidence check that happened to be of
  // it); jet 2 confirmed stuck off at 1 111 s against 2 118 s.
  EXPECT_GT(with.blocker_checks, without.blocker_checks);
  ASSERT_GE(with.confirmations, 1);
  EXPECT_EQ(with.first.thruster, 2);
  EXPECT_EQ(with.first.kind, FaultKind::kStuckOff);
  EXPECT_TRUE(without.confirmed_at < 0 || with.confirmed_at < without.confirmed_at)
      << with.confirmed_at << " against " << without.confirmed_at;
  for (const BlockerRun* run : {&without, &with}) {
    EXPECT_FALSE(run->confirmations > 0 && run->first.thruster != 2)
        << "thruster " << run->first.thruster << " confirmed " << to_string(run->first.kind);
  }
}

TEST(FaultDetector, ATwinJetWhoseSignatureTheModelsErrorMatchesIsNotConfirmedDegraded) {
  FaultDetectorParams exact;
  exact.model_sigmas = 0.0;
  int n_exact = 0;
  const FaultEvents trap = fly_twin(exact, 120000, n_exact);
  ASSERT_GE(n_exact, 1) << "the trap: with the model taken as exact, a partial loss is confirmed";
  EXPECT_EQ(trap.thruster, 11) << "the trap: the twin's fit is the better one";
  EXPECT_EQ(trap.kind, FaultKind::kDegraded);

  int n = 0;
  const FaultEvents now = fly_twin(FaultDetectorParams{}, 120000, n);
  EXPECT_FALSE(n > 0 && now.thruster == 11) << "the twin confirmed " << to_string(now.kind);
  EXPECT_FALSE(n > 0 && now.thruster != 2) << "thruster " << now.thruster << " confirmed";
}

}  // namespace
}  // namespace rocksteady::gnc

namespace rocksteady::gnc {
namespace {

// (F25) A HOLD-like flight with the model identified (the centre of mass to 1 mm), a quiet gyro,
// channel 4 (thrusters 8 and 9) never commanded and the others at a few newtons, and thruster 9
// stuck on from tick `onset`. If `stale`, thruster 8 (the same pod and channel) is commanded at
// 0.5 N for 30 s from tick 400 while the truth gives nothing (its windows pooled, F11), and is
// idle after: its stuck-off score is left above zero, below the suspicion level, for the rest of
// the flight, as an idle jet's can be in HOLD.
struct HeldRun {
  RunResult r;
  std::uint32_t probes{0};
  std::uint32_t restarts{0};
  FaultDetectorStatus before_onset;
};

HeldRun fly_held(bool episode_restart, int onset, bool stale,
                 int probe_windows = FaultDetectorParams{}.probe_windows) {
  Truth t;
  t.gyro_sigma = 1e-7;  // cases 1-4: a perfect gyro (the detector's floor)
  t.body.omega = V3(1e-4, -2e-4, 1e-4);  // HOLD
  FaultDetectorParams p = bank_params(t.gyro_sigma);
  p.episode_restart = episode_restart;
  p.probe_windows = probe_windows;
  FaultDetector d;
  d.configure(p, study_rcs_layout(kUmax), kUmax, kDt);
  d.set_model(identified_model(t));
  std::mt19937_64 rng(23);
  Vec16 prev = Vec16::Zero();
  HeldRun out;
  constexpr int kStaleFrom = 400;
  constexpr int kStaleTo = 700;
  for (int k = 0; k < onset + 600; ++k) {
    if (k == onset) t.stuck_on = 9;
    t.stuck_off = stale && k >= kStaleFrom && k < kStaleTo ? 8 : -1;
    FaultDetectorInput in;
    in.omega = t.gyro();
    in.omega_valid = true;
    in.thrust = prev;
    in.valve_open = t.valve;
    const FaultEvents e = d.update(in);
    if (e.confirmed && out.r.confirmed_at < 0) {
      out.r.confirmed_at = k;
      out.r.thruster = e.thruster;
      out.r.kind = e.kind;
    }
    t.valve = {{true, true, true, true}};
    for (int i = 0; i < 16; ++i) {
      if ((d.confirmed_on() >> i) & 1u) t.valve[static_cast<std::size_t>(i / 4)] = false;
    }
    if (d.probe_pod() >= 0) t.valve[static_cast<std::size_t>(d.probe_pod())] = false;
    Vec16 cmd = 0.05 * random_firing(rng);  // HOLD: a few newtons
    cmd(8) = cmd(9) = 0.0;
    if (stale && k >= kStaleFrom && k < kStaleTo) cmd(8) = 0.5;
    if (k == onset - 1) out.before_onset = d.status();
    t.advance(cmd);
    prev = cmd;
  }
  out.probes = d.status().probes;
  out.restarts = d.status().episode_restarts;
  return out;
}

// (F8)'s pairwise sums run over the episode. It used to start only when every score was zero,
// and thruster 8's stale score keeps it open: the stuck-on leader's unfloored sum then carries
// 290 s of healthy flight in which its idle jet would have shown (about -1e7), and every
// alternative leads it. Without isolation tests the leader is never confirmed; with them, only
// after a test has closed its pod. With (F25) a suspicion that starts with a new leader restarts
// the episode with its window, and the leader is confirmed in the windows that show it.
TEST(FaultDetector, TheEpisodeStartsWhenTheFaultShowsNotWithAStaleScore) {
  constexpr int kOnset = 3500;
  const HeldRun untested = fly_held(false, kOnset, true, 0);
  ASSERT_EQ(untested.before_onset.best, 16 + 8) << "no stale score: the case tests nothing";
  EXPECT_GT(untested.before_onset.best_llr, 0.0);
  EXPECT_LT(untested.before_onset.best_llr, 0.5 * FaultDetectorParams{}.confirm_llr);
  EXPECT_LT(untested.r.confirmed_at, 0)
      << "confirmed " << untested.r.thruster << " at tick " << untested.r.confirmed_at
      << ": the former episode did not hold the leader";
  const HeldRun tested = fly_held(false, kOnset, true);
  EXPECT_GE(tested.probes, 1u) << "the former episode confirmed without an isolation test";

  for (int probe_windows : {0, FaultDetectorParams{}.probe_windows}) {
    const HeldRun fresh = fly_held(true, kOnset, false, probe_windows);
    const HeldRun stale = fly_held(true, kOnset, true, probe_windows);
    EXPECT_EQ(stale.before_onset.best, 16 + 8);
    EXPECT_GE(stale.restarts, 1u) << "the suspicion of 9 did not restart the episode";
    for (const HeldRun* run : {&fresh, &stale}) {
      ASSERT_GE(run->r.confirmed_at, 0) << "not confirmed (isolation tests " << probe_windows << ")";
      EXPECT_EQ(run->r.thruster, 9);
      EXPECT_EQ(run->r.kind, FaultKind::kStuckOn);
      EXPECT_LE(run->r.confirmed_at, kOnset + 30) << "more than 3 s after the onset";
      EXPECT_EQ(run->probes, 0u);
    }
  }
}

// (F25) A half-strength jet under a steady firing is not a stuck-on jet of another pod. Thruster
// 0 fires 200 N throughout and delivers 100 N; thruster j, the one of another pod whose torque is
// the most nearly opposite to 0's, fires 180 N throughout, so "j stuck on" predicts only 20 N more
// of it. Under a steady firing every ramp has the same shape, and the bank's "0 stuck off"
// predicts twice the loss: a stuck-on hypothesis of another pod leads (thruster 6 here, as in the
// flight's case 1 with jet 0 at half strength during the despin), is confirmed without a rival and
// closes a healthy pod. A stuck-on leader must now beat every jet's partial loss as well.
struct SteadyRun {
  int rival{-1};
  int tests{0};  // ticks flown with a pod closed for a test
  FaultEvents first;
  int confirmations{0};
};

// test: 0 no isolation test; 1 aligned one-window tests (F27) whose verdict knows only the bank's
// hypotheses; 2 the same, the verdict also against every jet's partial loss (F29); 3 as 2, the test
// also read on its closed window (F32). With a test, the
// flight's allocation follows the valve: with the rival's pod closed, jet 0 (which the steady
// firing balances against the rival) is not commanded either.
SteadyRun fly_steady_loss(bool episode_restart, int test = 0) {
  Truth t;
  t.gyro_sigma = 1e-7;
  t.degraded = 0;
  t.degraded_factor = 0.5;
  SteadyRun out;
  const M3 j_inv = t.body.j.inverse();
  auto b = [&](int i) {
    const auto k = static_cast<std::size_t>(i);
    return V3(j_inv * (t.pos[k] + t.r).cross(t.dir[k]));
  };
  double most = 0.0;
  for (int i = 4; i < 16; ++i) {
    const double c = b(i).normalized().dot(b(0).normalized());
    if (c < most) {
      most = c;
      out.rival = i;
    }
  }
  FaultDetectorParams p = bank_params(t.gyro_sigma);
  p.probe_windows = test == 0 ? 0 : 1;
  p.probe_aligned = test != 0;
  p.probe_partial_rival = test >= 2;
  p.probe_read_closed = test == 3;
  p.degraded_min_loss = 0.1;  // (F18)
  p.episode_restart = episode_restart;
  FaultDetector d;
  d.configure(p, study_rcs_layout(kUmax), kUmax, kDt);
  d.set_model(identified_model(t));
  std::mt19937_64 rng(31);
  Vec16 prev = Vec16::Zero();
  for (int k = 0; k < 600; ++k) {
    FaultDetectorInput in;
    in.omega = t.gyro();
    in.omega_valid = true;
    in.thrust = prev;
    in.valve_open = t.valve;
    const FaultEvents e = d.update(in);
    if (e.confirmed && out.confirmations++ == 0) out.first = e;
    Vec16 cmd = 0.05 * random_firing(rng);
    cmd(0) = kUmax;
    cmd(1) = 0.0;
    const int partner = out.rival ^ 1;
    cmd(out.rival) = 0.9 * kUmax;
    cmd(partner) = 0.0;
    t.valve = {{true, true, true, true}};
    if (d.probe_pod() >= 0) {
      t.valve[static_cast<std::size_t>(d.probe_pod())] = false;
      ++out.tests;
      if (d.probe_pod() == out.rival / 4) cmd(0) = 0.0;
    }
    t.advance(cmd);
    prev = cmd;
  }
  return out;
}

TEST(FaultDetector, AHalfStrengthJetUnderSteadyFiringIsNotAStuckOnJetOfAnotherPod) {
  const SteadyRun trap = fly_steady_loss(false);
  ASSERT_GE(trap.rival, 0);
  ASSERT_GE(trap.confirmations, 1) << "the trap: nothing confirmed without the rival";
  EXPECT_NE(trap.first.thruster, 0) << "the trap";
  EXPECT_NE(trap.first.thruster / 4, 0) << "the trap: a jet of another pod";
  EXPECT_EQ(trap.first.kind, FaultKind::kStuckOn) << "the trap";
  const SteadyRun now = fly_steady_loss(true);
  EXPECT_FALSE(now.confirmations > 0 && now.first.kind == FaultKind::kStuckOn)
      << "thruster " << now.first.thruster << " confirmed stuck on";
  ASSERT_GE(now.confirmations, 1) << "the partial loss was not confirmed";
  EXPECT_EQ(now.confirmations, 1);
  EXPECT_EQ(now.first.thruster, 0);
  EXPECT_EQ(now.first.kind, FaultKind::kDegraded);
  EXPECT_NEAR(now.first.factor, 0.5, 0.05);
}

// (F29) The same jet at half strength, flown with one-window isolation tests while the allocation
// follows the valve. The episode's rival (F25) blocks the stuck-on leader, so its pod is tested:
// with the rival's pod closed, jet 0 (which the rival balanced) is not commanded either. A verdict
// that knows only the bank's hypotheses names a stuck-on jet of another pod (jet 6 here, as in
// case 1's closed loop at 10 000 s); against jet 0's partial loss over the same windows it does not.
TEST(FaultDetector, AnIsolationTestsVerdictBeatsEveryJetsPartialLoss) {
  const SteadyRun trap = fly_steady_loss(true, 1);
  ASSERT_GT(trap.tests, 0) << "no isolation test";
  ASSERT_GE(trap.confirmations, 1) << "the trap: nothing confirmed";
  EXPECT_NE(trap.first.thruster / 4, 0) << "the trap: a jet of another pod";
  EXPECT_EQ(trap.first.kind, FaultKind::kStuckOn) << "the trap";
  const SteadyRun now = fly_steady_loss(true, 2);
  EXPECT_GT(now.tests, 0);
  EXPECT_FALSE(now.confirmations > 0 && now.first.kind == FaultKind::kStuckOn)
      << "thruster " << now.first.thruster << " confirmed stuck on";
  if (now.confirmations > 0) {
    EXPECT_EQ(now.first.thruster, 0);
    EXPECT_EQ(now.first.kind, FaultKind::kDegraded);
  }
}

// (F32) The same trap read on the closed window: it is quiet because the allocation stopped
// commanding jet 0 with the rival's pod closed, not because a stuck jet stopped. The alternative
// that blocked the leader is jet 0's loss, which a window where jet 0 is not commanded cannot
// contradict, so the closed window names nothing and the run is flown as without (F32). Either
// guard holds the trap alone: the blocker's contradiction, or (F29)'s partial rival over the start
// and closed windows; with neither, the closed window names a stuck-on jet of the rival's pod.
TEST(FaultDetector, ATestsClosedWindowQuietForAnotherReasonNamesNoJetOfThatPod) {
  const SteadyRun reopened = fly_steady_loss(true, 2);
  const SteadyRun now = fly_steady_loss(true, 3);
  EXPECT_GT(now.tests, 0) << "no isolation test";
  EXPECT_FALSE(now.confirmations > 0 && now.first.kind == FaultKind::kStuckOn)
      << "thruster " << now.first.thruster << " confirmed stuck on";
  // Nothing is read on the closed window: the run is the reopened window's verdict's (F29).
  EXPECT_EQ(now.tests, reopened.tests);
  EXPECT_EQ(now.confirmations, reopened.confirmations);
  if (now.confirmations > 0) {
    EXPECT_EQ(now.first.thruster, 0);
    EXPECT_EQ(now.first.kind, FaultKind::kDegraded);
  }
}

// (F25) The mirror trap of (F8) with the episode restart: never the mirror jet without the
// isolation test, thruster 2 with it.
TEST(FaultDetector, TheEpisodeRestartNeverConfirmsTheMirrorJet) {
  FaultDetectorParams no_test;
  no_test.probe_windows = 0;
  no_test.episode_restart = true;
  const AmbiguousRun alone = fly_ambiguous(no_test);
  EXPECT_NE(alone.r.thruster, 11);
  FaultDetectorParams with_test;
  with_test.episode_restart = true;
  const AmbiguousRun tested = fly_ambiguous(with_test);
  ASSERT_GE(tested.r.confirmed_at, 0) << "not isolated";
  EXPECT_EQ(tested.r.thruster, 2);
  EXPECT_EQ(tested.r.kind, FaultKind::kStuckOn);
}

TEST(FaultDetector, HealthyFiringNeverConfirmsAFaultWithTheEpisodeRestart) {
  for (double sigma : {3.1623e-6, 3.1623e-5}) {
    Truth t;
    t.gyro_sigma = sigma;
    FaultDetectorParams p = bank_params(sigma);
    p.episode_restart = true;
    p.degraded_min_loss = 0.1;  // (F18) on: the rival compares partial losses
    FaultDetector d;
    d.configure(p, study_rcs_layout(kUmax), kUmax, kDt);
    d.set_model(identified_model(t));
    const RunResult r = fly(t, d, 20000, -1, -1, -1);
    EXPECT_LT(r.confirmed_at, 0) << "false alarm: thruster " << r.thruster << " "
                                 << to_string(r.kind) << " at tick " << r.confirmed_at;
    EXPECT_GT(d.status().windows, 1900u);
  }
}

// (F28) The window's no-fault statistic under white gyro noise alone (a held vehicle, the truth's
// model, no floor, no disturbance): chi-square with 3 degrees of freedom, mean 3, when the gyro's
// share of a sample's variance is sigma_g^2, since the start sample's noise is a common offset
// that the centring removes; half of that when it is counted twice (2 sigma_g^2).
double mean_quiet_chi2(bool centred, double* above) {
  Truth t;
  t.gyro_sigma = 3.1623e-5;  // case 6
  t.body.omega = V3(1e-5, -1e-5, 2e-5);
  FaultDetectorParams p = bank_params(t.gyro_sigma, 25);
  p.centred_gyro_noise = centred;
  p.model_rel_floor = 0.0;
  FaultDetector d;
  d.configure(p, study_rcs_layout(kUmax), kUmax, kDt);
  FaultModel m = identified_model(t);
  m.j_rel_sigma = 0.0;
  m.r_cov = Mat3::Zero();
  m.k_sigma = 0.0;
  d.set_model(m);
  double sum = 0.0;
  int n = 0;
  int over = 0;
  std::uint32_t seen = 0;
  for (int k = 0; k < 25 * 4000 + 10; ++k) {
    FaultDetectorInput in;
    in.omega = t.gyro();
    in.omega_valid = true;
    in.thrust = Vec16::Zero();
    d.update(in);
    t.advance(Vec16::Zero());
    if (d.status().windows != seen) {
      seen = d.status().windows;
      sum += d.status().chi2;
      if (d.status().chi2 > 7.815) ++over;  // chi-square(3) at 0.95
      ++n;
    }
  }
  *above = static_cast<double>(over) / n;
  return sum / n;
}

TEST(FaultDetector, TheNoFaultStatisticIsChiSquareThreeUnderWhiteGyroNoise) {
  double above = 0.0;
  const double centred = mean_quiet_chi2(true, &above);
  // 4000 windows: the mean's 1 sigma is sqrt(6 / 4000) = 0.04; the tail's (5 %) 0.0034.
  EXPECT_NEAR(centred, 3.0, 0.2);
  EXPECT_NEAR(above, 0.05, 0.015);
  const double doubled = mean_quiet_chi2(false, &above);
  EXPECT_NEAR(doubled, 1.5, 0.1);
  EXPECT_LT(above, 0.01);  // chi-square(3) > 15.6: 0.14 %
}

// (F57) HOLD's milli-newton firing and one firm burst of jet 6 (100 N for 6 s, at 100 s) while
// it is at half strength. The burst's stuck-off energy verifies the jet (F36) and leaves its
// partial-loss evidence below check_llr: with the survey's 20 000 s interval the jet is neither
// checked nor surveyed again in the 4 000 s flown, and its loss is never seen. With
// survey_loss_llr the evidence keeps it unverified, it is surveyed one check interval (600 s)
// after the burst, and the surveys take it to its evidence checks and its confirmation, degraded
// at about half strength. The healthy jet, with the same burst, is verified and never surveyed.
struct BurstHold {
  MilliNewtonHold base;
  int jet;
  double force;
  int from;
  int len;
  Vec16 next(int tick) {
    Vec16 f = base.next(tick);
    if (tick >= from && tick < from + len) {
      f(jet ^ 1) = 0.0;
      f(jet) = force;
    }
    return f;
  }
};

TEST(FaultDetector, AJetWithPartialLossEvidenceIsNotVerifiedByItsEnergyAndIsSurveyed) {
  constexpr int kJet = 6;
  constexpr int kBurstEnd = 1060;
  for (const bool degraded : {true, false}) {
    for (const double loss_llr : {0.0, 2.5}) {
      const std::string what = std::string(degraded ? "half strength" : "healthy") +
                               ", survey_loss_llr " + std::to_string(loss_llr);
      Truth t;
      t.degraded = degraded ? kJet : -1;
      FaultDetectorParams p = survey_params(t, 20000.0);
      p.survey_loss_llr = loss_llr;
      FaultDetector d = make_detector(t, p);
      const SurveyRun run =
          fly_checks(t, d, BurstHold{MilliNewtonHold(5), kJet, 100.0, 1000, 60}, 100000);
      std::vector<int> own;  // ticks of the checks of jet 6
      std::vector<bool> own_survey;
      for (std::size_t a = 0; a < run.checked.size(); ++a) {
        if (run.checked[a] != kJet) continue;
        own.push_back(run.check_ticks[a]);
        own_survey.push_back(run.surveyed[a]);
      }
      if (!degraded || loss_llr == 0.0) {
        EXPECT_LT(run.r.confirmed_at, 0) << what << ": thruster " << run.r.thruster << " "
                                         << to_string(run.r.kind);
        EXPECT_TRUE(own.empty()) << what << ": jet 6 checked at tick " << own.front();
        continue;
      }
      ASSERT_FALSE(own.empty()) << what << ": never surveyed";
      EXPECT_TRUE(own_survey.front()) << what << ": its first check was not the survey's";
      // One survey for its evidence in the survey interval; the evidence checks do the rest.
      EXPECT_EQ(std::count(own_survey.begin(), own_survey.end(), true), 1) << what;
      EXPECT_GE(own.size(), 2u) << what << ": no evidence check after the survey";
      // 600 s after the burst verified its energy, within a decision round of 16 jets.
      EXPECT_GE(own.front(), kBurstEnd + 6000 - 100) << what;
      EXPECT_LE(own.front(), kBurstEnd + 6000 + 16 * 10) << what;
      ASSERT_GE(run.r.confirmed_at, 0) << what;
      EXPECT_EQ(run.r.thruster, kJet) << what;
      EXPECT_EQ(run.r.kind, FaultKind::kDegraded) << what;
      EXPECT_NEAR(run.factor, 0.5, 0.1) << what;
      EXPECT_EQ(run.confirmations, 1) << what;
    }
  }
}


// (F58) A stuck-off leader whose fitted loss lies total_loss_sigmas (3) of the fit's own 1 sigma
// (1 / sqrt(E)) below the total-loss floor is held back as a partial loss; without it only the
// margin_llr of partial_not_total (sqrt(20) = 4.5 of them) does. The centre of mass known to
// 0.3 m puts every jet's floor at 0.75-0.79 (the model's error, the gap capped); the despin's weak
// firing four times as strong; a jet at 35 % or 40 % of its thrust (a loss of 0.65 or 0.6,
// 0.1-0.18 below the floor), 10 jets x 3 firings each, each flown to its first confirmation.
// Without (F58) its decision often lands with the fitted loss between 3 and 4.5 of its 1 sigma
// below the floor, and the jet is named stuck off; with it, fewer runs are. No run changes otherwise than from stuck off to degraded or
// to nothing confirmed, and no run names another jet. A dead jet fits at the floor or above, and
// is confirmed stuck off with (F58) in every one of 16 runs.
struct StrongerWeakFiring {
  WeakFiring firing;
  Vec16 next(int tick) { return 4.0 * firing.next(tick); }
};

TEST(FaultDetector, AStuckOffLeaderWellBelowTheTotalLossFloorIsHeldAsAPartialLoss) {
  constexpr double kRSigma = 0.3;
  // The jets this firing decides within 10 000 s at 35-40 % thrust: the tangential ones and pod
  // 1's axial pair (the other axial jets' losses lie within their model's error and stay
  // unconfirmed either way).
  constexpr std::array<int, 10> kJets{{0, 1, 4, 5, 6, 7, 8, 9, 12, 13}};
  auto params = [](const Truth& t, double sigmas) {
    FaultDetectorParams p = bank_params(t.gyro_sigma);
    p.degraded_min_loss = 0.1;
    p.model_sigmas = 3.0;
    p.margin_llr = 10.0;
    p.confirm_llr = 25.0;
    p.episode_restart = true;
    p.degraded_loss_projection = true;
    p.total_loss_sigmas = sigmas;
    return p;
  };
  int stuck_off[2] = {0, 0};  // runs named stuck off, without and with (F58)
  int degraded[2] = {0, 0};
  for (const double factor : {0.35, 0.4}) {
    for (const std::uint64_t seed : {700u, 800u, 900u}) {
      for (const int jet : kJets) {
        FaultKind kind[2] = {FaultKind::kNone, FaultKind::kNone};
        for (int with = 0; with < 2; ++with) {
          const std::string what = "jet " + std::to_string(jet) + " at " +
                                   std::to_string(factor) + ", firing " + std::to_string(seed) +
                                   (with != 0 ? ", F58" : ", without F58");
          Truth t;
          t.degraded = jet;
          t.degraded_factor = factor;
          FaultDetector d = make_detector_r(t, params(t, with != 0 ? 3.0 : 0.0), kRSigma);
          const double floor = d.total_loss_floor(jet);
          EXPECT_GE(floor, 0.75) << what;
          EXPECT_LE(floor, 0.79) << what;
          const CheckRun run = fly_checks(
              t, d, StrongerWeakFiring{WeakFiring(seed + static_cast<std::uint64_t>(jet))}, 100000,
              -1, -1, 0, true);  // to the first confirmation (the aarch64 build's time under qemu)
          if (run.r.confirmed_at < 0) continue;
          EXPECT_EQ(run.r.thruster, jet) << what;
          kind[with] = run.r.kind;
          if (run.r.kind == FaultKind::kStuckOff) ++stuck_off[with];
          if (run.r.kind == FaultKind::kDegraded) {
            ++degraded[with];
            EXPECT_NEAR(run.factor, factor, 0.05) << what;
          }
        }
        if (kind[1] != kind[0]) {
          EXPECT_EQ(kind[0], FaultKind::kStuckOff)
              << "jet " << jet << " at " << factor << ", firing " << seed << ": "
              << to_string(kind[0]) << " became " << to_string(kind[1]);
        }
      }
    }
  }
  std::printf("stuck off without / with F58: %d / %d; degraded %d / %d (60 runs)\n", stuck_off[0],
              stuck_off[1], degraded[0], degraded[1]);
  EXPECT_GE(stuck_off[0], 10) << "the rig puts decisions near the floor";
  EXPECT_LE(stuck_off[1], stuck_off[0] - 4);
  EXPECT_GT(degraded[1], degraded[0]);
  for (int jet = 0; jet < 16; ++jet) {
    Truth t;
    t.stuck_off = jet;
    FaultDetector d = make_detector_r(t, params(t, 3.0), kRSigma);
    const CheckRun run = fly_checks(
        t, d, StrongerWeakFiring{WeakFiring(700 + static_cast<std::uint64_t>(jet))}, 30000, -1, -1, 0,
        true);
    ASSERT_GE(run.r.confirmed_at, 0) << "dead jet " << jet;
    EXPECT_EQ(run.r.thruster, jet);
    EXPECT_EQ(run.r.kind, FaultKind::kStuckOff) << "dead jet " << jet;
  }
}

// (F59) After a confirmed fault, no stuck-off or partial-loss confirmation and no check on a
// model whose inertia is not known to after_fault_max_j_rel (0.01). Jet 14 is latched stuck off
// (declared; the firing no longer commands it) and jet 5 fails at 5 s under random firing, the body
// at HOLD's rate. On a model with J known to 1e-4, jet 5 dead is confirmed stuck off and at half strength degraded,
// gate or not; on one known to 5 % neither is confirmed with the gate, and no check is flown,
// while without the gate, or without the latch, the same flight confirms it. A jet stuck on is
// confirmed with the gate as without it (its isolation test's pod closed by the harness).
struct RandomWithoutJet {
  std::mt19937_64 rng;
  int jet;
  Vec16 next(int) {
    Vec16 f = random_firing(rng);
    if (jet >= 0) f(jet) = 0.0;  // a latched jet is not allocated
    return f;
  }
};

TEST(FaultDetector, AfterAFaultNoFurtherLossIsConfirmedOnAModelNotConfidentAgain) {
  constexpr int kJet = 5;
  constexpr int kLatched = 14;
  for (const FaultKind kind : {FaultKind::kStuckOff, FaultKind::kDegraded, FaultKind::kStuckOn}) {
    for (const double j_rel : {1e-4, 0.02}) {
      for (const bool latch : {true, false}) {
        for (const double gate : {0.0, 0.01}) {
          if (!latch && gate == 0.0) continue;
          const std::string what = to_string(kind) + std::string(", J 1 sigma ") +
                                   std::to_string(j_rel) + (latch ? ", jet 14 latched" : "") +
                                   ", gate " + std::to_string(gate);
          Truth t;
          t.gyro_sigma = 1e-6;
          t.body.omega = V3(1e-5, -2e-5, 1e-5);  // HOLD: the gyroscopic term's share of J's error small
          FaultDetectorParams p = bank_params(t.gyro_sigma);
          p.degraded_min_loss = 0.1;
          p.check_llr = 5.0;
          p.after_fault_max_j_rel = gate;
          p.probe_after_windows = 1;  // (F9) a stuck-on jet's isolation test: its pod closed
          p.probe_windows = 1;
          ASSERT_TRUE(validate(p).ok) << what;
          FaultDetector d;
          d.configure(p, study_rcs_layout(kUmax), kUmax, kDt);
          FaultModel m = identified_model(t);
          m.j_rel_sigma = j_rel;
          d.set_model(m);
          if (latch) d.declare(kLatched, FaultKind::kStuckOff);
          RandomWithoutJet firing{std::mt19937_64(11), latch ? kLatched : -1};
          Vec16 prev = Vec16::Zero();
          DegradedRun run;
          int checks_started = 0;
          for (int k = 0; k < 20000; ++k) {  // 2000 s
            if (k == 50) {
              if (kind == FaultKind::kStuckOff) t.stuck_off = kJet;
              if (kind == FaultKind::kStuckOn) t.stuck_on = kJet;
              if (kind == FaultKind::kDegraded) t.degraded = kJet;
            }
            FaultDetectorInput in;
            in.omega = t.gyro();
            in.omega_valid = true;
            in.thrust = prev;
            in.valve_open = t.valve;
            const int before = d.check_jet();
            run.note(d.update(in), k);
            if (d.check_jet() >= 0 && d.check_jet() != before) ++checks_started;
            Vec16 cmd = firing.next(k);
            if (d.check_jet() >= 0) cmd(d.check_jet()) += d.check_force();
            for (int q = 0; q < 4; ++q) t.valve[static_cast<std::size_t>(q)] = q != d.probe_pod();
            t.advance(cmd);
            prev = cmd;
          }
          const bool gated = latch && gate > 0.0 && j_rel > gate && kind != FaultKind::kStuckOn;
          if (gated) {
            EXPECT_LT(run.r.confirmed_at, 0) << what << ": confirmed " << run.r.thruster << " "
                                             << to_string(run.r.kind);
            EXPECT_EQ(checks_started, 0) << what;
            EXPECT_EQ(d.status().checks, 0u) << what;
            continue;
          }
          ASSERT_GE(run.r.confirmed_at, 0) << what;
          EXPECT_EQ(run.r.thruster, kJet) << what;
          EXPECT_EQ(run.r.kind, kind) << what;
          EXPECT_EQ(run.confirmations, 1) << what;
        }
      }
    }
  }
}

}  // namespace
}  // namespace rocksteady::gnc
