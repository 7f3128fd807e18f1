#include "fsw/auth/auth.hpp"

#include <cstring>

#include <sodium.h>

namespace rocksteady::fsw::auth {

namespace {

// Version of the canonical encoding; a change of layout changes it.
constexpr char kDomain[] = "rocksteady-auth-v1";
constexpr char kChannelCommand[] = "RS_GROUND_CMD";
constexpr char kChannelChunk[] = "RS_TRAJ_UPLINK";
constexpr char kChannelAck[] = "RS_CMD_ACK";
constexpr char kChannelEvents[] = "RS_EVENTS";
constexpr char kChannelParams[] = "RS_PARAMS";
constexpr std::int16_t kParamsVersion = 2;  // param_table_t VERSION (with key_id and mac)
constexpr std::int16_t kVersion = 1;  // the messages' VERSION

// The canonical encoder: fields go straight into the HMAC state (nothing buffered, no heap).
class Canonical {
 public:
  Canonical(const Key& key, const char* channel, MessageKind kind) {
    crypto_auth_hmacsha256_init(&st_, key.data(), key.size());
    bytes(kDomain, sizeof kDomain - 1);
    u32(static_cast<std::uint32_t>(std::strlen(channel)));
    bytes(channel, std::strlen(channel));
    i16(static_cast<std::int16_t>(kind));
    i16(kVersion);
  }
  void bytes(const void* p, std::size_t n) {
    crypto_auth_hmacsha256_update(&st_, static_cast<const unsigned char*>(p), n);
  }
  void u64(std::uint64_t v) {
    unsigned char b[8];
    for (int i = 0; i < 8; ++i) b[i] = static_cast<unsigned char>(v >> (56 - 8 * i));
    bytes(b, 8);
  }
  void u32(std::uint32_t v) {
    unsigned char b[4];
    for (int i = 0; i < 4; ++i) b[i] = static_cast<unsigned char>(v >> (24 - 8 * i));
    bytes(b, 4);
  }
  void i16(std::int16_t v) {
    const auto u = static_cast<std::uint16_t>(v);
    const unsigned char b[2] = {static_cast<unsigned char>(u >> 8),
                                static_cast<unsigned char>(u & 0xFF)};
    bytes(b, 2);
  }
  void i64(std::int64_t v) { u64(static_cast<std::uint64_t>(v)); }
  void i32(std::int32_t v) { u32(static_cast<std::uint32_t>(v)); }
  void f64(double v) {
    std::uint64_t bits;
    std::memcpy(&bits, &v, sizeof bits);
    u64(bits);
  }
  void finish(MacBytes& out) { crypto_auth_hmacsha256_final(&st_, out.data()); }

