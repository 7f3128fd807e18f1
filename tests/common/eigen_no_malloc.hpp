// Eigen's own allocation check for the zero-heap tests. The native build compiles the gnc sources
// for them with EIGEN_RUNTIME_NO_MALLOC (rocksteady_test_gnc_no_malloc), so Eigen asserts on any
// allocation of its own; the cross builds link the ordinary library, and the heap counter
// (heap_counter.hpp) is the proof there.
#pragma once

#include <Eigen/Core>

namespace rocksteady::test {

inline void eigen_malloc_allowed(bool allowed) {
#ifdef EIGEN_RUNTIME_NO_MALLOC
  Eigen::internal::set_is_malloc_allowed(allowed);
#else
  (void)allowed;
#endif
}

}  // namespace rocksteady::test
