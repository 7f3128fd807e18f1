// On-line identification of the body the flight software flies: J_tot (6 unique entries),
// r_SO/BCM (3) and a strength factor k_i per physical thruster (16), by three concurrent recursive
// least-squares estimators, one per group, each using the others' latest estimates (Wilson, Lages &
// Mah 2002). Design note with the equations and the observability analysis: README.md beside this
// file (§I). Equation tags (I1)... refer to it.
//
// Data: the body rate (gyro or estimate) each tick and the channel forces actually commanded over
// the previous tick. The model is Eq. (2) integrated against a triangular modulating window w(t)
// over windows of length T, so no differentiated gyro is needed (I2):
//   -∫ w' J omega dt + ∫ w omega x (J omega) dt = ∫ w tau dt,
//   tau = sum_i k_i (p_i + r) x e_i F_i                       (SPEC §4, per physical thruster)
// The per-tick work is accumulation; at a window's end the data are latched and the groups are
// updated on the following ticks in small steps (joint: gain in two halves, apply in two halves,
// scale anchor, report; concurrent: J, r, k, report), so no tick does more than one step.
//
// Flight code: fixed-size Eigen, no heap, no exceptions, no I/O.
#pragma once

#include <array>
#include <cstdint>

#include "gnc/estimation/excitation.hpp"
#include "gnc/model/rcs.hpp"
#include "gnc/types.hpp"

