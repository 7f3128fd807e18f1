// The monitor's text from a telemetry message, an event and an acknowledgement (pure functions).
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "fsw/interface.hpp"
#include "ground/cli/monitor_format.hpp"

namespace rocksteady::ground::cli {
namespace {

// (the bus library is rocksteady::wire)

std::string joined(const std::vector<std::string>& lines) {
  std::string s;
  for (const std::string& l : lines) s += l + "\n";
  return s;
}

void expect_has(const std::string& text, const std::string& part) {
  EXPECT_NE(text.find(part), std::string::npos) << "missing '" << part << "' in:\n" << text;
}

rocksteady::gnc_telemetry_t sample() {
  auto m = wire::make<rocksteady::gnc_telemetry_t>();
  m.t = 1234.5;
  m.tick = 12345;
  m.frame_seq = 12340;
  m.mode = 3;   // TRACK
  m.law = 4;    // so3
  m.phase = 4;  // track_augmented
  m.trajectory_loaded = 1;
  m.omega_hat[0] = 3e-3;  // |w| = 5e-3 (3-4-5)
  m.omega_hat[1] = -4e-3;
  // Attitude error q = [tan(pi/8), 0, 0]: a 90 degree rotation, |q| = 0.414214.
  m.attitude_error[0] = std::tan(M_PI / 8.0);
  m.q_hat[2] = 0.25;
  m.saturated = 1;
  m.alloc_scale = 0.5;
  m.thrusters_enabled = 1;
  m.torque_requested[2] = 150.0;
  m.fuel_kg = 87.654321;
  m.base_ticks = 20000;
  m.base_missed = 3;
  m.rate_group_count = 2;
  m.rg_cycles[0] = 12345;
  m.rg_last_exec_ns[0] = 1500000;  // 1.5 ms
  m.rg_max_exec_ns[0] = 2250000;   // 2.25 ms
  m.rg_slips[0] = 2;
  m.rg_missed[0] = 1;
  m.rg_cycles[1] = 1234;
  m.rg_cycles[2] = 999;  // beyond rate_group_count: not shown
  m.cmd_accepted = 17;
  m.cmd_rejected = 4;
  m.cmd_last_seq = 21;
  m.cmd_last_opcode = 2;
  m.cmd_last_reject = 7;
  m.rx_ok = 5000;
  m.rx_malformed = 6;
  m.rx_bad_kind = 7;
  m.rx_out_of_range = 8;
  m.uplink_id = 33;
  m.uplink_chunks_received = 5;
  m.uplink_total_chunks = 32;
  return m;
}

TEST(MonitorFormat, StatusBlockShowsEverySection) {
  MonitorCounts c;
  c.rx.ok = 100;
  c.rx.too_short = 2;
  c.rx.bad_kind = 1;
  const std::string s = joined(format_status(sample(), c));
  expect_has(s, "t=1234.500 s");
  expect_has(s, "mode TRACK");
  expect_has(s, "law so3");
  expect_has(s, "phase track_augmented");
  expect_has(s, "trajectory loaded");
  expect_has(s, "|w|=5.000000e-03 rad/s");
  expect_has(s, "w=[ 3.000000e-03 -4.000000e-03  0.000000e+00]");
  expect_has(s, "|err|=0.414214 (90.000 deg)");
  expect_has(s, "saturated yes");
  expect_has(s, "scale 0.5000");
  expect_has(s, "|u_c|=1.5000e+02 N m");
  expect_has(s, "fuel 87.6543 kg");
  expect_has(s, "base ticks 20000  missed 3");
  expect_has(s, "gnc  cycles 12345  last 1.500 ms  max 2.250 ms  slips 2  missed 1");
  expect_has(s, "hk   cycles 1234");
  EXPECT_EQ(s.find("cycles 999"), std::string::npos) << s;
  expect_has(
      s, "accepted 17  rejected 4  last seq 21 SET_TARGET  last reject not allowed in this mode");
  expect_has(s, "fsw: ok 5000  malformed 6  bad kind 7  out of range 8");
  expect_has(s, "monitor: ok 100  rejected 3");
  expect_has(s, "uplink id 33  5/32 chunks");
  for (const std::string& line : format_status(sample(), c)) {
    EXPECT_EQ(line.find('\n'), std::string::npos);
  }
}

TEST(MonitorFormat, StatusLineCarriesTheEssentials) {
  const std::string l = format_status_line(sample(), MonitorCounts{});
  EXPECT_EQ(l.find('\n'), std::string::npos);
  expect_has(l, "t=1234.500 mode=TRACK law=so3 phase=track_augmented");
  expect_has(l, "|w|=5.000000e-03");
  expect_has(l, "|err|=0.414214");
  expect_has(l, "fuel=87.6543");
  expect_has(l, "sat=1");
  expect_has(l, "gnc_cycles=12345 last_ms=1.500 max_ms=2.250 slips=2 missed=1");
  expect_has(l, "cmd_acc=17 cmd_rej=4");
  expect_has(l, "rx_malformed=6 rx_bad_kind=7 rx_out_of_range=8");
}

TEST(MonitorFormat, IdleVehicleShowsThrustersOffAndNoUplink) {
  auto m = wire::make<rocksteady::gnc_telemetry_t>();
  m.uplink_id = -1;
  m.cmd_last_opcode = -1;
  const std::string s = joined(format_status(m, MonitorCounts{}));
  expect_has(s, "mode IDLE");
  expect_has(s, "thrusters OFF");
  expect_has(s, "uplink none");
  expect_has(s, "last seq 0 -  last reject -");
  expect_has(s, "|err|=0.000000 (0.000 deg)");
}

TEST(MonitorFormat, MrpAngleIsFourArctanOfTheNorm) {
  const double q[3] = {0.0, std::tan(M_PI / 12.0), 0.0};  // 60 degrees
  EXPECT_NEAR(mrp_angle_deg(q), 60.0, 1e-12);
  const double w[3] = {1.0, 2.0, 2.0};
  EXPECT_DOUBLE_EQ(norm3(w), 3.0);
}

TEST(MonitorFormat, EventLineHasSeverityNameArgumentsAndText) {
  auto e = wire::make<rocksteady::event_t>();
  e.t = 12.3;
  e.severity = rocksteady::event_t::SEV_WARNING;
  e.id = static_cast<std::int32_t>(fsw::EventId::kCommandRejected);
  e.arg0 = 2;
  e.arg1 = 7;
  e.text = "SET_TARGET rejected";
  EXPECT_EQ(format_event(e),
            "[t=12.300] WARNING command_rejected (101) arg0=2 arg1=7: SET_TARGET rejected");
  e.id = 1003;  // a plant event: no name on the ground
  e.text.clear();
  EXPECT_EQ(format_event(e), "[t=12.300] WARNING event 1003 (1003) arg0=2 arg1=7");
}

TEST(MonitorFormat, AckVerdictNamesReasonDetailAndText) {
  auto a = wire::make<rocksteady::cmd_ack_t>();
  a.seq = 9;
  a.sender_id = 1;
  a.opcode = 1;
  a.accepted = 1;
  EXPECT_EQ(format_ack_verdict(a), "ACCEPTED");
  EXPECT_EQ(format_ack(a), "ack seq 9 from 1 SET_MODE: ACCEPTED");
  a.accepted = 0;
  a.reason = rocksteady::cmd_ack_t::REASON_NOT_ALLOWED_IN_MODE;
  a.detail = static_cast<std::int32_t>(gnc::TransitionCheck::kNoTrajectory);
  a.text = "no valid trajectory loaded";
  EXPECT_EQ(format_ack_verdict(a),
            "REJECTED: not allowed in this mode (no valid trajectory loaded)");
  a.text = "opcode not allowed in this mode";
  EXPECT_EQ(
      format_ack_verdict(a),
      "REJECTED: not allowed in this mode (no valid trajectory loaded): opcode not allowed in "
      "this mode");
  a.reason = rocksteady::cmd_ack_t::REASON_UPLOAD_INCOMPLETE;
  a.detail = 3;
  a.text = "";
  EXPECT_EQ(format_ack_verdict(a), "REJECTED: uplink incomplete (3 chunks received)");
  a.reason = rocksteady::cmd_ack_t::REASON_STALE_SEQUENCE;
  a.detail = 0;
  EXPECT_EQ(format_ack_verdict(a), "REJECTED: stale or repeated sequence number");
}

// Event and acknowledgement text from the bus reaches the terminal without a single control
// character: ESC sequences (clear screen, cursor moves, OSC title), C1 CSI, DEL, bare CR/BS and
// broken UTF-8 are shown as \xNN; printable text and valid UTF-8 pass unchanged.
TEST(MonitorFormat, BusTextIsSanitisedBeforeTheTerminal) {
  rocksteady::event_t e{};
  e.kind = rocksteady::event_t::KIND;
  e.version = rocksteady::event_t::VERSION;
  e.text = "ok \x1b[2J\x1b[H\x1b]0;owned\x07 \r\b\x7f \xc2\x9b" "31m \xff\xfe caf\xc3\xa9 \xe2\x86\x92";
  const std::string s = format_event(e);
  for (const char c : s) {
    const auto u = static_cast<unsigned char>(c);
    EXPECT_FALSE(u < 0x20 || u == 0x7f) << static_cast<int>(u);
  }
  EXPECT_NE(s.find("ok \\x1b[2J\\x1b[H\\x1b]0;owned\\x07 \\x0d\\x08\\x7f \\xc2\\x9b31m \\xff\\xfe"),
            std::string::npos)
      << s;
  EXPECT_NE(s.find("caf\xc3\xa9 \xe2\x86\x92"), std::string::npos) << s;  // valid UTF-8 kept
  rocksteady::cmd_ack_t a{};
  a.accepted = 0;
  a.reason = 4;
  a.text = "bad\x1b[31m";
  EXPECT_EQ(format_ack_verdict(a).find('\x1b'), std::string::npos);
  EXPECT_EQ(sanitize_text("plain text, 100%"), "plain text, 100%");
}

}  // namespace
}  // namespace rocksteady::ground::cli
