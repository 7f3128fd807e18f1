// Mode manager (DESIGN.md "Modes"): IDLE, DETUMBLE, HOLD, TRACK, SAFE. Ground requests are checked
// against the transition table and applied at the start of a tick; autonomous transitions
// (DETUMBLE -> HOLD at |omega| <= omega_switch, faults -> SAFE) follow. Every transition is reported.
#pragma once

#include <array>
#include <cstdint>

#include "gnc/params.hpp"

namespace rocksteady::gnc {

enum class TransitionCheck : std::uint8_t {
  kOk = 0,
  kSameMode,         // already in that mode
  kNotAllowed,       // not in the transition table
  kNoTrajectory,     // TRACK without a valid trajectory
  kLawCannotTrack,   // TRACK with the D+PD law
  kNoEstimate,       // leaving SAFE/IDLE before the estimator has a valid state
  kInvalidMode,      // not one of the five modes
};
const char* to_string(TransitionCheck c);

enum class EventId : std::uint8_t {
  kModeChanged = 0,   // from -> to, by ground request
  kAutoHold,          // DETUMBLE -> HOLD at omega_switch
  kSensorTimeout,     // -> SAFE: no valid sensor sample within the timeout
  kNonFiniteState,    // -> SAFE: the estimate or command went non-finite
  kRequestRejected,   // a mode request that failed the check at the tick boundary
  kSensorRejected,    // a sample failed validity / range checks
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

struct TransitionContext {
  bool estimate_valid{false};
  bool trajectory_valid{false};
  LawId law{LawId::kNtcl};
};

// The transition table plus the context rules.
TransitionCheck check_transition(Mode from, Mode to, const TransitionContext& ctx);

class ModeManager {
 public:
  void configure(const ModeParams& p, double omega_switch);
  void reset(Mode initial);
  Mode mode() const { return mode_; }
  // True on the first tick spent in the current mode.
  bool entered() const { return entered_; }

  // Start of tick: the ground request (if any), then autonomous transitions.
  void update(bool has_request, Mode request, const TransitionContext& ctx, double omega_norm,
              double sensor_age_s, bool state_finite, ModeEvents& events);

 private:
  void go(Mode to, EventId why, ModeEvents& events);

  ModeParams p_{};
  double omega_switch_{5e-4};
  Mode mode_{Mode::kIdle};
  bool entered_{true};
};

}  // namespace rocksteady::gnc