 private:
  crypto_auth_hmacsha256_state st_{};
};

}  // namespace

const KeyEntry* KeySet::find(std::int32_t id) const {
  for (int i = 0; i < count && i < kMaxKeys; ++i) {
    if (keys[static_cast<std::size_t>(i)].id == id) return &keys[static_cast<std::size_t>(i)];
  }
  return nullptr;
}

void mac_command(const GroundCommand& cmd, const Key& key, MacBytes& out) {
  Canonical c(key, kChannelCommand, MessageKind::kCommand);
  c.i32(cmd.key_id);
  c.i64(cmd.seq);
  c.i32(cmd.source);
  c.i32(cmd.opcode);
  c.i32(cmd.arg_count);
  for (const double a : cmd.args) c.f64(a);
  c.finish(out);
}

void mac_chunk(const TrajectoryChunk& chunk, const Key& key, MacBytes& out) {
  Canonical c(key, kChannelChunk, MessageKind::kChunk);
  c.i32(chunk.key_id);
  c.i64(chunk.seq);
  c.i32(chunk.upload_id);
  c.i32(chunk.chunk_index);
  c.i32(chunk.chunk_count);
  c.i32(chunk.total_samples);
  c.u32(chunk.crc32);
  c.i32(chunk.n);
  for (const gnc::TrajectorySample& s : chunk.samples) {
    c.f64(s.t);
    for (int a = 0; a < 3; ++a) c.f64(s.omega_d(a));
    for (int a = 0; a < 3; ++a) c.f64(s.omega_d_dot(a));
  }
  c.finish(out);
}

void mac_ack(const AckFields& ack, const Key& key, MacBytes& out) {
  Canonical c(key, kChannelAck, MessageKind::kAck);
  c.i32(ack.key_id);
  c.f64(ack.t);
  c.i64(ack.seq);
  c.i32(ack.sender_id);
  c.i32(ack.opcode);
  c.i32(ack.accepted ? 1 : 0);
  c.i32(ack.reason);
  c.i32(ack.detail);
  c.u32(static_cast<std::uint32_t>(ack.text_len));
  c.bytes(ack.text, ack.text_len);
  c.finish(out);
}

void mac_event(const EventFields& e, const Key& key, MacBytes& out) {
  Canonical c(key, kChannelEvents, MessageKind::kEvent);
  c.i32(e.key_id);
  c.f64(e.t);
  c.i64(e.seq);
  c.i32(e.severity);
  c.i32(e.id);
  c.i32(e.arg0);
  c.i32(e.arg1);
  c.u32(static_cast<std::uint32_t>(e.text_len));
  c.bytes(e.text, e.text_len);
  c.finish(out);
}

void mac_params(const ParamDump& d, std::int32_t key_id, const Key& key, MacBytes& out) {
  Canonical c(key, kChannelParams, MessageKind::kParams);
  c.i16(kParamsVersion);
  c.i32(key_id);
  c.f64(d.t);
  c.u32(d.seq);
  c.i32(d.count);
  for (const std::int32_t n : d.value_count) c.i32(n);
  for (const auto& row : d.values) {
    for (const double v : row) c.f64(v);
  }
  c.finish(out);
}

bool mac_equal(const MacBytes& a, const MacBytes& b) {
  return crypto_verify_32(a.data(), b.data()) == 0;
}

// ----------------------------------------------------------------------------------------------
// Replay window
// ----------------------------------------------------------------------------------------------

void ReplayWindow::restore(std::int64_t floor) {
  count_ = 0;
  floor_ = floor < 0 ? 0 : floor;
  highest_ = floor_;
}

bool ReplayWindow::fresh(std::int64_t counter) const {
  if (counter <= floor_) return false;
  std::int64_t oldest = counter;
  for (int i = 0; i < count_; ++i) {
    const std::int64_t s = seen_[static_cast<std::size_t>(i)];
    if (s == counter) return false;
    if (s < oldest) oldest = s;
  }
  // A full window covers [its oldest counter, ...): anything older is outside it.
  return count_ < kReplayWindow || counter > oldest;
}

void ReplayWindow::accept(std::int64_t counter) {
  if (count_ < kReplayWindow) {
    seen_[static_cast<std::size_t>(count_++)] = counter;
  } else {
    // Full: forget the oldest remembered counter (fresh() guarantees this one is newer); it becomes
    // the floor, so it and everything below stay refused. Invariant: every accepted counter above
    // the floor is in seen_.
    int oldest = 0;
    for (int i = 1; i < count_; ++i) {
      if (seen_[static_cast<std::size_t>(i)] < seen_[static_cast<std::size_t>(oldest)]) oldest = i;
    }
    const std::int64_t dropped = seen_[static_cast<std::size_t>(oldest)];
    if (dropped > floor_) floor_ = dropped;
    seen_[static_cast<std::size_t>(oldest)] = counter;
  }
  if (counter > highest_) highest_ = counter;
}

// ----------------------------------------------------------------------------------------------
// Command security
// ----------------------------------------------------------------------------------------------

const char* to_string(AuthResult r) {
  switch (r) {
    case AuthResult::kOk:
      return "authentic";
    case AuthResult::kLabMode:
      return "lab mode (not authenticated)";
    case AuthResult::kUnknownKey:
      return "unknown or inactive key id";
    case AuthResult::kBadMac:
      return "authenticator does not match";
    case AuthResult::kReplay:
      return "replayed or too old counter";
    case AuthResult::kBadCounter:
      return "counter not positive or too far ahead";
  }
  return "?";
}

CommandSecurity::InitCheck CommandSecurity::init(const SecurityConfig& config) {
  *this = CommandSecurity{};
  if (config.lab_mode) {
    if (config.keys.count != 0) {
      return {false, "security.lab_mode", "lab mode and command keys are exclusive"};
    }
    lab_mode_ = true;
    refresh_state();
    return {};
  }
  if (config.keys.count <= 0 || config.keys.count > kMaxKeys) {
    return {false, "security.keys",
            "no command key (give a key file, or start in lab mode explicitly)"};
  }
  std::int32_t lowest = 0;
  for (int i = 0; i < config.keys.count; ++i) {
    const std::int32_t id = config.keys.keys[static_cast<std::size_t>(i)].id;
    if (id <= 0) return {false, "security.keys", "key ids must be positive"};
    for (int j = 0; j < i; ++j) {
      if (config.keys.keys[static_cast<std::size_t>(j)].id == id) {
        return {false, "security.keys", "duplicate key id"};
      }
    }
    if (lowest == 0 || id < lowest) lowest = id;
  }
  keys_ = config.keys;
  active_ = config.active_key_id != 0 ? config.active_key_id : lowest;
  if (keys_.find(active_) == nullptr) {
    return {false, "security.active_key_id", "the active key id is not in the key file"};
  }
  for (int i = 0; i < config.restored && i < kMaxKeys; ++i) {
    const int s = slot_of(config.restored_key[static_cast<std::size_t>(i)]);
    if (s >= 0) windows_[static_cast<std::size_t>(s)].restore(config.restored_counter[static_cast<std::size_t>(i)]);
  }
  refresh_state();
  return {};
}

int CommandSecurity::slot_of(std::int32_t key_id) const {
  for (int i = 0; i < keys_.count; ++i) {
    if (keys_.keys[static_cast<std::size_t>(i)].id == key_id) return i;
  }
  return -1;
}

AuthResult CommandSecurity::check_counter(int slot, std::int64_t counter) {
  const ReplayWindow& w = windows_[static_cast<std::size_t>(slot)];
  if (counter <= 0 || counter - w.highest() > kMaxCounterStep) return AuthResult::kBadCounter;
  if (!w.fresh(counter)) return AuthResult::kReplay;
  return AuthResult::kOk;
}

void CommandSecurity::consume(int slot, std::int64_t counter) {
  windows_[static_cast<std::size_t>(slot)].accept(counter);
  refresh_state();
}

void CommandSecurity::refresh_state() {
  state_.generation += 1;
  state_.active_key_id = active_;
  state_.count = keys_.count;
  for (int i = 0; i < keys_.count; ++i) {
    state_.key_id[static_cast<std::size_t>(i)] = keys_.keys[static_cast<std::size_t>(i)].id;
    state_.highest[static_cast<std::size_t>(i)] = windows_[static_cast<std::size_t>(i)].highest();
  }
}

// Key, MAC (constant time), then the replay window; only an authentic, fresh message consumes its
// counter. `mac_of` computes the expected MAC of the message with the slot's key.
template <class Msg, class MacFn>
AuthResult CommandSecurity::verify_message(const Msg& m, MacFn mac_of) {
  if (lab_mode_) return AuthResult::kLabMode;
  const int slot = m.key_id == active_ ? slot_of(m.key_id) : -1;
  if (slot < 0) {
    ++auth_rejected_;
    return AuthResult::kUnknownKey;
  }
  MacBytes expect;
  mac_of(m, keys_.keys[static_cast<std::size_t>(slot)].key, expect);
  MacBytes got;
  std::memcpy(got.data(), m.mac.data(), got.size());
  const bool ok = mac_equal(expect, got);
  sodium_memzero(expect.data(), expect.size());
  if (!ok) {
    ++auth_rejected_;
    return AuthResult::kBadMac;
  }
  const AuthResult c = check_counter(slot, m.seq);
  if (c != AuthResult::kOk) {
    ++replays_rejected_;
    return c;
  }
  consume(slot, m.seq);
  return AuthResult::kOk;
}

AuthResult CommandSecurity::verify(const GroundCommand& cmd) {
  return verify_message(cmd, [](const GroundCommand& c, const auto& key, MacBytes& out) {
    mac_command(c, key, out);
  });
}

AuthResult CommandSecurity::verify(const TrajectoryChunk& chunk) {
  return verify_message(chunk, [](const TrajectoryChunk& c, const auto& key, MacBytes& out) {
    mac_chunk(c, key, out);
  });
}

bool CommandSecurity::can_rotate_to(std::int32_t key_id) const {
  return !lab_mode_ && key_id > active_ && slot_of(key_id) >= 0;
}

bool CommandSecurity::rotate(std::int32_t key_id) {
  if (!can_rotate_to(key_id)) return false;
  active_ = key_id;
  ++rotations_;
  refresh_state();
  return true;
}

bool CommandSecurity::sign_ack(AckFields& ack, MacBytes& out) const {
  if (lab_mode_) {
    ack.key_id = 0;
    out.fill(0);
    return false;
  }
  int slot = ack.key_id >= active_ ? slot_of(ack.key_id) : -1;
  if (slot < 0) {
    ack.key_id = active_;
    slot = slot_of(active_);
  }
  mac_ack(ack, keys_.keys[static_cast<std::size_t>(slot)].key, out);
  return true;
}

bool CommandSecurity::sign_event(EventFields& event, MacBytes& out) const {
  if (lab_mode_) {
    event.key_id = 0;
    out.fill(0);
    return false;
  }
  event.key_id = active_;
  mac_event(event, keys_.keys[static_cast<std::size_t>(slot_of(active_))].key, out);
  return true;
}

bool CommandSecurity::sign_event_with(std::int32_t key_id, EventFields& event,
                                      MacBytes& out) const {
  const int slot = lab_mode_ ? -1 : slot_of(key_id);
  if (slot < 0) {
    event.key_id = 0;
    out.fill(0);
    return false;
  }
  event.key_id = key_id;
  mac_event(event, keys_.keys[static_cast<std::size_t>(slot)].key, out);
  return true;
}

bool CommandSecurity::sign_params(const ParamDump& dump, std::int32_t& key_id,
                                  MacBytes& out) const {
  if (lab_mode_) {
    key_id = 0;
    out.fill(0);
    return false;
  }
  key_id = active_;
  mac_params(dump, key_id, keys_.keys[static_cast<std::size_t>(slot_of(active_))].key, out);
  return true;
}

}  // namespace rocksteady::fsw::auth
