// firmware/app/board.hpp: the few Cortex-M system registers the application
// uses (ARMv7-M Architecture Reference Manual, B3.3 SysTick).
//
// Conventions: the MPS2 boards (AN385 Cortex-M3, AN386 Cortex-M4F, and the DPU
// alike) clock SysTick from the core clock, kCoreClockHz. Under QEMU with
// -icount shift=0 one instruction takes 1 ns of virtual time, so one SysTick
// count is 1e9/kCoreClockHz = 40 instructions (toolchain/qemu-run).
// SysTick counts down from LOAD to 0, then reloads and raises its exception.
#pragma once

#include <cstdint>

namespace ascorr::app::board {

inline constexpr std::uint32_t kCoreClockHz = 25000000U;

struct SysTickRegisters {
    volatile std::uint32_t ctrl;   // 0xE000E010: bit 0 enable, 1 interrupt, 2 core clock
    volatile std::uint32_t load;   // 0xE000E014: reload value, 24 bits
    volatile std::uint32_t val;    // 0xE000E018: current value (write clears)
    volatile std::uint32_t calib;  // 0xE000E01C
};

inline SysTickRegisters& systick() noexcept {
    return *reinterpret_cast<SysTickRegisters*>(std::uintptr_t{0xE000E010U});  // NOLINT: memory-mapped register
}

inline constexpr std::uint32_t kSysTickMax = 0x00FFFFFFU;

// Starts SysTick with a period of `period` core clocks (1 ≤ period ≤ 2²⁴),
// with (interrupt = true) or without its exception.
inline void systick_start(std::uint32_t period, bool interrupt) noexcept {
    SysTickRegisters& st = systick();
    st.ctrl = 0U;
    st.load = (period - 1U) & kSysTickMax;
    st.val = 0U;
    st.ctrl = interrupt ? 7U : 5U;
}

inline std::uint32_t systick_value() noexcept {
    return systick().val;
}

inline void wait_for_interrupt() noexcept {
    __asm__ volatile("wfi" ::: "memory");
}

// PRIMASK: with interrupts masked an interrupt still wakes WFI (it stays
// pending) but its handler runs only after unmask_interrupts().
inline void mask_interrupts() noexcept {
    __asm__ volatile("cpsid i" ::: "memory");
}
inline void unmask_interrupts() noexcept {
    __asm__ volatile("cpsie i" ::: "memory");
}

// Sleeps until `counter` (advanced by an interrupt handler) differs from
// `seen`, without the lost-wake-up race of check-then-sleep: the check and the
// WFI run with interrupts masked, so a tick between them is pending and wakes
// the WFI at once; the handler then runs when interrupts are unmasked.
inline void sleep_until_changed(const volatile std::uint32_t& counter, std::uint32_t seen) noexcept {
    for (;;) {  // one pass per interrupt taken while waiting
        mask_interrupts();
        if (counter != seen) {
            unmask_interrupts();
            return;
        }
        wait_for_interrupt();
        unmask_interrupts();
    }
}

}  // namespace ascorr::app::board
