// bench/combination_fixture.hpp: the epochs the combination is benchmarked on
// (bench/target_bench.cpp under QEMU, bench/host_bench.cpp under callgrind).
//
// Three near-orthogonal heads (boresights near CRF x, y, z, each tilted a few
// degrees), the contract's noise (σc = 1.3″ across, σa = 9″ about each
// boresight), and per epoch a true CRF attitude (the caller's, e.g. the
// quaternions of vectors.bin) seen by the three heads with noise: the usual
// epoch of the flight loop (three usable heads, all consistent). The noise is
// uniform with those σ from a fixed linear congruential sequence, so the
// host and both targets see the same inputs. Setup only (double, sqrt).
#pragma once

#include <cmath>
#include <cstdint>

#include "ascorr/combine/combiner.hpp"
#include "ascorr/core/constants.hpp"

namespace ascorr::bench {

inline constexpr std::uint8_t kCombinationHeads = 3;

// A unit quaternion for a rotation of `angle` rad about the unit axis (x, y, z).
inline Quaternion<double> axis_angle(double x, double y, double z, double angle) {
    const double s = std::sin(0.5 * angle);
    return {std::cos(0.5 * angle), x * s, y * s, z * s};
}

inline combine::Mountings combination_mountings() {
    constexpr double kDeg = kPi / 180.0;
    combine::Mountings m{};
    // q_chu_crf: CHU z along CRF +x (A), +y (B), +z (C), each then tilted.
    const Quaternion<double> base[kCombinationHeads] = {
        axis_angle(0.0, 1.0, 0.0, -90.0 * kDeg), axis_angle(1.0, 0.0, 0.0, 90.0 * kDeg), {1.0, 0.0, 0.0, 0.0}};
    const Quaternion<double> tilt[kCombinationHeads] = {axis_angle(0.6, 0.8, 0.0, 4.0 * kDeg),
                                                        axis_angle(0.0, 0.6, 0.8, 7.0 * kDeg),
                                                        axis_angle(0.8, 0.0, 0.6, 3.0 * kDeg)};
    for (std::uint8_t h = 0; h < kCombinationHeads; ++h) {
        m.head[h] = {true, tilt[h] * base[h], 1.3, 9.0};
    }
    return m;
}

// The heads' q_chu_icrf for the true attitude q_crf_icrf: noise (arcsec, CHU
// axes) from the sequence *state, applied on the left.
inline void combination_epoch(const combine::Mountings& m, const Quaternion<double>& q_crf_icrf, std::uint32_t* state,
                              Quaternion<double> (&q_chu_icrf)[kCombinationHeads]) {
    const auto uniform = [state] {  // in [−√3, √3): unit variance
        *state = *state * 1664525U + 1013904223U;
        return (static_cast<double>(*state >> 8U) * 0x1p-24 * 2.0 - 1.0) * 1.7320508075688772;
    };
    for (std::uint8_t h = 0; h < kCombinationHeads; ++h) {
        const combine::HeadMounting& hm = m.head[h];
        const double hx = 0.5 * kArcsecToRad * hm.sigma_cross_arcsec * uniform();
        const double hy = 0.5 * kArcsecToRad * hm.sigma_cross_arcsec * uniform();
        const double hz = 0.5 * kArcsecToRad * hm.sigma_about_arcsec * uniform();
        const double w = std::sqrt(1.0 - hx * hx - hy * hy - hz * hz);
        q_chu_icrf[h] = Quaternion<double>{w, hx, hy, hz} * (hm.q_chu_crf * q_crf_icrf);
    }
}

}  // namespace ascorr::bench
