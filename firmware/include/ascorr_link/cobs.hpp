// ascorr_link/cobs.hpp: Consistent Overhead Byte Stuffing.
//
// A frame on the wire is COBS(raw) followed by one 0x00 delimiter, so a
// receiver resynchronises at the next zero byte after any corruption, and
// never needs a timeout to find frame boundaries. Overhead: one byte per 254
// bytes of raw data, plus one. Both functions are bounded by their input size,
// write nothing beyond the capacity they are given, and report failure by a
// zero return (a valid encoding is never empty).
#pragma once

#include <cstddef>
#include <cstdint>

namespace ascorr::link {

// Largest encoded size of n raw bytes (without the delimiter).
constexpr std::size_t cobs_max_encoded(std::size_t n) noexcept {
    return n + n / 254U + 1U;
}

// Encodes in[0..n) into out (capacity cap). Returns the encoded size, or 0 if
// cap is too small. The output contains no zero byte.
constexpr std::size_t cobs_encode(const std::uint8_t* in, std::size_t n, std::uint8_t* out, std::size_t cap) noexcept {
    if (cap < cobs_max_encoded(n)) {
        return 0;
    }
    std::size_t code_at = 0;  // where the current block's code byte goes
    std::size_t o = 1;
    std::uint8_t code = 1;
    for (std::size_t i = 0; i < n; ++i) {
        if (in[i] == 0U) {
            out[code_at] = code;
            code_at = o++;
            code = 1;
        } else {
            out[o++] = in[i];
            if (++code == 0xFFU) {
                out[code_at] = code;
                code_at = o++;
                code = 1;
            }
        }
    }
    out[code_at] = code;
    return o;
}

// Decodes in[0..n) (no delimiter) into out (capacity cap). Returns the decoded
// size, or 0 on a malformed encoding (a zero byte, a code running past the
// end) or when cap is too small. An encoding of zero raw bytes also returns 0:
// the link never sends empty frames.
constexpr std::size_t cobs_decode(const std::uint8_t* in, std::size_t n, std::uint8_t* out, std::size_t cap) noexcept {
    std::size_t i = 0;
    std::size_t o = 0;
    while (i < n) {
        const std::uint8_t code = in[i++];
        if (code == 0U) {
            return 0;
        }
        for (std::uint8_t k = 1; k < code; ++k) {
            if (i >= n || in[i] == 0U || o >= cap) {
                return 0;
            }
            out[o++] = in[i++];
        }
        if (code != 0xFFU && i < n) {
            if (o >= cap) {
                return 0;
            }
            out[o++] = 0U;
        }
    }
    return o;
}

}  // namespace ascorr::link
