// firmware/app/link_main.cpp: the DPU's link service (hardware-in-the-loop
// replay, firmware/link-protocol.md) on the CMSDK UART0 of the MPS2 boards.
//
// Conventions: at boot the UART is enabled and, after one delimiter byte,
// HELLO is announced (sequence 0), so that the host learns of every restart; then each received byte goes
// to the LinkServer, which owns the model, velocity and temperatures in static
// storage and answers through the UART. The core runs in the build's scalar
// (app_scalar.hpp). Each loop iteration is bounded; the image serves until
// reset. The boot id is the same at every boot (no reset counter survives a
// reset on these boards); the host therefore treats any unprompted HELLO as a
// restart.
//
// The cost reported with each solution is the instructions of
// correct_solution(): SysTick runs free from the core clock (no exception)
// and one count is kInstructionsPerCount instructions (40 under QEMU's
// -icount shift=0, board.hpp; 1 core clock on the board). The measure has a
// resolution of one count and includes the two counter reads.
#include <cstdint>

#include "app_scalar.hpp"
#include "ascorr_link/server.hpp"
#include "board.hpp"
#include "cmsdk_uart.hpp"

#ifndef ASCORR_LINK_INSTRUCTIONS_PER_COUNT
#define ASCORR_LINK_INSTRUCTIONS_PER_COUNT 40
#endif

namespace ascorr::app {
namespace {

constexpr std::uint32_t kBaud = 115200U;
constexpr std::uint32_t kBootId = 0x41534331U;  // "ASC1"
constexpr std::uint32_t kInstructionsPerCount = ASCORR_LINK_INSTRUCTIONS_PER_COUNT;

// SysTick extended to 32 bits in software. Only the difference of two reads
// less than 2^24 counts apart is meaningful, which is what the LinkServer
// takes around one correct_solution() (a few thousand instructions).
struct SysTickCounter {
    static std::uint32_t last;   // up-counting SysTick value at the previous read
    static std::uint32_t total;  // counts accumulated over reads
    std::uint32_t operator()() const noexcept {
        const std::uint32_t now = board::kSysTickMax - board::systick_value();
        total += (now - last) & board::kSysTickMax;
        last = now;
        return total * kInstructionsPerCount;
    }
};
std::uint32_t SysTickCounter::last = 0U;
std::uint32_t SysTickCounter::total = 0U;

using Server = link::LinkServer<Scalar, SysTickCounter>;
Server g_server(kBootId, SysTickCounter{});  // static: model, velocity, temperatures and caches
std::uint32_t g_tx_dropped = 0U;             // bytes the UART could not take (inspect with a debugger)

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
    board::systick_start(board::kSysTickMax + 1U, false);
    uart::init(board::kCoreClockHz, kBaud);
    // A delimiter first: it ends whatever partial frame the host's decoder
    // holds from before the reset, so that the HELLO is received whole.
    const std::uint8_t idle = 0U;
    send(&idle, 1U);
    g_server.announce(send);
    for (;;) {  // the service loop: one received byte per iteration
        std::uint8_t b = 0U;
        if (uart::try_read(b)) {
            g_server.on_byte(b, send);
        }
    }
}
