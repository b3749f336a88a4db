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
#include <limits>

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

// atan(t) for |t| ≤ 1 (NaN beyond, and for NaN). |t| is reduced to
// r = (|t| − c)/(1 + c·|t|), c = k/4 the nearest of 0, ¼, ½, ¾, 1, so that
// |r| ≤ ⅛ and atan|t| = atan c + atan r; |t| − c is exact (Sterbenz), c·|t|
// too but for c = ¾. atan r is the Taylor polynomial r − r³/3 + … + r¹⁷/17
// (truncation r¹⁹/19 ≤ 2⁻⁵⁷/19 of |r|); atan c is a double and its
// remainder (kAtanQuarterHi/Lo). One ÷ and no √: relative error ≲ 4·2⁻⁵³
// (measured against long double; tests/test_calib.cpp bounds atan2_upper).
inline constexpr double kAtanQuarterHi[5] = {0.0, 0x1.f5b75f92c80ddp-3, 0x1.dac670561bb4fp-2, 0x1.4978fa3269ee1p-1,
                                             0x1.921fb54442d18p-1};  // atan(k/4) to the nearest double
inline constexpr double kAtanQuarterLo[5] = {0.0, 0x1.8ab6e3cf7afbdp-57, 0x1.a2b7f222f65e2p-56, 0x1.2419a87f2a458p-56,
                                             0x1.1a62633145c07p-55};  // atan(k/4) − Hi (mpmath, 50 digits)
inline double atan_unit(double t) noexcept {
    const double a = std::fabs(t);
    if (!(a <= 1.0)) {
        return std::numeric_limits<double>::quiet_NaN();  // out of the domain, or NaN given
    }
    const auto k = static_cast<int>(4.0 * a + 0.5);  // 0 … 4: a ≤ 1, no overflow
    const double c = 0.25 * k;
    const double r = (a - c) / (1.0 + c * a);
    const double u = r * r;
    double p = 1.0 / 17.0;
    constexpr double kOdd[] = {1.0 / 15.0, 1.0 / 13.0, 1.0 / 11.0, 1.0 / 9.0, 1.0 / 7.0, 1.0 / 5.0, 1.0 / 3.0, 1.0};
    for (const double co : kOdd) {  // Horner, alternating: co − u·p
        p = co - u * p;
    }
    const double at = kAtanQuarterHi[k] + (kAtanQuarterLo[k] + r * p);
    return t < 0.0 ? -at : at;
}

// atan2(y, x) in the upper half-plane, y ≥ 0 (the angle between two vectors
// from |a×b| and a·b): [0, π]. atan_unit of the smaller over the larger of y
// and |x|, then reflected, so that every argument is ≤ 1 and nothing cancels
// but π − a (absolute error ≲ 2⁻⁵⁰ rad < 2e-10″). Its edges: 0 for y = 0 and
// x ≥ ±0 (atan2 gives π for x = −0), π for x < 0; NaN for y < 0, for NaN and
// for y = |x| = ∞ (atan2: π/4, 3π/4).
inline double atan2_upper(double y, double x) noexcept {
    const double ax = std::fabs(x);
    if (!(y >= 0.0)) {
        return std::numeric_limits<double>::quiet_NaN();  // not the upper half-plane, or NaN
    }
    if (y == 0.0 && ax == 0.0) {
        return 0.0;
    }
    if (y <= ax) {
        const double a = atan_unit(y / ax);
        return x > 0.0 ? a : kPi - a;
    }
    return kPi / 2.0 - atan_unit(x / y);  // NaN x: NaN
}

}  // namespace ascorr::calib
