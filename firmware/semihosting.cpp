#include "semihosting.hpp"

#include <cmath>

namespace rocksteady::firmware {
namespace {

// Semihosting call on M-profile: BKPT 0xAB, operation in r0, parameter in r1, result in r0.
std::uintptr_t semihost(std::uintptr_t op, const void* arg) {
  register std::uintptr_t r0 __asm__("r0") = op;
  register const void* r1 __asm__("r1") = arg;
  __asm__ volatile("bkpt 0xAB" : "+r"(r0) : "r"(r1) : "memory");
  return r0;
}

constexpr std::uintptr_t kSysWrite0 = 0x04;
constexpr std::uintptr_t kSysGetCmdline = 0x15;
constexpr std::uintptr_t kSysExitExtended = 0x20;
constexpr std::uintptr_t kAdpStoppedApplicationExit = 0x20026;

}  // namespace

void host_write(const char* s) { semihost(kSysWrite0, s); }

void host_exit(int code) {
  const std::uintptr_t block[2] = {kAdpStoppedApplicationExit, static_cast<std::uintptr_t>(code)};
  semihost(kSysExitExtended, block);
  for (;;) {
    __asm__ volatile("bkpt 0");
  }
}

bool host_cmdline(char* buf, std::size_t size) {
  struct {
    char* buf;
    std::size_t size;
  } block{buf, size};
  if (size == 0) return false;
  buf[0] = '\0';
  return semihost(kSysGetCmdline, &block) == 0;
}

void Line::put(char c) {
  if (len_ < kCapacity) buf_[len_++] = c;
}

Line& Line::str(const char* s) {
  while (*s != '\0') put(*s++);
  return *this;
}

Line& Line::u32(std::uint32_t v) {
  char tmp[11];
  int n = 0;
  do {
    tmp[n++] = static_cast<char>('0' + v % 10U);
    v /= 10U;
  } while (v != 0U);
  while (n > 0) put(tmp[--n]);
  return *this;
}

Line& Line::i32(std::int32_t v) {
  if (v < 0) {
    put('-');
    return u32(static_cast<std::uint32_t>(-(static_cast<std::int64_t>(v))));
  }
  return u32(static_cast<std::uint32_t>(v));
}

Line& Line::sci(double v, int digits) {
  if (std::isnan(v)) return str("nan");
  if (v < 0.0) {
    put('-');
    v = -v;
  }
  if (std::isinf(v)) return str("inf");
  if (digits < 1) digits = 1;
  if (digits > 15) digits = 15;
  int exp10 = 0;
  if (v != 0.0) {
    exp10 = static_cast<int>(std::floor(std::log10(v)));
    v /= std::pow(10.0, exp10);
  }
  // Round the mantissa to `digits` significant digits; carry into the exponent when it reaches 10.
  const double scale = std::pow(10.0, digits - 1);
  auto mant = static_cast<std::uint64_t>(std::llround(v * scale));
  if (mant >= static_cast<std::uint64_t>(10.0 * scale)) {
    mant /= 10U;
    ++exp10;
  }
  char tmp[16];
  for (int i = digits - 1; i >= 0; --i) {
    tmp[i] = static_cast<char>('0' + mant % 10U);
    mant /= 10U;
  }
  put(tmp[0]);
  if (digits > 1) {
    put('.');
    for (int i = 1; i < digits; ++i) put(tmp[i]);
  }
  put('e');
  put(exp10 < 0 ? '-' : '+');
  const int e = exp10 < 0 ? -exp10 : exp10;
  if (e < 10) put('0');
  return u32(static_cast<std::uint32_t>(e));
}

Line& Line::fix(double v, int decimals) {
  if (std::isnan(v)) return str("nan");
  if (v < 0.0) {
    put('-');
    v = -v;
  }
  if (std::isinf(v) || v >= 1e15) return str("inf");
  if (decimals < 0) decimals = 0;
  if (decimals > 9) decimals = 9;
  const double scale = std::pow(10.0, decimals);
  auto whole_scaled = static_cast<std::uint64_t>(std::llround(v * scale));
  const auto s = static_cast<std::uint64_t>(scale);
  const std::uint64_t whole = whole_scaled / s;
  std::uint64_t frac = whole_scaled % s;
  char tmp[21];
  int n = 0;
  std::uint64_t w = whole;
  do {
    tmp[n++] = static_cast<char>('0' + w % 10U);
    w /= 10U;
  } while (w != 0U);
  while (n > 0) put(tmp[--n]);
  if (decimals > 0) {
    put('.');
    for (int i = decimals - 1; i >= 0; --i) {
      tmp[i] = static_cast<char>('0' + frac % 10U);
      frac /= 10U;
    }
    for (int i = 0; i < decimals; ++i) put(tmp[i]);
  }
  return *this;
}

void Line::flush() {
  buf_[len_] = '\n';
  buf_[len_ + 1] = '\0';
  host_write(buf_);
  len_ = 0;
}

}  // namespace rocksteady::firmware
