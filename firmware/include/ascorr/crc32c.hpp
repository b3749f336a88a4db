// ascorr/crc32c.hpp: CRC-32C (Castagnoli), for link frames and for the
// identity of a thermal model (calib/model_identity.hpp).
//
// Polynomial 0x1EDC6F41 (reflected 0x82F63B78), init 0xFFFFFFFF, reflected
// input and output, final XOR 0xFFFFFFFF; check value of "123456789" is
// 0xE3069283. Chosen over CRC-16 because at the 1 % frame-corruption rate of
// the replay tests a 16-bit CRC would let about one corrupted frame in 65536
// through; CRC-32C detects every burst up to 32 bits and all odd bit counts.
// Table-driven (1 KiB of flash, built at compile time), one loop bounded by
// the frame length.
#pragma once

#include <cstddef>
#include <cstdint>

namespace ascorr {

namespace detail {
struct Crc32cTable {
    std::uint32_t v[256];
};
constexpr Crc32cTable make_crc32c_table() noexcept {
    Crc32cTable t{};
    for (std::uint32_t i = 0; i < 256U; ++i) {
        std::uint32_t c = i;
        for (int k = 0; k < 8; ++k) {
            c = (c & 1U) != 0U ? (c >> 1) ^ 0x82F63B78U : c >> 1;
        }
        t.v[i] = c;
    }
    return t;
}
inline constexpr Crc32cTable kCrc32cTable = make_crc32c_table();
}  // namespace detail

constexpr std::uint32_t crc32c(const std::uint8_t* data, std::size_t n, std::uint32_t crc = 0U) noexcept {
    crc = ~crc;
    for (std::size_t i = 0; i < n; ++i) {
        crc = detail::kCrc32cTable.v[(crc ^ data[i]) & 0xFFU] ^ (crc >> 8);
    }
    return ~crc;
}

}  // namespace ascorr
