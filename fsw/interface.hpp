// The flight application's interface as plain data: what comes in (ground commands, trajectory
// chunks, sensor samples) and what goes out (acknowledgements, events, health telemetry). No LCM
// here: the bus layer maps its messages onto these structs. See fsw/README.md.
#pragma once

#include <array>
#include <cstdint>

#include "gnc/guidance/trajectory.hpp"
#include "gnc/io.hpp"

namespace rocksteady::fsw {

// ---------------------------------------------------------------------------------------------
// Ground commands
// ---------------------------------------------------------------------------------------------

inline constexpr int kMaxCommandArgs = 8;

// The numbers are those of lcmtypes' ground_cmd_t OP_* (tied by static_assert in fsw/bus).
enum class Opcode : std::int32_t {
  kNoop = 0,            // no arguments
  kSetMode = 1,         // [mode]                      gnc::Mode
  kSetTarget = 2,       // [q1, q2, q3]                q_final, MRP, |q| <= 1
  kSetLaw = 3,          // [law] or [law, reference]   gnc::LawId, ReferenceId
  kLoadTrajectory = 4,  // [upload_id]                 hand a completely uplinked table to TRACK
  kAbortUplink = 5,     // [upload_id]                 discard an uplink in progress
  kResetCounters = 6,   // no arguments
  kParamLoad = 7,       // [param_id, v0, ...]         into the inactive table (see ParamId)
  kParamActivate = 8,   // no arguments                inactive -> active at the next tick
  kParamDiscard = 9,    // no arguments                inactive := active
  kParamDump = 10,      // no arguments                the active table -> telemetry (ParamDump)
  kKeyRotate = 11,      // [key_id]                    active command key at the next tick
  kParamLoadIdentified = 12,  // no arguments        the identified model -> the inactive table
  kFaultDeclare = 13,      // [thruster, kind]            declare a thruster failed: 1 stuck-on, 2 stuck-off
  kFaultClear = 14,        // [thruster]                  clear a declaration or confirmation (-1: all)
  kValve = 15,             // [pod, open]                 command a pod's latch valve (1 open, 0 closed)
  kIsolationInhibit = 16,  // [flag]                      1: a confirmed stuck-on no longer closes its valve
};
inline constexpr int kOpcodeCount = 17;
const char* to_string(Opcode op);

// The reference of "select law and reference" (second argument of kSetLaw).
enum class ReferenceId : std::int32_t {
  kKeep = 0,         // law only, the mode is unchanged
  kDpdRef = 1,       // D+PD-based reference, Eq. (51): DETUMBLE (then HOLD)
  kFuelOptimal = 2,  // fuel-optimal reference, Eqs. (45)-(48): TRACK
};

inline constexpr int kMacSize = 32;  // HMAC-SHA256 (fsw/auth/auth.hpp)

struct GroundCommand {
  std::int64_t seq{0};     // the key's message counter (fsw/auth), > 0
  std::int32_t source{0};  // who sent it (operator console, campaign script, ...)
  std::int32_t opcode{0};  // Opcode
  std::int32_t arg_count{0};
  std::array<double, kMaxCommandArgs> args{};
  std::int32_t key_id{0};                      // 0: unauthenticated (lab mode)
  std::array<std::uint8_t, kMacSize> mac{};    // authenticator (fsw/auth)
};

// Numbers 0..10 are those of lcmtypes' cmd_ack_t REASON_*; 11..13 are the fsw's additions.
enum class RejectReason : std::int32_t {
  kNone = 0,
  kUnknownOpcode = 1,
  kBadLength = 2,  // wrong argument count (or value count for the parameter)
  kArgNotFinite = 3,
  kOutOfRange = 4,          // detail = index of the first bad argument
  kStaleSequence = 5,       // seq not newer than the last accepted from that source
  kNotAuthenticated = 6,    // reserved for the bus layer (the core does not authenticate)
  kNotAllowedInMode = 7,    // detail = gnc::TransitionCheck when a mode transition was refused
  kTrajectoryRejected = 8,  // detail = gnc::TrajectoryError
  kBusy = 9,                // command queue full, an activation/handover already pending, ...
  kInternal = 10,
  kInvalidTable = 11,       // the parameter table fails gnc::validate; text = first bad field
  kNothingToActivate = 12,  // activate/discard with no parameter load pending
  kUploadIncomplete = 13,   // load of an uplink with missing chunks; detail = chunks received
};
const char* to_string(RejectReason r);

struct CommandAck {
  std::int64_t seq{0};
  std::int32_t source{0};
  std::int32_t opcode{0};
  bool accepted{false};
  RejectReason reason{RejectReason::kNone};
  std::int32_t detail{0};
  const char* text{""};  // static storage: safe to keep
};

// ---------------------------------------------------------------------------------------------
// Trajectory uplink (not a command: chunks are stored, the kLoadTrajectory command hands over)
// ---------------------------------------------------------------------------------------------

inline constexpr int kChunkSamples = 32;
inline constexpr int kMaxChunks = (gnc::kMaxTrajectorySamples + kChunkSamples - 1) / kChunkSamples;

struct TrajectoryChunk {
  std::int32_t upload_id{0};      // >= 0, one table's uplink
  std::int32_t chunk_index{0};    // 0 .. chunk_count - 1; carries samples [32 i, 32 i + n)
  std::int32_t chunk_count{0};    // ceil(total_samples / 32)
  std::int32_t total_samples{0};  // 2 .. gnc::kMaxTrajectorySamples
  std::uint32_t crc32{0};         // gnc::trajectory_checksum of the whole table
  std::int32_t n{0};              // samples in this chunk: 32, the last one the remainder
  std::array<gnc::TrajectorySample, kChunkSamples> samples{};
  std::int64_t seq{0};                        // the key's message counter (fsw/auth)
  std::int32_t key_id{0};                     // 0: unauthenticated (lab mode)
  std::array<std::uint8_t, kMacSize> mac{};   // authenticator (fsw/auth)
};

enum class ChunkStatus : std::uint8_t {
  kStored = 0,
  kBadHeader,       // upload id, total or chunk count out of range or inconsistent
  kBadIndex,        // chunk_index outside [0, chunk_count)
  kBadCount,        // n is not the number of samples this chunk must carry
  kHeaderMismatch,  // same upload id, different total / chunk count / CRC
  kBusy,            // a completed table is waiting for the tick boundary
  kNotAuthenticated,  // bad authenticator, unknown key or replayed counter (fsw/auth)
  kOtherUplinkActive,  // another upload id is in progress: only an authenticated ABORT_UPLINK
                       // (or its load) ends it
};
const char* to_string(ChunkStatus s);

// ---------------------------------------------------------------------------------------------
// Events
// ---------------------------------------------------------------------------------------------

// Numbers are those of lcmtypes' event_t SEV_*.
enum class Severity : std::int8_t { kDebug = 0, kInfo = 1, kWarning = 2, kError = 3, kFatal = 4 };

// The fsw's event ids (from 100, clear of gnc::EventId which the fsw translates).
enum class EventId : std::int32_t {
  kCommandAccepted = 100,      // arg0 = opcode, arg1 = low 32 bits of seq
  kCommandRejected = 101,      // arg0 = opcode, arg1 = RejectReason
  kModeChanged = 102,          // arg0 = from, arg1 = to
  kAutoHold = 103,             // DETUMBLE -> HOLD at omega_switch
  kSensorTimeout = 104,        // -> SAFE, thrusters off
  kNonFiniteState = 105,       // -> SAFE, thrusters off
  kModeRequestRejected = 106,  // at the tick boundary; arg0 = requested, arg1 = TransitionCheck
  kSensorRejected = 107,       // throttled; arg0 = rejects since the last report
  kFrameRejected = 108,        // throttled; non-finite or non-increasing frame time
  kSlip = 109,                 // throttled; arg0 = group, arg1 = slips suppressed since last
  kMissedTicks = 110,          // throttled; arg0 = ticks missed now, arg1 = suppressed reports
  kTableLoaded = 111,          // arg0 = ParamId
  kTableActivated = 112,
  kTableActivationFailed = 113,
  kTableDiscarded = 114,
  kLawChanged = 115,  // arg0 = from, arg1 = to
  kTargetSet = 116,
  kChunkRejected = 117,       // arg0 = upload id, arg1 = ChunkStatus
  kUplinkStarted = 118,       // arg0 = upload id, arg1 = chunk count
  kUplinkAbandoned = 119,     // arg0 = upload id, arg1 = chunks received
  kUplinkComplete = 120,      // all chunks received; arg0 = upload id
  kTrajectoryRejected = 121,  // arg0 = upload id, arg1 = gnc::TrajectoryError
  kTrajectoryLoaded = 122,    // handed to the flight core at the tick boundary
  kCountersReset = 123,
  kOverrunSafe = 124,  // -> SAFE: arg0 = consecutive GNC slips
  kParamsDumped = 125, // the active table read back; arg0 = dump number
  kLabMode = 126,      // warning at init: commands are NOT authenticated (explicit lab mode)
  kAuthRejected = 127, // throttled; a command/chunk failed authentication; arg0 = AuthResult,
                       // arg1 = 0 command / 1 chunk
  kKeyRotated = 128,   // arg0 = old key id, arg1 = new key id (at the tick boundary)
  kModelAdopted = 129,  // the identified model became the active table (automatic policy)
  kModelRefused = 130,  // a confident identified model failed table validation
  kModelLoaded = 131,   // PARAM_LOAD_IDENTIFIED: the identified model is in the inactive table
  kFaultSuspected = 132,   // arg0 = leading thruster (-1 none or not ranked yet), arg1 = 1 stuck-on / 2 stuck-off
  kFaultConfirmed = 133,   // arg0 = thruster, arg1 = gnc::FaultKind; latched until cleared
  kValveClosed = 134,      // arg0 = pod, arg1 = the stuck-on thruster it isolates
  kFaultOverride = 135,    // arg0 = thruster / pod / -1, arg1 = kind / 10 open / 11 close / 20, 21 inhibit
  kReducedAuthority = 136, // arg0 = rank, arg1 = usable channels
  kTrajectorySwitched = 137,  // the staged trajectory became active at the tick boundary
  kTrajectoryStale = 138,     // the staged trajectory was stale: refused, the active one kept
  kIsolationTest = 139,       // arg0 = pod whose valve the detector closed for an isolation test,
                              // arg1 = 1 started / 0 ended (the valve reopens unless confirmed)
  kJetCheck = 140,            // arg0 = thruster the detector fires for a jet check (gnc/fdi F19),
                              // arg1 = 1 started / 0 ended
};
const char* to_string(EventId id);

inline constexpr int kEventTextSize = 96;

struct Event {
  std::uint64_t seq{0};  // emitter's event counter
  double t{0.0};         // s, on-board time (time of the last GNC tick)
  Severity severity{Severity::kInfo};
  EventId id{EventId::kCommandAccepted};
  std::int32_t arg0{0};
  std::int32_t arg1{0};
  std::array<char, kEventTextSize> text{};  // NUL-terminated
};

// ---------------------------------------------------------------------------------------------
// Parameter read-back (PARAM_DUMP)
// ---------------------------------------------------------------------------------------------

inline constexpr int kMaxDumpParams = 32;
inline constexpr int kMaxParamValues = 6;

struct ParamDump {
  double t{0.0};             // on-board time of the dump
  std::uint32_t seq{0};      // dumps so far
  std::int32_t count{0};     // parameters (fsw::kParamCount)
  std::array<std::int32_t, kMaxDumpParams> value_count{};
  std::array<std::array<double, kMaxParamValues>, kMaxDumpParams> values{};
};

// ---------------------------------------------------------------------------------------------
// Health telemetry (published by the housekeeping rate group)
// ---------------------------------------------------------------------------------------------

struct RateGroupStats {
  std::uint32_t cycles{0};        // cycles run (never reset: it must keep moving)
  std::uint32_t slips{0};         // a tick arrived before the previous cycle had ended
  std::uint32_t missed_ticks{0};  // cycles of this group skipped (late wake-up, frame gap)
  std::int64_t last_exec_ns{0};   // execution time of the last cycle
  std::int64_t max_exec_ns{0};
};

struct HealthTelemetry {
  double t{0.0};                 // s, time of the last GNC tick
  std::uint64_t base_ticks{0};   // base ticks seen by the executive
  std::uint32_t base_missed{0};  // base ticks missed
  gnc::Mode mode{gnc::Mode::kIdle};
  gnc::LawId law{gnc::LawId::kNtcl};
  RateGroupStats gnc{};
  RateGroupStats housekeeping{};

