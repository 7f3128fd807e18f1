// Command security: authenticated ground commands, uplink chunks and acknowledgements, replay and
// lock-out protection, key rotation.
//
// Authenticator: HMAC-SHA256 (libsodium's crypto_auth_hmacsha256, never our own crypto) over a
// canonical encoding of the message: a domain string, the channel name and the message kind, then
// every field in a fixed order, big-endian, doubles as their IEEE-754 bit patterns (so -0.0, 0.0 and
// every NaN payload differ). The channel and kind are part of the MAC input, so a chunk's bytes can
// never verify as a command or an acknowledgement (LCM's fingerprints ignore type names), and a
// message authenticated for one channel never verifies on another. Comparison is constant-time
// (crypto_verify_32).
//
// Replay protection: every key has one monotonic message counter shared by commands and chunks
// (the ground stamps counters from the key's counter file, at least its wall-clock microseconds).
// A ReplayWindow remembers the kReplayWindow most recent accepted counters of its key: a counter
// above every one seen is accepted; an older one only when it is inside the window (newer than the
// oldest counter remembered, or than the restored floor) and not yet seen (reordering); anything
// else is a replay. The state is changed only
// by an authentic message, so forged or unauthenticated traffic cannot consume it: no sequence of
// forged messages can lock the ground out (the old per-sender slot table is gone). Across a reboot
// the highest counter of each key and the active key id are restored from the state file
// (fsw/auth/key_file.hpp): after a restart, the floor is that counter, so a captured message never
// verifies again.
//
// Keys: up to kMaxKeys (id > 0, 32 bytes) loaded at start-up from the key file; exactly one is active.
// KEY_ROTATE (authenticated by the active key) makes a key with a higher id active at the next GNC
// tick boundary; lower ids can never become active again. Keys are never logged, evented or
// telemetered: nothing here exposes them, and acknowledgements carry only the key id.
//
// Lab mode: no keys, explicit start-up flag only (FlightConfig::security.lab_mode); announced by an
// event at init and flagged in every telemetry packet. Commands are then unauthenticated and not
// replay protected; acknowledgements carry no authenticator.
//
// No heap, no exceptions, no I/O: the verifier runs inside the flight's command path. The HMAC
// state lives on the stack.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "fsw/interface.hpp"

namespace rocksteady::fsw::auth {

inline constexpr int kKeyBytes = 32;
inline constexpr int kMacBytes = 32;
inline constexpr int kMaxKeys = 4;
inline constexpr int kReplayWindow = 64;
// A counter more than this above the key's highest is refused (kBadCounter): 2^53 us is 285 years,
// so no run of authentic commands can spend a key's counter space (a lock-out by its own holder).
inline constexpr std::int64_t kMaxCounterStep = std::int64_t{1} << 53;

using Key = std::array<std::uint8_t, kKeyBytes>;
using MacBytes = std::array<std::uint8_t, kMacBytes>;

// What a MAC covers (domain separation; the numbers are the lcmtypes KIND of each message).
enum class MessageKind : std::int16_t { kEvent = 4, kCommand = 5, kAck = 6, kChunk = 8, kParams = 9 };

struct KeyEntry {
  std::int32_t id{0};  // > 0
  Key key{};
};

struct KeySet {
  std::array<KeyEntry, kMaxKeys> keys{};
  int count{0};
  const KeyEntry* find(std::int32_t id) const;
};

// The acknowledgement's fields as they go on the bus (cmd_ack_t without kind/version/mac).
struct AckFields {
  double t{0.0};
  std::int64_t seq{0};
  std::int32_t sender_id{0};
  std::int32_t opcode{0};
  bool accepted{false};
  std::int32_t reason{0};
  std::int32_t detail{0};
  std::int32_t key_id{0};
  const char* text{""};
  std::size_t text_len{0};
};

// An event's fields as they go on the bus (event_t without kind/version/mac).
struct EventFields {
  double t{0.0};
  std::int64_t seq{0};
  std::int32_t severity{0};
  std::int32_t id{0};
  std::int32_t arg0{0};
  std::int32_t arg1{0};
  std::int32_t key_id{0};
  const char* text{""};
  std::size_t text_len{0};
};

// The MACs (the command's and chunk's key_id/seq are inside the structs).
void mac_command(const GroundCommand& cmd, const Key& key, MacBytes& out);
void mac_chunk(const TrajectoryChunk& chunk, const Key& key, MacBytes& out);
void mac_ack(const AckFields& ack, const Key& key, MacBytes& out);
void mac_event(const EventFields& event, const Key& key, MacBytes& out);
// The parameter read-back (RS_PARAMS): every field of the dump, with the signing key's id.
void mac_params(const ParamDump& dump, std::int32_t key_id, const Key& key, MacBytes& out);
// Constant-time comparison of two MACs.
bool mac_equal(const MacBytes& a, const MacBytes& b);

// The last kReplayWindow accepted counters of one key.
class ReplayWindow {
 public:
  // After a restart: everything at or below `floor` is a replay.
  void restore(std::int64_t floor);
  // True when `counter` has not been accepted and is inside the window.
  bool fresh(std::int64_t counter) const;
  // Records an accepted counter (call only after fresh() and authentication).
  void accept(std::int64_t counter);
  std::int64_t highest() const { return highest_; }
  std::int64_t floor() const { return floor_; }

