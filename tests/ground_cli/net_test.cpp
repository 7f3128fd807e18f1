// rocksteady-ground over a real LCM bus, inside a private network namespace (unshare -rn, loopback
// with the LCM multicast group routed; ENVIRONMENT.md) so nothing leaves this test. A small
// responder (test_responder.cpp) plays the flight side with the flight's own command checks.
// Every run is bounded: `timeout`, the CLI's --timeout and the responder's --seconds.
#include <gtest/gtest.h>

#include <string>

#include "ground/cli/sequence_store.hpp"
#include "ground/cli/trajectory_input.hpp"
#include "ground/planner/planner.hpp"
#include "ground/planner/trajectory_file.hpp"
#include "test_util.hpp"

namespace rocksteady::ground::cli {
namespace {

const std::string kGround = ROCKSTEADY_GROUND_EXE;
const std::string kResponder = ROCKSTEADY_RESPONDER_EXE;

std::string url(int port) {
  return test::lcm_url(port);
}

// `script` runs in a fresh network namespace; `responder_args` (if any) start the responder first,
// the script waits until it is subscribed, and `stop_responder` ends it after the script. The
// script's status is the result; the responder's is printed to stderr as "responder=N".
test::Run in_namespace(const test::TempDir& dir, const std::string& responder_args,
                       const std::string& script, bool stop_responder = false) {
  std::string s;
  if (!responder_args.empty()) {
    const std::string ready = dir.file("responder.ready");
    s += test::quote(kResponder) + " --ready " + test::quote(ready) + " " + responder_args + " &\n";
    s += "rpid=$!\n";
    s += "i=0; while [ ! -e " + test::quote(ready) +
         " ] && [ $i -lt 400 ]; do sleep 0.025; i=$((i+1)); done\n";
  }
  s += "( " + script + " )\nrc=$?\n";
  if (stop_responder) s += "kill $rpid\n";
  if (!responder_args.empty()) s += "wait $rpid; echo responder=$? >&2\n";
  s += "exit $rc\n";
  return test::run_in_namespace(s, dir);
}

std::string ground(int port, const std::string& args) {
  return test::quote(kGround) + " --lcm-url " + test::quote(url(port)) + " " + args;
}

TEST(GroundCliNet, NamespaceIsAvailable) {
  test::TempDir dir;
  const test::Run r = in_namespace(dir, "", "true");
  ASSERT_EQ(r.exit_code, 0) << "unshare -rn with a multicast loopback is needed by these tests: "
                            << r.err;
}

TEST(GroundCliNet, SendNoopPrintsAcceptedAndExitsZero) {
  test::TempDir dir;
  const int port = 17601;
  const std::string state = dir.file("state");
  const test::Run r =
      in_namespace(dir, "--url " + test::quote(url(port)) + " --commands 1 --seconds 20",
                   ground(port, "send noop --timeout 10 --state-dir " + test::quote(state)));
  EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_EQ(r.out, "ACCEPTED\n") << r.err;
  EXPECT_NE(r.err.find("responder=0"), std::string::npos) << r.err;
  EXPECT_EQ(SequenceStore(sequence_file(state, 1)).last(), 1);
}

// No flight software, only a forger that answers every command with an unauthenticated "accepted"
// acknowledgement (the responder does not sign): a ground with the key reports it as forged and
// exits 1; never ACCEPTED.
TEST(GroundCliNet, ForgedAcknowledgementIsReportedAsForged) {
  test::TempDir dir;
  const int port = 17611;
  const std::string key = dir.file("key");
  const std::string state = test::quote(dir.file("state"));
  const test::Run r = in_namespace(
      dir, "--url " + test::quote(url(port)) + " --commands 2 --seconds 20",
      test::quote(kGround) + " keygen " + test::quote(key) + " >/dev/null && " +
          ground(port, "--key-file " + test::quote(key) + " send set-mode SAFE --timeout 2 "
                       "--state-dir " + state) +
          "; echo rc=$?; " +
          ground(port, "--key-file " + test::quote(key) + " send noop --timeout 2 --state-dir " +
                           state) +
          "; echo rc=$?");
  EXPECT_EQ(r.out.find("ACCEPTED"), std::string::npos) << r.out << r.err;
  EXPECT_NE(r.out.find("FORGED: 1 acknowledgement(s) of seq "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("rc=1\n"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("rc=0"), std::string::npos) << r.out;
}

TEST(GroundCliNet, SequenceNumbersKeepIncreasingAndAStaleOneIsRejected) {
  test::TempDir dir;
  const int port = 17602;
  const std::string state = test::quote(dir.file("state"));
  const std::string send = "send noop --timeout 10 --state-dir " + state;
  // Two sends take numbers 1 and 2 from the state file; --seq 2 again is stale for the flight.
  const test::Run r = in_namespace(
      dir, "--url " + test::quote(url(port)) + " --commands 3 --seconds 20",
      ground(port, send) + " && " + ground(port, send) + " && " + ground(port, send + " --seq 2"));
  EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
  EXPECT_EQ(r.out,
            "ACCEPTED\nACCEPTED\nREJECTED: stale or repeated sequence number: stale sequence\n")
      << r.err;
  EXPECT_NE(r.err.find("hint:"), std::string::npos) << r.err;
}

TEST(GroundCliNet, CommandNotAllowedInTheFlightModeIsRejectedWithExitOne) {
  test::TempDir dir;
  const int port = 17603;
  const test::Run r = in_namespace(
      dir, "--url " + test::quote(url(port)) + " --mode TRACK --commands 1 --seconds 20",
      ground(port, "send set-target 0 -0.1 0.2 --timeout 10 --seq 5"));
  EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
  EXPECT_EQ(r.out.rfind("REJECTED: not allowed in this mode", 0), 0u) << r.out;
}

// One exit convention for every tool: a command that is never acknowledged is a failed run (1),
// not a usage error (2).
TEST(GroundCliNet, NoAcknowledgementIsATimeoutWithExitOne) {
  test::TempDir dir;
  const test::Run r = in_namespace(dir, "", ground(17604, "send noop --timeout 0.3 --seq 1"));
  EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
  EXPECT_EQ(r.out.rfind("TIMEOUT: no acknowledgement of seq 1", 0), 0u) << r.out;
}

TEST(GroundCliNet, BadOperatorInputExitsTwoWithoutSending) {
  test::TempDir dir;
  const test::Run r = in_namespace(dir, "", ground(17605, "send set-mode CRUISE --seq 1"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_TRUE(r.out.empty()) << r.out;
  EXPECT_NE(r.err.find("unknown mode 'CRUISE'"), std::string::npos) << r.err;
}

TEST(GroundCliNet, MonitorPrintsOneLinePerTelemetryMessage) {
  test::TempDir dir;
  const int port = 17606;
  const test::Run r =
      in_namespace(dir, "--url " + test::quote(url(port)) + " --telemetry --commands 0 --seconds 6",
                   ground(port, "monitor --count 3 --seconds 5 --plain"), true);
  EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
  int lines = 0;
  for (std::size_t at = r.out.find("TLM t="); at != std::string::npos;
       at = r.out.find("TLM t=", at + 1)) {
    ++lines;
  }
  EXPECT_EQ(lines, 3) << r.out;
  EXPECT_NE(r.out.find("mode=IDLE law=so3"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("|w|=5.000000e-03"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("fuel=12.5000"), std::string::npos) << r.out;
  EXPECT_NE(r.err.find("monitor: 3 telemetry"), std::string::npos) << r.err;
}

TEST(GroundCliNet, MonitorFlagsSilenceAsStale) {
  test::TempDir dir;
  // Nobody publishes: the monitor says so instead of staying blank, once, in plain mode.
  const test::Run r =
      in_namespace(dir, "", ground(17608, "monitor --seconds 1.5 --plain --stale-after 0.5"));
  EXPECT_NE(r.out.find("STALE: no telemetry on RS_GNC_TLM for"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("(none received yet)"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("STALE", r.out.find("STALE") + 1), std::string::npos) << r.out;
}

// A real plan (case 1, coarse grid) uplinked in chunks: the responder reassembles it with the
// flight's TrajectoryUplink, announces uplink_complete, and accepts LOAD_TRAJECTORY only when the
// reassembled table validates (CRC-32 included).
TEST(GroundCliNet, UploadTrajectoryChunksCompleteAndLoad) {
  test::TempDir dir;
  planner::PlanProblem problem;
  problem.case_name = "cli-upload";
  problem.model = planner::study_case_model(200.0, 0.0, 0.0);
  problem.settings.nodes = 51;
  problem.settings.verify_refinement = false;
  const planner::PlanResult plan = planner::plan(problem);
  ASSERT_TRUE(plan.ok) << plan.error;
  const std::string file = dir.file("plan.yaml");
  planner::write_trajectory_file(file, problem, plan);

  const int port = 17607;
  const test::Run r = in_namespace(
      dir, "--url " + test::quote(url(port)) + " --commands 1 --seconds 30",
      ground(port, "send upload-trajectory " + test::quote(file) +
                       " --upload-id 77 --seq 3 --chunk-interval 0.005 --wait 10 --timeout 10"));
  EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_EQ(r.out, "ACCEPTED\n") << r.err;
  EXPECT_NE(r.err.find("upload 77 complete on board (4 chunks)"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("LOAD_TRAJECTORY 77 seq 3"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("responder=0"), std::string::npos) << r.err;
}

// --case N is checked against study case N's model, whose configs are found next to the program
// even when run from a folder without them; a case that does not exist is named as typed.
TEST(GroundCliConfigs, UploadCaseNumberFromAnyDirectory) {
  test::TempDir dir;
  planner::PlanProblem problem;
  problem.case_name = "cli-case";
  problem.model = planner::study_case_model(200.0, 0.0, 0.0);
  problem.settings.nodes = 51;
  problem.settings.verify_refinement = false;
  const planner::PlanResult plan = planner::plan(problem);
  ASSERT_TRUE(plan.ok) << plan.error;
  const std::string file = dir.file("plan.yaml");
  planner::write_trajectory_file(file, problem, plan);
  const std::string g = "cd " + test::quote(dir.str()) + " && env -u ROCKSTEADY_CONFIG_DIR " +
                        test::quote(ROCKSTEADY_GROUND_EXE) + " send upload-trajectory " +
                        test::quote(file) + " --dry-run --seq 1 ";
  const test::Run missing = test::run(g + "--case 9", dir);
  EXPECT_EQ(missing.exit_code, 2) << missing.err;
  EXPECT_NE(missing.err.find("--case 9: no case file"), std::string::npos) << missing.err;
  // Case 1's configured model: the file (planned for the nominal study model) is checked against
  // it, so the outcome is the loader's verdict, not "cannot read configs/mission.yaml".
  const test::Run one = test::run(g + "--case 1", dir);
  EXPECT_EQ(one.err.find("cannot read file"), std::string::npos) << one.err;
  EXPECT_EQ(one.err.find("no configuration folder"), std::string::npos) << one.err;
  const test::Run alone = test::run(g + "--mission x.yaml", dir);
  EXPECT_EQ(alone.exit_code, 2);
  EXPECT_NE(alone.err.find("--mission needs --case"), std::string::npos) << alone.err;
}

}  // namespace
}  // namespace rocksteady::ground::cli
