#include "ground/cli/ground_auth.hpp"

#include <chrono>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <stdexcept>

#include "fsw/auth/key_file.hpp"
#include "ground/cli/sequence_store.hpp"

namespace rocksteady::ground::cli {

namespace {

namespace auth = rocksteady::fsw::auth;

struct State {
  bool configured{false};
  bool lab{false};
  auth::KeySet keys{};
  std::int32_t key_id{0};
};

std::mutex g_mutex;
State g_state;

const auth::KeyEntry& signing_key() {
  if (!g_state.configured) {
    throw std::runtime_error(
        "no command key: give --key-file (or set ROCKSTEADY_KEY_FILE; make one with "
        "`rocksteady-ground keygen FILE`), or --lab for a flight started with --lab-mode");
  }
  const auth::KeyEntry* k = g_state.keys.find(g_state.key_id);
  if (k == nullptr) throw std::runtime_error("the signing key is not in the key file");
  return *k;
}

std::int64_t wall_us() {
  return std::chrono::duration_cast<std::chrono::microseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

}  // namespace

std::string configure_auth(const AuthOptions& options) {
  std::lock_guard<std::mutex> lock(g_mutex);
  g_state = State{};
  const char* lab_env = std::getenv("ROCKSTEADY_LAB_MODE");
  std::string key_file = options.key_file;
  if (key_file.empty()) {
    const char* e = std::getenv("ROCKSTEADY_KEY_FILE");
    if (e != nullptr) key_file = e;
  }
  const bool lab = options.lab || (options.key_file.empty() && key_file.empty() &&
                                   lab_env != nullptr && std::strcmp(lab_env, "1") == 0);
  if (lab) {
    if (!options.key_file.empty()) return "--lab and --key-file are exclusive";
    g_state.configured = true;
    g_state.lab = true;
    return "";
  }
  if (key_file.empty()) return "";  // not configured: sending will say what is missing
  const std::string err = auth::load_key_file(key_file, g_state.keys);
  if (!err.empty()) {
    g_state = State{};
    return err;
  }
  std::int32_t id = options.key_id;
  if (id == 0) {
    if (const char* e = std::getenv("ROCKSTEADY_KEY_ID"); e != nullptr && e[0] != '\0') {
      id = static_cast<std::int32_t>(std::strtol(e, nullptr, 10));
    }
  }
  if (id == 0) {
    for (int i = 0; i < g_state.keys.count; ++i) {
      const std::int32_t k = g_state.keys.keys[static_cast<std::size_t>(i)].id;
      if (id == 0 || k < id) id = k;
    }
  }
  if (g_state.keys.find(id) == nullptr) {
    const std::string e = key_file + ": no key with id " + std::to_string(id);
    g_state = State{};
    return e;
  }
  g_state.key_id = id;
  g_state.configured = true;
  return "";
}

void reset_auth() {
  std::lock_guard<std::mutex> lock(g_mutex);
  g_state = State{};
}

bool auth_configured() {
  std::lock_guard<std::mutex> lock(g_mutex);
  return g_state.configured;
}

bool auth_lab_mode() {
  std::lock_guard<std::mutex> lock(g_mutex);
  return g_state.configured && g_state.lab;
}

std::int32_t auth_key_id() {
  std::lock_guard<std::mutex> lock(g_mutex);
  return g_state.lab ? 0 : g_state.key_id;
}

std::int64_t next_counter(const std::string& state_dir, std::int32_t sender_id,
                          std::int64_t at_least) {
  std::int32_t key = 0;
  {
    std::lock_guard<std::mutex> lock(g_mutex);
    if (!g_state.configured) signing_key();  // throws the explanation
    key = g_state.lab ? 0 : g_state.key_id;
  }
  if (state_dir.empty()) {
    throw std::runtime_error("no state directory for counters ($XDG_STATE_HOME or $HOME)");
  }
  if (key == 0) return SequenceStore(sequence_file(state_dir, sender_id)).next(at_least);
  const std::int64_t now = wall_us();
  return SequenceStore(state_dir + "/ground-key-" + std::to_string(key) + "-counter")
      .next(at_least > now ? at_least : now);
}

void authenticate(rocksteady::ground_cmd_t& cmd) {
  std::lock_guard<std::mutex> lock(g_mutex);
  // Canonical form: unused argument slots are zero (the flight's decoder insists).
  for (int i = cmd.nargs < 0 ? 0 : cmd.nargs; i < rocksteady::ground_cmd_t::MAX_ARGS; ++i) {
    cmd.args[i] = 0.0;
  }
  if (g_state.configured && g_state.lab) {
    cmd.key_id = 0;
    std::memset(cmd.mac, 0, sizeof cmd.mac);
    return;
  }
  const auth::KeyEntry& k = signing_key();
  fsw::GroundCommand c;
  c.seq = cmd.seq;
  c.source = cmd.sender_id;
  c.opcode = cmd.opcode;
  c.arg_count = cmd.nargs;
  for (int i = 0; i < fsw::kMaxCommandArgs && i < cmd.nargs; ++i) {
    c.args[static_cast<std::size_t>(i)] = cmd.args[i];
  }
  c.key_id = k.id;
  auth::MacBytes mac;
  auth::mac_command(c, k.key, mac);
  cmd.key_id = k.id;
  std::memcpy(cmd.mac, mac.data(), mac.size());
}

void authenticate(rocksteady::trajectory_chunk_t& m) {
  std::lock_guard<std::mutex> lock(g_mutex);
  if (g_state.configured && g_state.lab) {
    m.key_id = 0;
    std::memset(m.mac, 0, sizeof m.mac);
    return;
  }
  const auth::KeyEntry& k = signing_key();
  // The flight's TrajectoryChunk as fsw/bus maps it (to_chunk).
  fsw::TrajectoryChunk c;
  c.upload_id = m.upload_id;
  c.chunk_index = m.chunk_index;
  c.chunk_count = m.total_chunks;
  c.total_samples = m.total_samples;
  c.crc32 = static_cast<std::uint32_t>(m.table_crc & 0xFFFFFFFFLL);
  c.n = m.count;
  for (int i = 0; i < fsw::kChunkSamples && i < m.count; ++i) {
    gnc::TrajectorySample& s = c.samples[static_cast<std::size_t>(i)];
    s.t = m.t[i];
    for (int a = 0; a < 3; ++a) {
      s.omega_d(a) = m.omega_d[i][a];
      s.omega_d_dot(a) = m.omega_d_dot[i][a];
    }
  }
  c.seq = m.seq;
  c.key_id = k.id;
  auth::MacBytes mac;
  auth::mac_chunk(c, k.key, mac);
  m.key_id = k.id;
  std::memcpy(m.mac, mac.data(), mac.size());
}

AckAuth verify_ack(const rocksteady::cmd_ack_t& ack) {
  std::lock_guard<std::mutex> lock(g_mutex);
  if (g_state.configured && g_state.lab) return AckAuth::kLabMode;
  if (!g_state.configured) return AckAuth::kForged;
  const auth::KeyEntry* k = g_state.keys.find(ack.key_id);
  if (k == nullptr) return AckAuth::kForged;
  auth::AckFields f;
  f.t = ack.t;
  f.seq = ack.seq;
  f.sender_id = ack.sender_id;
  f.opcode = ack.opcode;
  f.accepted = ack.accepted != 0;
  f.reason = ack.reason;
  f.detail = ack.detail;
  f.key_id = ack.key_id;
  f.text = ack.text.c_str();
  f.text_len = ack.text.size();
  auth::MacBytes expect;
  auth::mac_ack(f, k->key, expect);
  auth::MacBytes got;
  std::memcpy(got.data(), ack.mac, got.size());
  return auth::mac_equal(expect, got) ? AckAuth::kAuthentic : AckAuth::kForged;
}

AckAuth verify_event(const rocksteady::event_t& e) {
  std::lock_guard<std::mutex> lock(g_mutex);
  if (g_state.configured && g_state.lab) return AckAuth::kLabMode;
  if (!g_state.configured) return AckAuth::kForged;
  const auth::KeyEntry* k = g_state.keys.find(e.key_id);
  if (k == nullptr) return AckAuth::kForged;
  auth::EventFields f;
  f.t = e.t;
  f.seq = e.seq;
  f.severity = e.severity;
  f.id = e.id;
  f.arg0 = e.arg0;
  f.arg1 = e.arg1;
  f.key_id = e.key_id;
  f.text = e.text.c_str();
  f.text_len = e.text.size();
  auth::MacBytes expect;
  auth::mac_event(f, k->key, expect);
  auth::MacBytes got;
  std::memcpy(got.data(), e.mac, got.size());
  return auth::mac_equal(expect, got) ? AckAuth::kAuthentic : AckAuth::kForged;
}

AckAuth verify_params(const rocksteady::param_table_t& m) {
  std::lock_guard<std::mutex> lock(g_mutex);
  if (g_state.configured && g_state.lab) return AckAuth::kLabMode;
  if (!g_state.configured) return AckAuth::kForged;
  const auth::KeyEntry* k = g_state.keys.find(m.key_id);
  if (k == nullptr || m.count < 0 || m.count > fsw::kMaxDumpParams) return AckAuth::kForged;
  // The flight's ParamDump as fsw/bus maps it (to_message).
  fsw::ParamDump d;
  d.t = m.t;
  d.seq = static_cast<std::uint32_t>(m.dump_seq);
  if (static_cast<std::int64_t>(d.seq) != m.dump_seq) return AckAuth::kForged;
  d.count = m.count;
  for (int i = 0; i < fsw::kMaxDumpParams; ++i) {
    const auto p = static_cast<std::size_t>(i);
    d.value_count[p] = m.value_count[i];
    for (int v = 0; v < fsw::kMaxParamValues; ++v) {
      d.values[p][static_cast<std::size_t>(v)] = m.values[i][v];
    }
  }
  auth::MacBytes expect;
  auth::mac_params(d, m.key_id, k->key, expect);
  auth::MacBytes got;
  std::memcpy(got.data(), m.mac, got.size());
  return auth::mac_equal(expect, got) ? AckAuth::kAuthentic : AckAuth::kForged;
}

}  // namespace rocksteady::ground::cli
