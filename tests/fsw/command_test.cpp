// Ground-command validation: every reject reason, the acknowledgement and event contract, the
// sequence-number rule, and the tick boundary at which accepted commands take effect.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "fsw/commands/command_table.hpp"
#include "fsw_harness.hpp"

namespace rocksteady::fsw {
namespace {

using test::AppFixture;
using test::command;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

double mode_arg(gnc::Mode m) {
  return static_cast<double>(static_cast<int>(m));
}
double law_arg(gnc::LawId l) {
  return static_cast<double>(static_cast<int>(l));
}
double ref_arg(ReferenceId r) {
  return static_cast<double>(static_cast<int>(r));
}

TEST(CommandTable, RowsMatchTheirOpcodeAndRejectOneArgumentTooManyOrTooFew) {
  const auto& table = opcode_table();
  for (int i = 0; i < kOpcodeCount; ++i) {
    const OpcodeSpec& s = table[i];
    EXPECT_EQ(static_cast<int>(s.opcode), i);
    GroundCommand c;
    c.opcode = i;
    c.arg_count = s.max_args + 1;
    EXPECT_EQ(check_command(c, gnc::Mode::kIdle).reason, RejectReason::kBadLength) << i;
    if (s.min_args > 0) {
      c.arg_count = s.min_args - 1;
      EXPECT_EQ(check_command(c, gnc::Mode::kIdle).reason, RejectReason::kBadLength) << i;
    }
  }
}

TEST(CommandValidation, UnknownOpcode) {
  AppFixture f;
  for (const std::int32_t op : {-1, kOpcodeCount, 42}) {
    GroundCommand c = command(++f.seq, Opcode::kNoop);
    c.opcode = op;
    const CommandAck a = f.app->submit(c);
    EXPECT_FALSE(a.accepted);
    EXPECT_EQ(a.reason, RejectReason::kUnknownOpcode);
    EXPECT_EQ(a.opcode, op);
  }
}

TEST(CommandValidation, BadLength) {
  AppFixture f;
  EXPECT_EQ(f.send(Opcode::kSetMode).reason, RejectReason::kBadLength);
  EXPECT_EQ(f.send(Opcode::kSetTarget, {0.1, 0.2}).reason, RejectReason::kBadLength);
  EXPECT_EQ(f.send(Opcode::kNoop, {1.0}).reason, RejectReason::kBadLength);
  GroundCommand c = command(++f.seq, Opcode::kNoop);
  c.arg_count = -3;
  EXPECT_EQ(f.app->submit(c).reason, RejectReason::kBadLength);
  c = command(++f.seq, Opcode::kSetTarget, {0, 0, 0});
  c.arg_count = kMaxCommandArgs + 1;
  EXPECT_EQ(f.app->submit(c).reason, RejectReason::kBadLength);
  // The value count of a parameter: a matrix takes 3 or 6 values, a scalar 1.
  const double k_ntcl = static_cast<double>(static_cast<int>(ParamId::kNtclK));
  const double k_p = static_cast<double>(static_cast<int>(ParamId::kDpdKp));
  EXPECT_EQ(f.send(Opcode::kParamLoad, {k_ntcl, 1, 2}).reason, RejectReason::kBadLength);
  EXPECT_EQ(f.send(Opcode::kParamLoad, {k_ntcl, 1, 2, 3, 4}).reason, RejectReason::kBadLength);
  EXPECT_EQ(f.send(Opcode::kParamLoad, {k_p, 1, 2}).reason, RejectReason::kBadLength);
}

TEST(CommandValidation, NonFiniteArgument) {
  AppFixture f;
  const CommandAck a = f.send(Opcode::kSetTarget, {0.1, kNaN, 0.0});
  EXPECT_EQ(a.reason, RejectReason::kArgNotFinite);
  EXPECT_EQ(a.detail, 1);  // the index of the bad argument
  EXPECT_EQ(f.send(Opcode::kSetMode, {kInf}).reason, RejectReason::kArgNotFinite);
  EXPECT_EQ(f.send(Opcode::kParamLoad, {18.0, -kInf}).reason, RejectReason::kArgNotFinite);
}

TEST(CommandValidation, OutOfRangeArgument) {
  AppFixture f;
  EXPECT_EQ(f.send(Opcode::kSetMode, {5.0}).reason, RejectReason::kOutOfRange);
  EXPECT_EQ(f.send(Opcode::kSetMode, {-1.0}).reason, RejectReason::kOutOfRange);
  EXPECT_EQ(f.send(Opcode::kSetMode, {1.5}).reason, RejectReason::kOutOfRange);  // not an integer
  EXPECT_EQ(f.send(Opcode::kSetLaw, {7.0}).reason, RejectReason::kOutOfRange);
  const CommandAck ref = f.send(Opcode::kSetLaw, {0.0, 3.0});
  EXPECT_EQ(ref.reason, RejectReason::kOutOfRange);
  EXPECT_EQ(ref.detail, 1);
  EXPECT_EQ(f.send(Opcode::kSetTarget, {1.5, 0, 0}).reason, RejectReason::kOutOfRange);
  // Each component within [-1, 1] but |q| > 1.
  EXPECT_EQ(f.send(Opcode::kSetTarget, {0.8, 0.8, 0.0}).reason, RejectReason::kOutOfRange);
  EXPECT_EQ(f.send(Opcode::kParamLoad, {static_cast<double>(kParamCount), 1.0}).reason,
            RejectReason::kOutOfRange);
  const double auto_hold = static_cast<double>(static_cast<int>(ParamId::kAutoHold));
  EXPECT_EQ(f.send(Opcode::kParamLoad, {auto_hold, 2.0}).reason, RejectReason::kOutOfRange);
  EXPECT_EQ(f.send(Opcode::kLoadTrajectory, {-1.0}).reason, RejectReason::kOutOfRange);
  EXPECT_EQ(f.send(Opcode::kLoadTrajectory, {7.0}).reason, RejectReason::kOutOfRange);  // no such
  EXPECT_EQ(f.send(Opcode::kAbortUplink, {7.0}).reason, RejectReason::kOutOfRange);
}

TEST(CommandValidation, NotAllowedInThisMode) {
  AppFixture f;
  // No estimate before the first valid sample: no actuating mode.
  CommandAck a = f.send(Opcode::kSetMode, {mode_arg(gnc::Mode::kDetumble)});
  EXPECT_EQ(a.reason, RejectReason::kNotAllowedInMode);
  EXPECT_EQ(a.detail, static_cast<std::int32_t>(gnc::TransitionCheck::kNoEstimate));
  f.ticks(2);
  a = f.send(Opcode::kSetMode, {mode_arg(gnc::Mode::kIdle)});
  EXPECT_EQ(a.reason, RejectReason::kNotAllowedInMode);
  EXPECT_EQ(a.detail, static_cast<std::int32_t>(gnc::TransitionCheck::kSameMode));
  a = f.send(Opcode::kSetMode, {mode_arg(gnc::Mode::kTrack)});
  EXPECT_EQ(a.detail, static_cast<std::int32_t>(gnc::TransitionCheck::kNoTrajectory));
  a = f.send(Opcode::kSetLaw, {law_arg(gnc::LawId::kDpd), ref_arg(ReferenceId::kFuelOptimal)});
  EXPECT_EQ(a.reason, RejectReason::kNotAllowedInMode);
  EXPECT_EQ(a.detail, static_cast<std::int32_t>(gnc::TransitionCheck::kLawCannotTrack));
  // SAFE is left for IDLE or DETUMBLE only.
  ASSERT_TRUE(f.send(Opcode::kSetMode, {mode_arg(gnc::Mode::kSafe)}).accepted);
  f.ticks(1);
  ASSERT_EQ(f.app->mode(), gnc::Mode::kSafe);
  a = f.send(Opcode::kSetMode, {mode_arg(gnc::Mode::kHold)});
  EXPECT_EQ(a.reason, RejectReason::kNotAllowedInMode);
  EXPECT_EQ(a.detail, static_cast<std::int32_t>(gnc::TransitionCheck::kNotAllowed));
  EXPECT_TRUE(f.send(Opcode::kSetMode, {mode_arg(gnc::Mode::kDetumble)}).accepted);
}

TEST(CommandValidation, ValidationUsesTheModeThePendingRequestsLeadTo) {
  AppFixture f;
  f.ticks(2);
  ASSERT_TRUE(f.send(Opcode::kSetMode, {mode_arg(gnc::Mode::kSafe)}).accepted);
  // Still IDLE now, but SAFE at the next tick: SAFE -> HOLD is not allowed.
  EXPECT_EQ(f.app->mode(), gnc::Mode::kIdle);
  EXPECT_EQ(f.send(Opcode::kSetMode, {mode_arg(gnc::Mode::kHold)}).reason,
            RejectReason::kNotAllowedInMode);
}

TEST(CommandValidation, StaleOrRepeatedSequenceNumber) {
  AppFixture f;
  EXPECT_TRUE(f.app->submit(command(5, Opcode::kNoop)).accepted);
  CommandAck a = f.app->submit(command(5, Opcode::kNoop));
  EXPECT_EQ(a.reason, RejectReason::kStaleSequence);
  EXPECT_EQ(f.app->submit(command(4, Opcode::kNoop)).reason, RejectReason::kStaleSequence);
  EXPECT_TRUE(f.app->submit(command(6, Opcode::kNoop)).accepted);
  // Per source: another sender starts its own numbering; numbers start above 0.
  EXPECT_TRUE(f.app->submit(command(1, Opcode::kNoop, {}, 2)).accepted);
  EXPECT_EQ(f.app->submit(command(0, Opcode::kNoop, {}, 3)).reason, RejectReason::kStaleSequence);
  EXPECT_EQ(f.app->submit(command(-7, Opcode::kNoop, {}, 3)).reason, RejectReason::kStaleSequence);
  // A rejected command does not use up its number (cmd_ack_t: "newer than the last accepted").
  EXPECT_EQ(f.app->submit(command(7, Opcode::kSetMode, {9.0})).reason, RejectReason::kOutOfRange);
  EXPECT_TRUE(f.app->submit(command(7, Opcode::kNoop)).accepted);
  // A stale number is refused before anything else is looked at.
  GroundCommand c = command(7, Opcode::kNoop);
  c.opcode = 99;
  EXPECT_EQ(f.app->submit(c).reason, RejectReason::kStaleSequence);
}

TEST(CommandValidation, BusyWhenQueueIsFullNeverWhenTheSourceTableIs) {
  AppFixture f;
  int accepted = 0;
  CommandAck last;
  for (int i = 0; i < 20; ++i) {
    last = f.send(Opcode::kSetTarget, {0.01 * i, 0, 0});
    accepted += last.accepted ? 1 : 0;
  }
  EXPECT_EQ(accepted, 16);  // the pending queue's capacity
  EXPECT_EQ(last.reason, RejectReason::kBusy);
  AppFixture g;
  for (std::int32_t src = 0; src < SequenceTracker::kMaxSources; ++src) {
    ASSERT_TRUE(g.app->submit(command(1, Opcode::kNoop, {}, 100 + src)).accepted);
  }
  // Lab mode: a new source takes the least recently used slot, so sources cannot lock each other
  // out (with keys there is no per-source state at all: fsw/auth).
  EXPECT_TRUE(g.app->submit(command(1, Opcode::kNoop, {}, 999)).accepted);
  EXPECT_FALSE(g.app->submit(command(1, Opcode::kNoop, {}, 999)).accepted);  // its own seq state
}

TEST(CommandValidation, InvalidParameterTableAndNothingToActivate) {
  AppFixture f;
  EXPECT_EQ(f.send(Opcode::kParamActivate).reason, RejectReason::kNothingToActivate);
  EXPECT_EQ(f.send(Opcode::kParamDiscard).reason, RejectReason::kNothingToActivate);
  const double k_ntcl = static_cast<double>(static_cast<int>(ParamId::kNtclK));
  const CommandAck a = f.send(Opcode::kParamLoad, {k_ntcl, -1.0, 4.0, 4.0});
  EXPECT_EQ(a.reason, RejectReason::kInvalidTable);
  EXPECT_STREQ(a.text, "ntcl.K");
}

TEST(CommandContract, EveryCommandIsAnsweredWithAnEventAndCounted) {
  AppFixture f;
  test::drain(*f.app);  // the lab-mode announcement
  const CommandAck ok = f.send(Opcode::kNoop);
  const CommandAck bad = f.send(Opcode::kSetMode, {17.0});
  EXPECT_TRUE(ok.accepted);
  EXPECT_EQ(ok.reason, RejectReason::kNone);
  EXPECT_EQ(ok.seq, 1);
  EXPECT_EQ(ok.source, 1);
  EXPECT_FALSE(bad.accepted);
  EXPECT_EQ(bad.seq, 2);
  const std::vector<Event> ev = test::drain(*f.app);
  ASSERT_EQ(ev.size(), 2u);
  EXPECT_EQ(ev[0].id, EventId::kCommandAccepted);
  EXPECT_EQ(ev[0].severity, Severity::kInfo);
  EXPECT_EQ(ev[1].id, EventId::kCommandRejected);
  EXPECT_EQ(ev[1].severity, Severity::kWarning);
  EXPECT_EQ(ev[1].arg1, static_cast<std::int32_t>(RejectReason::kOutOfRange));
  EXPECT_NE(std::string(ev[1].text.data()).find("out-of-range"), std::string::npos);
  const HealthTelemetry h = f.app->health();
  EXPECT_EQ(h.cmd_accepted, 1u);
  EXPECT_EQ(h.cmd_rejected, 1u);
  EXPECT_EQ(h.last_reject, RejectReason::kOutOfRange);
  EXPECT_EQ(h.last_cmd_seq, 2);
}

TEST(CommandContract, ModeChangesTakeEffectAtTheNextTick) {
  AppFixture f;
  f.loop.truth.omega = test::V3(0.05, -0.03, 0.02);
  f.ticks(3);
  ASSERT_TRUE(f.send(Opcode::kSetMode, {mode_arg(gnc::Mode::kDetumble)}).accepted);
  EXPECT_EQ(f.app->mode(), gnc::Mode::kIdle);
  EXPECT_EQ(f.app->pending_commands(), 1);
  f.ticks(1);
  EXPECT_EQ(f.app->mode(), gnc::Mode::kDetumble);
  EXPECT_TRUE(f.out.command.enabled);
  EXPECT_EQ(f.app->pending_commands(), 0);
}

TEST(CommandContract, QueuedRequestsApplyInOrderOnePerTickWhenTheyConflict) {
  AppFixture f;
  f.loop.truth.omega = test::V3(0.05, -0.03, 0.02);
  f.ticks(3);
  ASSERT_TRUE(f.send(Opcode::kSetMode, {mode_arg(gnc::Mode::kDetumble)}).accepted);
  ASSERT_TRUE(f.send(Opcode::kSetMode, {mode_arg(gnc::Mode::kSafe)}).accepted);
  f.ticks(1);
  EXPECT_EQ(f.app->mode(), gnc::Mode::kDetumble);
  f.ticks(1);
  EXPECT_EQ(f.app->mode(), gnc::Mode::kSafe);
  EXPECT_FALSE(f.out.command.enabled);
}

TEST(CommandContract, ResetCountersAtTheTickBoundary) {
  AppFixture f;
  f.send(Opcode::kSetMode, {17.0});
  f.send(Opcode::kNoop);
  ASSERT_TRUE(f.send(Opcode::kResetCounters).accepted);
  EXPECT_EQ(f.app->health().cmd_rejected, 1u);
  f.ticks(1);
  const HealthTelemetry h = f.app->health();
  EXPECT_EQ(h.cmd_accepted, 0u);
  EXPECT_EQ(h.cmd_rejected, 0u);
  EXPECT_EQ(h.last_reject, RejectReason::kNone);
  // The sequence numbers are not reset: a replay stays a replay.
  EXPECT_EQ(f.app->submit(command(2, Opcode::kNoop)).reason, RejectReason::kStaleSequence);
}

TEST(CommandContract, UninitialisedApplicationRejectsAndCommandsNothing) {
  auto app = std::make_unique<FlightApp>();
  const CommandAck a = app->submit(command(1, Opcode::kNoop));
  EXPECT_FALSE(a.accepted);
  Outputs out;
  out.gnc_ran = true;
  app->gnc_tick(gnc::SensorSample{}, out);
  EXPECT_FALSE(out.gnc_ran);
}

}  // namespace
}  // namespace rocksteady::fsw

