// Safe decoding of the bus messages. LCM 1.3.1's generated decode() throws on a negative array count
// or a non-positive string length and can over-read on a huge count (ENVIRONMENT.md), and its
// fingerprint ignores the type's name. safe_decode() therefore
//   1. bounds the length and checks the fingerprint itself,
//   2. checks the exact encoded size before decode() runs: every type is fixed-size, except event_t
//      and cmd_ack_t whose only variable part is their last field (a string), whose length prefix is
//      checked first,
//   3. calls decode() inside a catch-all (the only try/catch of the HAL),
//   4. checks the decoded fields: kind and version, counts, booleans, finiteness.
// A rejected message is counted and left unused; nothing here aborts. Decoding a fixed-size type
// does not allocate.
#pragma once

#include <cstdint>
#include <cstring>

#include "lcmtypes/channels.hpp"
#include "rocksteady/cmd_ack_t.hpp"
#include "rocksteady/event_t.hpp"
#include "rocksteady/gnc_telemetry_t.hpp"
#include "rocksteady/ground_cmd_t.hpp"
#include "rocksteady/plant_fault_cmd_t.hpp"
#include "rocksteady/plant_truth_t.hpp"
#include "rocksteady/sensor_frame_t.hpp"
#include "rocksteady/thruster_cmd_t.hpp"
#include "rocksteady/param_table_t.hpp"
#include "rocksteady/trajectory_chunk_t.hpp"

namespace rocksteady::wire {

// Messages stay well below LCM's ~65 KB fragmentation limit; anything longer is not ours.
inline constexpr int kMaxMessageBytes = 60000;

enum class DecodeStatus : std::uint8_t {
  kOk = 0,
  kTooShort,        // shorter than the fingerprint or the type's size
  kTooLong,         // longer than the type's size (or kMaxMessageBytes)
  kBadFingerprint,  // another type, or another version of the layout
  kBadLength,       // a length prefix disagrees with the buffer
  kMalformed,       // decode() failed or threw
  kBadKind,         // right layout, wrong `kind` (another type with the same layout)
  kBadVersion,
  kOutOfRange,      // decoded, but a field is out of range (count, boolean, NaN, ...)
};
const char* to_string(DecodeStatus s);

struct RxCounters {
  std::uint64_t ok{0};
  std::uint64_t too_short{0};
  std::uint64_t too_long{0};
  std::uint64_t bad_fingerprint{0};
  std::uint64_t bad_length{0};
  std::uint64_t malformed{0};
  std::uint64_t bad_kind{0};
  std::uint64_t bad_version{0};
  std::uint64_t out_of_range{0};

