#include "gnc/io.hpp"

namespace rocksteady::gnc {

const char* to_string(Mode m) {
  switch (m) {
    case Mode::kIdle: return "IDLE";
    case Mode::kDetumble: return "DETUMBLE";
    case Mode::kHold: return "HOLD";
    case Mode::kTrack: return "TRACK";
    case Mode::kSafe: return "SAFE";
  }
  return "?";
}

const char* to_string(LawId l) {
  switch (l) {
    case LawId::kNtcl: return "ntcl";
    case LawId::kNtclEl: return "el";
    case LawId::kIntegral: return "integral";
    case LawId::kAdaptive: return "adaptive";
    case LawId::kSo3: return "so3";
    case LawId::kDpd: return "dpd";
    case LawId::kFeedforward: return "feedforward";
  }
  return "?";
}

const char* to_string(ReferencePhase p) {
  switch (p) {
    case ReferencePhase::kNone: return "none";
    case ReferencePhase::kDamping: return "damping";
    case ReferencePhase::kHold: return "hold";
    case ReferencePhase::kTrack: return "track";
    case ReferencePhase::kTrackAugmented: return "track_augmented";
  }
  return "?";
}

const char* to_string(TransitionCheck c) {
  switch (c) {
    case TransitionCheck::kOk: return "ok";
    case TransitionCheck::kSameMode: return "already in that mode";
    case TransitionCheck::kNotAllowed: return "transition not allowed";
    case TransitionCheck::kNoTrajectory: return "no valid trajectory loaded";
    case TransitionCheck::kLawCannotTrack: return "the D+PD law cannot track a trajectory";
    case TransitionCheck::kNoEstimate: return "no valid state estimate";
    case TransitionCheck::kInvalidMode: return "unknown mode";
  }
  return "?";
}

const char* to_string(EventId e) {
  switch (e) {
    case EventId::kModeChanged: return "mode_changed";
    case EventId::kAutoHold: return "auto_hold";
    case EventId::kSensorTimeout: return "sensor_timeout";
    case EventId::kNonFiniteState: return "non_finite_state";
    case EventId::kRequestRejected: return "request_rejected";
    case EventId::kSensorRejected: return "sensor_rejected";
    case EventId::kTrajectorySwitched: return "trajectory_switched";
    case EventId::kTrajectoryStale: return "trajectory_stale";
  }
  return "?";
}

}  // namespace rocksteady::gnc
