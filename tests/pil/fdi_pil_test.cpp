// Thruster fault detection, isolation and reallocation over the bus: rocksteady-plant and
// rocksteady-fsw in lockstep (private network namespace, see pil_tests.cpp's main()), the flight
// software identifying the model on line and running the fault detector. A stuck-on thruster is
// injected into the running plant on RS_PLANT_FAULT once the telemetry shows the identified model
// confident; everything asserted is read from the bus: the flight's events and telemetry, and the
// plant's truth (RS_PLANT_TRUTH, which the flight software never reads).
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "lcmtypes/channels.hpp"
#include "rocksteady/plant_fault_cmd_t.hpp"
#include "rocksteady/plant_truth_t.hpp"
#include "tests/pil/pil_harness.hpp"
#include "wire/codec.hpp"

namespace rocksteady::pil {
namespace {

constexpr int kHold = 2;
constexpr int kEvFaultConfirmed = 133, kEvValveClosed = 134;  // fsw/interface.hpp
constexpr int kEvPlantFaultAccepted = 1003;                   // ground/plantd
constexpr int kFaultKindStuckOn = 1;                          // gnc::FaultKind

std::vector<std::uint8_t> encode_fault(rocksteady::plant_fault_cmd_t m) {
  std::vector<std::uint8_t> buf(static_cast<std::size_t>(m.getEncodedSize()));
  m.encode(buf.data(), 0, static_cast<int>(buf.size()));
  return buf;
}

// Case 1 with a short despin (ten times the thrust, stiffer NTCL gains, as the other lockstep
// tests), on-line identification with automatic adoption and the fault detector on.
struct FdiRig {
  std::string dir, mission, gnc, case_file;
};

FdiRig make_rig(const std::string& name) {
  FdiRig r;
  r.dir = scratch_dir(name);
  r.mission = config_dir() + "/mission.yaml";
  r.gnc = r.dir + "/gnc_fdi.yaml";
  r.case_file = r.dir + "/case1_fast.yaml";
  copy_with_lines(config_dir() + "/gnc.yaml", r.gnc,
                  {{"  ntcl:", "  ntcl:        {K: 1.0e6, Lambda: 3.0e-2}"},
                   {"  enabled: false         # off for the study's strategies (the campaign's ':id'",
                    "  enabled: true"},
                   {"  adopt: off", "  adopt: auto"},
                   {"  enabled: false         # off for the study's strategies (the campaign's ':fdi'",
                    "  enabled: true"}});
  copy_with_lines(config_dir() + "/cases/case1.yaml", r.case_file,
                  {{"u_max_n:", "u_max_n: 2000"}, {"duration_s:", "duration_s: 600"}});
  return r;
}

// The model is confident at ~180 s of this case, just after DETUMBLE handed over to HOLD with
// |omega| ~ 0.01 rad/s left to remove (the D+PD hold swings the rate up again before it settles).
// The plant and the flight number the sixteen physical thrusters alike: 4 pod + position, i.e.
// index 2c / 2c+1 of channel c.
void stuck_on_over_the_bus(const std::string& name, int port, std::int16_t kThruster) {
  const int kPod = kThruster / 4;  // its pod
  const FdiRig rig = make_rig(name);
  const std::string url = lcm_url(port);
  TestBus bus(url);
  double t_confident = -1.0;  // telemetry time at which the identified model was first confident
  bus.on_each_tlm = [&](const rocksteady::gnc_telemetry_t& m) {
    if (t_confident < 0.0 && m.identifying && m.id_inertia_confident && m.id_offset_confident) {
      t_confident = m.t;
    }
  };
  Process fsw({fsw_exe(), "--lcm-url", url, "--mission", rig.mission, "--gnc", rig.gnc, "--case",
               rig.case_file, "-v", "--lab-mode", "--law", "ntcl", "--tlm-every", "10",
               "--start-mode", "DETUMBLE"},
              rig.dir + "/fsw.log");
  Process plant({plant_exe(), "--lcm-url", url, "--mission", rig.mission, "--gnc", rig.gnc,
                 "--case", rig.case_file, "--summary", "--retries", "1000", "--timeout-ms", "100",
                 "--truth-every", "10"},
                rig.dir + "/plant.log");
  const auto logs = [&] {
    return "--- fsw:\n" + read_file(rig.dir + "/fsw.log") + "--- plant:\n" +
           read_file(rig.dir + "/plant.log");
  };

  // The identification converges first; the fault is injected after that, with its onset a few
  // seconds ahead of the newest telemetry (the plant acts on it at once if it is already past).
  ASSERT_TRUE(bus.spin_until([&] { return t_confident >= 0.0; }, 60.0)) << logs();
  ASSERT_TRUE(bus.have_tlm);
  EXPECT_FALSE(bus.has_event(kEvFaultConfirmed)) << "a false alarm before any fault";
  EXPECT_EQ(bus.tlm.fdi_enabled, 1);
  using F = rocksteady::plant_fault_cmd_t;
  auto inject = wire::make<F>();
  inject.seq = 1;
  inject.op = F::OP_INJECT;
  inject.thruster = kThruster;
  inject.fault_kind = F::FAULT_STUCK_ON;
  inject.onset_s = bus.tlm.t + 5.0;
  inject.factor = 1.0;
  bus.publish_raw(channels::kPlantFault, encode_fault(inject));
  ASSERT_TRUE(bus.spin_until([&] { return bus.has_event(kEvPlantFaultAccepted); }, 10.0)) << logs();

  // The flight confirms the injected thruster stuck on, and closes its pod's valve.
  ASSERT_TRUE(bus.spin_until([&] { return bus.has_event(kEvFaultConfirmed); }, 60.0)) << logs();
  int confirmations = 0;
  for (const auto& e : bus.events) {
    if (e.id != kEvFaultConfirmed) continue;
    ++confirmations;
    EXPECT_EQ(e.arg0, kThruster) << e.text;
    EXPECT_EQ(e.arg1, kFaultKindStuckOn) << e.text;
  }
  EXPECT_EQ(confirmations, 1);
  ASSERT_TRUE(bus.spin_until([&] { return bus.has_event(kEvValveClosed); }, 10.0)) << logs();
  for (const auto& e : bus.events) {
    if (e.id == kEvValveClosed) {
      EXPECT_EQ(e.arg0, kPod);
      EXPECT_EQ(e.arg1, kThruster);
    }
  }

  // The despin completes on the other three pods: HOLD, at rest, and the plant finishes its run.
  int status = -1;
  EXPECT_TRUE(plant.wait(110.0, &status)) << "the plant did not finish";
  EXPECT_EQ(status, 0) << logs();
  bus.spin_for(0.3);  // what was still in flight
  EXPECT_EQ(bus.tlm.mode, kHold) << logs();
  EXPECT_NE(bus.tlm.fdi_confirmed_on & (1 << kThruster), 0);
  EXPECT_EQ(bus.tlm.fdi_confirmed_on & ~(1 << kThruster), 0) << "another thruster confirmed";
  EXPECT_EQ(bus.tlm.fdi_confirmed_off, 0);
  for (int p = 0; p < 4; ++p) EXPECT_EQ(bus.tlm.valve_open[p] != 0, p != kPod) << "pod " << p;
  EXPECT_TRUE(fsw.running()) << logs();

  // The plant's truth: the fault acted from after the model was confident, the valve closed, and
  // after that the pod delivered nothing while the spacecraft came to rest.
  ASSERT_FALSE(bus.truths.empty()) << logs();
  double t_fault = -1.0, t_closed = -1.0, omega_at_fault = 0.0;
  for (const auto& tr : bus.truths) {
    if (t_fault < 0.0 && tr.fault_kind[kThruster] == int{rocksteady::plant_truth_t::FAULT_STUCK_ON}) {
      t_fault = tr.t;
      omega_at_fault = tr.omega_norm;
    }
    if (t_closed >= 0.0 && tr.t > t_closed) {
      EXPECT_FALSE(tr.valve_open[kPod]) << "pod " << kPod << "'s valve reopened at " << tr.t;
      for (int j = 4 * kPod; j < 4 * kPod + 4; ++j) {
        EXPECT_EQ(tr.thruster_force[j], 0.0) << "thruster " << j << " at " << tr.t;
      }
    }
    if (t_closed < 0.0 && !tr.valve_open[kPod]) t_closed = tr.t;
  }
  ASSERT_GE(t_fault, 0.0) << "the truth never showed the injected fault";
  ASSERT_GE(t_closed, 0.0) << "the truth never showed pod " << kPod << "'s valve closed";
  EXPECT_GT(t_fault, t_confident);
  EXPECT_GT(t_closed, t_fault);
  const auto& last = bus.truths.back();
  EXPECT_EQ(int{last.fault_kind[kThruster]}, int{rocksteady::plant_truth_t::FAULT_STUCK_ON});
  // The despin still had most of its work ahead when the fault struck (the rate at onset is
  // 1e-3...2e-2 rad/s in this case's hold phase): it is done on three pods.
  EXPECT_GT(omega_at_fault, 1e-3);
  EXPECT_LT(last.omega_norm, 1e-4) << "not at rest: " << last.omega_norm << " rad/s";
  const auto s = plant_summary(read_file(rig.dir + "/plant.log"));
  ASSERT_TRUE(s.count("t_omega")) << logs();
  EXPECT_NE(s.at("t_omega"), "NC") << logs();
  EXPECT_EQ(s.at("flight_mode"), "HOLD");
}

// Thruster 0, pod 0's tangential "+" jet: no other hypothesis resembles it.
TEST(PilFdi, AStuckOnThrusterInjectedOverTheBusIsIsolatedItsPodClosedAndTheDespinCompletes) {
  stuck_on_over_the_bus("fdi_stuck_on", 7871, 0);
}

// Thruster 6, pod 1's axial "+z" jet: pod 3's "-z" jet (15) pushes the body the same way up to the
// centre of mass's xy offset (gnc/fdi/README.md, "Which hypotheses look alike"); the former
// detector isolated 15 in this case. The flight settles it by its isolation test (F9).
TEST(PilFdi, AStuckOnAxialJetWithAMirrorOnTheOppositePodIsIsolatedToItself) {
  stuck_on_over_the_bus("fdi_stuck_on_axial", 7872, 6);
}

}  // namespace
}  // namespace rocksteady::pil
