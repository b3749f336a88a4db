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
//    costs 136 instructions on the M3 instead of the separate rotation's 613,
//    63 on the M4F instead of 153 (docs/figures.md).
// Why the head's own frame: the Sun heats the bench by where it stands in the
// spacecraft's frame, which on a nadir-pointing spacecraft is the orbital
// frame (v̂, n̂, r̂) the study chose (bench/inside_orbit_terms.py), and every
// solution carries it, from its attitude and its time, with no state.
// Domain: |S| row sums ≤ kMaxThermalAngleRad, as the polynomial's angles;
// s_icrf of unit norm. An attitude error of ε rad moves s_chu by ε: the
// term's angle by ≤ |S|·ε (5e-5 of the term for a 10″ attitude error).
// Scalars: double, float and Q30. In Q30 (q_formats.hpp) the angles are one
// kernel of their own (plus_sun_term_angles, below, with its range and
// rounding: ≤ 2⁻³¹ rad per angle plus |S| row sum · 7·2⁻²⁶ from ŝ_chu, plus
// the coefficients' conversion, each rounded to nearest once, ≤ 2⁻³¹ rad,
// relative 4.8e-5 of a 2″ coefficient);
// the rotation runs on the core's Q30 kernels (thermal.hpp's
// thermal_rotation; for the contract's form also quaternion.hpp's
// add_left_increment and renormalized_sum), with their rounding (thermal.hpp:
// 7.7e-4″). An angle at the domain's edge may pass thermal_rotation's clamp
// by a few LSB, which it then removes.
#pragma once

#include <cstddef>
#include <cstdint>

#include "constants.hpp"
#include "heads.hpp"
#include "model_terms.hpp"
#include "quaternion.hpp"
#include "scalar_traits.hpp"
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

