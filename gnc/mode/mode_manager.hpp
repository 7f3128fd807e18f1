// Mode manager (DESIGN.md "Modes"): IDLE, DETUMBLE, HOLD, TRACK, SAFE. Ground requests are checked
// against the transition table and applied at the start of a tick; autonomous transitions
// (DETUMBLE -> HOLD at |omega| <= omega_switch, faults -> SAFE) follow. Every transition is
// reported. The modes, transition checks and events are the step's vocabulary (gnc/io.hpp).
#pragma once

#include "gnc/io.hpp"

namespace rocksteady::gnc {

struct ModeParams {
  Mode initial{Mode::kIdle};
  bool auto_hold{true};          // DETUMBLE -> HOLD at |omega_hat| <= omega_switch
  double sensor_timeout_s{1.0};  // no valid sensor sample for this long -> SAFE
};

struct TransitionContext {
  bool estimate_valid{false};
  bool trajectory_valid{false};
  LawId law{LawId::kNtcl};
};

// The transition table plus the context rules.
TransitionCheck check_transition(Mode from, Mode to, const TransitionContext& ctx);

// What the mode manager looks at once per tick.
struct ModeInputs {
  bool has_request{false};  // a ground mode request arrived for this tick
  Mode request{Mode::kIdle};
  TransitionContext ctx{};
  double omega_norm{0.0};    // |omega_hat|, rad/s (auto-hold, Eq. 51)
  double sensor_age_s{0.0};  // time since the last sample with both sensors valid
  bool state_finite{true};   // the estimate (or the commanded torque) is finite
};

class ModeManager {
 public:
  void configure(const ModeParams& p, double omega_switch);
  void reset(Mode initial);
  Mode mode() const { return mode_; }
  // True on the first tick spent in the current mode.
  bool entered() const { return entered_; }

  // Start of tick: the ground request (if any), then autonomous transitions.
  void update(const ModeInputs& in, ModeEvents& events);

 private:
  void go(Mode to, EventId why, ModeEvents& events);

  ModeParams p_{};
  double omega_switch_{5e-4};
  Mode mode_{Mode::kIdle};
  bool entered_{true};
};

}  // namespace rocksteady::gnc
