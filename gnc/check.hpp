// The one result type of a validation across gnc, fsw and the configuration loaders: ok, or the
// first bad field and why. Plain data (string literals only), so flight code can return it from a
// tick-free configure() without exceptions or heap.
#pragma once

#include <cmath>

namespace rocksteady::gnc {

struct Check {
  bool ok{true};
  const char* field{""};   // the first offending field, e.g. "mode.sensor_timeout"
  const char* reason{""};  // why it was rejected
};

// The range tests every validator uses.
inline bool finite_positive(double v) { return std::isfinite(v) && v > 0.0; }
inline bool finite_non_negative(double v) { return std::isfinite(v) && v >= 0.0; }

}  // namespace rocksteady::gnc
