// ARM semihosting (the debugger/emulator console) for the bare-metal image, and a small allocation-
// free text formatter, so the image needs neither stdio nor a heap.
#pragma once

#include <cstddef>
#include <cstdint>

namespace rocksteady::firmware {

// SYS_WRITE0: writes a NUL-terminated string to the host console.
void host_write(const char* s);
// SYS_EXIT_EXTENDED with ADP_Stopped_ApplicationExit: the emulator exits with `code`.
[[noreturn]] void host_exit(int code);
// SYS_GET_CMDLINE: the command line given to the emulator (QEMU: -semihosting-config arg=...).
// Returns false when the host provides none.
bool host_cmdline(char* buf, std::size_t size);

// Fixed-capacity line buffer with number formatting; output is truncated, never overflows.
class Line {
 public:
  Line& str(const char* s);
  Line& u32(std::uint32_t v);
  Line& i32(std::int32_t v);
  // Scientific notation with `digits` significant digits (1..15), e.g. 3.7417e-02.
  Line& sci(double v, int digits = 5);
  // Fixed point with `decimals` decimals (|v| < 1e15).
  Line& fix(double v, int decimals = 1);
  // Writes the line (with a newline) to the host console and clears it.
  void flush();

 private:
  void put(char c);
  static constexpr std::size_t kCapacity = 160;
  char buf_[kCapacity + 2]{};
  std::size_t len_{0};
};

}  // namespace rocksteady::firmware
