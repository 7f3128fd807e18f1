// Processor-in-the-loop tests: rocksteady-plant and rocksteady-fsw as real processes over LCM, in a
// private network namespace (see main() below). Each test has its own LCM port and its own
// namespace; every process is killed when the test ends.
#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "ground/campaign/flight_side.hpp"
#include "ground/campaign/fsw_flight_side.hpp"
#include "ground/campaign/runner.hpp"
#include "ground/campaign/strategy.hpp"
#include "ground/config/config.hpp"
#include "wire/codec.hpp"
#include "lcmtypes/channels.hpp"
#include "rocksteady/ground_cmd_t.hpp"
#include "rocksteady/plant_fault_cmd_t.hpp"
#include "rocksteady/sensor_frame_t.hpp"
#include "rocksteady/thruster_cmd_t.hpp"
#include "rocksteady/trajectory_chunk_t.hpp"
#include "tests/pil/pil_harness.hpp"

namespace rocksteady::pil {
namespace {

// Modes, opcodes, reasons and event ids as the bus carries them (lcmtypes, fsw/README.md).
constexpr int kIdle = 0, kDetumble = 1, kHold = 2, kTrack = 3, kSafe = 4;
constexpr int kOpSetMode = 1, kOpParamLoad = 7, kOpParamActivate = 8;
constexpr int kReasonNotAllowedInMode = 7, kReasonUnknownOpcode = 1;
constexpr int kEvCommandRejected = 101, kEvModeChanged = 102, kEvSensorTimeout = 104,
              kEvTableActivated = 112, kEvStreamRestart = 200, kEvFrameWatchdog = 201;
constexpr int kNoTrajectory = 3;  // gnc::TransitionCheck::kNoTrajectory

// Case 1 with a shorter despin: ten times the thrust (2000 N) and stiffer NTCL gains
// (K = 1e6, Lambda = 3e-2), so despin and hold converge within 600 s of simulated time.
struct FastCase {
  std::string mission, gnc, case_file;
  double duration_s{600.0};
};

FastCase make_fast_case(const std::string& dir) {
  FastCase f;
  f.mission = config_dir() + "/mission.yaml";
  f.gnc = dir + "/gnc_fast.yaml";
  f.case_file = dir + "/case1_fast.yaml";
  copy_with_lines(config_dir() + "/gnc.yaml", f.gnc,
                  {{"  ntcl:", "  ntcl:        {K: 1.0e6, Lambda: 3.0e-2}"}});
  copy_with_lines(config_dir() + "/cases/case1.yaml", f.case_file,
                  {{"u_max_n:", "u_max_n: 2000"}, {"duration_s:", "duration_s: 600"}});
  return f;
}

std::vector<std::string> plant_args(const std::string& url, const std::string& mission,
                                    const std::string& gnc, const std::string& case_file,
                                    std::vector<std::string> extra) {
  std::vector<std::string> a = {plant_exe(), "--lcm-url", url,      "--mission", mission,
                                "--gnc",     gnc,         "--case", case_file,   "--summary",
                                "--retries", "1000",      "--timeout-ms", "100"};
  a.insert(a.end(), extra.begin(), extra.end());
  return a;
}

std::vector<std::string> fsw_args(const std::string& url, const std::string& mission,
                                  const std::string& gnc, const std::string& case_file,
                                  std::vector<std::string> extra) {
  // Lab mode: these tests command through the harness's unsigned messages (authentication over the
  // bus is tested in auth_pil_test below and in tests/ground_cli/fsw_net_test.cpp).
  std::vector<std::string> a = {fsw_exe(), "--lcm-url", url,       "--mission", mission, "--gnc",
                                gnc,       "--case",    case_file, "-v",        "--lab-mode"};
  a.insert(a.end(), extra.begin(), extra.end());
  return a;
}

std::string exact(const std::optional<double>& v) {
  if (!v) return "NC";
  char b[64];
  std::snprintf(b, sizeof b, "%.17g", *v);
  return b;
}
std::string exact(double v) { return exact(std::optional<double>(v)); }

// A lockstep PIL run of the fast case; returns the plant's summary.
std::map<std::string, std::string> run_fast_pil(const std::string& name, int port,
                                                const std::vector<std::string>& fsw_extra,
                                                FastCase* out_case,
                                                const std::vector<std::string>& plant_extra = {}) {
  const std::string dir = scratch_dir(name);
  const FastCase fc = make_fast_case(dir);
  if (out_case != nullptr) *out_case = fc;
  const std::string url = lcm_url(port);
  std::vector<std::string> fx = {"--law", "ntcl", "--tlm-every", "10"};
  fx.insert(fx.end(), fsw_extra.begin(), fsw_extra.end());
  Process fsw(fsw_args(url, fc.mission, fc.gnc, fc.case_file, fx), dir + "/fsw.log");
  std::vector<std::string> px = {"--truth-every", "10"};
  px.insert(px.end(), plant_extra.begin(), plant_extra.end());
  Process plant(plant_args(url, fc.mission, fc.gnc, fc.case_file, px), dir + "/plant.log");
  int status = -1;
  EXPECT_TRUE(plant.wait(120.0, &status)) << "plant did not finish";
  EXPECT_EQ(status, 0) << read_file(plant.log_path());
  EXPECT_TRUE(fsw.running()) << read_file(fsw.log_path());
  return plant_summary(read_file(plant.log_path()));
}

campaign::RunResult run_in_process(const FastCase& fc, campaign::FlightSide& side) {
  const config::RunSetup setup = config::load_run(fc.mission, fc.gnc, fc.case_file);
  const campaign::Strategy strategy = *campaign::parse_strategy("ntcl+dpd_ref");
  campaign::RunOptions opt;
  opt.duration_s = fc.duration_s;
  opt.log_interval_s = 0.0;
  return campaign::run_closed_loop(setup, strategy, side, nullptr, opt);
}

void expect_same_figures(const std::map<std::string, std::string>& pil,
                         const campaign::RunResult& r) {
  EXPECT_EQ(pil.at("t_omega"), exact(r.t_omega_conv_s));
  EXPECT_EQ(pil.at("fuel_omega"), exact(r.fuel_at_t_omega_kg));
  EXPECT_EQ(pil.at("t_q"), exact(r.t_q_conv_s));
  EXPECT_EQ(pil.at("fuel_q"), exact(r.fuel_at_t_q_kg));
  EXPECT_EQ(pil.at("total_fuel"), exact(r.total_fuel_kg));
  EXPECT_EQ(pil.at("final_rate"), exact(r.final_rate_rad_s));
  EXPECT_EQ(pil.at("final_q_error"), exact(r.final_q_error));
  EXPECT_EQ(pil.at("flight_mode"), r.final_mode);
}

// ---------------------------------------------------------------------------------------------

TEST(PilLockstep, DespinAndHoldOfTheFastCase1Converge) {
  FastCase fc;
  const auto s = run_fast_pil("despin_hold", 7811, {"--start-mode", "DETUMBLE"}, &fc);
  ASSERT_FALSE(s.empty()) << "no plant summary";
  const config::RunSetup setup = config::load_run(fc.mission, fc.gnc, fc.case_file);
  // SPEC §7 on the plant's true state: both criteria met for good, and the end state within them.
  ASSERT_NE(s.at("t_omega"), "NC");
  ASSERT_NE(s.at("t_q"), "NC");
  EXPECT_LT(std::stod(s.at("t_omega")), fc.duration_s);
  EXPECT_LE(std::stod(s.at("final_rate")), setup.omega_tol_rad_s);
  EXPECT_LE(std::stod(s.at("final_q_error")), setup.q_tol);
  EXPECT_GT(std::stod(s.at("total_fuel")), 0.0);
  EXPECT_EQ(s.at("flight_mode"), "HOLD");  // DETUMBLE -> HOLD happened on board (auto_hold)
  EXPECT_EQ(s.at("holds"), "0");           // every period was answered
  EXPECT_EQ(s.at("rx_rejected"), "0");
  EXPECT_EQ(s.at("periods"), "6000");
}

// The same configuration and seed in one process (campaign's FswFlightSide: FlightApp through the
// in-process HAL, DETUMBLE commanded after the first tick) and over LCM (--start-mode DETUMBLE):
// doubles cross the bus exactly and lockstep keeps the order, so the runs are identical.
TEST(PilLockstep, MatchesTheInProcessFlightApplicationRunBitForBit) {
  FastCase fc;
  const auto s = run_fast_pil("vs_app", 7812, {"--start-mode", "DETUMBLE"}, &fc);
  ASSERT_FALSE(s.empty()) << "no plant summary";
  campaign::FswFlightSide side;
  const campaign::RunResult r = run_in_process(fc, side);
  ASSERT_EQ(r.status, campaign::RunStatus::kOk) << r.note;
  expect_same_figures(s, r);
}

// The fast lockstep layout: sensor frames, thruster commands and the ground channels on three
// buses, the hot channels read by each process's loop itself (--direct-rx, no LCM receive thread).
// Same messages, same order: the same run bit for bit.
TEST(PilLockstep, SplitBusesWithDirectReceiveMatchTheInProcessRunBitForBit) {
  FastCase fc;
  const std::vector<std::string> buses = {"--actuator-lcm-url", lcm_url(7815), "--ground-lcm-url",
                                          lcm_url(7816), "--direct-rx"};
  std::vector<std::string> fx = {"--start-mode", "DETUMBLE"};
  fx.insert(fx.end(), buses.begin(), buses.end());
  const auto s = run_fast_pil("vs_app_direct", 7814, fx, &fc, buses);
  ASSERT_FALSE(s.empty()) << "no plant summary";
  EXPECT_EQ(s.at("holds"), "0");
  campaign::FswFlightSide side;
  const campaign::RunResult r = run_in_process(fc, side);
  ASSERT_EQ(r.status, campaign::RunStatus::kOk) << r.note;
  expect_same_figures(s, r);
}

// Booting in DETUMBLE (mode.initial) is the bare flight core's start (GncFlightSide requests
// DETUMBLE on the first tick): the PIL run matches it bit for bit too.
TEST(PilLockstep, BootModeDetumbleMatchesTheInProcessFlightCoreRunBitForBit) {
  FastCase fc;
  const auto s = run_fast_pil("vs_core", 7813, {"--initial-mode", "DETUMBLE"}, &fc);
  ASSERT_FALSE(s.empty()) << "no plant summary";
  campaign::GncFlightSide side;
  const campaign::RunResult r = run_in_process(fc, side);
  ASSERT_EQ(r.status, campaign::RunStatus::kOk) << r.note;
  expect_same_figures(s, r);
}

// A flood of garbage on RS_GROUND_CMD, published as fast as a thread can, during a lockstep run of
// the fast case, on the one bus and on a separate ground bus. Every tick still has its sensor frame
// (fsw: ticks = frames = the plant's periods, no frameless tick), the plant never holds a command,
// and the run is the in-process run bit for bit. The per-tick bound (here 4) drops the excess
// undecoded, and the fsw's exit line counts it.
struct FloodResult {
  std::map<std::string, std::string> plant, fsw;  // plant summary, fsw exit line
  std::uint64_t sent{0};
};

std::map<std::string, std::string> fsw_exit_line(const std::string& log) {
  std::map<std::string, std::string> kv;
  const std::size_t at = log.find("fsw exit: ");
  if (at == std::string::npos) return kv;
  std::istringstream line(log.substr(at + 10, log.find('\n', at) - at - 10));
  std::string item;
  while (line >> item) {
    const std::size_t eq = item.find('=');
    if (eq != std::string::npos) kv[item.substr(0, eq)] = item.substr(eq + 1);
  }
  return kv;
}

FloodResult run_flooded_pil(const std::string& name, int port, bool separate_ground_bus,
                            FastCase* out_case) {
  const std::string dir = scratch_dir(name);
  const FastCase fc = make_fast_case(dir);
  *out_case = fc;
  const std::string url = lcm_url(port);
  const std::string ground_url = separate_ground_bus ? lcm_url(port + 1) : url;
  std::vector<std::string> fx = {"--law",        "ntcl",     "--tlm-every",        "10",
                                 "--start-mode", "DETUMBLE", "--ground-drain-max", "4"};
  std::vector<std::string> px = {"--truth-every", "10"};
  if (separate_ground_bus) {
    fx.insert(fx.end(), {"--ground-lcm-url", ground_url});
    px.insert(px.end(), {"--ground-lcm-url", ground_url});
  }
  FloodResult res;
  std::atomic<bool> stop{false};
  std::atomic<std::uint64_t> sent{0};
  std::thread flooder([&] {
    lcm_t* lcm = lcm_create(ground_url.c_str());
    if (lcm == nullptr) return;
    std::vector<std::uint8_t> junk(200);
    std::uint32_t x = 12345;
    while (!stop.load()) {
      for (auto& b : junk) b = static_cast<std::uint8_t>((x = x * 1103515245u + 12345u) >> 24);
      if (lcm_publish(lcm, channels::kGroundCmd, junk.data(), static_cast<unsigned>(junk.size())) ==
          0) {
        ++sent;
      }
    }
    lcm_destroy(lcm);
  });
  {
    Process fsw(fsw_args(url, fc.mission, fc.gnc, fc.case_file, fx), dir + "/fsw.log");
    Process plant(plant_args(url, fc.mission, fc.gnc, fc.case_file, px), dir + "/plant.log");
    int status = -1;
    EXPECT_TRUE(plant.wait(180.0, &status)) << "plant did not finish";
    EXPECT_EQ(status, 0) << read_file(plant.log_path());
    stop.store(true);
    flooder.join();
    fsw.signal(SIGTERM);
    EXPECT_TRUE(fsw.wait(10.0, &status));
    EXPECT_EQ(status, 0) << read_file(fsw.log_path());
    res.plant = plant_summary(read_file(plant.log_path()));
    res.fsw = fsw_exit_line(read_file(fsw.log_path()));
  }
  if (flooder.joinable()) {
    stop.store(true);
    flooder.join();
  }
  res.sent = sent.load();
  return res;
}

void expect_flood_survived(const FloodResult& f, const FastCase& fc) {
  ASSERT_FALSE(f.plant.empty()) << "no plant summary";
  ASSERT_FALSE(f.fsw.empty()) << "no fsw exit line";
  std::printf(
      "flood: %llu garbage messages sent; fsw %s ticks, %s frames, %s frameless, "
      "%s rx rejected, %s ground dropped in %s bound-reaching ticks; plant timeouts %s\n",
      static_cast<unsigned long long>(f.sent), f.fsw.at("ticks").c_str(),
      f.fsw.at("frames").c_str(), f.fsw.at("frameless").c_str(), f.fsw.at("rx_rejected").c_str(),
      f.fsw.at("ground_dropped").c_str(), f.fsw.at("ground_bound_ticks").c_str(),
      f.plant.at("timeouts").c_str());
  EXPECT_GT(f.sent, 1000u) << "no flood";
  EXPECT_EQ(f.plant.at("holds"), "0");
  EXPECT_EQ(f.fsw.at("ticks"), f.plant.at("periods"));  // one tick per frame, no other tick
  EXPECT_EQ(f.fsw.at("frameless"), "0");
  // The garbage was seen: decoded and rejected within the bound, the rest dropped undecoded.
  EXPECT_GT(std::stoull(f.fsw.at("rx_rejected")) + std::stoull(f.fsw.at("ground_dropped")), 0u);
  EXPECT_LE(std::stoull(f.fsw.at("rx_rejected")),
            4 * (std::stoull(f.fsw.at("ticks")) + 1000));  // the bound, plus idle base periods
  campaign::FswFlightSide side;
  const campaign::RunResult r = run_in_process(fc, side);
  ASSERT_EQ(r.status, campaign::RunStatus::kOk) << r.note;
  expect_same_figures(f.plant, r);
}

TEST(PilBusFlood, AGroundFloodOnTheOneBusStarvesNoTickAndChangesNothing) {
  FastCase fc;
  expect_flood_survived(run_flooded_pil("flood_one_bus", 7845, false, &fc), fc);
}

TEST(PilBusFlood, AGroundFloodOnASeparateGroundBusStarvesNoTickAndChangesNothing) {
  FastCase fc;
  expect_flood_survived(run_flooded_pil("flood_ground_bus", 7847, true, &fc), fc);
}

// ---------------------------------------------------------------------------------------------

struct Case1Rig {
  std::string dir, url, mission, gnc, case_file;
  std::unique_ptr<Process> fsw, plant;
  std::unique_ptr<TestBus> bus;

