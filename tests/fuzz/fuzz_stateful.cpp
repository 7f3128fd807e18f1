// Stateful libFuzzer target over the whole inbound path of the flight: bus bytes -> safe decode ->
// bus mapping -> authentication (fsw/auth) -> command validation -> execution at the tick boundary,
// across many GNC ticks of one FlightApp with a command key. The input is a script of operations:
//   0  raw ground_cmd_t bytes (whatever the fuzzer makes)
//   1  a structured command (opcode, args from the input), correctly signed, then optionally one
//      byte of its encoding flipped before decoding
//   2  a raw trajectory_chunk_t
//   3  a correctly signed chunk of a small valid table (optionally one byte flipped)
//   4  one to eight GNC ticks with a sensor frame from the input (NaN and wild times included)
//   5  replay of the last signed message (command or chunk)
//   6  KEY_ROTATE to key 2, signed by the active key (then the ground signs with key 2)
// Invariants (a violation traps): nothing crashes or leaks; a message whose bytes were changed after
// signing, a replayed one, or raw fuzz bytes are never accepted (no change of the command counters,
// no chunk stored); every correctly signed fresh command is authenticated (never answered
// NOT_AUTHENTICATED / STALE_SEQUENCE).
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <memory>
#include <vector>

#include "fsw/app/flight_app.hpp"
#include "fsw/auth/auth.hpp"
#include "fsw/bus/bus_mapping.hpp"
#include "gnc/params.hpp"
#include "wire/codec.hpp"
#include "wire/uplink.hpp"

namespace rs = rocksteady;
namespace fsw = rocksteady::fsw;
namespace auth = rocksteady::fsw::auth;
namespace wire = rocksteady::wire;

namespace {

void require(bool ok) {
  if (!ok) __builtin_trap();
}

class Input {
 public:
  Input(const std::uint8_t* d, std::size_t n) : d_(d), n_(n) {}
  bool empty() const { return i_ >= n_; }
  std::uint8_t u8() { return i_ < n_ ? d_[i_++] : 0; }
  std::uint32_t u32() {
    std::uint32_t v = 0;
    for (int k = 0; k < 4; ++k) v = (v << 8) | u8();
    return v;
  }
  double f64() {
    std::uint64_t b = 0;
    for (int k = 0; k < 8; ++k) b = (b << 8) | u8();
    double v;
    std::memcpy(&v, &b, sizeof v);
    return v;
  }
  // A "nice" number most of the time (so commands pass the range checks), raw bits sometimes.
  double number() {
    const std::uint8_t k = u8();
    if (k < 200) return static_cast<double>(static_cast<std::int8_t>(u8())) / 16.0;
    return f64();
  }
  std::size_t take(std::size_t max, const std::uint8_t** p) {
    std::size_t len = u8();
    len = (len << 8) | u8();
    if (len > max) len = max;
    if (len > n_ - i_) len = n_ - i_;
    *p = d_ + i_;
    i_ += len;
    return len;
  }

 private:
  const std::uint8_t* d_;
  std::size_t n_;
  std::size_t i_{0};
};

class FuzzClock final : public fsw::Clock {
 public:
  std::int64_t now_ns() const override { return t_; }
  void sleep_until(std::int64_t) override {}
  void advance(std::int64_t ns) { t_ += ns; }

 private:
  std::int64_t t_{0};
};

auth::Key key_of(int id) {
  auth::Key k;
  for (std::size_t i = 0; i < k.size(); ++i) k[i] = static_cast<std::uint8_t>(17 * id + 5 * i);
  return k;
}

struct Harness {
  FuzzClock clock;
  fsw::FlightApp app;
  rs::ground_cmd_t cmd_msg{};
  rs::trajectory_chunk_t chunk_msg{};
  fsw::TrajectoryChunk chunk{};
  std::vector<unsigned char> buf = std::vector<unsigned char>(8192);
  std::int64_t counter{1};
  int signing_key{1};
  std::vector<unsigned char> last_signed;  // bytes of the last signed message
  bool last_was_chunk{false};
  std::unique_ptr<rs::gnc::TrajectoryTable> table = std::make_unique<rs::gnc::TrajectoryTable>();
  double t{0.0};

