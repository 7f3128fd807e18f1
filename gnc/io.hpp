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
};
const char* to_string(EventId e);

struct ModeEvent {
  EventId id{EventId::kModeChanged};
  Mode from{Mode::kIdle};
  Mode to{Mode::kIdle};
  TransitionCheck reason{TransitionCheck::kOk};
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
};

struct ThrusterCommand {
  Vec8 force{Vec8::Zero()};  // signed channel forces, N, |u_i| <= u_max
  bool enabled{false};       // false: all thrusters inhibited (IDLE, SAFE)
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
};

struct GncOutput {
  ThrusterCommand command{};
  GncTelemetry telemetry{};
  ModeEvents events{};  // transitions and faults raised during this tick
};

}  // namespace rocksteady::gnc
