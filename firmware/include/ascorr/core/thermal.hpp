// ascorr/core/thermal.hpp: the thermal model of Herceg, Jørgensen & Jørgensen 2017.
//
// Conventions (docs/contract.md, paper eqs. 4–10):
//  - Per head and axis: angle = c0 + c1·T1 + c2·(T2 − T1) + c3·(T3 − T1)
//      + c1_2·T1² + c2_2·(T2 − T1)² + c3_2·(T3 − T1)²,
//    T1 = T_CHU, T2 = T_THT00029, T3 = T_THT00032 in °C. Here the coefficients
//    are stored in radians (rad, rad/°C, rad/°C²); model files are in arcsec and
//    are converted once when loaded.
//  - R_corr = R3(γ)·R2(β)·R1(α)·R_raw with the paper's (passive) elementary
//    matrices, R1(a) = [[1,0,0],[0,cos a,sin a],[0,−sin a,cos a]] etc. Each is
//    the active rotation by −angle about its axis, so as quaternions
//    q1 = (cos α/2, −sin α/2, 0, 0), q2 = (cos β/2, 0, −sin β/2, 0),
//    q3 = (cos γ/2, 0, 0, −sin γ/2), and q_th = q3 ⊗ q2 ⊗ q1 is applied on the
//    CHU side: q_chu_icrf_corr = q_th ⊗ q_chu_icrf.
//
// Small-angle series, |angle| ≤ kMaxThermalAngleRad (1°), so h = angle/2 ≤ 8.73e-3:
//   cos h ≈ 1 − h²/2·(1 − h²/12),  truncation ≤ h⁶/720  = 6.1e-16;
//   sin h ≈ h·(1 − h²/6·(1 − h²/20)), truncation ≤ h⁷/5040 = 7.6e-19.
// Both are at or below double rounding; the cos error only scales the norm.
//
// Without double precision (float; Q30 has the same form in fixed_point.hpp)
// the rotation is returned as q_th/(c1c2c3), cᵢ = cos hᵢ: a positive multiple
// of q_th, hence the same rotation, and with tᵢ = tan hᵢ exactly
//   (1 − t1t2t3, −t1 − t2t3, −t2 + t1t3, −t1t2 − t3),
// four products instead of sixteen. tan h ≈ h·(1 + h²/3), truncation
// ≤ 2h⁵/15 = 6.7e-12. Its norm² is Π(1 + tᵢ²) ≤ 1 + 2.3e-4; the final
// renormalisation (one Newton step, quaternion.hpp) takes it out to
// ‖q‖² − 1 ≥ −3ε²/4 ≥ −4e-8 at the domain's limit, below float's resolution.
#pragma once

#include <cstdint>

#include "constants.hpp"
#include "heads.hpp"
#include "quaternion.hpp"
#include "scalar_traits.hpp"

