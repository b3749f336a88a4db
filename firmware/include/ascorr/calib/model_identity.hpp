// ascorr/calib/model_identity.hpp: the CRC-32C that identifies a thermal
// model (ModelCoefficients, model_coefficients.hpp) in the estimator's report
// and in the model history (and, by crc32c_of, the Sun learner's fit:
// sun_moments.hpp, sun_fit_crc).
//
// Byte stream, in this order: present[h] as one byte 0/1 for h = 0 … kMaxHeads − 1,
// then coefficient[h][axis][term] (h, axis, term ascending) each as the eight
// bytes of its IEEE-754 binary64 image, least significant byte first. The
// value is therefore the same on every host and target, whatever its
// endianness. Coefficients in the unit the model is kept in (arcsec; see
// estimator.hpp). CRC-32C as for the link's frames (crc32c.hpp).
// Fixed trip count, no allocation.
#pragma once

#include <cstdint>
#include <cstring>

#include "../core/model_coefficients.hpp"
#include "../crc32c.hpp"

namespace ascorr::calib {

// crc continued over x's bits as 8 little-endian bytes (the byte order is
// the wire's, whatever the machine's).
inline std::uint32_t crc32c_of(double x, std::uint32_t crc) noexcept {
    std::uint64_t bits = 0U;
    std::memcpy(&bits, &x, sizeof bits);
    std::uint8_t b[8];
    for (std::uint8_t i = 0; i < 8U; ++i) {
        b[i] = static_cast<std::uint8_t>(bits >> (8U * i));
    }
    return crc32c(b, 8U, crc);
}

inline std::uint32_t model_crc(const ModelCoefficients& m) noexcept {
    std::uint32_t crc = 0U;
    for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
        const std::uint8_t p = m.present[h] ? 1U : 0U;
        crc = crc32c(&p, 1U, crc);
    }
    for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
        for (std::uint8_t a = 0; a < kModelAxes; ++a) {
            for (std::uint8_t t = 0; t < kModelTerms; ++t) {
                crc = crc32c_of(m.coefficient[h][a][t], crc);
            }
        }
    }
    return crc;
}

}  // namespace ascorr::calib