  Case1Rig(const std::string& name, int port, const std::vector<std::string>& fsw_extra) {
    dir = scratch_dir(name);
    url = lcm_url(port);
    mission = config_dir() + "/mission.yaml";
    gnc = config_dir() + "/gnc.yaml";
    case_file = config_dir() + "/cases/case1.yaml";
    bus = std::make_unique<TestBus>(url);
    fsw = std::make_unique<Process>(fsw_args(url, mission, gnc, case_file, fsw_extra),
                                    dir + "/fsw.log");
    start_plant("plant.log");
  }
  void start_plant(const std::string& log) {
    plant = std::make_unique<Process>(plant_args(url, mission, gnc, case_file, {}), dir + "/" + log);
  }
  std::string logs() const {
    return "--- fsw:\n" + read_file(dir + "/fsw.log") + "--- plant:\n" + read_file(dir + "/plant.log");
  }
};

TEST(PilCommands, IdleDetumbleHoldWithARejectedCommandAndAGainsUpdate) {
  Case1Rig rig("commands", 7821, {});
  TestBus& bus = *rig.bus;
  ASSERT_TRUE(bus.spin_until([&] { return bus.have_tlm && bus.tlm.frames_accepted > 0; }, 20.0))
      << rig.logs();
  EXPECT_EQ(bus.tlm.mode, kIdle);
  EXPECT_EQ(bus.tlm.thrusters_enabled, 0);

  // IDLE -> DETUMBLE.
  bus.send_command(1, kOpSetMode, {kDetumble});
  ASSERT_TRUE(bus.spin_until([&] { return bus.ack_for(1) != nullptr; }, 20.0)) << rig.logs();
  EXPECT_EQ(bus.ack_for(1)->accepted, 1) << bus.ack_for(1)->text;
  ASSERT_TRUE(bus.spin_until([&] { return bus.tlm.mode == kDetumble && bus.tlm.thrusters_enabled; }, 20.0));

  // TRACK without an uplinked trajectory: rejected, with the reason and an event.
  bus.send_command(2, kOpSetMode, {kTrack});
  ASSERT_TRUE(bus.spin_until([&] { return bus.ack_for(2) != nullptr; }, 20.0));
  EXPECT_EQ(bus.ack_for(2)->accepted, 0);
  EXPECT_EQ(bus.ack_for(2)->reason, kReasonNotAllowedInMode);
  EXPECT_EQ(bus.ack_for(2)->detail, kNoTrajectory);
  EXPECT_TRUE(bus.spin_until([&] { return bus.has_event(kEvCommandRejected); }, 2.0));

  // Gains update: load ntcl.K (param 0) into the inactive table, then activate it at a tick.
  bus.send_command(3, kOpParamLoad, {0, 2.0e4, 2.0e4, 2.0e4});
  bus.send_command(4, kOpParamActivate, {});
  ASSERT_TRUE(bus.spin_until([&] { return bus.ack_for(4) != nullptr; }, 20.0));
  ASSERT_NE(bus.ack_for(3), nullptr);
  EXPECT_EQ(bus.ack_for(3)->accepted, 1) << bus.ack_for(3)->text;
  EXPECT_EQ(bus.ack_for(4)->accepted, 1) << bus.ack_for(4)->text;
  ASSERT_TRUE(bus.spin_until([&] { return bus.tlm.table_activations == 1; }, 20.0));
  EXPECT_EQ(bus.tlm.table_loads, 1);
  EXPECT_TRUE(bus.spin_until([&] { return bus.has_event(kEvTableActivated); }, 2.0));

  // DETUMBLE -> HOLD by command (the despin of case 1 takes ~2e4 s: far from the auto switch).
  bus.send_command(5, kOpSetMode, {kHold});
  ASSERT_TRUE(bus.spin_until([&] { return bus.ack_for(5) != nullptr; }, 20.0));
  EXPECT_EQ(bus.ack_for(5)->accepted, 1) << bus.ack_for(5)->text;
  ASSERT_TRUE(bus.spin_until([&] { return bus.tlm.mode == kHold; }, 20.0));
  EXPECT_TRUE(bus.tlm.thrusters_enabled);
  EXPECT_TRUE(bus.spin_until([&] { return bus.tlm.cmd_accepted == 4 && bus.tlm.cmd_rejected == 1; }, 2.0))
      << "accepted " << bus.tlm.cmd_accepted << " rejected " << bus.tlm.cmd_rejected;
  const auto mode_changes = [&] {
    int n = 0;
    for (const auto& e : bus.events) n += e.id == kEvModeChanged ? 1 : 0;
    return n;
  };
  EXPECT_TRUE(bus.spin_until([&] { return mode_changes() == 2; }, 2.0)) << mode_changes();
  EXPECT_TRUE(rig.fsw->running());
}

// ---------------------------------------------------------------------------------------------

template <class T> std::vector<std::uint8_t> encode(const T& m) {
  std::vector<std::uint8_t> b(static_cast<std::size_t>(m.getEncodedSize()));
  m.encode(b.data(), 0, static_cast<int>(b.size()));
  return b;
}

// Malformed variants of one valid message: 5 "malformed" (empty, truncated, too long, garbage,
// another type), 2 "bad kind" (kind, version), 1 "out of range" (from `out_of_range`).
template <class T>
std::vector<std::vector<std::uint8_t>> bad_variants(const T& valid, const T& out_of_range) {
  const std::vector<std::uint8_t> v = encode(valid);
  std::vector<std::vector<std::uint8_t>> out;
  out.push_back({});
  out.emplace_back(v.begin(), v.begin() + static_cast<long>(v.size() / 2));
  std::vector<std::uint8_t> longer = v;
  longer.insert(longer.end(), 7, 0xAB);
  out.push_back(longer);
  std::vector<std::uint8_t> garbage(v.size());
  for (std::size_t i = 0; i < garbage.size(); ++i) garbage[i] = static_cast<std::uint8_t>(37 * i + 11);
  out.push_back(garbage);
  out.push_back(encode(wire::make<rocksteady::plant_truth_t>()));  // another type
  T k = valid;
  k.kind = 99;
  out.push_back(encode(k));
  T ver = valid;
  ver.version = 9;
  out.push_back(encode(ver));
  out.push_back(encode(out_of_range));
  return out;
}

TEST(PilProtection, MalformedMessagesOnEveryInputChannelAreCountedAndIgnored) {
  Case1Rig rig("malformed", 7831, {"--start-mode", "DETUMBLE"});
  TestBus& bus = *rig.bus;
  ASSERT_TRUE(bus.spin_until([&] { return bus.have_tlm && bus.tlm.mode == kDetumble; }, 20.0))
      << rig.logs();
  ASSERT_EQ(bus.tlm.rx_malformed + bus.tlm.rx_bad_kind + bus.tlm.rx_out_of_range, 0);

  auto frame = wire::make<rocksteady::sensor_frame_t>();
  frame.seq = 5;
  frame.t = 0.5;
  frame.star_quat[3] = 1.0;
  auto frame_bad = frame;
  frame_bad.t = std::nan("");
  auto cmd = wire::make<rocksteady::ground_cmd_t>();
  cmd.seq = 1;
  cmd.sender_id = 3;
  auto cmd_bad = cmd;
  cmd_bad.nargs = 100;
  auto chunk = wire::make<rocksteady::trajectory_chunk_t>();
  chunk.total_samples = 40;
  chunk.total_chunks = 2;
  chunk.count = 32;
  auto chunk_bad = chunk;
  chunk_bad.count = 31;
  auto thr = wire::make<rocksteady::thruster_cmd_t>();
  auto thr_bad = thr;
  thr_bad.thruster_force[3] = -1.0;

  const struct {
    const char* channel;
    std::vector<std::vector<std::uint8_t>> msgs;
  } inputs[] = {
      {channels::kSensors, bad_variants(frame, frame_bad)},
      {channels::kGroundCmd, bad_variants(cmd, cmd_bad)},
      {channels::kTrajUplink, bad_variants(chunk, chunk_bad)},
      {channels::kThrusterCmd, bad_variants(thr, thr_bad)},  // the plant's input
  };
  for (const auto& in : inputs) {
    for (const auto& m : in.msgs) {
      bus.publish_raw(in.channel, m);
      bus.spin_for(0.002);
    }
  }
  // A well-formed command with an unknown opcode is not a bus error: it is answered.
  auto unknown = cmd;
  unknown.opcode = 77;
  bus.publish_raw(channels::kGroundCmd, encode(unknown));

  // Three flight-software inputs x (5 malformed, 2 bad kind, 1 out of range).
  ASSERT_TRUE(bus.spin_until([&] {
    return bus.tlm.rx_malformed == 15 && bus.tlm.rx_bad_kind == 6 && bus.tlm.rx_out_of_range == 3;
  }, 10.0)) << "malformed " << bus.tlm.rx_malformed << " bad kind " << bus.tlm.rx_bad_kind
            << " out of range " << bus.tlm.rx_out_of_range;
  ASSERT_TRUE(bus.spin_until([&] { return bus.ack_for(1, 3) != nullptr; }, 20.0));
  EXPECT_EQ(bus.ack_for(1, 3)->reason, kReasonUnknownOpcode);

  // Both processes live on and keep the loop closed.
  const std::int64_t frames = bus.tlm.frames_accepted;
  ASSERT_TRUE(bus.spin_until([&] { return bus.tlm.frames_accepted > frames + 100; }, 10.0));
  EXPECT_EQ(bus.tlm.mode, kDetumble);
  EXPECT_EQ(bus.tlm.frames_rejected, 0);  // the bad frames never reached the application
  EXPECT_TRUE(rig.fsw->running());
  ASSERT_TRUE(rig.plant->running()) << rig.logs();
  rig.plant->signal(SIGINT);  // ends the run early; the summary has the plant's counters
  ASSERT_TRUE(rig.plant->wait(10.0));
  const auto s = plant_summary(read_file(rig.dir + "/plant.log"));
  ASSERT_FALSE(s.empty()) << rig.logs();
  EXPECT_EQ(s.at("rx_rejected"), "8");
  EXPECT_TRUE(rig.fsw->running());
}

// ---------------------------------------------------------------------------------------------

TEST(PilProtection, KillingThePlantSendsTheFlightSoftwareToSafeAndARestartRecovers) {
  Case1Rig rig("plant_loss", 7841, {"--start-mode", "DETUMBLE", "--frame-watchdog", "0.3"});
  TestBus& bus = *rig.bus;
  ASSERT_TRUE(bus.spin_until([&] {
    return bus.have_tlm && bus.tlm.mode == kDetumble && bus.tlm.thrusters_enabled;
  }, 20.0)) << rig.logs();

  rig.plant->signal(SIGKILL);
  ASSERT_TRUE(rig.plant->wait(5.0));
  // No frames: the watchdog's frameless ticks let the sensor timeout fire -> SAFE, thrusters off.
  ASSERT_TRUE(bus.spin_until([&] { return bus.tlm.mode == kSafe; }, 10.0)) << rig.logs();
  EXPECT_EQ(bus.tlm.thrusters_enabled, 0);
  EXPECT_GT(bus.tlm.frameless_ticks, 0);
  EXPECT_TRUE(bus.spin_until([&] { return bus.has_event(kEvSensorTimeout); }, 2.0));
  EXPECT_TRUE(bus.has_event(kEvFrameWatchdog));
  const std::uint64_t n = bus.thruster_count;
  ASSERT_TRUE(bus.spin_until([&] { return bus.thruster_count > n + 2; }, 20.0));
  EXPECT_EQ(bus.thruster.enabled, 0);
  for (int i = 0; i < 16; ++i) EXPECT_EQ(bus.thruster.thruster_on[i], 0) << i;
  EXPECT_TRUE(rig.fsw->running());

  // A new plant: its frames count from 0 again. The fsw re-anchors and takes them.
  const std::int64_t accepted = bus.tlm.frames_accepted;
  rig.start_plant("plant2.log");
  ASSERT_TRUE(bus.spin_until([&] { return bus.tlm.frames_accepted > accepted + 20; }, 20.0))
      << rig.logs();
  EXPECT_TRUE(bus.has_event(kEvStreamRestart));
  EXPECT_EQ(bus.tlm.mode, kSafe);  // SAFE is left by ground command only

  bus.send_command(1, kOpSetMode, {kDetumble});
  ASSERT_TRUE(bus.spin_until([&] { return bus.ack_for(1) != nullptr; }, 20.0));
  EXPECT_EQ(bus.ack_for(1)->accepted, 1) << bus.ack_for(1)->text;
  ASSERT_TRUE(bus.spin_until([&] {
    return bus.tlm.mode == kDetumble && bus.tlm.thrusters_enabled && bus.thruster.enabled;
  }, 20.0)) << rig.logs();
  const std::int64_t later = bus.tlm.frames_accepted;
  EXPECT_TRUE(bus.spin_until([&] { return bus.tlm.frames_accepted > later + 100; }, 10.0));
  EXPECT_EQ(bus.tlm.mode, kDetumble);
}

// ---------------------------------------------------------------------------------------------

// The plant's fault injection over the bus (RS_PLANT_FAULT, answered with events) and its valve
// driver: when the flight software dies, the plant (holding after one short echo wait per period)
// switches every thruster off once 1 s of plant time has passed without a command.
TEST(PilPlantFaults, BusInjectionIsAnsweredAndTheValveDriverSwitchesOffWhenTheFlightSoftwareDies) {
  constexpr int kEvFaultAccepted = 1003, kEvFaultRejected = 1004, kEvValveDriverTimeout = 1005;
  const std::string dir = scratch_dir("plant_faults");
  const std::string url = lcm_url(7851);
  const std::string mission = config_dir() + "/mission.yaml", gnc = config_dir() + "/gnc.yaml",
                    case_file = config_dir() + "/cases/case1.yaml";
  TestBus bus(url);
  Process fsw(fsw_args(url, mission, gnc, case_file, {"--start-mode", "DETUMBLE"}), dir + "/fsw.log");
  Process plant({plant_exe(), "--lcm-url", url, "--mission", mission, "--gnc", gnc, "--case",
                 case_file, "--summary", "--retries", "0", "--timeout-ms", "20",
                 "--valve-timeout", "1.0"},
                dir + "/plant.log");
  auto logs = [&] { return read_file(dir + "/fsw.log") + "--- plant:\n" + read_file(dir + "/plant.log"); };
  ASSERT_TRUE(bus.spin_until([&] {
    return bus.have_tlm && bus.tlm.mode == kDetumble && bus.tlm.thrusters_enabled;
  }, 20.0)) << logs();

  using F = rocksteady::plant_fault_cmd_t;
  auto inject = wire::make<F>();
  inject.seq = 1;
  inject.op = F::OP_INJECT;
  inject.thruster = 6;
  inject.fault_kind = F::FAULT_STUCK_ON;
  bus.publish_raw(channels::kPlantFault, encode(inject));
  ASSERT_TRUE(bus.spin_until([&] { return bus.has_event(kEvFaultAccepted); }, 20.0)) << logs();
  auto bad = inject;
  bad.seq = 2;
  bad.thruster = 20;
  bus.publish_raw(channels::kPlantFault, encode(bad));
  ASSERT_TRUE(bus.spin_until([&] { return bus.has_event(kEvFaultRejected); }, 20.0)) << logs();
  for (const auto& e : bus.events) {
    if (e.id == kEvFaultRejected) {
      EXPECT_NE(e.text.find("[0, 15]"), std::string::npos) << e.text;
    }
    if (e.id == kEvFaultAccepted) {
      EXPECT_NE(e.text.find("thruster 6 stuck_on"), std::string::npos) << e.text;
    }
  }
  auto malformed = inject;
  malformed.onset_s = std::nan("");
  bus.publish_raw(channels::kPlantFault, encode(malformed));
  bus.spin_for(0.2);
  EXPECT_FALSE(bus.has_event(kEvValveDriverTimeout));  // commands are flowing

  fsw.signal(SIGKILL);
  ASSERT_TRUE(fsw.wait(5.0));
  ASSERT_TRUE(bus.spin_until([&] { return bus.has_event(kEvValveDriverTimeout); }, 10.0)) << logs();
  plant.signal(SIGINT);
  ASSERT_TRUE(plant.wait(10.0));
  const std::string text = read_file(dir + "/plant.log");
  EXPECT_NE(text.find("faults: thruster 6 stuck_on at 0 s; commands accepted 1, rejected 1, "
                      "malformed 1; valve-driver timeouts 1"),
            std::string::npos)
      << text;
}

TEST(PilRealtime, WallClockRunClosesTheLoop) {
  const std::string dir = scratch_dir("realtime");
  const std::string url = lcm_url(7851);
  const std::string mission = config_dir() + "/mission.yaml", gnc = config_dir() + "/gnc.yaml",
                    case_file = config_dir() + "/cases/case1.yaml";
  Process fsw(fsw_args(url, mission, gnc, case_file, {"--clock", "realtime", "--start-mode", "DETUMBLE"}),
              dir + "/fsw.log");
  Process plant(plant_args(url, mission, gnc, case_file, {"--mode", "realtime", "--duration", "3"}),
                dir + "/plant.log");
  int status = -1;
  ASSERT_TRUE(plant.wait(30.0, &status));
  EXPECT_EQ(status, 0);
  const auto s = plant_summary(read_file(plant.log_path()));
  ASSERT_FALSE(s.empty()) << read_file(plant.log_path());
  EXPECT_EQ(s.at("periods"), "30");
  EXPECT_EQ(s.at("flight_mode"), "DETUMBLE");
  EXPECT_GT(std::stod(s.at("total_fuel")), 0.0);  // the thrusters the fsw commanded fired
  EXPECT_TRUE(fsw.running());
}

}  // namespace
}  // namespace rocksteady::pil

// The tests need LCM multicast without touching the machine's network: run the whole binary in a
// private network namespace (user + net, no root needed) with the loopback up and the LCM group
// routed to it.
int main(int argc, char** argv) {
  if (std::getenv("ROCKSTEADY_PIL_NETNS") == nullptr) {
    setenv("ROCKSTEADY_PIL_NETNS", "1", 1);
    char self[4096];
    const ssize_t n = readlink("/proc/self/exe", self, sizeof self - 1);
    if (n <= 0) return 1;
    self[n] = '\0';
    std::vector<std::string> args = {
        "unshare", "-rn", "sh", "-c",
        "ip link set lo up && ip link set lo multicast on && ip route add 239.255.76.67 dev lo && "
        "exec \"$0\" \"$@\"",
        self};
    for (int i = 1; i < argc; ++i) args.emplace_back(argv[i]);
    std::vector<char*> av;
    for (auto& a : args) av.push_back(a.data());
    av.push_back(nullptr);
    execvp("unshare", av.data());
    std::perror("unshare (a private network namespace is needed for the PIL tests)");
    return 1;
  }
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
