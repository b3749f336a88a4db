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
//  - Applied as the thermal stage is, on the CHU side: q ← q_sun ⊗ q with
//    q_sun = thermal_rotation(angles). Applied after the polynomial's q_th it
//    differs from the rotation of the summed angles by the two rotations'
//    commutator, ≤ |θ_th|·|θ_sun|/2 rad (2.9e-4″ for 60″ and 2″).
// Why the head's own frame: the Sun heats the bench by where it stands in the
// spacecraft's frame, which on a nadir-pointing spacecraft is the orbital
// frame (v̂, n̂, r̂) the study chose (bench/inside_orbit_terms.py), and every
// solution carries it, from its attitude and its time, with no state.
// Domain: |S| row sums ≤ kMaxThermalAngleRad, as the polynomial's angles;
// s_icrf of unit norm. An attitude error of ε rad moves s_chu by ε: the
// term's angle by ≤ |S|·ε (5e-5 of the term for a 10″ attitude error).
// Scalars: double, float and Q30. In Q30 (q_formats.hpp) the same templates
// run on the core's Q30 kernels (quaternion.hpp's product, add_left_increment
// and renormalized_sum, thermal.hpp's thermal_rotation), with:
//  - range: q and s_icrf unit, so every component of q ⊗ (0, s) ⊗ q* and of
//    s_chu is within ±1 (+ rounding): no product or sum saturates; the
//    coefficients in rad within ±kMaxThermalAngleRad (the model's domain:
//    |S| row sums ≤ 3600″), raw < 2²⁵; each angle Σ_m S[a][m]·s_chu[m]
//    within ±kMaxThermalAngleRad too, so its two saturating additions never
//    act;
//  - rounding: each coefficient rounded to nearest once at conversion
//    (≤ 2⁻³¹ rad, 9.6e-5″, relative 4.8e-5 of a 2″ coefficient); s_chu's
//    components two products each rounded, the first's error carried
//    through the second (≤ 3·2⁻³¹); each angle three products rounded
//    (≤ 3·2⁻³¹ rad) plus the coefficients' and s_chu's (Σ|s_chu| ≤ √3):
//    ≤ 5e-9 rad, 1e-3″ per angle (an angle at the domain's edge may pass
//    thermal_rotation's clamp by those few LSB, which it then removes);
//    thermal_rotation's and the increment's rounding as the polynomial's
//    (thermal.hpp: 7.7e-4″).
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

// Whether head h has a Sun term (a coefficient not 0): where it has none the
// term is the identity and needs no Sun direction.
template <typename T>
constexpr bool has_sun_term(const SunTermModel<T>& m, std::uint8_t head) noexcept {
    constexpr T zero = constant<T>(0.0);
    bool any = false;
    for (std::uint8_t a = 0; head < kMaxHeads && m.present[head] && a < kModelAxes; ++a) {
        for (std::uint8_t c = 0; c < kSunComponents; ++c) {
            any = any || !(m.coefficient[head][a][c] == zero);
        }
    }
    return any;
}

// v rotated by q: R(q)·v, the components in q's target frame of a vector
// given in its source frame (q_b_a maps a into b). Unit q.
template <typename T>
constexpr Vector3<T> rotated(const Quaternion<T>& q, const Vector3<T>& v) noexcept {
    const Quaternion<T> p{constant<T>(0.0), v.x, v.y, v.z};
    const Quaternion<T> r = q * p * conjugate(q);
    return {r.x, r.y, r.z};
}

// The term's rotation for head h at attitude q_chu_icrf, or the identity for
// a head without one.
template <typename T>
constexpr SmallRotation<T> sun_term_rotation(const SunTermModel<T>& m, std::uint8_t head,
                                             const Quaternion<T>& q_chu_icrf, const Vector3<T>& s_icrf) noexcept {
    constexpr T zero = constant<T>(0.0);
    if (head >= kMaxHeads || !m.present[head]) {
        return {zero, {zero, zero, zero}};
    }
    const Vector3<T> s_chu = rotated(q_chu_icrf, s_icrf);
    const auto angle = [&](std::uint8_t a) {
        const T(&c)[kSunComponents] = m.coefficient[head][a];
        return c[0] * s_chu.x + c[1] * s_chu.y + c[2] * s_chu.z;
    };
    return thermal_rotation(angle(0), angle(1), angle(2));
}

// q_sun ⊗ q, renormalised and with w ≥ 0, as correct_solution() ends
// (correct.hpp): the term applied to an attitude the core has corrected.
template <typename T>
constexpr Quaternion<T> with_sun_term(const Quaternion<T>& q, const SmallRotation<T>& q_sun) noexcept {
    constexpr T zero = constant<T>(0.0);
    return canonical(renormalized_sum(q, add_left_increment(Quaternion<T>{zero, zero, zero, zero}, q_sun, q)));
}

}  // namespace ascorr
