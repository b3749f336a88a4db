// ascorr/core/model_terms.hpp: the thermal model's terms, one table of regressors.
//
// Conventions (paper eqs. 4–10; thermal.hpp; docs/contract.md "Model file"):
// an axis' angle is Σₖ cₖ·xₖ over the terms of kModelTermTable, each term a
// power of one regressor of a head's temperatures: 1, x₁ = T1, x₂ = T2 − T1,
// x₃ = T3 − T1 (°C). A term's entry gives
//  - its name: the model file's column and the name in every message;
//  - its regressor and power: its function of T1..T3 (term_value below, the
//    fit's design and the estimator's unknowns);
//  - by its power, its format: ScalarTraits<T>::coefficient for powers 0 and 1,
//    quadratic_coefficient for 2 (model_coefficients.hpp), and so its word
//    on the link (wire.hpp).
// The table's order is the order of the model file's columns, of
// ModelCoefficients::coefficient[head][axis][term], of AxisPolynomial's
// fields (for_each_term, thermal.hpp) and of the link's words; the linear
// terms (powers 0 and 1) come first, so a linear model is a prefix. This
// header is the one place that says which terms there are; the counts below
// are derived from it (DEVELOPERS.md, "Add a model term").
#pragma once

#include <cstdint>

namespace ascorr {

enum class Regressor : std::uint8_t {
    kOne = 0,        // the constant term's
    kT1 = 1,         // x₁ = T1 = T_CHU
    kT2MinusT1 = 2,  // x₂ = T2 − T1, T2 = THT00029
    kT3MinusT1 = 3,  // x₃ = T3 − T1, T3 = THT00032
};
inline constexpr std::uint8_t kRegressors = 3;  // x₁, x₂, x₃: x[j] is x_{j+1}

struct ModelTerm {
    const char* name;     // the model file's column
    Regressor regressor;  // kOne for the constant
    std::uint8_t power;   // 0 (constant), 1 (linear) or 2 (quadratic)
};

inline constexpr ModelTerm kModelTermTable[] = {
    {"c0", Regressor::kOne, 0},          // arcsec (rad in the core)
    {"c1", Regressor::kT1, 1},           // arcsec/°C
    {"c2", Regressor::kT2MinusT1, 1},    //
    {"c3", Regressor::kT3MinusT1, 1},    //
    {"c1_2", Regressor::kT1, 2},         // arcsec/°C²
    {"c2_2", Regressor::kT2MinusT1, 2},  //
    {"c3_2", Regressor::kT3MinusT1, 2},  //
};

inline constexpr std::uint8_t kModelAxes = 3;  // alpha, beta, gamma
inline constexpr std::uint8_t kModelTerms = sizeof(kModelTermTable) / sizeof(kModelTermTable[0]);

// The count of linear terms (powers 0 and 1) at the table's head.
constexpr std::uint8_t linear_prefix() noexcept {
    std::uint8_t n = 0;
    while (n < kModelTerms && kModelTermTable[n].power <= 1) {
        ++n;
    }
    return n;
}
inline constexpr std::uint8_t kLinearModelTerms = linear_prefix();  // the rest are quadratic

// Whether the table keeps the conventions above: the constant first, linear
// terms before quadratic ones, powers 0 … 2, a constant only with power 0.
constexpr bool table_well_formed() noexcept {
    bool ok = kModelTerms > 0 && kModelTermTable[0].regressor == Regressor::kOne;
    for (std::uint8_t k = 0; k < kModelTerms; ++k) {
        const ModelTerm& t = kModelTermTable[k];
        ok = ok && t.power <= 2 && (t.regressor == Regressor::kOne) == (t.power == 0) &&
             (k < kLinearModelTerms) == (t.power <= 1);
    }
    return ok;
}
static_assert(table_well_formed(), "model_terms.hpp: constant first, then linear terms, then quadratic ones");

// Whether term k takes the quadratic coefficient format.
constexpr bool quadratic_term(std::uint8_t k) noexcept {
    return kModelTermTable[k].power == 2;
}

// Term k as a compile-time constant, for the visitors of named fields
// (for_each_term, thermal.hpp): a visitor chooses the term's format with
// `if constexpr (quadratic_term(K::value))`.
template <std::uint8_t K>
struct TermIndex {
    static_assert(K < kModelTerms, "a term of kModelTermTable");
    static constexpr std::uint8_t value = K;
    constexpr operator std::uint8_t() const noexcept { return K; }  // converts: k indexes arrays
};

// The index j into x[] of term k's regressor (term k must not be the constant).
constexpr std::uint8_t regressor_index(std::uint8_t k) noexcept {
    return static_cast<std::uint8_t>(static_cast<std::uint8_t>(kModelTermTable[k].regressor) - 1U);
}

// The index of the term of regressor r and power p; kModelTerms when the
// table has none.
constexpr std::uint8_t term_index(Regressor r, std::uint8_t p) noexcept {
    std::uint8_t k = 0;
    while (k < kModelTerms && !(kModelTermTable[k].regressor == r && kModelTermTable[k].power == p)) {
        ++k;
    }
    return k;
}

// Term k's contribution c·xⱼ^p, evaluated left to right (c, c·x, c·x·x)
// in T; x = (x₁, x₂, x₃).
template <typename T>
constexpr T term_value(std::uint8_t k, const T& c, const T (&x)[kRegressors]) noexcept {
    const std::uint8_t p = kModelTermTable[k].power;
    if (p == 0) {
        return c;
    }
    const T& xj = x[regressor_index(k)];
    return p == 1 ? c * xj : c * xj * xj;
}

// The model's angle of one axis, Σₖ cₖ·xₖ summed in the table's order, in
// the unit of c (the host's and the estimator's double evaluation; the
// core's scalars evaluate thermal_angle, thermal.hpp).
template <typename T>
constexpr T model_polynomial(const T (&c)[kModelTerms], const T (&x)[kRegressors]) noexcept {
    T sum = term_value(0, c[0], x);
    for (std::uint8_t k = 1; k < kModelTerms; ++k) {
        sum += term_value(k, c[k], x);
    }
    return sum;
}

}  // namespace ascorr
