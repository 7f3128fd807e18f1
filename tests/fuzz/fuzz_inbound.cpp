// libFuzzer targets over every inbound bus decoder (wire/codec.hpp) and what consumes the decoded
// message next: the sensor layer, the thruster bank, the flight application's command validator and
// trajectory uplink. One source, one target per build (ROCKSTEADY_FUZZ_TARGET):
//   1 sensor_frame_t   2 thruster_cmd_t   3 ground_cmd_t   4 trajectory_chunk_t
//   5 the ground side's inbound types (event_t, cmd_ack_t, gnc_telemetry_t, plant_truth_t,
//     plant_fault_cmd_t)
// Each input is tried as a whole message and, so the fuzzer explores the body without having to find
// the 8-byte fingerprint, once more behind the right fingerprint. Invariant: a message the decoder
// accepts re-encodes to exactly the same bytes. Any violation traps.
// If ROCKSTEADY_FUZZ_SEED_DIR is set, valid messages are written there first (the seed corpus).
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "wire/codec.hpp"
#include "wire/convert.hpp"
#include "wire/uplink.hpp"
#include "hal/sensors.hpp"
#include "hal/thruster_bank.hpp"

#ifdef ROCKSTEADY_FUZZ_WITH_FSW
#include "fsw/commands/command_table.hpp"
#include "fsw/uplink/trajectory_uplink.hpp"
#endif

namespace rs = rocksteady;
namespace wire = rocksteady::wire;