namespace rocksteady::gnc {

using Mat16 = Eigen::Matrix<double, kThrusters, kThrusters>;
using Mat6 = Eigen::Matrix<double, 6, 6>;
using Mat316 = Eigen::Matrix<double, 3, kThrusters>;

// Inertia parameters a = [Jxx Jyy Jzz Jxy Jxz Jyz] and back (I1).
Vec6 inertia_params(const Mat3& j);
Mat3 inertia_matrix(const Vec6& a);
// L(v) with L(v) a = J v (I1).
Mat36 inertia_regressor(const Vec3& v);
// (I20) Covariance of the cross product x = a x b of independent zero-mean vectors with
// covariances A and B (symmetric), in closed form:
//   E[x x'] = (tr A tr B - tr(AB)) I - tr(A) B - tr(B) A + AB + BA.
Mat3 cross_product_covariance(const Mat3& a, const Mat3& b);
// (I20) B_k P_a, k = 0..2, with B_k = S(m) L(e_k) + S(e_k) L(m) (I17's Jacobian G(a) b = sum_k
// b_k B_k a); L(e_k) only selects rows, so B_k P_a costs one L(m) P_a and three S(m) products.
void bias_jacobian_times(const Vec3& m, const Mat6& p_a, Mat36 (&out)[3]);
// (I20) cov(G(da) db) = sum_kl P_b(k, l) B_k P_a B_l' for independent da ~ N(0, P_a) and
// db ~ N(0, P_b), from the B_k P_a of bias_jacobian_times.
Mat3 bilinear_bias_covariance(const Vec3& m, const Mat36 (&bpa)[3], const Mat3& p_b);
// Unit force direction e_i and position p_i (F_S, relative to SO) of physical thruster i.
Vec3 thruster_direction(const RcsLayout& l, int i);
Vec3 thruster_position(const RcsLayout& l, int i);

// How the three groups are estimated (§I.5). kConcurrent: one RLS per group, each holding the
// others at their latest estimates and counting their uncertainty as noise (Wilson, Lages & Mah
// 2002). kJoint: the same window equation linearised in all 28 parameters at once (J, r, k and
// the rate bias, I17; an extended RLS), which keeps the cross-covariances the concurrent form
// drops.
enum class IdentifierMode : std::uint8_t { kConcurrent = 0, kJoint = 1 };

// Joint state [a (6); r (3); k (16); b (3); d (3)]: b is the bias of the rate the identifier is
// given (I17), d an unknown constant body-frame torque (I22: a stuck-on thruster present while the
// model is identified). Index of each group's first parameter:
inline constexpr int kIdJ = 0;
inline constexpr int kIdR = 6;
inline constexpr int kIdK = 9;
inline constexpr int kIdB = 9 + kThrusters;
inline constexpr int kIdD = 9 + kThrusters + 3;
inline constexpr int kIdParams = 6 + 3 + kThrusters + 3 + 3;
using VecId = Eigen::Matrix<double, kIdParams, 1>;
using MatId = Eigen::Matrix<double, kIdParams, kIdParams>;

struct IdentifierConfig {
  IdentifierMode mode{IdentifierMode::kJoint};
  double dt{0.1};         // s, tick period
  double window_s{20.0};  // s, modulating-window length T (an even number of ticks)
  // (I30) The windows that close within the first early_span_s of identification are
  // early_window_s long (an even number of ticks, at most window_s): more steps while the prior is
  // far and the couples of the excitation's inertia phase (X8) cycle. 0: every window window_s.
  double early_window_s{0.0};
  double early_span_s{0.0};
  RcsLayout rcs{};        // thruster geometry (positions, directions); u_max unused
  // Priors (the table's values) and their 1 sigma.
  Mat3 j0{Mat3::Identity()};   // kg m^2
  Vec3 r0{Vec3::Zero()};       // m
  Vec16 k0{Vec16::Ones()};     // -
  double j_prior_sigma{1e7};   // kg m^2, per inertia parameter
  double r_prior_sigma{1.0};   // m, per axis
  double k_prior_sigma{0.05};  // per thruster; also anchors the common thrust scale (§I.4)
  // Noise of the window equation (I5): gyro white noise per sample (rad/s), the external
  // disturbance (N m per axis, held for disturbance_corr_s), and a floor (N m).
  double gyro_sigma{0.0};
  // Bias of the given rate, 1 sigma per axis (rad/s; the gyro's data sheet). kJoint estimates it
  // as three more parameters (I17): a bias b in omega puts -G b into the window equation, G the
  // gyroscopic term's Jacobian. 0: the rate is taken as unbiased (b held at zero).
  double gyro_bias_sigma{0.0};
  // true: b is estimated with the others; false: b is a consider parameter (Schmidt): its
  // uncertainty and cross-covariances are carried, so J, r and k are as uncertain as the bias
  // makes them, but b-hat stays at zero (the rate as given) and the linearisation point with it.
  bool gyro_bias_estimated{false};
  // Innovation gate (I18, kJoint): a window whose residual e0' S^-1 e0 exceeds gate_chi2 does
  // not fit the model with the confidence the covariance claims (an unmodelled fault, a model
  // change); it is refused and counted, estimate and covariance untouched. After
  // gate_reinflate_after refused windows in a row the model is declared changed: J, r and k go
  // back to their prior covariance (re-inflation), so the data are fitted again honestly.
  // 0: no gate.
  double gate_chi2{0.0};
  // (I20) the second-order term of the bilinear products joins the innovation covariance
  // (consistency from far priors; slower to become confident while r and k are both uncertain).
  bool second_order_noise{false};
  int gate_reinflate_after{3};
  // (I22, kJoint) An unknown constant body-frame torque d (N m) joins the window equation,
  // prior 1 sigma per axis fault_torque_sigma (the largest single-jet torque): a stuck-on thruster
  // present while the model is identified is then fitted as d instead of breaking J, r and k,
  // and d-hat with its covariance is the evidence for the 16 stuck-on hypotheses (I23), scored
  // after each window (fault_torque()). 0: no such state (d held at zero).
  double fault_torque_sigma{0.0};
  double disturbance_sigma{0.57735026918962576};
  double disturbance_corr_s{10.0};
  double torque_floor{0.1};
  // Exponential forgetting time constants per group (s); 0 = no forgetting. The strengths do not
  // forget by default: their prior is what fixes the common scale of J and k (§I.4).
  double j_forget_s{3000.0};
  double r_forget_s{3000.0};
  double k_forget_s{0.0};
  // The common scale of J and k is not in the data (§I.4). true: it is fixed by the thrusters'
  // calibration, the mean strength of the reference thrusters (all, minus those declared changed)
  // held at the mean of k0 by a constraint after each update; false: only the k prior holds it.
  bool anchor_thrust_scale{true};
  // Excitation: a window excites the inertia scale when its weighted torque impulse exceeds
  // min_torque_impulse (N m s), r when the net-force impulse exceeds min_force_impulse (N s),
  // thruster i when its impulse exceeds min_thruster_impulse (N s).
  double min_torque_impulse{50.0};
  double min_force_impulse{20.0};
  // ... and the torque impulse (commanded, or inertial for the ratios) must also exceed min_snr
  // times the window's noise sigma (I16): in a closed loop, windows where the commands only
  // answer the disturbance bias the estimate.
  double min_snr{10.0};
  // (I26) A window updates J only when its information on J is at least this share of what J
  // already knows, tr(R^-1 H_a P_a H_a') (0: off). The window's noise correlated with its own
  // regressor (the gyro's noise in A_J; in a closed loop, the disturbance the commands answer)
  // biases J by about the same amount in every window, whatever its torque, while what a window
  // teaches falls with the despin's torque: without the gate the late windows pulled J by
  // percents (estimation README §I.8). J does not forget in a window it does not use.
  double min_inertia_information{0.0};
  // ... and r only when its information tr(R^-1 S(F) P_r S(F)') is at least this share (0: off).
  double min_offset_information{0.0};
  double min_thruster_impulse{5.0};
  // Guards: a J update that leaves J not positive definite or violating the triangle inequality
  // of the principal moments is refused; r must stay within r_max_offset of r0 (else refused);
  // k_i is clamped to [k_min, k_max].
  double r_max_offset{5.0};
  double k_min{0.0};
  double k_max{1.5};
  // (I28) A step the guards refuse is first halved up to this many times: the largest fraction
  // 2^-n of the gain that the guards accept is applied, with the covariance of that gain (the
  // full form, valid for any gain), so a first window from a far prior is not lost. With it on
  // (> 0), the triangle inequality is asked only as far as the estimate already meets it: a prior
  // outside it may move back, never further out. 0: refused, the inequality strict.
  int guard_halvings{0};
  // Observability: a direction whose 1 sigma is still above unobservable_ratio times its prior
  // is reported unobservable (not estimated).
  double unobservable_ratio{0.5};
  // Confidence: J's largest 1 sigma relative to ||J_hat|| (Frobenius), r's largest observable
  // 1 sigma (m), k_i's 1 sigma.
  double j_confident_rel{0.01};
  double r_confident{0.02};
  double k_confident{0.02};
};

struct IdentifierConfigCheck {
  bool ok{true};
  const char* field{""};
  const char* reason{""};
};

// The first bad field and why, or ok.
IdentifierConfigCheck validate(const IdentifierConfig& c);

// (I21) Variance of ∫ w d dt per unit disturbance variance, w the triangular window of length
// window_s, d held for hold_s with a random phase (autocorrelation 1 - |u| / hold_s):
// 2 ∫_0^hold (1 - u / hold) R_w(u) du, R_w the window's autocorrelation.
double held_disturbance_factor(double window_s, double hold_s);

struct IdentifierInput {
  Vec3 omega{Vec3::Zero()};  // body rate at this tick, rad/s (gyro or estimate)
  bool omega_valid{false};
  Vec8 force{Vec8::Zero()};  // channel forces commanded over the previous tick, N (SPEC §4)
  bool force_valid{true};    // false: the previous tick's thrust is unknown (window discarded)
};

struct IdentifierExcitation {
  bool inertia_motion{false};               // the window carried rotation (inertia ratios)
  bool inertia_scale{false};                // ... and enough commanded torque (inertia scale)
  bool inertia_informative{true};           // (I26) ... and adds enough to what J already knows
  double inertia_information{0.0};          // (I26) tr(R^-1 H_a P_a H_a'), 0 when not computed
  bool offset_informative{true};            // (I26) the same test for r
  bool offset{false};                       // enough net force (r, normal to it)
  std::array<bool, kThrusters> thruster{};  // thruster i fired enough
};

// What can and cannot be told from the data so far (§I.3).
struct IdentifierObservability {
  int offset_unobservable{0};               // how many directions of r are unobservable
  std::array<Vec3, 3> offset_directions{};  // their unit vectors (first offset_unobservable)
  bool inertia_scale_unobservable{true};    // sigma along a_hat / prior above the ratio
  int inertia_unobservable{0};              // inertia parameters still near their prior sigma
  std::array<bool, kThrusters> thruster_unobservable{};
  // The common scale of J and all k_i never shows in gyro + commanded-thrust data (§I.4): it is
  // anchored by the thrusters' calibration prior, not estimated. Always true; reported so nobody
  // reads the inertia scale as measured independently of the thrust calibration.
  bool thrust_scale_anchored{true};
};

struct IdentifierCounters {
  std::uint32_t windows{0};            // windows completed
  std::uint32_t windows_discarded{0};  // a missing rate or thrust sample broke the window
  std::uint32_t inertia_updates{0};
  std::uint32_t offset_updates{0};
  std::uint32_t strength_updates{0};
  std::uint32_t inertia_refused{0};  // guard refusals
  std::uint32_t offset_refused{0};
  std::uint32_t strength_clamped{0};
  std::uint32_t damped_steps{0};     // (I28) steps applied at a halved gain
  std::uint32_t reinflations{0};
  std::uint32_t windows_gated{0};      // refused by the innovation gate (I18)
  std::uint32_t gate_reinflations{0};  // ... re-inflations after too many in a row
  std::uint32_t fault_torque_settles{0};  // d settled at zero and taken out of the state (I24)
};

struct IdentifierEstimate {
  Mat3 j{Mat3::Identity()};
  Vec6 j_sigma{Vec6::Zero()};  // 1 sigma of [Jxx Jyy Jzz Jxy Jxz Jyz]
  Vec3 r{Vec3::Zero()};
  Vec3 r_sigma{Vec3::Zero()};
  Vec16 k{Vec16::Ones()};
  Vec16 k_sigma{Vec16::Zero()};
  // (I29) Relative 1 sigma of the thrust scale the anchor (I15) holds: the thrusters' mean
  // calibration error. j_sigma and k_sigma include it (their marginal 1 sigma); the covariances
  // (inertia_covariance() ...) are conditional on the scale, which no prediction of the motion
  // depends on (J^-1 (tau(k) - omega x J omega) is invariant under (J, k) -> (sJ, sk)).
  double thrust_scale_sigma{0.0};
  // The marginal covariances of J's parameters (with the scale, I29) and of r, packed (pack_upper):
  // the normalised error of J is da' C^-1 da with the correlations, not the sum over 1 sigma.
  Vec21 j_cov{Vec21::Zero()};
  Vec6 r_cov{Vec6::Zero()};
  Vec3 gyro_bias{Vec3::Zero()};  // bias of the given rate (I17), rad/s
  Vec3 gyro_bias_sigma{Vec3::Zero()};
  bool inertia_confident{false};
  bool offset_confident{false};  // every observable direction within r_confident
  std::array<bool, kThrusters> thruster_confident{};
  // Mean residual torque of the last window with the latest estimates (N m, F_B), and its
  // squared norm normalised by the window noise (a fault detector's input).
  Vec3 residual_torque{Vec3::Zero()};
  double residual_chi2{0.0};
};

// (I23) The stuck-on evidence of the fault torque d (I22), scored after each window.
struct IdentifierFaultTorque {
  std::uint32_t scored{0};       // windows scored so far (changes when a new score is out)
  bool fitted{false};            // the scored window updated the estimate (not gated, not refused)
  Vec3 d{Vec3::Zero()};          // d-hat, N m (F_B)
  Mat3 d_cov{Mat3::Zero()};      // its covariance
  double chi2_zero{0.0};         // d-hat' P_d^-1 d-hat: d against zero (3 dof)
  // (d-hat - u_max k_i (p_i + r) x e_i)' C_i^-1 (...), C_i from the joint covariance of d, r
  // and k_i: d against thruster i stuck on (3 dof).
  std::array<double, kThrusters> chi2_jet{};
  // u_max k_i (p_i + r) x e_i against zero along its own direction, with its covariance from r
  // and k_i (1 dof, (|col|^2)^2 / col' C col): how far thruster
  // i's stuck-on torque stands out of the model's uncertainty (a jet near the centre of mass, or
  // whose arm r makes uncertain, cannot be told from no fault).
  std::array<double, kThrusters> chi2_column{};
  bool held_zero{false};  // d was settled at zero (I24) and is out of the state
};

class Identifier {
 public:
  // Takes a validated config; sets the estimates to the priors.
  void configure(const IdentifierConfig& c);
  // Back to the priors and empty windows.
  void reset();
  // One tick.
  // `background`: whether this tick may carry a block of the latched window's step (the
  // executive leaves it out on ticks that already carry other periodic work, e.g. the fault
  // detector's heavy evaluation steps). A step still running when the next window closes is
  // finished then.
  void update(const IdentifierInput& in, bool background = true);

