// Cortex-M7 core peripherals the image uses: FPU enable, SysTick as a free-running counter, stack
// painting for the high-water mark.
#pragma once

#include <cstdint>

namespace rocksteady::firmware::board {

void enable_fpu();

// SysTick as a 24-bit down-counter on the processor clock, interrupt off. Under QEMU with -icount
// its counts are proportional to executed instructions (see calibrate_counts_per_kinsn()).
void counter_start();
std::uint32_t counter_now();
// Elapsed counts from `earlier` to `later` (handles one 24-bit wrap).
std::uint32_t counter_elapsed(std::uint32_t earlier, std::uint32_t later);
// Counts taken by a loop of exactly 2 * `iterations` Thumb instructions (subs + bne), used to
// convert counter readings to instructions.
std::uint32_t counter_for_known_loop(std::uint32_t iterations);

// Stack painting. The stack region is [_sstack, _estack).
inline constexpr std::uint32_t kStackPaint = 0xC0FFEE5AU;
std::uintptr_t stack_bottom();
std::uintptr_t stack_top();
// Paints the stack from its bottom up to 64 bytes below the caller's current stack pointer.
void paint_stack_below_sp();
// Lowest stack address written since it was painted.
std::uintptr_t lowest_stack_address_used();
std::uintptr_t current_sp();

}  // namespace rocksteady::firmware::board
