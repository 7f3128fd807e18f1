#include "ground/cli/dictionary.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cstdlib>

#include "gnc/guidance/trajectory.hpp"
#include "gnc/io.hpp"
#include "fsw/params/param_table.hpp"
#include "ground/dictionary/dictionary.hpp"

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

// The names come from the generated dictionary (ground/dictionary): the dictionary's own enums
// (mode, law, phase, reference, severity) and the flight's tables (reason, event, opcode).
const char* enum_cstr(const char* enum_name, int value, const char* fallback) {
  const auto& e = dictionary::generated::enums();
  const auto it = e.find(enum_name);
  if (it == e.end()) return fallback;
  const auto v = it->second.find(value);
  return v == it->second.end() ? fallback : v->second.c_str();
}

std::optional<int> enum_index(const char* enum_name, const std::string& key) {
  return dictionary::enum_value(enum_name, key);
}

constexpr std::array<const char*, 8> kChunkStatus{
    "stored",
    "bad header (upload id, total samples or chunk count)",
    "chunk index out of range",
    "wrong number of samples in chunk",
    "header differs from the uplink in progress",
    "a completed table awaits the tick boundary",
    "not authenticated (bad authenticator, unknown key or replayed counter)",
    "another uplink is in progress: abort it first",
};

template <std::size_t N>
const char* name_or(const std::array<const char*, N>& names, int i, const char* fallback) {
  return i >= 0 && i < static_cast<int>(N) ? names[static_cast<std::size_t>(i)] : fallback;
}

}  // namespace

std::optional<int> mode_from_name(const std::string& name) {
  std::string up = name;
  std::transform(up.begin(), up.end(), up.begin(),
                 [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
  return enum_index("mode", up);
}
const char* mode_name(int mode) {
  return enum_cstr("mode", mode, "?");
}
std::vector<std::string> mode_names() {
  return dictionary::enum_names("mode");
}

std::optional<int> law_from_name(const std::string& name) {
  return enum_index("law", lower(name));
}
const char* law_name(int law) {
  return enum_cstr("law", law, "?");
}
std::vector<std::string> law_names() {
  return dictionary::enum_names("law");
}

std::optional<int> reference_from_name(const std::string& name) {
  return enum_index("reference", dashes_to_underscores(lower(name)));
}
const char* reference_name(int ref) {
  return enum_cstr("reference", ref, "?");
}
std::vector<std::string> reference_names() {
  return dictionary::enum_names("reference");
}

const char* phase_name(int phase) {
  return enum_cstr("phase", phase, "?");
}

const std::vector<ParamEntry>& param_dictionary() {
  static const std::vector<ParamEntry> table = [] {
    std::vector<ParamEntry> t;
    for (const fsw::ParamSpec& s : fsw::param_specs()) {
      const ParamKind kind = s.kind == fsw::ParamKind::kMatrix   ? ParamKind::kMatrix
                             : s.kind == fsw::ParamKind::kScalar ? ParamKind::kScalar
                                                                 : ParamKind::kFlag;
      t.push_back(ParamEntry{static_cast<int>(s.id), s.name, kind, s.units});
    }
    return t;
  }();
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
  const char* n = enum_cstr("reason", reason, nullptr);
  return n != nullptr ? std::string(n) : "reason " + std::to_string(reason);
}

std::string event_name(int id) {
  const char* n = enum_cstr("event", id, nullptr);
  return n != nullptr ? std::string(n) : "event " + std::to_string(id);
}

std::string chunk_status_name(int status) {
  const char* n = name_or(kChunkStatus, status, nullptr);
  return n != nullptr ? std::string(n) : "chunk status " + std::to_string(status);
}

const char* severity_name(int severity) {
  return enum_cstr("severity", severity, "?");
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
