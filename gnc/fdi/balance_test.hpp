// (F61) Channel balance test: a comparison of a channel's two halves that needs no model of the
// body. A channel is an opposed pair: its "+" and "-" thrusters sit at the same point p and push
// along +d and -d. Fired one after the other with the same impulse F, they put rate changes
//   g+ F = k+ J^-1 (p + r) x d F   and   g- F = -k- J^-1 (p + r) x d F
// on the body (HOLD: the gyroscopic term is negligible). J and r, which the identification may
// not know (a fault present while it identified them goes into J and r, gnc/fdi/README.md F59),
// cancel from the comparison: g+ + g- = (k+ - k-) J^-1 (p + r) x d, zero for a healthy channel,
// and along g+ - g- the two halves' responses s+ = g+.u and s- = -g-.u have the ratio k- / k+.
//
// One test of channel c flies, from its start sample, while the body drifts free (Gnc): q quiet
// samples (sized by the gyro's noise, at most quiet_ticks), the "+" half at force_n for n_f
// samples, q quiet, the "-" half at force_n for n_f, q quiet. n_f is sized so that each firing
// turns the rate by about kick_rad_s: on the detector's model for a channel's first test, then on
// its measured response; with a healthy channel the second firing undoes the first. Every sample's residual (the rate less its start
// and less the motion the model predicts from every other jet's commanded thrust) is fitted with
// an offset and the two halves' commanded impulses (I+, I-) as regressors, per axis:
//   r_j = o + g+ I+(j) + g- I-(j) + e_j.                                              (F61a)
// The information on (g+, g-) after the offset is eliminated is summed over a channel's tests
// in a round, so an inconclusive test is followed by one that adds to it. Verdicts (F61b):
//   - chi2 = |g+ + g-|^2 / var(g+ + g-) below chi2_bound: the channel is balanced (verified);
//   - else the weaker half w, its response ratio rho = s_w / s_s and loss 1 - rho: a loss below
//     min_loss is a verified channel too; a weaker half within total_sigmas of its own 1 sigma
//     of zero, with rho below kMaxTotalRatio, is stuck off; one at least partial_sigmas above zero
//     is degraded with factor rho; anything between, or a stronger half less than min_snr of its
//     1 sigma, is inconclusive (tested again, up to max_tests).
// (F61c) The other jets' motion is the model's prediction, with its relative error: its effect
// on the fit (the same sums with the prediction in place of the residual, times the error) is a
// bias that every margin must clear, and a start gate keeps the test off a busy flight.
// (F61e) A test whose fit leaves more than its noise (the residual's chi-square past its degrees
// of freedom by 5 of their sigma: something else acted on the body) is inconclusive, whatever
// its responses say.
// Flight code: fixed-size, no heap, no exceptions, no I/O.
#pragma once

#include <array>
#include <cstdint>

#include "gnc/io.hpp"
#include "gnc/types.hpp"

namespace rocksteady::gnc {

struct BalanceTestParams {
  double kick_rad_s{0.0};      // each firing's rate on the body, on the model (0: no tests)
  double force_n{100.0};       // the halves' force (at most u_max)
  int quiet_ticks{100};        // at most this many samples before, between and after the firings
  int max_fire_ticks{200};     // at most this many samples per firing
  double interval_s{20000.0};  // a round of every channel at most this often
  double chi2_bound{30.66};    // chi-square(3) at 1 - 1e-6: a channel out of balance
  double min_snr{10.0};        // a verdict needs the stronger half this many of its 1 sigma
  double total_sigmas{2.0};    // a weaker half within this of zero is stuck off ...
  double partial_sigmas{3.0};  // ... at least this far from it, degraded
  double min_loss{0.1};        // a smaller loss is a balanced channel
  int max_tests{6};            // tests of one channel per round
};

// What the test decided for a channel (F61b).
enum class BalanceOutcome : std::uint8_t { kNone = 0, kBalanced, kFault, kInconclusive };

struct BalanceVerdict {
  BalanceOutcome outcome{BalanceOutcome::kNone};
  int channel{-1};
  int thruster{-1};                     // kFault: the weaker half (2c "+", 2c + 1 "-")
  FaultKind kind{FaultKind::kNone};     // kStuckOff or kDegraded
  double factor{0.0};                   // kDegraded: rho, the weaker half's strength ratio
  double factor_sigma{0.0};
  double chi2{0.0};                     // |g+ + g-|^2 / var
  double ratio{1.0};                    // rho
};

class ChannelBalanceTest {
 public:
  static constexpr double kMaxTotalRatio = 0.25;  // a stuck-off half: rho below this too
  // (F61c) The model's error enters as a bias, bounded at this many of its 1 sigma: a verdict
  // needs every margin beyond it, and a test whose bias could hide half of min_loss is
  // inconclusive (the flight was busy: its other jets' motion is the model's, with its error).
  static constexpr double kBiasSigmas = 3.0;
  // (F61d) A test whose residual rate leaves kAbortKicks kicks (plus 5 sigma of the gyro; 5e-4 rad/s,
  // the HOLD bound of gnc.yaml's omega_switch, with its kick; the model may size a first kick a few
  // times off) is
  // dropped on that sample: something else moves the body (a jet stuck on), and the flight takes
  // control again at once.
  static constexpr double kAbortKicks = 10.0;

