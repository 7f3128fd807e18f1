#include "fsw/bus/bus_mapping.hpp"

#include <cstring>

#include "wire/convert.hpp"

namespace rocksteady::fsw::bus {

// Every opcode and reject reason is the number its .lcm constant says (lcmtypes/ground_cmd_t.lcm,
// cmd_ack_t.lcm): a renumbering on either side stops the build.
using GroundCmd = rocksteady::ground_cmd_t;
using Ack = rocksteady::cmd_ack_t;
static_assert(static_cast<std::int32_t>(Opcode::kNoop) == GroundCmd::OP_NOOP);
static_assert(static_cast<std::int32_t>(Opcode::kSetMode) == GroundCmd::OP_SET_MODE);
static_assert(static_cast<std::int32_t>(Opcode::kSetTarget) == GroundCmd::OP_SET_TARGET);
static_assert(static_cast<std::int32_t>(Opcode::kSetLaw) == GroundCmd::OP_SET_LAW);
static_assert(static_cast<std::int32_t>(Opcode::kLoadTrajectory) == GroundCmd::OP_LOAD_TRAJECTORY);
static_assert(static_cast<std::int32_t>(Opcode::kAbortUplink) == GroundCmd::OP_ABORT_UPLINK);
static_assert(static_cast<std::int32_t>(Opcode::kResetCounters) == GroundCmd::OP_RESET_COUNTERS);
static_assert(static_cast<std::int32_t>(Opcode::kParamLoad) == GroundCmd::OP_PARAM_LOAD);
static_assert(static_cast<std::int32_t>(Opcode::kParamActivate) == GroundCmd::OP_PARAM_ACTIVATE);
static_assert(static_cast<std::int32_t>(Opcode::kParamDiscard) == GroundCmd::OP_PARAM_DISCARD);
static_assert(static_cast<std::int32_t>(Opcode::kParamDump) == GroundCmd::OP_PARAM_DUMP);
static_assert(static_cast<std::int32_t>(Opcode::kParamLoadIdentified) ==
              GroundCmd::OP_PARAM_LOAD_IDENTIFIED);
static_assert(static_cast<std::int32_t>(Opcode::kFaultDeclare) == GroundCmd::OP_FAULT_DECLARE);
static_assert(static_cast<std::int32_t>(Opcode::kFaultClear) == GroundCmd::OP_FAULT_CLEAR);
static_assert(static_cast<std::int32_t>(Opcode::kValve) == GroundCmd::OP_VALVE);
static_assert(static_cast<std::int32_t>(Opcode::kIsolationInhibit) ==
              GroundCmd::OP_ISOLATION_INHIBIT);
static_assert(kOpcodeCount == GroundCmd::OP_COUNT);
static_assert(kMaxDumpParams == rocksteady::param_table_t::MAX_PARAMS);
static_assert(kMaxParamValues == rocksteady::param_table_t::MAX_VALUES);
static_assert(kMaxCommandArgs == GroundCmd::MAX_ARGS);
static_assert(static_cast<std::int32_t>(RejectReason::kNone) == Ack::REASON_OK);
static_assert(static_cast<std::int32_t>(RejectReason::kUnknownOpcode) == Ack::REASON_UNKNOWN_OPCODE);
static_assert(static_cast<std::int32_t>(RejectReason::kBadLength) == Ack::REASON_BAD_ARG_COUNT);
static_assert(static_cast<std::int32_t>(RejectReason::kArgNotFinite) == Ack::REASON_ARG_NOT_FINITE);
static_assert(static_cast<std::int32_t>(RejectReason::kOutOfRange) == Ack::REASON_ARG_OUT_OF_RANGE);
static_assert(static_cast<std::int32_t>(RejectReason::kStaleSequence) == Ack::REASON_STALE_SEQUENCE);
static_assert(static_cast<std::int32_t>(RejectReason::kNotAuthenticated) ==
              Ack::REASON_NOT_AUTHENTICATED);
static_assert(static_cast<std::int32_t>(RejectReason::kNotAllowedInMode) ==
              Ack::REASON_NOT_ALLOWED_IN_MODE);
static_assert(static_cast<std::int32_t>(RejectReason::kTrajectoryRejected) ==
              Ack::REASON_TRAJECTORY_REJECTED);
static_assert(static_cast<std::int32_t>(RejectReason::kBusy) == Ack::REASON_BUSY);
static_assert(static_cast<std::int32_t>(RejectReason::kInternal) == Ack::REASON_INTERNAL);
static_assert(static_cast<std::int32_t>(RejectReason::kInvalidTable) == Ack::REASON_INVALID_TABLE);
static_assert(static_cast<std::int32_t>(RejectReason::kNothingToActivate) ==
              Ack::REASON_NOTHING_TO_ACTIVATE);
static_assert(static_cast<std::int32_t>(RejectReason::kUploadIncomplete) ==
              Ack::REASON_UPLOAD_INCOMPLETE);
static_assert(static_cast<std::int8_t>(Severity::kDebug) == rocksteady::event_t::SEV_DEBUG);
static_assert(static_cast<std::int8_t>(Severity::kInfo) == rocksteady::event_t::SEV_INFO);
static_assert(static_cast<std::int8_t>(Severity::kWarning) == rocksteady::event_t::SEV_WARNING);
static_assert(static_cast<std::int8_t>(Severity::kError) == rocksteady::event_t::SEV_ERROR);
static_assert(static_cast<std::int8_t>(Severity::kFatal) == rocksteady::event_t::SEV_FATAL);
static_assert(kChunkSamples == rocksteady::trajectory_chunk_t::SAMPLES);

namespace {

// Copy at most max_len bytes of a NUL-terminated text into a string with reserved capacity.
void set_text(std::string& s, const char* text, int max_len) {
  s.clear();
  if (text == nullptr) return;
  std::size_t n = 0;
  while (n < static_cast<std::size_t>(max_len) && text[n] != '\0') ++n;
  s.append(text, n);
}

std::int64_t i64(std::uint64_t v) {
  return v > static_cast<std::uint64_t>(INT64_MAX) ? INT64_MAX : static_cast<std::int64_t>(v);
}

}  // namespace

GroundCommand to_command(const rocksteady::ground_cmd_t& m) {
  GroundCommand c;
  c.seq = m.seq;
  c.source = m.sender_id;
  c.opcode = m.opcode;
  c.arg_count = m.nargs;
  for (int i = 0; i < kMaxCommandArgs && i < m.nargs; ++i) {
    c.args[static_cast<std::size_t>(i)] = m.args[i];
  }
  c.key_id = m.key_id;
  for (int i = 0; i < kMacSize; ++i) c.mac[static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(m.mac[i]);
  return c;
}

void to_chunk(const rocksteady::trajectory_chunk_t& m, TrajectoryChunk& out) {
  out.upload_id = m.upload_id;
  out.chunk_index = m.chunk_index;
  out.chunk_count = m.total_chunks;
  out.total_samples = m.total_samples;
  out.crc32 = static_cast<std::uint32_t>(m.table_crc & 0xFFFFFFFFLL);
  out.n = m.count;
  for (int i = 0; i < kChunkSamples; ++i) {
    gnc::TrajectorySample& s = out.samples[static_cast<std::size_t>(i)];
    if (i < m.count) {
      s.t = m.t[i];
      for (int a = 0; a < 3; ++a) {
        s.omega_d(a) = m.omega_d[i][a];
        s.omega_d_dot(a) = m.omega_d_dot[i][a];
      }
    } else {
      s = gnc::TrajectorySample{};
    }
  }
  out.seq = m.seq;
  out.key_id = m.key_id;
  for (int i = 0; i < kMacSize; ++i) {
    out.mac[static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(m.mac[i]);
  }
}

void reserve_text(rocksteady::cmd_ack_t& m) {
  m.text.reserve(static_cast<std::size_t>(rocksteady::cmd_ack_t::MAX_TEXT) + 1);
}
void reserve_text(rocksteady::event_t& m) {
  m.text.reserve(static_cast<std::size_t>(rocksteady::event_t::MAX_TEXT) + 1);
}

void to_message(const CommandAck& ack, double t, rocksteady::cmd_ack_t& m) {
  m.kind = rocksteady::cmd_ack_t::KIND;
  m.version = rocksteady::cmd_ack_t::VERSION;
  m.t = t;
  m.seq = ack.seq;
  m.sender_id = ack.source;
  m.opcode = ack.opcode;
  m.accepted = ack.accepted ? 1 : 0;
  m.reason = static_cast<std::int32_t>(ack.reason);
  m.detail = ack.detail;
  set_text(m.text, ack.text, rocksteady::cmd_ack_t::MAX_TEXT);
  m.key_id = 0;
  std::memset(m.mac, 0, sizeof m.mac);
}

bool sign(const FlightApp& app, rocksteady::cmd_ack_t& m) {
  auth::AckFields f = ack_fields(m);
  auth::MacBytes mac{};
  const bool signed_ = app.sign_ack(f, mac);
  m.key_id = f.key_id;
  for (int i = 0; i < kMacSize; ++i) m.mac[i] = static_cast<std::int8_t>(mac[static_cast<std::size_t>(i)]);
  return signed_;
}

auth::EventFields event_fields(const rocksteady::event_t& m) {
  auth::EventFields f;
  f.t = m.t;
  f.seq = m.seq;
  f.severity = m.severity;
  f.id = m.id;
  f.arg0 = m.arg0;
  f.arg1 = m.arg1;
  f.key_id = m.key_id;
  f.text = m.text.c_str();
  f.text_len = m.text.size();
  return f;
}

bool sign(const FlightApp& app, rocksteady::event_t& m) {
  auth::EventFields f = event_fields(m);
  auth::MacBytes mac{};
  const bool signed_ = app.sign_event(f, mac);
  m.key_id = f.key_id;
  for (int i = 0; i < kMacSize; ++i) m.mac[i] = static_cast<std::int8_t>(mac[static_cast<std::size_t>(i)]);
  return signed_;
}

auth::AckFields ack_fields(const rocksteady::cmd_ack_t& m) {
  auth::AckFields f;
  f.t = m.t;
  f.seq = m.seq;
  f.sender_id = m.sender_id;
  f.opcode = m.opcode;
  f.accepted = m.accepted != 0;
  f.reason = m.reason;
  f.detail = m.detail;
  f.key_id = m.key_id;
  f.text = m.text.c_str();
  f.text_len = m.text.size();
  return f;
}

void to_message(const Event& e, rocksteady::event_t& m) {
  m.kind = rocksteady::event_t::KIND;
  m.version = rocksteady::event_t::VERSION;
  m.t = e.t;
  m.seq = i64(e.seq);
  m.severity = static_cast<std::int8_t>(e.severity);
  m.id = static_cast<std::int32_t>(e.id);
  m.arg0 = e.arg0;
  m.arg1 = e.arg1;
  set_text(m.text, e.text.data(), rocksteady::event_t::MAX_TEXT);
  m.key_id = 0;
  std::memset(m.mac, 0, sizeof m.mac);
}

void to_message(const ParamDump& d, const FlightApp& app, rocksteady::param_table_t& m) {
  m.kind = rocksteady::param_table_t::KIND;
  m.version = rocksteady::param_table_t::VERSION;
  m.t = d.t;
  m.dump_seq = d.seq;
  m.count = d.count;
  for (int i = 0; i < kMaxDumpParams; ++i) {
    const auto k = static_cast<std::size_t>(i);
    m.value_count[i] = d.value_count[k];
    for (int v = 0; v < kMaxParamValues; ++v) m.values[i][v] = d.values[k][static_cast<std::size_t>(v)];
  }
  auth::MacBytes mac{};
  std::int32_t key_id = 0;
  (void)app.security().sign_params(d, key_id, mac);
  m.key_id = key_id;
  for (int i = 0; i < kMacSize; ++i) m.mac[i] = static_cast<std::int8_t>(mac[static_cast<std::size_t>(i)]);
}

void fill_health(const HealthTelemetry& h, rocksteady::gnc_telemetry_t& m) {
  m.base_ticks = i64(h.base_ticks);
  m.base_missed = h.base_missed;
  m.rate_group_count = 2;
  const RateGroupStats* groups[2] = {&h.gnc, &h.housekeeping};
  for (int g = 0; g < rocksteady::gnc_telemetry_t::RATE_GROUPS; ++g) {
    const bool used = g < 2;
    m.rg_cycles[g] = used ? groups[g]->cycles : 0;
    m.rg_last_exec_ns[g] = used ? groups[g]->last_exec_ns : 0;
    m.rg_max_exec_ns[g] = used ? groups[g]->max_exec_ns : 0;
    m.rg_slips[g] = used ? groups[g]->slips : 0;
    m.rg_missed[g] = used ? groups[g]->missed_ticks : 0;
  }
  m.cmd_accepted = h.cmd_accepted;
  m.cmd_rejected = h.cmd_rejected;
  m.cmd_last_seq = h.last_cmd_seq;
  m.cmd_last_opcode = h.last_cmd_opcode;
  m.cmd_last_reject = static_cast<std::int32_t>(h.last_reject);
  m.cmd_pending = static_cast<std::int32_t>(h.cmd_pending);
  m.events_emitted = h.events_emitted;
  m.events_dropped = h.events_dropped;
  m.frames_accepted = h.frames_accepted;
  m.frames_rejected = h.frames_rejected;
  m.frameless_ticks = h.frameless_ticks;
  m.sensor_rejects = h.sensor_rejects;
  m.table_loads = h.table_loads;
  m.table_activations = h.table_activations;
  m.table_loaded = h.table_loaded ? 1 : 0;
  m.uplink_id = h.uplink_id;
  m.uplink_chunks_received = h.uplink_chunks_received;
  m.uplink_total_chunks = h.uplink_chunk_count;
  m.uplink_chunks_rejected = h.uplink_chunks_rejected;
  m.trajectories_loaded = h.trajectories_loaded;
  m.lab_mode = h.lab_mode ? 1 : 0;
  m.auth_key_id = h.auth_key_id;
  m.auth_rejected = i64(h.auth_rejected);
  m.replays_rejected = i64(h.replays_rejected);
}

void fill_rx(const wire::RxCounters& rx, rocksteady::gnc_telemetry_t& m) {
  m.rx_ok = i64(rx.ok);
  m.rx_malformed = i64(rx.malformed_total());
  m.rx_bad_kind = i64(rx.bad_kind_total());
  m.rx_out_of_range = i64(rx.out_of_range);
}

}  // namespace rocksteady::fsw::bus
