// Command sequences: the whole file is validated before anything is sent (every error reported with
// its line), conditions compare as written, and — against the real flight and plant in real time in
// a private network namespace — a sequence completes, stops at the first rejection or timeout with
// the step and reason, and an invalid one sends nothing.
#include <gtest/gtest.h>

#include <string>

#include "fsw/interface.hpp"
#include "ground/cli/sequence.hpp"
#include "ground/cli/sequence_store.hpp"
#include "test_util.hpp"

namespace rocksteady::ground::cli {
namespace {

TEST(Sequence, ParsesSendWaitAndSleep) {
  const SequenceParse p = parse_sequence(
      "name: hold\n"
      "steps:\n"
      "  - send: set-mode DETUMBLE\n"
      "  - wait: mode == HOLD, timeout 600 s\n"
      "  - sleep: 2.5 s\n"
      "  - wait: RS_PLANT_TRUTH.omega_norm <= 1e-3, timeout 30\n",
      "seq.yaml");
  ASSERT_TRUE(p.ok) << (p.errors.empty() ? "" : p.errors[0]);
  ASSERT_EQ(p.sequence.steps.size(), 4u);
  EXPECT_EQ(p.sequence.name, "hold");
  const Step& send = p.sequence.steps[0];
  EXPECT_EQ(send.kind, Step::Kind::kSend);
  EXPECT_EQ(send.command, "set-mode");
  EXPECT_EQ(send.args, std::vector<std::string>{"DETUMBLE"});
  EXPECT_EQ(send.line, 3);
  const Step& wait = p.sequence.steps[1];
  EXPECT_EQ(wait.kind, Step::Kind::kWait);
  EXPECT_EQ(wait.condition.channel, "RS_GNC_TLM");
  EXPECT_EQ(wait.condition.point, "mode");
  EXPECT_EQ(wait.condition.op, Condition::Op::kEq);
  EXPECT_EQ(wait.condition.value, static_cast<double>(gnc::Mode::kHold));
  EXPECT_EQ(wait.timeout_s, 600.0);
  EXPECT_EQ(p.sequence.steps[2].sleep_s, 2.5);
  const Step& truth = p.sequence.steps[3];
  EXPECT_EQ(truth.condition.channel, "RS_PLANT_TRUTH");
  EXPECT_EQ(truth.condition.op, Condition::Op::kLe);
  EXPECT_EQ(truth.condition.value, 1e-3);
  EXPECT_EQ(truth.timeout_s, 30.0);
}

TEST(Sequence, ReportsEveryErrorWithItsLine) {
  const SequenceParse p = parse_sequence(
      "steps:\n"
      "  - send: set-mode HOVER\n"               // 2: not a mode
      "  - send: fly-away\n"                     // 3: not a command
      "  - wait: mdoe == HOLD, timeout 5 s\n"    // 4: not a point
      "  - wait: mode == HOLD\n"                 // 5: no timeout
      "  - wait: mode == LANDED, timeout 5 s\n"  // 6: not a mode name
      "  - wait: fuel_kg > 1, timeout -5 s\n"    // 7: negative timeout
      "  - sleep: soon\n"                        // 8: not seconds
      "  - send: noop\n",                        // 9: fine
      "bad.yaml");
  EXPECT_FALSE(p.ok);
  ASSERT_EQ(p.errors.size(), 7u);
  const char* expected[] = {
      "bad.yaml:2: step 1 (send): set-mode: unknown mode 'HOVER'",
      "bad.yaml:3: step 2 (send): ",
      "bad.yaml:4: step 3 (wait): unknown point 'mdoe'",
      "bad.yaml:5: step 4 (wait): expected 'POINT OP VALUE, timeout N s'",
      "bad.yaml:6: step 5 (wait): 'LANDED' is not a number or a value of mode",
      "bad.yaml:7: step 6 (wait): timeout '-5 s' must be a positive",
      "bad.yaml:8: step 7 (sleep): 'soon' is not a positive number"};
  for (std::size_t i = 0; i < 7; ++i) {
    EXPECT_EQ(p.errors[i].rfind(expected[i], 0), 0u) << p.errors[i];
  }
  EXPECT_FALSE(parse_sequence("steps: []\n", "e.yaml").ok);
  EXPECT_FALSE(parse_sequence("stepz:\n  - send: noop\n", "e.yaml").ok);
  EXPECT_FALSE(
      parse_sequence("steps:\n  - send: noop\n    wait: mode == HOLD, timeout 1\n", "e.yaml").ok);
}

TEST(Sequence, ConditionsCompareAsWritten) {
  Condition c;
  c.value = 2.0;
  const std::pair<Condition::Op, std::array<bool, 3>> table[] = {
      {Condition::Op::kEq, {false, true, false}}, {Condition::Op::kNe, {true, false, true}},
      {Condition::Op::kLt, {true, false, false}}, {Condition::Op::kLe, {true, true, false}},
      {Condition::Op::kGt, {false, false, true}}, {Condition::Op::kGe, {false, true, true}}};
  for (const auto& [op, expect] : table) {
    c.op = op;
    EXPECT_EQ(holds(c, 1.0), expect[0]);
    EXPECT_EQ(holds(c, 2.0), expect[1]);
    EXPECT_EQ(holds(c, 3.0), expect[2]);
  }
}

#if defined(ROCKSTEADY_FSW_EXE) && defined(ROCKSTEADY_PLANT_EXE)

TEST(SequenceWithFlight, CompletesAbortsOnRejectionAndTimeoutAndSendsNothingWhenInvalid) {
  test::TempDir dir;
  auto write = [&](const std::string& name, const std::string& text) {
    std::ofstream(dir.file(name)) << text;
    return test::quote(dir.file(name));
  };
  const std::string good = write("good.yaml",
                                 "name: detumble-then-hold\n"
                                 "steps:\n"
                                 "  - wait: frames_accepted >= 5, timeout 10 s\n"
                                 "  - send: set-mode DETUMBLE\n"
                                 "  - wait: mode == DETUMBLE, timeout 10 s\n"
                                 "  - send: set-mode HOLD\n"
                                 "  - wait: mode == HOLD, timeout 10 s\n");
  // TRACK without a loaded trajectory: the flight refuses it.
  const std::string rejected = write("rejected.yaml",
                                     "steps:\n"
                                     "  - send: noop\n"
                                     "  - send: set-mode TRACK\n"
                                     "  - send: noop\n");
  const std::string slow = write("slow.yaml",
                                 "steps:\n"
                                 "  - wait: fuel_kg > 1e6, timeout 1.5 s\n"
                                 "  - send: noop\n");
  const std::string invalid = write("invalid.yaml",
                                    "steps:\n"
                                    "  - send: noop\n"
                                    "  - send: set-mode HOVER\n");
  const std::string url = test::lcm_url(17640);
  const std::string g = test::quote(ROCKSTEADY_GROUND_EXE) + " --lcm-url " + test::quote(url) + " ";
  const std::string state = " --state-dir " + test::quote(dir.file("state"));
  const std::string cfg = " --config-dir " + test::quote(ROCKSTEADY_CONFIG_DIR) + " --case 1 ";
  std::string s;
  s += test::quote(ROCKSTEADY_FSW_EXE) + cfg + "--lab-mode --clock realtime --exit-after 40 --lcm-url " +
       test::quote(url) + " >" + test::quote(dir.file("fsw.txt")) + " 2>&1 &\nfpid=$!\n";
  s += test::quote(ROCKSTEADY_PLANT_EXE) + cfg + "--mode realtime --duration 300 --lcm-url " +
       test::quote(url) + " >" + test::quote(dir.file("plant.txt")) + " 2>&1 &\nppid=$!\n";
  s += "i=0; until " + g + "send noop --timeout 0.25" + state +
       " >/dev/null 2>&1; do\n"
       "  i=$((i+1)); [ $i -ge 40 ] && { echo LINK DOWN; kill $fpid $ppid; exit 3; }\n"
       "done\n";
  s += g + "run " + good + state + "; echo rc=$?\n";
  s += g + "run " + rejected + state + "; echo rc=$?\n";
  s += g + "run " + slow + state + "; echo rc=$?\n";
  s += "echo before=$(cat " + test::quote(dir.file("state") + "/ground-seq-1") + ")\n";
  s += g + "run " + invalid + state + "; echo rc=$?\n";
  s += "echo after=$(cat " + test::quote(dir.file("state") + "/ground-seq-1") + ")\n";
  s += "kill $fpid $ppid; wait $fpid $ppid\n";
  const test::Run r = test::run_in_namespace(s, dir, 120);
  const std::string& o = r.out;
  const std::string said = "--- stdout\n" + o + "--- stderr\n" + r.err + "--- fsw\n" +
                           test::read_file(dir.file("fsw.txt"));
  ASSERT_EQ(o.find("LINK DOWN"), std::string::npos) << said;
  // 1. Completed: every step, in order, then rc 0.
  EXPECT_NE(o.find("step 5/5 (line 7) wait mode == HOLD: met after"), std::string::npos) << said;
  EXPECT_NE(o.find("COMPLETED: 5 steps of 'detumble-then-hold'"), std::string::npos) << said;
  EXPECT_NE(o.find("s\nrc=0\n"), std::string::npos) << said;
  // 2. Stopped at the rejection with the flight's reason; step 3 never ran.
  EXPECT_NE(o.find("step 2/3 (line 3) send set-mode TRACK: SET_MODE TRACK"), std::string::npos)
      << said;
  EXPECT_NE(o.find("ABORTED at step 2 (line 3): set-mode TRACK was rejected: REJECTED: not "
                   "allowed in this mode"),
            std::string::npos)
      << said;
  EXPECT_EQ(o.find("step 3/3"), std::string::npos) << said;
  // 3. A telemetry condition that never holds times out with the last value seen.
  EXPECT_NE(o.find("step 1/2 (line 2) wait fuel_kg > 1e6: TIMEOUT after"), std::string::npos)
      << said;
  EXPECT_NE(o.find("ABORTED at step 1 (line 2): fuel_kg > 1e6 not met within"), std::string::npos)
      << said;
  EXPECT_EQ(o.find("step 2/2"), std::string::npos) << said;
  std::size_t aborted_rc = 0;
  for (std::size_t at = o.find("not run\nrc=1\n"); at != std::string::npos;
       at = o.find("not run\nrc=1\n", at + 1)) {
    ++aborted_rc;
  }
  EXPECT_EQ(aborted_rc, 2u) << said;
  // 4. Invalid: refused with its line, exit 2, and no sequence number was used (nothing sent).
  EXPECT_NE(r.err.find("invalid.yaml:3: step 2 (send): set-mode: unknown mode 'HOVER'"),
            std::string::npos)
      << said;
  EXPECT_NE(o.find("rc=2\n"), std::string::npos) << said;
  const auto num = [&](const std::string& key) {
    const std::size_t at = o.find(key + "=");
    return at == std::string::npos ? std::string("?") : o.substr(at, o.find('\n', at) - at);
  };
  EXPECT_EQ(num("before").substr(7), num("after").substr(6)) << said;
}

#endif

}  // namespace
}  // namespace rocksteady::ground::cli
