// What goes into and comes out of one GNC tick (Gnc::step), and the vocabulary those structs carry:
// modes, control laws, reference phases, mode events. Users that only exchange data with the flight
// core (HAL devices, bus codecs, the flight application, ground tools) include this header, not the
// whole component (gnc/gnc.hpp).
#pragma once

#include <array>
#include <cstdint>

#include "gnc/allocation/allocator.hpp"
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

// Phase of the desired attitude trajectory (SPEC §3), chosen by the mode.
enum class ReferencePhase : std::uint8_t {
  kNone = 0,            // IDLE, SAFE: no reference, thrusters inhibited
  kDamping = 1,         // Eq. (51) phase 1: omega_r = 0 (rate damping)
  kHold = 2,            // Eq. (51) phase 2 / hold: q_d = q_final, qdot_d = 0
  kTrack = 3,           // Eq. (45): follow omega_d(t)
  kTrackAugmented = 4,  // Eqs. (46)-(48): omega_d plus convergence to q_final
  kTrackSlew = 5,       // after the plan: the acquisition slew to q_final (guidance.slew_s > 0)
};
const char* to_string(ReferencePhase p);

// Result of checking a mode request against the transition table (DESIGN.md "Modes").
enum class TransitionCheck : std::uint8_t {
  kOk = 0,
  kSameMode,        // already in that mode
  kNotAllowed,      // not in the transition table
  kNoTrajectory,    // TRACK without a valid trajectory
  kLawCannotTrack,  // TRACK with the D+PD law
  kNoEstimate,      // leaving SAFE/IDLE before the estimator has a valid state
  kInvalidMode,     // not one of the five modes
};
const char* to_string(TransitionCheck c);

enum class EventId : std::uint8_t {
  kModeChanged = 0,  // from -> to, by ground request
  kAutoHold,         // DETUMBLE -> HOLD at omega_switch
  kSensorTimeout,    // -> SAFE: no valid sensor sample within the timeout
  kNonFiniteState,   // -> SAFE: the estimate or command went non-finite
  kRequestRejected,  // a mode request that failed the check at the tick boundary
  kSensorRejected,   // a sample failed validity / range checks
  kTrajectorySwitched,  // a staged trajectory became active at this tick boundary (TRACK re-synced)
  kTrajectoryStale,     // a staged trajectory was refused at the boundary; the active one kept
  kModelAdopted,     // the identified model became the active table (automatic policy)
  kModelRefused,     // a confident identified model failed table validation (kept the old one)
  kFaultSuspected,   // a residual window failed the no-fault test (arg0 = leading thruster or -1;
                     // -1 also when detected before the window closed, F33)
  kFaultConfirmed,   // a thruster fault confirmed and latched (arg0 = thruster, arg1 = FaultKind)
  kValveClosed,      // a pod's latch valve closed to isolate a stuck-on thruster (arg0 = pod)
  kFaultOverride,    // a ground override applied (arg0 = thruster or pod, arg1 = what)
  kReducedAuthority, // the remaining thrusters cannot produce every torque direction
  kIsolationTest,    // (F9) a pod's valve closed for an isolation test, or reopened after it
                     // (arg0 = pod, arg1 = 1 started / 0 ended)
  kJetCheck,         // (F19) a jet fired in B_hat's null space for a jet check, or the check's
                     // end (arg0 = thruster, arg1 = 1 started / 0 ended)
};

// Thruster fault kinds the flight software declares (gnc/fdi).
enum class FaultKind : std::uint8_t { kNone = 0, kStuckOn = 1, kStuckOff = 2, kDegraded = 3 };
const char* to_string(FaultKind k);
const char* to_string(EventId e);

// Why an identified model is or is not a parameter-table candidate now (Gnc::model_candidate).
enum class ModelCandidate : std::uint8_t {
  kOk = 0,
  kDisabled,       // identification is off
  kNotConfident,   // inertia or centre-of-mass 1 sigma above the confidence bounds
  kUnchanged,      // the active table already holds this model (within the confidence bounds)
  kInvalid,        // the model fails table validation (e.g. J_ast not positive definite)
};
const char* to_string(ModelCandidate c);

