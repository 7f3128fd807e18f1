#include "gnc/mode/mode_manager.hpp"

namespace rocksteady::gnc {

namespace {
// Rows: from; columns: to (IDLE, DETUMBLE, HOLD, TRACK, SAFE).
// SAFE is left only for IDLE or DETUMBLE, by ground command.
constexpr bool kTable[kModeCount][kModeCount] = {
    /* IDLE     */ {false, true, true, true, true},
    /* DETUMBLE */ {true, false, true, true, true},
    /* HOLD     */ {true, true, false, true, true},
    /* TRACK    */ {true, true, true, false, true},
    /* SAFE     */ {true, true, false, false, false},
};
}  // namespace

TransitionCheck check_transition(Mode from, Mode to, const TransitionContext& ctx) {
  const int f = static_cast<int>(from);
  const int t = static_cast<int>(to);
  if (t < 0 || t >= kModeCount || f < 0 || f >= kModeCount) return TransitionCheck::kInvalidMode;
  if (f == t) return TransitionCheck::kSameMode;
  if (!kTable[f][t]) return TransitionCheck::kNotAllowed;
  const bool actuating = to == Mode::kDetumble || to == Mode::kHold || to == Mode::kTrack;
  if (actuating && !ctx.estimate_valid) return TransitionCheck::kNoEstimate;
  if (to == Mode::kTrack) {
    if (ctx.law == LawId::kDpd) return TransitionCheck::kLawCannotTrack;
    if (!ctx.trajectory_valid) return TransitionCheck::kNoTrajectory;
  }
  return TransitionCheck::kOk;
}

void ModeManager::configure(const ModeParams& p, double omega_switch) {
  p_ = p;
  omega_switch_ = omega_switch;
}

void ModeManager::reset(Mode initial) {
  mode_ = initial;
  entered_ = true;
}

void ModeManager::go(Mode to, EventId why, ModeEvents& events) {
  events.push(ModeEvent{why, mode_, to, TransitionCheck::kOk});
  mode_ = to;
  entered_ = true;
}

void ModeManager::update(const ModeInputs& in, ModeEvents& events) {
  entered_ = false;
  if (in.has_request) {
    const TransitionCheck c = check_transition(mode_, in.request, in.ctx);
    if (c == TransitionCheck::kOk) {
      go(in.request, EventId::kModeChanged, events);
    } else {
      events.push(ModeEvent{EventId::kRequestRejected, mode_, in.request, c});
    }
  }
  // Faults first: they override everything but SAFE itself.
  if (mode_ != Mode::kSafe) {
    if (!in.state_finite) {
      go(Mode::kSafe, EventId::kNonFiniteState, events);
      return;
    }
    if (in.sensor_age_s > p_.sensor_timeout_s) {
      go(Mode::kSafe, EventId::kSensorTimeout, events);
      return;
    }
  }
  if (mode_ == Mode::kDetumble && p_.auto_hold && in.omega_norm <= omega_switch_) {
    go(Mode::kHold, EventId::kAutoHold, events);  // Eq. (51): the D+PD-based switch
  }
}

}  // namespace rocksteady::gnc
