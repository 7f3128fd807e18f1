#include "ground/cli/monitor_format.hpp"

#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstdio>

#include "ground/cli/commands.hpp"
#include "ground/cli/dictionary.hpp"

namespace rocksteady::ground::cli {

namespace {

constexpr double kPi = 3.14159265358979323846;

__attribute__((format(printf, 1, 2))) std::string fmt(const char* format, ...) {
  char buf[512];
  va_list ap;
  va_start(ap, format);
  std::vsnprintf(buf, sizeof buf, format, ap);
  va_end(ap);
  return buf;
}

const char* yes_no(std::int8_t b) {
  return b != 0 ? "yes" : "no";
}

double ms(std::int64_t ns) {
  return static_cast<double>(ns) * 1e-6;
}

const char* group_name(int i) {
  switch (i) {
    case 0:
      return "gnc";
    case 1:
      return "hk";
    default:
      return "rg";
  }
}

}  // namespace

double norm3(const double (&v)[3]) {
  return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
}

double mrp_angle_deg(const double (&q)[3]) {
  return 4.0 * std::atan(norm3(q)) * 180.0 / kPi;
}

std::vector<std::string> format_status(const rocksteady::gnc_telemetry_t& m,
                                       const MonitorCounts& c) {
  std::vector<std::string> lines;
  lines.push_back(fmt("Rocksteady  t=%.3f s  tick=%lld  frame=%lld", m.t,
                      static_cast<long long>(m.tick), static_cast<long long>(m.frame_seq)));
  lines.push_back(fmt("mode %-8s  law %-11s  phase %-15s  trajectory %s", mode_name(m.mode),
                      law_name(m.law), phase_name(m.phase),
                      m.trajectory_loaded != 0 ? "loaded" : "none"));
  lines.push_back(fmt("rate   |w|=%.6e rad/s  w=[% .6e % .6e % .6e]", norm3(m.omega_hat),
                      m.omega_hat[0], m.omega_hat[1], m.omega_hat[2]));
  lines.push_back(
      fmt("att    |err|=%.6f (%.3f deg)  q_hat=[% .5f % .5f % .5f]  q_d=[% .5f % .5f % .5f]",
          norm3(m.attitude_error), mrp_angle_deg(m.attitude_error), m.q_hat[0], m.q_hat[1],
          m.q_hat[2], m.q_d[0], m.q_d[1], m.q_d[2]));
  lines.push_back(fmt("act    thrusters %s  saturated %s  scale %.4f  |u_c|=%.4e N m  fuel %.4f kg",
                      m.thrusters_enabled != 0 ? "on" : "OFF", yes_no(m.saturated), m.alloc_scale,
                      norm3(m.torque_requested), m.fuel_kg));
  lines.push_back(fmt("exec   base ticks %lld  missed %lld", static_cast<long long>(m.base_ticks),
                      static_cast<long long>(m.base_missed)));
  constexpr int kGroups = rocksteady::gnc_telemetry_t::RATE_GROUPS;
  const int groups = std::clamp(static_cast<int>(m.rate_group_count), 0, kGroups);
  for (int i = 0; i < groups; ++i) {
    const auto k = static_cast<std::size_t>(i);
    lines.push_back(fmt(
        "  %-3s  cycles %lld  last %.3f ms  max %.3f ms  slips %lld  missed %lld", group_name(i),
        static_cast<long long>(m.rg_cycles[k]), ms(m.rg_last_exec_ns[k]), ms(m.rg_max_exec_ns[k]),
        static_cast<long long>(m.rg_slips[k]), static_cast<long long>(m.rg_missed[k])));
  }
  lines.push_back(
      fmt("cmd    accepted %lld  rejected %lld  last seq %lld %s  last reject %s  pending %d",
          static_cast<long long>(m.cmd_accepted), static_cast<long long>(m.cmd_rejected),
          static_cast<long long>(m.cmd_last_seq),
          m.cmd_last_opcode < 0 ? "-" : opcode_name(m.cmd_last_opcode).c_str(),
          m.cmd_last_reject == 0 ? "-" : reason_name(m.cmd_last_reject).c_str(), m.cmd_pending));
  lines.push_back(fmt(
      "rx     fsw: ok %lld  malformed %lld  bad kind %lld  out of range %lld   "
      "monitor: ok %llu  rejected %llu",
      static_cast<long long>(m.rx_ok), static_cast<long long>(m.rx_malformed),
      static_cast<long long>(m.rx_bad_kind), static_cast<long long>(m.rx_out_of_range),
      static_cast<unsigned long long>(c.rx.ok), static_cast<unsigned long long>(c.rx.rejected())));
  lines.push_back(
      fmt("health frames ok %lld  rejected %lld  frameless %lld  sensor rejects %lld  "
          "events %lld (dropped %lld)",
          static_cast<long long>(m.frames_accepted), static_cast<long long>(m.frames_rejected),
          static_cast<long long>(m.frameless_ticks), static_cast<long long>(m.sensor_rejects),
          static_cast<long long>(m.events_emitted), static_cast<long long>(m.events_dropped)));
  std::string uplink = m.uplink_id < 0 ? std::string("none")
                                       : fmt("id %d  %d/%d chunks", m.uplink_id,
                                             m.uplink_chunks_received, m.uplink_total_chunks);
  lines.push_back(
      fmt("tables loads %lld  activations %lld  pending %s   uplink %s  rejected chunks "
          "%lld  trajectories %lld",
          static_cast<long long>(m.table_loads), static_cast<long long>(m.table_activations),
          yes_no(m.table_loaded), uplink.c_str(), static_cast<long long>(m.uplink_chunks_rejected),
          static_cast<long long>(m.trajectories_loaded)));
  return lines;
}

std::string format_status_line(const rocksteady::gnc_telemetry_t& m, const MonitorCounts& c) {
  const std::size_t g = 0;
  return fmt(
      "t=%.3f mode=%s law=%s phase=%s |w|=%.6e w=[%.6e,%.6e,%.6e] |err|=%.6f fuel=%.4f "
      "sat=%d gnc_cycles=%lld last_ms=%.3f max_ms=%.3f slips=%lld missed=%lld "
      "cmd_acc=%lld cmd_rej=%lld rx_malformed=%lld rx_bad_kind=%lld rx_out_of_range=%lld "
      "mon_rejected=%llu",
      m.t, mode_name(m.mode), law_name(m.law), phase_name(m.phase), norm3(m.omega_hat),
      m.omega_hat[0], m.omega_hat[1], m.omega_hat[2], norm3(m.attitude_error), m.fuel_kg,
      m.saturated != 0 ? 1 : 0, static_cast<long long>(m.rg_cycles[g]), ms(m.rg_last_exec_ns[g]),
      ms(m.rg_max_exec_ns[g]), static_cast<long long>(m.rg_slips[g]),
      static_cast<long long>(m.rg_missed[g]), static_cast<long long>(m.cmd_accepted),
      static_cast<long long>(m.cmd_rejected), static_cast<long long>(m.rx_malformed),
      static_cast<long long>(m.rx_bad_kind), static_cast<long long>(m.rx_out_of_range),
      static_cast<unsigned long long>(c.rx.rejected()));
}

std::string sanitize_text(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  const auto* b = reinterpret_cast<const unsigned char*>(text.data());
  const std::size_t n = text.size();
  auto escape = [&](unsigned char c) {
    static const char* const kHex = "0123456789abcdef";
    out += "\\x";
    out += kHex[c >> 4];
    out += kHex[c & 15];
  };
  for (std::size_t i = 0; i < n;) {
    const unsigned char c = b[i];
    if (c < 0x20 || c == 0x7f) {
      escape(c);
      ++i;
      continue;
    }
    if (c < 0x80) {
      out += static_cast<char>(c);
      ++i;
      continue;
    }
    // A well-formed UTF-8 sequence (2..4 bytes, no overlong lead, no C1 controls U+0080..U+009F).
    int len = c >= 0xC2 && c <= 0xDF ? 2 : c >= 0xE0 && c <= 0xEF ? 3 : c >= 0xF0 && c <= 0xF4 ? 4 : 0;
    bool ok = len > 0 && i + static_cast<std::size_t>(len) <= n;
    for (int k = 1; ok && k < len; ++k) ok = (b[i + static_cast<std::size_t>(k)] & 0xC0) == 0x80;
    if (ok && c == 0xC2 && b[i + 1] < 0xA0) ok = false;  // C1 controls (e.g. CSI 0x9b)
    if (!ok) {
      escape(c);
      ++i;
      continue;
    }
    out.append(text, i, static_cast<std::size_t>(len));
    i += static_cast<std::size_t>(len);
  }
  return out;
}

std::string format_event(const rocksteady::event_t& e) {
  std::string s = fmt("[t=%.3f] %-7s %s (%d) arg0=%d arg1=%d", e.t, severity_name(e.severity),
                      event_name(e.id).c_str(), e.id, e.arg0, e.arg1);
  if (!e.text.empty()) s += ": " + sanitize_text(e.text);
  return s;
}

std::string format_ack_verdict(const rocksteady::cmd_ack_t& a) {
  if (a.accepted != 0) return "ACCEPTED";
  std::string s = "REJECTED: " + reason_name(a.reason);
  const std::string detail = reason_detail(a.reason, a.detail);
  if (!detail.empty()) s += " (" + detail + ")";
  if (!a.text.empty() && a.text != detail) s += ": " + sanitize_text(a.text);
  return s;
}

std::string format_ack(const rocksteady::cmd_ack_t& a) {
  return fmt("ack seq %lld from %d %s: ", static_cast<long long>(a.seq), a.sender_id,
             opcode_name(a.opcode).c_str()) +
         format_ack_verdict(a);
}

}  // namespace rocksteady::ground::cli
