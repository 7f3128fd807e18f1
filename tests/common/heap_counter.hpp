// Test instrument: counts heap allocations (global operator new, and on glibc without sanitizers
// malloc/calloc/realloc) while armed. Linking rocksteady_test_heap_counter replaces the global
// allocation functions of the test executable.
#pragma once

namespace rocksteady::test {

long heap_allocations();  // since the last arm

// Counts while alive.
class HeapArmed {
 public:
  HeapArmed();
  ~HeapArmed();
  HeapArmed(const HeapArmed&) = delete;
  HeapArmed& operator=(const HeapArmed&) = delete;
};

}  // namespace rocksteady::test
