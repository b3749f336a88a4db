#include "alloc_counter.hpp"

#include <atomic>
#include <cstdlib>
#include <new>

// Our replacement new and delete are a malloc/free pair; GCC cannot see that
// the replaced delete matches the replaced new and warns at every delete.
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"

namespace {
std::atomic<long> g_allocations{0};
std::atomic<bool> g_armed{false};
}  // namespace

void* operator new(std::size_t n) {
    if (g_armed.load()) {
        ++g_allocations;
    }
    if (void* p = std::malloc(n == 0 ? 1 : n)) {
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
