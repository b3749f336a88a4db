// ascorr/core/fixed_point.hpp: the fixed-point scalar of the core (DPU without FPU).
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
//      dot, cross, squared_norm, quaternion product : overloads of the
//                         generic functions for any input: exact products
//                         summed in int64, rounded and saturated once per
//                         result (see "Sums of products" below).
//      the correction's kernels (norm_within, boresight, right_increment,
//      add_left_increment, renormalized_sum, beta_in_domain,
//      aberration_rotation, thermal_angle, thermal_rotation) : Q30 versions
//                         of the core's functions, each with its range
//                         argument: the core's checks bound their operands, so
//                         they round once per result and need no saturation
//                         (thermal_angle, which takes any temperatures and
//                         coefficients, saturates).
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
#include "compiler.hpp"
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

// 2^e as a double, exact for |e| ≤ 1022; folded at compile time.
constexpr double pow2(int e) noexcept {
    double p = 1.0;
    for (int i = 0; i < e; ++i) {
        p *= 2.0;
    }
    for (int i = 0; i > e; --i) {
        p *= 0.5;
    }
    return p;
}

// x·2^Frac as a raw value: one multiplication (by the exact constant 2^Frac),
// rounded to nearest (ties away from zero), saturated to ±(2³¹ − 1); NaN →
// kRawMax. At compile time for constants; at run time it costs one double
// product, two comparisons and one conversion.
template <int Frac>
constexpr std::int32_t raw_from_double(double x) noexcept {
    constexpr double kScale = pow2(Frac);
    const double s = x * kScale;
    if (!(s < 2147483647.0)) {
        return kRawMax;  // also NaN
    }
    if (s <= -2147483647.0) {
        return -kRawMax;  // symmetric: −2 (raw INT32_MIN) is never produced
    }
    return static_cast<std::int32_t>(s < 0.0 ? s - 0.5 : s + 0.5);
}

