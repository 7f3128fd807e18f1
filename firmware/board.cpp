#include "board.hpp"

extern "C" {
extern std::uint32_t _sstack;
extern std::uint32_t _estack;
}

namespace rocksteady::firmware::board {
namespace {

struct SysTickRegs {
  volatile std::uint32_t ctrl;
  volatile std::uint32_t load;
  volatile std::uint32_t val;
  volatile std::uint32_t calib;
};
constexpr std::uintptr_t kSysTickBase = 0xE000E010U;
constexpr std::uintptr_t kCpacr = 0xE000ED88U;
constexpr std::uint32_t kCounterMask = 0x00FFFFFFU;

SysTickRegs& systick() { return *reinterpret_cast<SysTickRegs*>(kSysTickBase); }

}  // namespace

void enable_fpu() {
  auto& cpacr = *reinterpret_cast<volatile std::uint32_t*>(kCpacr);
  cpacr = cpacr | (0xFU << 20);  // CP10, CP11: full access
  __asm__ volatile("dsb\n\tisb" ::: "memory");
}

void counter_start() {
  systick().ctrl = 0U;
  systick().load = kCounterMask;
  systick().val = 0U;
  systick().ctrl = (1U << 2) | 1U;  // CLKSOURCE = processor clock, ENABLE, no interrupt
}

std::uint32_t counter_now() { return systick().val & kCounterMask; }

std::uint32_t counter_elapsed(std::uint32_t earlier, std::uint32_t later) {
  return (earlier - later) & kCounterMask;  // down-counter
}

std::uint32_t counter_for_known_loop(std::uint32_t iterations) {
  const std::uint32_t start = counter_now();
  std::uint32_t n = iterations;
  __asm__ volatile(
      "1:\n\t"
      "subs %0, %0, #1\n\t"
      "bne 1b"
      : "+r"(n)
      :
      : "cc");
  return counter_elapsed(start, counter_now());
}

std::uintptr_t stack_bottom() { return reinterpret_cast<std::uintptr_t>(&_sstack); }
std::uintptr_t stack_top() { return reinterpret_cast<std::uintptr_t>(&_estack); }

std::uintptr_t current_sp() {
  std::uintptr_t sp = 0;
  __asm__ volatile("mov %0, sp" : "=r"(sp));
  return sp;
}

__attribute__((noinline)) void paint_stack_below_sp() {
  const std::uintptr_t limit = current_sp() - 64U;
  for (auto* p = reinterpret_cast<volatile std::uint32_t*>(stack_bottom());
       reinterpret_cast<std::uintptr_t>(p) < limit; ++p) {
    *p = kStackPaint;
  }
}

std::uintptr_t lowest_stack_address_used() {
  auto* p = reinterpret_cast<const volatile std::uint32_t*>(stack_bottom());
  const auto* top = reinterpret_cast<const volatile std::uint32_t*>(stack_top());
  while (p < top && *p == kStackPaint) ++p;
  return reinterpret_cast<std::uintptr_t>(p);
}

}  // namespace rocksteady::firmware::board