  // Re-inflation on a declared change (a fault, a table switch): the group's covariance goes
  // back to its prior; the estimate is kept as the starting point.
  void reinflate_inertia();
  void reinflate_offset();
  void reinflate_thruster(int i);
  void reinflate_all();  // also the fault torque d (I22)
  // Right after reinflate_all: J, r and k start again from a model known better than the
  // identifier's estimate, with its uncertainty (each at most the prior's): per-parameter 1 sigma
  // of J, the covariance of r, the 1 sigma of each k. The fault detector's held model (gnc/fdi
  // README F12) after the fault the identifier absorbed meanwhile is confirmed.
  void restart_at(const Mat3& j, double j_sigma, const Vec3& r, const Mat3& r_cov, const Vec16& k,
                  double k_sigma);
  void reinflate_fault_torque();
  // The rate given from the next window on has `delta` subtracted beyond what was subtracted so
  // far (e.g. a new gyro-bias estimate from the attitude filter): the bias state follows,
  // b <- b - delta, once the step of the window already closed (which used the old rate) is done.
  void shift_rate_bias(const Vec3& delta);
  // With b a consider parameter (gyro_bias_estimated false): the rate given from the next window
  // on has been corrected by a bias estimate whose error has this 1 sigma per axis (e.g. the
  // attitude filter's); b's covariance becomes diag(sigma^2), its mean zero and its cross terms
  // cleared (a fresh consider parameter), once the closed window's step is done.
  void consider_rate_bias(const Vec3& sigma);

