#include "ground/cli/csv.hpp"

#include <cstdio>
#include <functional>
#include <map>
#include <ostream>
#include <stdexcept>

#include <lcm/lcm-cpp.hpp>

#include "ground/dictionary/dictionary.hpp"

namespace rocksteady::ground::cli {

// (the bus library is rocksteady::wire)

namespace {

// A message's fields, visited in .lcm order. The header and the rows come from the same visit, so
// they cannot disagree.
class Sink {
 public:
  explicit Sink(bool header) : header_(header) {}

  void integer(const std::string& name, std::int64_t v) { add(name, std::to_string(v)); }
  void real(const std::string& name, double v) {
    if (header_) return add(name, "");
    char buf[40];
    std::snprintf(buf, sizeof buf, "%.17g", v);
    add(name, buf);
  }
  void text(const std::string& name, const std::string& v) { add(name, v); }

  template <class T, std::size_t N>
  void array(const std::string& name, const T (&a)[N]) {
    for (std::size_t i = 0; i < N; ++i) scalar(name + "_" + std::to_string(i), a[i]);
  }
  template <class T, std::size_t N, std::size_t M>
  void array(const std::string& name, const T (&a)[N][M]) {
    for (std::size_t i = 0; i < N; ++i) {
      for (std::size_t j = 0; j < M; ++j) {
        scalar(name + "_" + std::to_string(i) + "_" + std::to_string(j), a[i][j]);
      }
    }
  }

  std::vector<std::string>& cells() { return cells_; }

 private:
  void scalar(const std::string& name, double v) { real(name, v); }
  void scalar(const std::string& name, std::int64_t v) { integer(name, v); }
  void scalar(const std::string& name, std::int32_t v) { integer(name, v); }
  void scalar(const std::string& name, std::int8_t v) { integer(name, v); }
  void scalar(const std::string& name, std::uint8_t v) { integer(name, v); }
  void add(const std::string& name, const std::string& value) {
    cells_.push_back(header_ ? name : value);
  }

