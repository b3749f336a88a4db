// firmware/app/report.hpp: text output over semihosting without printf.
//
// Conventions: integers only (decimal and 8-digit hex), so that no
// floating-point formatting code is linked into the images (the M3's
// per-cycle code must stay free of soft-float routines). Output goes to stdout (semihosting under QEMU);
// in flight the same calls would go to the telemetry UART.
#pragma once

#include <cstdint>
#include <cstdio>

namespace ascorr::app::report {

inline void text(const char* s) noexcept {
    std::fputs(s, stdout);
}

// A count in decimal (u32: the same digits).
inline void u64(std::uint64_t v) noexcept {
    char buf[21];
    int i = 20;
    buf[i] = '\0';
    do {  // at most 20 digits
        buf[--i] = static_cast<char>('0' + v % 10U);
        v /= 10U;
    } while (v != 0U && i > 0);
    text(&buf[i]);
}

inline void u32(std::uint32_t v) noexcept {
    u64(v);
}

inline void hex32(std::uint32_t v) noexcept {
    char buf[9];
    for (int i = 7; i >= 0; --i) {
        buf[i] = "0123456789abcdef"[v & 0xFU];
        v >>= 4U;
    }
    buf[8] = '\0';
    text(buf);
}

}  // namespace ascorr::app::report
