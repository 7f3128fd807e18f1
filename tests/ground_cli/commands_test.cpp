// Operator input -> ground_cmd_t: every command the console can send passes the flight side's own
// validator (fsw::check_command) in a mode where it is allowed, carries the numbers the flight
// application interprets, and bad input is refused on the ground with a message naming the problem.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <set>
#include <string>
#include <vector>

#include "fsw/commands/command_table.hpp"
#include "fsw/params/param_table.hpp"
#include "gnc/params.hpp"
#include "ground/cli/commands.hpp"
#include "ground/cli/dictionary.hpp"

namespace rocksteady::ground::cli {
namespace {

// The bus layer's mapping of ground_cmd_t onto the flight application's command.
fsw::GroundCommand to_flight(const rocksteady::ground_cmd_t& m) {
  fsw::GroundCommand c;
  c.seq = m.seq;
  c.source = m.sender_id;
  c.opcode = m.opcode;
  c.arg_count = m.nargs;
  for (int i = 0; i < m.nargs; ++i) c.args[static_cast<std::size_t>(i)] = m.args[i];
  return c;
}

std::string num(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

struct Case {
  std::string name;
  std::vector<std::string> args;
  bool quat;
  gnc::Mode mode;      // a mode the command is allowed in
  fsw::Opcode opcode;  // what the flight must see
  std::vector<double> expected_args;
};

std::vector<Case> cases() {
  const double tan_pi_8 = std::tan(M_PI / 8.0);  // MRP of a 90 deg rotation: tan(theta / 4)
  using M = gnc::Mode;
  using O = fsw::Opcode;
  auto law = [](gnc::LawId l) { return static_cast<double>(l); };
  auto ref = [](fsw::ReferenceId r) { return static_cast<double>(r); };
  return {
      {"noop", {}, false, M::kIdle, O::kNoop, {}},
      {"set-mode", {"IDLE"}, false, M::kSafe, O::kSetMode, {0}},
      {"set-mode", {"detumble"}, false, M::kIdle, O::kSetMode, {static_cast<double>(M::kDetumble)}},
      {"set-mode", {"HOLD"}, false, M::kDetumble, O::kSetMode, {static_cast<double>(M::kHold)}},
      {"set-mode", {"TRACK"}, false, M::kHold, O::kSetMode, {static_cast<double>(M::kTrack)}},
      {"set-mode", {"SAFE"}, false, M::kTrack, O::kSetMode, {static_cast<double>(M::kSafe)}},
      {"set-target", {"-0.1", "0", "0.2"}, false, M::kHold, O::kSetTarget, {-0.1, 0.0, 0.2}},
      {"set-target", {"0", "0", "1"}, false, M::kIdle, O::kSetTarget, {0.0, 0.0, 1.0}},
      {"set-target",
       {"0", "0", num(std::sin(M_PI / 4)), num(std::cos(M_PI / 4))},
       true,
       M::kHold,
       O::kSetTarget,
       {0.0, 0.0, tan_pi_8}},
      {"set-target", {"1", "0", "0", "0"}, true, M::kHold, O::kSetTarget, {1.0, 0.0, 0.0}},
      {"select-law", {"ntcl"}, false, M::kHold, O::kSetLaw, {law(gnc::LawId::kNtcl)}},
      {"select-law", {"el"}, false, M::kHold, O::kSetLaw, {law(gnc::LawId::kNtclEl)}},
      {"select-law",
       {"integral", "keep"},
       false,
       M::kHold,
       O::kSetLaw,
       {law(gnc::LawId::kIntegral), ref(fsw::ReferenceId::kKeep)}},
      {"select-law",
       {"adaptive", "fuel-optimal"},
       false,
       M::kHold,
       O::kSetLaw,
       {law(gnc::LawId::kAdaptive), ref(fsw::ReferenceId::kFuelOptimal)}},
      {"select-law",
       {"so3", "fuel_optimal"},
       false,
       M::kTrack,
       O::kSetLaw,
       {law(gnc::LawId::kSo3), ref(fsw::ReferenceId::kFuelOptimal)}},
      {"select-law",
       {"dpd", "dpd-ref"},
       false,
       M::kIdle,
       O::kSetLaw,
       {law(gnc::LawId::kDpd), ref(fsw::ReferenceId::kDpdRef)}},
      {"select-law",
       {"feedforward"},
       false,
       M::kTrack,
       O::kSetLaw,
       {law(gnc::LawId::kFeedforward)}},
      {"set-gain",
       {"ntcl.K", "1e4", "2e4", "3e4"},
       false,
       M::kHold,
       O::kParamLoad,
       {0, 1e4, 2e4, 3e4}},
      {"set-gain",
       {"so3.Lambda", "1", "2", "3", "0.1", "0.2", "0.3"},
       false,
       M::kTrack,
       O::kParamLoad,
       {16, 1, 2, 3, 0.1, 0.2, 0.3}},
      {"set-gain",
       {"guidance.omega_switch", "0.002"},
       false,
       M::kDetumble,
       O::kParamLoad,
       {19, 0.002}},
      {"set-gain", {"24", "0"}, false, M::kIdle, O::kParamLoad, {24, 0}},
      {"activate-gains", {}, false, M::kHold, O::kParamActivate, {}},
      {"discard-gains", {}, false, M::kHold, O::kParamDiscard, {}},
      {"dump-params", {}, false, M::kTrack, O::kParamDump, {}},
      {"load-identified", {}, false, M::kDetumble, O::kParamLoadIdentified, {}},
      {"declare-fault", {"7", "stuck-on"}, false, M::kDetumble, O::kFaultDeclare, {7.0, 1.0}},
      {"declare-fault", {"15", "stuck-off"}, false, M::kHold, O::kFaultDeclare, {15.0, 2.0}},
      {"declare-fault", {"4", "degraded", "0.6"}, false, M::kDetumble, O::kFaultDeclare,
       {4.0, 3.0, 0.6}},
      {"clear-fault", {"all"}, false, M::kHold, O::kFaultClear, {-1.0}},
      {"clear-fault", {"3"}, false, M::kSafe, O::kFaultClear, {3.0}},
      {"valve", {"2", "close"}, false, M::kDetumble, O::kValve, {2.0, 0.0}},
      {"valve", {"0", "open"}, false, M::kHold, O::kValve, {0.0, 1.0}},
      {"isolation", {"inhibit"}, false, M::kHold, O::kIsolationInhibit, {1.0}},
      {"reset-counters", {}, false, M::kSafe, O::kResetCounters, {}},
      {"load-trajectory", {"7"}, false, M::kHold, O::kLoadTrajectory, {7}},
      {"abort-uplink", {"2147483647"}, false, M::kTrack, O::kAbortUplink, {2147483647.0}},
      {"key-rotate", {"2"}, false, M::kTrack, O::kKeyRotate, {2}},
  };
}

TEST(GroundCommands, EveryCommandPassesTheFlightCommandCheck) {
  for (const Case& c : cases()) {
    SCOPED_TRACE(c.name + (c.args.empty() ? "" : " " + c.args[0]));
    EncodeOptions o;
    o.quaternion = c.quat;
    Encoded e = encode_command(c.name, c.args, o);
    ASSERT_TRUE(e.ok) << e.error;
    EXPECT_EQ(e.cmd.kind, static_cast<int>(rocksteady::ground_cmd_t::KIND));
    EXPECT_EQ(e.cmd.version, static_cast<int>(rocksteady::ground_cmd_t::VERSION));
    stamp(e.cmd, 42, 3);
    const fsw::GroundCommand f = to_flight(e.cmd);
    EXPECT_EQ(f.seq, 42);
    EXPECT_EQ(f.source, 3);
    EXPECT_EQ(f.opcode, static_cast<std::int32_t>(c.opcode));
    ASSERT_EQ(f.arg_count, static_cast<int>(c.expected_args.size()));
    for (std::size_t i = 0; i < c.expected_args.size(); ++i) {
      EXPECT_NEAR(f.args[i], c.expected_args[i], 1e-12) << "argument " << i;
    }
    const fsw::CommandCheck check = fsw::check_command(f, c.mode);
    EXPECT_TRUE(check.ok()) << fsw::to_string(check.reason) << ": " << check.text;
  }
}

TEST(GroundCommands, EveryListedCommandIsCoveredByTheFlightCheckTest) {
  std::set<std::string> covered;
  for (const Case& c : cases()) covered.insert(c.name);
  for (const CommandHelp& h : command_help()) {
    if (std::string(h.name) == "upload-trajectory")
      continue;  // a procedure (its load: load-trajectory)
    EXPECT_TRUE(covered.count(h.name)) << h.name;
  }
}

TEST(GroundCommands, SetTargetIsRefusedByTheFlightWhileTracking) {
  const Encoded e = encode_command("set-target", {"0", "0", "0.1"});
  ASSERT_TRUE(e.ok);
  const fsw::CommandCheck check = fsw::check_command(to_flight(e.cmd), gnc::Mode::kTrack);
  EXPECT_EQ(check.reason, fsw::RejectReason::kNotAllowedInMode);
}

// set-gain values, written by the flight's own parameter writer, land in the right field.
TEST(GroundCommands, SetGainValuesAreWhatTheFlightParameterWriterExpects) {
  const Encoded e = encode_command("set-gain", {"so3.Lambda", "1", "2", "3", "0.1", "0.2", "0.3"});
  ASSERT_TRUE(e.ok) << e.error;
  gnc::GncParams p;
  const auto id = static_cast<std::int32_t>(e.cmd.args[0]);
  const fsw::ParamLoadResult r = fsw::write_param(p, id, &e.cmd.args[1], e.cmd.nargs - 1);
  ASSERT_TRUE(r.ok()) << r.text;
  gnc::Mat3 expected;
  expected << 1, 0.1, 0.2, 0.1, 2, 0.3, 0.2, 0.3, 3;
  EXPECT_TRUE(p.so3.lambda.isApprox(expected));

  const Encoded s = encode_command("set-gain", {"dpd.k_p", "2.5"});
  ASSERT_TRUE(s.ok);
  ASSERT_TRUE(
      fsw::write_param(p, static_cast<std::int32_t>(s.cmd.args[0]), &s.cmd.args[1], s.cmd.nargs - 1)
          .ok());
  EXPECT_EQ(p.dpd.k_p, 2.5);
}

struct Bad {
  std::string name;
  std::vector<std::string> args;
  bool quat;
  std::string message;  // part of the error the operator sees
};

TEST(GroundCommands, BadOperatorInputIsRefusedLocallyWithAClearMessage) {
  const std::vector<Bad> bad{
      {"frobnicate", {}, false, "unknown command 'frobnicate'"},
      {"noop", {"1"}, false, "noop takes no arguments, got 1"},
      {"set-mode", {}, false, "set-mode takes 1 argument, got 0"},
      {"set-mode", {"HOLD", "now"}, false, "set-mode takes 1 argument, got 2"},
      {"set-mode", {"CRUISE"}, false, "unknown mode 'CRUISE'"},
      {"set-target", {"0.1", "0.2"}, false, "set-target takes 3 arguments"},
      {"set-target", {"0.1", "x", "0.2"}, false, "argument 2 'x' is not a finite number"},
      {"set-target", {"0.1", "nan", "0.2"}, false, "'nan' is not a finite number"},
      {"set-target", {"inf", "0", "0"}, false, "'inf' is not a finite number"},
      {"set-target", {"1e999", "0", "0"}, false, "'1e999' is not a finite number"},
      {"set-target", {"0x1p-2", "0", "0"}, false, "'0x1p-2' is not a finite number"},
      {"set-target", {"0.8", "0.8", "0"}, false, "MRP norm 1.13137085 is above 1"},
      {"set-target", {"0", "0", "0.5"}, true, "takes 4 arguments with --quat"},
      {"set-target", {"0", "0", "0.5", "0.5"}, true, "is not 1"},
      {"select-law", {}, false, "select-law takes 1 or 2 arguments (law [reference]), got 0"},
      {"select-law", {"pid"}, false, "unknown law 'pid'"},
      {"select-law", {"ntcl", "sideways"}, false, "unknown reference 'sideways'"},
      {"select-law", {"dpd", "fuel-optimal"}, false, "D+PD law cannot track"},
      {"set-gain", {"ntcl.K"}, false, "set-gain takes a parameter and its values, got 1"},
      {"set-gain", {"ntcl.Q", "1"}, false, "unknown parameter 'ntcl.Q'"},
      {"set-gain", {"28", "1"}, false, "unknown parameter '28'"},
      {"set-gain", {"ntcl.K", "1", "2", "3", "4"}, false, "is a matrix: 3 values (diagonal) or 6"},
      {"set-gain", {"dpd.k_p", "1", "2"}, false, "is a scalar: 1 value, got 2"},
      {"set-gain", {"mode.auto_hold", "2"}, false, "is a flag: one value, 0 or 1"},
      {"set-gain", {"dpd.k_p", "1e31"}, false, "out of range"},
      {"set-gain", {"dpd.k_p", "fast"}, false, "'fast' is not a finite number"},
      {"activate-gains", {"now"}, false, "activate-gains takes no arguments"},
      {"load-trajectory", {}, false, "load-trajectory takes 1 argument"},
      {"load-trajectory", {"-1"}, false, "must be an integer in [0, 2147483647]"},
      {"abort-uplink", {"1.5"}, false, "must be an integer in [0, 2147483647]"},
      {"abort-uplink", {"2147483648"}, false, "must be an integer in [0, 2147483647]"},
      {"noop", {}, true, "--quat applies to set-target only"},
      {"declare-fault", {"4", "leaking"}, false, "kind must be stuck-on, stuck-off or degraded"},
      {"declare-fault", {"4", "degraded"}, false, "a degraded thruster needs its FACTOR"},
      {"declare-fault", {"4", "degraded", "1.2"}, false, "FACTOR must be a number in 0.01..0.99"},
      {"declare-fault", {"4", "degraded", "half"}, false, "FACTOR must be a number in 0.01..0.99"},
      {"declare-fault", {"4", "stuck-on", "0.5"}, false, "only a degraded thruster takes a FACTOR"},
  };
  for (const Bad& b : bad) {
    EncodeOptions o;
    o.quaternion = b.quat;
    const Encoded e = encode_command(b.name, b.args, o);
    EXPECT_FALSE(e.ok) << b.name;
    EXPECT_NE(e.error.find(b.message), std::string::npos)
        << b.name << ": '" << e.error << "' lacks '" << b.message << "'";
  }
}

TEST(GroundCommands, MrpAboveUnitNormSuggestsTheShadowSet) {
  const Encoded e = encode_command("set-target", {"2", "0", "0"});
  ASSERT_FALSE(e.ok);
  // Shadow set -q / |q|^2 = [-0.5 0 0]: the same attitude.
  EXPECT_NE(e.error.find("[-0.5 0 0]"), std::string::npos) << e.error;
}

TEST(GroundCommands, ParseNumberAcceptsOnlyFiniteDecimalNumbers) {
  double v = 0.0;
  EXPECT_TRUE(parse_number("-1.25e-3", v));
  EXPECT_EQ(v, -1.25e-3);
  EXPECT_TRUE(parse_number("+7", v));
  EXPECT_EQ(v, 7.0);
  for (const char* s : {"", " 1", "1 ", "1,5", "1e", "--1", "NaN", "infinity", "0x10", "1.0f"}) {
    EXPECT_FALSE(parse_number(s, v)) << "'" << s << "'";
  }
}

// The ground's dictionary and the flight's tables, entry by entry.
TEST(GroundDictionary, ParametersMatchTheFlightParameterTable) {
  const auto& flight = fsw::param_specs();
  ASSERT_EQ(param_dictionary().size(), flight.size());
  for (std::size_t i = 0; i < flight.size(); ++i) {
    const ParamEntry& g = param_dictionary()[i];
    EXPECT_EQ(g.id, static_cast<int>(flight[i].id));
    EXPECT_STREQ(g.name, flight[i].name);
    EXPECT_EQ(static_cast<int>(g.kind), static_cast<int>(flight[i].kind)) << g.name;
    const auto found = find_param(g.name);
    ASSERT_TRUE(found.has_value());
    EXPECT_EQ(found->id, g.id);
  }
}

TEST(GroundDictionary, NamesMatchTheFlightNames) {
  for (int r = 0; r < kReasonCount; ++r) {
    EXPECT_EQ(reason_name(r), fsw::to_string(static_cast<fsw::RejectReason>(r)));
  }
  for (int id = kFirstEventId; id <= kLastEventId; ++id) {
    EXPECT_EQ(event_name(id), fsw::to_string(static_cast<fsw::EventId>(id)));
  }
  for (int op = 0; op < fsw::kOpcodeCount; ++op) {
    EXPECT_EQ(opcode_name(op), fsw::to_string(static_cast<fsw::Opcode>(op)));
  }
  EXPECT_EQ(kChunkStatusOtherUplinkActive,
            static_cast<int>(fsw::ChunkStatus::kOtherUplinkActive));
  for (int s = 0; s <= static_cast<int>(fsw::ChunkStatus::kOtherUplinkActive); ++s) {
    EXPECT_EQ(chunk_status_name(s), fsw::to_string(static_cast<fsw::ChunkStatus>(s)));
  }
  for (int m = 0; m < gnc::kModeCount; ++m) {
    EXPECT_STREQ(mode_name(m), gnc::to_string(static_cast<gnc::Mode>(m)));
    EXPECT_EQ(mode_from_name(gnc::to_string(static_cast<gnc::Mode>(m))), m);
  }
  for (int l = 0; l < gnc::kLawCount; ++l) {
    EXPECT_STREQ(law_name(l), gnc::to_string(static_cast<gnc::LawId>(l)));
  }
  EXPECT_EQ(reference_from_name("dpd-ref"), static_cast<int>(fsw::ReferenceId::kDpdRef));
  EXPECT_EQ(reference_from_name("fuel-optimal"), static_cast<int>(fsw::ReferenceId::kFuelOptimal));
  EXPECT_EQ(reference_from_name("keep"), static_cast<int>(fsw::ReferenceId::kKeep));
}

TEST(GroundDictionary, OpcodeNumbersAreTheFlightOpcodes) {
  using G = rocksteady::ground_cmd_t;
  EXPECT_EQ(G::OP_COUNT, fsw::kOpcodeCount);
  EXPECT_EQ(G::OP_PARAM_LOAD, static_cast<int>(fsw::Opcode::kParamLoad));
  EXPECT_EQ(G::OP_PARAM_ACTIVATE, static_cast<int>(fsw::Opcode::kParamActivate));
  EXPECT_EQ(G::OP_PARAM_DISCARD, static_cast<int>(fsw::Opcode::kParamDiscard));
  EXPECT_EQ(G::OP_LOAD_TRAJECTORY, static_cast<int>(fsw::Opcode::kLoadTrajectory));
  EXPECT_EQ(G::OP_ABORT_UPLINK, static_cast<int>(fsw::Opcode::kAbortUplink));
}

// The ground refuses what the flight would refuse, with the same table and reason.
TEST(GroundCommands, SetGainChecksThePhysicalRangesBeforeSending) {
  const Encoded e = encode_command("set-gain", {"mode.sensor_timeout", "1e30"});
  EXPECT_FALSE(e.ok);
  EXPECT_NE(e.error.find("outside its physical range"), std::string::npos) << e.error;
  EXPECT_NE(e.error.find("mode.sensor_timeout"), std::string::npos) << e.error;
  EXPECT_TRUE(encode_command("set-gain", {"mode.sensor_timeout", "2"}).ok);
}

}  // namespace
}  // namespace rocksteady::ground::cli