  std::uint32_t cmd_accepted{0};
  std::uint32_t cmd_rejected{0};
  std::int64_t last_cmd_seq{0};
  std::int32_t last_cmd_opcode{-1};
  RejectReason last_reject{RejectReason::kNone};
  std::uint32_t cmd_pending{0};  // accepted, waiting for the tick boundary

  std::uint32_t events_emitted{0};
  std::uint32_t events_dropped{0};  // event queue full

  std::uint32_t frames_accepted{0};
  std::uint32_t frames_rejected{0};  // non-finite / non-increasing frame time
  std::uint32_t frameless_ticks{0};  // GNC ticks run without a fresh sensor frame
  std::uint32_t sensor_rejects{0};   // samples rejected by the flight core (invalid values)

  std::uint32_t table_loads{0};
  std::uint32_t table_activations{0};
  bool table_loaded{false};  // the inactive table differs from the active one

  std::int32_t uplink_id{-1};  // -1: no uplink in progress
  std::int32_t uplink_chunks_received{0};
  std::int32_t uplink_chunk_count{0};
  std::uint32_t uplink_chunks_rejected{0};
  std::uint32_t trajectories_loaded{0};
  bool trajectory_loaded{false};

  bool lab_mode{false};                 // commands are not authenticated
  std::int32_t auth_key_id{0};          // active command key (0: lab mode)
  std::uint64_t auth_rejected{0};       // failed authentication
  std::uint64_t replays_rejected{0};    // authentic but replayed / too old
};

}  // namespace rocksteady::fsw
