// ascorr/fixed_point.hpp: the fixed-point scalar of the core (DPU without FPU).
//
// Conventions (CMSIS style: every format states range, scaling, rounding and
// saturation; 32-bit storage, 64-bit intermediates, no floating point at run
// time; the double conversions are for constants folded at compile time and for
// the host):
//
//  Q30 (the scalar T): signed Q1.30 ("Q2.30" in ARM's count), value = raw·2⁻³⁰,
//    range [−2, 2 − 2⁻³⁰], resolution 9.3e-10 (1.9e-4" as an angle in rad).
//    Holds unit quaternions and vectors, β = v/c, angles in radians, and the
//    small terms the core forms from them. ±2 is the range a sum of unit terms
//    needs (the core never doubles by multiplying with 2, see boresight()).
//      a + b, a − b, −a : exact when the result is in range, else saturated to
//                         the nearest end of the range (never wraps).
//      a · b            : 64-bit product (exact, |a·b| ≤ 2⁶²), rounded to the
//                         nearest Q30 (ties towards +∞: + 2²⁹, arithmetic shift
//                         right by 30), saturated.  Error ≤ 2⁻³¹.
//      comparisons      : exact.
//      dot, cross, squared_norm, quaternion product, boresight,
//      renormalized_sum : overloads of the core's generic functions that sum
//                         exact products in int64 and round and saturate once
//                         per result (see "Sums of products" below).
//      thermal_angle, thermal_rotation, beta_in_domain : Q30 versions of the
//                         core's functions, each with its range argument.
//    On a Cortex-M3 a product is one SMULL/SMLAL; no floating point is used.
//  QCelsius (temperatures): signed Q11.20, value = raw·2⁻²⁰ °C, range ±2048 °C,
//    resolution 9.5e-7 °C. The core accepts ±200 °C (temperature_in_domain), so
//    a difference of two readings (≤ 400 °C) has |raw| < 2²⁹.
//  QCoefficient (linear thermal-model coefficients, rad, rad/°C): signed,
//    value = raw·2⁻³⁶, range ±2⁻⁵ = ±0.03125 (±6445"), resolution 1.5e-11
//    (3e-6"). Model coefficients are below 1e-3 rad (c0) and 1e-5 rad/°C (the
//    paper's Table 2: 2e-3 to 5"/°C), so the format has 5 bits of headroom above
//    c0 and resolves a linear coefficient to 1e-6 relative. Q1.30 would resolve
//    1e-6 rad/°C to only 1e-3 relative, hence the extra fractional bits.
//  QQuadraticCoefficient (rad/°C²): signed, value = raw·2⁻⁴⁸, range ±2⁻¹⁷
//    = ±7.6e-6 rad/°C² (±1.57"/°C²), resolution 3.6e-15 rad/°C²: at the
//    largest temperature difference (400 °C, T² = 1.6e5) one LSB is 1.2e-4".
//    Quadratic coefficients are 1e3–1e4 times smaller than linear ones; in the
//    linear format a 0.01"/°C² coefficient would carry a 0.03" error at 100 °C.
//
//  Conversions from double (ScalarTraits<Q30>::from_double, celsius,
//  coefficient) round to nearest (ties away from zero) and saturate to the
//  symmetric range [−(2³¹ − 1), 2³¹ − 1] raw; NaN maps
//  to the positive end of the range, so that a non-finite input lands outside
//  every domain check of the core and is flagged exactly as it would be in
//  floating point (is_finite() is always true for a fixed-point value).
#pragma once

#include <cstdint>

#include "aberration.hpp"
#include "constants.hpp"
#include "quaternion.hpp"
#include "scalar_traits.hpp"
#include "thermal.hpp"
#include "vector3.hpp"

