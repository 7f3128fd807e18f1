// The ground-command validator: each rule, with the reason the acknowledgement carries.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "gnc/params.hpp"
#include "hal/lcm/codec.hpp"
#include "hal/lcm/command.hpp"

namespace rocksteady::hal::wire {
namespace {

using Cmd = rocksteady::ground_cmd_t;
using Ack = rocksteady::cmd_ack_t;

Cmd command(std::int32_t opcode, std::initializer_list<double> args) {
  auto c = make<Cmd>();
  c.seq = 10;
  c.sender_id = 3;
  c.opcode = opcode;
  c.nargs = static_cast<std::int8_t>(args.size());
  int i = 0;
  for (const double a : args) c.args[i++] = a;
  return c;
}

std::int32_t reason(const Cmd& c) { return check_command(c).reason; }

TEST(CheckCommand, AcceptsWellFormedCommandsOfEveryOpcode) {
  EXPECT_EQ(reason(command(Cmd::OP_NOOP, {})), Ack::REASON_OK);
  EXPECT_EQ(reason(command(Cmd::OP_SET_MODE, {2.0})), Ack::REASON_OK);
  EXPECT_EQ(reason(command(Cmd::OP_SET_TARGET, {0.1, -0.2, 0.3})), Ack::REASON_OK);
  EXPECT_EQ(reason(command(Cmd::OP_SET_LAW, {5.0})), Ack::REASON_OK);
  EXPECT_EQ(reason(command(Cmd::OP_LOAD_TRAJECTORY, {7.0})), Ack::REASON_OK);
  EXPECT_EQ(reason(command(Cmd::OP_ABORT_UPLINK, {7.0})), Ack::REASON_OK);
  EXPECT_EQ(reason(command(Cmd::OP_RESET_COUNTERS, {})), Ack::REASON_OK);
  for (int op = 0; op < Cmd::OP_COUNT; ++op) EXPECT_GE(expected_args(op), 0) << op;
}

TEST(CheckCommand, RejectsUnknownOpcodes) {
  EXPECT_EQ(reason(command(Cmd::OP_COUNT, {})), Ack::REASON_UNKNOWN_OPCODE);
  EXPECT_EQ(reason(command(-1, {})), Ack::REASON_UNKNOWN_OPCODE);
  EXPECT_EQ(reason(command(std::numeric_limits<std::int32_t>::max(), {})), Ack::REASON_UNKNOWN_OPCODE);
}

TEST(CheckCommand, RejectsWrongArgumentCounts) {
  EXPECT_EQ(reason(command(Cmd::OP_SET_MODE, {})), Ack::REASON_BAD_ARG_COUNT);
  EXPECT_EQ(reason(command(Cmd::OP_SET_TARGET, {0.0, 0.0})), Ack::REASON_BAD_ARG_COUNT);
  EXPECT_EQ(reason(command(Cmd::OP_NOOP, {1.0})), Ack::REASON_BAD_ARG_COUNT);
}

TEST(CheckCommand, RejectsNonFiniteArgumentsAndNamesTheIndex) {
  const CommandCheck c = check_command(command(Cmd::OP_SET_TARGET, {0.0, NAN, 0.0}));
  EXPECT_EQ(c.reason, Ack::REASON_ARG_NOT_FINITE);
  EXPECT_EQ(c.detail, 1);
  EXPECT_EQ(reason(command(Cmd::OP_SET_MODE, {INFINITY})), Ack::REASON_ARG_NOT_FINITE);
}

TEST(CheckCommand, RejectsOutOfRangeModesLawsIdsAndTargets) {
  EXPECT_EQ(reason(command(Cmd::OP_SET_MODE, {static_cast<double>(gnc::kModeCount)})),
            Ack::REASON_ARG_OUT_OF_RANGE);
  EXPECT_EQ(reason(command(Cmd::OP_SET_MODE, {-1.0})), Ack::REASON_ARG_OUT_OF_RANGE);
  EXPECT_EQ(reason(command(Cmd::OP_SET_MODE, {1.5})), Ack::REASON_ARG_OUT_OF_RANGE);
  EXPECT_EQ(reason(command(Cmd::OP_SET_LAW, {static_cast<double>(gnc::kLawCount)})),
            Ack::REASON_ARG_OUT_OF_RANGE);
  EXPECT_EQ(reason(command(Cmd::OP_LOAD_TRAJECTORY, {-3.0})), Ack::REASON_ARG_OUT_OF_RANGE);
  EXPECT_EQ(reason(command(Cmd::OP_ABORT_UPLINK, {4e9})), Ack::REASON_ARG_OUT_OF_RANGE);
  EXPECT_EQ(reason(command(Cmd::OP_SET_TARGET, {2e3, 0.0, 0.0})), Ack::REASON_ARG_OUT_OF_RANGE);
  EXPECT_EQ(reason(command(Cmd::OP_SET_TARGET, {1e200, 1e200, 0.0})), Ack::REASON_ARG_OUT_OF_RANGE);
}

TEST(CheckCommand, RejectsNonPositiveSequenceNumbers) {
  Cmd c = command(Cmd::OP_NOOP, {});
  c.seq = 0;
  EXPECT_EQ(reason(c), Ack::REASON_STALE_SEQUENCE);
}

TEST(MakeAck, EchoesTheCommandAndCarriesTheVerdict) {
  const Cmd c = command(Cmd::OP_SET_MODE, {9.0});
  const CommandCheck v = check_command(c);
  const Ack a = make_ack(c, v, 3.5);
  EXPECT_EQ(a.seq, c.seq);
  EXPECT_EQ(a.sender_id, c.sender_id);
  EXPECT_EQ(a.opcode, c.opcode);
  EXPECT_EQ(a.accepted, 0);
  EXPECT_EQ(a.reason, Ack::REASON_ARG_OUT_OF_RANGE);
  EXPECT_EQ(a.t, 3.5);
  EXPECT_EQ(check(a), DecodeStatus::kOk);
  const Ack ok = make_ack(command(Cmd::OP_NOOP, {}), CommandCheck{}, 1.0);
  EXPECT_EQ(ok.accepted, 1);
  EXPECT_EQ(check(ok), DecodeStatus::kOk);
}

}  // namespace
}  // namespace rocksteady::hal::wire
