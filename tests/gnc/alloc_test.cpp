// Zero heap allocations per tick: global operator new and malloc are counted once armed (after
// initialisation), across every law x mode combination; Eigen's own EIGEN_RUNTIME_NO_MALLOC check
// is on as well (this executable compiles the gnc sources with it and with assertions enabled).
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>

#include "gnc/gnc.hpp"
#include "gnc_harness.hpp"

namespace {
std::atomic<bool> g_armed{false};
std::atomic<long> g_allocations{0};
void note_allocation() {
  if (g_armed.load(std::memory_order_relaxed)) g_allocations.fetch_add(1);
}
}  // namespace

void* operator new(std::size_t n) {
  note_allocation();
  if (void* p = std::malloc(n == 0 ? 1 : n)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t n) { return operator new(n); }
void* operator new(std::size_t n, const std::nothrow_t&) noexcept {
  note_allocation();
  return std::malloc(n == 0 ? 1 : n);
}
void* operator new[](std::size_t n, const std::nothrow_t& t) noexcept { return operator new(n, t); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }

#if !defined(ROCKSTEADY_SANITIZE) && defined(__GLIBC__)
// Also catch C allocations (glibc lets a program interpose malloc and reach the real one).
extern "C" void* __libc_malloc(std::size_t);
extern "C" void* __libc_calloc(std::size_t, std::size_t);
extern "C" void* __libc_realloc(void*, std::size_t);
extern "C" void* malloc(std::size_t n) {
  note_allocation();
  return __libc_malloc(n);
}
extern "C" void* calloc(std::size_t n, std::size_t m) {
  note_allocation();
  return __libc_calloc(n, m);
}
extern "C" void* realloc(void* p, std::size_t n) {
  note_allocation();
  return __libc_realloc(p, n);
}
#endif

namespace rocksteady::gnc {
namespace {

struct Armed {
  Armed() {
    g_allocations = 0;
    Eigen::internal::set_is_malloc_allowed(false);
    g_armed = true;
  }
  ~Armed() {
    g_armed = false;
    Eigen::internal::set_is_malloc_allowed(true);
  }
};

TEST(ZeroAllocation, CountingHookSeesAnAllocation) {
  // The hook itself works: an allocation while armed is counted.
  long counted = 0;
  {
    Armed armed;
    Eigen::internal::set_is_malloc_allowed(true);
    int* volatile p = new int(3);
    counted = g_allocations.load();
    delete p;
  }
  EXPECT_GE(counted, 1);
}

TEST(ZeroAllocation, NoHeapInAnyTickOfAnyLawAndMode) {
  const LawId laws[] = {LawId::kNtcl,     LawId::kNtclEl, LawId::kIntegral,   LawId::kAdaptive,
                        LawId::kSo3,      LawId::kDpd,    LawId::kFeedforward};
  for (EstimatorKind est : {EstimatorKind::kPassThrough, EstimatorKind::kFilter}) {
    for (LawId law : laws) {
      GncParams p = test::small_vehicle_params();
      p.law = law;
      p.estimator.kind = est;
      auto* loop = new test::SmallLoop(p);  // initialisation may allocate
      ASSERT_TRUE(loop->gnc.init(p).ok);
      TrajectoryTable* tab = new TrajectoryTable();
      test::linear_despin_table(Vec3(0.3, -0.2, 0.25), 30.0, *tab);
      ASSERT_EQ(loop->gnc.load_trajectory(*tab), TrajectoryError::kOk);
      long ticks = 0;
      {
        Armed armed;
        GncCommands c;
        c.has_mode_request = true;
        const Mode sequence[] = {Mode::kDetumble, Mode::kHold, Mode::kTrack, Mode::kIdle,
                                 Mode::kSafe, Mode::kDetumble};
        for (Mode m : sequence) {
          c.mode_request = m;
          loop->tick(c);
          for (int i = 0; i < 400; ++i) loop->tick();
          ticks += 401;
        }
        // Faulty input too: lost sensors into SAFE.
        SensorSample s = loop->sample();
        s.gyro_valid = s.star_valid = false;
        for (int i = 0; i < 30; ++i) {
          s.t += p.dt;
          loop->gnc.step(s, {}, loop->out);
          ++ticks;
        }
      }
      EXPECT_EQ(g_allocations.load(), 0) << to_string(law) << " over " << ticks << " ticks";
      EXPECT_EQ(loop->gnc.mode(), Mode::kSafe);
      delete tab;
      delete loop;
    }
  }
}

}  // namespace
}  // namespace rocksteady::gnc
