// ascorr/core/aberration.hpp: stellar aberration as an attitude rotation.
//
// Conventions:
//  - beta_icrf = v_obs_icrf / c: observer velocity (Earth barycentric + spacecraft
//    geocentric), ICRF axes, in units of the speed of light.
//  - The formula is ERFA eraAb (relativistic, with the Sun's potential term):
//      pdv = z·β,  bm1 = sqrt(1 − β²),  w1 = 1 + pdv/(1 + bm1),  w2 = SRS/s,
//      p   = bm1·z + w1·β + w2·(β − pdv·z),   z_corr = p/|p|,
//    where z is the natural (catalogue) direction and z_corr the proper one.
//  - The result is q_ab (as a SmallRotation), the minimal active rotation in ICRF with
//    R(q_ab)·z = z_corr. The attitude correction is applied on the inertial
//    side: R_corr = R_raw·R(q_ab)ᵀ, i.e. q_chu_icrf_corr = q_chu_icrf ⊗ q_ab*.
//
// Evaluation without sqrt or division:
//  z × p = (w1 + w2)·(z × β) exactly, and |p| = 1 + pdv up to a relative
//  2·w2·w1·(β² − pdv²) ≤ 5e-13 (the w1 part of the formula is exactly unit
//  after division by 1 + pdv). Hence, with c = z × β,
//      u = z × z_corr = sin θ·n = f·c,   f = (w1 + w2)/(1 + pdv),
//  and with x = |u|² = sin²θ = f²·|c|² the half-angle quaternion is
//      q_ab = (cos θ/2, sin θ/2·n) = (1 − x/8, f/2·(1 + x/8)·c) + O(x²).
//  Truncation errors for |β| ≤ kMaxBeta = 3.34e-3 (θ ≤ 3.34e-3 rad), double:
//   - 1/(1 + bm1) = (1 + β²/4)/2 + O(β⁴/16): error in w1 ≤ pdv·β⁴/16 ≤ 2.6e-14;
//   - 1/(1 + pdv) to pdv⁴: remainder ≤ |pdv|⁵/(1 − |pdv|) ≤ 4.3e-13 relative;
//   - cos θ/2 = 1 − x/8 − 5x²/128 − …: dropped term ≤ 4.8e-12, a norm error
//     the final renormalisation removes (its effect on the angle ≤ θ·4.8e-12);
//   - 1/(2 cos θ/2) = (1 + x/8)/2 + O(3x²/128).
//  In angle that is below 3e-9" at the domain limit and below 1e-12" for
//  |v| ≤ 100 km/s. The solar term itself is ≤ 4e-7", which is why it stays.
//  Without double precision (float; Q30 has its own, below) the
//  series stop where float's resolution (2⁻²⁴ = 6e-8 relative) does:
//      f = 1 − pdv/2 + pdv²/2,   x = |c|²,
//  dropping pdv³/2 ≤ 1.9e-8 and pdv·β²/8 ≤ 4.6e-9 (relative to f), the
//  solar term w2 ≤ 2e-8/s (below half an ulp of f ≈ 1, so float would round it
//  away), and in x the factor f² = 1 − pdv + …: x/8 is then off by ≤ 4.6e-9,
//  a change of norm (≤ 1.6e-11 rad in direction), and the scale by ≤ 4.6e-9
//  relative. Together ≤ 5e-8 of θ: 3.4e-5" at the domain limit.
#pragma once

#include <cstdint>

#include "constants.hpp"
#include "q_formats.hpp"
#include "quaternion.hpp"
#include "scalar_traits.hpp"
#include "vector3.hpp"

