// The image has no heap. The flight core never allocates at run time, but Eigen's generic blocked
// kernels (e.g. a triangular solve with a matrix right-hand side) keep a heap fall-back for
// workspaces above EIGEN_STACK_ALLOCATION_LIMIT, so malloc/free are referenced. These definitions
// replace newlib's allocator: any call is a fatal error reported over semihosting (exit code 5),
// never a silent allocation.
#include <cstddef>

#include "semihosting.hpp"

extern "C" {

void* malloc(std::size_t /*size*/) {
  rocksteady::firmware::host_write("firmware: FATAL heap allocation (malloc) on a no-heap target\n");
  rocksteady::firmware::host_exit(5);
}

void free(void* ptr) {
  if (ptr == nullptr) return;
  rocksteady::firmware::host_write("firmware: FATAL free() on a no-heap target\n");
  rocksteady::firmware::host_exit(5);
}

void* calloc(std::size_t /*n*/, std::size_t /*size*/) {
  rocksteady::firmware::host_write("firmware: FATAL heap allocation (calloc) on a no-heap target\n");
  rocksteady::firmware::host_exit(5);
}

void* realloc(void* /*ptr*/, std::size_t /*size*/) {
  rocksteady::firmware::host_write("firmware: FATAL heap allocation (realloc) on a no-heap target\n");
  rocksteady::firmware::host_exit(5);
}

}  // extern "C"