struct ModeEvent {
  EventId id{EventId::kModeChanged};
  Mode from{Mode::kIdle};
  Mode to{Mode::kIdle};
  TransitionCheck reason{TransitionCheck::kOk};
  std::int16_t arg0{0};  // event data where the event has any (fault events)
  std::int16_t arg1{0};
};

struct ModeEvents {
  static constexpr int kCapacity = 4;
  int count{0};
  std::array<ModeEvent, kCapacity> items{};
  void clear() { count = 0; }
  void push(const ModeEvent& e) {
    if (count < kCapacity) items[count++] = e;
  }
};

// What the HAL delivers each tick, already rotated into the body frame.
struct SensorSample {
  double t{0.0};                 // s, sample time
  Vec3 gyro_rate{Vec3::Zero()};  // measured omega, rad/s, F_B
  bool gyro_valid{false};
  Vec4 star_quat{0, 0, 0, 1};  // measured attitude of F_B in F_I, [beta_v; beta4]
  bool star_valid{false};
};

// Requests from the ground (already validated and acknowledged by the flight application); applied
// at the start of the tick.
struct GncCommands {
  bool has_mode_request{false};
  Mode mode_request{Mode::kIdle};
  bool has_target{false};
  Vec3 target_mrp{Vec3::Zero()};
  bool has_law{false};
  LawId law{LawId::kNtcl};
  // Ground overrides of fault management.
  bool has_fault_declaration{false};
  std::int8_t fault_thruster{-1};        // 0..15; -1 with kNone: clear every declaration
  FaultKind fault_kind{FaultKind::kNone};  // kNone: clear
  double fault_factor{1.0};  // kDegraded: the fraction of its thrust the thruster still delivers
  bool has_valve{false};
  std::int8_t valve_pod{0};
  bool valve_open{true};
  bool has_isolation_inhibit{false};
  bool isolation_inhibited{false};       // true: a confirmed stuck-on does not close its valve
};

struct ThrusterCommand {
  Vec8 force{Vec8::Zero()};  // signed channel forces, N, |u_i| <= u_max
  bool enabled{false};       // false: all thrusters inhibited (IDLE, SAFE)
  // Latch valve of each pod (isolates a failed-on thruster): closed, none of the pod's four
  // thrusters can fire. Independent of `enabled`; all open by default.
  std::array<bool, kPods> valve_open{true, true, true, true};
};

// What the estimators report each tick (zeros for a module that is off).
struct EstimationTelemetry {
  bool mekf{false};                  // the MEKF is the active estimator
  Vec3 gyro_bias{Vec3::Zero()};      // MEKF gyro bias estimate, rad/s
  Vec3 attitude_sigma{Vec3::Zero()}; // MEKF attitude 1 sigma per axis, rad
  Vec3 bias_sigma{Vec3::Zero()};     // MEKF bias 1 sigma per axis, rad/s
  std::uint32_t star_gated{0};       // MEKF star-tracker samples rejected by the gate
  bool identifying{false};           // the identifier runs
  Vec6 j{Vec6::Zero()};              // identified J_tot [Jxx Jyy Jzz Jxy Jxz Jyz], kg m^2
  Vec6 j_sigma{Vec6::Zero()};
  Vec3 r{Vec3::Zero()};              // identified r_SO/BCM, m
  Vec3 r_sigma{Vec3::Zero()};
  Vec16 k{Vec16::Zero()};            // identified thruster strengths
  Vec16 k_sigma{Vec16::Zero()};
  Vec21 j_cov{Vec21::Zero()};        // covariance of j, packed (pack_upper), kg^2 m^4
  Vec6 r_cov{Vec6::Zero()};          // covariance of r, packed, m^2
  double thrust_scale_sigma{0.0};    // (I29) relative 1 sigma of the thrust scale the identifier anchors
  bool inertia_confident{false};
  bool offset_confident{false};
  std::uint16_t thruster_confident{0};  // bit i: thruster i within its confidence bound
  bool excited_inertia{false};          // last window: commanded torque excited the inertia scale
  bool excited_offset{false};           // last window: net force excited r
  std::uint16_t excited_thrusters{0};   // bit i: thruster i fired enough in the last window
  std::uint8_t offset_unobservable{0};  // directions of r not (yet) observable
  Vec3 residual_torque{Vec3::Zero()};   // N m, last window's mean residual with the estimates
  double residual_chi2{0.0};            // its squared norm normalised by the window noise
  std::uint32_t windows{0};
  Vec3 rate_bias_sigma{Vec3::Zero()};   // rad/s, the gyro bias 1 sigma the identifier carries (I17)
  std::uint32_t windows_gated{0};       // windows refused by the innovation gate (I18)
  std::uint32_t gate_reinflations{0};   // J, r, k re-inflated after gated windows in a row (I18)
  std::uint32_t guard_refusals{0};      // updates refused by the guards (I14)
  bool excitation_active{false};        // (X1-X6) the identification excitation flew this tick
  Vec3 excitation_force{Vec3::Zero()};  // N, the net force it asked for (F_B), before gamma
  double excitation_gamma{0.0};         // the fraction of it that fitted the channels' box (X5)
  bool excitation_inertia{false};       // (X8) the inertia phase: the net force nulled, a couple added
  Vec3 excitation_torque{Vec3::Zero()}; // N m, (X8) the couple it asked for (F_B), before gamma
  ModelCandidate candidate{ModelCandidate::kDisabled};
  std::uint32_t adoptions{0};           // identified models adopted into the active table
};

