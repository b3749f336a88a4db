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
// Without double precision (float; Q30 has the same form, below)
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
#include "model_terms.hpp"
#include "q_formats.hpp"
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

// Calls f(TermIndex<k>{}, coefficient k) for p's coefficients in the order
// of kModelTermTable (model_terms.hpp): the one place that lists the fields
// by term. P is AxisPolynomial<T>, const or not.
template <typename P, typename F>
constexpr void for_each_term(P& p, F&& f) noexcept {
    static_assert(kModelTerms == 7, "AxisPolynomial has a field per term of kModelTermTable, in its order");
    f(TermIndex<0>{}, p.c0);
    f(TermIndex<1>{}, p.c1);
    f(TermIndex<2>{}, p.c2);
    f(TermIndex<3>{}, p.c3);
    f(TermIndex<4>{}, p.c1_2);
    f(TermIndex<5>{}, p.c2_2);
    f(TermIndex<6>{}, p.c3_2);
}

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
// (the coefficient and temperature formats differ from T's). Written out by
// term, grouped by regressor (Horner: x·(c + c_2·x)), not a loop over the
// table: a loop would sum in another order and change float's results.
// Always inlined, as the Q30 one: left to GCC, the float core called it out
// of line once the thermal stage grew a Sun term (M4F: 326 instructions per
// solution instead of the 278 it then took).
template <typename T>
[[gnu::always_inline]] constexpr T thermal_angle(const AxisPolynomial<T>& p, const Celsius<T>& t1, const Celsius<T>& t2,
                                                 const Celsius<T>& t3) noexcept {
    static_assert(kModelTerms == 7, "thermal_angle evaluates every term of kModelTermTable");
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

// ---- In Q30 (q_formats.hpp): thermal_angle is a specialisation of the
// template above; thermal_rotation an overload followed by its guard
// (vector3.hpp).
namespace fx {

// (t·2⁻²⁰)² in units of 2⁻¹² °C², rounded to nearest. |t| ≤ 2²⁹ (≤ 512 °C):
// t² ≤ 2⁵⁸ fits int64 and the result ≤ 2¹⁸·2¹² = 2³⁰ fits int32. Error ≤ 2⁻¹³ °C².
constexpr std::int32_t square_celsius(std::int32_t t) noexcept {
    const std::int32_t u = unshared(t);
    return narrow<2 * QCelsius::kFracBits - 12>(mul(u, u));
}

// Clamps a temperature to [−2²⁸, 2²⁸ − 1] raw (±256 °C; one SSAT on Armv7-M):
// then a difference of two is within ±2²⁹ (±512 °C) in int32, the range for
// which thermal_angle's 64-bit sums cannot overflow. Readings inside the
// core's domain (±200 °C) pass unchanged.
constexpr std::int32_t clamp_celsius(std::int32_t t) noexcept {
    constexpr std::int32_t hi = (std::int32_t{1} << 28) - 1;
    constexpr std::int32_t lo = -(std::int32_t{1} << 28);
    return t > hi ? hi : (t < lo ? lo : t);
}

}  // namespace fx

// The model angle in Q30 rad from QCoefficient / QQuadraticCoefficient
// coefficients and QCelsius temperatures (above for the polynomial).
// All products in int64:
//   linear    c·T  : |c| < 2³¹, |T| ≤ 2²⁹ → < 2⁶⁰ each, units 2⁻⁵⁶ rad;
//   quadratic c·T² : |c| < 2³¹, T² ≤ 2³⁰ (units 2⁻¹²) → < 2⁶¹ each, units 2⁻⁶⁰
//                    rad, their sum (< 1.5·2⁶²) rounded once to 2⁻⁵⁶ (→ < 1.5·2⁵⁸);
//   the sum in units of 2⁻⁵⁶: c0·2²⁰ + Σlin + Σquad < 2⁵¹ + 3·2⁶⁰ + 1.5·2⁵⁸ < 2⁶²,
//     no overflow for any input, because temperatures are clamped to ±256 °C
//     first, so that they and their differences are within ±512 °C (the core
//     calls this only for readings inside ±200 °C, where the clamp does nothing).
// Result rounded once to Q30 (error ≤ 2⁻³¹ rad = 9.6e-5") and saturated (the
// core then flags it beyond kMaxThermalAngleRad). Other rounding, in rad:
// T² ≤ 2⁻¹³ °C²·|c_2| (≤ 1e-10 at the largest c_2) and 2⁻⁵⁷ for the
// quadratic terms together. Coefficient and temperature quantisation (the inputs) add ≤ 2⁻³⁷·|T|,
// 2⁻⁴⁹·T² and 2⁻²¹·|c| per term.
// The three quadratic products are skipped for an axis whose quadratic
// coefficients are all zero (the usual linear model): same result, fewer
// instructions. A branch, not a loop: the instruction count stays bounded.
// Written out by term, not a loop over kModelTermTable: the bound on the sum
// above is argued term by term, and the linear terms share one
// multiply-accumulate chain (sum_products) that a loop would not keep.
template <>
[[gnu::always_inline]] constexpr Q30 thermal_angle<Q30>(const AxisPolynomial<Q30>& p, const QCelsius& t1,
                                                        const QCelsius& t2, const QCelsius& t3) noexcept {
    static_assert(kModelTerms == 7 && kLinearModelTerms == 4, "the Q30 kernel evaluates c0 … c3, c1_2 … c3_2");
    using fx::mul;
    constexpr int kSumFrac = QCoefficient::kFracBits + QCelsius::kFracBits;       // 56
    constexpr int kQuadShift = QQuadraticCoefficient::kFracBits + 12 - kSumFrac;  // 4
    const std::int32_t a = fx::clamp_celsius(t1.raw);
    const std::int32_t d2 = fx::clamp_celsius(t2.raw) - a;
    const std::int32_t d3 = fx::clamp_celsius(t3.raw) - a;
    std::int64_t sum =
        fx::sum_products(p.c0.raw, std::int32_t{1} << QCelsius::kFracBits, p.c1.raw, a, p.c2.raw, d2, p.c3.raw, d3);
    if ((p.c1_2.raw | p.c2_2.raw | p.c3_2.raw) != 0) {
        sum += fx::round_shift<kQuadShift>(fx::sum_products(
            p.c1_2.raw, fx::square_celsius(a), p.c2_2.raw, fx::square_celsius(d2), p.c3_2.raw, fx::square_celsius(d3)));
    }
    return {fx::narrow_sat<kSumFrac - Q30::kFracBits>(sum)};
}

// The thermal rotation in Q30 (above: q_th = q3(γ) ⊗ q2(β) ⊗ q1(α)),
// in the format's own, cheaper form: q_th divided by c1c2c3 (cᵢ = cos hᵢ,
// hᵢ = angleᵢ/2), a positive multiple of q_th and so the same rotation. With
// tᵢ = tan hᵢ each factor is (1, −tᵢ·axisᵢ) and the product is exactly
//   q_th/(c1c2c3) = (1 − t1t2t3, −t1 − t2t3, −t2 + t1t3, −t1t2 − t3):
// four products instead of sixteen. Its norm² is Π(1 + tᵢ²) ≤ 1 + 2.3e-4
// (angles ≤ 1°); renormalized_sum() removes that with its second-order step.
//
// Range: each angle is first clamped to ±kMaxThermalAngleRad (the core calls
// this only after checking that bound, so the clamp never acts there): then
// |a| < 2²⁵ raw, |h| ≤ 8.73e-3, |t| ≤ 8.74e-3 and every product is far inside
// int64, every result inside ±2⁻⁶: no saturation is needed.
// Series: tan h = h·(1 + h²/3) + O(2h⁵/15 ≤ 6.7e-12), with h²/6 taken as
// h²·⌈2³²/6⌉·2⁻³² (relative error 5e-10 of a term ≤ 1.3e-5).
// Rounding: h², h²/6, t, the products: ≤ 2⁻³¹ each, ≤ 2·2⁻³⁰ per component
// (7.7e-4" as a rotation: an error δ in the vector part turns by 2δ).
namespace fx {

// tan(angle/2) in Q30, |angle| clamped to ≤ kMaxThermalAngleRad.
constexpr std::int32_t tan_half_angle(Q30 angle) noexcept {
    constexpr std::int32_t lim = raw_from_double<Q30::kFracBits>(kMaxThermalAngleRad);
    constexpr std::int32_t kSixth = 715827883;  // ⌈2³²/6⌉
    const std::int32_t a = unshared(angle.raw > lim ? lim : (angle.raw < -lim ? -lim : angle.raw));
    const std::int32_t h2 = narrow<32>(mul(a, a));  // (a/2)², Q30, < 2¹⁷
    const std::int32_t half_1_h2_3 = (std::int32_t{1} << 29) + narrow<32>(mul(h2, kSixth));
    return fx::narrow<30>(0, a, half_1_h2_3);  // (a/2)·(1 + h²/3)
}

}  // namespace fx

constexpr SmallRotation<Q30> thermal_rotation(const Q30& alpha, const Q30& beta, const Q30& gamma) noexcept {
    const std::int32_t t1 = fx::tan_half_angle(alpha);
    const std::int32_t t2 = fx::tan_half_angle(beta);
    const std::int32_t t3 = fx::tan_half_angle(gamma);
    const std::int32_t t12 = fx::narrow<30>(0, t1, t2);
    const std::int32_t t13 = fx::narrow<30>(0, t1, t3);
    const std::int32_t t23 = fx::narrow<30>(0, t2, t3);
    const std::int32_t t123 = fx::narrow<30>(0, t12, t3);
    return {{-t123}, {{-t1 - t23}, {t13 - t2}, {-t12 - t3}}};
}
template <>
SmallRotation<Q30> thermal_rotation<Q30>(const Q30&, const Q30&, const Q30&) noexcept = delete;

}  // namespace ascorr
