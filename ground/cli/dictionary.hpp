// The ground's command and telemetry dictionary: the names an operator types and reads, mapped to
// the numbers on the bus (lcmtypes' ground_cmd_t OP_*, cmd_ack_t REASON_*, the fsw's event ids and
// parameter ids). Names come from the generated dictionary (ground/dictionary); tests/ground_cli
// checks it against the flight application's tables entry by entry.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace rocksteady::ground::cli {

// gnc::Mode numbers and names (IDLE, DETUMBLE, HOLD, TRACK, SAFE).
std::optional<int> mode_from_name(const std::string& name);  // case-insensitive
const char* mode_name(int mode);                             // "?" outside 0..4
std::vector<std::string> mode_names();

// gnc::LawId numbers and names (ntcl, el, integral, adaptive, so3, dpd, feedforward).
std::optional<int> law_from_name(const std::string& name);
const char* law_name(int law);
std::vector<std::string> law_names();

// fsw::ReferenceId: keep (0), dpd-ref (1), fuel-optimal (2). '_' and '-' are interchangeable.
std::optional<int> reference_from_name(const std::string& name);
const char* reference_name(int ref);
std::vector<std::string> reference_names();

// gnc::ReferencePhase names (none, damping, hold, track, track_augmented).
const char* phase_name(int phase);

// Loadable parameters (fsw::ParamId), with the number of values each takes.
enum class ParamKind : std::uint8_t { kMatrix, kScalar, kFlag };
struct ParamEntry {
  int id;
  const char* name;  // as in fsw/README.md: "ntcl.K", "guidance.omega_switch", ...
  ParamKind kind;
  const char* units;
};
// The flight's own parameter table (fsw::param_specs): one source of ids, names, kinds and units.
const std::vector<ParamEntry>& param_dictionary();
// By name (case-sensitive, as in the README) or by number.
std::optional<ParamEntry> find_param(const std::string& name_or_id);

// cmd_ack_t REASON_* (fsw::RejectReason) descriptions; "reason N" for an unknown number.
std::string reason_name(int reason);
inline constexpr int kReasonCount = 14;

// fsw::EventId names (100..139), gnc-level event names are not on the bus; "event N" otherwise.
std::string event_name(int id);
inline constexpr int kFirstEventId = 100;
inline constexpr int kLastEventId = 139;
// The plant's (simulator's) event ids start here (event_t.id); they carry no flight authenticator.
inline constexpr int kFirstPlantEventId = 1000;
// Event ids the uplink procedure listens to.
inline constexpr int kEventChunkRejected = 117;
inline constexpr int kEventUplinkStarted = 118;
inline constexpr int kEventUplinkAbandoned = 119;
inline constexpr int kEventUplinkComplete = 120;
inline constexpr int kEventTrajectoryRejected = 121;
inline constexpr int kEventTrajectoryLoaded = 122;

// fsw::ChunkStatus descriptions (arg1 of chunk_rejected).
std::string chunk_status_name(int status);
// fsw::ChunkStatus::kOtherUplinkActive: the flight has another upload in progress and refuses
// this one until the ground aborts it.
inline constexpr int kChunkStatusOtherUplinkActive = 7;

// event_t SEV_* names (DEBUG .. FATAL).
const char* severity_name(int severity);

// Detail of a rejection, decoded where the reason defines it (transition check, trajectory error).
std::string reason_detail(int reason, int detail);

}  // namespace rocksteady::ground::cli