  void init() {
    fsw::FlightConfig cfg;
    cfg.gnc = rs::gnc::study_gnc_params(200.0);
    cfg.gnc.estimator.kind = rs::gnc::EstimatorKind::kPassThrough;
    cfg.executive = fsw::lockstep_executive(cfg.gnc.dt, 1.0);
    cfg.security.keys.count = 2;
    cfg.security.keys.keys[0] = {1, key_of(1)};
    cfg.security.keys.keys[1] = {2, key_of(2)};
    require(app.init(cfg, clock).ok);
    counter = 1;
    signing_key = 1;
    last_signed.clear();
    t = 0.0;
    // A small valid table for signed chunks: omega_d decaying over 40 samples.
    table->count = 40;
    for (int i = 0; i < table->count; ++i) {
      const double s = static_cast<double>(i) / (table->count - 1);
      table->samples[static_cast<std::size_t>(i)].t = 100.0 * s;
      table->samples[static_cast<std::size_t>(i)].omega_d = (1.0 - s) * rs::gnc::Vec3(0.01, 0.0, 0.0);
      table->samples[static_cast<std::size_t>(i)].omega_d_dot = rs::gnc::Vec3(-0.0001, 0.0, 0.0);
    }
    table->checksum = rs::gnc::trajectory_checksum(*table);
  }

  std::uint32_t accepted() const { return app.health().cmd_accepted; }

  // Bytes -> command through the flight's own path; returns the acknowledgement (or nullptr).
  bool submit_bytes(const unsigned char* p, std::size_t n, fsw::CommandAck& ack) {
    if (!wire::safe_decode(p, static_cast<int>(n), cmd_msg)) return false;
    ack = app.submit(fsw::bus::to_command(cmd_msg));
    return true;
  }
  bool chunk_bytes(const unsigned char* p, std::size_t n, fsw::ChunkStatus& st) {
    if (!wire::safe_decode(p, static_cast<int>(n), chunk_msg)) return false;
    fsw::bus::to_chunk(chunk_msg, chunk);
    st = app.receive_chunk(chunk);
    return true;
  }

  std::size_t encode_cmd(const rs::ground_cmd_t& m) {
    const int n = wire::encode(m, buf.data(), static_cast<int>(buf.size()));
    require(n > 0);
    return static_cast<std::size_t>(n);
  }

  void sign(rs::ground_cmd_t& m) {
    fsw::GroundCommand c = fsw::bus::to_command(m);
    c.key_id = signing_key;
    auth::MacBytes mac;
    auth::mac_command(c, key_of(signing_key), mac);
    m.key_id = signing_key;
    std::memcpy(m.mac, mac.data(), mac.size());
  }

  void signed_command(Input& in, bool rotate) {
    rs::ground_cmd_t m = wire::make<rs::ground_cmd_t>();
    m.seq = counter++;
    m.sender_id = static_cast<std::int32_t>(in.u8() % 4);
    if (rotate) {
      m.opcode = rs::ground_cmd_t::OP_KEY_ROTATE;
      m.nargs = 1;
      m.args[0] = 2.0;
    } else {
      m.opcode = static_cast<std::int32_t>(in.u8() % (rs::ground_cmd_t::OP_COUNT + 1));
      m.nargs = static_cast<std::int8_t>(in.u8() % (rs::ground_cmd_t::MAX_ARGS + 1));
      for (int i = 0; i < m.nargs; ++i) m.args[i] = in.number();
    }
    sign(m);
    const std::size_t n = encode_cmd(m);
    const std::uint8_t flip = in.u8();
    const bool tamper = flip >= 128;
    if (tamper) {
      // Flip one bit of the signed message (anywhere past the fingerprint).
      const std::size_t at = 8 + in.u32() % (n - 8);
      buf[at] ^= static_cast<unsigned char>(1u << (flip & 7));
    }
    const std::uint32_t before = accepted();
    fsw::CommandAck ack;
    if (!submit_bytes(buf.data(), n, ack)) return;  // a flip the decoder refuses
    if (tamper) {
      require(!ack.accepted);
      require(accepted() == before);
    } else {
      require(ack.reason != fsw::RejectReason::kNotAuthenticated &&
              ack.reason != fsw::RejectReason::kStaleSequence);
      // Only what the flight has really received can be replayed.
      last_signed.assign(buf.begin(), buf.begin() + static_cast<std::ptrdiff_t>(n));
      last_was_chunk = false;
    }
  }