namespace ascorr {

// One axis of one head: radians and rad/°C, rad/°C².
template <typename T>
struct AxisPolynomial {
    Coefficient<T> c0;
    Coefficient<T> c1;
    Coefficient<T> c2;
    Coefficient<T> c3;
    QuadraticCoefficient<T> c1_2;
    QuadraticCoefficient<T> c2_2;
    QuadraticCoefficient<T> c3_2;
};

template <typename T>
struct HeadThermalModel {
    bool present;  // false: no coefficients for this head, thermal stage skipped
    AxisPolynomial<T> alpha;
    AxisPolynomial<T> beta;
    AxisPolynomial<T> gamma;
};

template <typename T>
struct ThermalModel {
    HeadThermalModel<T> head[kMaxHeads];  // by head index (heads.hpp)
};

template <typename T>
struct TemperatureReading {
    Celsius<T> value;
    bool valid;  // false: missing, or withheld by the acquisition (fault, stale)
};

template <typename T>
struct HeadTemperatures {
    TemperatureReading<T> t_chu;  // T1, the head's own (CCD) temperature
    TemperatureReading<T> t_029;  // T2, THT00029, optical bench / boom interface
    TemperatureReading<T> t_032;  // T3, THT00032, optical bench next to the SiC cube
};

// A usable temperature: finite and inside ±kMaxAbsTemperatureC (false for a
// NaN or an infinity).
template <typename T>
constexpr bool temperature_in_domain(const Celsius<T>& t) noexcept {
    constexpr Celsius<T> lim = ScalarTraits<T>::celsius(kMaxAbsTemperatureC);
    return abs_within(t, lim);
}

// The model angle of one axis, in radians. A fixed-point scalar overloads this
// (the coefficient and temperature formats differ from T's).
template <typename T>
constexpr T thermal_angle(const AxisPolynomial<T>& p, const Celsius<T>& t1, const Celsius<T>& t2,
                          const Celsius<T>& t3) noexcept {
    const Celsius<T> d2 = t2 - t1;
    const Celsius<T> d3 = t3 - t1;
    return p.c0 + t1 * (p.c1 + p.c1_2 * t1) + d2 * (p.c2 + p.c2_2 * d2) + d3 * (p.c3 + p.c3_2 * d3);
}

template <typename T>
struct HalfAngle {
    T cm1;  // cos(angle/2) − 1, kept small for precision
    T s;    // sin(angle/2)
};

// cos and sin of half an angle, |angle| ≤ kMaxThermalAngleRad (series above).
template <typename T>
constexpr HalfAngle<T> half_angle(const T& angle) noexcept {
    constexpr T one = constant<T>(1.0);
    constexpr T half = constant<T>(0.5);
    constexpr T twelfth = constant<T>(1.0 / 12.0);
    constexpr T sixth = constant<T>(1.0 / 6.0);
    constexpr T twentieth = constant<T>(0.05);
    const T h = half * angle;
    const T h2 = h * h;
    return {-(half * h2 * (one - twelfth * h2)), h * (one - sixth * h2 * (one - twentieth * h2))};
}

// q_th = q3(γ) ⊗ q2(β) ⊗ q1(α) (double precision; without, the multiple of
// it described at the top), expanded (16 products instead of 32), with
// c_i = 1 + cm1_i and s_i the half-angle cosines and sines:
//   w =  c1c2c3 − s1s2s3      x = −s1c2c3 − c1s2s3
//   y = −c1s2c3 + s1c2s3      z = −s1s2c3 − c1c2s3
// w − 1 is formed from the cm1 terms, never as a difference of near-ones.
template <typename T>
constexpr SmallRotation<T> thermal_rotation(const T& alpha, const T& beta, const T& gamma) noexcept {
    if constexpr (!ScalarTraits<T>::double_precision) {
        const auto tan_half = [](const T& angle) {
            constexpr T half = constant<T>(0.5);
            constexpr T third = constant<T>(1.0 / 3.0);
            const T h = half * angle;
            return h + third * (h * h) * h;
        };
        const T t1 = tan_half(alpha);
        const T t2 = tan_half(beta);
        const T t3 = tan_half(gamma);
        const T t12 = t1 * t2;
        return {-(t12 * t3), {-(t1 + t2 * t3), t1 * t3 - t2, -(t12 + t3)}};
    }
    const HalfAngle<T> a = half_angle(alpha);
    const HalfAngle<T> b = half_angle(beta);
    const HalfAngle<T> g = half_angle(gamma);
    constexpr T one = constant<T>(1.0);
    const T ac = one + a.cm1;
    const T bc = one + b.cm1;
    const T gc = one + g.cm1;
    const T ccm1 = a.cm1 + b.cm1 + a.cm1 * b.cm1;  // c1c2 − 1
    const T cc = one + ccm1;
    const T sc = a.s * bc;
    const T cs = ac * b.s;
    const T ss = a.s * b.s;
    return {ccm1 + g.cm1 + ccm1 * g.cm1 - ss * g.s, {-(sc * gc + cs * g.s), sc * g.s - cs * gc, -(ss * gc + cc * g.s)}};
}

}  // namespace ascorr
