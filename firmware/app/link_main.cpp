// firmware/app/link_main.cpp: the DPU's link service (hardware-in-the-loop
// replay, firmware/link-protocol.md) on the CMSDK UART0 of the MPS2 boards.
//
// Conventions: at boot the UART is enabled and, after one delimiter byte,
// HELLO is announced (sequence 0), so that the host learns of every restart.
// Then each received byte goes to the LinkServer, which owns the model,
// velocity and temperatures in static storage and answers through the UART;
// between bytes the core sleeps (WFI). The core runs in the build's scalar
// (app_scalar.hpp). Each loop iteration is bounded; the image serves until
// reset. The boot id is the same at every boot (no reset counter survives a
// reset on these boards), so the host treats any unprompted HELLO as a
// restart.
//
// The cost reported with each solution is the instructions of
// correct_solution(): SysTick runs free from the core clock (no exception)
// and one count is kInstructionsPerCount instructions (40 under QEMU's
// -icount shift=0, board.hpp), refined by polling (SysTickCounter). On the
// board the same figures are core clocks with kInstructionsPerCount = 1 (and
// the poll's cost in clocks). The figure includes part of the counter reads.
// The stack is painted at boot and its high-water mark answers STACK_REPORT
// (stack_watch.hpp).
#include <cstdint>

#include "app_scalar.hpp"
#include "ascorr_link/server.hpp"
#include "board.hpp"
#include "cmsdk_uart.hpp"
#include "stack_watch.hpp"

#ifndef ASCORR_LINK_INSTRUCTIONS_PER_COUNT
#define ASCORR_LINK_INSTRUCTIONS_PER_COUNT 40
#endif

namespace ascorr::app {
namespace {

constexpr std::uint32_t kBaud = 115200U;
constexpr std::uint32_t kBootId = 0x41534331U;  // "ASC1"
constexpr std::uint32_t kInstructionsPerCount = ASCORR_LINK_INSTRUCTIONS_PER_COUNT;

// Instructions between two reads of this counter, to a few instructions.
// SysTick alone resolves one count (40 instructions), and under QEMU's
// deterministic clock that error does not average out over solutions. So each
// read polls SysTick until its next count, in a loop of kPollInstructions
// instructions per poll, and returns the instant of that count less the
// polls: the time of the read plus a constant, which cancels in a difference,
// with a resolution of one poll. SysTick is extended to 32 bits in software;
// the difference of two reads is exact while they are less than 2^24 counts
// apart, as the LinkServer's reads around one correct_solution() are.
struct SysTickCounter {
    static constexpr std::uint32_t kPollInstructions = 5U;  // ldr, cmp, bne, subs, bne
    static constexpr std::uint32_t kMaxPolls = 64U;         // > 40 / kPollInstructions: bounded if SysTick stopped
    static std::uint32_t last;                              // up-counting SysTick value at the previous read
    static std::uint32_t total;                             // counts accumulated over reads
    std::uint32_t operator()() const noexcept {
        const std::uint32_t before = board::systick_value();
        std::uint32_t now = before;
        std::uint32_t left = kMaxPolls;
        __asm__ volatile(
            "1: ldr %[now], [%[val]]\n"
            "   cmp %[now], %[before]\n"
            "   bne 2f\n"
            "   subs %[left], %[left], #1\n"
            "   bne 1b\n"
            "2:\n"
            : [now] "+&r"(now), [left] "+&r"(left)
            : [val] "r"(&board::systick().val), [before] "r"(before)
            : "cc", "memory");
        const std::uint32_t up = board::kSysTickMax - now;
        total += (up - last) & board::kSysTickMax;
        last = up;
        return total * kInstructionsPerCount - (kMaxPolls - left) * kPollInstructions;
    }
};
std::uint32_t SysTickCounter::last = 0U;
std::uint32_t SysTickCounter::total = 0U;

// The stack's mark, scanned for STACK_REPORT (stack_watch.hpp: at most 4096
// words; painted at boot by stack_watch_boot.cpp, before the static
// constructors, the server's among them).
struct PaintedStack {
    link::StackReport operator()() const noexcept { return {stack_watch::high_water(), stack_watch::size()}; }
};

using Server = link::LinkServer<Scalar, SysTickCounter, PaintedStack>;
Server g_server(kBootId, SysTickCounter{});  // static: model, velocity, temperatures and caches
std::uint32_t g_tx_dropped = 0U;             // bytes the UART could not take (inspect with a debugger)

// NVIC set-enable and clear-pending registers, lines 0–31 (ARMv7-M ARM B3.4).
volatile std::uint32_t& nvic_iser0() noexcept {
    return *reinterpret_cast<volatile std::uint32_t*>(std::uintptr_t{0xE000E100U});  // NOLINT: register
}
volatile std::uint32_t& nvic_icpr0() noexcept {
    return *reinterpret_cast<volatile std::uint32_t*>(std::uintptr_t{0xE000E280U});  // NOLINT: register
}

// Sleeps until a byte may have arrived. The RX interrupt is pending-only
// (exceptions are masked): it wakes WFI and is cleared here before the last
// look at the UART, so a byte arriving after that look still wakes the core.
// Sleeping instead of polling also leaves the host's CPU to QEMU's I/O.
void wait_for_rx() noexcept {
    uart::uart0().intstatus = uart::kIntRx;
    nvic_icpr0() = 1U << uart::kUart0RxIrq;
    if ((uart::uart0().state & uart::kStateRxFull) == 0U) {
        // SysTick holds its value while asleep: under QEMU's -icount
        // sleep=off a running timer would make the emulator skip from one
        // SysTick wrap to the next and spin the host's CPU while idle.
        board::systick().ctrl = 0U;
        board::wait_for_interrupt();
        board::systick().ctrl = 5U;  // enabled, core clock, no exception
    }
}

void send(const std::uint8_t* p, std::size_t n) noexcept {
    for (std::size_t i = 0; i < n; ++i) {  // n ≤ link::kMaxWire
        if (!uart::write(p[i])) {
            ++g_tx_dropped;
        }
    }
}

}  // namespace
}  // namespace ascorr::app

int main() {
    using namespace ascorr::app;
    __asm__ volatile("cpsid i" ::: "memory");  // PRIMASK: interrupts wake WFI but no handler runs
    board::systick_start(board::kSysTickMax + 1U, false);
    uart::init(board::kCoreClockHz, kBaud);
    nvic_iser0() = 1U << uart::kUart0RxIrq;
    // A delimiter first: it ends whatever partial frame the host's decoder
    // holds from before the reset, so that the HELLO is received whole.
    const std::uint8_t idle = 0U;
    send(&idle, 1U);
    g_server.announce(send);
    for (;;) {  // the service loop: one received byte, or one sleep, per iteration
        std::uint8_t b = 0U;
        if (uart::try_read(b)) {
            g_server.on_byte(b, send);
        } else {
            wait_for_rx();
        }
    }
}