  void signed_chunk(Input& in) {
    const int chunks = wire::chunk_count(table->count);
    const int index = in.u8() % chunks;
    require(wire::make_chunk(*table, static_cast<std::int32_t>(in.u8() % 3), index, chunk_msg));
    chunk_msg.seq = counter++;
    fsw::bus::to_chunk(chunk_msg, chunk);
    chunk.key_id = signing_key;
    auth::MacBytes mac;
    auth::mac_chunk(chunk, key_of(signing_key), mac);
    chunk_msg.key_id = signing_key;
    std::memcpy(chunk_msg.mac, mac.data(), mac.size());
    const int n = wire::encode(chunk_msg, buf.data(), static_cast<int>(buf.size()));
    require(n > 0);
    const std::uint8_t flip = in.u8();
    const bool tamper = flip >= 128;
    if (tamper) {
      const std::size_t at = 8 + in.u32() % static_cast<std::uint32_t>(n - 8);
      buf[at] ^= static_cast<unsigned char>(1u << (flip & 7));
    }
    fsw::ChunkStatus st;
    if (!chunk_bytes(buf.data(), static_cast<std::size_t>(n), st)) return;
    if (tamper) require(st == fsw::ChunkStatus::kNotAuthenticated);
    if (!tamper) {
      require(st != fsw::ChunkStatus::kNotAuthenticated);
      last_signed.assign(buf.begin(), buf.begin() + n);
      last_was_chunk = true;
    }
  }

  void replay() {
    if (last_signed.empty()) return;
    const std::uint32_t before = accepted();
    if (last_was_chunk) {
      fsw::ChunkStatus st;
      if (chunk_bytes(last_signed.data(), last_signed.size(), st)) {
        require(st == fsw::ChunkStatus::kNotAuthenticated);
      }
    } else {
      fsw::CommandAck ack;
      if (submit_bytes(last_signed.data(), last_signed.size(), ack)) {
        require(!ack.accepted);
        require(accepted() == before);
      }
    }
  }

  void ticks(Input& in) {
    const int n = 1 + in.u8() % 8;
    fsw::Outputs out;
    for (int k = 0; k < n; ++k) {
      rs::gnc::SensorSample s;
      t += 0.1;
      const std::uint8_t kind = in.u8();
      s.t = kind < 220 ? t : in.f64();
      s.gyro_rate = rs::gnc::Vec3(in.number() * 0.01, in.number() * 0.01, in.number() * 0.01);
      s.gyro_valid = (kind & 1) == 0;
      s.star_quat = rs::gnc::Vec4(0.0, 0.0, 0.0, 1.0);
      if (kind >= 240) s.star_quat(0) = in.f64();
      s.star_valid = (kind & 2) == 0;
      clock.advance(100000000);
      if (kind % 17 == 16) {
        app.gnc_tick_without_frame(t, out);
      } else {
        app.gnc_tick(s, out);
      }
      // A KEY_ROTATE takes effect at a tick boundary: the ground follows the flight's telemetry.
      signing_key = app.health().auth_key_id;
    }
  }
};

Harness& harness() {
  static Harness* h = new Harness();  // large, once
  return *h;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  Harness& h = harness();
  h.init();
  Input in(data, size);
  int steps = 0;
  while (!in.empty() && steps++ < 256) {
    const std::uint8_t op = in.u8() % 7;
    switch (op) {
      case 0: {
        const std::uint8_t* p;
        const std::size_t n = in.take(2048, &p);
        const std::uint32_t before = h.accepted();
        fsw::CommandAck ack;
        if (h.submit_bytes(p, n, ack)) {
          // Raw bytes carry no valid authenticator (2^-256): never accepted.
          require(!ack.accepted);
          require(h.accepted() == before);
        }
        break;
      }
      case 1:
        h.signed_command(in, false);
        break;
      case 2: {
        const std::uint8_t* p;
        const std::size_t n = in.take(4096, &p);
        fsw::ChunkStatus st;
        if (h.chunk_bytes(p, n, st)) require(st == fsw::ChunkStatus::kNotAuthenticated);
        break;
      }
      case 3:
        h.signed_chunk(in);
        break;
      case 4:
        h.ticks(in);
        break;
      case 5:
        h.replay();
        break;
      case 6:
        h.signed_command(in, true);
        break;
    }
  }
  return 0;
}