// raw·2^−Frac, exact.
template <int Frac>
constexpr double raw_to_double(std::int32_t raw) noexcept {
    constexpr double kScale = pow2(-Frac);
    return static_cast<double>(raw) * kScale;
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
// |x| ≤ lim for lim ≥ 0 (scalar_traits.hpp): two comparisons, exact.
constexpr bool abs_within(Q30 x, Q30 lim) noexcept {
    return x.raw <= lim.raw && -lim.raw <= x.raw;
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
constexpr bool abs_within(QCelsius x, QCelsius lim) noexcept {
    return x.raw <= lim.raw && -lim.raw <= x.raw;
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
    static constexpr Q30 from_double(double x) noexcept { return {fx::raw_from_double<Q30::kFracBits>(x)}; }
    static constexpr double to_double(Q30 x) noexcept { return fx::raw_to_double<Q30::kFracBits>(x.raw); }
    static constexpr QCelsius celsius(double x) noexcept { return {fx::raw_from_double<QCelsius::kFracBits>(x)}; }
    static constexpr double to_double(QCelsius x) noexcept { return fx::raw_to_double<QCelsius::kFracBits>(x.raw); }
    static constexpr QCoefficient coefficient(double x) noexcept {
        return {fx::raw_from_double<QCoefficient::kFracBits>(x)};
    }
    static constexpr double to_double(QCoefficient x) noexcept {
        return fx::raw_to_double<QCoefficient::kFracBits>(x.raw);
    }
    static constexpr QQuadraticCoefficient quadratic_coefficient(double x) noexcept {
        return {fx::raw_from_double<QQuadraticCoefficient::kFracBits>(x)};
    }
    static constexpr double to_double(QQuadraticCoefficient x) noexcept {
        return fx::raw_to_double<QQuadraticCoefficient::kFracBits>(x.raw);
    }
    // Largest coefficients the formats hold (rad, rad/°C; rad/°C²); a model
    // beyond them cannot be represented and must be refused by the loader.
    static constexpr double max_coefficient = 0x1p-5;
    static constexpr double max_quadratic_coefficient = 0x1p-17;
    // Rounding a unit quaternion's components to 2⁻³¹ leaves |‖q‖² − 1| ≤ 4e-9;
    // the bound is the double path's, so both reject the same inputs.
    static constexpr Q30 unit_norm_tolerance = {fx::raw_from_double<Q30::kFracBits>(1e-6)};
    // The core's series are specialised for Q30 below (aberration_rotation,
    // thermal_rotation), cut at the format's resolution.
    static constexpr bool double_precision = false;
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

// ---- The correction's kernels in Q30: the functions correct_solution() calls
// (found by argument-dependent lookup, preferred to the generic templates).
// Their operands are bounded by the core's own checks, stated per function,
// so that no sum can overflow and no result can leave the format: each sum of
// products is formed exactly in int64 and rounded once to Q30 (to nearest,
// ties towards +∞, error ≤ 2⁻³¹), without saturation. A subtracted product is
// written as the product with the negated smaller operand (bounded far from
// −2, so negation is exact): every sum is then a chain of multiply-accumulates,
// one SMULL and then one SMLAL per product on a Cortex-M3. (Written as a
// difference, or with saturating steps in between, GCC 12 builds some products
// from MUL/MLA/UMULL instead, three to four times the instructions.)
namespace fx {

// x, as a value the compiler cannot identify with x. Each kernel below takes
// its operands through this, so that their 64-bit sign extensions are not
// shared with other kernels: when one value feeds products in several
// kernels (inlined into one function), GCC 12 for Armv7-M extends it once and
// then multiplies 64 × 64 bits with MUL, MLA and UMULL instead of one SMULL
// or SMLAL, three to four times the instructions. Emits no instruction.
#if defined(__ARM_ARCH_7M__) || defined(__ARM_ARCH_7EM__)
inline void arm_opaque(std::int32_t& x) noexcept {
    __asm__ volatile("" : "+r"(x));  // volatile: two with the same input are not merged
}
#endif

constexpr std::int32_t unshared(std::int32_t x) noexcept {
#if defined(__ARM_ARCH_7M__) || defined(__ARM_ARCH_7EM__)
    if (!__builtin_is_constant_evaluated()) {
        arm_opaque(x);
    }
#endif
    return x;
}

// a·b exactly, in 64 bits (one SMULL; SMLAL into a sum).
constexpr std::int64_t mul(std::int32_t a, std::int32_t b) noexcept {
    return std::int64_t{a} * b;
}

// acc + Σ aᵢ·bᵢ over the pairs (a₀, b₀, a₁, b₁, …), exact: a chain of SMLAL.
constexpr std::int64_t accumulate_products(std::int64_t acc) noexcept {
    return acc;
}
template <typename... Rest>
constexpr std::int64_t accumulate_products(std::int64_t acc, std::int32_t a, std::int32_t b, Rest... rest) noexcept {
    return accumulate_products(acc + mul(a, b), rest...);
}
// Σ aᵢ·bᵢ, exact: one SMULL, then SMLAL.
template <typename... Rest>
constexpr std::int64_t sum_products(std::int32_t a, std::int32_t b, Rest... rest) noexcept {
    return accumulate_products(mul(a, b), rest...);
}

// (acc + Σ aᵢ·bᵢ)·2⁻³⁰ rounded to nearest (ties towards +∞), without
// saturation: a sum of Q30 products (units 2⁻⁶⁰; acc in the same units)
// rounded once to Q30. The rounding constant starts the accumulator, so the
// rounding costs no instruction of its own. Precondition: the result fits.
template <typename... Pairs>
constexpr Q30 round30_sum(std::int64_t acc, Pairs... pairs) noexcept {
    return {static_cast<std::int32_t>(accumulate_products(acc + (std::int64_t{1} << 29), pairs...) >> 30)};
}

// v·2⁻ˢ rounded to nearest (ties towards +∞). Precondition: the result fits
// int32 and v + 2^(S−1) fits int64.
template <int S>
constexpr std::int32_t round_shift_to_int32(std::int64_t v) noexcept {
    static_assert(S >= 1 && S <= 62, "shift");
    return static_cast<std::int32_t>((v + (std::int64_t{1} << (S - 1))) >> S);
}

}  // namespace fx

// boresight (quaternion.hpp), the third row of R(q), in Q30: each component
// a sum of two products, exact, doubled exactly (read in units 2⁻⁵⁹) and
// rounded once. Range: q passed norm_within() (|qᵢ| ≤ 1 + 5e-7); then every
// component is ≤ 1 + 1e-6 in magnitude.
constexpr Vector3<Q30> boresight(const Quaternion<Q30>& q) noexcept {
    using fx::unshared;
    const std::int32_t qw = unshared(q.w.raw);
    const std::int32_t qx = unshared(q.x.raw);
    const std::int32_t qy = unshared(q.y.raw);
    const std::int32_t qz = unshared(q.z.raw);
    constexpr std::int64_t kHalfLsb = std::int64_t{1} << 28;  // units 2⁻⁵⁹
    const auto round29 = [](std::int64_t v) { return Q30{static_cast<std::int32_t>(v >> 29)}; };
    return {round29(fx::accumulate_products(kHalfLsb, qx, qz, -qw, qy)),
            round29(fx::accumulate_products(kHalfLsb, qy, qz, qw, qx)),
            round29(fx::accumulate_products((std::int64_t{1} << 59) + kHalfLsb, -qx, qx, -qy, qy))};
}

// conjugate (quaternion.hpp) of a SmallRotation in Q30: plain negation, exact,
// since a rotation's vector part is within ±1 (never −2).
constexpr SmallRotation<Q30> conjugate(const SmallRotation<Q30>& r) noexcept {
    return {r.dw, {{-r.v.x.raw}, {-r.v.y.raw}, {-r.v.z.raw}}};
}

// norm_within (quaternion.hpp) in Q30, exact and for any input: ‖q‖² − 1 in
// units 2⁻⁶⁰. The four squares (each ≤ 2⁶²) are summed modulo 2⁶⁴: exact
// below 2⁶⁴; the only sum that wraps (all four components −2) reads 0, and
// any true ‖q‖² − 1 ≥ 2⁶³ (units 2⁻⁶⁰; some |component| > 1.4) reads
// ≤ −2⁶⁰ as a signed value: both are rejected, as they must be.
constexpr bool norm_within(const Quaternion<Q30>& q, Q30 tol) noexcept {
    const auto sq = [](Q30 c) { return static_cast<std::uint64_t>(fx::mul(c.raw, c.raw)); };
    const auto e = static_cast<std::int64_t>(sq(q.w) + sq(q.x) + sq(q.y) + sq(q.z) - (std::uint64_t{1} << 60));
    const std::int64_t t = fx::mul(tol.raw, std::int32_t{1} << 30);
    return -t <= e && e <= t;
}

// right_increment (quaternion.hpp): q ⊗ (r − 1) in Q30, each component
// rounded once. Range: q passed norm_within() (|qᵢ| ≤ 1 + 5e-7) and the
// components of r − 1 are within ±2⁻⁴ (aberration: ≤ 1.7e-3); each
// product ≤ 2⁵⁷, each result ≤ 2⁻² in magnitude.
constexpr Quaternion<Q30> right_increment(const Quaternion<Q30>& q, const SmallRotation<Q30>& r) noexcept {
    using fx::round30_sum;
    using fx::unshared;
    const std::int32_t qw = unshared(q.w.raw);
    const std::int32_t qx = unshared(q.x.raw);
    const std::int32_t qy = unshared(q.y.raw);
    const std::int32_t qz = unshared(q.z.raw);
    const std::int32_t aw = unshared(r.dw.raw);
    const std::int32_t ax = unshared(r.v.x.raw);
    const std::int32_t ay = unshared(r.v.y.raw);
    const std::int32_t az = unshared(r.v.z.raw);
    return {round30_sum(0, qw, aw, qx, -ax, qy, -ay, qz, -az), round30_sum(0, qw, ax, qx, aw, qy, az, qz, -ay),
            round30_sum(0, qw, ay, qx, -az, qy, aw, qz, ax), round30_sum(0, qw, az, qx, ay, qy, -ax, qz, aw)};
}

// add_left_increment (quaternion.hpp): d + (r − 1) ⊗ (q + d) in Q30, each
// component dᵢ·2³⁰ + Σ (r − 1)ⱼ·(q + d)ₖ exact in int64 and rounded once.
// Range: q passed norm_within(), |dᵢ| ≤ 2⁻⁴ (the aberration increment,
// ≤ 1.7e-3), the components of r − 1 within ±2⁻⁴ (thermal, angles ≤ 1°:
// ≤ 0.016); then |q + d| < 1.07, each product < 2⁵⁷ and each result ≤ 2⁻³.
constexpr Quaternion<Q30> add_left_increment(const Quaternion<Q30>& d, const SmallRotation<Q30>& r,
                                             const Quaternion<Q30>& q) noexcept {
    using fx::round30_sum;
    using fx::unshared;
    const std::int32_t sw = unshared(q.w.raw + d.w.raw);
    const std::int32_t sx = unshared(q.x.raw + d.x.raw);
    const std::int32_t sy = unshared(q.y.raw + d.y.raw);
    const std::int32_t sz = unshared(q.z.raw + d.z.raw);
    const std::int32_t aw = unshared(r.dw.raw);
    const std::int32_t ax = unshared(r.v.x.raw);
    const std::int32_t ay = unshared(r.v.y.raw);
    const std::int32_t az = unshared(r.v.z.raw);
    const auto units60 = [](Q30 x) { return std::int64_t{x.raw} * (std::int64_t{1} << 30); };
    // (r − 1) ⊗ s: w = aw sw − ax sx − ay sy − az sz, x = aw sx + ax sw + ay sz − az sy,
    //              y = aw sy − ax sz + ay sw + az sx,  z = aw sz + ax sy − ay sx + az sw.
    return {round30_sum(units60(d.w), aw, sw, -ax, sx, -ay, sy, -az, sz),
            round30_sum(units60(d.x), aw, sx, ax, sw, ay, sz, -az, sy),
            round30_sum(units60(d.y), aw, sy, -ax, sz, ay, sw, az, sx),
            round30_sum(units60(d.z), aw, sz, ax, sy, -ay, sx, az, sw)};
}

// renormalized_sum (quaternion.hpp) in Q30: s = q + d (exact), ε = ‖s‖² − 1
// exact in int64, and each component sᵢ·(1 + g) with the Newton step taken to
// second order, g = −ε/2 + 3ε²/8 (1/√(1 + ε) = 1 − ε/2 + 3ε²/8 − …): then
// ‖result‖² − 1 = 5ε³/8 + O(ε⁴), which stays below 2⁻³⁰ for |ε| ≤ 1.1e-3,
// four times what the thermal rotation's scale (≤ 2.3e-4) and the input's
// tolerance (1e-6) add. g and each sᵢ·g are rounded once. Range: q passed
// norm_within(), |dᵢ| ≤ 2⁻⁴ (the corrections' increments are ≤ 0.017,
// correct.hpp); then |sᵢ| < 1.07, ‖s‖² < 4.6 (< 2⁶³ in units 2⁻⁶⁰); with
// |dᵢ| ≤ 2⁻⁴, |ε| ≤ 0.27, |g| < 0.17 and every result < 1.3 in magnitude
// (the actual increments give |ε| ≤ 0.07).
constexpr Quaternion<Q30> renormalized_sum(const Quaternion<Q30>& q, const Quaternion<Q30>& d) noexcept {
    using fx::unshared;
    const std::int32_t sw = unshared(q.w.raw + d.w.raw);
    const std::int32_t sx = unshared(q.x.raw + d.x.raw);
    const std::int32_t sy = unshared(q.y.raw + d.y.raw);
    const std::int32_t sz = unshared(q.z.raw + d.z.raw);
    const std::int64_t eps = fx::accumulate_products(-(std::int64_t{1} << 60), sw, sw, sx, sx, sy, sy, sz, sz);
    const std::int32_t e = fx::round_shift_to_int32<30>(eps);  // ε, Q30
    const std::int32_t g = fx::round_shift_to_int32<33>(3 * fx::mul(e, e)) - fx::round_shift_to_int32<31>(eps);
    const auto step = [g](std::int32_t s) { return s + fx::round30_sum(0, s, g).raw; };
    return {{step(sw)}, {step(sx)}, {step(sy)}, {step(sz)}};
}

// beta_in_domain (aberration.hpp) in Q30, for any input: each component
// within ±kMaxBeta (then |βᵢ| < 2²², the squares are exact and small), then
// |β|² against kMaxBeta² exactly, in units 2⁻⁶⁰.
constexpr bool beta_in_domain(const Vector3<Q30>& beta) noexcept {
    constexpr std::int32_t lim = fx::raw_from_double<Q30::kFracBits>(kMaxBeta);
    constexpr auto lim2 = static_cast<std::int64_t>(kMaxBeta * kMaxBeta * 0x1p60);
    const auto within = [](Q30 c) { return c.raw <= lim && -lim <= c.raw; };
    return within(beta.x) && within(beta.y) && within(beta.z) &&
           fx::mul(beta.x.raw, beta.x.raw) + fx::mul(beta.y.raw, beta.y.raw) + fx::mul(beta.z.raw, beta.z.raw) <= lim2;
}

// aberration_rotation (aberration.hpp) in Q30: the same q_ab, with the series
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
    const std::int32_t p = fx::round30_sum(0, zx, bx, zy, by, zz, bz).raw;
    const std::int32_t cx = fx::round30_sum(0, zy, bz, zz, -by).raw;
    const std::int32_t cy = fx::round30_sum(0, zz, bx, zx, -bz).raw;
    const std::int32_t cz = fx::round30_sum(0, zx, by, zy, -bx).raw;
    const std::int64_t n = fx::sum_products(cx, cx, cy, cy, cz, cz);  // units 2⁻⁶⁰
    constexpr std::int32_t kOne = std::int32_t{1} << 30;
    const std::int32_t f = kOne - fx::round_shift_to_int32<1>(p) + fx::round_shift_to_int32<31>(fx::mul(p, p));
    const std::int32_t half_1_x8 = (kOne >> 1) + fx::round_shift_to_int32<34>(n);  // (1 + n/8)/2
    const std::int32_t scale = fx::round30_sum(0, f, half_1_x8).raw;
    return {{-fx::round_shift_to_int32<33>(n)},
            {fx::round30_sum(0, scale, cx), fx::round30_sum(0, scale, cy), fx::round30_sum(0, scale, cz)}};
}

namespace fx {

// (t·2⁻²⁰)² in units of 2⁻¹² °C², rounded to nearest. |t| ≤ 2²⁹ (≤ 512 °C):
// t² ≤ 2⁵⁸ fits int64 and the result ≤ 2¹⁸·2¹² = 2³⁰ fits int32. Error ≤ 2⁻¹³ °C².
constexpr std::int32_t square_celsius(std::int32_t t) noexcept {
    const std::int32_t u = unshared(t);
    return round_shift_to_int32<2 * QCelsius::kFracBits - 12>(mul(u, u));
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
// coefficients and QCelsius temperatures (thermal.hpp for the polynomial).
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
template <>
[[gnu::always_inline]] constexpr Q30 thermal_angle<Q30>(const AxisPolynomial<Q30>& p, const QCelsius& t1,
                                                        const QCelsius& t2, const QCelsius& t3) noexcept {
    using fx::mul;
    constexpr int kSumFrac = QCoefficient::kFracBits + QCelsius::kFracBits;       // 56
    constexpr int kQuadShift = QQuadraticCoefficient::kFracBits + 12 - kSumFrac;  // 4
    const std::int32_t a = fx::clamp_celsius(t1.raw);
    const std::int32_t d2 = fx::clamp_celsius(t2.raw) - a;
    const std::int32_t d3 = fx::clamp_celsius(t3.raw) - a;
    std::int64_t sum =
        fx::sum_products(p.c0.raw, std::int32_t{1} << QCelsius::kFracBits, p.c1.raw, a, p.c2.raw, d2, p.c3.raw, d3);
    if ((p.c1_2.raw | p.c2_2.raw | p.c3_2.raw) != 0) {
        sum += fx::round_shift(fx::sum_products(p.c1_2.raw, fx::square_celsius(a), p.c2_2.raw, fx::square_celsius(d2),
                                                p.c3_2.raw, fx::square_celsius(d3)),
                               kQuadShift);
    }
    return {fx::narrow_shift<kSumFrac - Q30::kFracBits>(sum)};
}

// ---- The thermal rotation in Q30 (thermal.hpp: q_th = q3(γ) ⊗ q2(β) ⊗ q1(α)),
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
    const std::int32_t h2 = round_shift_to_int32<32>(mul(a, a));  // (a/2)², Q30, < 2¹⁷
    const std::int32_t half_1_h2_3 = (std::int32_t{1} << 29) + round_shift_to_int32<32>(mul(h2, kSixth));
    return round30_sum(0, a, half_1_h2_3).raw;  // (a/2)·(1 + h²/3)
}

}  // namespace fx

constexpr SmallRotation<Q30> thermal_rotation(const Q30& alpha, const Q30& beta, const Q30& gamma) noexcept {
    using fx::round30_sum;
    const std::int32_t t1 = fx::tan_half_angle(alpha);
    const std::int32_t t2 = fx::tan_half_angle(beta);
    const std::int32_t t3 = fx::tan_half_angle(gamma);
    const std::int32_t t12 = round30_sum(0, t1, t2).raw;
    const std::int32_t t13 = round30_sum(0, t1, t3).raw;
    const std::int32_t t23 = round30_sum(0, t2, t3).raw;
    const std::int32_t t123 = round30_sum(0, t12, t3).raw;
    return {{-t123}, {{-t1 - t23}, {t13 - t2}, {-t12 - t3}}};
}

// ---- Guards: a Q30 call never falls back to a generic template.
// Each kernel above is an overload of a generic template of the core (which
// rounds per product, saturates per operation and, for the series, is cut for
// floating point). Overload resolution prefers these non-templates only while
// their signatures match the call; one that drifts (a parameter's type or
// reference changed) would silently lose to the template. The templates'
// Q30 specialisations are therefore deleted: such a call does not compile.
// The error analysis of each kernel stays with the kernel above.
// tests/compile_fail/q30_guards.cpp checks every line (and, as its control,
// that the same calls compile for float).
template <>
Q30 dot<Q30>(const Vector3<Q30>&, const Vector3<Q30>&) noexcept = delete;
template <>
Q30 squared_norm<Q30>(const Vector3<Q30>&) noexcept = delete;
template <>
Vector3<Q30> cross<Q30>(const Vector3<Q30>&, const Vector3<Q30>&) noexcept = delete;
template <>
Q30 dot<Q30>(const Quaternion<Q30>&, const Quaternion<Q30>&) noexcept = delete;
template <>
Q30 squared_norm<Q30>(const Quaternion<Q30>&) noexcept = delete;
template <>
Quaternion<Q30> operator*<Q30>(const Quaternion<Q30>&, const Quaternion<Q30>&) noexcept = delete;
template <>
Vector3<Q30> boresight<Q30>(const Quaternion<Q30>&) noexcept = delete;
template <>
SmallRotation<Q30> conjugate<Q30>(const SmallRotation<Q30>&) noexcept = delete;
template <>
bool norm_within<Q30>(const Quaternion<Q30>&, const Q30&) noexcept = delete;
template <>
Quaternion<Q30> right_increment<Q30>(const Quaternion<Q30>&, const SmallRotation<Q30>&) noexcept = delete;
template <>
Quaternion<Q30> add_left_increment<Q30>(const Quaternion<Q30>&, const SmallRotation<Q30>&,
                                        const Quaternion<Q30>&) noexcept = delete;
template <>
Quaternion<Q30> renormalized_sum<Q30>(const Quaternion<Q30>&, const Quaternion<Q30>&) noexcept = delete;
template <>
bool beta_in_domain<Q30>(const Vector3<Q30>&) noexcept = delete;
template <>
SmallRotation<Q30> aberration_rotation<Q30>(const Vector3<Q30>&, const Vector3<Q30>&, const Q30&) noexcept = delete;
template <>
SmallRotation<Q30> thermal_rotation<Q30>(const Q30&, const Q30&, const Q30&) noexcept = delete;

}  // namespace ascorr