namespace {

void require(bool ok) {
  if (!ok) __builtin_trap();
}

template <class T> std::vector<unsigned char> encoded(const T& m) {
  std::vector<unsigned char> b(static_cast<std::size_t>(m.getEncodedSize()));
  require(wire::encode(m, b.data(), static_cast<int>(b.size())) == static_cast<int>(b.size()));
  return b;
}

// Decode; on success check the re-encode invariant and hand the message to `use`.
template <class T, class Use> void try_decode(const unsigned char* data, std::size_t size, Use&& use) {
  static T msg;  // static: decoding a fixed-size type must not need the heap
  wire::RxCounters counters;
  const int len = size > static_cast<std::size_t>(wire::kMaxMessageBytes) + 1
                      ? wire::kMaxMessageBytes + 1
                      : static_cast<int>(size);
  if (!wire::safe_decode(data, len, msg, &counters)) {
    require(counters.rejected() == 1);
    return;
  }
  const auto again = encoded(msg);
  require(again.size() == static_cast<std::size_t>(len) && std::memcmp(again.data(), data, again.size()) == 0);
  use(msg);
}

template <class T, class Use> void fuzz_type(const std::uint8_t* data, std::size_t size, Use&& use) {
  try_decode<T>(data, size, use);
  // Behind the right fingerprint.
  static std::vector<unsigned char> buf(static_cast<std::size_t>(wire::kMaxMessageBytes) + 16);
  const std::size_t n = size + 8 > buf.size() ? buf.size() - 8 : size;
  const auto hash = static_cast<std::uint64_t>(T::getHash());
  for (int i = 0; i < 8; ++i) buf[static_cast<std::size_t>(i)] = static_cast<unsigned char>(hash >> (56 - 8 * i));
  if (n > 0) std::memcpy(buf.data() + 8, data, n);
  // An exactly sized copy so that ASan sees any read past the end.
  std::vector<unsigned char> exact(buf.begin(), buf.begin() + static_cast<std::ptrdiff_t>(n + 8));
  try_decode<T>(exact.data(), exact.size(), use);
}

// --- consumers ---------------------------------------------------------------------------------

void use_frame(const rs::sensor_frame_t& m) {
  static rs::hal::Gyro gyro;
  static rs::hal::StarTracker star;
  static bool configured = false;
  if (!configured) {
    rs::hal::SensorConfig c;
    c.body_from_sensor << 0, -1, 0, 1, 0, 0, 0, 0, 1;
    require(gyro.configure(c) == rs::hal::SensorConfigError::kOk);
    require(star.configure(c) == rs::hal::SensorConfigError::kOk);
    configured = true;
  }
  const rs::hal::RawSensors raw = wire::to_raw(m);
  rs::gnc::SensorSample s;
  s.t = raw.t;
  gyro.read(raw.gyro, raw.t, s);
  star.read(raw.star, raw.t, s);
  require(!s.gyro_valid || s.gyro_rate.allFinite());
  require(!s.star_valid || s.star_quat.allFinite());
}

void use_thruster_cmd(const rs::thruster_cmd_t& m) {
  static rs::hal::ThrusterBank bank;
  if (!bank.configured()) require(bank.configure(rs::hal::default_thruster_bank_config(200.0)).ok());
  const rs::hal::ThrusterOutputs o = wire::to_outputs(m);
  const rs::gnc::Vec8 u = bank.channel_forces(o);
  require(u.allFinite());
  rs::gnc::ThrusterCommand cmd;
  cmd.enabled = o.enabled;
  cmd.force = wire::channel_forces(m);
  rs::hal::ThrusterOutputs again;
  const rs::hal::BankStatus st = bank.command(cmd, again);
  require(st.non_finite == 0);
  for (const double f : again.force) require(f >= 0.0 && f <= 200.0);
}

#ifdef ROCKSTEADY_FUZZ_WITH_FSW
// ground_cmd_t -> fsw::GroundCommand, as the bus layer maps it.
rs::fsw::GroundCommand to_command(const rs::ground_cmd_t& m) {
  rs::fsw::GroundCommand c;
  c.seq = m.seq;
  c.source = m.sender_id;
  c.opcode = m.opcode;
  c.arg_count = m.nargs;
  for (int i = 0; i < rs::fsw::kMaxCommandArgs; ++i) c.args[static_cast<std::size_t>(i)] = m.args[i];
  return c;
}
#endif

void use_ground_cmd(const rs::ground_cmd_t& m) {
  require(m.nargs >= 0 && m.nargs <= rs::ground_cmd_t::MAX_ARGS);
#ifdef ROCKSTEADY_FUZZ_WITH_FSW
  static rs::fsw::SequenceTracker seq;
  const rs::fsw::GroundCommand c = to_command(m);
  for (int mode = 0; mode < rs::gnc::kModeCount; ++mode) {
    const rs::fsw::CommandCheck v = rs::fsw::check_command(c, static_cast<rs::gnc::Mode>(mode));
    require(v.text != nullptr);
    if (v.ok()) require(rs::fsw::find_opcode(c.opcode) != nullptr);
  }
  if (seq.check(c.source, c.seq) == rs::fsw::RejectReason::kNone) seq.accept(c.source, c.seq);
#endif
}

void use_chunk(const rs::trajectory_chunk_t& m) {
#ifdef ROCKSTEADY_FUZZ_WITH_FSW
  static rs::fsw::TrajectoryUplink uplink;
  static rs::fsw::TrajectoryChunk c;
  c.upload_id = m.upload_id;
  c.chunk_index = m.chunk_index;
  c.chunk_count = m.total_chunks;
  c.total_samples = m.total_samples;
  c.crc32 = static_cast<std::uint32_t>(m.table_crc);
  c.n = m.count;
  for (int i = 0; i < m.count; ++i) {
    auto& s = c.samples[static_cast<std::size_t>(i)];
    s.t = m.t[i];
    s.omega_d = rs::gnc::Vec3(m.omega_d[i][0], m.omega_d[i][1], m.omega_d[i][2]);
    s.omega_d_dot = rs::gnc::Vec3(m.omega_d_dot[i][0], m.omega_d_dot[i][1], m.omega_d_dot[i][2]);
  }
  const rs::fsw::ChunkResult r = uplink.receive(c);
  // The codec's checks cover the header, index and count rules; only a clash with the upload in
  // progress remains (its header, or another upload id, which an abort would end).
  require(r.status == rs::fsw::ChunkStatus::kStored ||
          r.status == rs::fsw::ChunkStatus::kHeaderMismatch ||
          r.status == rs::fsw::ChunkStatus::kOtherUplinkActive);
  if (r.status == rs::fsw::ChunkStatus::kOtherUplinkActive) {
    require(uplink.active() && uplink.upload_id() == r.active_id);
    uplink.clear();  // the ground's ABORT_UPLINK
  }
  if (uplink.complete()) {
    (void)uplink.finalize(0.05);
    uplink.clear();
  }
#else
  require(m.count >= 1 && m.count <= rs::trajectory_chunk_t::SAMPLES);
#endif
}

// --- seeds -------------------------------------------------------------------------------------

int seed_number = 0;
void write_seed(const std::filesystem::path& dir, const std::vector<unsigned char>& b) {
  std::ofstream out(dir / ("seed_" + std::to_string(seed_number++)), std::ios::binary);
  out.write(reinterpret_cast<const char*>(b.data()), static_cast<std::streamsize>(b.size()));
}

void write_seeds(const std::filesystem::path& dir) {
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
#if ROCKSTEADY_FUZZ_TARGET == 1
  rs::hal::RawSensors s;
  s.seq = 7;
  s.t = 0.7;
  s.gyro = {0.69, rs::gnc::Vec3(0.01, 0.02, 0.03), true};
  s.star = {0.68, rs::gnc::Vec4(0.0, 0.0, 0.0, 1.0), true};
  write_seed(dir, encoded(wire::to_message(s)));
  write_seed(dir, encoded(wire::make<rs::sensor_frame_t>()));
#elif ROCKSTEADY_FUZZ_TARGET == 2
  rs::hal::ThrusterBank bank;
  bank.configure(rs::hal::default_thruster_bank_config(200.0));
  rs::gnc::ThrusterCommand cmd;
  cmd.enabled = true;
  cmd.force << 10, -20, 30, -40, 50, -60, 70, -80;
  rs::hal::ThrusterOutputs o;
  bank.command(cmd, o);
  write_seed(dir, encoded(wire::to_message(o, cmd.force, 3, 0.3)));
  write_seed(dir, encoded(wire::make<rs::thruster_cmd_t>()));
#elif ROCKSTEADY_FUZZ_TARGET == 3
  for (int op = 0; op < rs::ground_cmd_t::OP_COUNT; ++op) {
    auto m = wire::make<rs::ground_cmd_t>();
    m.seq = op + 1;
    m.opcode = op;
    m.nargs = static_cast<std::int8_t>(op == 2 ? 3 : (op % 2));
    m.args[0] = 1.0;
    write_seed(dir, encoded(m));
  }
#elif ROCKSTEADY_FUZZ_TARGET == 4
  static rs::gnc::TrajectoryTable table;
  table.count = 70;
  for (int i = 0; i < table.count; ++i) {
    auto& smp = table.samples[static_cast<std::size_t>(i)];
    smp.t = 10.0 * i;
    smp.omega_d = rs::gnc::Vec3(1e-3, 0.0, -1e-3) * (i + 1 < table.count ? 1.0 : 0.0);
  }
  for (int i = 0; i < wire::chunk_count(table.count); ++i) {
    rs::trajectory_chunk_t c;
    require(wire::make_chunk(table, 5, i, c));
    write_seed(dir, encoded(c));
  }
#else
  auto e = wire::make<rs::event_t>();
  e.text = "mode changed";
  e.severity = rs::event_t::SEV_INFO;
  std::vector<unsigned char> b = encoded(e);
  b.insert(b.begin(), 0);
  write_seed(dir, b);
  auto a = wire::make<rs::cmd_ack_t>();
  a.accepted = 1;
  b = encoded(a);
  b.insert(b.begin(), 1);
  write_seed(dir, b);
  b = encoded(wire::make<rs::gnc_telemetry_t>());
  b.insert(b.begin(), 2);
  write_seed(dir, b);
  b = encoded(wire::make<rs::plant_truth_t>());
  b.insert(b.begin(), 3);
  write_seed(dir, b);
  b = encoded(wire::make<rs::plant_fault_cmd_t>());
  b.insert(b.begin(), 4);
  write_seed(dir, b);
#endif
}

template <class T> void nothing(const T&) {}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  if (const char* dir = std::getenv("ROCKSTEADY_FUZZ_SEED_DIR"); dir != nullptr && *dir != '\0') {
    write_seeds(dir);
  }
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
#if ROCKSTEADY_FUZZ_TARGET == 1
  fuzz_type<rs::sensor_frame_t>(data, size, use_frame);
#elif ROCKSTEADY_FUZZ_TARGET == 2
  fuzz_type<rs::thruster_cmd_t>(data, size, use_thruster_cmd);
#elif ROCKSTEADY_FUZZ_TARGET == 3
  fuzz_type<rs::ground_cmd_t>(data, size, use_ground_cmd);
#elif ROCKSTEADY_FUZZ_TARGET == 4
  fuzz_type<rs::trajectory_chunk_t>(data, size, use_chunk);
#else
  // First byte selects the type.
  if (size < 1) return 0;
  switch (data[0] % 5) {
    case 0: fuzz_type<rs::event_t>(data + 1, size - 1, nothing<rs::event_t>); break;
    case 1: fuzz_type<rs::cmd_ack_t>(data + 1, size - 1, nothing<rs::cmd_ack_t>); break;
    case 2: fuzz_type<rs::gnc_telemetry_t>(data + 1, size - 1, nothing<rs::gnc_telemetry_t>); break;
    case 3: fuzz_type<rs::plant_truth_t>(data + 1, size - 1, nothing<rs::plant_truth_t>); break;
    default: fuzz_type<rs::plant_fault_cmd_t>(data + 1, size - 1, nothing<rs::plant_fault_cmd_t>); break;
  }
#endif
  return 0;
}
