// (F61) The channel balance test through the fault detector, against a separately written truth:
// the rigid body of tests/common, sixteen thrusters whose torques are written out here from the
// SPEC §4 geometry, a noisy gyro and the external disturbance. The detector's model is far from
// the truth (J 50 % off, the centre of mass 3 m off, as after a fault absorbed while identifying):
// the test needs none of it. Every half, dead or at half strength, is named with its kind; a
// healthy RCS is never blamed; a flight that moves the body with other jets leaves it undecided.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <random>

#include "gnc/fdi/fault_detector.hpp"
#include "gnc/model/mass_properties.hpp"
#include "rigid_body.hpp"

namespace rocksteady::gnc {
namespace {

using test::V3;

constexpr double kUmax = 200.0;
constexpr double kDt = 0.1;

struct Rig {
  std::array<V3, 16> pos{};
  std::array<V3, 16> dir{};
  V3 r{-0.0495, -0.0004, 3.5456};  // the study's r_SO/BCM
  test::RigidBody body;
  std::mt19937_64 rng{11};
  double gyro_sigma{3.1623e-6};  // case 5
  double disturbance_sigma{0.57735026918962576};
  int faulty{-1};
  double factor{0.0};  // the faulty thruster's strength (0: dead)
  int stuck_on{-1};    // ... or this one stuck on from tick stuck_on_tick
  int stuck_on_tick{0};
  V3 disturbance{V3::Zero()};

