// Cortex-M7 startup: vector table, reset handler (FPU on, .data copied from flash, .bss zeroed, the
// stack painted for the high-water mark, static constructors), fault handlers that report over
// semihosting and exit non-zero.
#include <cstdint>

#include "board.hpp"
#include "semihosting.hpp"

extern "C" {
// Linker-script symbols (mps2_an500.ld).
extern std::uint32_t _sidata;  // .data load address (flash)
extern std::uint32_t _sdata;
extern std::uint32_t _edata;
extern std::uint32_t _sbss;
extern std::uint32_t _ebss;
extern std::uint32_t _sstack;  // lowest address of the stack region
extern std::uint32_t _estack;  // initial stack pointer (top of the stack region)
using InitFn = void (*)();
extern InitFn __preinit_array_start[];
extern InitFn __preinit_array_end[];
extern InitFn __init_array_start[];
extern InitFn __init_array_end[];

void Reset_Handler();
void Fault_Handler();
void Default_Handler();
}

int firmware_main();  // main.cpp (ISO C++ forbids calling main itself)

namespace {

using Handler = void (*)();

struct VectorTable {
  std::uint32_t* initial_sp;
  Handler handlers[15];  // Reset .. SysTick (ARMv7-M exceptions 1..15)
};

}  // namespace

// Placed at address 0 by the linker script (VTOR resets to 0 on the mps2-an500).
__attribute__((section(".isr_vector"), used)) const VectorTable g_vector_table = {
    &_estack,
    {
        Reset_Handler,    // 1 Reset
        Fault_Handler,    // 2 NMI
        Fault_Handler,    // 3 HardFault
        Fault_Handler,    // 4 MemManage
        Fault_Handler,    // 5 BusFault
        Fault_Handler,    // 6 UsageFault
        nullptr,          // 7
        nullptr,          // 8
        nullptr,          // 9
        nullptr,          // 10
        Default_Handler,  // 11 SVCall
        Default_Handler,  // 12 DebugMonitor
        nullptr,          // 13
        Default_Handler,  // 14 PendSV
        Default_Handler,  // 15 SysTick (polled, its interrupt is never enabled)
    }};

extern "C" void Reset_Handler() {
  // Full access to CP10/CP11 (the FPU) before any floating-point instruction.
  rocksteady::firmware::board::enable_fpu();

  const std::uint32_t* src = &_sidata;
  for (std::uint32_t* dst = &_sdata; dst < &_edata;) *dst++ = *src++;
  for (std::uint32_t* dst = &_sbss; dst < &_ebss;) *dst++ = 0U;

  // Paint the unused stack (below this frame) so the deepest use can be found later.
  rocksteady::firmware::board::paint_stack_below_sp();

  for (InitFn* f = __preinit_array_start; f < __preinit_array_end; ++f) (*f)();
  for (InitFn* f = __init_array_start; f < __init_array_end; ++f) (*f)();

  rocksteady::firmware::host_exit(firmware_main());
}

extern "C" void Fault_Handler() {
  rocksteady::firmware::host_write("firmware: FAULT (HardFault/MemManage/BusFault/UsageFault/NMI)\n");
  rocksteady::firmware::host_exit(3);
}

extern "C" void Default_Handler() {
  rocksteady::firmware::host_write("firmware: unexpected exception\n");
  rocksteady::firmware::host_exit(4);
}