  const IdentifierEstimate& estimate() const { return est_; }
  const IdentifierExcitation& excitation() const { return exc_; }
  const IdentifierObservability& observability() const { return obs_; }
  const IdentifierCounters& counters() const { return counters_; }
  // (I5) The variance of one row of the last closed window's equation, (N m s)^2: the gyro's
  // noise through the window, the held disturbance, the floor (0 before the first window).
  double latched_window_noise() const { return counters_.windows > 0 ? latched_noise_ : 0.0; }
  // The last closed window's length (s), and the length of all closed windows (I30: the early
  // windows are shorter than window_s).
  double latched_window_s() const { return latched_.length_s > 0.0 ? latched_.length_s : c_.window_s; }
  double identified_s() const { return identified_s_; }
  const Mat6& inertia_covariance() const { return p_j_; }
  const Mat3& offset_covariance() const { return p_r_; }
  const Mat16& strength_covariance() const { return p_k_; }
  const Mat3& bias_covariance() const { return p_b_; }
  // kJoint: the whole covariance of [a; r; k; b; d] as it stands (rows of a step may be pending).
  // A latched window's step (or its fault-torque scoring) is still under way.
  bool stepping() const { return phase_ != Phase::kIdle; }
  // reinflate_all's rewrite of the joint covariance waits for the next update with a free block.
  bool covariance_rewrite_pending() const { return fill_pending_; }
  // The next block is the joint step's linearisation, the heaviest (about 3 k Cortex-M7
  // instructions): the executive keeps its other periodic work off that tick.
  bool heavy_block_next() const {
    return !fill_pending_ && phase_ == Phase::kInertia && c_.mode == IdentifierMode::kJoint;
  }
  // The joint covariance (completes a re-inflation's deferred rewrite first).
  const MatId& joint_covariance();
  const IdentifierFaultTorque& fault_torque() const { return ft_; }
  // (I24) d is held at zero now (from the tick the settling starts; fault_torque().held_zero
  // follows at the next score).
  bool fault_torque_held_zero() const { return d_held_zero_; }

