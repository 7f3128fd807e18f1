#include "ground/cli/dictionary.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cstdlib>

#include "gnc/guidance/trajectory.hpp"
#include "gnc/io.hpp"

namespace rocksteady::ground::cli {

namespace {

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

std::string dashes_to_underscores(std::string s) {
  std::replace(s.begin(), s.end(), '-', '_');
  return s;
}

constexpr std::array<const char*, 5> kModes{"IDLE", "DETUMBLE", "HOLD", "TRACK", "SAFE"};
constexpr std::array<const char*, 7> kLaws{"ntcl", "el",  "integral",   "adaptive",
                                           "so3",  "dpd", "feedforward"};
constexpr std::array<const char*, 3> kReferences{"keep", "dpd_ref", "fuel_optimal"};
constexpr std::array<const char*, 5> kPhases{"none", "damping", "hold", "track", "track_augmented"};

constexpr std::array<const char*, kReasonCount> kReasons{
    "accepted",
    "unknown opcode",
    "bad length",
    "argument not finite",
    "out-of-range argument",
    "stale or repeated sequence number",
    "not authenticated",
    "not allowed in this mode",
    "trajectory rejected",
    "busy",
    "internal error",
    "parameter table invalid",
    "no parameter load pending",
    "uplink incomplete",
};

constexpr std::array<const char*, kLastEventId - kFirstEventId + 1> kEvents{
    "command_accepted",
    "command_rejected",
    "mode_changed",
    "auto_hold",
    "sensor_timeout",
    "non_finite_state",
    "mode_request_rejected",
    "sensor_rejected",
    "frame_rejected",
    "slip",
    "missed_ticks",
    "table_loaded",
    "table_activated",
    "table_activation_failed",
    "table_discarded",
    "law_changed",
    "target_set",
    "chunk_rejected",
    "uplink_started",
    "uplink_abandoned",
    "uplink_complete",
    "trajectory_rejected",
    "trajectory_loaded",
    "counters_reset",
    "overrun_safe",
};

constexpr std::array<const char*, 6> kChunkStatus{
    "stored",
    "bad header (upload id, total samples or chunk count)",
    "chunk index out of range",
    "wrong number of samples in chunk",
    "header differs from the uplink in progress",
    "a completed table awaits the tick boundary",
};

constexpr std::array<const char*, 5> kSeverities{"DEBUG", "INFO", "WARNING", "ERROR", "FATAL"};

template <std::size_t N>
const char* name_or(const std::array<const char*, N>& names, int i, const char* fallback) {
  return i >= 0 && i < static_cast<int>(N) ? names[static_cast<std::size_t>(i)] : fallback;
}

template <std::size_t N>
std::optional<int> index_of(const std::array<const char*, N>& names, const std::string& key) {
  for (std::size_t i = 0; i < N; ++i) {
    if (key == names[i]) return static_cast<int>(i);
  }
  return std::nullopt;
}

}  // namespace

std::optional<int> mode_from_name(const std::string& name) {
  std::string up = name;
  std::transform(up.begin(), up.end(), up.begin(),
                 [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
  return index_of(kModes, up);
}
const char* mode_name(int mode) {
  return name_or(kModes, mode, "?");
}
std::vector<std::string> mode_names() {
  return {kModes.begin(), kModes.end()};
}

std::optional<int> law_from_name(const std::string& name) {
  return index_of(kLaws, lower(name));
}
const char* law_name(int law) {
  return name_or(kLaws, law, "?");
}
std::vector<std::string> law_names() {
  return {kLaws.begin(), kLaws.end()};
}

std::optional<int> reference_from_name(const std::string& name) {
  return index_of(kReferences, dashes_to_underscores(lower(name)));
}
const char* reference_name(int ref) {
  return name_or(kReferences, ref, "?");
}
std::vector<std::string> reference_names() {
  return {kReferences.begin(), kReferences.end()};
}

const char* phase_name(int phase) {
  return name_or(kPhases, phase, "?");
}

const std::vector<ParamEntry>& param_dictionary() {
  static const std::vector<ParamEntry> table{
      {0, "ntcl.K", ParamKind::kMatrix},
      {1, "ntcl.Lambda", ParamKind::kMatrix},
      {2, "el.K", ParamKind::kMatrix},
      {3, "el.Lambda", ParamKind::kMatrix},
      {4, "feedforward.K", ParamKind::kMatrix},
      {5, "feedforward.Lambda", ParamKind::kMatrix},
      {6, "integral.K", ParamKind::kMatrix},
      {7, "integral.Lambda", ParamKind::kMatrix},
      {8, "integral.K_I", ParamKind::kMatrix},
      {9, "integral.integral_limit", ParamKind::kScalar},
      {10, "adaptive.K", ParamKind::kMatrix},
      {11, "adaptive.Lambda", ParamKind::kMatrix},
      {12, "adaptive.Gamma", ParamKind::kScalar},
      {13, "adaptive.eig_floor_ratio", ParamKind::kScalar},
      {14, "adaptive.eig_ceiling_ratio", ParamKind::kScalar},
      {15, "so3.K", ParamKind::kMatrix},
      {16, "so3.Lambda", ParamKind::kMatrix},
      {17, "dpd.K_d", ParamKind::kMatrix},
      {18, "dpd.k_p", ParamKind::kScalar},
      {19, "guidance.omega_switch", ParamKind::kScalar},
      {20, "guidance.k_qd", ParamKind::kScalar},
      {21, "guidance.eps_trans", ParamKind::kScalar},
      {22, "guidance.track_reset_period", ParamKind::kScalar},
      {23, "mode.sensor_timeout", ParamKind::kScalar},
      {24, "mode.auto_hold", ParamKind::kFlag},
      {25, "estimator.gyro_max_rate", ParamKind::kScalar},
      {26, "estimator.quat_norm_tolerance", ParamKind::kScalar},
      {27, "estimator.omega_c", ParamKind::kScalar},
  };
  return table;
}

std::optional<ParamEntry> find_param(const std::string& name_or_id) {
  for (const ParamEntry& e : param_dictionary()) {
    if (name_or_id == e.name) return e;
  }
  // A number: all digits, within the table.
  if (!name_or_id.empty() && name_or_id.size() <= 4 &&
      std::all_of(name_or_id.begin(), name_or_id.end(),
                  [](unsigned char c) { return std::isdigit(c) != 0; })) {
    const int id = std::atoi(name_or_id.c_str());
    for (const ParamEntry& e : param_dictionary()) {
      if (e.id == id) return e;
    }
  }
  return std::nullopt;
}

std::string reason_name(int reason) {
  const char* n = name_or(kReasons, reason, nullptr);
  return n != nullptr ? std::string(n) : "reason " + std::to_string(reason);
}

std::string event_name(int id) {
  const char* n = name_or(kEvents, id - kFirstEventId, nullptr);
  return n != nullptr ? std::string(n) : "event " + std::to_string(id);
}

std::string chunk_status_name(int status) {
  const char* n = name_or(kChunkStatus, status, nullptr);
  return n != nullptr ? std::string(n) : "chunk status " + std::to_string(status);
}

const char* severity_name(int severity) {
  return name_or(kSeverities, severity, "?");
}

std::string reason_detail(int reason, int detail) {
  switch (reason) {
    case 2:
      return "count " + std::to_string(detail);
    case 3:
    case 4:
      return "argument " + std::to_string(detail);
    case 7:
      if (detail == 0) return "";
      if (detail > 0 && detail <= static_cast<int>(gnc::TransitionCheck::kInvalidMode)) {
        return gnc::to_string(static_cast<gnc::TransitionCheck>(detail));
      }
      return "transition check " + std::to_string(detail);
    case 8:
      if (detail >= 0 && detail <= static_cast<int>(gnc::TrajectoryError::kBusyTracking)) {
        return gnc::to_string(static_cast<gnc::TrajectoryError>(detail));
      }
      return "trajectory error " + std::to_string(detail);
    case 11:
      return "parameter " + std::to_string(detail);
    case 13:
      return std::to_string(detail) + " chunks received";
    default:
      return detail == 0 ? "" : "detail " + std::to_string(detail);
  }
}

}  // namespace rocksteady::ground::cli
