#include "fsw/interface.hpp"

namespace rocksteady::fsw {

const char* to_string(Opcode op) {
  switch (op) {
    case Opcode::kNoop:
      return "NOOP";
    case Opcode::kSetMode:
      return "SET_MODE";
    case Opcode::kSetTarget:
      return "SET_TARGET";
    case Opcode::kSetLaw:
      return "SET_LAW";
    case Opcode::kLoadTrajectory:
      return "LOAD_TRAJECTORY";
    case Opcode::kAbortUplink:
      return "ABORT_UPLINK";
    case Opcode::kResetCounters:
      return "RESET_COUNTERS";
    case Opcode::kParamLoad:
      return "PARAM_LOAD";
    case Opcode::kParamActivate:
      return "PARAM_ACTIVATE";
    case Opcode::kParamDiscard:
      return "PARAM_DISCARD";
    case Opcode::kParamDump:
      return "PARAM_DUMP";
    case Opcode::kKeyRotate:
      return "KEY_ROTATE";
    case Opcode::kParamLoadIdentified:
      return "PARAM_LOAD_IDENTIFIED";
    case Opcode::kFaultDeclare:
      return "FAULT_DECLARE";
    case Opcode::kFaultClear:
      return "FAULT_CLEAR";
    case Opcode::kValve:
      return "VALVE";
    case Opcode::kIsolationInhibit:
      return "ISOLATION_INHIBIT";
  }
  return "?";
}

const char* to_string(RejectReason r) {
  switch (r) {
    case RejectReason::kNone:
      return "accepted";
    case RejectReason::kUnknownOpcode:
      return "unknown opcode";
    case RejectReason::kBadLength:
      return "bad length";
    case RejectReason::kArgNotFinite:
      return "argument not finite";
    case RejectReason::kOutOfRange:
      return "out-of-range argument";
    case RejectReason::kStaleSequence:
      return "stale or repeated sequence number";
    case RejectReason::kNotAuthenticated:
      return "not authenticated";
    case RejectReason::kNotAllowedInMode:
      return "not allowed in this mode";
    case RejectReason::kTrajectoryRejected:
      return "trajectory rejected";
    case RejectReason::kBusy:
      return "busy";
    case RejectReason::kInternal:
      return "internal error";
    case RejectReason::kInvalidTable:
      return "parameter table invalid";
    case RejectReason::kNothingToActivate:
      return "no parameter load pending";
    case RejectReason::kUploadIncomplete:
      return "uplink incomplete";
  }
  return "?";
}

const char* to_string(ChunkStatus s) {
  switch (s) {
    case ChunkStatus::kStored:
      return "stored";
    case ChunkStatus::kBadHeader:
      return "bad header (upload id, total samples or chunk count)";
    case ChunkStatus::kBadIndex:
      return "chunk index out of range";
    case ChunkStatus::kBadCount:
      return "wrong number of samples in chunk";
    case ChunkStatus::kHeaderMismatch:
      return "header differs from the uplink in progress";
    case ChunkStatus::kBusy:
      return "a completed table awaits the tick boundary";
    case ChunkStatus::kNotAuthenticated:
      return "not authenticated (bad authenticator, unknown key or replayed counter)";
    case ChunkStatus::kOtherUplinkActive:
      return "another uplink is in progress: abort it first";
  }
  return "?";
}

const char* to_string(EventId id) {
  switch (id) {
    case EventId::kCommandAccepted:
      return "command_accepted";
    case EventId::kCommandRejected:
      return "command_rejected";
    case EventId::kModeChanged:
      return "mode_changed";
    case EventId::kAutoHold:
      return "auto_hold";
    case EventId::kSensorTimeout:
      return "sensor_timeout";
    case EventId::kNonFiniteState:
      return "non_finite_state";
    case EventId::kModeRequestRejected:
      return "mode_request_rejected";
    case EventId::kSensorRejected:
      return "sensor_rejected";
    case EventId::kFrameRejected:
      return "frame_rejected";
    case EventId::kSlip:
      return "slip";
    case EventId::kMissedTicks:
      return "missed_ticks";
    case EventId::kTableLoaded:
      return "table_loaded";
    case EventId::kTableActivated:
      return "table_activated";
    case EventId::kTableActivationFailed:
      return "table_activation_failed";
    case EventId::kTableDiscarded:
      return "table_discarded";
    case EventId::kLawChanged:
      return "law_changed";
    case EventId::kTargetSet:
      return "target_set";
    case EventId::kChunkRejected:
      return "chunk_rejected";
    case EventId::kUplinkStarted:
      return "uplink_started";
    case EventId::kUplinkAbandoned:
      return "uplink_abandoned";
    case EventId::kUplinkComplete:
      return "uplink_complete";
    case EventId::kTrajectoryRejected:
      return "trajectory_rejected";
    case EventId::kTrajectoryLoaded:
      return "trajectory_loaded";
    case EventId::kCountersReset:
      return "counters_reset";
    case EventId::kOverrunSafe:
      return "overrun_safe";
    case EventId::kParamsDumped:
      return "params_dumped";
    case EventId::kLabMode:
      return "lab_mode";
    case EventId::kAuthRejected:
      return "auth_rejected";
    case EventId::kKeyRotated:
      return "key_rotated";
    case EventId::kModelAdopted:
      return "model_adopted";
    case EventId::kModelRefused:
      return "model_refused";
    case EventId::kModelLoaded:
      return "model_loaded";
    case EventId::kFaultSuspected:
      return "fault_suspected";
    case EventId::kFaultConfirmed:
      return "fault_confirmed";
    case EventId::kValveClosed:
      return "valve_closed";
    case EventId::kFaultOverride:
      return "fault_override";
    case EventId::kReducedAuthority:
      return "reduced_authority";
    case EventId::kTrajectorySwitched:
      return "trajectory_switched";
    case EventId::kTrajectoryStale:
      return "trajectory_stale";
    case EventId::kIsolationTest:
      return "isolation_test";
    case EventId::kJetCheck:
      return "jet_check";
  }
  return "?";
}

}  // namespace rocksteady::fsw