 private:
  // The data of one window, latched at its end.
  struct Window {
    Mat36 a_j{Mat36::Zero()};      // A_J of (I3): A_J a = -∫ w' J omega + ∫ w omega x J omega
    Vec16 impulse{Vec16::Zero()};  // ∫ w F_i dt per thruster, N s
    double weight{0.0};            // ∫ w dt, s
    double sum_alpha2{0.0};        // sum of the per-sample weights on L(omega), squared (I5)
    double sum_gyro2{0.0};         // sum of (w dt |omega|)^2 (I5)
    Vec3 m{Vec3::Zero()};          // sum of w dt omega: G = S(m) J - S(J m) (I17)
    Mat3 w2{Mat3::Zero()};         // sum of (w dt)^2 omega omega' (I19)
    Vec3 n{Vec3::Zero()};          // sum of alpha w dt omega (I19)
    double length_s{0.0};          // the window's length T (I30: early windows are shorter)
    double dist_factor{0.0};       // (I21) for that length
  };
  enum class Phase : std::uint8_t {
    kIdle, kNoise, kInertia, kSecondOrder, kGain, kOffset, kApply, kStrength, kAnchor, kSync, kReport, kFaultScore,
    kSettleFactors, kSettleStart, kSettle
  };
  // (I23) Thrusters scored per tick after the report (the Cortex-M7 tick budget).
  static constexpr int kFaultJetsPerTick = 2;
  int fault_jet_next_{0};
  bool window_fitted_{false};  // the latched window's step updated the estimate
  // (I24) d settled at zero: once d-hat has stayed consistent with zero (chi-square below the
  // gate) with a 1 sigma below a tenth of its prior for kSettleWindows fitted windows, the
  // pseudo-measurement d = 0 is applied (its information returns to J, r and k) and d is held
  // out of the state until the gate or a declared change re-inflates it.
  static constexpr int kSettleWindows = 3;
  static constexpr int kSettleRowsPerTick = 3;
  int settle_streak_{0};
  bool d_held_zero_{false};
  struct SettleStep {
    bool pending{false};
    int rows{0};
    Eigen::Matrix<double, kIdParams, 3> pd{Eigen::Matrix<double, kIdParams, 3>::Zero()};  // P_:d
    Eigen::Matrix<double, kIdParams, 3> g{Eigen::Matrix<double, kIdParams, 3>::Zero()};   // P_:d P_dd^-1
    bool factored{false};        // pd and g are ready (settle_factors)
    std::uint32_t generation{0};  // ... for the covariance of this re-inflation count
  };
  SettleStep settle_{};
  void settle_factors();  // (I24) the rank-3 covariance term's factors, on a tick of its own
  void start_settle();   // (I24) the state from those factors
  bool settle_rows();    // ... a block of rows of the covariance (true when done)
  void finish_settle();  // ... every remaining row
  void score_fault_torque(int first, int n);  // (I23) thrusters [first, first + n)
  IdentifierFaultTorque ft_{};

