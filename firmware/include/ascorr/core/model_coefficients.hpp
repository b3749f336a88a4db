// ascorr/core/model_coefficients.hpp: a thermal model as plain numbers, and the one
// conversion of such numbers into the core's ThermalModel<T>.
//
// Conventions: coefficient[head][axis][term], head by index (heads.hpp), axis
// alpha, beta, gamma (0, 1, 2; kModelAxes of them), term by kModelTermTable
// (model_terms.hpp: c0, c1, c2, c3, c1_2, c2_2, c3_2, the model file's
// columns, docs/contract.md "Model file"), in one unit given with
// the numbers: `unit_to_rad` = kArcsecToRad for a model file's arcsec (arcsec/°C,
// arcsec/°C²), 1 for radians. Each coefficient is multiplied by unit_to_rad in
// double (× 1 is exact) and then rounded once into T's formats by
// ScalarTraits<T>::coefficient (powers 0, 1) or quadratic_coefficient (2):
// round to nearest; the fixed-point formats saturate, so a loader must refuse
// a model beyond ScalarTraits<Q30>::max_coefficient / max_quadratic_coefficient
// first (the host's check_fixed_point_range). Every producer of a core model
// (the host's model files and Python's ascorr.Model, the flight application's
// built-in Table 2, the example consumer, the target test vectors) converts
// through thermal_model() below; constexpr, so the flight model is converted
// at compile time. No allocation, fixed trip counts (kMaxHeads × kModelAxes).
#pragma once

#include <cstdint>

#include "constants.hpp"
#include "heads.hpp"
#include "model_terms.hpp"
#include "scalar_traits.hpp"
#include "thermal.hpp"

namespace ascorr {

struct ModelCoefficients {
    bool present[kMaxHeads];  // false: no coefficients for this head (status 256)
    double coefficient[kMaxHeads][kModelAxes][kModelTerms];
};

// One axis: kModelTerms numbers in the unit of unit_to_rad → the core's
// formats, each by its term's format.
template <typename T>
constexpr AxisPolynomial<T> axis_polynomial(const double (&c)[kModelTerms], double unit_to_rad) noexcept {
    using Tr = ScalarTraits<T>;
    AxisPolynomial<T> p{};
    for_each_term(p, [&](auto k, auto& field) {
        if constexpr (quadratic_term(decltype(k)::value)) {
            field = Tr::quadratic_coefficient(c[k] * unit_to_rad);
        } else {
            field = Tr::coefficient(c[k] * unit_to_rad);
        }
    });
    return p;
}

// ---- The float core's thermal angle over the whole temperature domain.
// thermal_angle<float> (thermal.hpp) of one axis, at temperatures within
// ±kMaxAbsTemperatureC, differs from the exact polynomial of the axis' double
// coefficients by at most 12·2⁻²⁴·S (first order), with
//   S = |c0| + 200·|c1| + 400·(|c2| + |c3|) + 200²·|c1_2| + 400²·(|c2_2| + |c3_2|)  (rad),
// the largest sum of the terms' magnitudes over the domain (T1 within ±200 °C,
// T2 − T1 and T3 − T1 within ±400 °C): coefficients and temperatures rounded
// to float (2⁻²⁴ each), the differences (≤ 2·2⁻²⁴·400 °C), the products and
// inner sums (≤ 8·2⁻²⁴ of a term), the three outer sums (≤ 3·2⁻²⁴·S). Terms
// that cancel leave that error in a small angle. With S ≤ kFloatMaxTermSumRad
// for every head and axis the angle is within kFloatAngleErrorRad (0.01″, a
// fifth of the float path's 0.05″, tests/target/accuracy-bounds.txt); a
// loader refuses a model beyond it for the float scalar (the host's
// check_float_range), as one beyond the Q30 formats for fixed point. (Table
// 2's largest S is 1152″; the limit is 13981″.)
inline constexpr double kFloatAngleErrorRad = 0.01 * kArcsecToRad;
inline constexpr double kFloatMaxTermSumRad = kFloatAngleErrorRad / (12.0 * 0x1p-24);

// S above for one axis' coefficients c in the unit of unit_to_rad, in rad.
// Written out by term (not a loop over the table: the sums by regressor
// round as they always did).
constexpr double float_term_sum(const double (&c)[kModelTerms], double unit_to_rad) noexcept {
    static_assert(kModelTerms == 7, "float_term_sum bounds every term of kModelTermTable");
    constexpr double t = kMaxAbsTemperatureC;
    constexpr double d = 2.0 * kMaxAbsTemperatureC;
    const auto mag = [](double x) { return x < 0.0 ? -x : x; };
    return (mag(c[0]) + t * mag(c[1]) + d * (mag(c[2]) + mag(c[3])) + t * t * mag(c[4]) +
            d * d * (mag(c[5]) + mag(c[6]))) *
           unit_to_rad;
}

// The whole model; a head not present keeps zero coefficients.
template <typename T>
constexpr ThermalModel<T> thermal_model(const ModelCoefficients& m, double unit_to_rad) noexcept {
    ThermalModel<T> out{};
    for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
        out.head[h].present = m.present[h];
        out.head[h].alpha = axis_polynomial<T>(m.coefficient[h][0], unit_to_rad);
        out.head[h].beta = axis_polynomial<T>(m.coefficient[h][1], unit_to_rad);
        out.head[h].gamma = axis_polynomial<T>(m.coefficient[h][2], unit_to_rad);
    }
    return out;
}

}  // namespace ascorr
