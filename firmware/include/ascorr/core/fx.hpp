// ascorr/core/fx.hpp: the integer arithmetic under the Q formats (q_formats.hpp).
//
// Conventions (CMSIS style): a Q value is a 32-bit raw integer, value
// = raw·2^−F for its format's F fractional bits; intermediates are 64-bit;
// nothing here uses floating point at run time but the conversions from and
// to double. Each function states its range, scaling, rounding and saturation.
// Rounding is always to nearest; ties go towards +∞ (add 2^(S−1), then
// arithmetic shift right by S, compiler.hpp) except in the conversion from
// double (ties away from zero, as a decimal constant is read).
//
//   function               in → out       scaling      rounding     saturation
//   raw_from_double<F>(x)  double → i32   x·2^F        nearest,     to ±(2³¹ − 1);
//                                                      ties away    NaN → 2³¹ − 1
//   raw_to_double<F>(r)    i32 → double   r·2^−F       exact        none
//   add_sat, sub_sat,      i32 → i32      none         exact        to [−2³¹, 2³¹ − 1]
//   neg_sat
//   round_shift<S>(v)      i64 → i64      v·2^−S       nearest      none (fits)
//   narrow<S>(acc, a₀, b₀, …)
//                          i64, i32 pairs (acc + Σ aᵢbᵢ)·2^−S
//                                 → i32                nearest      none: the caller
//                                                                   states the range
//   narrow_sat<S>(v)       i64 → i32      v·2^−S       nearest      to [−2³¹, 2³¹ − 1]
//   mul_high(a, b)         i32 → i32      a·b·2^−32    towards −∞   none (|result| ≤ 2³⁰)
//
// and the exact products the sums are made of: mul, accumulate_products,
// sum_products (and unshared(), which keeps them single SMULL/SMLAL on Armv7-M).
#pragma once

#include <cstdint>

#include "compiler.hpp"

namespace ascorr::fx {

inline constexpr std::int32_t kRawMax = INT32_MAX;
inline constexpr std::int32_t kRawMin = INT32_MIN;

// ---- Conversions (compile time for constants; at run time one product).

// 2^e as a double, exact for |e| ≤ 1022; for the constants below (folded at
// compile time).
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

// x·2^F as a raw value: one multiplication (by the exact constant 2^F),
// rounded to nearest (ties away from zero), saturated to the symmetric range
// ±(2³¹ − 1) (−2³¹ is never produced); NaN → kRawMax. At run time: one double
// product, two comparisons and one conversion.
template <int F>
constexpr std::int32_t raw_from_double(double x) noexcept {
    constexpr double kScale = pow2(F);
    const double s = x * kScale;
    if (!(s < 2147483647.0)) {
        return kRawMax;  // also NaN
    }
    if (s <= -2147483647.0) {
        return -kRawMax;
    }
    return static_cast<std::int32_t>(s < 0.0 ? s - 0.5 : s + 0.5);
}

// raw·2^−F, exact (a 32-bit integer times a power of two).
template <int F>
constexpr double raw_to_double(std::int32_t raw) noexcept {
    constexpr double kScale = pow2(-F);
    return static_cast<double>(raw) * kScale;
}

// ---- Saturating sums of two raws of one format: exact when the result is in
// [−2³¹, 2³¹ − 1], else the nearest end (never wraps).

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

// ---- Exact products.

// x, as a value the compiler cannot identify with x. The Q30 kernels take
// their operands through this where it measures cheaper (the target bench;
// sun_term.hpp's kernel does not), so that their 64-bit sign extensions are not
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

// a·b exactly, in 64 bits (one SMULL; SMLAL into a sum). |a·b| ≤ 2⁶².
constexpr std::int64_t mul(std::int32_t a, std::int32_t b) noexcept {
    return std::int64_t{a} * b;
}

// ⌊a·b·2^−32⌋: the high word of one SMULL, for a product whose low bits a
// kernel can give up (its error, in [0, 1) of the result's LSB, is stated by
// the caller). Range: any a, b; |result| ≤ 2³⁰.
constexpr std::int32_t mul_high(std::int32_t a, std::int32_t b) noexcept {
    return static_cast<std::int32_t>(mul(a, b) >> 32);
}

// acc + Σ aᵢ·bᵢ over the pairs (a₀, b₀, a₁, b₁, …), exact: a chain of SMLAL.
// Precondition: the sum fits int64 (each caller states its range).
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

// ---- The rounding family: v·2^−S to nearest, ties towards +∞.

// Range: S in [1, 62], v + 2^(S−1) fits int64. Result in int64, not saturated.
template <int S>
constexpr std::int64_t round_shift(std::int64_t v) noexcept {
    static_assert(S >= 1 && S <= 62, "shift");
    return (v + (std::int64_t{1} << (S - 1))) >> S;
}

// (acc + Σ aᵢ·bᵢ)·2^−S to int32, not saturated: a sum of products rounded
// once. The rounding constant starts the accumulator, so the rounding costs
// no instruction of its own (one SMULL/SMLAL chain and a shift). Range:
// S in [1, 62], the sum plus 2^(S−1) fits int64 and the result fits int32
// (each caller states why). With no pairs, v·2^−S for one v.
template <int S, typename... Pairs>
constexpr std::int32_t narrow(std::int64_t acc, Pairs... pairs) noexcept {
    static_assert(S >= 1 && S <= 62, "shift");
    return static_cast<std::int32_t>(accumulate_products(acc + (std::int64_t{1} << (S - 1)), pairs...) >> S);
}

// v·2^−S to int32, saturated to [−2³¹, 2³¹ − 1]. Range: S in [1, 31],
// |v| ≤ 2⁶³ − 2^(S−1). The range test is on the high word only: the result
// fits iff r = v + 2^(S−1) lies in [−2^(31+S), 2^(31+S)), i.e. iff the top
// 33 − S bits of r's high word are all equal.
template <int S>
constexpr std::int32_t narrow_sat(std::int64_t v) noexcept {
    static_assert(S >= 1 && S <= 31, "shift");
    const std::int64_t r = v + (std::int64_t{1} << (S - 1));
    const auto u = static_cast<std::uint64_t>(r);
    const auto hi = static_cast<std::uint32_t>(u >> 32U);
    if (hi + (std::uint32_t{1} << (S - 1)) >= (std::uint32_t{1} << S)) {
        return static_cast<std::int32_t>(hi) < 0 ? kRawMin : kRawMax;
    }
    return static_cast<std::int32_t>((static_cast<std::uint32_t>(u) >> S) | (hi << (32 - S)));
}

}  // namespace ascorr::fx
