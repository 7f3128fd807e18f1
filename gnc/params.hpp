// Plain-data parameters of the flight core, and their validation (returns the first bad field).
// Defaults are the study's Table 4 (SPEC §5) where the study gives them; [Rocksteady choice] marks
// the rest.
#pragma once

#include <cstdint>

#include "gnc/allocation/allocator.hpp"
#include "gnc/model/mass_properties.hpp"
#include "gnc/model/rcs.hpp"
#include "gnc/types.hpp"

namespace rocksteady::gnc {

enum class Mode : std::uint8_t { kIdle = 0, kDetumble = 1, kHold = 2, kTrack = 3, kSafe = 4 };
inline constexpr int kModeCount = 5;
const char* to_string(Mode m);

// Control law (SPEC §2). Orthogonal to the mode: the mode picks the reference phase.
enum class LawId : std::uint8_t {
  kNtcl = 0,         // Robust NTCL, Eq. (9)
  kNtclEl = 1,       // NTCL for Euler-Lagrange systems, Eq. (17)/(18)
  kIntegral = 2,     // Integral NTCL, Eq. (19)
  kAdaptive = 3,     // Adaptive NTCL, Eq. (34)
  kSo3 = 4,          // NTCL on SO(3), Eq. (37)
  kDpd = 5,          // D+PD, Eqs. (49)-(50)
  kFeedforward = 6,  // feed-forward cancellation (comparison only)
};
inline constexpr int kLawCount = 7;
const char* to_string(LawId l);

enum class EstimatorKind : std::uint8_t { kPassThrough = 0, kFilter = 1 };

struct TrackingGains {  // K (N m s) and Lambda (1/s) of Eqs. (9), (17), feed-forward law
  Mat3 k{1e4 * Mat3::Identity()};
  Mat3 lambda{1e-3 * Mat3::Identity()};
};

struct IntegralGains {  // Eq. (19)
  Mat3 k{1e4 * Mat3::Identity()};
  Mat3 lambda{1e-3 * Mat3::Identity()};
  // [Rocksteady choice] K_I: the study gives no value. K_I = 1 N m/(rad) puts the integral
  // corner (K_I/K = 1e-4 1/s) a factor ~3 below the contraction rate lambda_min(K)/lambda_max(J).
  Mat3 k_i{1.0 * Mat3::Identity()};
  // [Rocksteady choice] anti-windup: |integral| clamped per axis, frozen while the allocator
  // saturates.
  double integral_limit_nm{500.0};
};

struct AdaptiveGains {  // Eq. (34)
  Mat3 k{1e4 * Mat3::Identity()};
  Mat3 lambda{1e-3 * Mat3::Identity()};
  double gamma{1e12};
  // [Rocksteady choice] projection set: the eigenvalues of J(a_hat) stay within
  // [floor_ratio * lambda_min(J_hat0), ceiling_ratio * lambda_max(J_hat0)].
  double eig_floor_ratio{0.5};
  double eig_ceiling_ratio{2.0};
};

struct So3Gains {  // Eq. (37)
  Mat3 k{1e4 * Mat3::Identity()};
  // [Rocksteady choice] Lambda_e = 4 Lambda_r: near the goal e_R ~ theta/2 and E ~ I/2, so this
  // gives the MRP law's small-angle attitude bandwidth (q ~ theta/4, Z ~ I/4).
  Mat3 lambda{4e-3 * Mat3::Identity()};
};

struct DpdGains {  // Eqs. (49)-(50)
  Mat3 k_d{1e4 * Mat3::Identity()};
  double k_p{10.0};
};

struct GuidanceParams {
  double omega_switch{5e-4};  // rad/s: D+PD-based switch (51), fuel-optimal augmentation (46)-(48)
  double k_qd{1e-4};          // 1/s, Eq. (46)-(48)
  Vec3 q_final{Vec3::Zero()};  // MRP, the commanded final attitude (ground can change it)
  // [Rocksteady choice] period of the TRACK reference reset from the current estimate; 0: only at
  // activation.
  double track_reset_period_s{0.0};
  double eps_trans{0.5 * 2.0 * 3.14159265358979323846 / 60.0};  // 0.5 rpm in rad/s (SPEC §5)
};

struct EstimatorParams {  // SPEC §6
  EstimatorKind kind{EstimatorKind::kPassThrough};
  double omega_c{0.02 * 3.14159265358979323846};  // rad/s
  int predict_substeps{1};                         // RK4 steps per tick in the prediction
  // Sample acceptance: a gyro rate above this, or a star-tracker quaternion whose norm is off by
  // more than the tolerance, is rejected (counted, and the model carries the estimate).
  double gyro_max_rate{1.0};          // rad/s
  double quat_norm_tolerance{0.01};
};

struct ModeParams {
  Mode initial{Mode::kIdle};
  bool auto_hold{true};         // DETUMBLE -> HOLD at |omega_hat| <= omega_switch
  double sensor_timeout_s{1.0};  // no valid sensor sample for this long -> SAFE
};

struct GncParams {
  double dt{0.1};  // GNC period, s (10 Hz)
  MassProperties mass_hat{};  // the flight software's estimate (hatted quantities, Eq. 6)
  RcsLayout rcs{};
  LawId law{LawId::kNtcl};
  TrackingGains ntcl{};
  TrackingGains el{};
  TrackingGains feedforward{};
  IntegralGains integral{};
  AdaptiveGains adaptive{};
  So3Gains so3{};
  DpdGains dpd{};
  GuidanceParams guidance{};
  EstimatorParams estimator{};
  ModeParams mode{};
  // SPEC §4: the study's pseudoinverse, Eq. (53), or the fuel-optimal allocation, Eq. (52).
  AllocatorKind allocator{AllocatorKind::kPseudoInverse};
  double isp_s{287.0};  // Eq. (54)
  double g0{9.8};
};

// The study's parameters (Tables 2 and 4) with the estimated mass properties equal to the true ones.
GncParams study_gnc_params(double u_max);

struct ParamCheck {
  bool ok{true};
  const char* field{""};
  const char* reason{""};
};

// Validates every field; returns the first bad one with a reason (non-positive-definite inertia or
// gains, rank-deficient B_hat, non-finite values, bad rates or thresholds).
ParamCheck validate(const GncParams& p);

// Helpers shared by validation and the components.
bool all_finite(const Mat3& m);
bool is_symmetric_positive_definite(const Mat3& m);

}  // namespace rocksteady::gnc