 private:
  std::array<std::int64_t, kReplayWindow> seen_{};
  int count_{0};
  std::int64_t floor_{0};
  std::int64_t highest_{0};
};

// What the security layer starts with: keys and the persisted state.
struct SecurityConfig {
  bool lab_mode{false};  // explicit: no keys, no authentication (announced, flagged in telemetry)
  KeySet keys{};
  std::int32_t active_key_id{0};  // 0: the lowest key id in `keys`
  // Persisted replay state: highest accepted counter per key id (pairs, `restored` of them).
  std::array<std::int32_t, kMaxKeys> restored_key{};
  std::array<std::int64_t, kMaxKeys> restored_counter{};
  int restored{0};
};

// What survives a reboot (written by the bus layer to the state file when `generation` changes).
struct SecurityState {
  std::uint64_t generation{0};
  std::int32_t active_key_id{0};
  int count{0};
  std::array<std::int32_t, kMaxKeys> key_id{};
  std::array<std::int64_t, kMaxKeys> highest{};
};

enum class AuthResult : std::uint8_t {
  kOk = 0,
  kLabMode,        // not checked (lab mode)
  kUnknownKey,     // key id not in the key set, or not the active key
  kBadMac,         // authenticator does not match (forged, altered, truncated, zero)
  kReplay,         // counter already used, or at/below the window's floor
  kBadCounter,     // counter <= 0, or more than kMaxCounterStep above the highest
};
const char* to_string(AuthResult r);

class CommandSecurity {
 public:
  // {ok, field, reason}: no keys without lab mode, keys with lab mode, bad ids, unknown active id.
  struct InitCheck {
    bool ok{true};
    const char* field{""};
    const char* reason{""};
  };
  InitCheck init(const SecurityConfig& config);

  bool lab_mode() const { return lab_mode_; }
  std::int32_t active_key_id() const { return active_; }

  // Verifies a command / chunk against the active key and its replay window; on kOk the counter is
  // consumed (an authentic command is never accepted twice, whatever its outcome). Anything else
  // changes no state except the rejection counters.
  AuthResult verify(const GroundCommand& cmd);
  AuthResult verify(const TrajectoryChunk& chunk);

  // KEY_ROTATE: may `key_id` become active? (known, higher than the active id)
  bool can_rotate_to(std::int32_t key_id) const;
  // At the tick boundary: the key becomes active (false if not allowed).
  bool rotate(std::int32_t key_id);

  // Downlink authenticator for an acknowledgement: with key `key_id` when it is a known key that is
  // not retired (the command's key), else the active key. Sets ack.key_id. False in lab mode.
  bool sign_ack(AckFields& ack, MacBytes& out) const;
  // Downlink authenticator of an event, with the active key (sets event.key_id). False in lab mode.
  bool sign_event(EventFields& event, MacBytes& out) const;
  // The same with a given key (the watchdog thread signs with the key id the tick thread last
  // published; it reads only the key material, which is fixed after init). False in lab mode or
  // for an unknown id.
  bool sign_event_with(std::int32_t key_id, EventFields& event, MacBytes& out) const;
  // Downlink authenticator of the parameter read-back, with the active key. False in lab mode.
  bool sign_params(const ParamDump& dump, std::int32_t& key_id, MacBytes& out) const;

  const SecurityState& state() const { return state_; }
  std::uint64_t auth_rejected() const { return auth_rejected_; }
  std::uint64_t replays_rejected() const { return replays_rejected_; }
  std::uint32_t rotations() const { return rotations_; }

 private:
  int slot_of(std::int32_t key_id) const;
  template <class Msg, class MacFn>
  AuthResult verify_message(const Msg& m, MacFn mac_of);
  AuthResult check_counter(int slot, std::int64_t counter);
  void consume(int slot, std::int64_t counter);
  void refresh_state();

  bool lab_mode_{false};
  KeySet keys_{};
  std::array<ReplayWindow, kMaxKeys> windows_{};
  std::int32_t active_{0};
  SecurityState state_{};
  std::uint64_t auth_rejected_{0};
  std::uint64_t replays_rejected_{0};
  std::uint32_t rotations_{0};
};

}  // namespace rocksteady::fsw::auth
