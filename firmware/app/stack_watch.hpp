// firmware/app/stack_watch.hpp: the image's stack high-water mark, by
// painting. The compiler bounds each out-of-line entry's frames
// (-Wstack-usage, firmware/app/CMakeLists.txt) but not their sum along the
// loop's call paths; this measures the sum on the paths a run takes.
//
// Conventions: picolibc's linker script (picolibcpp.ld) puts the stack at the
// top of RAM, [__heap_end, __stack): __stack_size bytes (the toolchain's
// one definition, toolchain/ascorr-picolibc.ld), and below it the heap's
// room, unused (nothing allocates). paint() (at boot, before the static
// constructors) fills with kPaint the stack
// below its caller's frame and a guard of one more stack size below the
// stack (within the heap's room); high_water() finds the lowest word no
// longer kPaint and returns the bytes from it to the top: the deepest the
// stack reached since paint(). An overflow into the guard is measured, not
// silent (up to twice the stack size; deeper reads as twice). A word the
// program wrote with kPaint's own value at the very edge would be missed:
// one chance in 2^32. Exceptions taken meanwhile (SysTick) push onto this
// stack and are included. Both loops are bounded by the guard's and stack's
// words (linker constants): 2 × 8 KiB / 4 = 4096 iterations.
#pragma once

#include <cstdint>

// picolibc's linker script symbols (their addresses are the values).
extern "C" {
extern std::uint32_t __heap_start[];  // NOLINT: picolibc's linker symbol
extern std::uint32_t __heap_end[];    // NOLINT: picolibc's linker symbol
extern std::uint32_t __stack[];       // NOLINT: picolibc's linker symbol
}

namespace ascorr::app::stack_watch {

inline constexpr std::uint32_t kPaint = 0xA5C3F00DU;

inline std::uintptr_t address(const std::uint32_t* p) noexcept {
    return reinterpret_cast<std::uintptr_t>(p);  // NOLINT: linker symbols are addresses
}
inline volatile std::uint32_t& word(std::uintptr_t a) noexcept {
    return *reinterpret_cast<volatile std::uint32_t*>(a);  // NOLINT: painting RAM by address
}

// The stack's size in bytes (the linker's __stack_size).
inline std::uint32_t size() noexcept {
    return static_cast<std::uint32_t>(address(__stack) - address(__heap_end));
}

// The lowest painted address: one stack size below the stack, not below the
// heap's start (word-aligned).
inline std::uintptr_t guard_bottom() noexcept {
    const std::uintptr_t bottom = address(__heap_end) - size();
    const std::uintptr_t heap = (address(__heap_start) + 3U) & ~std::uintptr_t{3U};
    return bottom > heap ? bottom : heap;
}

// Paints the guard and the stack below the caller's frame. noinline: the
// words below this function's own stack pointer are all free. An image runs
// it from .preinit_array, which crt0 calls before .init_array (the static
// constructors, whose frames are then measured too: FlightCycle's, some
// 900 B).
__attribute__((noinline)) inline void paint() noexcept {
    std::uintptr_t sp = 0U;
    __asm__ volatile("mov %0, sp" : "=r"(sp));
    for (std::uintptr_t a = guard_bottom(); a + 4U <= sp; a += 4U) {
        word(a) = kPaint;
    }
}

// The bytes from the lowest word written since paint() to the stack's top.
inline std::uint32_t high_water() noexcept {
    const std::uintptr_t top = address(__stack);
    std::uintptr_t a = guard_bottom();
    while (a < top && word(a) == kPaint) {  // at most the guard's and stack's words
        a += 4U;
    }
    return static_cast<std::uint32_t>(top - a);
}

}  // namespace ascorr::app::stack_watch