  void configure(const BalanceTestParams& p, double dt, double u_max, double gyro_sigma,
                 double disturbance_sigma);
  void reset();  // tests and rounds (the detector's status keeps the counts)
  bool enabled() const { return p_.kick_rad_s > 0.0; }
  bool active() const { return channel_ >= 0; }
  // The test's samples are still coming: the body drifts free under it (its fit may wait).
  bool flying() const { return channel_ >= 0 && !pending_; }
  int channel() const { return channel_; }
  // The signed force the test adds to its channel over the next interval (0 outside firings).
  double command() const { return command_; }
  // A round is due at window count `now_s` (s of flight), and channel c may be tested
  // (usable(c): both halves unlatched, pod valve open). Starts the next test on start sample
  // omega; b_plus_norm is the model's rate per N s of the channel's "+" half (sizes n_f),
  // j_inv_norm and model_rel the model's for the noise of its prediction. False: nothing started.
  bool start(double now_s, std::uint8_t usable, const Vec3& omega,
             const std::array<double, kChannels>& b_plus_norm, double j_inv_norm,
             double model_rel);
  // One sample of the test under way: the interval that ends now, with the rate change the model
  // predicts from every other jet (and the gyroscopic term), and the forces commanded on the
  // channel's two halves over it (N). Returns a verdict when the test's last sample is in.
  // other_thrust: the part of predicted_other that the other jets' thrust makes (its norm counts
  // towards a busy test, F61c).
  BalanceVerdict sample(const Vec3& omega, const Vec3& predicted_other, const Vec3& other_thrust,
                        double f_plus, double f_minus);
  // (F61d) The last sample left the test's bound: the test was dropped (counted as aborted).
  bool dropped_on_motion() const { return dropped_; }
  // The last sample is in: the fit waits for finish(), which the detector runs on an update that
  // carries none of its own heavy steps (the Cortex-M7 tick budget).
  bool evaluate_pending() const { return pending_; }
  BalanceVerdict finish();
  void abort();  // a gap, a closed valve, a latched fault or the body's motion: the test is dropped
  // (F61c) A test may start while the other jets move the body at other_rate (rad/s^2, on the
  // model).
  bool quiet_enough(double other_rate) const;
  int fire_ticks() const { return n_fire_; }
  int test_ticks() const { return 3 * quiet_ + 2 * n_fire_; }
  int quiet_ticks() const { return quiet_; }
  // (F61a) per channel this round: the summed information on (g+, g-) and its vector (exposed
  // for tests).
  struct ChannelInfo {
    double a00{0.0}, a01{0.0}, a11{0.0};
    Vec3 y0{Vec3::Zero()}, y1{Vec3::Zero()};
    // (F61c) the same with the other jets' predicted motion, times the model's relative error, in
    // place of the residual: the fit's sensitivity to the model's error.
    Vec3 yb0{Vec3::Zero()}, yb1{Vec3::Zero()};
    int tests{0};
    bool done{false};
    // The stronger half's measured response (rad/s per N s), once it stands 3 of its 1 sigma out:
    // it sizes the channel's next test in place of the model's (which may be far off).
    double response{0.0};
  };
  const ChannelInfo& info(int c) const { return info_[static_cast<std::size_t>(c)]; }

 private:
  BalanceVerdict evaluate();
  void next_command();
  BalanceTestParams p_{};
  double dt_{0.1};
  double u_max_{200.0};
  double gyro_var_{1e-14};
  double dist_sigma_{0.0};
  int channel_{-1};
  bool pending_{false};
  bool dropped_{false};
  int n_fire_{1};
  int quiet_{100};  // the quiet segments' samples, sized by the gyro's noise
  int k_{0};  // samples in so far
  double command_{0.0};
  double j_inv_norm_{0.0};
  double model_rel_{0.0};
  Vec3 omega_start_{Vec3::Zero()};
  Vec3 predicted_{Vec3::Zero()};
  double motion_{0.0};
  double i_plus_{0.0}, i_minus_{0.0};
  double n_{0.0}, s1_{0.0}, s2_{0.0}, s11_{0.0}, s22_{0.0}, s12_{0.0};
  Vec3 sr_{Vec3::Zero()}, s1r_{Vec3::Zero()}, s2r_{Vec3::Zero()};
  Vec3 sp_{Vec3::Zero()}, s1p_{Vec3::Zero()}, s2p_{Vec3::Zero()};
  double srr_{0.0};
  std::array<ChannelInfo, kChannels> info_{};
  bool round_open_{false};
  double round_end_s_{-1e300};
};

}  // namespace rocksteady::gnc
