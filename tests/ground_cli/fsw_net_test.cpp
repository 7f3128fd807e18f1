// rocksteady-ground against the real flight process, rocksteady-fsw (case 1, real-time clock, no
// plant), over LCM in a private network namespace: commands are acknowledged by the flight's bus
// layer, telemetry reaches the monitor, and a planned trajectory is uplinked, completed and loaded.
// Bounded: the flight process exits by itself (--exit-after), every CLI call has a timeout.
#include <gtest/gtest.h>

#include <string>

#include "ground/planner/planner.hpp"
#include "ground/planner/trajectory_file.hpp"
#include "test_util.hpp"

#ifdef ROCKSTEADY_FSW_EXE

namespace rocksteady::ground::cli {
namespace {

TEST(GroundCliWithFlight, CommandsMonitorAndUploadAgainstRocksteadyFsw) {
  test::TempDir dir;
  planner::PlanProblem problem;
  problem.case_name = "cli-fsw";
  problem.model = planner::study_case_model(200.0, 0.0, 0.0);
  problem.settings.nodes = 51;
  problem.settings.verify_refinement = false;
  const planner::PlanResult plan = planner::plan(problem);
  ASSERT_TRUE(plan.ok) << plan.error;
  const std::string file = dir.file("plan.yaml");
  planner::write_trajectory_file(file, problem, plan);

  const std::string url = test::lcm_url(17620);
  const std::string key = dir.file("key");
  const std::string g = test::quote(ROCKSTEADY_GROUND_EXE) + " --lcm-url " + test::quote(url) +
                        " --key-file " + test::quote(key) + " ";
  const std::string state = " --state-dir " + test::quote(dir.file("state"));
  std::string s;
  // A test key made by the test (authenticated commanding end to end).
  s += test::quote(ROCKSTEADY_GROUND_EXE) + " keygen " + test::quote(key) + " >/dev/null\n";
  s += test::quote(ROCKSTEADY_FSW_EXE) + " --config-dir " + test::quote(ROCKSTEADY_CONFIG_DIR) +
       " --case 1 --clock realtime --exit-after 20 --key-file " + test::quote(key) +
       " --lcm-url " + test::quote(url) + " >" + test::quote(dir.file("fsw.txt")) + " 2>&1 &\n";
  s += "fpid=$!\n";
  // Link check: noops until the flight answers (it may not be subscribed yet).
  s += "i=0; until " + g + "send noop --timeout 0.25" + state +
       " >/dev/null 2>&1; do\n"
       "  i=$((i+1)); [ $i -ge 40 ] && { echo LINK DOWN; kill $fpid; exit 3; }\n"
       "done\n";
  s += "echo LINK UP\n";
  // Booted in IDLE without sensors: no estimate yet, so HOLD is refused by the flight.
  s += g + "send set-mode HOLD --timeout 5" + state + "; echo rc=$?\n";
  s += g + "send set-gain ntcl.K 2e4 2e4 3e4 --timeout 5" + state + "; echo rc=$?\n";
  s += g + "send activate-gains --timeout 5" + state + "; echo rc=$?\n";
  s += g + "send upload-trajectory " + test::quote(file) +
       " --chunk-interval 0.01 --wait 5 --timeout 5" + state + "; echo rc=$?\n";
  s += g + "monitor --count 2 --seconds 5 --plain; echo rc=$?\n";
  s += g + "params get --timeout 5" + state + "; echo rc=$?\n";
  // An uplink in progress (complete, not loaded) is ended only by an authenticated abort: another
  // upload is refused with the id to abort; after the abort it goes through.
  const std::string up = g + "send upload-trajectory " + test::quote(file) +
                         " --no-load --chunk-interval 0.01 --wait 5 --passes 1 --timeout 5" +
                         state;
  s += up + " --upload-id 41; echo rc=$?\n";
  s += up + " --upload-id 42; echo rc=$?\n";
  s += g + "send abort-uplink 41 --timeout 5" + state + "; echo rc=$?\n";
  s += up + " --upload-id 42; echo rc=$?\n";
  s += "kill $fpid; wait $fpid\n";
  const test::Run r = test::run_in_namespace(s, dir, 90);
  const std::string& o = r.out;
  // Everything the three parties said, for a failure message.
  const std::string said = "--- stdout\n" + o + "--- stderr\n" + r.err + "--- rocksteady-fsw\n" +
                           test::read_file(dir.file("fsw.txt"));
  ASSERT_NE(o.find("LINK UP"), std::string::npos) << said;
  EXPECT_NE(o.find("REJECTED: not allowed in this mode (no valid state estimate)\nrc=1\n"),
            std::string::npos)
      << said;
  // set-gain, activate-gains, then the upload's LOAD_TRAJECTORY: accepted, exit 0.
  EXPECT_NE(o.find("ACCEPTED\nrc=0\nACCEPTED\nrc=0\nACCEPTED\nrc=0\n"), std::string::npos) << said;
  EXPECT_NE(r.err.find("complete on board (4 chunks)"), std::string::npos) << said;
  std::size_t tlm = 0;
  for (std::size_t at = o.find("TLM t="); at != std::string::npos; at = o.find("TLM t=", at + 1)) {
    ++tlm;
  }
  EXPECT_EQ(tlm, 2u) << said;
  // The flight's counters as the monitor shows them: only the HOLD request was rejected, and the
  // flight decoded everything the console sent.
  EXPECT_NE(o.find("cmd_rej=1 "), std::string::npos) << said;
  EXPECT_NE(o.find("rx_malformed=0 rx_bad_kind=0 rx_out_of_range=0"), std::string::npos) << said;
  // The read-back shows the activated gains (PARAM_DUMP -> RS_PARAMS), with names and units.
  EXPECT_NE(o.find(" 0  ntcl.K                         N m s            [xx yy zz xy xz yz] 20000 "
                   "20000 30000 0 0 0\n"),
            std::string::npos)
      << said;
  EXPECT_NE(o.find("23  mode.sensor_timeout            s                1\n"), std::string::npos)
      << said;
  EXPECT_EQ(o.find("FORGED"), std::string::npos) << said;  // the read-back is authentic
  const std::size_t first = o.find("UPLOADED: upload id 41 ");
  const std::size_t refused = o.find("REFUSED: the flight refuses upload 42 while another is in progress");
  const std::size_t aborted = o.find("ACCEPTED\nrc=0\n", refused);
  const std::size_t second = o.find("UPLOADED: upload id 42 ");
  ASSERT_NE(first, std::string::npos) << said;
  ASSERT_NE(refused, std::string::npos) << said;
  EXPECT_NE(o.find("ABORT_UPLINK 41", refused), std::string::npos) << said;
  EXPECT_EQ(o.substr(o.find('\n', refused), 6), "\nrc=1\n") << said;
  ASSERT_NE(aborted, std::string::npos) << said;
  ASSERT_NE(second, std::string::npos) << said;
  EXPECT_LT(first, refused);
  EXPECT_LT(refused, aborted);
  EXPECT_LT(aborted, second);
}

// The replay state survives a restart of the flight process: a command accepted before the restart
// (the very same counter and authenticator) is refused after it; a new one is accepted; a wrong
// key file is refused at the ground's and the flight's start.
TEST(GroundCliWithFlight, CapturedCommandIsRefusedAfterAFlightRestart) {
  test::TempDir dir;
  const std::string url = test::lcm_url(17621);
  const std::string key = dir.file("key");
  const std::string g = test::quote(ROCKSTEADY_GROUND_EXE) + " --lcm-url " + test::quote(url) +
                        " --key-file " + test::quote(key) + " ";
  const std::string state = " --state-dir " + test::quote(dir.file("state"));
  const std::string fsw = test::quote(ROCKSTEADY_FSW_EXE) + " --config-dir " +
                          test::quote(ROCKSTEADY_CONFIG_DIR) +
                          " --case 1 --clock realtime --exit-after 20 --key-file " +
                          test::quote(key) + " --lcm-url " + test::quote(url);
  const std::string link = "i=0; until " + g + "send noop --timeout 0.25" + state +
                           " >/dev/null 2>&1; do\n"
                           "  i=$((i+1)); [ $i -ge 40 ] && { echo LINK DOWN; exit 3; }\n"
                           "done\n";
  const std::string captured = "send noop --seq 9000000000000000 --timeout 5" + state;
  std::string s;
  s += test::quote(ROCKSTEADY_GROUND_EXE) + " keygen " + test::quote(key) + " >/dev/null\n";
  s += "chmod 644 " + test::quote(key) + "\n";
  s += fsw + " >" + test::quote(dir.file("fsw0.txt")) + " 2>&1; echo fsw_open_key=$?\n";
  s += g + "send noop --timeout 1" + state + "; echo ground_open_key=$?\n";
  s += "chmod 600 " + test::quote(key) + "\n";
  s += fsw + " >" + test::quote(dir.file("fsw1.txt")) + " 2>&1 &\nfpid=$!\n" + link;
  s += g + captured + "; echo rc=$?\n";
  s += "kill -INT $fpid; wait $fpid\n";
  s += fsw + " >" + test::quote(dir.file("fsw2.txt")) + " 2>&1 &\nfpid=$!\n" + link;
  s += "echo RESTARTED\n";
  s += g + captured + "; echo rc=$?\n";
  s += g + "send noop --timeout 5" + state + "; echo rc=$?\n";
  s += "kill -INT $fpid; wait $fpid\n";
  const test::Run r = test::run_in_namespace(s, dir, 90);
  const std::string said = "--- stdout\n" + r.out + "--- stderr\n" + r.err + "--- fsw\n" +
                           test::read_file(dir.file("fsw0.txt")) +
                           test::read_file(dir.file("fsw1.txt")) +
                           test::read_file(dir.file("fsw2.txt"));
  EXPECT_NE(r.out.find("fsw_open_key=2"), std::string::npos) << said;
  EXPECT_NE(r.out.find("ground_open_key=2"), std::string::npos) << said;
  EXPECT_NE(test::read_file(dir.file("fsw0.txt")).find("too open"), std::string::npos) << said;
  const std::size_t restart = r.out.find("RESTARTED");
  ASSERT_NE(restart, std::string::npos) << said;
  EXPECT_NE(r.out.find("ACCEPTED\nrc=0\n"), std::string::npos) << said;
  EXPECT_EQ(r.out.substr(restart),
            "RESTARTED\nREJECTED: stale or repeated sequence number: replayed or too old counter\n"
            "rc=1\nACCEPTED\nrc=0\n")
      << said;
  EXPECT_NE(test::read_file(dir.file("fsw2.txt")).find("replay state restored"), std::string::npos)
      << said;
}

}  // namespace
}  // namespace rocksteady::ground::cli

#endif  // ROCKSTEADY_FSW_EXE