  void accumulate(const IdentifierInput& in);
  double sample_alpha(int i) const;   // coefficient of L(omega_i), (I4)
  double sample_weight(int i) const;  // w(t_i)
  double window_noise() const;        // row variance of the latched window (I5)
  Mat3 window_noise_matrix() const;  // covariance of the latched window's equation (I19)
  bool information_gate();  // (I26) before the first block of gain rows; false: both gates off
  bool gate_reinflate();                    // (I18) a re-inflation the gate asked for, a part per block
  int gate_reinflation_due_{0};             // ... its next part, 1-4 (0: none)
  double torque_threshold() const;    // (I16)
  Vec3 model_torque_impulse(const Vec16& k, const Vec3& r) const;  // ∫ w tau dt (I6)
  Vec3 net_force_impulse() const;     // sum k_i e_i ∫ w F_i dt with k_hat
  Mat3 bias_jacobian() const;         // G(J_hat) of (I17)
  // (I20) The bilinear terms' covariance, one part per tick (true when it is complete).
  bool second_order_step();
  Mat316 strength_regressor() const;  // (I11) with r_hat
  Mat3 consider_inertia() const;      // (I7)
  Mat3 consider_offset() const;
  Mat3 consider_strengths() const;
  void joint_gain();       // (I13) gain of the joint step: the linearisation
  bool joint_gain_rows();  // ... a block of rows of P H'; then S and K (true when done)
  void joint_apply();
  void joint_covariance_rows(int first, int n);  // rows [first, first + n) of the P update
  bool joint_covariance_step();  // a block of rows of the P update (true when all are done)
  void symmetrise_rows(int first, int n);
  void joint_finish_covariance();  // the remaining rows, symmetrise, cap        // (I13), (I14)
                                   // apply it, guarded
  void sync_blocks();              // joint covariance -> per-group blocks
  void anchor_scale();             // (I15) the state, and the covariance's rank-one term
  bool anchor_rows();              // ... a block of rows of the covariance (true when done)
  void finish_anchor();            // ... every remaining row
  // reinflate_all: every pending block of rows (joint step, anchor, settling) on the kept rows
  // only.
  void finish_kept_rows(const std::array<bool, kIdParams>& kept);
  void anchor_scale_finish();
  double thrust_scale_sigma() const;  // (I29)
  // reinflate_all's rewrite of p_all_, deferred to the identifier's next block (or to whatever
  // reads p_all_ first).
  void complete_reinflation();
  struct Fill {
    Mat3 p_bb{Mat3::Zero()};
    Mat3 p_bd{Mat3::Zero()};
    Mat3 p_dd{Mat3::Zero()};
    bool d_live{false};
    double vj{0.0};  // J's, r's and k's blocks after the rewrite (the priors, or restart_at's)
    Mat3 p_r{Mat3::Zero()};
    double vk{0.0};
  };
  Fill fill_{};
  bool fill_pending_{false};
  void update_inertia();
  void update_offset();
  void update_strengths();
  void report();
  void step_phase();   // one block of the latched window's step
  void finish_step();  // every remaining block at once
  int window_ticks_next() const;  // (I30)

