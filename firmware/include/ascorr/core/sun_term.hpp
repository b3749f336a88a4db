// ascorr/core/sun_term.hpp: the orbit-periodic term of the thermal model, the
// bench's rotation with the Sun's direction in the head's frame (issue 40).
//
// Conventions (quaternion.hpp, thermal.hpp; docs/contract.md, "The Sun term"):
//  - s_icrf: the Sun's geocentric unit direction, ICRF components
//    (nav/sun_direction.hpp); s_chu = R(q_chu_icrf)·s_icrf, its components in
//    the head's frame, from the attitude being corrected.
//  - Per head and axis a ∈ (alpha, beta, gamma): angle_a = Σ_m S[a][m]·s_chu[m]
//    (rad; the model file's sun_x, sun_y, sun_z in arcsec), an angle of the
//    same axis and sign as the polynomial's (thermal.hpp), so that the model's
//    angle is the polynomial's plus this one.
//  - Two forms. The contract's (with_sun_term(), sun_term_rotation(): the
//    host): applied as the thermal stage is, on the CHU side, q ← q_sun ⊗ q
//    with q_sun = thermal_rotation(angles), after the polynomial's q_th and
//    with s_chu from the attitude that q_th gave. The flight form
//    (correct.hpp, correct_solution() with a SunTermInput): the angles added
//    to the polynomial's before its one rotation, s_chu from the raw
//    attitude; it differs from the contract's by the bound correct.hpp states
//    (4e-3″ for 2″ coefficients, a 25″ aberration and a 60″ polynomial) and
//    costs 183 instructions on the M3 instead of the separate rotation's 613,
//    70 on the M4F instead of 153 (docs/figures.md).
// Why the head's own frame: the Sun heats the bench by where it stands in the
// spacecraft's frame, which on a nadir-pointing spacecraft is the orbital
// frame (v̂, n̂, r̂) the study chose (bench/inside_orbit_terms.py), and every
// solution carries it, from its attitude and its time, with no state.
// Domain: |S| row sums ≤ kMaxThermalAngleRad, as the polynomial's angles;
// s_icrf of unit norm. An attitude error of ε rad moves s_chu by ε: the
// term's angle by ≤ |S|·ε (5e-5 of the term for a 10″ attitude error).
// Scalars: double, float and Q30. In Q30 (q_formats.hpp) the angles are one
// kernel of their own (plus_sun_term_angles, below, with its range and
// rounding: ≤ 2⁻³¹ rad per angle plus the coefficients' conversion, each
// rounded to nearest once, ≤ 2⁻³¹ rad, relative 4.8e-5 of a 2″ coefficient);
// the rotation runs on the core's Q30 kernels (thermal.hpp's
// thermal_rotation; for the contract's form also quaternion.hpp's
// add_left_increment and renormalized_sum), with their rounding (thermal.hpp:
// 7.7e-4″). An angle at the domain's edge may pass thermal_rotation's clamp
// by a few LSB, which it then removes.
#pragma once

#include <cstdint>

#include "heads.hpp"
#include "model_terms.hpp"
#include "quaternion.hpp"
#include "thermal.hpp"
#include "vector3.hpp"

namespace ascorr {

inline constexpr std::uint8_t kSunComponents = 3;  // s_chu x, y, z

template <typename T>
struct SunTermModel {
    bool present[kMaxHeads];                               // false: the head has no Sun term
    T coefficient[kMaxHeads][kModelAxes][kSunComponents];  // rad per unit of s_chu's component
};

// Whether head h's coefficients hold a term (one not 0), whatever present[h]
// says: what a producer sets present[h] from. Precondition: h < kMaxHeads.
template <typename T>
constexpr bool any_sun_coefficient(const SunTermModel<T>& m, std::uint8_t head) noexcept {
    constexpr T zero = constant<T>(0.0);
    bool any = false;
    for (const auto& row : m.coefficient[head]) {
        for (const T& c : row) {
            any = any || !(c == zero);
        }
    }
    return any;
}

// Whether head h has a Sun term (present, and a coefficient not 0): where it
// has none the term is the identity and needs no Sun direction.
template <typename T>
constexpr bool has_sun_term(const SunTermModel<T>& m, std::uint8_t head) noexcept {
    return head < kMaxHeads && m.present[head] && any_sun_coefficient(m, head);
}

// present[h] kept only where head h has a term (a coefficient not 0), as
// every producer of a model leaves it: the flight form (correct.hpp) keys on
// present alone, with no loop per solution. (The host's model file decides
// it on its double coefficients: a term that rounds to 0 in float or Q30
// stays present there, with angles of 0; the link refuses such a term.)
template <typename T>
constexpr void keep_present_where_terms(SunTermModel<T>& m) noexcept {
    for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
        m.present[h] = has_sun_term(m, h);
    }
}