// Fault detection and isolation (zeros when off).
struct FdiTelemetry {
  bool enabled{false};
  Vec3 residual{Vec3::Zero()};  // rad/s, last window's unexplained rate change
  double chi2{0.0};             // its no-fault chi-square (3 dof)
  double noise_sigma{0.0};      // rad/s, the residual's 1 sigma
  std::int8_t best{-1};         // leading hypothesis: 0..15 stuck-on, 16..31 stuck-off
  double best_llr{0.0};
  double runner_up_llr{0.0};
  std::uint16_t suspected_on{0};
  std::uint16_t suspected_off{0};
  std::uint16_t confirmed_on{0};
  std::uint16_t confirmed_off{0};
  std::uint16_t confirmed_degraded{0};  // (F18) latched partial losses of thrust
  Vec16 strength_factor{Vec16::Ones()};  // (F18) latched strength factor per thruster, 1 unless degraded
  std::array<bool, kPods> valve_open{{true, true, true, true}};
  bool isolation_inhibited{false};
  std::uint32_t windows{0};
  std::uint32_t suspicions{0};
  std::int8_t probe_pod{-1};    // (F9) pod closed for an isolation test this tick, -1 none
  std::uint32_t probes{0};      // isolation tests started
  std::int8_t check_jet{-1};    // (F19) thruster fired for a jet check this tick, -1 none
  std::uint32_t checks{0};      // jet checks started
  std::uint32_t checks_unfit{0};  // check windows not scored: they showed a model error
  std::uint32_t surveys{0};       // (F36) of the checks, those the jet survey started
  std::uint16_t unverified{0};    // (F36) bit i: thruster i commanded and not verified since
  std::int8_t balance_channel{-1};  // (F61) channel under a balance test this tick, -1 none
  std::uint32_t balance_tests{0};   // (F61) balance tests flown
  std::uint32_t balance_confirmations{0};  // (F61) faults a balance test confirmed
};

struct GncTelemetry {
  double t{0.0};
  std::uint32_t tick{0};
  Mode mode{Mode::kIdle};
  LawId law{LawId::kNtcl};
  ReferencePhase phase{ReferencePhase::kNone};
  Vec3 omega_hat{Vec3::Zero()};
  Vec3 q_hat{Vec3::Zero()};
  Vec3 q_d{Vec3::Zero()};
  Vec3 omega_r{Vec3::Zero()};
  Vec3 attitude_error{Vec3::Zero()};  // q_hat - q_final (same MRP set)
  AllocatorStatus alloc{};
  double fuel_kg{0.0};              // on-board estimate, Eq. (54)
  std::uint32_t sensor_rejects{0};  // samples rejected (invalid or non-finite)
  bool trajectory_loaded{false};
  Vec6 a_hat{Vec6::Zero()};     // adaptive law's inertia estimate
  Vec3 integral{Vec3::Zero()};  // integral law's state
  EstimationTelemetry est{};
  FdiTelemetry fdi{};
};

struct GncOutput {
  ThrusterCommand command{};
  GncTelemetry telemetry{};
  ModeEvents events{};  // transitions and faults raised during this tick
};

}  // namespace rocksteady::gnc