namespace rocksteady::fsw {
namespace {

// Fault management from the ground: accepted, queued, and applied by the core at the next tick
// boundary (the telemetry of that tick shows it); out-of-range arguments are refused.
TEST(FaultCommands, DeclareValveInhibitAndClearReachTheCoreAtTheBoundary) {
  test::AppFixture f;
  f.ticks(2);
  EXPECT_TRUE(f.send(Opcode::kFaultDeclare, {5.0, 2.0}).accepted);  // thruster 5 stuck off
  EXPECT_TRUE(f.send(Opcode::kValve, {3.0, 0.0}).accepted);         // close pod 3
  EXPECT_TRUE(f.send(Opcode::kIsolationInhibit, {1.0}).accepted);
  EXPECT_EQ(f.out.telemetry.fdi.confirmed_off, 0u);  // nothing before the boundary
  f.ticks(1);
  EXPECT_EQ(f.out.telemetry.fdi.confirmed_off, 1u << 5);
  EXPECT_FALSE(f.out.telemetry.fdi.valve_open[3]);
  EXPECT_FALSE(f.out.command.valve_open[3]);
  EXPECT_TRUE(f.out.telemetry.fdi.isolation_inhibited);
  EXPECT_TRUE(f.send(Opcode::kFaultClear, {-1.0}).accepted);
  EXPECT_TRUE(f.send(Opcode::kValve, {3.0, 1.0}).accepted);
  f.ticks(2);
  EXPECT_EQ(f.out.telemetry.fdi.confirmed_off, 0u);
  EXPECT_TRUE(f.out.command.valve_open[3]);
  EXPECT_EQ(f.send(Opcode::kFaultDeclare, {16.0, 1.0}).reason, RejectReason::kOutOfRange);
  EXPECT_EQ(f.send(Opcode::kFaultDeclare, {3.0, 0.0}).reason, RejectReason::kOutOfRange);
  EXPECT_EQ(f.send(Opcode::kValve, {4.0, 1.0}).reason, RejectReason::kOutOfRange);
  EXPECT_EQ(f.send(Opcode::kFaultClear, {-2.0}).reason, RejectReason::kOutOfRange);
}

// A degraded thruster is declared with the fraction of its thrust it delivers (F18): latched at
// the boundary with that factor; without a factor, or a factor on a stuck kind, or out of
// (0.01, 0.99), the command is refused with the reason.
TEST(FaultCommands, ADegradedThrusterIsDeclaredWithItsFactor) {
  test::AppFixture f;
  f.ticks(2);
  EXPECT_EQ(f.send(Opcode::kFaultDeclare, {6.0, 3.0}).reason, RejectReason::kBadLength);
  EXPECT_EQ(f.send(Opcode::kFaultDeclare, {6.0, 2.0, 0.5}).reason, RejectReason::kBadLength);
  EXPECT_EQ(f.send(Opcode::kFaultDeclare, {6.0, 3.0, 1.5}).reason, RejectReason::kOutOfRange);
  EXPECT_EQ(f.send(Opcode::kFaultDeclare, {6.0, 3.0, 0.0}).reason, RejectReason::kOutOfRange);
  f.ticks(1);
  EXPECT_EQ(f.out.telemetry.fdi.confirmed_degraded, 0u);  // nothing refused reached the core
  EXPECT_TRUE(f.send(Opcode::kFaultDeclare, {6.0, 3.0, 0.7}).accepted);
  f.ticks(1);
  EXPECT_EQ(f.out.telemetry.fdi.confirmed_degraded, 1u << 6);
  EXPECT_DOUBLE_EQ(f.out.telemetry.fdi.strength_factor(6), 0.7);
  EXPECT_EQ(f.out.telemetry.fdi.confirmed_on | f.out.telemetry.fdi.confirmed_off, 0u);
  EXPECT_TRUE(f.send(Opcode::kFaultClear, {6.0}).accepted);
  f.ticks(1);
  EXPECT_EQ(f.out.telemetry.fdi.confirmed_degraded, 0u);
  EXPECT_DOUBLE_EQ(f.out.telemetry.fdi.strength_factor(6), 1.0);
}

TEST(FaultCommands, LoadIdentifiedIsRefusedWithTheReasonWhileIdentificationIsOff) {
  test::AppFixture f;
  f.ticks(1);
  const CommandAck a = f.send(Opcode::kParamLoadIdentified);
  EXPECT_FALSE(a.accepted);
  EXPECT_EQ(a.reason, RejectReason::kInvalidTable);
  // Nothing was loaded: an activation finds nothing to activate.
  EXPECT_EQ(f.send(Opcode::kParamActivate).reason, RejectReason::kNothingToActivate);
}

}  // namespace
}  // namespace rocksteady::fsw