// v rotated by q: R(q)·v, the components in q's target frame of a vector
// given in its source frame (q_b_a maps a into b). Unit q = (w, u):
//   R(q)·v = q ⊗ (0, v) ⊗ q* = v + 2·m,  m = w·t + u × t,  t = u × v,
// 15 products instead of the two quaternion products' 24. Range (Q30): unit
// q and v give |t| ≤ 1 and |m| ≤ |u|·(|w| + |u|) ≤ (1 + √2)/2 per component,
// and v + m = (v + R(q)·v)/2 within ±1, so no sum saturates.
template <typename T>
constexpr Vector3<T> rotated(const Quaternion<T>& q, const Vector3<T>& v) noexcept {
    const Vector3<T> u{q.x, q.y, q.z};
    const Vector3<T> t = cross(u, v);
    const Vector3<T> m = q.w * t + cross(u, t);
    return (v + m) + m;
}

// base + the term's angles (alpha, beta, gamma as x, y, z; rad) for head h
// at attitude q_chu_icrf: base + S·ŝ_chu. base is the polynomial's angles
// where the term is folded into its rotation (correct.hpp), else 0.
// Precondition: h < kMaxHeads.
template <typename T>
constexpr Vector3<T> plus_sun_term_angles(const Vector3<T>& base, const SunTermModel<T>& m, std::uint8_t head,
                                          const Quaternion<T>& q_chu_icrf, const Vector3<T>& s_icrf) noexcept {
    const Vector3<T> s_chu = rotated(q_chu_icrf, s_icrf);
    const auto angle = [&](std::uint8_t a) {
        const T(&c)[kSunComponents] = m.coefficient[head][a];
        return dot(Vector3<T>{c[0], c[1], c[2]}, s_chu);
    };
    return base + Vector3<T>{angle(0), angle(1), angle(2)};
}

