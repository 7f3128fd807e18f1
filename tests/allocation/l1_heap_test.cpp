// Zero heap use in the fuel-optimal allocator: global operator new (and, on glibc without
// sanitizers, malloc/calloc/realloc) are counted while armed, around many allocate() calls of both
// kinds, saturated and not, and a full Gnc tick with the L1 allocator.
#include <gtest/gtest.h>

#include "heap_counter.hpp"

#include <cstdlib>
#include <random>

#include "gnc/allocation/allocator.hpp"
#include "gnc/gnc.hpp"
#include "gnc/model/mass_properties.hpp"
#include "gnc/model/rcs.hpp"


namespace rocksteady::gnc {
namespace {

using Armed = rocksteady::test::HeapArmed;

TEST(L1ZeroAllocation, CountingHookSeesAnAllocation) {
  long counted = 0;
  {
    Armed armed;
    int* volatile p = new int(3);
    counted = rocksteady::test::heap_allocations();
    delete p;
  }
  EXPECT_GE(counted, 1);
}

TEST(L1ZeroAllocation, AllocateNeverTouchesTheHeap) {
  const Mat38 b = torque_matrix(study_rcs_layout(200.0), study_true_mass_properties().r_so_bcm);
  Allocator l1, pinv;
  ASSERT_TRUE(l1.configure(b, 200.0, AllocatorKind::kL1));
  ASSERT_TRUE(pinv.configure(b, 200.0));
  // Requests drawn before arming (the generator itself is heap-free, but keep the armed region
  // to the calls under test).
  std::mt19937 rng(3);
  std::normal_distribution<double> n(0.0, 1.0);
  Vec3 requests[500];
  for (Vec3& r : requests) r = Vec3(n(rng), n(rng), n(rng)) * 3000.0;  // many saturate
  requests[0].setZero();
  Vec8 u;
  AllocatorStatus st;
  double sink = 0.0;
  int saturated = 0;
  long counted = 0;
  {
    Armed armed;
    for (const Vec3& r : requests) {
      l1.allocate(r, u, st);
      sink += u.sum();
      saturated += st.saturated ? 1 : 0;
      pinv.allocate(r, u, st);
      sink += u.sum();
    }
    counted = rocksteady::test::heap_allocations();
  }
  EXPECT_EQ(counted, 0);
  EXPECT_GT(saturated, 50);  // both paths of the rescale were exercised
  EXPECT_TRUE(std::isfinite(sink));
}

TEST(L1ZeroAllocation, GncTickWithL1AllocatorNeverTouchesTheHeap) {
  GncParams p = study_gnc_params(200.0);
  p.allocator = AllocatorKind::kL1;
  Gnc g;
  ASSERT_TRUE(g.init(p).ok);
  GncCommands cmd;
  cmd.has_mode_request = true;
  cmd.mode_request = Mode::kDetumble;
  GncOutput out;
  long counted = 0;
  int enabled = 0;
  {
    Armed armed;
    for (int k = 0; k < 300; ++k) {
      SensorSample s;
      s.t = 0.1 * k;
      s.gyro_rate = Vec3(0.02, -0.01 * k / 300.0, 0.03);
      s.gyro_valid = true;
      s.star_valid = true;
      g.step(s, cmd, out);
      cmd = GncCommands{};
      enabled += out.command.enabled ? 1 : 0;
    }
    counted = rocksteady::test::heap_allocations();
  }
  EXPECT_EQ(counted, 0);
  EXPECT_EQ(enabled, 300);
}

}  // namespace
}  // namespace rocksteady::gnc
