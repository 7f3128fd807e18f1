// Unit constants shared by the flight core, the flight software and the ground tools.
#pragma once

#include <cstdint>

namespace rocksteady::gnc {

// Nanoseconds per second: the one conversion between the executive's integer time base (ns) and
// seconds.
inline constexpr std::int64_t kNsPerS = 1'000'000'000;

}  // namespace rocksteady::gnc
