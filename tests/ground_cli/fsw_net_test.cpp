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
  const std::string g = test::quote(ROCKSTEADY_GROUND_EXE) + " --lcm-url " + test::quote(url) + " ";
  const std::string state = " --state-dir " + test::quote(dir.file("state"));
  std::string s;
  s += test::quote(ROCKSTEADY_FSW_EXE) + " --config-dir " + test::quote(ROCKSTEADY_CONFIG_DIR) +
       " --case 1 --clock realtime --exit-after 20 --lcm-url " + test::quote(url) + " >" +
       test::quote(dir.file("fsw.txt")) + " 2>&1 &\n";
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
}

}  // namespace
}  // namespace rocksteady::ground::cli

#endif  // ROCKSTEADY_FSW_EXE
