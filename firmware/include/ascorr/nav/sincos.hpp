// ascorr/nav/sincos.hpp: sine and cosine in double without the C library.
//
// The core's double-precision trigonometry (the Earth rotation angle,
// earth_frame.hpp; the Earth series' fundamental arguments, earth_series.hpp)
// runs on the host and on the DPU, and the link replay compares their answers
// bit for bit. Library sin/cos differ between C libraries (glibc, picolibc) in
// the last bit for some arguments; this one is a fixed sequence of IEEE
// double additions and multiplications. Double has no fused multiply-add on
// either side (software double on the Cortex-M DPUs, SSE2 on x86-64), so every
// platform gets the same bits.
#pragma once

#include <cstdint>

#include "../core/constants.hpp"

namespace ascorr {

// sin and cos of 2π·f, f any turn count with |f| < 2³¹: reduced to an octant
// around a multiple of a quarter turn, then Taylor to x¹⁵ / x¹⁶ on |x| ≤ π/4,
// whose truncation is ≤ (π/4)¹⁷/17! = 6.7e-17 / (π/4)¹⁸/18! = 3e-18.
// Error ≤ 2e-16 + the reduction's f·2⁻⁵³ (θ's own rounding).
struct SinCos {
    double s;
    double c;
};
constexpr SinCos sincos_turns(double f) noexcept {
    const double q4 = 4.0 * f;
    const std::int64_t quadrant = static_cast<std::int64_t>(q4 < 0.0 ? q4 - 0.5 : q4 + 0.5);
    const double x = (q4 - static_cast<double>(quadrant)) * (0.5 * kPi);  // |x| ≤ π/4
    const double x2 = x * x;
    const double s =
        x *
        (1.0 - x2 * (1.0 / 6.0) *
                   (1.0 - x2 * (1.0 / 20.0) *
                              (1.0 - x2 * (1.0 / 42.0) *
                                         (1.0 - x2 * (1.0 / 72.0) *
                                                    (1.0 - x2 * (1.0 / 110.0) *
                                                               (1.0 - x2 * (1.0 / 156.0) *
                                                                          (1.0 - x2 * (1.0 / 210.0) *
                                                                                     (1.0 - x2 * (1.0 / 272.0)))))))));
    const double c =
        1.0 - x2 * (1.0 / 2.0) *
                  (1.0 - x2 * (1.0 / 12.0) *
                             (1.0 - x2 * (1.0 / 30.0) *
                                        (1.0 - x2 * (1.0 / 56.0) *
                                                   (1.0 - x2 * (1.0 / 90.0) *
                                                              (1.0 - x2 * (1.0 / 132.0) *
                                                                         (1.0 - x2 * (1.0 / 182.0) *
                                                                                    (1.0 - x2 * (1.0 / 240.0))))))));
    switch (static_cast<unsigned>(quadrant & 3)) {
        case 0U:
            return {s, c};
        case 1U:
            return {c, -s};
        case 2U:
            return {-s, -c};
        default:
            return {-c, s};
    }
}

}  // namespace ascorr
