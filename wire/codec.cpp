#include "wire/codec.hpp"

#include <cmath>

namespace rocksteady::wire {

namespace {

template <std::size_t N> bool finite(const double (&a)[N]) {
  for (const double v : a) {
    if (!std::isfinite(v)) return false;
  }
  return true;
}
template <std::size_t N, std::size_t M> bool finite(const double (&a)[N][M]) {
  for (const auto& row : a) {
    if (!finite(row)) return false;
  }
  return true;
}
bool is_bool(std::int8_t b) { return b == 0 || b == 1; }
template <std::size_t N> bool all_bool(const std::int8_t (&a)[N]) {
  for (const std::int8_t v : a) {
    if (!is_bool(v)) return false;
  }
  return true;
}
template <std::size_t N> bool non_negative(const std::int64_t (&a)[N]) {
  for (const std::int64_t v : a) {
    if (v < 0) return false;
  }
  return true;
}

// kind and version first: a message of another type with the same layout is "bad kind".
template <class T> DecodeStatus header(const T& m) {
  if (m.kind != T::KIND) return DecodeStatus::kBadKind;
  if (m.version != T::VERSION) return DecodeStatus::kBadVersion;
  return DecodeStatus::kOk;
}

// Bounded, and no embedded '\0': the text must survive a re-encode (LCM encodes up to the first
// '\0').
bool text_ok(const std::string& text, int max_len) {
  return text.size() <= static_cast<std::size_t>(max_len) && text.find('\0') == std::string::npos;
}

DecodeStatus range(bool ok) { return ok ? DecodeStatus::kOk : DecodeStatus::kOutOfRange; }

// Canonical form: unused slots of a fixed-size array are all-zero bits, so every bit of a message
// is either a field the authenticator covers or a zero the decoder enforces (fsw/auth).
bool zero_bits(const void* p, std::size_t n) {
  const auto* b = static_cast<const unsigned char*>(p);
  for (std::size_t i = 0; i < n; ++i) {
    if (b[i] != 0) return false;
  }
  return true;
}

}  // namespace

const char* to_string(DecodeStatus s) {
  switch (s) {
    case DecodeStatus::kOk: return "ok";
    case DecodeStatus::kTooShort: return "too short";
    case DecodeStatus::kTooLong: return "too long";
    case DecodeStatus::kBadFingerprint: return "bad fingerprint";
    case DecodeStatus::kBadLength: return "bad length prefix";
    case DecodeStatus::kMalformed: return "malformed";
    case DecodeStatus::kBadKind: return "bad kind";
    case DecodeStatus::kBadVersion: return "bad version";
    case DecodeStatus::kOutOfRange: return "field out of range";
  }
  return "unknown";
}

void RxCounters::count(DecodeStatus s) {
  switch (s) {
    case DecodeStatus::kOk: ++ok; break;
    case DecodeStatus::kTooShort: ++too_short; break;
    case DecodeStatus::kTooLong: ++too_long; break;
    case DecodeStatus::kBadFingerprint: ++bad_fingerprint; break;
    case DecodeStatus::kBadLength: ++bad_length; break;
    case DecodeStatus::kMalformed: ++malformed; break;
    case DecodeStatus::kBadKind: ++bad_kind; break;
    case DecodeStatus::kBadVersion: ++bad_version; break;
    case DecodeStatus::kOutOfRange: ++out_of_range; break;
  }
}

DecodeStatus check(const rocksteady::sensor_frame_t& m) {
  if (const DecodeStatus h = header(m); h != DecodeStatus::kOk) return h;
  // Sensor values may be NaN (the HAL marks such a reading invalid); times and flags may not be.
  return range(m.seq >= 0 && std::isfinite(m.t) && std::isfinite(m.gyro_t) &&
               std::isfinite(m.star_t) && is_bool(m.gyro_valid) && is_bool(m.star_valid));
}

DecodeStatus check(const rocksteady::thruster_cmd_t& m) {
  if (const DecodeStatus h = header(m); h != DecodeStatus::kOk) return h;
  if (m.seq < 0 || !std::isfinite(m.t) || !is_bool(m.enabled) || !all_bool(m.thruster_on) ||
      !finite(m.channel_force) || !finite(m.thruster_force) || !all_bool(m.valve_closed)) {
    return DecodeStatus::kOutOfRange;
  }
  for (const double f : m.thruster_force) {
    if (f < 0.0) return DecodeStatus::kOutOfRange;
  }
  return DecodeStatus::kOk;
}

DecodeStatus check(const rocksteady::gnc_telemetry_t& m) {
  if (const DecodeStatus h = header(m); h != DecodeStatus::kOk) return h;
  return range(std::isfinite(m.t) && m.tick >= 0 && m.rate_group_count >= 0 &&
               m.rate_group_count <= rocksteady::gnc_telemetry_t::RATE_GROUPS &&
               is_bool(m.trajectory_loaded) && is_bool(m.saturated) &&
               is_bool(m.thrusters_enabled) && is_bool(m.table_loaded) && is_bool(m.lab_mode) && non_negative(m.rg_cycles) &&
               non_negative(m.rg_slips) && non_negative(m.rg_missed));
}

DecodeStatus check(const rocksteady::event_t& m) {
  if (const DecodeStatus h = header(m); h != DecodeStatus::kOk) return h;
  return range(std::isfinite(m.t) && m.severity >= rocksteady::event_t::SEV_DEBUG &&
               m.severity <= rocksteady::event_t::SEV_FATAL &&
               text_ok(m.text, rocksteady::event_t::MAX_TEXT));
}

DecodeStatus check(const rocksteady::ground_cmd_t& m) {
  if (const DecodeStatus h = header(m); h != DecodeStatus::kOk) return h;
  // Structure only: the opcode and its arguments are judged by the flight application's command
  // table, which answers with a rejection reason instead of dropping the command.
  if (m.nargs < 0 || m.nargs > rocksteady::ground_cmd_t::MAX_ARGS) return DecodeStatus::kOutOfRange;
  const std::size_t used = static_cast<std::size_t>(m.nargs);
  return range(zero_bits(&m.args[used], sizeof(double) * (rocksteady::ground_cmd_t::MAX_ARGS - used)));
}

DecodeStatus check(const rocksteady::cmd_ack_t& m) {
  if (const DecodeStatus h = header(m); h != DecodeStatus::kOk) return h;
  return range(std::isfinite(m.t) && is_bool(m.accepted) &&
               (m.accepted == 0) == (m.reason != rocksteady::cmd_ack_t::REASON_OK) &&
               text_ok(m.text, rocksteady::cmd_ack_t::MAX_TEXT));
}

DecodeStatus check(const rocksteady::plant_truth_t& m) {
  if (const DecodeStatus h = header(m); h != DecodeStatus::kOk) return h;
  return range(m.seq >= 0 && std::isfinite(m.t) && all_bool(m.valve_open) &&
               is_bool(m.command_timeout));
}

// Wire validity only; what the command asks (op, thruster, kind, factor) is the plant's to judge,
// with a reason in its answer.
DecodeStatus check(const rocksteady::plant_fault_cmd_t& m) {
  if (const DecodeStatus h = header(m); h != DecodeStatus::kOk) return h;
  return range(m.seq >= 0 && std::isfinite(m.onset_s) && std::isfinite(m.factor));
}

DecodeStatus check(const rocksteady::trajectory_chunk_t& m) {
  using C = rocksteady::trajectory_chunk_t;
  if (const DecodeStatus h = header(m); h != DecodeStatus::kOk) return h;
  if (m.upload_id < 0 || m.total_samples < 2 || m.total_samples > C::MAX_TABLE_SAMPLES) {
    return DecodeStatus::kOutOfRange;
  }
  const int chunks = (m.total_samples + C::SAMPLES - 1) / C::SAMPLES;
  if (m.total_chunks != chunks || m.chunk_index < 0 || m.chunk_index >= chunks) {
    return DecodeStatus::kOutOfRange;
  }
  const int first = m.chunk_index * C::SAMPLES;
  const int count = m.total_samples - first < C::SAMPLES ? m.total_samples - first : C::SAMPLES;
  if (m.first_sample != first || m.count != count) return DecodeStatus::kOutOfRange;
  if (m.table_crc < 0 || m.table_crc > 0xFFFFFFFFLL) return DecodeStatus::kOutOfRange;
  for (int i = 0; i < count; ++i) {
    const auto k = static_cast<std::size_t>(i);
    if (!std::isfinite(m.t[k]) || !finite(m.omega_d[k]) || !finite(m.omega_d_dot[k])) {
      return DecodeStatus::kOutOfRange;
    }
  }
  for (int i = count; i < C::SAMPLES; ++i) {
    const auto k = static_cast<std::size_t>(i);
    if (!zero_bits(&m.t[k], sizeof m.t[k]) || !zero_bits(m.omega_d[k], sizeof m.omega_d[k]) ||
        !zero_bits(m.omega_d_dot[k], sizeof m.omega_d_dot[k])) {
      return DecodeStatus::kOutOfRange;
    }
  }
  return DecodeStatus::kOk;
}

DecodeStatus check(const rocksteady::param_table_t& m) {
  using P = rocksteady::param_table_t;
  if (const DecodeStatus h = header(m); h != DecodeStatus::kOk) return h;
  if (m.count < 0 || m.count > P::MAX_PARAMS || m.dump_seq < 0 || !std::isfinite(m.t)) {
    return DecodeStatus::kOutOfRange;
  }
  for (int i = 0; i < P::MAX_PARAMS; ++i) {
    const int n = m.value_count[i];
    if (n < 0 || n > P::MAX_VALUES || (i >= m.count && n != 0)) return DecodeStatus::kOutOfRange;
    for (int k = 0; k < n; ++k) {
      if (!std::isfinite(m.values[i][k])) return DecodeStatus::kOutOfRange;
    }
  }
  return DecodeStatus::kOk;
}

}  // namespace rocksteady::wire
