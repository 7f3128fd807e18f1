// Multiplicative extended Kalman filter (MEKF) on star-tracker attitude and gyro rate, with gyro
// bias (design note: gnc/estimation/README.md, §M). Six error states: the small body-frame attitude
// error dtheta (beta_true = beta_hat (x) [dtheta/2; 1]) and the gyro bias error db.
//
// The gyro drives the attitude propagation ("model replacement", Markley & Crassidis 2014 §6.2):
// the rate is not a state, omega_hat = omega_gyro - b_hat. Why not a dynamic model with J_hat and
// the commanded torque: in the study's cases 4 and 7 J_hat is off by up to 1e7 kg m^2, which makes
// the predicted angular acceleration wrong by ~2e-4 rad/s^2 (issue 18); a filter that trusts that
// model is biased exactly when it matters, whereas the gyro is measured every tick at 10 Hz. The
// model uncertainty enters as extra attitude process noise (model_sigma), which also covers what
// the trapezoid rate (mean of the two gyro samples bounding a tick) leaves out.
//
// Conventions (gnc/math/rotation.hpp): quaternions scalar last, R = C_IB, a (x) b <-> R(a) R(b);
// the output MRP is in the |q| <= 1 set, same as the SPEC §6 filter (StateFilter).
// Flight code: fixed-size Eigen, no heap, no exceptions, no I/O.
#pragma once

#include <cstdint>

#include "gnc/types.hpp"

namespace rocksteady::gnc {

using Mat6 = Eigen::Matrix<double, 6, 6>;

struct MekfConfig {
  double dt{0.1};  // s, tick (= sensor) period
  // Gyro model (Farrenkopf 1978): omega_gyro = omega + b + eta_v, b_dot = eta_u.
  // sigma_v: angle random walk, rad/sqrt(s) (per-sample sigma sqrt(sigma_v^2 / T_s), so
  // sigma_v^2 = P(dw) of SPEC §5); sigma_u: bias random walk, rad/s^(3/2).
  double gyro_arw{1e-6};
  double gyro_bias_rw{1e-9};
  // Star tracker: per-axis attitude noise, rad (1 sigma). SPEC §5 gives MRP noise sigma_q per axis;
  // for small angles dtheta = 4 dq, so sigma_theta = 4 sqrt(P(dq) / T_s).
  double star_sigma{1e-4};
  // Model uncertainty (rad/sqrt(s)): extra attitude process noise for what the gyro-driven
  // propagation does not model (rate curvature within a tick, alignment, timing).
  double model_sigma{0.0};
  // Initial 1 sigma: attitude (rad, after the first star sample), bias (rad/s).
  double init_attitude_sigma{1e-2};
  double init_bias_sigma{1e-3};
  Vec3 init_bias{Vec3::Zero()};  // rad/s
  // Measurement gate: squared Mahalanobis distance of the star-tracker innovation (3 dof).
  // 16.27 = chi-square(3) at 0.999.
  double gate_chi2{16.27};
  // After this many consecutive gated samples the filter re-initialises its attitude from the
  // star tracker (a persistent jump is not an outlier).
  int max_consecutive_rejects{50};
  // Sample acceptance (as the SPEC §6 filter): rate above this, or quaternion norm off by more.
  double gyro_max_rate{1.0};
  double quat_norm_tolerance{0.01};
  // (M8) Rate output stage, rad/s. 0: omega_hat = omega_gyro - b_hat (the gyro's white noise
  // unfiltered). > 0: omega_hat is predicted through Eq. (2) with the model J_hat
  // (set_rate_model) and the commanded torque, then corrected towards omega_gyro - b_hat with the
  // gain 1 - exp(-rate_cutoff dt): the SPEC §6 filter's rate step on the bias-corrected gyro.
  double rate_cutoff{0.0};
};

struct MekfConfigCheck {
  bool ok{true};
  const char* field{""};
  const char* reason{""};
};

// The first bad field and why, or ok.
MekfConfigCheck validate(const MekfConfig& c);

// One tick's sensor data, as the sensors deliver it.
struct MekfInput {
  double t{0.0};  // sample time, s: a star sample whose time has not advanced is not re-used
  Vec3 gyro_rate{Vec3::Zero()};  // rad/s, F_B
  bool gyro_valid{false};
  Vec4 star_quat{0.0, 0.0, 0.0, 1.0};  // attitude of F_B in F_I, scalar last
  bool star_valid{false};
  Vec3 torque{Vec3::Zero()};  // N m, commanded over the previous tick (the rate stage, M8)
};

struct MekfCounters {
  std::uint32_t updates{0};         // star-tracker samples used
  std::uint32_t gated{0};           // star-tracker samples rejected by the chi-square gate
  std::uint32_t rejected_input{0};  // samples rejected by the acceptance checks
  std::uint32_t reinitialised{0};   // re-initialisations after consecutive gating
};

class Mekf {
 public:
  // Takes a validated config (call validate() first; configure() does not re-check). A filter
  // that is running keeps its estimate and covariance; call reset() to forget them.
  void configure(const MekfConfig& c);
  // The model of the rate stage (M8): J_hat, Eq. (1) with the estimates. Keeps the estimate.
  void set_rate_model(const Mat3& j_hat);
  // Forget the estimate: the next valid gyro + star pair initialises it.
  void reset();
  // One tick: propagate over dt with the mean of the previous and this tick's gyro samples, then
  // the star-tracker update (a star sample whose time has not advanced is not used twice).
  void update(const MekfInput& in);

