// ascorr/combine/kernels.hpp: the combination's per-epoch arithmetic, in the scalar T.
//
// Conventions (quaternion.hpp; combiner.hpp): a head's estimate q_crf_icrf_i
// differs from the reference attitude q_ref by a small rotation in CRF axes,
// applied on the left: q_crf_icrf_i = δ_i ⊗ q_ref. The combiner works with the
// half-angle vector of δ_i,
//   h_i = vec(δ_i) = vec(q_crf_icrf_i ⊗ q_ref*), sign chosen so that w(δ_i) ≥ 0,
// which is sin(φ/2)·axis = θ_i/2 + O(φ³): for φ ≤ 2⁻⁸ rad (the gross gate,
// combiner.hpp; 806″) the relative difference sin(φ/2)/(φ/2) − 1 ≤ φ²/24
// ≤ 6.4e-7, at the consistency gate's floor of 60″ 3.5e-9 (2e-7″). Applying
// the weighted mean h̄ as (1, h̄) ⊗ ref, renormalised, turns by 2·atan|h̄|
// instead of 2·asin|h̄|: a relative difference ≤ |h̄|² (2e-8 at 60″). The
// weighted mean of the h_i itself differs from the weighted least-squares
// attitude on the rotation group by second-order terms ≤ ½·max|θ_i|·|θ̄|
// (the Baker–Campbell–Hausdorff commutator): 0.004″ for heads 60″ apart,
// 2e-5″ for the 3″ of uncorrected thermal deformation
// (measured against the exact iteration: tests/test_combine.cpp).
//
// Each function has a generic version (double, float) and, where fixed point
// needs it, a Q30 version beside it with its range, scaling, rounding and
// saturation, followed by its guard (the deleted Q30 specialisation of the
// template, as in core/vector3.hpp).
#pragma once

#include <cstdint>

#include "../core/q_formats.hpp"
#include "../core/quaternion.hpp"
#include "../core/scalar_traits.hpp"
#include "../core/vector3.hpp"

namespace ascorr::combine {

// The formats of the tables: a gain (dimensionless, |·| ≤ kMaxGainRowSum), a
// gate factor (per radian of half-angle) and the gate's statistic. In double
// and float all are T; Q30 has its own (below).
template <typename T>
struct CombineFormats {
    using gain = T;
    using gate = T;
    using gate_value = T;
    static constexpr gain gain_from_double(double x) noexcept { return ScalarTraits<T>::from_double(x); }
    static constexpr gate gate_from_double(double x) noexcept { return ScalarTraits<T>::from_double(x); }
};

template <typename T>
using Gain = typename CombineFormats<T>::gain;
template <typename T>
using GateFactor = typename CombineFormats<T>::gate;
template <typename T>
using GateValue = typename CombineFormats<T>::gate_value;

// K_{S,i} (subset_tables.hpp), row-major.
template <typename T>
struct GainMatrix {
    Gain<T> k[3][3];
};

// U_{S,i} (subset_tables.hpp), upper triangular.
template <typename T>
struct GateMatrix {
    GateFactor<T> u00, u01, u02, u11, u12, u22;
};

// q ⊗ ref* as the half-angle vector h (above), and whether the rotation is
// within the gross gate: ‖h‖² ≤ near2 (near2 = sin²(φ_max/2)).
template <typename T>
struct HalfDifference {
    Vector3<T> h;
    bool near;
};

template <typename T>
constexpr HalfDifference<T> half_difference(const Quaternion<T>& q, const Quaternion<T>& ref, const T& near2) noexcept {
    constexpr T zero = constant<T>(0.0);
    const Quaternion<T> d = q * conjugate(ref);
    const Vector3<T> h = d.w < zero ? Vector3<T>{-d.x, -d.y, -d.z} : Vector3<T>{d.x, d.y, d.z};
    return {h, squared_norm(h) <= near2};
}

// q_a and q_b within the gross gate of each other, either sign:
// (q_a·q_b)² ≥ cos²(φ_max/2) = 1 − near2.
template <typename T>
constexpr bool near_each_other(const Quaternion<T>& a, const Quaternion<T>& b, const T& one_minus_near2) noexcept {
    const T c = dot(a, b);
    return c * c >= one_minus_near2;
}

// Σ K h over the heads of a subset.
template <typename T>
struct Accumulator {
    Vector3<T> sum;
};

template <typename T>
constexpr Accumulator<T> zero_accumulator() noexcept {
    constexpr T zero = constant<T>(0.0);
    return {{zero, zero, zero}};
}

template <typename T>
constexpr void accumulate(Accumulator<T>& a, const GainMatrix<T>& g, const Vector3<T>& h) noexcept {
    a.sum.x = a.sum.x + (g.k[0][0] * h.x + g.k[0][1] * h.y + g.k[0][2] * h.z);
    a.sum.y = a.sum.y + (g.k[1][0] * h.x + g.k[1][1] * h.y + g.k[1][2] * h.z);
    a.sum.z = a.sum.z + (g.k[2][0] * h.x + g.k[2][1] * h.y + g.k[2][2] * h.z);
}

template <typename T>
constexpr Vector3<T> result(const Accumulator<T>& a) noexcept {
    return a.sum;
}

// ‖U e‖² (subset_tables.hpp): the gate's d²/k²; the head is inconsistent
// when it exceeds 1 (gate_exceeds).
template <typename T>
constexpr GateValue<T> gate_value(const GateMatrix<T>& u, const Vector3<T>& e) noexcept {
    const T y0 = u.u00 * e.x + u.u01 * e.y + u.u02 * e.z;
    const T y1 = u.u11 * e.y + u.u12 * e.z;
    const T y2 = u.u22 * e.z;
    return y0 * y0 + y1 * y1 + y2 * y2;
}

template <typename T>
constexpr bool gate_exceeds(const T& v) noexcept {
    constexpr T one = constant<T>(1.0);
    return v > one;
}

// (0, h) ⊗ q: the increment that applying the small rotation (1, h) on the
// left adds to q, so that (1, h) ⊗ q = q + result (renormalized_sum then
// takes out the scale 1 + ‖h‖²/2 of (1, h), quaternion.hpp).
template <typename T>
constexpr Quaternion<T> left_increment(const Vector3<T>& h, const Quaternion<T>& q) noexcept {
    const Vector3<T> qv{q.x, q.y, q.z};
    const Vector3<T> v = q.w * h + cross(h, qv);
    return {-dot(h, qv), v.x, v.y, v.z};
}

}  // namespace ascorr::combine