  IdentifierConfig c_{};
  int n_{200};                                // ticks of the window being accumulated
  int n_full_{200};                           // ... window_s
  int n_early_{0};                            // ... early_window_s (I30), 0: none
  double dist_factor_early_{0.0};             // (I21) for early_window_s
  double identified_s_{0.0};                  // total length of the windows closed so far
  std::array<Vec3, kThrusters> e_{};          // thruster directions
  std::array<Vec3, kThrusters> p_pos_{};      // thruster positions
  std::array<Vec3, kThrusters> p_cross_e_{};  // p_i x e_i

  // Estimates and covariances.
  Vec6 a_{Vec6::Zero()};
  Mat6 p_j_{Mat6::Identity()};
  Vec3 r_{Vec3::Zero()};
  Mat3 p_r_{Mat3::Identity()};
  Vec16 k_{Vec16::Ones()};
  Mat16 p_k_{Mat16::Identity()};
  Vec3 b_{Vec3::Zero()};
  Mat3 p_b_{Mat3::Zero()};
  Vec3 d_{Vec3::Zero()};  // (I22) constant body torque, N m
  Vec3 bias_shift_{Vec3::Zero()};           // shift_rate_bias not yet applied (a step is running)
  Vec3 bias_consider_sigma_{Vec3::Zero()};  // consider_rate_bias not yet applied
  bool bias_consider_pending_{false};
  void apply_bias_changes();
  int gated_in_row_{0};
  MatId p_all_{MatId::Identity()};            // kJoint: [a; r; k]
  std::array<bool, kThrusters> reference_{};  // thrusters that define the thrust scale
  // The joint step is spread over ticks in row blocks (the Cortex-M7 tick budget): rows of P H'
  // per tick while the gain is formed, rows of P per tick while the covariance is updated. For a
  // window too short for that many ticks, configure() takes bigger blocks (every step must be done
  // before the next window closes).
  int gain_rows_per_tick_{4};
  int cov_rows_per_tick_{1};
  static constexpr int kSymmetriseRowsPerTick = 5;
  struct JointStep {  // the gain over several ticks, applied on one, the covariance over several
    bool started{false};
    bool pending{false};
    bool rows_pending{false};  // covariance rows still to be updated
    int gain_rows{0};          // rows of p_ht computed so far
    int cov_rows{0};           // rows of P updated so far
    int sym_rows{0};           // ... then symmetrised
    Eigen::Matrix<double, 3, kIdParams> h{Eigen::Matrix<double, 3, kIdParams>::Zero()};
    Eigen::Matrix<double, kIdParams, 3> dht{Eigen::Matrix<double, kIdParams, 3>::Zero()};
    bool any_thruster{false};
    bool inertia_held{false};  // (I26) J's gain is zero in this window: the full covariance form
    bool offset_held{false};   // (I26) ... r's
    bool damped{false};        // (I28) the gain was halved for the guards: the full form
    bool gated{false};         // (I26) the information gate has been decided for this step
    VecId d{VecId::Ones()};
    Vec3 e0{Vec3::Zero()};
    Mat3 s{Mat3::Identity()};
    Mat3 second_order{Mat3::Zero()};  // (I20) the bilinear terms' covariance
    int second_order_part{0};          // ... the next of its parts (second_order_step)
    Mat36 bpa[3]{};                    // ... B_k P_a (bias_jacobian_times)
    Eigen::Matrix<double, kIdParams, 3> p_ht{Eigen::Matrix<double, kIdParams, 3>::Zero()};
    Eigen::Matrix<double, kIdParams, 3> k{Eigen::Matrix<double, kIdParams, 3>::Zero()};
  };
  JointStep joint_{};
  static constexpr int kAnchorRowsPerTick = 4;
  struct AnchorStep {  // the thrust-scale anchor's covariance term, a block of rows per tick
    bool pending{false};
    int rows{0};
    bool pc_pending{false};   // P c begun (the first eight thrusters); its end and x on the next block
    VecId c{VecId::Zero()};
    double b{0.0};
    VecId pc{VecId::Zero()};  // P c
    VecId g{VecId::Zero()};   // P c / (c' P c)
  };
  AnchorStep anchor_{};

