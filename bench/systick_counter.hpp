// bench/systick_counter.hpp: instructions counted with SysTick under QEMU
// -icount shift=0 (toolchain/qemu-run), for the target benchmarks.
//
// SysTick runs from the core clock (25 MHz) without interrupt; with icount
// every instruction is 1 ns of virtual time, so a SysTick count is 40
// instructions. The ratio is measured, not assumed: a loop of known length
// (2 instructions per iteration) calibrates it.
#pragma once

#include <cstdint>

#include "board.hpp"

namespace ascorr::bench {

// SysTick counts elapsed while `body` runs (< 2^24).
template <typename F>
std::uint32_t counts(F&& body) {
    namespace board = ascorr::app::board;
    board::systick_start(board::kSysTickMax + 1U, false);
    const std::uint32_t start = board::systick_value();
    body();
    const std::uint32_t end = board::systick_value();
    return (start - end) & board::kSysTickMax;
}

// Instructions per SysTick count, from a loop of 2 instructions per iteration.
inline std::uint32_t instructions_per_count() {
    constexpr std::uint32_t kIterations = 1U << 20;
    const std::uint32_t c = counts([] {
        std::uint32_t n = kIterations;
        __asm__ volatile("1: subs %0, %0, #1\n bne 1b" : "+r"(n) : : "cc");
    });
    return (2U * kIterations + c / 2U) / c;
}

}  // namespace ascorr::bench