// Whether some head of m has a term (present: as keep_present_where_terms
// or sun_term_from_arcsec leave it).
template <typename T>
constexpr bool any_sun_term(const SunTermModel<T>& m) noexcept {
    bool any = false;
    for (const bool p : m.present) {
        any = any || p;
    }
    return any;
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

// A term given in arcsec (sun[h][a][m], as a model file's sun_x, sun_y,
// sun_z and the self-calibration's learnt term hold it; Arcsec: any array so
// indexable) in the core's units in T: each coefficient × kArcsecToRad
// rounded to T once; present[h] where a coefficient is not 0 in double, so
// that a term that rounds to 0 in T still needs the Sun's direction (128
// beyond 2051), as in double; its angles are then 0. The one conversion of
// every producer in T (the host's model reader, the link server's learnt
// term), so that they hold the same bits.
template <typename T, typename Arcsec>
constexpr SunTermModel<T> sun_term_from_arcsec(const Arcsec& sun) noexcept {
    SunTermModel<T> out{};
    for (std::size_t h = 0; h < kMaxHeads; ++h) {
        out.present[h] = false;
        for (std::size_t a = 0; a < kModelAxes; ++a) {
            for (std::size_t c = 0; c < kSunComponents; ++c) {
                out.present[h] = out.present[h] || sun[h][a][c] != 0.0;
                out.coefficient[h][a][c] = ScalarTraits<T>::from_double(sun[h][a][c] * kArcsecToRad);
            }
        }
    }
    return out;
}

// v rotated by q: R(q)·v, the components in q's target frame of a vector
// given in its source frame (q_b_a maps a into b). Unit q = (w, u):
//   R(q)·v = q ⊗ (0, v) ⊗ q* = v + 2·m,  m = w·t + u × t,  t = u × v,
// 15 products instead of the two quaternion products' 24; |t| ≤ 1 and
// |m| ≤ |u|·(|w| + |u|) ≤ (1 + √2)/2 per component for unit q and v. v + 2·m
// is written as one product and one sum (2·m is exact): one rounding, and
// one FMA where the build fuses.
template <typename T>
constexpr Vector3<T> rotated(const Quaternion<T>& q, const Vector3<T>& v) noexcept {
    const Vector3<T> u{q.x, q.y, q.z};
    const Vector3<T> t = cross(u, v);
    const Vector3<T> m = q.w * t + cross(u, t);
    return v + constant<T>(2.0) * m;
}

// base + the term's angles (alpha, beta, gamma as x, y, z; rad) for head h
// at attitude q_chu_icrf: base + S·ŝ_chu, each angle summed from base, a
// product at a time (three FMA where the build fuses). base is the
// polynomial's angles where the term is folded into its rotation
// (correct.hpp), else 0. Precondition: h < kMaxHeads.
template <typename T>
constexpr Vector3<T> plus_sun_term_angles(const Vector3<T>& base, const SunTermModel<T>& m, std::uint8_t head,
                                          const Quaternion<T>& q_chu_icrf, const Vector3<T>& s_icrf) noexcept {
    const Vector3<T> s_chu = rotated(q_chu_icrf, s_icrf);
    const auto angle = [&](std::uint8_t a, T b) {
        const T(&c)[kSunComponents] = m.coefficient[head][a];
        return ((b + c[0] * s_chu.x) + c[1] * s_chu.y) + c[2] * s_chu.z;
    };
    return {angle(0, base.x), angle(1, base.y), angle(2, base.z)};
}

// In Q30 (q_formats.hpp): plus_sun_term_angles as one kernel. ŝ_chu feeds
// only the term, a small angle (|S| row sums ≤ kMaxThermalAngleRad), so it is
// formed from the high words of single SMULLs (fx::mul_high, ⌊a·b·2⁻³²⌋) in
// 32-bit sums, at 2⁻²⁶, and only the angles are 64-bit sums rounded once:
//   t = u × s      at 2⁻²⁸ (Q30·Q30·2⁻³²), |t| ≤ |u|·|s| ≤ 1 + 2⁻¹⁹;
//   m = w·t + u × t  at 2⁻²⁶, |m| ≤ (1 + √2)/2 (rotated(), above);
//   ŝ_chu = s·2⁻⁴ + 2m  at 2⁻²⁶ (s's arithmetic shift), within ±(1 + 2⁻¹⁸);
//   angle = base + round(c · ŝ_chu · 2⁻²⁶)  three SMLAL from the rounding
//     constant; base (Q30) added after the shift: base·2²⁶ is a multiple of
//     2²⁶, so the same bits as a sum started from base·2²⁶.
// Range: with q and s unit within the core's tolerance (|qᵢ|, |sᵢ| ≤
// 1 + 2⁻²⁰; the core validates q, the producer forms s unit), every 32-bit
// sum is far from ±2³¹ (|t| raw ≤ 2²⁸·1.0001, |m|, |ŝ_chu| raw ≤ 2²⁶·1.21);
// the 32-bit sums are modular all the same, so that any q and s give wrong
// angles, never undefined behaviour. The angles' int64 sum: |c| row sums <
// 2²⁵ raw (the model's domain) times |ŝ_chu| raw < 2³¹ whatever it wrapped to:
// < 2⁵⁶, fits; the result, base (|base| ≤ kMaxThermalAngleRad, raw < 2²⁵,
// checked before) plus the term (< 2²⁶ raw for a unit ŝ), fits int32.
// Rounding (each mul_high rounds towards −∞, an error in [0, 1) of its LSB):
// t within 2⁻²⁸; m within 2·2⁻²⁶ of its own plus (|w| + |u_y| + |u_z|)·2⁻²⁸
// < 2⁻²⁶ carried from t; ŝ_chu within 2⁻²⁶ (the shift) + 2·3·2⁻²⁶ = 7·2⁻²⁶
// (1.04e-7) per component; each angle within |c| row sum · 1.04e-7 (a
// relative 1e-7 of the term: 6e-7″ for a 6″ row, 3.8e-4″ at the domain's 1°)
// plus 2⁻³¹ rad (9.6e-5″) from its rounding, plus the coefficients' own
// conversion (≤ 2⁻³¹ rad each). Instructions: bench "sun" (docs/figures.md).
constexpr Vector3<Q30> plus_sun_term_angles(const Vector3<Q30>& base, const SunTermModel<Q30>& m, std::uint8_t head,
                                            const Quaternion<Q30>& q_chu_icrf, const Vector3<Q30>& s_icrf) noexcept {
    using fx::mul_high;
    const auto wrap = [](std::uint32_t v) { return static_cast<std::int32_t>(v); };  // modular (above)
    const auto u32 = [](std::int32_t v) { return static_cast<std::uint32_t>(v); };
    const std::int32_t w = q_chu_icrf.w.raw;
    const std::int32_t ux = q_chu_icrf.x.raw;
    const std::int32_t uy = q_chu_icrf.y.raw;
    const std::int32_t uz = q_chu_icrf.z.raw;
    const std::int32_t sx = s_icrf.x.raw;
    const std::int32_t sy = s_icrf.y.raw;
    const std::int32_t sz = s_icrf.z.raw;
    const auto cross = [&](std::int32_t a1, std::int32_t b2, std::int32_t a2, std::int32_t b1) {  // a1·b2 − a2·b1
        return wrap(u32(mul_high(a1, b2)) - u32(mul_high(a2, b1)));
    };
    const std::int32_t tx = cross(uy, sz, uz, sy);
    const std::int32_t ty = cross(uz, sx, ux, sz);
    const std::int32_t tz = cross(ux, sy, uy, sx);
    const auto s_chu = [&](std::int32_t sc, std::int32_t t, std::int32_t cross_t) {  // s·2⁻⁴ + 2(w·t + u × t)
        const std::uint32_t mc = u32(mul_high(w, t)) + u32(cross_t);
        return wrap(u32(sc >> 4) + mc + mc);
    };
    const std::int32_t cx = s_chu(sx, tx, cross(uy, tz, uz, ty));
    const std::int32_t cy = s_chu(sy, ty, cross(uz, tx, ux, tz));
    const std::int32_t cz = s_chu(sz, tz, cross(ux, ty, uy, tx));
    const auto angle = [&](std::uint8_t a, Q30 b) {
        const Q30(&c)[kSunComponents] = m.coefficient[head][a];
        return Q30{wrap(u32(b.raw) + u32(fx::narrow<26>(0, c[0].raw, cx, c[1].raw, cy, c[2].raw, cz)))};
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
