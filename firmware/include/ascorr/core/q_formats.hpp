// ascorr/core/q_formats.hpp: the fixed-point formats of the core (DPU without FPU).
//
//
// Conventions (CMSIS style: every format states range, scaling, rounding and
// saturation; 32-bit storage, 64-bit intermediates (fx.hpp), no floating point
// at run time but the conversions from double (constants, folded at compile
// time; the host's readers; the velocity node, once per node)):
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
//                         generic functions for any input (vector3.hpp,
//                         quaternion.hpp): exact products summed in int64,
//                         rounded and saturated once per result.
//      the correction's kernels (quaternion.hpp: norm_within, boresight,
//      right_increment, add_left_increment, renormalized_sum; aberration.hpp:
//      beta_in_domain, aberration_rotation; thermal.hpp: thermal_angle,
//      thermal_rotation) : Q30 versions of the core's functions, each beside
//                         its generic version with its range argument and its
//                         guard: the core's checks bound their operands, so
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
//  coefficient, quadratic_coefficient; fx::raw_from_double) round to nearest (ties away from zero) and saturate to the
//  symmetric range [−(2³¹ − 1), 2³¹ − 1] raw; NaN maps
//  to the positive end of the range, so that a non-finite input lands outside
//  every domain check of the core and is flagged exactly as it would be in
//  floating point (is_finite() is always true for a fixed-point value).
#pragma once

#include <cstdint>

#include "compiler.hpp"
#include "fx.hpp"
#include "scalar_traits.hpp"

namespace ascorr {

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
    return {fx::narrow_sat<30>(fx::mul(a.raw, b.raw))};
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
    // The core's series have Q30 versions (aberration_rotation in
    // aberration.hpp, thermal_rotation in thermal.hpp), cut at the format's
    // resolution.
    static constexpr bool double_precision = false;
};

}  // namespace ascorr
