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
    case ReferencePhase::kTrackSlew: return "track_slew";
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
    case EventId::kModelAdopted: return "model_adopted";
    case EventId::kModelRefused: return "model_refused";
    case EventId::kFaultSuspected: return "fault_suspected";
    case EventId::kFaultConfirmed: return "fault_confirmed";
    case EventId::kValveClosed: return "valve_closed";
    case EventId::kFaultOverride: return "fault_override";
    case EventId::kReducedAuthority: return "reduced_authority";
    case EventId::kIsolationTest: return "isolation_test";
    case EventId::kJetCheck: return "jet_check";
  }
  return "?";
}

const char* to_string(FaultKind k) {
  switch (k) {
    case FaultKind::kNone: return "none";
    case FaultKind::kStuckOn: return "stuck-on";
    case FaultKind::kStuckOff: return "stuck-off";
    case FaultKind::kDegraded: return "degraded";
  }
  return "?";
}

const char* to_string(ModelCandidate c) {
  switch (c) {
    case ModelCandidate::kOk: return "ok";
    case ModelCandidate::kDisabled: return "identification off";
    case ModelCandidate::kNotConfident: return "identification not confident";
    case ModelCandidate::kUnchanged: return "the active table already holds the identified model";
    case ModelCandidate::kInvalid: return "the identified model fails table validation";
  }
  return "?";
}

}  // namespace rocksteady::gnc