namespace ascorr {

template <typename T>
struct ObserverVelocity {
    Vector3<T> beta_icrf;   // v_obs_icrf / c
    T inv_sun_distance_au;  // 1/s, s = Sun–observer distance in au (1 if unknown: the term is ≤ 4e-7");
                            // domain [1/kMaxSunDistanceAu, 1/kMinSunDistanceAu]
    bool valid;             // false: not available or stale
};

// True when beta is finite and inside the domain of the series below
// (|v| ≤ kMaxObserverSpeedKmS, which also excludes |v| ≥ c). One comparison
// decides: a NaN component makes |β|² NaN, which fails it; an infinite or
// huge one makes |β|² infinite in floating point, or saturates it (≥ 2) in
// fixed point, which fails it too.
template <typename T>
constexpr bool beta_in_domain(const Vector3<T>& beta) noexcept {
    constexpr T lim = constant<T>(kMaxBeta * kMaxBeta);
    return squared_norm(beta) <= lim;
}

// True when 1/s (1/au) is inside [1/kMaxSunDistanceAu, 1/kMinSunDistanceAu];
// false for NaN (both comparisons fail). In fixed point a NaN or huge input
// converts to the top of the range (≥ 1.99), which fails the upper bound.
template <typename T>
constexpr bool inv_sun_distance_in_domain(const T& inv_sun_distance_au) noexcept {
    constexpr T lo = constant<T>(1.0 / kMaxSunDistanceAu);
    constexpr T hi = constant<T>(1.0 / kMinSunDistanceAu);
    return lo <= inv_sun_distance_au && inv_sun_distance_au <= hi;
}

// Both parts of an observer velocity inside the series' domain.
template <typename T>
constexpr bool velocity_in_domain(const ObserverVelocity<T>& v) noexcept {
    return beta_in_domain(v.beta_icrf) && inv_sun_distance_in_domain(v.inv_sun_distance_au);
}

// q_ab: the minimal rotation (ICRF, active) taking the natural direction
// z_icrf (unit) to its aberrated, proper direction. Requires beta_in_domain().
template <typename T>
constexpr SmallRotation<T> aberration_rotation(const Vector3<T>& z_icrf, const Vector3<T>& beta_icrf,
                                               const T& inv_sun_distance_au) noexcept {
    constexpr T one = constant<T>(1.0);
    constexpr T half = constant<T>(0.5);
    constexpr T eighth = constant<T>(0.125);
    const T pdv = dot(z_icrf, beta_icrf);
    const Vector3<T> c = cross(z_icrf, beta_icrf);
    const T n = squared_norm(c);
    T f = one + half * pdv * (pdv - one);
    T x = n;
    if constexpr (ScalarTraits<T>::double_precision) {
        const T b2 = squared_norm(beta_icrf);
        constexpr T quarter = constant<T>(0.25);
        constexpr T sun_radius = constant<T>(kSunSchwarzschildRadiusAu);
        const T w1 = one + half * pdv * (one + quarter * b2);
        const T w2 = sun_radius * inv_sun_distance_au;
        // 1/(1 + pdv) by Horner: 1 − p(1 − p(1 − p(1 − p))).
        const T inv_1_pdv = one - pdv * (one - pdv * (one - pdv * (one - pdv)));
        f = (w1 + w2) * inv_1_pdv;
        x = f * f * n;
    } else {
        static_cast<void>(inv_sun_distance_au);
    }
    const T eighth_x = eighth * x;
    return {-eighth_x, (half * f * (one + eighth_x)) * c};
}

// ---- In Q30 (q_formats.hpp), each overload followed by its guard (vector3.hpp).
// beta_in_domain (above) in Q30, for any input: each component
// within ±kMaxBeta (then |βᵢ| < 2²², the squares are exact and small), then
// |β|² against kMaxBeta² exactly, in units 2⁻⁶⁰.
constexpr bool beta_in_domain(const Vector3<Q30>& beta) noexcept {
    constexpr std::int32_t lim = fx::raw_from_double<Q30::kFracBits>(kMaxBeta);
    constexpr auto lim2 = static_cast<std::int64_t>(kMaxBeta * kMaxBeta * 0x1p60);
    const auto within = [](Q30 c) { return c.raw <= lim && -lim <= c.raw; };
    return within(beta.x) && within(beta.y) && within(beta.z) &&
           fx::mul(beta.x.raw, beta.x.raw) + fx::mul(beta.y.raw, beta.y.raw) + fx::mul(beta.z.raw, beta.z.raw) <= lim2;
}
template <>
bool beta_in_domain<Q30>(const Vector3<Q30>&) noexcept = delete;

// aberration_rotation (above) in Q30: the same q_ab, with the series
// cut at the format's resolution (2⁻³⁰ = 9.3e-10). With c = z × β,
// n = |c|² = sin²θ·(1 + p)²/(w1 + w2)² and p = z·β:
//   f = (w1 + w2)/(1 + p) = 1 − p/2 + p²/2 + O(p³/2, p·β²/8, w2),
//   q_ab = (−x/8, f/2·(1 + x/8)·c) with x = f²n = n·(1 + O(p)).
// Dropped, relative to |c| ≤ kMaxBeta (3.34e-3), hence in absolute terms:
// p³/2 ≤ 1.9e-8 → 6e-11; p·β²/8 ≤ 4.6e-9 → 1.5e-11; the solar term
// w2 ≤ 2e-8/s → 7e-11 for s ≥ 1 au (the unused inv_sun_distance_au): each
// below one LSB. In x/8 the O(p) is ≤ 4.6e-9 (5 LSB) in dw, a change of norm
// only, which the renormalisation takes out, and 7.7e-12 in v. Precondition: beta_in_domain(β) and |zᵢ| ≤ 1 + 2e-6 (the
// boresight of a quaternion that passed norm_within()); then |p|, |cᵢ| ≤
// 3.35e-3 and n ≤ 1.2e-5, so nothing overflows.
// Rounding: c, p, f, the scale and v once each (≤ 2⁻³¹ each; v's error
// ≤ 2.1·2⁻³¹ absolute), n exact (units 2⁻⁶⁰).
constexpr SmallRotation<Q30> aberration_rotation(const Vector3<Q30>& z_icrf, const Vector3<Q30>& beta_icrf,
                                                 const Q30& /*inv_sun_distance_au*/) noexcept {
    using fx::unshared;
    const std::int32_t zx = unshared(z_icrf.x.raw);
    const std::int32_t zy = unshared(z_icrf.y.raw);
    const std::int32_t zz = unshared(z_icrf.z.raw);
    const std::int32_t bx = unshared(beta_icrf.x.raw);
    const std::int32_t by = unshared(beta_icrf.y.raw);
    const std::int32_t bz = unshared(beta_icrf.z.raw);
    const std::int32_t p = fx::narrow<30>(0, zx, bx, zy, by, zz, bz);
    const std::int32_t cx = fx::narrow<30>(0, zy, bz, zz, -by);
    const std::int32_t cy = fx::narrow<30>(0, zz, bx, zx, -bz);
    const std::int32_t cz = fx::narrow<30>(0, zx, by, zy, -bx);
    const std::int64_t n = fx::sum_products(cx, cx, cy, cy, cz, cz);  // units 2⁻⁶⁰
    constexpr std::int32_t kOne = std::int32_t{1} << 30;
    const std::int32_t f = kOne - fx::narrow<1>(p) + fx::narrow<31>(fx::mul(p, p));
    const std::int32_t half_1_x8 = (kOne >> 1) + fx::narrow<34>(n);  // (1 + n/8)/2
    const std::int32_t scale = fx::narrow<30>(0, f, half_1_x8);
    return {{-fx::narrow<33>(n)},
            {Q30{fx::narrow<30>(0, scale, cx)}, Q30{fx::narrow<30>(0, scale, cy)}, Q30{fx::narrow<30>(0, scale, cz)}}};
}
template <>
SmallRotation<Q30> aberration_rotation<Q30>(const Vector3<Q30>&, const Vector3<Q30>&, const Q30&) noexcept = delete;

}  // namespace ascorr
