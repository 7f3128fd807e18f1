// Physically justified ranges of every flight parameter: one table (param_bounds.cpp, the reason
// next to each row), used by gnc::validate (so by the flight's parameter loads and start-up), by the
// YAML loader (config/) and by the ground tools. A value outside its row is refused with the row's
// name and reason, never clamped.
//
// Gain matrices are bounded by what they do to the body, not by their raw entries: the decay rate
// lambda_min(K) / lambda_max(J_tot) of the sliding variable must be fast enough to despin within a
// mission, and lambda_max(K) / lambda_min(J_tot) no faster than the GNC loop can realise (1/dt).
// Bandwidth-like matrices (Lambda) are bounded by their eigenvalues.
//
// Flight core: no heap, no exceptions, no I/O.
#pragma once

#include "gnc/check.hpp"

namespace rocksteady::gnc {

struct GncParams;

enum class BoundKind : unsigned char {
  kScalar,    // the value itself
  kEigen,     // every eigenvalue of the (symmetric) matrix in [lo, hi]
  kBandwidth, // every eigenvalue in [lo, hi/dt] (hi = pi: the GNC loop's Nyquist rate)
  kGainRate,  // lambda_min(K)/lambda_max(J_tot) >= lo and lambda_max(K)/lambda_min(J_tot) <= hi/dt
};

struct ParamBound {
  const char* name;  // as gnc::validate and the parameter table name it
  BoundKind kind;
  double lo;
  double hi;          // kGainRate: hi is a multiple of 1/dt
  const char* units;
  const char* why;    // the physical justification
};

// The table (static storage) and its length.
const ParamBound* param_bounds(int& count);
// The row of `name`, or nullptr.
const ParamBound* find_param_bound(const char* name);
// Is a scalar value inside the row `name`? (true when there is no scalar row of that name)
bool within_bound(const char* name, double value);

// The first parameter outside its physical range: {false, name, reason}, else ok.
Check check_bounds(const GncParams& p);

}  // namespace rocksteady::gnc