  bool header_;
  std::vector<std::string> cells_;
};

// The fields of each type, grouped on lines in the .lcm file's order.
// clang-format off
#define RS_I(f) s.integer(#f, m.f)
#define RS_D(f) s.real(#f, m.f)
#define RS_A(f) s.array(#f, m.f)

void visit(const rocksteady::sensor_frame_t& m, Sink& s) {
  RS_I(kind); RS_I(version); RS_I(seq); RS_D(t);
  RS_D(gyro_t); RS_A(gyro_rate); RS_I(gyro_valid);
  RS_D(star_t); RS_A(star_quat); RS_I(star_valid);
}

void visit(const rocksteady::thruster_cmd_t& m, Sink& s) {
  RS_I(kind); RS_I(version); RS_I(seq); RS_D(t); RS_I(enabled);
  RS_A(channel_force); RS_A(thruster_on); RS_A(thruster_force); RS_A(valve_closed);
}

void visit(const rocksteady::gnc_telemetry_t& m, Sink& s) {
  RS_I(kind); RS_I(version); RS_D(t); RS_I(tick); RS_I(frame_seq);
  RS_I(mode); RS_I(law); RS_I(phase); RS_I(trajectory_loaded);
  RS_A(omega_hat); RS_A(q_hat); RS_A(q_d); RS_A(omega_r); RS_A(attitude_error); RS_A(a_hat);
  RS_A(integral);
  RS_A(torque_requested); RS_A(torque_achieved); RS_I(saturated); RS_D(alloc_scale);
  RS_I(thrusters_enabled); RS_A(channel_force); RS_D(fuel_kg);
  RS_I(mekf_active); RS_A(gyro_bias); RS_A(attitude_sigma); RS_A(gyro_bias_sigma);
  RS_I(star_gated); RS_I(identifying); RS_A(id_j); RS_A(id_j_sigma); RS_A(id_r); RS_A(id_r_sigma);
  RS_A(id_k); RS_A(id_k_sigma); RS_A(id_j_cov); RS_A(id_r_cov); RS_D(id_thrust_scale_sigma); RS_I(id_inertia_confident); RS_I(id_offset_confident);
  RS_I(id_thruster_confident); RS_I(id_excited_inertia); RS_I(id_excited_offset);
  RS_I(id_excited_thrusters); RS_I(id_offset_unobservable); RS_A(id_residual_torque);
  RS_D(id_residual_chi2); RS_I(id_windows); RS_A(id_rate_bias_sigma); RS_I(id_windows_gated);
  RS_I(id_gate_reinflations); RS_I(id_guard_refusals);
  RS_I(id_excitation_active); RS_A(id_excitation_force); RS_D(id_excitation_gamma); RS_I(id_excitation_inertia); RS_A(id_excitation_torque); RS_I(id_candidate); RS_I(model_adoptions);
  RS_I(fdi_enabled); RS_A(fdi_residual); RS_D(fdi_chi2); RS_D(fdi_noise_sigma); RS_I(fdi_best);
  RS_D(fdi_best_llr); RS_D(fdi_runner_up_llr); RS_I(fdi_suspected_on); RS_I(fdi_suspected_off);
  RS_I(fdi_confirmed_on); RS_I(fdi_confirmed_off);
  RS_I(fdi_confirmed_degraded); RS_A(fdi_strength_factor); RS_A(valve_open); RS_I(isolation_inhibited);
  RS_I(fdi_windows); RS_I(fdi_probe_pod); RS_I(fdi_probes);
  RS_I(fdi_check_jet); RS_I(fdi_checks); RS_I(reduced_authority); RS_I(alloc_rank);
  RS_I(base_ticks); RS_I(base_missed); RS_I(rate_group_count);
  RS_A(rg_cycles); RS_A(rg_last_exec_ns); RS_A(rg_max_exec_ns); RS_A(rg_slips); RS_A(rg_missed);
  RS_I(cmd_accepted); RS_I(cmd_rejected); RS_I(cmd_last_seq); RS_I(cmd_last_opcode);
  RS_I(cmd_last_reject); RS_I(cmd_pending);
  RS_I(events_emitted); RS_I(events_dropped); RS_I(frames_accepted); RS_I(frames_rejected);
  RS_I(frameless_ticks); RS_I(sensor_rejects); RS_I(rx_ok); RS_I(rx_malformed); RS_I(rx_bad_kind);
  RS_I(rx_out_of_range);
  RS_I(table_loads); RS_I(table_activations); RS_I(table_loaded);
  RS_I(uplink_id); RS_I(uplink_chunks_received); RS_I(uplink_total_chunks);
  RS_I(uplink_chunks_rejected); RS_I(trajectories_loaded);
  RS_I(lab_mode); RS_I(auth_key_id); RS_I(auth_rejected); RS_I(replays_rejected);
}

void visit(const rocksteady::event_t& m, Sink& s) {
  RS_I(kind); RS_I(version); RS_D(t); RS_I(seq); RS_I(severity); RS_I(id); RS_I(arg0); RS_I(arg1);
  RS_I(key_id); RS_A(mac);
  s.text("text", m.text);
}

void visit(const rocksteady::ground_cmd_t& m, Sink& s) {
  RS_I(kind); RS_I(version); RS_I(seq); RS_I(sender_id); RS_I(opcode); RS_I(nargs); RS_A(args);
  RS_I(key_id); RS_A(mac);
}

void visit(const rocksteady::cmd_ack_t& m, Sink& s) {
  RS_I(kind); RS_I(version); RS_D(t); RS_I(seq); RS_I(sender_id); RS_I(opcode); RS_I(accepted);
  RS_I(reason); RS_I(detail); RS_I(key_id); RS_A(mac);
  s.text("text", m.text);
}

void visit(const rocksteady::plant_truth_t& m, Sink& s) {
  RS_I(kind); RS_I(version); RS_I(seq); RS_D(t);
  RS_A(quat); RS_A(q); RS_A(omega); RS_D(omega_norm); RS_A(channel_force); RS_A(torque_control);
  RS_A(torque_disturbance); RS_D(fuel_used_kg);
  RS_A(fault_kind); RS_A(fault_factor); RS_A(fault_onset); RS_A(thruster_force); RS_A(valve_open);
  RS_I(command_timeout);
}

void visit(const rocksteady::trajectory_chunk_t& m, Sink& s) {
  RS_I(kind); RS_I(version); RS_I(upload_id); RS_I(chunk_index); RS_I(total_chunks);
  RS_I(total_samples); RS_I(first_sample); RS_I(count); RS_I(table_crc);
  RS_A(t); RS_A(omega_d); RS_A(omega_d_dot);
  RS_I(seq); RS_I(key_id); RS_A(mac);
}

#undef RS_I
#undef RS_D
#undef RS_A
// clang-format on

struct Converter {
  std::function<std::vector<std::string>()> header;
  std::function<bool(const void*, int, std::int64_t, std::vector<std::string>&,
                     wire::DecodeStatus&)>
      row;
};

// The dictionary's names of a channel's enum fields (mode, law, event id, severity, opcode,
// reason, ...) as trailing columns "<column>_name", after every field of the message.
void name_header(const char* channel, std::vector<std::string>& cells) {
  const dictionary::Channel* c = dictionary::find_channel(channel);
  if (c == nullptr) return;
  for (int i = 0; i < c->point_count; ++i) {
    if (c->points[i].enum_name[0] != '\0') cells.push_back(std::string(c->points[i].key) + "_name");
  }
}

void name_cells(const char* channel, const void* data, int len, std::vector<std::string>& cells) {
  const dictionary::Channel* c = dictionary::find_channel(channel);
  if (c == nullptr) return;
  std::vector<double> values(static_cast<std::size_t>(c->point_count));
  std::string text;
  wire::DecodeStatus status = wire::DecodeStatus::kOk;
  const bool ok = c->decode(data, len, values.data(), text, status);
  for (int i = 0; i < c->point_count; ++i) {
    if (c->points[i].enum_name[0] == '\0') continue;
    cells.push_back(ok ? dictionary::format_value(c->points[i], values[static_cast<std::size_t>(i)])
                       : std::string());
  }
}

template <class T>
Converter converter() {
  Converter c;
  c.header = [] {
    Sink s(true);
    s.integer("log_utime", 0);
    visit(wire::make<T>(), s);
    name_header(wire::channel_of<T>(), s.cells());
    return s.cells();
  };
  c.row = [](const void* data, int len, std::int64_t utime, std::vector<std::string>& row,
             wire::DecodeStatus& status) {
    T m{};
    status = wire::decode(data, len, m);
    if (status != wire::DecodeStatus::kOk) return false;
    Sink s(false);
    s.integer("log_utime", utime);
    visit(m, s);
    name_cells(wire::channel_of<T>(), data, len, s.cells());
    row = std::move(s.cells());
    return true;
  };
  return c;
}

const std::map<std::string, Converter>& converters() {
  static const std::map<std::string, Converter> table{
      {channels::kSensors, converter<rocksteady::sensor_frame_t>()},
      {channels::kThrusterCmd, converter<rocksteady::thruster_cmd_t>()},
      {channels::kGncTelemetry, converter<rocksteady::gnc_telemetry_t>()},
      {channels::kEvents, converter<rocksteady::event_t>()},
      {channels::kGroundCmd, converter<rocksteady::ground_cmd_t>()},
      {channels::kCmdAck, converter<rocksteady::cmd_ack_t>()},
      {channels::kPlantTruth, converter<rocksteady::plant_truth_t>()},
      {channels::kTrajUplink, converter<rocksteady::trajectory_chunk_t>()},
  };
  return table;
}

}  // namespace

std::vector<std::string> csv_channels() {
  std::vector<std::string> names;
  for (const auto& [name, c] : converters()) names.push_back(name);
  return names;
}

bool csv_supported(const std::string& channel) {
  return converters().count(channel) != 0;
}

std::vector<std::string> csv_header(const std::string& channel) {
  const auto it = converters().find(channel);
  return it == converters().end() ? std::vector<std::string>{} : it->second.header();
}

bool csv_row(const std::string& channel, const void* data, int len, std::int64_t log_utime,
             std::vector<std::string>& row, wire::DecodeStatus& status) {
  const auto it = converters().find(channel);
  if (it == converters().end()) {
    status = wire::DecodeStatus::kBadFingerprint;
    return false;
  }
  return it->second.row(data, len, log_utime, row, status);
}

std::string csv_line(const std::vector<std::string>& cells) {
  std::string line;
  for (std::size_t i = 0; i < cells.size(); ++i) {
    if (i > 0) line += ',';
    const std::string& c = cells[i];
    if (c.find_first_of(",\"\n\r") == std::string::npos) {
      line += c;
      continue;
    }
    line += '"';
    for (const char ch : c) {
      if (ch == '"') line += '"';
      line += ch;
    }
    line += '"';
  }
  line += '\n';
  return line;
}

Log2CsvStats log2csv(const std::string& log_path, const std::string& channel, std::ostream& out) {
  const auto it = converters().find(channel);
  if (it == converters().end()) {
    std::string known;
    for (const std::string& c : csv_channels()) known += (known.empty() ? "" : ", ") + c;
    throw std::runtime_error("channel '" + channel + "' is not supported (one of " + known + ")");
  }
  lcm::LogFile log(log_path, "r");
  if (!log.good()) throw std::runtime_error(log_path + ": cannot open as an LCM log");

  Log2CsvStats stats;
  out << csv_line(it->second.header());
  std::vector<std::string> row;
  for (const lcm::LogEvent* ev = log.readNextEvent(); ev != nullptr; ev = log.readNextEvent()) {
    ++stats.events;
    if (ev->channel != channel) continue;
    ++stats.on_channel;
    wire::DecodeStatus status = wire::DecodeStatus::kOk;
    const bool ok = it->second.row(ev->data, ev->datalen, ev->timestamp, row, status);
    stats.rx.count(status);
    if (!ok) continue;
    out << csv_line(row);
    ++stats.written;
  }
  if (!out) throw std::runtime_error("writing the CSV failed");
  return stats;
}

std::string describe_rejections(const wire::RxCounters& rx) {
  const std::pair<std::uint64_t, wire::DecodeStatus> causes[] = {
      {rx.too_short, wire::DecodeStatus::kTooShort},
      {rx.too_long, wire::DecodeStatus::kTooLong},
      {rx.bad_fingerprint, wire::DecodeStatus::kBadFingerprint},
      {rx.bad_length, wire::DecodeStatus::kBadLength},
      {rx.malformed, wire::DecodeStatus::kMalformed},
      {rx.bad_kind, wire::DecodeStatus::kBadKind},
      {rx.bad_version, wire::DecodeStatus::kBadVersion},
      {rx.out_of_range, wire::DecodeStatus::kOutOfRange},
  };
  std::string s = std::to_string(rx.rejected()) + " rejected";
  const char* sep = ": ";
  for (const auto& [n, status] : causes) {
    if (n == 0) continue;
    s += sep + std::to_string(n) + " " + wire::to_string(status);
    sep = ", ";
  }
  return s;
}

}  // namespace rocksteady::ground::cli