// In Q30 (q_formats.hpp): plus_sun_term_angles as one kernel, each component a
// chain of exact products rounded once (fx::narrow), with no saturation:
//   t = u × s      two products per component, |t| ≤ |u|·|s| ≤ 1;
//   m = w·t + u × t  three, |m| ≤ (1 + √2)/2 (rotated(), above);
//   ŝ_chu = s + m + m, exact, in 32-bit modular sums: s + m = (s + ŝ_chu)/2
//     and ŝ_chu are within ±1, so the true sums never wrap;
//   angle = base + c · ŝ_chu  three, base the accumulator's start (no
//     instruction of its own); |c| row sums ≤ kMaxThermalAngleRad (the
//     model's domain, raw < 2²⁵) and |base| ≤ kMaxThermalAngleRad (the
//     polynomial's, checked before), so the result is within ±2° (raw < 2²⁶).
// Range: q unit within the core's tolerance (|qᵢ| ≤ 1 + 2⁻²⁰, as the core
// validates it) and s unit (|sᵢ| ≤ 1 + 2⁻²⁰; the producer forms it so): no
// int64 sum exceeds 3·2⁶⁰·(1 + 2⁻¹⁹) < 2⁶³. Outside that range (|sᵢ| up to 2)
// the int64 sums still fit (≤ 2⁶²·1.0001 for t, 3·2⁶¹·1.0001 for m, using
// |t|'s raw, whatever it wrapped to, ≤ 2³¹) and the 32-bit sums are
// modular: the angles are then wrong, never undefined.
// Rounding: t ≤ 2⁻³¹; m ≤ 2⁻³¹ plus (|w| + 2|u|)·2⁻³¹ carried from t; ŝ_chu
// twice m's, ≤ 8·2⁻³¹ = 3.7e-9; each sum ≤ 2⁻³¹ rad (9.6e-5″) plus
// |S|·3.7e-9 (≤ 6.5e-11 rad for |S| ≤ 3600″), as the generic form's within a few LSB.
constexpr Vector3<Q30> plus_sun_term_angles(const Vector3<Q30>& base, const SunTermModel<Q30>& m, std::uint8_t head,
                                            const Quaternion<Q30>& q_chu_icrf, const Vector3<Q30>& s_icrf) noexcept {
    using fx::narrow;
    using fx::unshared;
    const std::int32_t w = unshared(q_chu_icrf.w.raw);
    const std::int32_t ux = unshared(q_chu_icrf.x.raw);
    const std::int32_t uy = unshared(q_chu_icrf.y.raw);
    const std::int32_t uz = unshared(q_chu_icrf.z.raw);
    const std::int32_t sx = unshared(s_icrf.x.raw);
    const std::int32_t sy = unshared(s_icrf.y.raw);
    const std::int32_t sz = unshared(s_icrf.z.raw);
    const auto negated = [](std::int32_t v) {  // modular: −(−2) is no concern of a validated q, and never UB
        return unshared(static_cast<std::int32_t>(0U - static_cast<std::uint32_t>(v)));
    };
    const std::int32_t nux = negated(ux);
    const std::int32_t nuy = negated(uy);
    const std::int32_t nuz = negated(uz);
    const std::int32_t tx = unshared(narrow<30>(0, uy, sz, nuz, sy));
    const std::int32_t ty = unshared(narrow<30>(0, uz, sx, nux, sz));
    const std::int32_t tz = unshared(narrow<30>(0, ux, sy, nuy, sx));
    const auto twice_plus = [](std::int32_t v, std::int32_t h) {  // v + 2h, modular (above)
        const auto u = static_cast<std::uint32_t>(h);
        return unshared(static_cast<std::int32_t>(static_cast<std::uint32_t>(v) + u + u));
    };
    const std::int32_t cx = twice_plus(sx, narrow<30>(0, w, tx, uy, tz, nuz, ty));
    const std::int32_t cy = twice_plus(sy, narrow<30>(0, w, ty, uz, tx, nux, tz));
    const std::int32_t cz = twice_plus(sz, narrow<30>(0, w, tz, ux, ty, nuy, tx));
    const auto angle = [&](std::uint8_t a, Q30 b) {
        const Q30(&c)[kSunComponents] = m.coefficient[head][a];
        return Q30{narrow<30>(std::int64_t{b.raw} * (std::int64_t{1} << 30), unshared(c[0].raw), cx, unshared(c[1].raw),
                              cy, unshared(c[2].raw), cz)};
    };
    return {angle(0, base.x), angle(1, base.y), angle(2, base.z)};
}
template <>
Vector3<Q30> plus_sun_term_angles<Q30>(const Vector3<Q30>&, const SunTermModel<Q30>&, std::uint8_t,
                                       const Quaternion<Q30>&, const Vector3<Q30>&) noexcept = delete;

// The term's rotation for head h at attitude q_chu_icrf, or the identity for
// a head without one.
template <typename T>
constexpr SmallRotation<T> sun_term_rotation(const SunTermModel<T>& m, std::uint8_t head,
                                             const Quaternion<T>& q_chu_icrf, const Vector3<T>& s_icrf) noexcept {
    constexpr T zero = constant<T>(0.0);
    if (head >= kMaxHeads || !m.present[head]) {
        return {zero, {zero, zero, zero}};
    }
    const Vector3<T> a = plus_sun_term_angles(Vector3<T>{zero, zero, zero}, m, head, q_chu_icrf, s_icrf);
    return thermal_rotation(a.x, a.y, a.z);
}

// q_sun ⊗ q, renormalised and with w ≥ 0, as correct_solution() ends
// (correct.hpp): the term applied to an attitude the core has corrected.
template <typename T>
constexpr Quaternion<T> with_sun_term(const Quaternion<T>& q, const SmallRotation<T>& q_sun) noexcept {
    constexpr T zero = constant<T>(0.0);
    return canonical(renormalized_sum(q, add_left_increment(Quaternion<T>{zero, zero, zero, zero}, q_sun, q)));
}

}  // namespace ascorr
