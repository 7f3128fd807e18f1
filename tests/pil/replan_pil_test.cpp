// Processor-in-the-loop re-planning: rocksteady-plant, rocksteady-fsw and rocksteady-planner as
// processes on one bus in a private network namespace (pil_tests.cpp main()), in real time, with
// command keys. The planner plans from the flight's telemetry, uplinks signed chunks and commands;
// the flight enters TRACK with the first plan and switches to a re-plan at a tick boundary.
#include <sys/stat.h>

#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "tests/pil/pil_harness.hpp"

namespace rocksteady::pil {
namespace {

constexpr int kTrack = 3;
constexpr int kPhaseTrack = 3;  // gnc::ReferencePhase::kTrack
constexpr int kEvTrajectoryLoaded = 122, kEvTrajectorySwitched = 137, kEvTrajectoryStale = 138;

TEST(PilReplan, ThePlannerProcessReplansAndTheFlightSwitchesTablesDuringTrack) {
  const std::string dir = scratch_dir("replan");
  const std::string url = lcm_url(7871);
  const std::string mission = config_dir() + "/mission.yaml",
                    case_file = config_dir() + "/cases/case1.yaml";
  // The flight settings the campaign's replan strategies set (ground/campaign/runner.hpp
  // ReplanOptions): momentum tracking and the acquisition slew, in the gnc file the flight and the
  // planner both read (the planner's tracking error and prediction follow the momentum tracking
  // from the telemetry's q_hat, q_d and phase).
  const std::string gnc = dir + "/gnc.yaml";
  {
    std::string text = read_file(config_dir() + "/gnc.yaml");
    const auto set_key = [&text](const std::string& key, const std::string& value) {
      const std::size_t at = text.find("  " + key + ": ");
      ASSERT_NE(at, std::string::npos) << key;
      const std::size_t end = text.find('\n', at);
      text.replace(at, end - at, "  " + key + ": " + value);
    };
    set_key("track_momentum_k", "0.001");
    set_key("slew_s", "40000");
    write_file(gnc, text);
  }
  // A key file shared by the flight and the planner (format of rocksteady-ground keygen).
  const std::string key = dir + "/keys";
  write_file(key,
             "1 000102030405060708090a0b0c0d0e0f101112131415161718191a1b1c1d1e1f\n"
             "2 202122232425262728292a2b2c2d2e2f303132333435363738393a3b3c3d3e3f\n");
  ASSERT_EQ(chmod(key.c_str(), 0600), 0);

  TestBus bus(url);
  Process fsw({fsw_exe(), "--lcm-url", url, "--mission", mission, "--gnc", gnc, "--case",
               case_file, "-v", "--clock", "realtime", "--start-mode", "DETUMBLE", "--law", "ntcl",
               "--key-file", key, "--state-file", dir + "/fsw.state"},
              dir + "/fsw.log");
  Process plant({plant_exe(), "--lcm-url", url, "--mission", mission, "--gnc", gnc, "--case",
                 case_file, "--mode", "realtime", "--duration", "110", "--summary"},
                dir + "/plant.log");
  // First plan after 3 s of D+PD, a re-plan 10 s later; each delivered 5 s after its telemetry.
  Process planner({planner_exe(), "--lcm-url", url, "--mission", mission, "--gnc", gnc, "--case",
                   case_file, "--key-file", key, "--state-dir", dir, "--first-plan", "3",
                   "--first-plan-max", "3", "--latency", "5", "--period", "10",
                   "--min-interval", "8", "--error-fraction", "0", "--exit-after-switches", "1",
                   "--duration", "105"},
                  dir + "/planner.log");

  // The flight loads the first plan and enters TRACK.
  ASSERT_TRUE(bus.spin_until([&] { return bus.has_event(kEvTrajectoryLoaded); }, 50.0))
      << read_file(planner.log_path()) << read_file(fsw.log_path());
  ASSERT_TRUE(bus.spin_until([&] { return bus.have_tlm && bus.tlm.mode == kTrack; }, 10.0))
      << read_file(planner.log_path());
  // The re-plan arrives while tracking and is switched in at a tick boundary.
  ASSERT_TRUE(bus.spin_until([&] { return bus.has_event(kEvTrajectorySwitched); }, 50.0))
      << read_file(planner.log_path()) << read_file(fsw.log_path());
  EXPECT_FALSE(bus.has_event(kEvTrajectoryStale));
  bus.spin_for(0.5);
  EXPECT_EQ(bus.tlm.mode, kTrack);
  EXPECT_EQ(bus.tlm.phase, kPhaseTrack);  // the plan running: flown on its momentum here
  EXPECT_TRUE(bus.tlm.trajectory_loaded);

  // The planner saw the switch (an authentic event) and exits on its own.
  int status = -1;
  ASSERT_TRUE(planner.wait(20.0, &status)) << read_file(planner.log_path());
  EXPECT_EQ(status, 0);
  const std::string log = read_file(planner.log_path());
  EXPECT_NE(log.find("signed"), std::string::npos) << log;
  EXPECT_NE(log.find("switched=1"), std::string::npos) << log;
  EXPECT_NE(log.find("delivery_failures=0"), std::string::npos) << log;
  EXPECT_NE(log.find("forged_events=0"), std::string::npos) << log;
  EXPECT_TRUE(fsw.running()) << read_file(fsw.log_path());
}

}  // namespace
}  // namespace rocksteady::pil