  bool initialised() const { return initialised_; }
  const Vec4& quaternion() const { return beta_; }  // beta_hat, scalar last
  Vec3 q() const;                                   // MRP, |q| <= 1 set
  // omega_hat, rad/s: omega_gyro - b_hat, or the rate stage's estimate (M8) when rate_cutoff > 0.
  const Vec3& omega() const { return omega_; }
  const Vec3& bias() const { return bias_; }        // b_hat, rad/s
  const Mat6& covariance() const { return p_; }     // [dtheta; db]
  Vec3 attitude_sigma() const;                      // rad, 1 sigma per body axis
  Vec3 bias_sigma() const;                          // rad/s
  // 1 sigma of omega_hat: the gyro's white noise per sample plus the bias uncertainty.
  Vec3 omega_sigma() const;
  // Last star-tracker innovation and its squared Mahalanobis distance.
  const Vec3& innovation() const { return innovation_; }
  double innovation_chi2() const { return innovation_chi2_; }
  const MekfCounters& counters() const { return counters_; }

  // Error-state transition and discrete process noise over dt at rate omega (exposed for tests).
  static Mat6 transition(const Vec3& omega, double dt);
  Mat6 process_noise() const { return q_; }

 private:
  void initialise(const Vec4& beta, const Vec3& gyro);
  void propagate(const Vec3& gyro_mean);
  void star_update(const Vec4& beta_meas);

  MekfConfig c_{};
  Mat6 q_{Mat6::Zero()};
  double r_var_{0.0};
  bool initialised_{false};
  Vec4 beta_{0.0, 0.0, 0.0, 1.0};
  Vec3 bias_{Vec3::Zero()};
  Vec3 omega_{Vec3::Zero()};
  Vec3 last_gyro_{Vec3::Zero()};
  Mat3 j_hat_{Mat3::Identity()};  // the rate stage's model (M8)
  Mat3 j_hat_inv_{Mat3::Identity()};
  double rate_gain_{1.0};
  Mat6 p_{Mat6::Identity()};
  double last_star_t_{0.0};
  int consecutive_rejects_{0};
  Vec3 innovation_{Vec3::Zero()};
  double innovation_chi2_{0.0};
  MekfCounters counters_{};
};

}  // namespace rocksteady::gnc