  Rig() {
    for (int k = 0; k < 4; ++k) {
      const double th = M_PI / 4 + M_PI / 2 * k;
      const V3 p(2.5 * std::cos(th), 2.5 * std::sin(th), 3.0);
      const V3 tang(-std::sin(th), std::cos(th), 0.0);
      for (int q = 0; q < 4; ++q) pos[static_cast<std::size_t>(4 * k + q)] = p;
      dir[static_cast<std::size_t>(4 * k)] = tang;
      dir[static_cast<std::size_t>(4 * k + 1)] = -tang;
      dir[static_cast<std::size_t>(4 * k + 2)] = V3(0, 0, 1);
      dir[static_cast<std::size_t>(4 * k + 3)] = V3(0, 0, -1);
    }
    body.j = total_inertia(study_true_mass_properties());
    body.omega = V3(2e-5, -1e-5, 1e-5);  // HOLD
  }
  void advance(const Vec16& f, int tick) {
    if (tick % 100 == 0) {  // held for 10 s, as the plant's
      std::normal_distribution<double> n(0.0, disturbance_sigma);
      disturbance = V3(n(rng), n(rng), n(rng));
    }
    V3 tau = disturbance;
    for (int i = 0; i < 16; ++i) {
      const double k = i == faulty ? factor : 1.0;
      const double fi = i == stuck_on && tick >= stuck_on_tick ? kUmax : f(i);
      tau += (pos[static_cast<std::size_t>(i)] + r).cross(k * fi * dir[static_cast<std::size_t>(i)]);
    }
    body.step(kDt, tau);
  }
  V3 gyro() {
    std::normal_distribution<double> n(0.0, gyro_sigma);
    return body.omega + V3(n(rng), n(rng), n(rng));
  }
};

FaultDetectorParams balance_params(double gyro_sigma) {
  FaultDetectorParams p;
  p.enabled = true;
  p.window_ticks = 10;
  p.gyro_sigma = gyro_sigma;
  p.centred_gyro_noise = true;
  p.balance.kick_rad_s = 5e-5;  // gnc.yaml's
  p.balance.force_n = 100.0;
  p.balance.quiet_ticks = 300;
  p.balance.max_fire_ticks = 200;
  p.balance.interval_s = 100.0;  // rounds back to back, for the test's length
  p.balance.chi2_bound = 30.66;
  p.balance.min_snr = 10.0;
  p.balance.total_sigmas = 2.0;
  p.balance.partial_sigmas = 3.0;
  p.balance.min_loss = 0.1;
  p.balance.max_tests = 6;
  return p;
}

// The detector's model: J 50 % larger (and its products doubled), the centre of mass 3 m off,
// and the identifier's 1 sigma saying it is not known.
FaultModel far_model(const Rig& t) {
  FaultModel m;
  Mat3 j = 1.5 * t.body.j;
  j(0, 1) *= 2.0;
  j(1, 0) = j(0, 1);
  m.j = j;
  m.r = t.r + Vec3(2.0, -2.0, 1.0);
  m.j_rel_sigma = 0.3;
  m.r_cov = Mat3::Identity() * 1.0;
  m.k_sigma = 0.01;
  return m;
}

struct Flown {
  int confirmations{0};
  int thruster{-1};
  FaultKind kind{FaultKind::kNone};
  double factor{0.0};
  double factor_sigma{0.0};
  FaultDetectorStatus status{};
};

// Flies `ticks` of HOLD in free drift; the only thrust is the balance test's, plus `busy_jet`
// at busy_force_n throughout (a flight moving the body with another jet).
Flown fly(Rig& t, const FaultDetectorParams& p, int ticks, int busy_jet = -1, double busy_force_n = 0.0) {
  FaultDetector d;
  d.configure(p, study_rcs_layout(kUmax), kUmax, kDt);
  d.set_model(far_model(t));
  Flown out;
  Vec16 prev = Vec16::Zero();
  for (int k = 0; k < ticks; ++k) {
    FaultDetectorInput in;
    in.omega = t.gyro();
    in.omega_valid = true;
    in.thrust = prev;
    in.balance_allowed = true;
    const FaultEvents e = d.update(in);
    if (e.confirmed) {
      ++out.confirmations;
      if (out.confirmations == 1) {
        out.thruster = e.thruster;
        out.kind = e.kind;
        out.factor = e.factor;
        out.factor_sigma = e.factor_sigma;
      }
    }
    Vec16 f = d.balance_thrust();
    if (busy_jet >= 0) f(busy_jet) += busy_force_n;
    t.advance(f, k);
    prev = f;
  }
  out.status = d.status();
  return out;
}

TEST(ChannelBalance, AHealthyRcsIsBalancedRoundAfterRound) {
  for (const double sigma : {3.1623e-6, 3.1623e-5}) {  // cases 5 and 6-7
    Rig t;
    t.gyro_sigma = sigma;
    const Flown f = fly(t, balance_params(sigma), sigma > 1e-5 ? 30000 : 12000);
    EXPECT_EQ(f.confirmations, 0) << sigma;
    EXPECT_GE(f.status.balance_tests, 24u) << sigma;  // three rounds of the eight channels at least
    EXPECT_EQ(f.status.balance_inconclusive, 0u) << sigma;
    EXPECT_EQ(f.status.balance_aborted, 0u) << sigma;
  }
}

// One confirmation, of thruster i with the kind its strength k says (0: stuck off), and a
// degraded factor within 3 of its 1 sigma (at least `tol`).
void expect_named(const Flown& f, int i, double k, double tol) {
  ASSERT_EQ(f.confirmations, 1) << "thruster " << i << " at " << k;
  EXPECT_EQ(f.thruster, i) << k;
  EXPECT_EQ(f.kind, k == 0.0 ? FaultKind::kStuckOff : FaultKind::kDegraded) << i;
  if (k > 0.0) {
    EXPECT_NEAR(f.factor, k, std::fmax(3.0 * f.factor_sigma, tol)) << i;
    EXPECT_GT(f.factor_sigma, 0.0) << i;
  }
}

TEST(ChannelBalance, EveryHalfDeadOrAtHalfStrengthIsNamedWithItsKind) {
  const FaultDetectorParams p = balance_params(3.1623e-6);
  for (int i = 0; i < 16; ++i) {
    for (const double k : {0.0, 0.5}) {
      Rig t;
      t.faulty = i;
      t.factor = k;
      const Flown f = fly(t, p, 3000);
      expect_named(f, i, k, 0.02);
      EXPECT_EQ(f.status.balance_confirmations, 1u) << i;
    }
  }
}

TEST(ChannelBalance, TheNoisyGyroOfCasesSixAndSevenNamesTheFaultyHalfToo) {
  const FaultDetectorParams p = balance_params(3.1623e-5);
  for (const int i : {0, 3, 9, 14}) {
    for (const double k : {0.0, 0.5}) {
      Rig t;
      t.gyro_sigma = 3.1623e-5;
      t.faulty = i;
      t.factor = k;
      expect_named(fly(t, p, 30000), i, k, 0.05);
    }
  }
}

TEST(ChannelBalance, ALossBelowMinLossIsBalancedAndOneAboveItIsNamed) {
  const FaultDetectorParams p = balance_params(3.1623e-6);
  for (const double k : {0.95, 0.75}) {
    Rig t;
    t.faulty = 5;
    t.factor = k;
    const Flown f = fly(t, p, 3000);
    if (k > 1.0 - p.balance.min_loss) {
      EXPECT_EQ(f.confirmations, 0) << k;
    } else {
      ASSERT_EQ(f.confirmations, 1) << k;
      EXPECT_EQ(f.thruster, 5);
      EXPECT_EQ(f.kind, FaultKind::kDegraded);
      EXPECT_NEAR(f.factor, k, std::fmax(3.0 * f.factor_sigma, 0.02));
    }
  }
}

// (F61c) A dead jet of channel 7 commanded at 2 N throughout: the model predicts its torque, the
// body does not get it. The tests of every other channel are then not clean (other jets' motion
// over a test beyond a quarter of min_loss of its kick): none of them is blamed.
TEST(ChannelBalance, AFlightMovingTheBodyWithOtherJetsBlamesNoHealthyChannel) {
  const FaultDetectorParams p = balance_params(3.1623e-6);
  Rig t;
  t.faulty = 14;
  t.factor = 0.0;
  const Flown f = fly(t, p, 6000, 14, 2.0);
  if (f.confirmations > 0) {
    EXPECT_EQ(f.thruster, 14);
  }
  EXPECT_LE(f.confirmations, 1);
  EXPECT_GE(f.status.balance_inconclusive, 7u);
  // The same flight without the busy jet names it at once (the rig is not inert).
  Rig quiet;
  quiet.faulty = 14;
  const Flown g = fly(quiet, p, 3000);
  EXPECT_EQ(g.confirmations, 1);
  EXPECT_EQ(g.thruster, 14);
}

// (F61d, F61e) A jet stuck on while a test flies: the test ends within a few seconds (dropped when
// the body moves beyond what the test can do, or its fit refused at its end), no balance verdict
// blames the tested channel, and the bank confirms the stuck jet on the windows after it.
TEST(ChannelBalance, AJetStuckOnDuringATestEndsItAndTheBankIsolatesTheJet) {
  const FaultDetectorParams p = balance_params(3.1623e-6);
  Rig t;
  t.stuck_on = 4;  // a tangential jet: no mirror, so the rig needs no valves for the isolation test
  t.stuck_on_tick = 25;  // within the first test (channel 0's)
  FaultDetector d;
  d.configure(p, study_rcs_layout(kUmax), kUmax, kDt);
  FaultModel m;  // the bank's model: the truth's (the test needs none; the bank does)
  m.j = t.body.j;
  m.r = t.r;
  m.j_rel_sigma = 1e-4;
  m.r_cov = Mat3::Identity() * 1e-6;
  m.k_sigma = 1e-3;
  d.set_model(m);
  Vec16 prev = Vec16::Zero();
  int dropped_at = -1;
  int confirmed_at = -1;
  for (int k = 0; k < 600 && confirmed_at < 0; ++k) {
    FaultDetectorInput in;
    in.omega = t.gyro();
    in.omega_valid = true;
    in.thrust = prev;
    in.balance_allowed = true;
    const int before = d.balance_channel();
    const FaultEvents e = d.update(in);
    if (k >= t.stuck_on_tick && before >= 0 && d.balance_channel() < 0 && dropped_at < 0) {
      dropped_at = k;  // the test under way at the onset ended (dropped, or its fit refused)
    }
    if (k == t.stuck_on_tick) {
      EXPECT_GE(d.balance_channel(), 0);  // the rig: the jet sticks while a test flies
    }
    if (e.confirmed) {
      confirmed_at = k;
      EXPECT_EQ(e.thruster, 4);
      EXPECT_EQ(e.kind, FaultKind::kStuckOn);
    }
    Vec16 f = d.balance_thrust();
    t.advance(f, k);
    prev = f;
  }
  ASSERT_GE(dropped_at, 0);
  EXPECT_LE(dropped_at, t.stuck_on_tick + 60);
  ASSERT_GE(confirmed_at, 0);
  EXPECT_LE(confirmed_at, t.stuck_on_tick + 100);
  EXPECT_EQ(d.status().balance_confirmations, 0u);
}

// Nothing starts outside HOLD (the GNC's balance_allowed) or with the test off.
// With windows of five updates and the partial-loss step on (the firmware's table), the closed
// window's evaluation and the partial-loss step take every update but one: the fit of a test
// whose last sample is in must still run (it once never did, and the flight drifted free with a
// jet stuck on), and the flight takes control again as soon as the test's samples are in.
TEST(ChannelBalance, ATestsFitRunsWithShortWindowsAndTheFlightResumesAtItsLastSample) {
  Rig t;
  FaultDetectorParams p = balance_params(t.gyro_sigma);
  p.window_ticks = 5;
  p.degraded_min_loss = 0.1;
  FaultDetector d;
  d.configure(p, study_rcs_layout(kUmax), kUmax, kDt);
  FaultModel m;
  m.j = t.body.j;
  m.r = t.r;
  m.j_rel_sigma = 0.01;
  m.r_cov = Mat3::Identity() * 1e-4;
  m.k_sigma = 0.01;
  d.set_model(m);
  Vec16 prev = Vec16::Zero();
  int pending_run = 0;
  int longest_pending = 0;
  int verdicts = 0;
  for (int k = 0; k < 3000; ++k) {
    FaultDetectorInput in;
    in.omega = t.gyro();
    in.omega_valid = true;
    in.thrust = prev;
    in.balance_allowed = true;
    const bool was_pending = d.balance_test().evaluate_pending();
    const FaultEvents e = d.update(in);
    EXPECT_FALSE(e.confirmed) << "tick " << k;
    const ChannelBalanceTest& bt = d.balance_test();
    if (was_pending && !bt.evaluate_pending()) ++verdicts;
    pending_run = bt.evaluate_pending() ? pending_run + 1 : 0;
    longest_pending = std::max(longest_pending, pending_run);
    const Vec16 f = d.balance_thrust();
    if (bt.evaluate_pending()) {  // the samples are in: no test flown, the flight's own thrust
      EXPECT_EQ(d.balance_channel(), -1) << "tick " << k;
      EXPECT_EQ(f.squaredNorm(), 0.0) << "tick " << k;
    }
    t.advance(f, k);
    prev = f;
  }
  const FaultDetectorStatus& st = d.status();
  EXPECT_GE(st.balance_tests, 8u);  // a round of every channel, at least
  EXPECT_GE(verdicts, 8);
  EXPECT_EQ(st.balance_aborted, 0u);
  EXPECT_EQ(st.balance_confirmations, 0u);
  EXPECT_LE(longest_pending, p.window_ticks);  // the fit waited at most one window
}

TEST(ChannelBalance, NoTestWithoutTheFlightsLeaveOrWithTheKickAtZero) {
  for (const bool allowed : {false, true}) {
    FaultDetectorParams p = balance_params(3.1623e-6);
    if (allowed) p.balance.kick_rad_s = 0.0;
    Rig t;
    t.faulty = 2;
    FaultDetector d;
    d.configure(p, study_rcs_layout(kUmax), kUmax, kDt);
    d.set_model(far_model(t));
    for (int k = 0; k < 2000; ++k) {
      FaultDetectorInput in;
      in.omega = t.gyro();
      in.omega_valid = true;
      in.balance_allowed = allowed;
      d.update(in);
      EXPECT_LT(d.balance_channel(), 0);
      t.advance(Vec16::Zero(), k);
    }
    EXPECT_EQ(d.status().balance_tests, 0u);
  }
}

TEST(ChannelBalance, BadParametersAreRefusedWithTheirField) {
  FaultDetectorParams p = balance_params(1e-6);
  p.balance.quiet_ticks = 0;
  EXPECT_STREQ(validate(p).field, "fdi.balance.quiet_ticks");
  p = balance_params(1e-6);
  p.balance.min_loss = 1.0;
  EXPECT_STREQ(validate(p).field, "fdi.balance.min_loss");
  p = balance_params(1e-6);
  p.balance.partial_sigmas = 1.0;  // below total_sigmas
  EXPECT_STREQ(validate(p).field, "fdi.balance.partial_sigmas");
  p = balance_params(1e-6);
  p.balance.kick_rad_s = -1.0;
  EXPECT_STREQ(validate(p).field, "fdi.balance.kick_rad_s");
  EXPECT_TRUE(validate(balance_params(1e-6)).ok);
}

}  // namespace
}  // namespace rocksteady::gnc
