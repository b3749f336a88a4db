#include "alloc_counter.hpp"

#include <atomic>
#include <cstdlib>
#include <new>

// Our replacement new and delete are a malloc/free pair; GCC cannot see that
// the replaced delete matches the replaced new and warns at every delete.
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"

// The real allocator behind the wrappers below (the linker's --wrap names).
extern "C" {
void* __real_malloc(std::size_t n);
void* __real_calloc(std::size_t n, std::size_t size);
void* __real_realloc(void* p, std::size_t n);
}

namespace {
std::atomic<long> g_allocations{0};
std::atomic<bool> g_armed{false};
}  // namespace

void* operator new(std::size_t n) {
    if (g_armed.load()) {
        ++g_allocations;
    }
    if (void* p = __real_malloc(n == 0 ? 1 : n)) {  // counted once, here, not again by __wrap_malloc
        return p;
    }
    throw std::bad_alloc();
}
void* operator new[](std::size_t n) {
    return operator new(n);
}
void operator delete(void* p) noexcept {
    std::free(p);
}
void operator delete[](void* p) noexcept {
    std::free(p);
}
void operator delete(void* p, std::size_t) noexcept {
    std::free(p);
}
void operator delete[](void* p, std::size_t) noexcept {
    std::free(p);
}

// malloc and its relatives, wrapped at link time (-Wl,--wrap=malloc etc.,
// ascorr_count_allocations() in tests/CMakeLists.txt): every call from the
// objects of the test program, which is where the header-only core is
// compiled, goes through these. (Calls from inside shared libraries are not
// wrapped; operator new is counted above.)
extern "C" {
void* __wrap_malloc(std::size_t n) {
    if (g_armed.load()) {
        ++g_allocations;
    }
    return __real_malloc(n);
}
void* __wrap_calloc(std::size_t n, std::size_t size) {
    if (g_armed.load()) {
        ++g_allocations;
    }
    return __real_calloc(n, size);
}
void* __wrap_realloc(void* p, std::size_t n) {
    if (g_armed.load()) {
        ++g_allocations;
    }
    return __real_realloc(p, n);
}
}

namespace ascorr::test {

void arm_allocation_counter() noexcept {
    g_allocations = 0;
    g_armed = true;
}

long disarm_allocation_counter() noexcept {
    g_armed = false;
    return g_allocations.load();
}

}  // namespace ascorr::test
