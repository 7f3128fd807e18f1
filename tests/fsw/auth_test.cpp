// Command security (fsw/auth): authenticated commands and uplink chunks, replay and lock-out
// protection, key rotation at the tick boundary, lab mode, the key and state files. Attack tests:
// every forged, replayed or cross-kind message is rejected with no change of the flight state,
// while valid commands are still accepted, every one of them.
#include <gtest/gtest.h>

#include <sys/stat.h>
#include <unistd.h>

#include <climits>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <string>

#include <sodium.h>

#include "fsw/auth/auth.hpp"
#include "fsw/auth/key_file.hpp"
#include "fsw_harness.hpp"
#include "heap_counter.hpp"

namespace rocksteady::fsw {
namespace {

using auth::AuthResult;
using auth::Key;
using auth::MacBytes;

Key key_of(std::uint8_t fill) {
  Key k;
  for (std::size_t i = 0; i < k.size(); ++i) k[i] = static_cast<std::uint8_t>(fill + 7 * i);
  return k;
}

const Key kKey1 = key_of(1);
const Key kKey2 = key_of(101);
const Key kWrongKey = key_of(55);

FlightConfig keyed_config() {
  FlightConfig c = test::small_config();
  c.security.lab_mode = false;
  c.security.keys.count = 2;
  c.security.keys.keys[0] = {1, kKey1};
  c.security.keys.keys[1] = {2, kKey2};
  return c;
}

GroundCommand signed_cmd(std::int64_t counter, Opcode op, std::initializer_list<double> args = {},
                         std::int32_t key_id = 1, const Key& key = kKey1, std::int32_t source = 1) {
  GroundCommand c = test::command(counter, op, args, source);
  c.key_id = key_id;
  MacBytes m;
  auth::mac_command(c, key, m);
  std::memcpy(c.mac.data(), m.data(), m.size());
  return c;
}

TrajectoryChunk signed_chunk(TrajectoryChunk c, std::int64_t counter, std::int32_t key_id = 1,
                             const Key& key = kKey1) {
  c.seq = counter;
  c.key_id = key_id;
  MacBytes m;
  auth::mac_chunk(c, key, m);
  std::memcpy(c.mac.data(), m.data(), m.size());
  return c;
}

// Everything a command or chunk could change, besides the authentication counters.
struct Snapshot {
  gnc::Mode mode;
  int pending;
  std::uint32_t accepted;
  std::int64_t last_seq;
  std::int32_t last_opcode;
  bool table_loaded;
  std::int32_t uplink_id;
  std::int32_t uplink_chunks;
  std::uint64_t security_generation;
  std::int32_t active_key;
  double k_p;
  bool operator==(const Snapshot& o) const {
    return mode == o.mode && pending == o.pending && accepted == o.accepted &&
           last_seq == o.last_seq && last_opcode == o.last_opcode &&
           table_loaded == o.table_loaded && uplink_id == o.uplink_id &&
           uplink_chunks == o.uplink_chunks && security_generation == o.security_generation &&
           active_key == o.active_key && k_p == o.k_p;
  }
};

Snapshot snapshot(const FlightApp& app) {
  const HealthTelemetry h = app.health();
  return Snapshot{app.mode(),
                  app.pending_commands(),
                  h.cmd_accepted,
                  h.last_cmd_seq,
                  h.last_cmd_opcode,
                  h.table_loaded,
                  h.uplink_id,
                  h.uplink_chunks_received,
                  app.security_state().generation,
                  app.security().active_key_id(),
                  app.param_table().inactive().dpd.k_p};
}

struct KeyedFixture : test::AppFixture {
  KeyedFixture() : test::AppFixture(keyed_config()) {
    loop.truth.omega = test::V3(0.08, -0.05, 0.04);  // tumbling: DETUMBLE stays DETUMBLE
  }
  std::int64_t counter = 1000;
  CommandAck send_signed(Opcode op, std::initializer_list<double> args = {}) {
    return app->submit(signed_cmd(++counter, op, args));
  }
};

// ----------------------------------------------------------------------------------------------
// Start-up
// ----------------------------------------------------------------------------------------------

TEST(CommandSecurity, NeitherKeysNorLabModeIsRefusedAtInit) {
  FlightConfig c = test::small_config();
  c.security = auth::SecurityConfig{};
  FakeClock clock{0};
  auto app = std::make_unique<FlightApp>();
  const InitResult r = app->init(c, clock);
  EXPECT_FALSE(r.ok);
  EXPECT_STREQ(r.field, "security.keys");
  c.security.lab_mode = true;
  c.security.keys.count = 1;
  c.security.keys.keys[0] = {1, kKey1};
  EXPECT_FALSE(app->init(c, clock).ok);  // lab mode and keys are exclusive
}

// The downlink beyond acks and events: the parameter read-back of an accepted PARAM_DUMP is
// signed with the active key over every field (mac_params recomputed here), and the watchdog
// thread signs its event with the key id the tick thread published (sign_event_with), never with
// an unknown id; in lab mode nothing is signed.
TEST(CommandSecurity, ParameterReadBackAndWatchdogEventCarryTheDownlinkAuthenticator) {
  KeyedFixture f;
  f.ticks(1);
  ASSERT_TRUE(f.send_signed(Opcode::kParamDump).accepted);
  ParamDump d;
  ASSERT_TRUE(f.app->take_param_dump(d));
  std::int32_t key_id = -1;
  auth::MacBytes mac{};
  ASSERT_TRUE(f.app->security().sign_params(d, key_id, mac));
  EXPECT_EQ(key_id, 1);
  auth::MacBytes expect{};
  auth::mac_params(d, 1, kKey1, expect);
  EXPECT_TRUE(auth::mac_equal(mac, expect));
  ParamDump changed = d;
  changed.values[0][0] += 1.0;
  auth::mac_params(changed, 1, kKey1, expect);
  EXPECT_FALSE(auth::mac_equal(mac, expect));

  auth::EventFields e;
  e.t = 12.0;
  e.id = 203;
  e.arg0 = 250;
  ASSERT_TRUE(f.app->security().sign_event_with(2, e, mac));
  EXPECT_EQ(e.key_id, 2);
  auth::mac_event(e, kKey2, expect);
  EXPECT_TRUE(auth::mac_equal(mac, expect));
  EXPECT_FALSE(f.app->security().sign_event_with(3, e, mac));  // not a loaded key
  EXPECT_EQ(e.key_id, 0);

  test::AppFixture lab;  // small_config: lab mode
  EXPECT_FALSE(lab.app->security().sign_params(d, key_id, mac));
  EXPECT_EQ(key_id, 0);
  EXPECT_FALSE(lab.app->security().sign_event_with(1, e, mac));
}

TEST(CommandSecurity, LabModeIsAnnouncedAndFlaggedInTelemetry) {
  test::AppFixture lab;  // small_config: lab mode
  const std::vector<Event> ev = test::drain(*lab.app);
  EXPECT_EQ(test::count_events(ev, EventId::kLabMode), 1);
  EXPECT_TRUE(lab.app->health().lab_mode);
  lab.ticks(25);
  EXPECT_TRUE(lab.out.health.lab_mode);  // every housekeeping packet carries the flag

  KeyedFixture keyed;
  EXPECT_EQ(test::count_events(test::drain(*keyed.app), EventId::kLabMode), 0);
  EXPECT_FALSE(keyed.app->health().lab_mode);
  EXPECT_EQ(keyed.app->health().auth_key_id, 1);
}

// ----------------------------------------------------------------------------------------------
// Forgeries
// ----------------------------------------------------------------------------------------------

TEST(CommandSecurity, ValidSignedCommandsAreAcceptedEveryOne) {
  KeyedFixture f;
  for (int i = 0; i < 2000; ++i) {
    const CommandAck a = f.send_signed(Opcode::kNoop);
    ASSERT_TRUE(a.accepted) << i << ": " << a.text;
  }
  EXPECT_EQ(f.app->health().cmd_accepted, 2000u);
  f.ticks(2);  // the estimator needs a sample before DETUMBLE
  const CommandAck m = f.send_signed(Opcode::kSetMode, {1.0});
  EXPECT_TRUE(m.accepted);
  f.ticks(1);
  EXPECT_EQ(f.app->mode(), gnc::Mode::kDetumble);
}

// Every bit of every field of a signed SET_MODE SAFE, flipped one at a time, and every MAC bit.
TEST(CommandSecurity, EveryFlippedBitOfEveryFieldIsRejectedWithoutStateChange) {
  KeyedFixture f;
  f.ticks(2);
  const GroundCommand good = signed_cmd(5000, Opcode::kSetMode, {4.0});
  const Snapshot before = snapshot(*f.app);
  int tried = 0, refused = 0;
  auto attempt = [&](const GroundCommand& c) {
    ++tried;
    const CommandAck a = f.app->submit(c);
    if (!a.accepted) ++refused;
    EXPECT_FALSE(a.accepted);
    EXPECT_TRUE(a.reason == RejectReason::kNotAuthenticated ||
                a.reason == RejectReason::kStaleSequence);
  };
  for (int b = 0; b < 64; ++b) {
    GroundCommand c = good;
    c.seq ^= static_cast<std::int64_t>(1ULL << b);
    attempt(c);
  }
  for (int b = 0; b < 32; ++b) {
    const std::uint32_t bit = 1u << b;
    GroundCommand c = good;
    c.source = static_cast<std::int32_t>(static_cast<std::uint32_t>(c.source) ^ bit);
    attempt(c);
    c = good;
    c.opcode = static_cast<std::int32_t>(static_cast<std::uint32_t>(c.opcode) ^ bit);
    attempt(c);
    c = good;
    c.arg_count = static_cast<std::int32_t>(static_cast<std::uint32_t>(c.arg_count) ^ bit);
    attempt(c);
    c = good;
    c.key_id = static_cast<std::int32_t>(static_cast<std::uint32_t>(c.key_id) ^ bit);
    attempt(c);
  }
  for (int i = 0; i < kMaxCommandArgs; ++i) {
    for (int b = 0; b < 64; ++b) {
      GroundCommand c = good;
      std::uint64_t bits;
      std::memcpy(&bits, &c.args[i], 8);
      bits ^= 1ULL << b;
      std::memcpy(&c.args[i], &bits, 8);
      attempt(c);
    }
  }
  for (int i = 0; i < kMacSize; ++i) {
    for (int b = 0; b < 8; ++b) {
      GroundCommand c = good;
      c.mac[i] = static_cast<std::uint8_t>(c.mac[i] ^ (1u << b));
      attempt(c);
    }
  }
  // Zero MAC, a MAC made with a wrong key, an unknown key id, and a truncated MAC (the tail zeroed).
  GroundCommand c = good;
  c.mac.fill(0);
  attempt(c);
  attempt(signed_cmd(5000, Opcode::kSetMode, {4.0}, 1, kWrongKey));
  attempt(signed_cmd(5000, Opcode::kSetMode, {4.0}, 9, kWrongKey));
  for (int cut = 1; cut < kMacSize; ++cut) {
    c = good;
    std::memset(c.mac.data() + cut, 0, static_cast<std::size_t>(kMacSize - cut));
    attempt(c);
  }
  // An unauthenticated command as lab mode sends it.
  attempt(test::command(5000, Opcode::kSetMode, {4.0}));
  EXPECT_EQ(refused, tried);
  EXPECT_GT(tried, 900);
  EXPECT_EQ(snapshot(*f.app), before);
  f.ticks(2);
  EXPECT_NE(f.app->mode(), gnc::Mode::kSafe);
  EXPECT_EQ(f.app->health().auth_rejected, static_cast<std::uint64_t>(tried));
  // The genuine one still goes through afterwards.
  EXPECT_TRUE(f.app->submit(good).accepted);
  f.ticks(1);
  EXPECT_EQ(f.app->mode(), gnc::Mode::kSafe);
}

TEST(CommandSecurity, AuthenticationFailuresRaiseThrottledEvents) {
  KeyedFixture f;
  test::drain(*f.app);
  for (int i = 0; i < 500; ++i) f.app->submit(test::command(i + 1, Opcode::kSetMode, {4.0}));
  const std::vector<Event> ev = test::drain(*f.app);
  EXPECT_EQ(test::count_events(ev, EventId::kAuthRejected), 1);  // one per interval, not 500
  EXPECT_EQ(test::count_events(ev, EventId::kCommandRejected), 0);
  EXPECT_EQ(f.app->health().auth_rejected, 500u);
}

// ----------------------------------------------------------------------------------------------
// Replay, reordering, restart
// ----------------------------------------------------------------------------------------------

TEST(CommandSecurity, ReplayedCommandIsRejectedWithoutStateChange) {
  KeyedFixture f;
  f.ticks(2);
  const GroundCommand c = signed_cmd(77, Opcode::kSetMode, {1.0});
  EXPECT_TRUE(f.app->submit(c).accepted);
  f.ticks(1);
  const Snapshot before = snapshot(*f.app);
  const CommandAck again = f.app->submit(c);
  EXPECT_FALSE(again.accepted);
  EXPECT_EQ(again.reason, RejectReason::kStaleSequence);
  EXPECT_EQ(snapshot(*f.app), before);
  EXPECT_EQ(f.app->health().replays_rejected, 1u);
}

TEST(CommandSecurity, ReorderedCountersInsideTheWindowAreAcceptedOnceOutsideNever) {
  KeyedFixture f;
  EXPECT_TRUE(f.app->submit(signed_cmd(10, Opcode::kNoop)).accepted);
  EXPECT_TRUE(f.app->submit(signed_cmd(12, Opcode::kNoop)).accepted);
  EXPECT_TRUE(f.app->submit(signed_cmd(11, Opcode::kNoop)).accepted);  // late, in the window
  EXPECT_FALSE(f.app->submit(signed_cmd(11, Opcode::kNoop)).accepted);
  // Fill the window with kReplayWindow newer counters: 10..12 fall out of it.
  for (int i = 0; i < auth::kReplayWindow; ++i) {
    ASSERT_TRUE(f.app->submit(signed_cmd(100 + i, Opcode::kNoop)).accepted);
  }
  EXPECT_FALSE(f.app->submit(signed_cmd(13, Opcode::kNoop)).accepted);  // never seen, too old
  EXPECT_FALSE(f.app->submit(signed_cmd(12, Opcode::kNoop)).accepted);
  // Still inside: a counter between the window's oldest and newest that was never used.
  EXPECT_TRUE(f.app->submit(signed_cmd(100 + auth::kReplayWindow + 5, Opcode::kNoop)).accepted);
  EXPECT_TRUE(f.app->submit(signed_cmd(100 + auth::kReplayWindow + 2, Opcode::kNoop)).accepted);
}

// Brute force against a model: a set of every accepted counter; a counter is accepted iff it was
// never accepted and is above the floor (the smallest counter the window has forgotten).
TEST(CommandSecurity, ReplayWindowNeverAcceptsACounterTwice) {
  auth::ReplayWindow w;
  std::vector<std::int64_t> accepted;
  std::uint32_t x = 12345;
  for (int i = 0; i < 20000; ++i) {
    x = x * 1664525u + 1013904223u;
    const std::int64_t c = 1 + static_cast<std::int64_t>(i / 2) + static_cast<std::int64_t>(x % 200);
    const bool seen = std::find(accepted.begin(), accepted.end(), c) != accepted.end();
    if (w.fresh(c)) {
      ASSERT_FALSE(seen) << c;
      w.accept(c);
      accepted.push_back(c);
    }
  }
  EXPECT_GT(accepted.size(), 5000u);
}

TEST(CommandSecurity, CapturedCommandNeverVerifiesAfterARestart) {
  FlightConfig cfg = keyed_config();
  const GroundCommand captured = signed_cmd(500, Opcode::kSetMode, {1.0});
  auth::SecurityState persisted;
  {
    test::AppFixture f(cfg);
    f.ticks(2);
    EXPECT_TRUE(f.app->submit(captured).accepted);
    persisted = f.app->security_state();
  }
  // The restart restores the persisted counters (as rocksteady-fsw does from its state file).
  for (int i = 0; i < persisted.count; ++i) {
    cfg.security.restored_key[i] = persisted.key_id[i];
    cfg.security.restored_counter[i] = persisted.highest[i];
  }
  cfg.security.restored = persisted.count;
  cfg.security.active_key_id = persisted.active_key_id;
  test::AppFixture g(cfg);
  g.ticks(2);
  const Snapshot before = snapshot(*g.app);
  EXPECT_FALSE(g.app->submit(captured).accepted);
  EXPECT_FALSE(g.app->submit(signed_cmd(499, Opcode::kNoop)).accepted);  // older, never seen
  EXPECT_EQ(snapshot(*g.app), before);
  EXPECT_TRUE(g.app->submit(signed_cmd(501, Opcode::kNoop)).accepted);
}

TEST(CommandSecurity, StateFileRoundTripsAndSurvivesARestart) {
  char dir[] = "/tmp/rs-auth-XXXXXX";
  ASSERT_NE(mkdtemp(dir), nullptr);
  const std::string path = std::string(dir) + "/state";
  auth::SecurityState s;
  s.active_key_id = 2;
  s.count = 2;
  s.key_id = {1, 2, 0, 0};
  s.highest = {1700000000123456LL, 42, 0, 0};
  EXPECT_EQ(auth::write_state_file(path, s), "");
  auth::SecurityConfig c;
  bool missing = true;
  EXPECT_EQ(auth::load_state_file(path, c, missing), "");
  EXPECT_FALSE(missing);
  EXPECT_EQ(c.active_key_id, 2);
  ASSERT_EQ(c.restored, 2);
  EXPECT_EQ(c.restored_counter[0], 1700000000123456LL);
  EXPECT_EQ(c.restored_counter[1], 42);
  EXPECT_EQ(auth::load_state_file(path + ".none", c, missing), "");
  EXPECT_TRUE(missing);
  std::ofstream(path) << "rocksteady-auth-state 1\nactive x\n";
  const std::string err = auth::load_state_file(path, c, missing);
  EXPECT_NE(err.find("line 2"), std::string::npos) << err;
  std::remove(path.c_str());
  rmdir(dir);
}

// ----------------------------------------------------------------------------------------------
// Lock-out
// ----------------------------------------------------------------------------------------------

// The old lock-out: one NOOP with seq INT64_MAX from each of 16 senders filled the sender table.
TEST(CommandSecurity, ForgedSendersCannotExhaustAnyStateOrLockTheGroundOut) {
  KeyedFixture f;
  const Snapshot before = snapshot(*f.app);
  for (int s = 0; s < 1000; ++s) {
    GroundCommand c = test::command(INT64_MAX, Opcode::kNoop, {}, 100 + s);
    if (s % 2 == 1) c = signed_cmd(INT64_MAX, Opcode::kNoop, {}, 1, kWrongKey, 100 + s);
    EXPECT_FALSE(f.app->submit(c).accepted);
  }
  EXPECT_EQ(snapshot(*f.app), before);
  for (int s = 0; s < 40; ++s) {
    EXPECT_TRUE(f.app->submit(signed_cmd(++f.counter, Opcode::kNoop, {}, 1, kKey1, 500 + s)).accepted);
  }
  EXPECT_TRUE(f.app->submit(signed_cmd(++f.counter, Opcode::kSetMode, {4.0})).accepted);
}

// Even the key's holder cannot spend the counter space: a counter too far ahead is refused.
TEST(CommandSecurity, ACounterTooFarAheadIsRefusedSoNoKeyCanBeLockedOut) {
  KeyedFixture f;
  const Snapshot before = snapshot(*f.app);
  EXPECT_EQ(f.app->submit(signed_cmd(INT64_MAX, Opcode::kNoop)).reason,
            RejectReason::kStaleSequence);
  EXPECT_EQ(f.app->submit(signed_cmd(auth::kMaxCounterStep + 1, Opcode::kNoop)).reason,
            RejectReason::kStaleSequence);
  EXPECT_EQ(snapshot(*f.app), before);
  EXPECT_TRUE(f.app->submit(signed_cmd(auth::kMaxCounterStep, Opcode::kNoop)).accepted);
  EXPECT_TRUE(f.app->submit(signed_cmd(2 * auth::kMaxCounterStep, Opcode::kNoop)).accepted);
}

TEST(CommandSecurity, LabModeSendersCannotLockEachOtherOut) {
  test::AppFixture f;  // lab mode: no authentication, per-source sequence numbers
  for (int s = 0; s < 16; ++s) {
    EXPECT_TRUE(f.app->submit(test::command(INT64_MAX, Opcode::kNoop, {}, 100 + s)).accepted);
  }
  const CommandAck a = f.app->submit(test::command(1, Opcode::kSetMode, {4.0}, 1));
  EXPECT_TRUE(a.accepted) << a.text;
}

// ----------------------------------------------------------------------------------------------
// Cross-kind
// ----------------------------------------------------------------------------------------------

TEST(CommandSecurity, AChunksAuthenticatorNeverVerifiesAsACommandOrAnAck) {
  KeyedFixture f;
  auto plan = std::make_unique<gnc::TrajectoryTable>();
  test::linear_despin_table(test::V3(0.05, 0.0, 0.0), 10.0, 40, *plan);
  const std::vector<TrajectoryChunk> chunks = test::chunks_of(*plan, 3);
  const TrajectoryChunk ch = signed_chunk(chunks[0], 900);
  // A command carrying the chunk's key, counter and MAC.
  GroundCommand c = test::command(900, Opcode::kNoop);
  c.key_id = 1;
  c.mac = ch.mac;
  const Snapshot before = snapshot(*f.app);
  EXPECT_FALSE(f.app->submit(c).accepted);
  // A chunk carrying a command's MAC.
  const GroundCommand good = signed_cmd(901, Opcode::kNoop);
  TrajectoryChunk x = chunks[0];
  x.seq = 901;
  x.key_id = 1;
  x.mac = good.mac;
  EXPECT_EQ(f.app->receive_chunk(x), ChunkStatus::kNotAuthenticated);
  EXPECT_EQ(snapshot(*f.app), before);
  // The domain separation itself: the same field values give different MACs per kind.
  auth::AckFields ack;
  ack.seq = 901;
  ack.key_id = 1;
  MacBytes am;
  auth::mac_ack(ack, kKey1, am);
  EXPECT_FALSE(auth::mac_equal(am, MacBytes{good.mac}));
  EXPECT_TRUE(f.app->submit(good).accepted);
  EXPECT_EQ(f.app->receive_chunk(signed_chunk(chunks[0], 902)), ChunkStatus::kStored);
}

TEST(CommandSecurity, UplinkChunksMustBeAuthenticAndFresh) {
  KeyedFixture f;
  auto plan = std::make_unique<gnc::TrajectoryTable>();
  test::linear_despin_table(test::V3(0.05, 0.0, 0.0), 10.0, 70, *plan);
  const std::vector<TrajectoryChunk> chunks = test::chunks_of(*plan, 4);
  const Snapshot before = snapshot(*f.app);
  // Unauthenticated, wrong key, a flipped sample bit: nothing stored, no uplink started.
  EXPECT_EQ(f.app->receive_chunk(chunks[0]), ChunkStatus::kNotAuthenticated);
  EXPECT_EQ(f.app->receive_chunk(signed_chunk(chunks[0], 10, 1, kWrongKey)),
            ChunkStatus::kNotAuthenticated);
  TrajectoryChunk flipped = signed_chunk(chunks[1], 11);
  flipped.samples[5].omega_d(1) = std::nextafter(flipped.samples[5].omega_d(1), 1.0);
  EXPECT_EQ(f.app->receive_chunk(flipped), ChunkStatus::kNotAuthenticated);
  EXPECT_EQ(snapshot(*f.app), before);
  std::int64_t n = 20;
  for (const TrajectoryChunk& c : chunks) {
    EXPECT_EQ(f.app->receive_chunk(signed_chunk(c, ++n)), ChunkStatus::kStored);
  }
  EXPECT_TRUE(f.app->uplink().complete());
  // A replayed chunk is refused.
  EXPECT_EQ(f.app->receive_chunk(signed_chunk(chunks[0], 21)), ChunkStatus::kNotAuthenticated);
}

// ----------------------------------------------------------------------------------------------
// Key rotation
// ----------------------------------------------------------------------------------------------

TEST(CommandSecurity, KeyRotationTakesEffectAtTheTickBoundary) {
  KeyedFixture f;
  f.ticks(1);
  test::drain(*f.app);
  EXPECT_TRUE(f.app->submit(signed_cmd(10, Opcode::kKeyRotate, {2.0})).accepted);
  // Race before the boundary: the new key is not active yet, the old one still is.
  EXPECT_FALSE(f.app->submit(signed_cmd(11, Opcode::kNoop, {}, 2, kKey2)).accepted);
  EXPECT_TRUE(f.app->submit(signed_cmd(12, Opcode::kNoop)).accepted);
  // A second rotation while one is pending is refused.
  EXPECT_EQ(f.app->submit(signed_cmd(13, Opcode::kKeyRotate, {2.0})).reason, RejectReason::kBusy);
  EXPECT_EQ(f.app->security().active_key_id(), 1);
  f.ticks(1);
  EXPECT_EQ(f.app->security().active_key_id(), 2);
  EXPECT_EQ(test::count_events(test::drain(*f.app), EventId::kKeyRotated), 1);
  // After the boundary: the old key is retired, the new one works, with its own counters.
  const Snapshot before = snapshot(*f.app);
  EXPECT_EQ(f.app->submit(signed_cmd(14, Opcode::kSetMode, {4.0})).reason,
            RejectReason::kNotAuthenticated);
  EXPECT_EQ(snapshot(*f.app), before);
  EXPECT_TRUE(f.app->submit(signed_cmd(1, Opcode::kNoop, {}, 2, kKey2)).accepted);
  // Never back to a lower key id; unknown ids are refused.
  EXPECT_EQ(f.app->submit(signed_cmd(2, Opcode::kKeyRotate, {1.0}, 2, kKey2)).reason,
            RejectReason::kOutOfRange);
  EXPECT_EQ(f.app->submit(signed_cmd(3, Opcode::kKeyRotate, {7.0}, 2, kKey2)).reason,
            RejectReason::kOutOfRange);
  // The persisted state names the new key.
  EXPECT_EQ(f.app->security_state().active_key_id, 2);
}

TEST(CommandSecurity, KeyRotationCannotBeForged) {
  KeyedFixture f;
  EXPECT_FALSE(f.app->submit(signed_cmd(10, Opcode::kKeyRotate, {2.0}, 2, kKey2)).accepted);
  EXPECT_FALSE(f.app->submit(signed_cmd(10, Opcode::kKeyRotate, {2.0}, 1, kWrongKey)).accepted);
  f.ticks(2);
  EXPECT_EQ(f.app->security().active_key_id(), 1);
}

// ----------------------------------------------------------------------------------------------
// Acknowledgements
// ----------------------------------------------------------------------------------------------

TEST(CommandSecurity, AcknowledgementsCarryAVerifiableAuthenticator) {
  KeyedFixture f;
  auth::AckFields a;
  a.t = 12.5;
  a.seq = 44;
  a.sender_id = 3;
  a.opcode = 1;
  a.accepted = true;
  a.key_id = 1;
  a.text = "accepted";
  a.text_len = 8;
  MacBytes m;
  ASSERT_TRUE(f.app->sign_ack(a, m));
  MacBytes expect;
  auth::mac_ack(a, kKey1, expect);
  EXPECT_TRUE(auth::mac_equal(m, expect));
  auth::AckFields forged = a;
  forged.accepted = false;
  auth::mac_ack(forged, kKey1, expect);
  EXPECT_FALSE(auth::mac_equal(m, expect));
  // An unknown key id in the ack request: signed with the active key.
  a.key_id = 9;
  ASSERT_TRUE(f.app->sign_ack(a, m));
  EXPECT_EQ(a.key_id, 1);
  // Lab mode: no authenticator.
  test::AppFixture lab;
  EXPECT_FALSE(lab.app->sign_ack(a, m));
  EXPECT_EQ(a.key_id, 0);
}

TEST(CommandSecurity, EventsCarryAVerifiableAuthenticatorDistinctFromAcks) {
  KeyedFixture f;
  auth::EventFields e;
  e.t = 3.0;
  e.seq = 12;
  e.id = 120;
  e.arg0 = 4;
  e.text = "uplink complete";
  e.text_len = 15;
  MacBytes m;
  ASSERT_TRUE(f.app->sign_event(e, m));
  EXPECT_EQ(e.key_id, 1);
  MacBytes expect;
  auth::mac_event(e, kKey1, expect);
  EXPECT_TRUE(auth::mac_equal(m, expect));
  auth::EventFields forged = e;
  forged.arg0 = 5;  // another upload id
  auth::mac_event(forged, kKey1, expect);
  EXPECT_FALSE(auth::mac_equal(m, expect));
  // The same numbers as an acknowledgement never give the event's authenticator.
  auth::AckFields a;
  a.t = e.t;
  a.seq = e.seq;
  a.key_id = 1;
  a.text = e.text;
  a.text_len = e.text_len;
  auth::mac_ack(a, kKey1, expect);
  EXPECT_FALSE(auth::mac_equal(m, expect));
  test::AppFixture lab;
  EXPECT_FALSE(lab.app->sign_event(e, m));
}

// ----------------------------------------------------------------------------------------------
// Key file
// ----------------------------------------------------------------------------------------------

struct TempDir {
  std::string path;
  TempDir() {
    char d[] = "/tmp/rs-keys-XXXXXX";
    path = mkdtemp(d);
  }
  ~TempDir() { std::system(("rm -rf '" + path + "'").c_str()); }
};

TEST(KeyFile, GeneratedFileLoadsAndIsOwnerOnly) {
  TempDir d;
  const std::string p = d.path + "/keys";
  ASSERT_EQ(auth::generate_key_file(p, 2), "");
  struct stat st {};
  ASSERT_EQ(stat(p.c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0600u);
  auth::KeySet ks;
  EXPECT_EQ(auth::load_key_file(p, ks), "");
  EXPECT_EQ(ks.count, 2);
  EXPECT_EQ(ks.keys[0].id, 1);
  EXPECT_EQ(ks.keys[1].id, 2);
  EXPECT_NE(ks.keys[0].key, ks.keys[1].key);
  EXPECT_NE(auth::generate_key_file(p, 1), "");  // never overwrites
}

TEST(KeyFile, TooOpenPermissionsAndSymlinksAreRefused) {
  TempDir d;
  const std::string p = d.path + "/keys";
  ASSERT_EQ(auth::generate_key_file(p, 1), "");
  auth::KeySet ks;
  for (const mode_t m : {0640, 0604, 0644, 0660, 0601, 0610}) {
    chmod(p.c_str(), m);
    const std::string err = auth::load_key_file(p, ks);
    EXPECT_NE(err.find("too open"), std::string::npos) << std::oct << m << ": " << err;
    EXPECT_EQ(ks.count, 0);
  }
  chmod(p.c_str(), 0400);
  EXPECT_EQ(auth::load_key_file(p, ks), "");
  const std::string link = d.path + "/link";
  ASSERT_EQ(symlink(p.c_str(), link.c_str()), 0);
  EXPECT_NE(auth::load_key_file(link, ks), "");
}

TEST(KeyFile, MalformedLinesNameTheLineAndNeverTheKey) {
  TempDir d;
  const std::string p = d.path + "/keys";
  const std::string hex63 = std::string(63, 'a');
  const std::string secret = "0123456789abcdef0123456789abcdef0123456789abcdef0123456789abcdef";
  const struct {
    std::string text;
    const char* expect;
  } cases[] = {
      {"# c\n1 " + hex63 + "\n", "line 2"},
      {"1 " + secret + "\n1 " + secret + "\n", "duplicate key id"},
      {"0 " + secret + "\n", "positive key id"},
      {"x " + secret + "\n", "line 1"},
      {"1 " + secret + " extra\n", "64 hex digits"},
      {"\n# nothing\n", "no key"},
  };
  for (const auto& c : cases) {
    std::remove(p.c_str());
    {
      std::ofstream(p) << c.text;
    }
    chmod(p.c_str(), 0600);
    auth::KeySet ks;
    const std::string err = auth::load_key_file(p, ks);
    EXPECT_NE(err.find(c.expect), std::string::npos) << err;
    EXPECT_EQ(err.find(secret.substr(0, 16)), std::string::npos) << err;
  }
}

// ----------------------------------------------------------------------------------------------
// No heap in the authenticated command path
// ----------------------------------------------------------------------------------------------

TEST(CommandSecurity, VerifyingCommandsAndChunksAllocatesNothing) {
  KeyedFixture f;
  auto plan = std::make_unique<gnc::TrajectoryTable>();
  test::linear_despin_table(test::V3(0.05, 0.0, 0.0), 10.0, 70, *plan);
  std::vector<TrajectoryChunk> chunks = test::chunks_of(*plan, 1);
  for (std::size_t i = 0; i < chunks.size(); ++i) chunks[i] = signed_chunk(chunks[i], 100 + i);
  const GroundCommand good = signed_cmd(200, Opcode::kSetMode, {1.0});
  const GroundCommand forged = signed_cmd(201, Opcode::kSetMode, {4.0}, 1, kWrongKey);
  const GroundCommand rotate = signed_cmd(202, Opcode::kKeyRotate, {2.0});
  const GroundCommand after = signed_cmd(1, Opcode::kNoop, {}, 2, kKey2);
  auth::AckFields a;
  MacBytes m;
  Event e;
  f.ticks(2);
  long allocations = -1;
  {
    const rocksteady::test::HeapArmed armed;
    for (const TrajectoryChunk& c : chunks) f.app->receive_chunk(c);
    f.app->submit(forged);
    f.app->submit(good);
    f.app->submit(good);  // replay
    f.app->submit(rotate);
    f.app->sign_ack(a, m);
    for (int i = 0; i < 3; ++i) {
      f.clock.advance(50000000);
      f.loop.tick(*f.app, f.out);
    }
    f.app->submit(after);
    while (f.app->pop_event(e)) {
    }
    allocations = rocksteady::test::heap_allocations();
  }
  EXPECT_EQ(allocations, 0);
  EXPECT_EQ(f.app->security().active_key_id(), 2);
  EXPECT_TRUE(f.app->uplink().complete());
  EXPECT_EQ(f.app->mode(), gnc::Mode::kDetumble);
}

}  // namespace
}  // namespace rocksteady::fsw
