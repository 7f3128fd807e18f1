// The hardened runtime of rocksteady-fsw as a process (issue 16): real-time options reported or
// refused with a clear message, the software watchdog catching a stalled tick while it is stalled.
// Runs inside the PIL test binary's private network namespace (an unprivileged user namespace: the
// kernel refuses SCHED_FIFO there, which is what the refusal tests rely on).
#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <lcm/lcm.h>

#include "fsw/auth/auth.hpp"
#include "fsw/auth/key_file.hpp"
#include "rt/udpm_receiver.hpp"

#include "tests/pil/pil_harness.hpp"

namespace rocksteady::pil {
namespace {

constexpr int kExitRealtimeRefused = 4;  // rt/realtime.hpp
constexpr int kExitWatchdog = 5;         // fsw/bus/flight_node.hpp
constexpr int kEvWatchdog = 203;

std::vector<std::string> fsw_realtime(const std::string& url, std::vector<std::string> extra) {
  std::vector<std::string> a = {fsw_exe(),    "--lcm-url", url,       "--config-dir",
                                config_dir(), "--clock",   "realtime", "--lab-mode"};
  a.insert(a.end(), extra.begin(), extra.end());
  return a;
}

// Runs a short fsw; returns its exit status and leaves its output in *log.
int run_fsw(const std::string& name, const std::vector<std::string>& argv, std::string* log) {
  const std::string dir = scratch_dir(name);
  Process p(argv, dir + "/fsw.log");
  int status = -1;
  EXPECT_TRUE(p.wait(20.0, &status)) << "rocksteady-fsw did not exit";
  *log = read_file(dir + "/fsw.log");
  return status;
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

TEST(PilRuntime, RealTimeOptionsAreReportedAtStart) {
  std::string log;
  EXPECT_EQ(run_fsw("rt_report",
                    fsw_realtime(lcm_url(7861), {"--exit-after-ticks", "2", "--cpu", "0",
                                                 "--prefault-stack", "65536"}),
                    &log),
            0)
      << log;
  EXPECT_TRUE(contains(log, "rocksteady-fsw: rt: --cpu 0: applied")) << log;
  EXPECT_TRUE(contains(log, "rocksteady-fsw: rt: --prefault-stack: applied (65536 bytes")) << log;

  EXPECT_EQ(run_fsw("rt_none", fsw_realtime(lcm_url(7861), {"--exit-after-ticks", "2"}), &log), 0)
      << log;
  EXPECT_TRUE(contains(log, "rocksteady-fsw: rt: none requested")) << log;
}

// SCHED_FIFO needs CAP_SYS_NICE in the initial user namespace or an RLIMIT_RTPRIO: this test's
// process is in a user namespace, and prlimit takes the RLIMIT_RTPRIO to 0 for certain.
TEST(PilRuntime, ARefusedSchedFifoGivesAClearMessageAndANonZeroExit) {
  std::vector<std::string> argv = {"/usr/bin/prlimit", "--rtprio=0", "--"};
  const auto fsw = fsw_realtime(lcm_url(7862), {"--exit-after-ticks", "2", "--sched-fifo", "50"});
  argv.insert(argv.end(), fsw.begin(), fsw.end());
  std::string log;
  EXPECT_EQ(run_fsw("rt_fifo", argv, &log), kExitRealtimeRefused) << log;
  EXPECT_TRUE(contains(log,
                       "rt: --sched-fifo 50: refused: sched_setscheduler(SCHED_FIFO): "
                       "Operation not permitted"))
      << log;
  EXPECT_TRUE(contains(log, "RLIMIT_RTPRIO of at least 50 (now 0/0")) << log;
  EXPECT_TRUE(contains(log, "exiting (status 4)")) << log;
  EXPECT_FALSE(contains(log, "fsw exit:")) << "the loop must not have run: " << log;
}

TEST(PilRuntime, AnImpossibleCpuOrMemoryLockIsRefusedClearly) {
  std::string log;
  EXPECT_EQ(
      run_fsw("rt_cpu", fsw_realtime(lcm_url(7863), {"--exit-after-ticks", "2", "--cpu", "1000"}),
              &log),
      kExitRealtimeRefused)
      << log;
  EXPECT_TRUE(contains(log, "rt: --cpu 1000: refused: sched_setaffinity: Invalid argument")) << log;

  std::vector<std::string> argv = {"/usr/bin/prlimit", "--memlock=0", "--"};
  const auto fsw = fsw_realtime(lcm_url(7863), {"--exit-after-ticks", "2", "--mlockall"});
  argv.insert(argv.end(), fsw.begin(), fsw.end());
  EXPECT_EQ(run_fsw("rt_mlock", argv, &log), kExitRealtimeRefused) << log;
  EXPECT_TRUE(contains(log, "rt: --mlockall: refused: mlockall(MCL_CURRENT|MCL_FUTURE)")) << log;
}

TEST(PilRuntime, BestEffortReportsTheRefusalAndRuns) {
  std::vector<std::string> argv = {"/usr/bin/prlimit", "--rtprio=0", "--"};
  const auto fsw = fsw_realtime(
      lcm_url(7864), {"--exit-after-ticks", "3", "--sched-fifo", "50", "--rt-best-effort", "-v"});
  argv.insert(argv.end(), fsw.begin(), fsw.end());
  std::string log;
  EXPECT_EQ(run_fsw("rt_best_effort", argv, &log), 0) << log;
  EXPECT_TRUE(contains(log, "rt: --sched-fifo 50: refused:")) << log;
  EXPECT_TRUE(contains(log, "continuing without it (--rt-best-effort)")) << log;
  EXPECT_TRUE(contains(log, "fsw exit:")) << log;
}

// The flight software despins case 1 in real time against the real-time plant; base tick 15 is made
// to stall forever (fault injection). Only the watchdog thread can end the process then: the test
// sees its event, an all-off thruster command after commands that fired, and exit status 5.
TEST(PilWatchdog, AStalledTickIsCaughtWhileStalledThrustersOffAndANonZeroExit) {
  const std::string dir = scratch_dir("watchdog");
  const std::string url = lcm_url(7865);
  TestBus bus(url);
  // With command keys (not lab mode): the watchdog thread's event carries the flight's downlink
  // authenticator, so the ground can tell it from a forged one.
  const std::string key_file = dir + "/key";
  std::remove(key_file.c_str());
  ASSERT_EQ(rocksteady::fsw::auth::generate_key_file(key_file, 1), "");
  rocksteady::fsw::auth::KeySet keys;
  ASSERT_EQ(rocksteady::fsw::auth::load_key_file(key_file, keys), "");
  std::vector<std::string> argv = fsw_realtime(url, {"--case", "1", "--start-mode", "DETUMBLE",
                                                     "--watchdog-ms", "300",
                                                     "--test-stall-at-tick", "15", "--key-file",
                                                     key_file, "--state-file", dir + "/state"});
  argv.erase(std::find(argv.begin(), argv.end(), std::string("--lab-mode")));
  Process fsw(argv, dir + "/fsw.log");
  Process plant({plant_exe(), "--lcm-url", url, "--config-dir", config_dir(), "--case", "1",
                 "--mode", "realtime", "--duration", "20"},
                dir + "/plant.log");
  ASSERT_TRUE(bus.spin_until([&] { return !fsw.running(); }, 20.0)) << read_file(dir + "/fsw.log");
  bus.spin_for(0.2);  // what was in flight
  int status = -1;
  ASSERT_TRUE(fsw.wait(1.0, &status));
  const std::string log = read_file(dir + "/fsw.log");
  EXPECT_EQ(status, kExitWatchdog) << log;

  // The stall began and never ended: the watchdog acted during it.
  const std::size_t stall_at =
      log.find("FAULT INJECTION (--test-stall-at-tick): tick 15 stalls forever");
  const std::size_t trip_at = log.find("WATCHDOG: no GNC cycle for");
  ASSERT_NE(stall_at, std::string::npos) << log;
  ASSERT_NE(trip_at, std::string::npos) << log;
  EXPECT_LT(stall_at, trip_at);
  EXPECT_TRUE(contains(log, "(last at base tick 14)")) << log;

  // The event, and the thrusters: commands that fired (DETUMBLE), then the last one all off.
  const rocksteady::event_t* ev = nullptr;
  for (const auto& e : bus.events) {
    if (e.id == kEvWatchdog) ev = &e;
  }
  ASSERT_NE(ev, nullptr) << "no watchdog event";
  EXPECT_EQ(static_cast<int>(ev->severity), int{rocksteady::event_t::SEV_ERROR});
  EXPECT_GE(ev->arg0, 300);  // ms since the last GNC cycle
  EXPECT_EQ(ev->arg1, 14);   // the last GNC cycle's base tick
  ASSERT_EQ(ev->key_id, 1);
  {
    rocksteady::fsw::auth::EventFields f;
    f.t = ev->t;
    f.seq = ev->seq;
    f.severity = ev->severity;
    f.id = ev->id;
    f.arg0 = ev->arg0;
    f.arg1 = ev->arg1;
    f.key_id = ev->key_id;
    f.text = ev->text.c_str();
    f.text_len = ev->text.size();
    rocksteady::fsw::auth::MacBytes expect{};
    rocksteady::fsw::auth::mac_event(f, keys.find(1)->key, expect);
    rocksteady::fsw::auth::MacBytes got{};
    std::memcpy(got.data(), ev->mac, got.size());
    EXPECT_TRUE(rocksteady::fsw::auth::mac_equal(expect, got)) << "watchdog event not authentic";
  }
  EXPECT_GT(bus.thruster_firing_count, 0u) << "the despin never fired: nothing to turn off";
  ASSERT_TRUE(bus.have_thruster);
  EXPECT_FALSE(bus.thruster.enabled);
  for (int i = 0; i < 16; ++i) {
    EXPECT_FALSE(bus.thruster.thruster_on[i]) << "thruster " << i;
    EXPECT_EQ(bus.thruster.thruster_force[i], 0.0) << "thruster " << i;
  }
  for (int i = 0; i < 8; ++i) EXPECT_EQ(bus.thruster.channel_force[i], 0.0) << "channel " << i;
}

// The direct receiver against LCM's own publisher: a small message arrives with its channel and
// payload byte for byte; a message LCM fragments (LCM 1.3 sends up to ~64 KB in one datagram; above
// that, "LC03" fragments) and a packet that is not LCM are counted and skipped, never delivered.
TEST(UdpmReceiver, ReadsLcmSmallMessagesAndSkipsFragmentsAndForeignPackets) {
  const std::string url = lcm_url(7866);
  rt::UdpmReceiver rx;
  ASSERT_TRUE(rx.open(url)) << rx.error();
  lcm_t* lcm = lcm_create(url.c_str());
  ASSERT_NE(lcm, nullptr);
  const auto wait_readable = [&] {
    pollfd p{rx.fd(), POLLIN, 0};
    return poll(&p, 1, 2000) == 1;
  };
  const char* channel = nullptr;
  const void* data = nullptr;
  int size = 0;

  std::vector<unsigned char> small(300);
  for (std::size_t i = 0; i < small.size(); ++i) small[i] = static_cast<unsigned char>(i * 7 + 1);
  ASSERT_EQ(lcm_publish(lcm, "RS_SENSORS", small.data(), static_cast<unsigned>(small.size())), 0);
  ASSERT_TRUE(wait_readable());
  ASSERT_EQ(rx.receive(&channel, &data, &size), 1);
  EXPECT_STREQ(channel, "RS_SENSORS");
  ASSERT_EQ(size, static_cast<int>(small.size()));
  EXPECT_EQ(std::memcmp(data, small.data(), small.size()), 0);
  EXPECT_EQ(rx.receive(&channel, &data, &size), 0);  // nothing else waiting

  std::vector<unsigned char> big(100000, 0x5a);  // fragmented by LCM: several LC03 packets
  ASSERT_EQ(lcm_publish(lcm, "RS_SENSORS", big.data(), static_cast<unsigned>(big.size())), 0);
  const int fd = socket(AF_INET, SOCK_DGRAM, 0);
  sockaddr_in to{};
  to.sin_family = AF_INET;
  to.sin_port = htons(7866);
  inet_aton("239.255.76.67", &to.sin_addr);
  const char junk[] = "not an LCM packet";
  ASSERT_GT(sendto(fd, junk, sizeof junk, 0, reinterpret_cast<const sockaddr*>(&to), sizeof to), 0);
  close(fd);
  ASSERT_EQ(lcm_publish(lcm, "RS_THRUSTER_CMD", small.data(), 10), 0);  // a marker after them
  ASSERT_TRUE(wait_readable());
  int got = 0;
  for (int i = 0; i < 100 && got == 0; ++i) {
    got = rx.receive(&channel, &data, &size);
    if (got == 0) wait_readable();
  }
  ASSERT_EQ(got, 1);
  EXPECT_STREQ(channel, "RS_THRUSTER_CMD");  // the fragments and the junk were skipped
  EXPECT_EQ(size, 10);
  EXPECT_EQ(rx.received(), 2u);
  EXPECT_GE(rx.rejected(), 2u + 1u);  // at least two fragments, and the junk
  lcm_destroy(lcm);
}

}  // namespace
}  // namespace rocksteady::pil
