// tests/alloc_counter.hpp: counts heap allocations while armed.
//
// alloc_counter.cpp replaces the global operator new/delete (a malloc/free
// pair) and wraps malloc, calloc and realloc at link time; a test program that
// links it (tests/CMakeLists.txt: ascorr_count_allocations) can prove a piece
// of code never allocates: arm, run, disarm, read the count.
#pragma once

namespace ascorr::test {

void arm_allocation_counter() noexcept;     // resets the count and starts counting
long disarm_allocation_counter() noexcept;  // stops counting, returns the count

}  // namespace ascorr::test
