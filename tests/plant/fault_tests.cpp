// The plant's thruster faults, latch valves and valve-driver timeout, against a separately written
// per-thruster model: torque = B_true (F_+ - F_-) per channel, fuel = sum of what flows / (Isp g0).
#include <cmath>
#include <stdexcept>
#include <memory>
#include <string>

#include <gtest/gtest.h>

#include "ground/plant/plant.hpp"

namespace rocksteady::plant {
namespace {

constexpr double kDt = 0.1;

PlantParams quiet() {
  PlantParams p;
  p.disturbance.sigma_nm = 0.0;
  p.omega0 = Vec3(0.01, 0.02, 0.03);
  p.beta0 = att::mrp_to_quat(Vec3(0.05, 0.04, 0.03));
  return p;
}

// The independent model of one period: per-thruster forces -> body torque with the true B.
Vec3 torque_of(const PlantParams& p, const Vec16& thrust) {
  const Mat38 b = gnc::torque_matrix(p.rcs, p.mass.r_so_bcm);
  Vec3 tau = Vec3::Zero();
  for (int i = 0; i < 16; ++i) tau += (i % 2 == 0 ? 1.0 : -1.0) * thrust(i) * b.col(i / 2);
  return tau;
}

// A fault-free plant driven with the given torque per period (the reference trajectory).
struct Reference {
  explicit Reference(const PlantParams& p) {
    PlantParams q = p;
    q.faults.clear();
    plant = std::make_unique<Plant>(q);
  }
  // Channel forces that reproduce a per-thruster thrust on the healthy plant.
  void advance(const Vec16& thrust) {
    Vec8 u;
    for (int c = 0; c < 8; ++c) u(c) = thrust(2 * c) - thrust(2 * c + 1);
    plant->advance(u, true);
  }
  std::unique_ptr<Plant> plant;
};

double fuel_of(const PlantParams& p, double flow_n) { return flow_n * kDt / (p.isp_s * p.g0); }

hal::ThrusterOutputs fire(int thruster, double force) {
  hal::ThrusterOutputs o;
  o.enabled = true;
  o.on[static_cast<std::size_t>(thruster)] = true;
  o.force[static_cast<std::size_t>(thruster)] = force;
  return o;
}

TEST(PlantFaults, FaultBeforeItsOnsetChangesNoBit) {
  PlantParams p = quiet();
  p.disturbance.sigma_nm = 0.57735026918962576;
  PlantParams f = p;
  f.faults = {{3, FaultKind::kStuckOn, 50.0, 1.0}, {9, FaultKind::kDegraded, 50.0, 0.5}};
  Plant a(p), b(f);
  const Vec8 u = (Vec8() << 150, -80, 40, 0, -120, 60, 0, 90).finished();
  for (int k = 0; k < 499; ++k) {  // up to t = 49.9 s
    a.advance(u, true);
    b.advance(u, true);
  }
  EXPECT_EQ(a.omega(), b.omega());
  EXPECT_EQ(a.beta(), b.beta());
  EXPECT_EQ(a.fuel_kg(), b.fuel_kg());
  for (const FaultKind k : b.active_faults()) EXPECT_EQ(k, FaultKind::kNone);
  a.advance(u, true);
  b.advance(u, true);  // t = 49.9 -> 50.0: still before (onset is at the period's start)
  EXPECT_EQ(a.omega(), b.omega());
  a.advance(u, true);
  b.advance(u, true);  // the period starting at 50 s has both faults
  EXPECT_NE(a.omega(), b.omega());
  EXPECT_EQ(b.active_faults()[3], FaultKind::kStuckOn);
  EXPECT_EQ(b.active_faults()[9], FaultKind::kDegraded);
}

TEST(PlantFaults, EachKindOnEveryThrusterMatchesThePerThrusterModel) {
  for (int i = 0; i < 16; ++i) {
    for (const FaultKind kind : {FaultKind::kStuckOff, FaultKind::kStuckOn, FaultKind::kDegraded}) {
      PlantParams p = quiet();
      p.faults = {{i, kind, 0.0, 0.4}};
      Plant plant(p);
      Reference ref(p);
      // Commanded: thruster i at 120 N, its opposite at 0, and an unrelated thruster of another pod.
      const int other = (i + 5) % 16;
      hal::ThrusterOutputs o = fire(i, 120.0);
      o.on[static_cast<std::size_t>(other)] = true;
      o.force[static_cast<std::size_t>(other)] = 70.0;
      Vec16 expect = Vec16::Zero();
      expect(other) = 70.0;
      double flow = 70.0;
      switch (kind) {
        case FaultKind::kStuckOff: break;
        case FaultKind::kStuckOn: expect(i) = 200.0, flow += 200.0; break;
        case FaultKind::kDegraded: expect(i) = 0.4 * 120.0, flow += 120.0; break;
        case FaultKind::kNone: break;
      }
      plant.advance(o);
      ref.advance(expect);
      const std::string what = "thruster " + std::to_string(i) + " " + to_string(kind);
      EXPECT_LT((plant.control_torque() - torque_of(p, expect)).norm(), 1e-9) << what;
      EXPECT_LT((plant.thruster_thrust() - expect).norm(), 1e-12) << what;
      EXPECT_LT((plant.omega() - ref.plant->omega()).norm(), 1e-15) << what;
      EXPECT_NEAR(plant.fuel_kg(), fuel_of(p, flow), 1e-15) << what;
    }
  }
}

TEST(PlantFaults, StuckOnFiresFullThrustWhateverIsCommanded) {
  PlantParams p = quiet();
  p.faults = {{6, FaultKind::kStuckOn, 0.0, 1.0}};  // pod 1 axial "+" = channel 3 "+"
  Plant plant(p);
  // Disabled command: the stuck thruster still fires.
  plant.advance(hal::ThrusterOutputs{});
  Vec16 expect = Vec16::Zero();
  expect(6) = 200.0;
  EXPECT_LT((plant.control_torque() - torque_of(p, expect)).norm(), 1e-9);
  EXPECT_NEAR(plant.fuel_kg(), fuel_of(p, 200.0), 1e-15);
  // The opposite thruster commanded at 150 N: the channel nets 50 N, both flow.
  plant.advance(fire(7, 150.0));
  expect(7) = 150.0;
  EXPECT_LT((plant.delivered_force()(3) - 50.0), 1e-12);
  EXPECT_LT((plant.control_torque() - torque_of(p, expect)).norm(), 1e-9);
  EXPECT_NEAR(plant.fuel_kg(), fuel_of(p, 200.0) + fuel_of(p, 350.0), 1e-15);
}

TEST(PlantValves, ClosedPodProducesNothingStuckOnIncluded) {
  for (int pod = 0; pod < 4; ++pod) {
    PlantParams p = quiet();
    p.faults = {{4 * pod + 2, FaultKind::kStuckOn, 0.0, 1.0}};
    Plant plant(p);
    hal::ThrusterOutputs o;
    o.enabled = true;
    for (int i = 0; i < 16; ++i) {
      if (i % 2 == 0) {  // every "+" thruster at 100 N
        o.on[static_cast<std::size_t>(i)] = true;
        o.force[static_cast<std::size_t>(i)] = 100.0;
      }
    }
    o.valve_open[static_cast<std::size_t>(pod)] = false;
    plant.advance(o);
    EXPECT_EQ(plant.valves(), o.valve_open);
    Vec16 expect = Vec16::Zero();
    double flow = 0.0;
    for (int i = 0; i < 16; ++i) {
      if (i / 4 != pod && i % 2 == 0) {
        expect(i) = 100.0;
        flow += 100.0;
      }
    }
    EXPECT_LT((plant.thruster_thrust() - expect).norm(), 1e-12) << "pod " << pod;
    EXPECT_LT((plant.control_torque() - torque_of(p, expect)).norm(), 1e-9) << "pod " << pod;
    EXPECT_NEAR(plant.fuel_kg(), fuel_of(p, flow), 1e-15);
    // Reopened: the stuck-on thruster fires again.
    o.valve_open.fill(true);
    plant.advance(o);
    expect(4 * pod + 2) = 200.0;
    for (int i = 4 * pod; i < 4 * pod + 4; ++i) {
      if (i % 2 == 0 && i != 4 * pod + 2) expect(i) = 100.0;
    }
    EXPECT_LT((plant.thruster_thrust() - expect).norm(), 1e-12) << "pod " << pod;
  }
}

TEST(PlantValveDriver, ThrustersOffOnceCommandsStopForTheTimeout) {
  PlantParams p = quiet();
  p.command_timeout_s = 1.0;
  Plant plant(p);
  plant.receive(fire(0, 100.0));
  int firing = 0;
  for (int k = 0; k < 30; ++k) {
    plant.advance();
    if (plant.thruster_thrust()(0) > 0.0) {
      ++firing;
      EXPECT_FALSE(plant.command_timed_out());
    } else {
      EXPECT_TRUE(plant.command_timed_out());
    }
  }
  EXPECT_EQ(firing, 10);  // periods starting at 0.0 .. 0.9 s after the command
  EXPECT_EQ(plant.timeout_periods(), 20u);
  EXPECT_NEAR(plant.fuel_kg(), 10 * fuel_of(p, 100.0), 1e-15);
  // A new command restarts the driver.
  plant.receive(fire(0, 100.0));
  plant.advance();
  EXPECT_EQ(plant.thruster_thrust()(0), 100.0);
  // A stuck-on thruster is not switched off by the driver, only by its latch valve.
  PlantParams s = p;
  s.faults = {{4, FaultKind::kStuckOn, 0.0, 1.0}};
  Plant stuck(s);
  stuck.receive(hal::ThrusterOutputs{});
  for (int k = 0; k < 20; ++k) stuck.advance();
  EXPECT_TRUE(stuck.command_timed_out());
  EXPECT_EQ(stuck.thruster_thrust()(4), 200.0);
  hal::ThrusterOutputs closed;
  closed.valve_open[1] = false;
  stuck.receive(closed);
  for (int k = 0; k < 20; ++k) stuck.advance();
  EXPECT_EQ(stuck.thruster_thrust()(4), 0.0);
}

TEST(PlantValveDriver, WithoutTimeoutTheLastCommandIsHeldForever) {
  PlantParams p = quiet();
  Plant held(p), fresh(p);
  held.receive(fire(5, 80.0));
  for (int k = 0; k < 100; ++k) {
    held.advance();
    fresh.advance(fire(5, 80.0));
  }
  EXPECT_FALSE(held.command_timed_out());
  EXPECT_EQ(held.omega(), fresh.omega());
  EXPECT_EQ(held.fuel_kg(), fresh.fuel_kg());
}

TEST(PlantFaults, InjectedAtRunTimeReplacesAndClears) {
  PlantParams p = quiet();
  Plant plant(p);
  EXPECT_EQ(plant.inject({16, FaultKind::kStuckOn, 0.0, 1.0}), "thruster must be in [0, 15]");
  EXPECT_FALSE(plant.inject({2, FaultKind::kDegraded, 0.0, 1.5}).empty());
  EXPECT_FALSE(plant.inject({2, FaultKind::kNone, 0.0, 1.0}).empty());
  EXPECT_EQ(plant.inject({2, FaultKind::kStuckOff, 0.0, 1.0}), "");
  EXPECT_EQ(plant.inject({2, FaultKind::kDegraded, 0.3, 0.5}), "");  // replaces the stuck-off
  ASSERT_EQ(plant.faults().size(), 1u);
  plant.advance(fire(2, 100.0));  // t = 0: before the onset
  EXPECT_EQ(plant.thruster_thrust()(2), 100.0);
  plant.advance(fire(2, 100.0));
  plant.advance(fire(2, 100.0));
  plant.advance(fire(2, 100.0));  // period starting at 0.3 s
  EXPECT_NEAR(plant.thruster_thrust()(2), 50.0, 1e-12);
  plant.clear_fault(2);
  plant.advance(fire(2, 100.0));
  EXPECT_EQ(plant.thruster_thrust()(2), 100.0);
  EXPECT_TRUE(plant.faults().empty());
}

TEST(PlantFaults, BadFaultsAreRejectedNamingTheEntry) {
  auto rejects = [](PlantParams p, const std::string& field, const std::string& reason) {
    try {
      Plant plant(p);
      ADD_FAILURE() << "accepted " << field;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(reason), std::string::npos) << e.what();
    }
  };
  PlantParams p = quiet();
  p.faults = {{0, FaultKind::kStuckOn, 0.0, 1.0}, {-1, FaultKind::kStuckOn, 0.0, 1.0}};
  rejects(p, "faults[1]", "[0, 15]");
  p.faults = {{3, FaultKind::kDegraded, 0.0, 0.0}};
  rejects(p, "faults[0]", "(0, 1)");
  p.faults = {{3, FaultKind::kStuckOff, -1.0, 1.0}};
  rejects(p, "faults[0]", "onset_s");
  p.faults = {{3, FaultKind::kStuckOff, 0.0, 1.0}, {3, FaultKind::kStuckOn, 5.0, 1.0}};
  rejects(p, "faults[1]", "two faults");
  p = quiet();
  p.command_timeout_s = -0.1;
  rejects(p, "command_timeout_s", ">= 0");
}

TEST(PlantFaults, NamesRoundTrip) {
  for (const FaultKind k : {FaultKind::kStuckOff, FaultKind::kStuckOn, FaultKind::kDegraded}) {
    FaultKind back = FaultKind::kNone;
    ASSERT_TRUE(parse_fault_kind(to_string(k), back));
    EXPECT_EQ(back, k);
  }
  FaultKind x = FaultKind::kNone;
  EXPECT_FALSE(parse_fault_kind("none", x));
  EXPECT_FALSE(parse_fault_kind("stuck", x));
  EXPECT_EQ(describe(std::vector<ThrusterFault>{}), "none");
  EXPECT_EQ(describe(ThrusterFault{3, FaultKind::kStuckOn, 60.0, 1.0}), "thruster 3 stuck_on at 60 s");
  EXPECT_EQ(describe(ThrusterFault{5, FaultKind::kDegraded, 100.0, 0.5}),
            "thruster 5 degraded x0.5 at 100 s");
}

}  // namespace
}  // namespace rocksteady::plant
