// Identification excitation (gnc/estimation/README.md §I.6): torque-free on the model in closed
// form, the asked net force, the channels' bounds under saturation and faults, the direction cycle,
// the stop rule. Independent truth: torque columns and net force written here from the SPEC §4
// geometry ((p + r) x d and the sum of d u), not from gnc::torque_matrix.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include <Eigen/QR>

#include "gnc/estimation/excitation.hpp"
#include "gnc/model/mass_properties.hpp"
#include "gnc/model/rcs.hpp"

namespace rocksteady::gnc {
namespace {

// The torque and net force of channel forces u, written from the layout (SPEC §4).
Vec3 torque_of(const RcsLayout& l, const Vec3& r, const Vec8& u) {
  Vec3 t = Vec3::Zero();
  for (int c = 0; c < kChannels; ++c) {
    const Vec3 arm = l.pod_position[static_cast<std::size_t>(l.channel_pod[c])] + r;
    t += arm.cross(l.channel_direction[static_cast<std::size_t>(c)]) * u(c);
  }
  return t;
}
Vec3 force_of(const RcsLayout& l, const Vec8& u) {
  Vec3 f = Vec3::Zero();
  for (int c = 0; c < kChannels; ++c) f += l.channel_direction[static_cast<std::size_t>(c)] * u(c);
  return f;
}

struct Rig {
  RcsLayout rcs{study_rcs_layout(200.0)};
  Vec3 r_hat{study_true_mass_properties().r_so_bcm + Vec3(-1.0, -1.0, -1.0) / std::sqrt(3.0)};
  IdentificationExcitation ex;
  explicit Rig(double force = 100.0) {
    ExcitationConfig c;
    c.enabled = true;
    c.force_n = Vec3::Constant(force);
    ex.configure(c);
    ex.set_model(torque_matrix(rcs, r_hat), rcs);
  }
  void ready() {
    for (int i = 0; i < IdentificationExcitation::kModelStages; ++i) {
      EXPECT_FALSE(ex.ready()) << "ready before stage " << i;
      ex.step_model();
    }
    ASSERT_TRUE(ex.ready());
  }
};

TEST(IdentificationExcitation, IsTorqueFreeOnTheModelAndMakesTheAskedForce) {
  Rig rig;
  rig.ready();
  // (X2) closed form: B_hat N = 0, E N = I, B_hat Z = E Z = 0, Z orthonormal.
  for (int k = 0; k < 3; ++k) {
    const Vec8 n = rig.ex.force_map().col(k);
    EXPECT_LT(torque_of(rig.rcs, rig.r_hat, n).norm(), 1e-9) << "column " << k;
    EXPECT_LT((force_of(rig.rcs, n) - Vec3::Unit(k)).norm(), 1e-12) << "column " << k;
  }
  for (int k = 0; k < 2; ++k) {
    const Vec8 z = rig.ex.kernel().col(k);
    EXPECT_LT(torque_of(rig.rcs, rig.r_hat, z).norm(), 1e-9);
    EXPECT_LT(force_of(rig.rcs, z).norm(), 1e-12);
    EXPECT_NEAR(z.norm(), 1.0, 1e-12);
  }
  EXPECT_NEAR(rig.ex.kernel().col(0).dot(rig.ex.kernel().col(1)), 0.0, 1e-12);
  // Added to an unsaturated allocation: exactly the force, no torque on the model.
  const Vec8 lo = Vec8::Constant(-200.0), hi = Vec8::Constant(200.0);
  for (std::uint32_t w = 0; w < 6; ++w) {
    const Vec8 u0 = Vec8::Constant(10.0) - 3.0 * Vec8::LinSpaced(0.0, 7.0);
    Vec8 u = u0;
    const Vec3 f = rig.ex.force(w);
    const ExcitationStatus s = rig.ex.apply(f, lo, hi, 0.1, u);
    EXPECT_TRUE(s.active);
    EXPECT_EQ(s.gamma, 1.0);
    EXPECT_EQ(s.blocked, 0);
    EXPECT_LT(torque_of(rig.rcs, rig.r_hat, u - u0).norm(), 1e-9);
    EXPECT_LT((force_of(rig.rcs, u - u0) - f).norm(), 1e-9);
  }
  EXPECT_NEAR(rig.ex.elapsed(), 0.6, 1e-12);
}

TEST(IdentificationExcitation, CyclesSixDirectionsOnePerWindow) {
  Rig rig(80.0);
  const Vec3 expected[6] = {Vec3(80, 0, 0), Vec3(-80, 0, 0), Vec3(0, 80, 0),
                            Vec3(0, -80, 0), Vec3(0, 0, 80), Vec3(0, 0, -80)};
  Vec3 sum = Vec3::Zero();
  for (std::uint32_t w = 0; w < 12; ++w) {
    EXPECT_EQ(rig.ex.force(w), expected[w % 6]);
    sum += rig.ex.force(w);
  }
  EXPECT_EQ(sum, Vec3::Zero());  // no net momentum over a cycle
  // An axis at zero amplitude leaves the cycle: +x, -x, +z, -z.
  ExcitationConfig c = rig.ex.config();
  c.force_n = Vec3(50.0, 0.0, 200.0);
  rig.ex.configure(c);
  EXPECT_EQ(rig.ex.force(0), Vec3(50, 0, 0));
  EXPECT_EQ(rig.ex.force(1), Vec3(-50, 0, 0));
  EXPECT_EQ(rig.ex.force(2), Vec3(0, 0, 200));
  EXPECT_EQ(rig.ex.force(3), Vec3(0, 0, -200));
  EXPECT_EQ(rig.ex.force(4), Vec3(50, 0, 0));
}

TEST(IdentificationExcitation, StaysOffUntilTheBasisIsReadyAndStopsWhenROrTimeIsDone) {
  Rig rig;
  Vec8 u = Vec8::Zero();
  EXPECT_FALSE(rig.ex.wanted(1.0, 3, 0.0));  // basis not computed yet
  const ExcitationStatus s0 =
      rig.ex.apply(rig.ex.force(0), Vec8::Constant(-200), Vec8::Constant(200), 0.1, u);
  EXPECT_FALSE(s0.active);
  EXPECT_EQ(u, Vec8::Zero());
  rig.ready();
  EXPECT_TRUE(rig.ex.wanted(1.0, 3, 0.0));
  EXPECT_TRUE(rig.ex.wanted(0.004, 1, 0.0));   // a direction still unobservable
  EXPECT_TRUE(rig.ex.wanted(0.006, 0, 0.0));   // above the stop sigma
  EXPECT_FALSE(rig.ex.wanted(0.004, 0, 0.0));  // known well enough
  // The start delay: not before start_after_s of identification.
  {
    ExcitationConfig c = rig.ex.config();
    c.start_after_s = 60.0;
    rig.ex.configure(c);
    EXPECT_FALSE(rig.ex.wanted(1.0, 3, 40.0));
    EXPECT_TRUE(rig.ex.wanted(1.0, 3, 60.0));
    c.start_after_s = 0.0;
    rig.ex.configure(c);
  }
  // The duration cap.
  for (int k = 0; k < 6000; ++k) {
    u.setZero();
    rig.ex.apply(rig.ex.force(0), Vec8::Constant(-200), Vec8::Constant(200), 0.1, u);
  }
  EXPECT_FALSE(rig.ex.wanted(1.0, 3, 0.0));
  rig.ex.restart();
  EXPECT_TRUE(rig.ex.wanted(1.0, 3, 0.0));
  // A new model switches it off until its basis is ready again.
  rig.ex.set_model(torque_matrix(rig.rcs, rig.r_hat + Vec3(0.1, 0, 0)), rig.rcs);
  EXPECT_FALSE(rig.ex.wanted(1.0, 3, 0.0));
}

// The study's saturating allocation: Eq. (53) rescaled so that the peak channel sits at u_max.
// The excitation never leaves the box, keeps the torque, makes gamma F; the channel at its bound
// is taken out of the excitation (X4), so gamma stays large where z = 0 would have to give 0.
TEST(IdentificationExcitation, KeepsTheChannelBoundsWhenTheAllocationSaturates) {
  Rig rig(150.0);
  rig.ready();
  const Mat38 b = torque_matrix(rig.rcs, rig.r_hat);
  const Mat83 pinv = b.transpose() * (b * b.transpose()).inverse();
  std::mt19937 gen(18);
  std::normal_distribution<double> n(0.0, 1.0);
  const double u_max = 200.0;
  int naive_zero = 0, rederived_zero = 0, blocked = 0;
  double gamma_sum = 0.0;
  const int draws = 2000;
  for (int d = 0; d < draws; ++d) {
    // Half the draws with per-channel limits as a degraded thruster gives them (asymmetric box).
    Vec8 lo = Vec8::Constant(-u_max), hi = Vec8::Constant(u_max);
    if (d % 2 == 1) {
      lo(d % 8) = -0.5 * u_max;
      hi((d / 2) % 8) = 0.7 * u_max;
    }
    Vec8 u0 = pinv * Vec3(n(gen), n(gen), n(gen)) * 3000.0;
    double scale = 1.0;
    for (int i = 0; i < kChannels; ++i) {
      if (u0(i) > hi(i)) scale = std::min(scale, hi(i) / u0(i));
      if (u0(i) < lo(i)) scale = std::min(scale, lo(i) / u0(i));
    }
    u0 *= scale;
    const Vec3 f = rig.ex.force(static_cast<std::uint32_t>(d));
    // z = 0 (no re-derivation): the largest fraction of N F that fits.
    const Vec8 du0 = rig.ex.force_map() * f;
    double g0 = 1.0;
    for (int i = 0; i < kChannels; ++i) {
      if (du0(i) > 0.0) g0 = std::min(g0, std::max(0.0, hi(i) - u0(i)) / du0(i));
      if (du0(i) < 0.0) g0 = std::min(g0, std::min(0.0, lo(i) - u0(i)) / du0(i));
    }
    naive_zero += g0 < 1e-9 ? 1 : 0;
    Vec8 u = u0;
    const ExcitationStatus s = rig.ex.apply(f, lo, hi, 0.1, u);
    for (int i = 0; i < kChannels; ++i) {
      ASSERT_LE(u(i), hi(i)) << "draw " << d;
      ASSERT_GE(u(i), lo(i)) << "draw " << d;
    }
    EXPECT_LT(torque_of(rig.rcs, rig.r_hat, u - u0).norm(), 1e-8) << "draw " << d;
    EXPECT_LT((force_of(rig.rcs, u - u0) - s.gamma * f).norm(), 1e-8) << "draw " << d;
    EXPECT_GE(s.gamma, g0 - 1e-12) << "draw " << d;  // never less than without re-derivation
    rederived_zero += s.gamma < 1e-9 ? 1 : 0;
    blocked += s.blocked > 0 ? 1 : 0;
    gamma_sum += s.gamma;
  }
  RecordProperty("naive_zero", naive_zero);
  RecordProperty("rederived_zero", rederived_zero);
  RecordProperty("mean_gamma_x1000", static_cast<int>(1000.0 * gamma_sum / draws));
  EXPECT_GT(blocked, draws / 4);                // saturation is common in these draws
  EXPECT_GT(naive_zero, draws / 5);             // and z = 0 often cannot excite at all
  EXPECT_LT(rederived_zero, naive_zero / 4);    // the re-derived term mostly can
}

// (X8) The inertia phase. Independent truth: the minimum-norm channel forces that make the law's
// torque plus the couple with no net force, from a complete orthogonal decomposition of the 6x8
// system [B; E] u = [tau; 0] written from the layout here (torque_of, force_of), not from N or C.
TEST(IdentificationExcitation, InertiaPhaseNullsTheNetForceAndAddsTheCoupleOnTheModel) {
  Rig rig;
  ExcitationConfig c = rig.ex.config();
  c.inertia_torque_nm = Vec3(100.0, 100.0, 100.0);
  rig.ex.configure(c);
  rig.ready();
  Eigen::Matrix<double, 6, kChannels> m;
  for (int ch = 0; ch < kChannels; ++ch) {
    Vec8 e = Vec8::Zero();
    e(ch) = 1.0;
    m.block<3, 1>(0, ch) = torque_of(rig.rcs, rig.r_hat, e);
    m.block<3, 1>(3, ch) = force_of(rig.rcs, e);
  }
  const Eigen::CompleteOrthogonalDecomposition<Eigen::Matrix<double, 6, kChannels>> cod(m);
  const Mat38 b = torque_matrix(rig.rcs, rig.r_hat);
  const Mat83 pinv = b.transpose() * (b * b.transpose()).inverse();  // Eq. (53)
  const Vec8 lo = Vec8::Constant(-1000.0), hi = Vec8::Constant(1000.0);
  std::mt19937 gen(8);
  std::normal_distribution<double> n(0.0, 1.0);
  for (int d = 0; d < 200; ++d) {
    const Vec3 law(300.0 * n(gen), 300.0 * n(gen), 300.0 * n(gen));
    const Vec3 tau = rig.ex.inertia_torque(static_cast<std::uint32_t>(d));
    // The pseudoinverse's allocation: the result is the minimum-norm force-free one.
    const Vec8 u0 = pinv * law;
    Vec8 u = u0;
    const ExcitationStatus s = rig.ex.apply_inertia(tau, lo, hi, 0.1, u);
    ASSERT_TRUE(s.active && s.inertia);
    ASSERT_EQ(s.gamma, 1.0);
    EXPECT_LT((s.force - force_of(rig.rcs, u0)).norm(), 1e-9);  // the force it nulled
    Eigen::Matrix<double, 6, 1> y;
    y << law + tau, Vec3::Zero();
    const Vec8 expected = cod.solve(y);
    EXPECT_LT((u - expected).cwiseAbs().maxCoeff(), 1e-9 * (1.0 + expected.cwiseAbs().maxCoeff())) << "draw " << d;
    EXPECT_LT(force_of(rig.rcs, u).norm(), 1e-9) << "draw " << d;
    EXPECT_LT((torque_of(rig.rcs, rig.r_hat, u) - law - tau).norm(), 1e-8) << "draw " << d;
    // Any allocation (here one with a null-space component, as L1's are): the force nulled and
    // the torque plus tau all the same.
    Vec8 v0 = u0 + 40.0 * rig.ex.kernel().col(d % 2) + rig.ex.force_map() * Vec3(n(gen), n(gen), n(gen)) * 50.0;
    Vec8 v = v0;
    rig.ex.apply_inertia(tau, lo, hi, 0.1, v);
    EXPECT_LT(force_of(rig.rcs, v).norm(), 1e-9) << "draw " << d;
    EXPECT_LT((torque_of(rig.rcs, rig.r_hat, v - v0) - tau).norm(), 1e-8) << "draw " << d;
  }
  EXPECT_NEAR(rig.ex.inertia_elapsed(), 40.0, 1e-9);
  EXPECT_EQ(rig.ex.elapsed(), 0.0);  // the force phase's budget is its own
  // The cycle: +x, -x, +y, -y, +z, -z at the configured amplitude, no net momentum per cycle.
  const Vec3 expected[6] = {Vec3(100, 0, 0), Vec3(-100, 0, 0), Vec3(0, 100, 0),
                            Vec3(0, -100, 0), Vec3(0, 0, 100), Vec3(0, 0, -100)};
  for (std::uint32_t w = 0; w < 12; ++w) EXPECT_EQ(rig.ex.inertia_torque(w), expected[w % 6]);
}

// (X8) In the box: a saturated allocation keeps every channel within its bounds, and what is added
// is a fraction gamma of the whole move (the couple and the nulling together), torque and force.
TEST(IdentificationExcitation, InertiaPhaseKeepsTheChannelBounds) {
  Rig rig;
  ExcitationConfig c = rig.ex.config();
  c.inertia_torque_nm = Vec3(300.0, 300.0, 300.0);
  rig.ex.configure(c);
  rig.ready();
  const Mat38 b = torque_matrix(rig.rcs, rig.r_hat);
  const Mat83 pinv = b.transpose() * (b * b.transpose()).inverse();
  std::mt19937 gen(81);
  std::normal_distribution<double> n(0.0, 1.0);
  int partial = 0;
  for (int d = 0; d < 2000; ++d) {
    Vec8 lo = Vec8::Constant(-200.0), hi = Vec8::Constant(200.0);
    if (d % 2 == 1) lo(d % 8) = -100.0;
    Vec8 u0 = pinv * Vec3(n(gen), n(gen), n(gen)) * 2000.0;
    double scale = 1.0;
    for (int i = 0; i < kChannels; ++i) {
      if (u0(i) > hi(i)) scale = std::min(scale, hi(i) / u0(i));
      if (u0(i) < lo(i)) scale = std::min(scale, lo(i) / u0(i));
    }
    u0 *= scale;
    const Vec3 tau = rig.ex.inertia_torque(static_cast<std::uint32_t>(d));
    Vec8 u = u0;
    const ExcitationStatus s = rig.ex.apply_inertia(tau, lo, hi, 0.1, u);
    for (int i = 0; i < kChannels; ++i) {
      ASSERT_LE(u(i), hi(i)) << "draw " << d;
      ASSERT_GE(u(i), lo(i)) << "draw " << d;
    }
    EXPECT_LT((torque_of(rig.rcs, rig.r_hat, u - u0) - s.gamma * tau).norm(), 1e-7) << "draw " << d;
    EXPECT_LT((force_of(rig.rcs, u) - (1.0 - s.gamma) * force_of(rig.rcs, u0)).norm(), 1e-7) << "draw " << d;
    partial += s.gamma < 1.0 ? 1 : 0;
  }
  EXPECT_GT(partial, 100);  // the draws do reach the bounds
}

TEST(IdentificationExcitation, InertiaPhaseOnlyBeforeTheForcePhaseAndOnlyWhenConfigured) {
  Rig rig;
  ExcitationConfig c = rig.ex.config();
  c.start_after_s = 60.0;
  rig.ex.configure(c);
  EXPECT_FALSE(rig.ex.inertia_wanted(0.0));  // basis not ready
  rig.ready();
  EXPECT_FALSE(rig.ex.inertia_wanted(0.0));  // no couple configured: no inertia phase
  EXPECT_EQ(rig.ex.inertia_torque(0), Vec3::Zero());
  c.inertia_torque_nm = Vec3(0.0, 50.0, 0.0);
  rig.ex.configure(c);
  EXPECT_TRUE(rig.ex.inertia_wanted(0.0));
  EXPECT_TRUE(rig.ex.inertia_wanted(40.0));
  EXPECT_FALSE(rig.ex.inertia_wanted(60.0));  // the force phase's turn
  EXPECT_TRUE(rig.ex.wanted(1.0, 3, 60.0));
  EXPECT_FALSE(rig.ex.wanted(1.0, 3, 40.0));
  EXPECT_EQ(rig.ex.inertia_torque(0), Vec3(0, 50, 0));  // an axis at 0 leaves the cycle
  EXPECT_EQ(rig.ex.inertia_torque(1), Vec3(0, -50, 0));
  EXPECT_EQ(rig.ex.inertia_torque(2), Vec3(0, 50, 0));
  c.enabled = false;
  rig.ex.configure(c);
  EXPECT_FALSE(rig.ex.inertia_wanted(0.0));
  // A new model: off until its basis is ready.
  c.enabled = true;
  rig.ex.configure(c);
  rig.ex.set_model(torque_matrix(rig.rcs, rig.r_hat + Vec3(0.1, 0, 0)), rig.rcs);
  EXPECT_FALSE(rig.ex.inertia_wanted(0.0));
  Vec8 u = Vec8::Constant(5.0);
  EXPECT_FALSE(rig.ex.apply_inertia(Vec3(0, 50, 0), Vec8::Constant(-200), Vec8::Constant(200), 0.1, u).active);
  EXPECT_EQ(u, Vec8::Constant(5.0));
}

TEST(IdentificationExcitation, ConfigValidationNamesTheField) {
  ExcitationConfig c;
  EXPECT_TRUE(validate(c).ok);
  c.force_n = Vec3::Zero();
  EXPECT_STREQ(validate(c).field, "identification.excitation.force_n");
  c = ExcitationConfig{};
  c.duration_s = -1.0;
  EXPECT_STREQ(validate(c).field, "identification.excitation.duration_s");
  c = ExcitationConfig{};
  c.r_sigma_stop_m = std::nan("");
  EXPECT_STREQ(validate(c).field, "identification.excitation.r_sigma_stop_m");
  c = ExcitationConfig{};
  c.start_after_s = -1.0;
  EXPECT_STREQ(validate(c).field, "identification.excitation.start_after_s");
  c = ExcitationConfig{};
  c.r_sigma_target_m = -0.01;
  EXPECT_STREQ(validate(c).field, "identification.excitation.r_sigma_target_m");
  c = ExcitationConfig{};
  c.inertia_torque_nm = Vec3(10.0, -1.0, 0.0);
  EXPECT_STREQ(validate(c).field, "identification.excitation.inertia_torque_nm");
  c.inertia_torque_nm = Vec3(10.0, std::nan(""), 0.0);
  EXPECT_STREQ(validate(c).field, "identification.excitation.inertia_torque_nm");
}

// (X7) Sized to the window noise. Independent truth: the information on r summed window by window
// from (X1), I_win = (T^2 / 4 rho) (|F|^2 I - F F'), over the D/T windows the cycle flies with the
// scaled forces; its inverse's largest diagonal is the worst 1 sigma, which the sizing must put at
// the target (or below it, at full amplitude, when the noise asks for more than force_n).
double worst_sigma_from_windows(const IdentificationExcitation& ex, double rho, double t_win,
                                double duration) {
  Mat3 info = Mat3::Zero();
  const int windows = static_cast<int>(std::lround(duration / t_win));
  for (int w = 0; w < windows; ++w) {
    const Vec3 f = ex.force(static_cast<std::uint32_t>(w));
    info += (t_win * t_win / (4.0 * rho)) * (f.squaredNorm() * Mat3::Identity() - f * f.transpose());
  }
  return std::sqrt(info.inverse().diagonal().maxCoeff());
}

TEST(IdentificationExcitation, SizedToTheWindowNoiseTheCycleReachesTheTargetSigma) {
  // 24 windows: whole cycles of six and of four directions.
  const double t_win = 20.0, duration = 480.0, target = 0.01;
  for (const Vec3& force : {Vec3(100.0, 100.0, 400.0), Vec3(100.0, 100.0, 0.0), Vec3(50.0, 80.0, 20.0)}) {
    ExcitationConfig c;
    c.enabled = true;
    c.force_n = force;
    c.duration_s = duration;
    c.r_sigma_target_m = target;
    IdentificationExcitation ex;
    ex.configure(c);
    // The case-1 disturbance's window noise (sqrt(rho) ~ 4.3 N m s), then case-6 noise (152).
    for (const double rho : {4.3 * 4.3, 30.0 * 30.0, 152.0 * 152.0}) {
      ex.size_to_window_noise(rho, t_win);
      const double s = ex.amplitude_scale();
      ASSERT_GT(s, 0.0);
      ASSERT_LE(s, 1.0);
      // The force flown is force_n times the scale, direction by direction.
      EXPECT_NEAR(ex.force(0)(0), s * force(0), 1e-9 * force(0));  // +x first (X3)
      EXPECT_NEAR(ex.force(1)(0), -s * force(0), 1e-9 * force(0));
      const double sigma = worst_sigma_from_windows(ex, rho, t_win, duration);
      if (s < 1.0) {
        EXPECT_NEAR(sigma, target, 1e-9) << "force " << force.transpose() << " rho " << rho;
      } else {
        EXPECT_GE(sigma, target * (1.0 - 1e-12)) << "full amplitude only when it is not enough";
      }
    }
    // With gnc.yaml's amplitudes quiet sensors need a fraction of the force; the case-6 window
    // noise needs all of it.
    if (force == Vec3(100.0, 100.0, 400.0)) {
      ex.size_to_window_noise(4.3 * 4.3, t_win);
      EXPECT_LT(ex.amplitude_scale(), 0.2);
    }
    ex.size_to_window_noise(152.0 * 152.0, 60.0);
    EXPECT_EQ(ex.amplitude_scale(), 1.0) << force.transpose();
    // No noise figure yet (before the first window), or nonsense: the amplitude as given.
    for (const double bad : {0.0, -1.0, std::nan(""), HUGE_VAL}) {
      ex.size_to_window_noise(bad, t_win);
      EXPECT_EQ(ex.amplitude_scale(), 1.0) << bad;
    }
  }
  // Not sized (target 0): the amplitude as given, whatever the noise.
  ExcitationConfig c;
  c.enabled = true;
  IdentificationExcitation ex;
  ex.configure(c);
  ex.size_to_window_noise(1.0, t_win);
  EXPECT_EQ(ex.amplitude_scale(), 1.0);
  EXPECT_EQ(ex.force(0), Vec3(c.force_n(0), 0.0, 0.0));
}

}  // namespace
}  // namespace rocksteady::gnc
