// firmware/app/cmsdk_uart.hpp: the CMSDK APB UART of the MPS2 boards, polled
// (ARM Cortex-M System Design Kit TRM, DDI 0479, 4.3 "UART").
//
// Conventions: UART0 at 0x40004000 on AN385 (Cortex-M3) and AN386 (Cortex-M4F),
// clocked from the 25 MHz peripheral clock. One-byte buffers each way: STATE
// bit 0 says the transmit buffer is full, bit 1 that a received byte is
// waiting. No interrupts are enabled; the link loop polls. Under QEMU the UART
// is backed by a character device (toolchain/qemu-link) that holds bytes
// while the receive buffer is full, so nothing is lost to the polling.
#pragma once

#include <cstdint>

namespace ascorr::app::uart {

struct Registers {
    volatile std::uint32_t data;       // 0x000: write to send, read to receive (low 8 bits)
    volatile std::uint32_t state;      // 0x004: bit 0 TX full, 1 RX full, 2 TX overrun, 3 RX overrun (write 1 clears)
    volatile std::uint32_t ctrl;       // 0x008: bit 0 TX enable, 1 RX enable, 2–5 interrupt enables
    volatile std::uint32_t intstatus;  // 0x00C: interrupt status / clear (write 1 clears)
    volatile std::uint32_t bauddiv;    // 0x010: PCLK cycles per bit, ≥ 16
};

inline constexpr std::uintptr_t kUart0Base = 0x40004000U;
inline constexpr std::uint32_t kStateTxFull = 1U << 0;
inline constexpr std::uint32_t kStateRxFull = 1U << 1;
inline constexpr std::uint32_t kStateOverruns = (1U << 2) | (1U << 3);
inline constexpr std::uint32_t kCtrlTxEnable = 1U << 0;
inline constexpr std::uint32_t kCtrlRxEnable = 1U << 1;
inline constexpr std::uint32_t kCtrlRxInterruptEnable = 1U << 3;
inline constexpr std::uint32_t kIntRx = 1U << 1;
inline constexpr std::uint32_t kUart0RxIrq = 0U;  // NVIC line of UART0 RX on AN385/AN386

inline Registers& uart0() noexcept {
    return *reinterpret_cast<Registers*>(kUart0Base);  // NOLINT: memory-mapped register
}

// Enables transmit and receive at `baud` from a PCLK of `pclk_hz`. The RX
// interrupt is raised only to wake the core from WFI (wait_for_rx): the
// caller keeps exceptions masked (PRIMASK), so no handler ever runs.
inline void init(std::uint32_t pclk_hz, std::uint32_t baud) noexcept {
    Registers& u = uart0();
    u.ctrl = 0U;
    u.bauddiv = pclk_hz / baud;
    u.state = kStateOverruns;  // clear stale overrun flags
    u.intstatus = 0xFU;
    u.ctrl = kCtrlTxEnable | kCtrlRxEnable | kCtrlRxInterruptEnable;
}

// One received byte, if any (never waits).
inline bool try_read(std::uint8_t& b) noexcept {
    Registers& u = uart0();
    if ((u.state & kStateRxFull) == 0U) {
        return false;
    }
    b = static_cast<std::uint8_t>(u.data & 0xFFU);
    return true;
}

// Polls of STATE before a byte is given up: the buffer empties within one
// character time (10 bits × BAUDDIV ≤ 2170 PCLK cycles at 115200 baud), and
// each poll takes more than one cycle.
inline constexpr std::uint32_t kTxPolls = 4096U;

// Sends one byte, waiting (boundedly) while the transmit buffer is full.
// False if the line stayed busy: the byte is dropped, and the host's time-out
// and resend recover the frame it belonged to.
inline bool write(std::uint8_t b) noexcept {
    Registers& u = uart0();
    for (std::uint32_t i = 0U; i < kTxPolls; ++i) {
        if ((u.state & kStateTxFull) == 0U) {
            u.data = b;
            return true;
        }
    }
    return false;
}

}  // namespace ascorr::app::uart
