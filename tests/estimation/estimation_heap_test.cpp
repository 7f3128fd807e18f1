// Zero heap per update: the MEKF and the identifier (every phase of its window cycle, both
// modes) allocate nothing once configured. This executable compiles the gnc sources with
// EIGEN_RUNTIME_NO_MALLOC and assertions on, and counts global operator new / malloc.
#include <gtest/gtest.h>

#include "heap_counter.hpp"
#include "eigen_no_malloc.hpp"

#include "gnc/estimation/identifier.hpp"
#include "gnc/estimation/mekf.hpp"
#include "gnc/math/rotation.hpp"
#include "gnc/model/mass_properties.hpp"

namespace rocksteady::gnc {
namespace {

struct Armed {
  Armed() { rocksteady::test::eigen_malloc_allowed(false); }
  ~Armed() { rocksteady::test::eigen_malloc_allowed(true); }
  rocksteady::test::HeapArmed heap;
};

TEST(EstimationHeap, MekfUpdatesAllocateNothing) {
  Mekf f;
  MekfConfig c;
  c.rate_cutoff = 0.0628;  // with the rate stage (M8)
  f.configure(c);
  f.set_rate_model(Vec3(3.0e7, 3.5e7, 4.0e7).asDiagonal());
  MekfInput in;
  in.gyro_valid = in.star_valid = true;
  in.gyro_rate = Vec3(1e-3, -2e-3, 3e-3);
  long counted = -1;
  {
    Armed armed;
    for (int k = 0; k < 500; ++k) {
      in.t = 0.1 * k;
      in.star_quat = mrp::to_quaternion(Vec3(0.05, 0.04, 0.03 + 1e-5 * k));
      if (k == 250) in.star_quat = mrp::to_quaternion(Vec3(0.3, 0.0, 0.0));  // gated
      f.update(in);
    }
    counted = rocksteady::test::heap_allocations();
  }
  EXPECT_EQ(counted, 0);
  EXPECT_GT(f.counters().updates, 400u);
}

TEST(EstimationHeap, IdentifierUpdatesAllocateNothingInEveryPhase) {
  for (IdentifierMode mode : {IdentifierMode::kJoint, IdentifierMode::kConcurrent}) {
    IdentifierConfig c;
    c.mode = mode;
    c.rcs = study_rcs_layout(200.0);
    c.j0 = total_inertia(study_true_mass_properties());
    c.window_s = 2.0;
    Identifier id;
    id.configure(c);
    IdentifierInput in;
    in.omega_valid = true;
    long counted = -1;
    {
      Armed armed;
      for (int k = 0; k < 400; ++k) {
        in.omega = Vec3(0.01, 0.02, 0.03) + 1e-5 * k * Vec3(1, -1, 0.5);
        for (int ch = 0; ch < kChannels; ++ch) in.force(ch) = 150.0 * std::sin(0.1 * k + ch);
        if (k == 100) id.reinflate_thruster(3);
        if (k == 200) id.reinflate_all();
        id.update(in);
      }
      counted = rocksteady::test::heap_allocations();
    }
    EXPECT_EQ(counted, 0);
    EXPECT_GT(id.counters().windows, 15u);
  }
}

// The flight's settings (I17-I21): the rate bias carried (considered and estimated), the
// second-order term, the innovation gate (forced to refuse and re-inflate by a tiny threshold), and
// the bias corrections from upstream.
TEST(EstimationHeap, IdentifierWithBiasGateSecondOrderTermAndFaultTorqueAllocatesNothing) {
  for (bool estimated : {false, true}) {
    for (double gate : {16.27, 1e-9}) {
      IdentifierConfig c;
      c.rcs = study_rcs_layout(200.0);
      c.j0 = total_inertia(study_true_mass_properties());
      c.window_s = 2.0;
      c.gyro_sigma = 1e-5;
      c.gyro_bias_sigma = 3e-5;
      c.gyro_bias_estimated = estimated;
      c.second_order_noise = true;
      c.gate_chi2 = gate;
      c.fault_torque_sigma = 2000.0;  // (I22)-(I23): the fault torque and its per-window scores
      c.min_inertia_information = 1.0;  // (I26) the information gate
      c.min_offset_information = 1.0;
      Identifier id;
      id.configure(c);
      IdentifierInput in;
      in.omega_valid = true;
      long counted = -1;
      {
        Armed armed;
        for (int k = 0; k < 400; ++k) {
          in.omega = Vec3(0.01, 0.02, 0.03) + 1e-5 * k * Vec3(1, -1, 0.5);
          for (int ch = 0; ch < kChannels; ++ch) in.force(ch) = 150.0 * std::sin(0.1 * k + ch);
          if (k % 20 == 1) {
            id.shift_rate_bias(Vec3(1e-7, 0.0, -1e-7));
            id.consider_rate_bias(Vec3(2e-6, 2e-6, 2e-6));
          }
          id.update(in);
        }
        counted = rocksteady::test::heap_allocations();
      }
      EXPECT_EQ(counted, 0);
      EXPECT_GT(id.counters().windows, 15u);
      EXPECT_GT(id.fault_torque().scored, 10u);
      if (gate < 1.0) {
        EXPECT_GT(id.counters().gate_reinflations, 0u);
      }
    }
  }
}

}  // namespace
}  // namespace rocksteady::gnc
