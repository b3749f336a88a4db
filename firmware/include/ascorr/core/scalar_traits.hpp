// ascorr/core/scalar_traits.hpp: per-scalar constants, tolerances and maths hooks.
//
// The core is written once, templated on a scalar type T, and instantiated for
// double (ground), float (DPU with single-precision FPU) and a Q-format fixed
// point type (DPU without FPU). Everything the core needs to know about T lives
// here, so the algorithms never name FLT_EPSILON or call std:: maths directly:
//
//  - values are converted by ScalarTraits<T>::from_double() (the one
//    conversion, see below), constants by constant<T>(), folded at compile
//    time for every T;
//  - is_finite() is found by argument-dependent lookup (a fixed-point type is
//    always finite and supplies its own);
//  - the tolerances that decide "bad input" are per type, because what counts
//    as rounding noise depends on the representation;
//  - double_precision says whether the core's truncated series carry the
//    terms that only a double resolves (each dropped term's bound is stated
//    where the series is).
//
// A new scalar type specialises ScalarTraits and provides is_finite() in its
// own namespace. The core itself never calls sqrt, sin, cos or divides: every
// nonlinear function is a truncated series whose error is bounded where it is
// used, so that the same code is cheap on a Cortex-M without FPU.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstring>

namespace ascorr {

template <typename T>
struct ScalarTraits;  // specialised per scalar type

template <>
struct ScalarTraits<double> {
    using coefficient_type = double;            // thermal-model coefficients (rad, rad/°C)
    using quadratic_coefficient_type = double;  // quadratic thermal-model coefficients (rad/°C²)
    using temperature_type = double;            // °C
    static constexpr double from_double(double x) noexcept { return x; }
    static constexpr double to_double(double x) noexcept { return x; }
    static constexpr double celsius(double x) noexcept { return x; }
    static constexpr double coefficient(double x) noexcept { return x; }
    static constexpr double quadratic_coefficient(double x) noexcept { return x; }
    // |‖q‖² − 1| above this rejects a quaternion. Recorded files carry 15
    // decimals (‖q‖² − 1 ≈ 1e-15); 1e-6 leaves room for producers that
    // normalise in float, and is far below any real attitude error
    // (1e-6 in ‖q‖² is a pure scale, not a rotation).
    static constexpr double unit_norm_tolerance = 1e-6;
    // The core's series keep the terms that only double resolves.
    static constexpr bool double_precision = true;
};

template <>
struct ScalarTraits<float> {
    using coefficient_type = float;
    using quadratic_coefficient_type = float;
    using temperature_type = float;
    static constexpr float from_double(double x) noexcept { return static_cast<float>(x); }
    static constexpr double to_double(float x) noexcept { return static_cast<double>(x); }
    static constexpr float celsius(double x) noexcept { return static_cast<float>(x); }
    static constexpr float coefficient(double x) noexcept { return static_cast<float>(x); }
    static constexpr float quadratic_coefficient(double x) noexcept { return static_cast<float>(x); }
    // Rounding four float components leaves ‖q‖² − 1 up to ~4.8e-7.
    static constexpr float unit_norm_tolerance = 1e-5F;
    // Series terms below float's resolution (2⁻²⁴ relative) are dropped,
    // each with its bound where the series is (aberration.hpp, thermal.hpp).
    static constexpr bool double_precision = false;
};

// Finite-ness of floating-point scalars. Unqualified calls to is_finite(x) in
// the core resolve here for float/double and to the fixed-point overload by ADL.
inline bool is_finite(double x) noexcept {
    return std::isfinite(x);
}
inline bool is_finite(float x) noexcept {
    return std::isfinite(x);
}

// |x| ≤ lim (lim ≥ 0), false for NaN: one comparison after clearing the sign.
// A fixed-point scalar overloads this.
inline bool abs_within(double x, double lim) noexcept {
    return std::fabs(x) <= lim;
}
inline bool abs_within(float x, float lim) noexcept {
    return std::fabs(x) <= lim;
}
// The same in float on the IEEE 754 binary32 bit patterns shifted left by one
// (the sign dropped): they order as the magnitudes do, and a NaN's lies above
// +∞'s, so for lim ≥ 0 this is exactly fabs(x) ≤ lim (test
// Core.FloatBitsWithinIsTheFabsOne). On the M4F, where x is in an FPU
// register, a move and one compare with a shifted operand: 3 instructions
// before the branch where vabs, vcmpe and vmrs take 4. Where x is read from
// memory GCC 12 may pass it through the stack instead (the lag stage +3
// measured with every float check so), so only the thermal angles, which
// are computed in registers, use it (correct.hpp).
inline bool abs_within_bits(float x, float lim) noexcept {
    return (__builtin_bit_cast(std::uint32_t, x) << 1U) <= (__builtin_bit_cast(std::uint32_t, lim) << 1U);
}
// The same for an x in memory, read as an integer: an integer load, a
// compare with a shifted operand and a branch on the M4F, where a value
// loaded into an FPU register takes vabs, vcmpe and vmrs (the lag stage's
// readings, temperature_lag.hpp).
inline bool abs_within_bits_at(const float& x, float lim) noexcept {
    std::uint32_t bits = 0U;
    std::memcpy(&bits, &x, sizeof bits);
    return (bits << 1U) <= (__builtin_bit_cast(std::uint32_t, lim) << 1U);
}

// A fixed-point scalar holds unit quantities (quaternions, v/c, radians) in a
// format with range ±2; coefficients (linear and quadratic, whose magnitudes
// differ by 1e3–1e4) and temperatures need other formats, so
// the core names them through these aliases. For float and double all are T.
template <typename T>
using Coefficient = typename ScalarTraits<T>::coefficient_type;
template <typename T>
using QuadraticCoefficient = typename ScalarTraits<T>::quadratic_coefficient_type;
template <typename T>
using Celsius = typename ScalarTraits<T>::temperature_type;

// ScalarTraits<T>::from_double is the one conversion from double to T (and
// to_double, celsius, coefficient, quadratic_coefficient the others of each
// format), at compile time and at run time alike: the host's readers, the
// velocity node (nav/velocity_node.hpp) and the literals of the algorithms all
// use it. For Q30 it is one product by the exact constant 2³⁰, two comparisons
// and one conversion (fx.hpp: fx::raw_from_double).
//
//   T       range                 rounding                     saturation
//   double  any                   exact                        none
//   float   |x| ≤ 3.4e38          to nearest, ties to even     none: beyond
//           (FLT_MAX)             (relative error ≤ 2⁻²⁴)      FLT_MAX ±inf
//                                                              (IEEE), NaN stays
//   Q30     [−2, 2 − 2⁻³⁰]        to nearest 2⁻³⁰, ties away   to ±(2 − 2⁻³⁰)
//           (raw ±(2³¹ − 1))      from zero (error ≤ 2⁻³¹)     (raw ±(2³¹ − 1));
//                                                              NaN → 2 − 2⁻³⁰
//
// constant<T>(x): the same conversion, named for the literals of the
// algorithms (½, 1, series coefficients, domain limits). Every call is bound
// to a constexpr variable (constexpr T half = constant<T>(0.5);), so the
// conversion is folded at every optimisation level and a -O0 build of the
// fixed-point core references no soft-float routine (checked on the
// Cortex-M3 Debug image, tests/target/target-tests.cmake).
// Every constant of the core lies within ±1.7 (the largest: 1/0.6 au, the
// Sun-distance domain), so none is rounded by more than 2⁻³¹ or saturated.
template <typename T>
constexpr T constant(double x) noexcept {
    return ScalarTraits<T>::from_double(x);
}

}  // namespace ascorr