  // Window in progress and the latched one.
  Window acc_{};
  Window latched_{};
  int sample_{-1};  // index of the last accumulated sample in the window, -1 = not started
  Vec8 last_force_{Vec8::Zero()};
  Phase phase_{Phase::kIdle};
  double latched_noise_{1.0};
  double dist_factor_{0.0};  // (I21) var(∫ w d dt) / sigma_d^2 for the held disturbance
  Mat3 latched_r_{Mat3::Identity()};
  Mat3 residual_cov_{Mat3::Identity()};  // innovation covariance of the latched window
  double innovation_chi2_{0.0};          // e0' S^-1 e0 of the latched window (I18)

  IdentifierEstimate est_{};
  IdentifierExcitation exc_{};
  IdentifierObservability obs_{};
  IdentifierCounters counters_{};
};

// How an identified model reaches the flight: through the parameter table, at a tick boundary,
// only when the confidence test passes (DESIGN.md "Modes": tables switch at a boundary).
enum class ModelAdoption : std::uint8_t {
  kOff = 0,   // estimate and report only; the ground adopts by command
  kAuto = 1,  // the core adopts a confident, changed model itself (never faster than the interval)
};
inline constexpr int kModelAdoptionCount = 2;

struct IdentificationParams {
  bool enabled{false};  // run the identifier in the tick
  ModelAdoption adopt{ModelAdoption::kOff};
  double adopt_interval_s{300.0};  // s, at least this long between two automatic adoptions
  // > 0: a confident model also counts as changed when the identifier's own covariance sets it
  // apart from the active table: some J_tot or r_SO/BCM parameter more than adopt_sigmas of its
  // 1 sigma away (a difference inside the fixed confidence bounds, e.g. 0.2 % of |J|, that the
  // data resolve). 0: changed only beyond the confidence bounds.
  double adopt_sigmas{0.0};
  // With the MEKF, the 1 sigma of the bias left in the corrected rate is the MEKF's bias sigma,
  // but never below this (rad/s): the MEKF's bias sigma at convergence understates its error,
  // and the identifier takes the residual bias afresh each window (README I17).
  double mekf_bias_sigma_floor{3e-6};
  // (I27) After a confirmed fault that the identifier does not restart from the detector's held
  // model (a stuck-on jet, or no model held), it restarts from its own estimate of the tick
  // before, if that was confident, with J's 1 sigma at least j_confident_rel of |J|, r's
  // covariance plus r_confident^2 per axis and the strengths' 1 sigma their largest before,
  // instead of all three groups at their prior; the window open at the confirmation is dropped.
  // false: at their prior (README I.9: measured, not adopted).
  bool keep_model_after_fault{false};
  // The identifier's tuning. Its dt, thruster geometry and priors (j0, r0, k0) are not read from
  // here: they are the active table's dt, rcs and mass_hat, filled in by build_identifier_config.
  IdentifierConfig config{};
  // Identification excitation (README §I.6): a torque-free net force while r is not yet known.
  // Needs `enabled` above; off by default (the study's strategies).
  ExcitationConfig excitation{};
};

}  // namespace rocksteady::gnc