  void count(DecodeStatus s);
  // The groups gnc_telemetry_t reports (rx_malformed, rx_bad_kind, rx_out_of_range).
  std::uint64_t malformed_total() const {
    return too_short + too_long + bad_fingerprint + bad_length + malformed;
  }
  std::uint64_t bad_kind_total() const { return bad_kind + bad_version; }
  std::uint64_t rejected() const { return malformed_total() + bad_kind_total() + out_of_range; }
};

// Field checks of decoded messages (step 4). Also usable on messages built locally.
DecodeStatus check(const rocksteady::sensor_frame_t& m);
DecodeStatus check(const rocksteady::thruster_cmd_t& m);
DecodeStatus check(const rocksteady::gnc_telemetry_t& m);
DecodeStatus check(const rocksteady::event_t& m);
DecodeStatus check(const rocksteady::ground_cmd_t& m);
DecodeStatus check(const rocksteady::cmd_ack_t& m);
DecodeStatus check(const rocksteady::plant_truth_t& m);
DecodeStatus check(const rocksteady::trajectory_chunk_t& m);
DecodeStatus check(const rocksteady::param_table_t& m);
DecodeStatus check(const rocksteady::plant_fault_cmd_t& m);

// Each type's channel (lcmtypes/channels.hpp).
template <class T> const char* channel_of();
template <> inline const char* channel_of<rocksteady::sensor_frame_t>() { return channels::kSensors; }
template <> inline const char* channel_of<rocksteady::thruster_cmd_t>() { return channels::kThrusterCmd; }
template <> inline const char* channel_of<rocksteady::gnc_telemetry_t>() { return channels::kGncTelemetry; }
template <> inline const char* channel_of<rocksteady::event_t>() { return channels::kEvents; }
template <> inline const char* channel_of<rocksteady::ground_cmd_t>() { return channels::kGroundCmd; }
template <> inline const char* channel_of<rocksteady::cmd_ack_t>() { return channels::kCmdAck; }
template <> inline const char* channel_of<rocksteady::plant_truth_t>() { return channels::kPlantTruth; }
template <> inline const char* channel_of<rocksteady::trajectory_chunk_t>() { return channels::kTrajUplink; }
template <> inline const char* channel_of<rocksteady::param_table_t>() { return channels::kParams; }
template <> inline const char* channel_of<rocksteady::plant_fault_cmd_t>() { return channels::kPlantFault; }

// Types whose only variable-length field is a trailing string.
template <class T> struct HasTrailingString { static constexpr bool value = false; };
template <> struct HasTrailingString<rocksteady::event_t> { static constexpr bool value = true; };
template <> struct HasTrailingString<rocksteady::cmd_ack_t> { static constexpr bool value = true; };

// A fresh message with kind and version set (everything else zero).
template <class T> T make() {
  T m{};
  m.kind = T::KIND;
  m.version = T::VERSION;
  return m;
}

namespace detail {

inline std::uint64_t read_be64(const unsigned char* p) {
  std::uint64_t v = 0;
  for (int i = 0; i < 8; ++i) v = (v << 8) | p[i];
  return v;
}
inline std::int32_t read_be32(const unsigned char* p) {
  const std::uint32_t v = (std::uint32_t{p[0]} << 24) | (std::uint32_t{p[1]} << 16) |
                          (std::uint32_t{p[2]} << 8) | std::uint32_t{p[3]};
  std::int32_t s;
  std::memcpy(&s, &v, sizeof s);
  return s;
}

// Encoded size (fingerprint included) of a message whose variable parts are empty.
template <class T> int base_size() {
  static const int size = T{}.getEncodedSize();
  return size;
}

// Steps 1-2: length, fingerprint and layout checks on the raw bytes.
template <class T> DecodeStatus precheck(const unsigned char* p, int len) {
  if (p == nullptr || len < 8) return DecodeStatus::kTooShort;
  if (len > kMaxMessageBytes) return DecodeStatus::kTooLong;
  const auto hash = static_cast<std::uint64_t>(T::getHash());
  if (read_be64(p) != hash) return DecodeStatus::kBadFingerprint;
  const int base = base_size<T>();
  if (len < base) return DecodeStatus::kTooShort;
  if constexpr (HasTrailingString<T>::value) {
    // Layout: [fixed fields][int32 n][n bytes, the last one '\0']; the empty string has n = 1.
    const int n = read_be32(p + (base - 5));
    if (n < 1 || n > len) return DecodeStatus::kBadLength;
    if (base - 1 + n != len) return len > base - 1 + n ? DecodeStatus::kTooLong : DecodeStatus::kBadLength;
    if (p[len - 1] != 0) return DecodeStatus::kBadLength;
  } else {
    if (len > base) return DecodeStatus::kTooLong;
  }
  return DecodeStatus::kOk;
}

}  // namespace detail

// Decode `len` bytes at `buf` into `out`. `out` is unspecified unless kOk is returned.
template <class T> DecodeStatus decode(const void* buf, int len, T& out) {
  const auto* p = static_cast<const unsigned char*>(buf);
  const DecodeStatus pre = detail::precheck<T>(p, len);
  if (pre != DecodeStatus::kOk) return pre;
  try {
    if (out.decode(buf, 0, len) != len) return DecodeStatus::kMalformed;
  } catch (...) {
    return DecodeStatus::kMalformed;
  }
  return check(out);
}

// decode(), counted. True when `out` holds a checked message.
template <class T> bool safe_decode(const void* buf, int len, T& out, RxCounters* counters = nullptr) {
  const DecodeStatus s = decode(buf, len, out);
  if (counters != nullptr) counters->count(s);
  return s == DecodeStatus::kOk;
}

// Encode into `buf` (capacity `cap`). Returns the encoded length, or -1 if it does not fit.
template <class T> int encode(const T& msg, void* buf, int cap) {
  const int size = msg.getEncodedSize();
  if (size > cap) return -1;
  return msg.encode(buf, 0, cap) == size ? size : -1;
}

}  // namespace rocksteady::wire
