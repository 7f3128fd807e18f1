// Safe decoding: every malformed buffer is counted and rejected, never thrown, never over-read.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include "wire/codec.hpp"

namespace rocksteady::wire {
namespace {

using Bytes = std::vector<unsigned char>;

template <class T> Bytes encode_bytes(const T& m) {
  Bytes b(static_cast<std::size_t>(m.getEncodedSize()));
  EXPECT_EQ(encode(m, b.data(), static_cast<int>(b.size())), static_cast<int>(b.size()));
  return b;
}

rocksteady::sensor_frame_t sample_frame() {
  auto m = make<rocksteady::sensor_frame_t>();
  m.seq = 42;
  m.t = 4.2;
  m.gyro_t = 4.19;
  m.gyro_rate[0] = 0.01;
  m.gyro_rate[1] = -0.02;
  m.gyro_rate[2] = 0.03;
  m.gyro_valid = 1;
  m.star_t = 4.18;
  m.star_quat[3] = 1.0;
  m.star_valid = 1;
  return m;
}

rocksteady::event_t sample_event(const std::string& text) {
  auto m = make<rocksteady::event_t>();
  m.t = 12.5;
  m.seq = 3;
  m.severity = rocksteady::event_t::SEV_WARNING;
  m.id = 7;
  m.text = text;
  return m;
}

// Offset of a field in the encoded sensor_frame_t: 8 (fingerprint) + kind 2 + version 2 + seq 8 + ...
constexpr std::size_t kFrameKindOffset = 8;
constexpr std::size_t kFrameVersionOffset = 10;
constexpr std::size_t kFrameGyroValidOffset = 8 + 2 + 2 + 8 + 8 + 8 + 24;

TEST(SafeDecode, RoundTripsAValidMessage) {
  const auto m = sample_frame();
  const Bytes b = encode_bytes(m);
  rocksteady::sensor_frame_t out{};
  RxCounters c;
  ASSERT_TRUE(safe_decode(b.data(), static_cast<int>(b.size()), out, &c));
  EXPECT_EQ(encode_bytes(out), b);
  EXPECT_EQ(c.ok, 1u);
  EXPECT_EQ(c.rejected(), 0u);
}

TEST(SafeDecode, RejectsEveryTruncation) {
  const Bytes b = encode_bytes(sample_frame());
  RxCounters c;
  for (std::size_t n = 0; n < b.size(); ++n) {
    // Exactly n bytes on the heap, so an over-read is caught by ASan builds.
    const Bytes cut(b.begin(), b.begin() + static_cast<std::ptrdiff_t>(n));
    rocksteady::sensor_frame_t out{};
    EXPECT_EQ(decode(cut.data(), static_cast<int>(n), out), DecodeStatus::kTooShort) << n;
    safe_decode(cut.data(), static_cast<int>(n), out, &c);
  }
  EXPECT_EQ(c.too_short, b.size());
  EXPECT_EQ(c.ok, 0u);
}

TEST(SafeDecode, RejectsNullAndOversizedBuffers) {
  rocksteady::sensor_frame_t out{};
  EXPECT_EQ(decode(nullptr, 100, out), DecodeStatus::kTooShort);
  Bytes b = encode_bytes(sample_frame());
  b.push_back(0);
  EXPECT_EQ(decode(b.data(), static_cast<int>(b.size()), out), DecodeStatus::kTooLong);
  Bytes huge(static_cast<std::size_t>(kMaxMessageBytes) + 1);
  std::memcpy(huge.data(), b.data(), b.size());
  EXPECT_EQ(decode(huge.data(), static_cast<int>(huge.size()), out), DecodeStatus::kTooLong);
}

TEST(SafeDecode, RejectsAWrongFingerprint) {
  Bytes b = encode_bytes(sample_frame());
  b[3] ^= 0x10;
  rocksteady::sensor_frame_t out{};
  EXPECT_EQ(decode(b.data(), static_cast<int>(b.size()), out), DecodeStatus::kBadFingerprint);
  // Another type's message on the wrong channel.
  const Bytes other = encode_bytes(make<rocksteady::plant_truth_t>());
  EXPECT_EQ(decode(other.data(), static_cast<int>(other.size()), out), DecodeStatus::kBadFingerprint);
}

TEST(SafeDecode, RejectsWrongKindAndVersion) {
  Bytes b = encode_bytes(sample_frame());
  b[kFrameKindOffset + 1] = static_cast<unsigned char>(rocksteady::thruster_cmd_t::KIND);
  rocksteady::sensor_frame_t out{};
  EXPECT_EQ(decode(b.data(), static_cast<int>(b.size()), out), DecodeStatus::kBadKind);
  b = encode_bytes(sample_frame());
  b[kFrameVersionOffset + 1] = 99;
  EXPECT_EQ(decode(b.data(), static_cast<int>(b.size()), out), DecodeStatus::kBadVersion);
}

TEST(SafeDecode, RejectsOutOfRangeFields) {
  Bytes b = encode_bytes(sample_frame());
  ASSERT_EQ(b[kFrameGyroValidOffset], 1);  // the offset really is gyro_valid
  b[kFrameGyroValidOffset] = 2;            // a boolean that is neither 0 nor 1
  rocksteady::sensor_frame_t out{};
  EXPECT_EQ(decode(b.data(), static_cast<int>(b.size()), out), DecodeStatus::kOutOfRange);

  auto m = sample_frame();
  m.t = std::numeric_limits<double>::quiet_NaN();
  b = encode_bytes(m);
  EXPECT_EQ(decode(b.data(), static_cast<int>(b.size()), out), DecodeStatus::kOutOfRange);
  m = sample_frame();
  m.seq = -1;
  b = encode_bytes(m);
  EXPECT_EQ(decode(b.data(), static_cast<int>(b.size()), out), DecodeStatus::kOutOfRange);

  auto cmd = make<rocksteady::ground_cmd_t>();
  for (const std::int8_t nargs : {std::int8_t{-1}, std::int8_t{9}, std::int8_t{-128}}) {
    cmd.nargs = nargs;
    b = encode_bytes(cmd);
    rocksteady::ground_cmd_t cout{};
    EXPECT_EQ(decode(b.data(), static_cast<int>(b.size()), cout), DecodeStatus::kOutOfRange);
  }
}

TEST(SafeDecode, SensorValuesMayBeNaNButAreDeliveredAsSuch) {
  // NaN readings are the sensor layer's to reject (as invalid readings), not the bus's.
  auto m = sample_frame();
  m.gyro_rate[1] = std::numeric_limits<double>::quiet_NaN();
  const Bytes b = encode_bytes(m);
  rocksteady::sensor_frame_t out{};
  ASSERT_EQ(decode(b.data(), static_cast<int>(b.size()), out), DecodeStatus::kOk);
  EXPECT_TRUE(std::isnan(out.gyro_rate[1]));
}

// --- event_t: the one type with a variable-length field (its trailing string) --------------------

Bytes event_with_length_prefix(std::int32_t n) {
  Bytes b = encode_bytes(sample_event("abc"));  // ... [int32 4]['a' 'b' 'c' '\0']
  const std::size_t at = b.size() - 8;
  const auto u = static_cast<std::uint32_t>(n);
  b[at] = static_cast<unsigned char>(u >> 24);
  b[at + 1] = static_cast<unsigned char>(u >> 16);
  b[at + 2] = static_cast<unsigned char>(u >> 8);
  b[at + 3] = static_cast<unsigned char>(u);
  return b;
}

TEST(SafeDecodeEvent, RoundTripsText) {
  for (const std::string& text : {std::string(), std::string("thruster 5 stuck"),
                                  std::string(static_cast<std::size_t>(rocksteady::event_t::MAX_TEXT), 'x')}) {
    const Bytes b = encode_bytes(sample_event(text));
    rocksteady::event_t out{};
    ASSERT_EQ(decode(b.data(), static_cast<int>(b.size()), out), DecodeStatus::kOk) << text;
    EXPECT_EQ(out.text, text);
  }
}

TEST(SafeDecodeEvent, NegativeAndZeroLengthsAreRejectedWhereLcmDecodeThrows) {
  for (const std::int32_t n : {0, -1, -5, std::numeric_limits<std::int32_t>::min()}) {
    const Bytes b = event_with_length_prefix(n);
    if (n != std::numeric_limits<std::int32_t>::min()) {
      // The hazard: LCM 1.3.1's own decode() throws on these (and with INT32_MIN, n - 1 wraps to
      // INT32_MAX and it reads 2 GB past the buffer: not something a test can call).
      rocksteady::event_t raw{};
      EXPECT_ANY_THROW(raw.decode(b.data(), 0, static_cast<int>(b.size()))) << n;
    }
    rocksteady::event_t out{};
    EXPECT_EQ(decode(b.data(), static_cast<int>(b.size()), out), DecodeStatus::kBadLength) << n;
  }
}

TEST(SafeDecodeEvent, HugeAndInconsistentLengthsAreRejected) {
  for (const std::int32_t n : {5, 3, 1000, 0x7fffffff}) {
    const Bytes b = event_with_length_prefix(n);
    rocksteady::event_t out{};
    const DecodeStatus s = decode(b.data(), static_cast<int>(b.size()), out);
    EXPECT_TRUE(s == DecodeStatus::kBadLength || s == DecodeStatus::kTooLong) << n << ' ' << to_string(s);
  }
  Bytes b = encode_bytes(sample_event("abc"));
  b.back() = 'x';  // no terminator
  rocksteady::event_t out{};
  EXPECT_EQ(decode(b.data(), static_cast<int>(b.size()), out), DecodeStatus::kBadLength);
}

TEST(SafeDecodeEvent, TooLongOrEmbeddedNulTextIsOutOfRange) {
  const std::string long_text(static_cast<std::size_t>(rocksteady::event_t::MAX_TEXT) + 1, 'y');
  Bytes b = encode_bytes(sample_event(long_text));
  rocksteady::event_t out{};
  EXPECT_EQ(decode(b.data(), static_cast<int>(b.size()), out), DecodeStatus::kOutOfRange);
  b = encode_bytes(sample_event("abcd"));
  b[b.size() - 3] = 0;  // "ab\0d"
  EXPECT_EQ(decode(b.data(), static_cast<int>(b.size()), out), DecodeStatus::kOutOfRange);
}

TEST(SafeDecodeAck, CarriesItsTextAndChecksTheVerdict) {
  auto a = make<rocksteady::cmd_ack_t>();
  a.seq = 5;
  a.accepted = 0;
  a.reason = rocksteady::cmd_ack_t::REASON_ARG_OUT_OF_RANGE;
  a.detail = 1;
  a.text = "mode out of range";
  Bytes b = encode_bytes(a);
  rocksteady::cmd_ack_t out{};
  ASSERT_EQ(decode(b.data(), static_cast<int>(b.size()), out), DecodeStatus::kOk);
  EXPECT_EQ(out.text, a.text);
  a.accepted = 1;  // accepted with a rejection reason
  b = encode_bytes(a);
  EXPECT_EQ(decode(b.data(), static_cast<int>(b.size()), out), DecodeStatus::kOutOfRange);
  a.accepted = 0;
  a.text = std::string(static_cast<std::size_t>(rocksteady::cmd_ack_t::MAX_TEXT) + 1, 'z');
  b = encode_bytes(a);
  EXPECT_EQ(decode(b.data(), static_cast<int>(b.size()), out), DecodeStatus::kOutOfRange);
}

// --- every type, random bytes behind a correct fingerprint -----------------------------------------

template <class T> void random_buffers_never_escape(std::uint32_t seed) {
  std::mt19937 rng(seed);
  const Bytes good = encode_bytes(make<T>());
  RxCounters c;
  for (int i = 0; i < 3000; ++i) {
    Bytes b = good;
    const int mode = i % 3;
    if (mode == 0) {  // random length, random body, correct fingerprint
      b.resize(std::uniform_int_distribution<std::size_t>(8, good.size() + 40)(rng));
      for (std::size_t k = 8; k < b.size(); ++k) b[k] = static_cast<unsigned char>(rng());
    } else {  // a few flipped bytes
      for (int f = 0; f < 1 + mode; ++f) {
        b[std::uniform_int_distribution<std::size_t>(0, b.size() - 1)(rng)] ^=
            static_cast<unsigned char>(1u + rng() % 255u);
      }
    }
    T out{};
    if (safe_decode(b.data(), static_cast<int>(b.size()), out, &c)) {
      EXPECT_EQ(encode_bytes(out), b);  // anything accepted re-encodes to the same bytes
    }
  }
  EXPECT_EQ(c.ok + c.rejected(), 3000u);
}

TEST(SafeDecode, RandomBuffersAreCountedNeverThrownForEveryType) {
  random_buffers_never_escape<rocksteady::sensor_frame_t>(1);
  random_buffers_never_escape<rocksteady::thruster_cmd_t>(2);
  random_buffers_never_escape<rocksteady::gnc_telemetry_t>(3);
  random_buffers_never_escape<rocksteady::event_t>(4);
  random_buffers_never_escape<rocksteady::ground_cmd_t>(5);
  random_buffers_never_escape<rocksteady::cmd_ack_t>(6);
  random_buffers_never_escape<rocksteady::plant_truth_t>(7);
  random_buffers_never_escape<rocksteady::trajectory_chunk_t>(8);
}

TEST(RxCounters, GroupTheStatusesAsTelemetryReportsThem) {
  RxCounters c;
  for (const DecodeStatus s :
       {DecodeStatus::kOk, DecodeStatus::kTooShort, DecodeStatus::kTooLong, DecodeStatus::kBadFingerprint,
        DecodeStatus::kBadLength, DecodeStatus::kMalformed, DecodeStatus::kBadKind,
        DecodeStatus::kBadVersion, DecodeStatus::kOutOfRange, DecodeStatus::kOutOfRange}) {
    c.count(s);
  }
  EXPECT_EQ(c.ok, 1u);
  EXPECT_EQ(c.malformed_total(), 5u);
  EXPECT_EQ(c.bad_kind_total(), 2u);
  EXPECT_EQ(c.out_of_range, 2u);
  EXPECT_EQ(c.rejected(), 9u);
}

TEST(Channels, EachTypeHasItsOwnChannel) {
  const char* names[] = {channel_of<rocksteady::sensor_frame_t>(), channel_of<rocksteady::thruster_cmd_t>(),
                         channel_of<rocksteady::gnc_telemetry_t>(), channel_of<rocksteady::event_t>(),
                         channel_of<rocksteady::ground_cmd_t>(),    channel_of<rocksteady::cmd_ack_t>(),
                         channel_of<rocksteady::plant_truth_t>(),   channel_of<rocksteady::trajectory_chunk_t>()};
  for (std::size_t i = 0; i < 8; ++i) {
    EXPECT_EQ(std::strncmp(names[i], "RS_", 3), 0);
    for (std::size_t j = i + 1; j < 8; ++j) EXPECT_STRNE(names[i], names[j]);
  }
}

}  // namespace
}  // namespace rocksteady::wire