namespace ascorr {

namespace fx {

inline constexpr std::int32_t kRawMax = INT32_MAX;
inline constexpr std::int32_t kRawMin = INT32_MIN;

// A 64-bit intermediate brought back to 32-bit storage: clamped to the range.
constexpr std::int32_t saturate(std::int64_t v) noexcept {
    return v > kRawMax ? kRawMax : (v < kRawMin ? kRawMin : static_cast<std::int32_t>(v));
}

// v·2⁻ˢ rounded to nearest, ties towards +∞ (add half, arithmetic shift).
// Precondition: v + 2^(s−1) does not overflow int64; s in [1, 62].
constexpr std::int64_t round_shift(std::int64_t v, int s) noexcept {
    return (v + (std::int64_t{1} << (s - 1))) >> s;
}

// x·2^frac as a raw value: round to nearest (ties away from zero), saturated;
// NaN → kRawMax. Compile time for constants, host only otherwise.
constexpr std::int32_t raw_from_double(double x, int frac) noexcept {
    if (!(x == x)) {
        return kRawMax;
    }
    double scale = 1.0;
    for (int i = 0; i < frac; ++i) {  // exact powers of two; folded at compile time
        scale *= 2.0;
    }
    const double s = x * scale;
    if (s >= 2147483647.0) {
        return kRawMax;
    }
    if (s <= -2147483647.0) {
        return -kRawMax;  // symmetric: −2 (raw INT32_MIN) is never produced
    }
    return static_cast<std::int32_t>(s < 0.0 ? s - 0.5 : s + 0.5);
}

constexpr double raw_to_double(std::int32_t raw, int frac) noexcept {
    double scale = 1.0;
    for (int i = 0; i < frac; ++i) {
        scale *= 0.5;
    }
    return static_cast<double>(raw) * scale;
}

constexpr std::int32_t add_sat(std::int32_t a, std::int32_t b) noexcept {
    std::int32_t r = 0;
    if (__builtin_add_overflow(a, b, &r)) {
        return a < 0 ? kRawMin : kRawMax;  // both operands have a's sign
    }
    return r;
}

constexpr std::int32_t sub_sat(std::int32_t a, std::int32_t b) noexcept {
    std::int32_t r = 0;
    if (__builtin_sub_overflow(a, b, &r)) {
        return a < 0 ? kRawMin : kRawMax;
    }
    return r;
}

constexpr std::int32_t neg_sat(std::int32_t a) noexcept {
    return a == kRawMin ? kRawMax : -a;
}

// A sum of Q30 products (units 2⁻⁶⁰) to Q30: + 2²⁹, arithmetic shift right by
// 30 (round to nearest, ties towards +∞), saturated. Precondition
// |acc| ≤ 2⁶³ − 2²⁹ (every caller's sums are, see mac2 and half_sum). The
// range test is on the high word only: the result fits iff acc + 2²⁹ lies in
// [−2⁶¹, 2⁶¹), i.e. iff the high word lies in [−2²⁹, 2²⁹).
// The same for any shift S in [1, 31]: acc·2⁻ˢ rounded to nearest (ties
// towards +∞) and saturated; precondition |acc| ≤ 2⁶³ − 2^(S−1).
template <int S>
constexpr std::int32_t narrow_shift(std::int64_t acc) noexcept {
    static_assert(S >= 1 && S <= 31, "shift");
    const std::int64_t r = acc + (std::int64_t{1} << (S - 1));
    const auto u = static_cast<std::uint64_t>(r);
    const auto hi = static_cast<std::uint32_t>(u >> 32U);
    // Fits iff r ∈ [−2^(31+S), 2^(31+S)), i.e. iff the top 33 − S bits of the
    // high word are all equal: hi + 2^(S−1) < 2^S as unsigned.
    if (hi + (std::uint32_t{1} << (S - 1)) >= (std::uint32_t{1} << S)) {
        return static_cast<std::int32_t>(hi) < 0 ? kRawMin : kRawMax;
    }
    return static_cast<std::int32_t>((static_cast<std::uint32_t>(u) >> S) | (hi << (32 - S)));
}

constexpr std::int32_t narrow_raw(std::int64_t acc) noexcept {
    return narrow_shift<30>(acc);
}

}  // namespace fx

// Q1.30 scalar, see the conventions above.
struct Q30 {
    static constexpr int kFracBits = 30;
    std::int32_t raw;
};

constexpr Q30 operator+(Q30 a, Q30 b) noexcept {
    return {fx::add_sat(a.raw, b.raw)};
}
constexpr Q30 operator-(Q30 a, Q30 b) noexcept {
    return {fx::sub_sat(a.raw, b.raw)};
}
constexpr Q30 operator-(Q30 a) noexcept {
    return {fx::neg_sat(a.raw)};
}
constexpr Q30 operator*(Q30 a, Q30 b) noexcept {
    return {fx::narrow_raw(std::int64_t{a.raw} * b.raw)};
}
constexpr bool operator<(Q30 a, Q30 b) noexcept {
    return a.raw < b.raw;
}
constexpr bool operator<=(Q30 a, Q30 b) noexcept {
    return a.raw <= b.raw;
}
constexpr bool operator>(Q30 a, Q30 b) noexcept {
    return a.raw > b.raw;
}
constexpr bool operator>=(Q30 a, Q30 b) noexcept {
    return a.raw >= b.raw;
}
constexpr bool operator==(Q30 a, Q30 b) noexcept {
    return a.raw == b.raw;
}
constexpr bool operator!=(Q30 a, Q30 b) noexcept {
    return a.raw != b.raw;
}
// A fixed-point value is always a number.
constexpr bool is_finite(Q30 /*unused*/) noexcept {
    return true;
}

// Q11.20 temperature in °C, see the conventions above.
struct QCelsius {
    static constexpr int kFracBits = 20;
    std::int32_t raw;
};

constexpr QCelsius operator-(QCelsius a) noexcept {
    return {fx::neg_sat(a.raw)};
}
constexpr bool operator<=(QCelsius a, QCelsius b) noexcept {
    return a.raw <= b.raw;
}
constexpr bool is_finite(QCelsius /*unused*/) noexcept {
    return true;
}

// Thermal-model coefficient, raw·2⁻³⁶ (rad, rad/°C), see above.
struct QCoefficient {
    static constexpr int kFracBits = 36;
    std::int32_t raw;
};

// Quadratic thermal-model coefficient, raw·2⁻⁴⁸ (rad/°C²), see above.
struct QQuadraticCoefficient {
    static constexpr int kFracBits = 48;
    std::int32_t raw;
};

template <>
struct ScalarTraits<Q30> {
    using coefficient_type = QCoefficient;
    using quadratic_coefficient_type = QQuadraticCoefficient;
    using temperature_type = QCelsius;
    static constexpr Q30 from_double(double x) noexcept { return {fx::raw_from_double(x, Q30::kFracBits)}; }
    static constexpr double to_double(Q30 x) noexcept { return fx::raw_to_double(x.raw, Q30::kFracBits); }
    static constexpr QCelsius celsius(double x) noexcept { return {fx::raw_from_double(x, QCelsius::kFracBits)}; }
    static constexpr double to_double(QCelsius x) noexcept { return fx::raw_to_double(x.raw, QCelsius::kFracBits); }
    static constexpr QCoefficient coefficient(double x) noexcept {
        return {fx::raw_from_double(x, QCoefficient::kFracBits)};
    }
    static constexpr double to_double(QCoefficient x) noexcept {
        return fx::raw_to_double(x.raw, QCoefficient::kFracBits);
    }
    static constexpr QQuadraticCoefficient quadratic_coefficient(double x) noexcept {
        return {fx::raw_from_double(x, QQuadraticCoefficient::kFracBits)};
    }
    static constexpr double to_double(QQuadraticCoefficient x) noexcept {
        return fx::raw_to_double(x.raw, QQuadraticCoefficient::kFracBits);
    }
    // Largest coefficients the formats hold (rad, rad/°C; rad/°C²); a model
    // beyond them cannot be represented and must be refused by the loader.
    static constexpr double max_coefficient = 0x1p-5;
    static constexpr double max_quadratic_coefficient = 0x1p-17;
    // Rounding a unit quaternion's components to 2⁻³¹ leaves |‖q‖² − 1| ≤ 4e-9;
    // the bound is the double path's, so both reject the same inputs.
    static constexpr Q30 unit_norm_tolerance = {fx::raw_from_double(1e-6, Q30::kFracBits)};
};

// ---- Sums of products, rounded once. The core's vector and quaternion
// operations on Q30 (found by argument-dependent lookup, preferred to the
// generic templates) accumulate their exact products in int64 and round and
// saturate once, as CMSIS's q31 dot products do: fewer roundings (≤ 2⁻³¹ per
// result instead of per product) and fewer instructions.
// Range: a product of two Q30 raws has |·| ≤ 2⁶², a sum or difference of two
// (mac2, msub2) |·| < 2⁶³, except a·b + c·d with all four −2 (raw INT32_MIN),
// which wraps (unsigned arithmetic, no undefined behaviour) to −2⁶³; neither
// conversions nor the core's data (validated unit quaternions, small terms)
// produce that. Four-term sums add the halves of two such sums (half_sum: each
// halved by an arithmetic shift, |·| < 2⁶², no overflow), losing at most
// 2⁻⁶⁰, far below the final rounding (narrow_shift<29>: ≤ 2⁻³¹, saturated).

namespace fx {

// a·b + c·d and a·b − c·d, units 2⁻⁶⁰ (see the range note above).
constexpr std::int64_t mac2(Q30 a, Q30 b, Q30 c, Q30 d) noexcept {
    return static_cast<std::int64_t>(static_cast<std::uint64_t>(std::int64_t{a.raw} * b.raw) +
                                     static_cast<std::uint64_t>(std::int64_t{c.raw} * d.raw));
}
constexpr std::int64_t msub2(Q30 a, Q30 b, Q30 c, Q30 d) noexcept {
    return static_cast<std::int64_t>(static_cast<std::uint64_t>(std::int64_t{a.raw} * b.raw) -
                                     static_cast<std::uint64_t>(std::int64_t{c.raw} * d.raw));
}

// (x + y)/2 for |x|, |y| < 2⁶³, without overflow; error ≤ 1 (units of x).
// Of two sums in units 2⁻⁶⁰ it is their sum in units 2⁻⁵⁹.
constexpr std::int64_t half_sum(std::int64_t x, std::int64_t y) noexcept {
    return (x >> 1) + (y >> 1);
}

constexpr Q30 narrow(std::int64_t acc) noexcept {  // units 2⁻⁶⁰ → Q30
    return {narrow_shift<30>(acc)};
}
constexpr Q30 narrow_half(std::int64_t half) noexcept {  // units 2⁻⁵⁹ → Q30
    return {narrow_shift<29>(half)};
}

}  // namespace fx

constexpr Q30 dot(const Vector3<Q30>& a, const Vector3<Q30>& b) noexcept {
    return fx::narrow_half(fx::half_sum(fx::mac2(a.x, b.x, a.y, b.y), std::int64_t{a.z.raw} * b.z.raw));
}

constexpr Q30 squared_norm(const Vector3<Q30>& a) noexcept {
    return dot(a, a);
}

constexpr Vector3<Q30> cross(const Vector3<Q30>& a, const Vector3<Q30>& b) noexcept {
    return {fx::narrow(fx::msub2(a.y, b.z, a.z, b.y)), fx::narrow(fx::msub2(a.z, b.x, a.x, b.z)),
            fx::narrow(fx::msub2(a.x, b.y, a.y, b.x))};
}

constexpr Q30 dot(const Quaternion<Q30>& a, const Quaternion<Q30>& b) noexcept {
    return fx::narrow_half(fx::half_sum(fx::mac2(a.w, b.w, a.x, b.x), fx::mac2(a.y, b.y, a.z, b.z)));
}

constexpr Q30 squared_norm(const Quaternion<Q30>& q) noexcept {
    return dot(q, q);
}

// Hamilton product a ⊗ b (quaternion.hpp), each component rounded once.
constexpr Quaternion<Q30> operator*(const Quaternion<Q30>& a, const Quaternion<Q30>& b) noexcept {
    using fx::half_sum;
    using fx::mac2;
    using fx::msub2;
    using fx::narrow_half;
    return {narrow_half(half_sum(msub2(a.w, b.w, a.x, b.x), -mac2(a.y, b.y, a.z, b.z))),
            narrow_half(half_sum(mac2(a.w, b.x, a.x, b.w), msub2(a.y, b.z, a.z, b.y))),
            narrow_half(half_sum(msub2(a.w, b.y, a.x, b.z), mac2(a.y, b.w, a.z, b.x))),
            narrow_half(half_sum(mac2(a.w, b.z, a.x, b.y), msub2(a.z, b.w, a.y, b.x)))};
}

// Third row of R(q) (quaternion.hpp), each component rounded once; the
// doubling is exact: a sum in units 2⁻⁶⁰ read in units 2⁻⁵⁹.
constexpr Vector3<Q30> boresight(const Quaternion<Q30>& q) noexcept {
    const std::int64_t a = fx::msub2(q.x, q.z, q.w, q.y);
    const std::int64_t b = fx::mac2(q.y, q.z, q.w, q.x);
    const std::int64_t c = fx::mac2(q.x, q.x, q.y, q.y);  // ≥ 0 (wraps only at x = y = −2)
    constexpr std::int64_t kOne = std::int64_t{1} << 59;  // 1 in units 2⁻⁵⁹
    return {fx::narrow_half(a), fx::narrow_half(b), fx::narrow_half(kOne - c)};
}

// q + d brought to unit norm by one Newton step (quaternion.hpp), in Q30.
// In integers q + d is exact (saturating add: |·| ≤ 2), so ε = ‖q + d‖² − 1 is
// formed exactly in int64 (units 2⁻⁵⁹ after half_sum), g = −ε/2 is rounded
// once to Q30 and saturated, and each component is (q + d)ᵢ + round((q + d)ᵢ·g),
// saturated: one rounding per component.
constexpr Quaternion<Q30> renormalized_sum(const Quaternion<Q30>& q, const Quaternion<Q30>& d) noexcept {
    const Quaternion<Q30> s{q.w + d.w, q.x + d.x, q.y + d.y, q.z + d.z};
    const std::int64_t n2_half = fx::half_sum(fx::mac2(s.w, s.w, s.x, s.x), fx::mac2(s.y, s.y, s.z, s.z));
    const Q30 g{fx::narrow_shift<30>((std::int64_t{1} << 59) - n2_half)};  // (1 − ‖s‖²)/2
    return {s.w + s.w * g, s.x + s.x * g, s.y + s.y * g, s.z + s.z * g};
}

namespace fx {

// (t·2⁻²⁰)² in units of 2⁻¹² °C², rounded to nearest. |t| < 2²⁹ (≤ 512 °C):
// t² < 2⁵⁸ fits int64 and the result < 2¹⁸·2¹² = 2³⁰ fits int32. Error ≤ 2⁻¹³ °C².
constexpr std::int32_t square_celsius(std::int32_t t) noexcept {
    return static_cast<std::int32_t>(round_shift(std::int64_t{t} * t, 2 * QCelsius::kFracBits - 12));
}

// Clamps a temperature to ±2²⁸ raw (±256 °C): then a difference of two is
// within ±2²⁹ (±512 °C) in int32, the range for which thermal_angle's 64-bit
// sums cannot overflow. Readings inside the core's domain (±200 °C) pass
// unchanged.
constexpr std::int32_t clamp_celsius(std::int32_t t) noexcept {
    constexpr std::int32_t lim = std::int32_t{1} << 28;
    return t > lim ? lim : (t < -lim ? -lim : t);
}

}  // namespace fx

// The model angle in Q30 rad from QCoefficient / QQuadraticCoefficient
// coefficients and QCelsius temperatures (thermal.hpp for the polynomial).
// All products in int64:
//   linear    c·T  : |c| < 2³¹, |T| ≤ 2²⁹ → < 2⁶⁰ each, units 2⁻⁵⁶ rad;
//   quadratic c·T² : |c| < 2³¹, T² ≤ 2³⁰ (units 2⁻¹²) → < 2⁶¹ each, units 2⁻⁶⁰
//                    rad, rounded to 2⁻⁵⁶ (→ < 2⁵⁷);
//   the sum in units of 2⁻⁵⁶: c0·2²⁰ + Σlin + Σquad < 2⁵¹ + 3·2⁶⁰ + 3·2⁵⁷ < 2⁶²,
//     no overflow for any input, because temperatures are clamped to ±256 °C
//     first, so that they and their differences are within ±512 °C (the core
//     calls this only for readings inside ±200 °C, where the clamp does nothing).
// Result rounded once to Q30 (error ≤ 2⁻³¹ rad = 9.6e-5") and saturated (the
// core then flags it beyond kMaxThermalAngleRad). Other rounding, in rad:
// T² ≤ 2⁻¹³ °C²·|c_2| (≤ 1e-10 at the largest c_2) and 2⁻⁵⁷ per quadratic
// term. Coefficient and temperature quantisation (the inputs) add ≤ 2⁻³⁷·|T|,
// 2⁻⁴⁹·T² and 2⁻²¹·|c| per term.
// The three quadratic products are skipped for an axis whose quadratic
// coefficients are all zero (the usual linear model): same result, fewer
// instructions. A branch, not a loop: the instruction count stays bounded.
template <>
[[gnu::always_inline]] constexpr Q30 thermal_angle<Q30>(const AxisPolynomial<Q30>& p, const QCelsius& t1,
                                                        const QCelsius& t2, const QCelsius& t3) noexcept {
    constexpr int kSumFrac = QCoefficient::kFracBits + QCelsius::kFracBits;       // 56
    constexpr int kQuadShift = QQuadraticCoefficient::kFracBits + 12 - kSumFrac;  // 4
    const std::int32_t a = fx::clamp_celsius(t1.raw);
    const std::int32_t d2 = fx::clamp_celsius(t2.raw) - a;
    const std::int32_t d3 = fx::clamp_celsius(t3.raw) - a;
    std::int64_t sum = std::int64_t{p.c0.raw} * (std::int64_t{1} << QCelsius::kFracBits) + std::int64_t{p.c1.raw} * a +
                       std::int64_t{p.c2.raw} * d2 + std::int64_t{p.c3.raw} * d3;
    if ((p.c1_2.raw | p.c2_2.raw | p.c3_2.raw) != 0) {
        sum += fx::round_shift(std::int64_t{p.c1_2.raw} * fx::square_celsius(a), kQuadShift) +
               fx::round_shift(std::int64_t{p.c2_2.raw} * fx::square_celsius(d2), kQuadShift) +
               fx::round_shift(std::int64_t{p.c3_2.raw} * fx::square_celsius(d3), kQuadShift);
    }
    return {fx::narrow_shift<kSumFrac - Q30::kFracBits>(sum)};
}

// ---- The thermal rotation in Q30 (thermal.hpp: q_th = q3(γ) ⊗ q2(β) ⊗ q1(α),
// 16-product expansion), specialised for the format's resolution.
//
// Range: each angle is first clamped to ±kMaxThermalAngleRad (the core calls
// this only after checking that bound, so the clamp never acts there). Then
// |h| = |angle|/2 ≤ 8.73e-3, |s| ≤ |h|, |cos h − 1| ≤ 3.81e-5: every factor
// is ≤ 1 in magnitude (raw ≤ 2³⁰), every product ≤ 2⁶⁰ and every sum of two
// ≤ 2⁶¹ in int64, and every result ≤ 1 + 2e-4 in magnitude: no overflow and
// no saturation needed, hence none is applied (plain int64 arithmetic).
// Series at Q30 resolution (2⁻³⁰ = 9.3e-10):
//   sin h = h − h³/6 + O(h⁵/120 ≤ 4.1e-13),
//   cos h − 1 = −h²/2 + O(h⁴/24 ≤ 2.4e-10; this changes |q| only to first
//     order, and the rotation angle by ≤ 2·s·2.4e-10 = 4e-12 rad).
// h³/6 uses 1/12 as 174763·2⁻²¹ (relative error 1.9e-6 of a term ≤ 1.1e-7).
// Rounding: to nearest at each product (≤ 2⁻³¹ each, about ten per
// component): ≤ 5e-9 absolute, 1e-3" as a rotation.
namespace fx {

// (a·b) rounded to Q30, for operands with |a·b| ≤ 2⁶¹ (no saturation).
constexpr std::int32_t mul_small(std::int32_t a, std::int32_t b) noexcept {
    return static_cast<std::int32_t>((std::int64_t{a} * b + (std::int64_t{1} << 29)) >> 30);
}

// (a·b + c·d) rounded to Q30, for |a·b| + |c·d| ≤ 2⁶¹ (no saturation).
constexpr std::int32_t mul2_small(std::int32_t a, std::int32_t b, std::int32_t c, std::int32_t d) noexcept {
    return static_cast<std::int32_t>((std::int64_t{a} * b + std::int64_t{c} * d + (std::int64_t{1} << 29)) >> 30);
}

struct HalfAngleQ30 {
    std::int32_t cm1;  // cos(angle/2) − 1, Q30
    std::int32_t s;    // sin(angle/2), Q30
};

constexpr HalfAngleQ30 half_angle_q30(Q30 angle) noexcept {
    constexpr std::int32_t lim = raw_from_double(kMaxThermalAngleRad, Q30::kFracBits);
    const std::int32_t a = angle.raw > lim ? lim : (angle.raw < -lim ? -lim : angle.raw);  // |a| < 2²⁵
    const std::int64_t a2 = std::int64_t{a} * a;                                           // (2h)², units 2⁻⁶⁰
    const auto h2 = static_cast<std::int32_t>((a2 + (std::int64_t{1} << 31)) >> 32);       // h², Q30, < 2¹⁷
    const std::int64_t t = std::int64_t{h2} * a;  // 2h³, units 2⁻⁶⁰, < 2⁴²
    const auto h3_6 = static_cast<std::int32_t>((t * 174763 + (std::int64_t{1} << 50)) >> 51);  // h³/6, Q30
    const std::int32_t h = (a + 1) >> 1;                                                        // Q30
    return {-((h2 + 1) >> 1), h - h3_6};
}

}  // namespace fx

constexpr SmallRotation<Q30> thermal_rotation(const Q30& alpha, const Q30& beta, const Q30& gamma) noexcept {
    using fx::mul2_small;
    using fx::mul_small;
    const fx::HalfAngleQ30 a = fx::half_angle_q30(alpha);
    const fx::HalfAngleQ30 b = fx::half_angle_q30(beta);
    const fx::HalfAngleQ30 g = fx::half_angle_q30(gamma);
    constexpr std::int32_t one = std::int32_t{1} << 30;
    const std::int32_t ac = one + a.cm1;
    const std::int32_t bc = one + b.cm1;
    const std::int32_t gc = one + g.cm1;
    const std::int32_t ccm1 = a.cm1 + b.cm1 + mul_small(a.cm1, b.cm1);  // c1c2 − 1
    const std::int32_t cc = one + ccm1;
    const std::int32_t sc = mul_small(a.s, bc);
    const std::int32_t cs = mul_small(ac, b.s);
    const std::int32_t ss = mul_small(a.s, b.s);
    return {{ccm1 + g.cm1 + mul2_small(ccm1, g.cm1, -ss, g.s)},
            {{-mul2_small(sc, gc, cs, g.s)}, {mul2_small(sc, g.s, -cs, gc)}, {-mul2_small(ss, gc, cc, g.s)}}};
}

// beta_in_domain (aberration.hpp) for Q30: the components first (each within
// ±kMaxBeta), then |β|². The same verdict as the generic test (which relies
// on saturation for huge components); on the Cortex-M3 the cheaper code, as
// measured (toolchain/run-target-bench): the early exits keep the aberration
// stage's registers free.
constexpr bool beta_in_domain(const Vector3<Q30>& beta) noexcept {
    constexpr Q30 lim{fx::raw_from_double(kMaxBeta, Q30::kFracBits)};
    constexpr Q30 lim2{fx::raw_from_double(kMaxBeta * kMaxBeta, Q30::kFracBits)};
    const auto within = [&](Q30 c) { return c <= lim && -lim <= c; };
    return within(beta.x) && within(beta.y) && within(beta.z) && squared_norm(beta) <= lim2;
}

// add_left_increment (quaternion.hpp) in Q30: each component
// dᵢ + Σ (r − 1)ⱼ·(q + d)ₖ summed exactly in int64 (dᵢ scaled to units 2⁻⁶⁰)
// and rounded and saturated once. Range: q + d is a saturating sum (|·| ≤ 2);
// for |r − 1| components ≤ 0.5 (a rotation's increment, here ≤ 3° of thermal
// rotation: ≤ 0.03) each product is ≤ 2⁶⁰ and the sum ≤ 2⁶¹ + 4·2⁶⁰ < 2⁶³.
constexpr Quaternion<Q30> add_left_increment(const Quaternion<Q30>& d, const SmallRotation<Q30>& r,
                                             const Quaternion<Q30>& q) noexcept {
    const Quaternion<Q30> s{q.w + d.w, q.x + d.x, q.y + d.y, q.z + d.z};
    const Quaternion<Q30> a = increment(r);
    const auto one = [](Q30 x) { return std::int64_t{x.raw} * (std::int64_t{1} << 30); };
    const auto p = [](Q30 x, Q30 y) { return std::int64_t{x.raw} * y.raw; };
    return {fx::narrow(one(d.w) + p(a.w, s.w) - p(a.x, s.x) - p(a.y, s.y) - p(a.z, s.z)),
            fx::narrow(one(d.x) + p(a.w, s.x) + p(a.x, s.w) + p(a.y, s.z) - p(a.z, s.y)),
            fx::narrow(one(d.y) + p(a.w, s.y) - p(a.x, s.z) + p(a.y, s.w) + p(a.z, s.x)),
            fx::narrow(one(d.z) + p(a.w, s.z) + p(a.x, s.y) - p(a.y, s.x) + p(a.z, s.w))};
}

}  // namespace ascorr
