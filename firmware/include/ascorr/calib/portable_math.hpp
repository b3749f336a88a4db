// ascorr/calib/portable_math.hpp: the elementary functions the estimator
// (and pipeline/temperature_lag.hpp, and the IBA of frame.hpp's
// angle_arcsec) need beyond +, −, ×, ÷ and √, written
// with those alone, so that the DPU
// (picolibc, software double on the M3) and the host (glibc, SSE2) compute
// the same bits: IEEE 754 rounds each basic operation and √ correctly
// everywhere, while libm's exp, hypot and atan2 are not correctly rounded and differ
// between libraries in the last bit. The on-board model history is checked
// bit for bit against the host's (tests/target/flight_expectation.cpp).
#pragma once

#include <cmath>

#include "../core/constants.hpp"

namespace ascorr::calib {

// The range reduction of exp_nonpositive and expm1_nonpositive: y ≤ 0
// halved until |y| ≤ 2⁻¹⁰, in place; the count k of halvings (k ≤ 20 for
// y ≥ −745: bounded). Each halving is exact.
inline int halve_into_series_range(double& y) noexcept {
    int k = 0;
    for (; k < 64 && y < -0x1p-10; ++k) {  // bounded: 745 < 2^10
        y *= 0.5;
    }
    return k;
}

// e^x for x ≤ 0 (the forgetting factor): x halved k times until |x/2^k| ≤
// 2⁻¹⁰ (k ≤ 20 for x ≥ −745, below which e^x is 0 in double), a Taylor
// polynomial of degree 5 (truncation |y|⁶/720 ≤ 2e-21), then squared k times
// (relative error ≲ 2^k·2⁻⁵³ ≤ 1.2e-10 at the longest gaps, 2e-16 for an
// orbit). NaN stays NaN; x > 0 is not its domain and gives 1.
inline double exp_nonpositive(double x) noexcept {
    if (std::isnan(x)) {
        return x;
    }
    if (!(x < 0.0)) {
        return 1.0;
    }
    if (x < -745.0) {
        return 0.0;
    }
    double y = x;
    const int k = halve_into_series_range(y);
    double e = 1.0 + y * (1.0 + y / 2.0 * (1.0 + y / 3.0 * (1.0 + y / 4.0 * (1.0 + y / 5.0))));
    for (int i = 0; i < k; ++i) {
        e *= e;
    }
    return e;
}

// e^x − 1 for x ≤ 0 (a first-order lag's −α): as exp_nonpositive, x halved
// k times until |x/2^k| ≤ 2⁻¹⁰ (k ≤ 20 for x ≥ −745), a Taylor polynomial
// of degree 6 (truncation |y|⁶/720 of |y|, ≤ 2e-21 relative), then doubled k
// times by expm1(2y) = m·(m + 2), which keeps the relative precision of a
// small result (where 1 − e^x would cancel): relative error ≲ (k + 2)·2⁻⁵³.
// NaN stays NaN; x > 0 is not its domain and gives 0; below −745, −1.
inline double expm1_nonpositive(double x) noexcept {
    if (std::isnan(x)) {
        return x;
    }
    if (!(x < 0.0)) {
        return 0.0;
    }
    if (x < -745.0) {
        return -1.0;
    }
    double y = x;
    const int k = halve_into_series_range(y);
    double m = y * (1.0 + y / 2.0 * (1.0 + y / 3.0 * (1.0 + y / 4.0 * (1.0 + y / 5.0 * (1.0 + y / 6.0)))));
    for (int i = 0; i < k; ++i) {
        m *= m + 2.0;
    }
    return m;
}

// √(p² + q²) without overflow or underflow of the squares: a·√(1 + (b/a)²),
// a = max(|p|, |q|), b = min (within 2 ulp of the exact value).
inline double hypot2(double p, double q) noexcept {
    double a = std::fabs(p);
    double b = std::fabs(q);
    if (a < b) {
        const double t = a;
        a = b;
        b = t;
    }
    if (a == 0.0 || !std::isfinite(a)) {
        return a + b;  // 0, ∞ or NaN
    }
    const double t = b / a;
    return a * std::sqrt(1.0 + t * t);
}

// atan(t) for |t| ≤ 1: t halved twice by the half-angle identity
// atan t = 2·atan(t / (1 + √(1 + t²))), so that |t| ≤ tan(π/16) < 0.199,
// then the Taylor polynomial t − t³/3 + … − t²³/23 (truncation
// t²⁴/25 ≤ 0.0396¹²/25 < 2e-19 of |t|): relative error ≲ 6·2⁻⁵³ (measured
// against long double; tests/test_calib.cpp bounds atan2_upper), two √ and
// two ÷ (libm's atan does about as much work, with other bits).
inline double atan_unit(double t) noexcept {
    t = t / (1.0 + std::sqrt(1.0 + t * t));
    t = t / (1.0 + std::sqrt(1.0 + t * t));
    const double u = t * t;
    double p = 1.0 / 23.0;
    constexpr double kOdd[] = {1.0 / 21.0, 1.0 / 19.0, 1.0 / 17.0, 1.0 / 15.0, 1.0 / 13.0, 1.0 / 11.0,
                               1.0 / 9.0,  1.0 / 7.0,  1.0 / 5.0,  1.0 / 3.0,  1.0};
    for (const double c : kOdd) {  // Horner, alternating: c − u·p
        p = c - u * p;
    }
    return 4.0 * (t * p);
}

// atan2(y, x) for y ≥ 0, in [0, π] (the angle between two vectors from
// |a×b| and a·b): atan_unit of the smaller over the larger of y and |x|,
// then reflected, so that every argument is ≤ 1 and nothing cancels but
// π − a (absolute error ≲ 2⁻⁵⁰ rad < 2e-10″). 0 for y = x = 0, NaN for NaN.
inline double atan2_upper(double y, double x) noexcept {
    const double ax = std::fabs(x);
    if (y == 0.0 && ax == 0.0) {
        return 0.0;
    }
    if (y <= ax) {
        const double a = atan_unit(y / ax);
        return x > 0.0 ? a : kPi - a;
    }
    return kPi / 2.0 - atan_unit(x / y);  // NaN y or x: NaN
}

}  // namespace ascorr::calib
