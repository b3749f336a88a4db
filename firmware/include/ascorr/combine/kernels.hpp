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
// template, as in core/vector3.hpp); the accumulation, the gate and the
// increment in Q30 are in kernels_q30.hpp.
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
    using quick_bound = T;            // a bound on ‖e‖² (rad² of half-angle), quick_gate
    using mounting = Quaternion<T>;   // q_chu_crf* as mounting_product() takes it
    using reference = Quaternion<T>;  // the reference attitude as half_difference() takes it
    static constexpr mounting mounting_from(const Quaternion<T>& conj) noexcept { return conj; }
    static constexpr reference reference_from(const Quaternion<T>& ref) noexcept { return ref; }
    static constexpr gain gain_from_double(double x) noexcept { return ScalarTraits<T>::from_double(x); }
    static constexpr gate gate_from_double(double x) noexcept { return ScalarTraits<T>::from_double(x); }
    static constexpr quick_bound quick_from_double(double x) noexcept { return ScalarTraits<T>::from_double(x); }
};

template <typename T>
using Gain = typename CombineFormats<T>::gain;
template <typename T>
using GateFactor = typename CombineFormats<T>::gate;
template <typename T>
using GateValue = typename CombineFormats<T>::gate_value;
template <typename T>
using QuickBound = typename CombineFormats<T>::quick_bound;
template <typename T>
using MountingFactor = typename CombineFormats<T>::mounting;
template <typename T>
using ReferenceFactor = typename CombineFormats<T>::reference;

// In Q30 (q_formats.hpp; fx.hpp's exact products and rounding), the
// formats of the tables (each kernel's Q30 version is beside its generic one):
//
//  QGain (a gain K_{S,i}): signed, value = raw·2⁻²⁵, range ±64, resolution
//    3e-8. Gains are bounded by kMaxGainRowSum = 60 (mountings.hpp), so a gain
//    never saturates; gains above 1 are common (two heads 20° apart: ~10),
//    hence the six integer bits. The resolution changes the estimate by at
//    most 60·2⁻²⁶·|h| (5e-12 rad at |h| = 3e-4).
//  QGate (a gate factor U_{S,i}, per radian of half-angle): signed, value =
//    raw·2⁻², range ±2²⁹, resolution 0.25. The combiner refuses tables with a
//    factor beyond kMaxGateFactor = 2²⁸ (combiner.hpp); with the default gate
//    the factors are below ~4e5. The resolution changes d/k by at most
//    3·2⁻³·|e| (1e-4 of the gate at |e| = 3e-4).
//  Quick bound (a bound on ‖e‖², rad² of half-angle): std::int64_t in
//    units 2⁻⁶⁰, exact to 2⁻⁶⁰ (the bounds are 1e-11 to 1e-7: ≥ 1e7 units),
//    rounded down (never looser than the double bound).
//  Gate statistic: ‖y‖² with y = U e in Q19.12 (value = raw·2⁻¹², range
//    ±2¹⁹, saturated), as std::uint64_t in units 2⁻²⁴; the gate trips above
//    2²⁴ (d/k = 1). A saturated component is ≥ 2¹⁹ ≫ 1: it always trips.
struct QGain {
    static constexpr int kFracBits = 25;
    std::int32_t raw;
};
struct QGate {
    static constexpr int kFracBits = 2;
    std::int32_t raw;
};
// q_chu_crf* ⊗ · as a signed 4 × 4 matrix of Q30 raws (row r: the factors of
// pw, px, py, pz in component r of the product): the products then take their
// factors from memory, with no negation, and the operands of one component
// fit the Cortex-M3's registers (the quaternion form spilled: 90 instructions
// per product, 55 in this form).
struct QMounting {
    std::int32_t m[4][4];
};

template <>
struct CombineFormats<Q30> {
    using gain = QGain;
    using gate = QGate;
    using gate_value = std::uint64_t;
    using quick_bound = std::int64_t;
    using mounting = QMounting;
    using reference = Quaternion<Q30>;  // the products of half_difference() keep it in registers
    static constexpr reference reference_from(const Quaternion<Q30>& r) noexcept { return r; }
    // The matrix of a ⊗ · for a = conj (already rounded to Q30): exact copies
    // and negations (|aᵢ| < 2).
    static constexpr mounting mounting_from(const Quaternion<Q30>& a) noexcept {
        const std::int32_t w = a.w.raw;
        const std::int32_t x = a.x.raw;
        const std::int32_t y = a.y.raw;
        const std::int32_t z = a.z.raw;
        return {{{w, -x, -y, -z}, {x, w, -z, y}, {y, z, w, -x}, {z, -y, x, w}}};
    }
    // Rounded to nearest, ties away from zero, saturated (fx::raw_from_double).
    static constexpr gain gain_from_double(double x) noexcept { return {fx::raw_from_double<QGain::kFracBits>(x)}; }
    static constexpr gate gate_from_double(double x) noexcept { return {fx::raw_from_double<QGate::kFracBits>(x)}; }
    // x in [0, 2): x·2⁶⁰ rounded down.
    static constexpr quick_bound quick_from_double(double x) noexcept {
        return static_cast<std::int64_t>(x * fx::pow2(60));
    }
};

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

// a ⊗ b (quaternion.hpp's Hamilton product; Q30 has no generic kernel that
// calls it). A function of its own, not `*` at the call: GCC 12 weighs the
// general path's inlining by it (without it the M4F keeps select() out of
// line), and the measured instruction counts are of this form.
template <typename T>
constexpr Quaternion<T> product(const Quaternion<T>& a, const Quaternion<T>& b) noexcept {
    return a * b;
}

// q_chu_crf* ⊗ q_chu_icrf: a head's estimate of q_crf_icrf, from its mounting
// factor (CombineFormats<T>::mounting).
template <typename T>
constexpr Quaternion<T> mounting_product(const MountingFactor<T>& conj, const Quaternion<T>& p) noexcept {
    return product(conj, p);
}

// mounting_product (above) in Q30 from the signed matrix: each component one
// chain of four exact products rounded once (≤ 2⁻³¹), without saturation.
// Range: |aᵢ|, |pᵢ| ≤ 1 + 1e-6 (unit quaternions that passed norm_within or
// the mountings' check): each component of a ⊗ p is ≤ ‖a‖‖p‖ ≤ 1 + 2e-6 in
// magnitude, its sum in units 2⁻⁶⁰ below 2⁶¹.
[[gnu::always_inline]] constexpr Quaternion<Q30> mounting_product(const QMounting& a,
                                                                  const Quaternion<Q30>& p) noexcept {
    using fx::unshared;
    const std::int32_t pw = unshared(p.w.raw);
    const std::int32_t px = unshared(p.x.raw);
    const std::int32_t py = unshared(p.y.raw);
    const std::int32_t pz = unshared(p.z.raw);
    const auto row = [&](const std::int32_t(&r)[4]) {
        return Q30{fx::narrow<30>(0, r[0], pw, r[1], px, r[2], py, r[3], pz)};
    };
    return {row(a.m[0]), row(a.m[1]), row(a.m[2]), row(a.m[3])};
}
template <>
Quaternion<Q30> mounting_product<Q30>(const QMounting&, const Quaternion<Q30>&) noexcept = delete;

// q ⊗ ref* as the half-angle vector h (above), and whether the rotation is
// within the gross gate: ‖h‖² ≤ near2 (near2 = sin²(φ_max/2)).
template <typename T>
struct HalfDifference {
    Vector3<T> h;
    bool near;
};

template <typename T>
constexpr HalfDifference<T> half_difference(const Quaternion<T>& q, const ReferenceFactor<T>& ref,
                                            const T& near2) noexcept {
    constexpr T zero = constant<T>(0.0);
    const Quaternion<T> d = product(q, conjugate(ref));
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

// Σ K h over the heads of a subset, started at a constant (the subset's
// rounding correction, combiner.hpp SubsetTable::start).
template <typename T>
struct Accumulator {
    Vector3<T> sum;
};

// The sums' start from a vector (at construction; combiner.hpp keeps the
// accumulators themselves, so an epoch starts with plain loads).
template <typename T>
constexpr Accumulator<T> accumulator_from(const Vector3<T>& start) noexcept {
    return {start};
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

// h − est: a head's difference from the combined estimate.
template <typename T>
constexpr Vector3<T> residual(const Vector3<T>& h, const Vector3<T>& est) noexcept {
    return h - est;
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

// ‖e‖² ≤ bound: then ‖U e‖² ≤ λ_max(UᵀU)·‖e‖² ≤ 1 for bound = 1/λ_max
// (subset_tables.hpp bounds λ_max from above), and the head passes the gate
// without its statistic: a cheaper test that decides the usual epoch.
template <typename T>
constexpr bool quick_gate(const Vector3<T>& e, const QuickBound<T>& bound) noexcept {
    return squared_norm(e) <= bound;
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

// The usual pass's test that every input is unit (combiner.hpp
// combine_usual_n), one comparison per epoch: Σ (‖p_i‖² − 1)² ≤ tol²
// implies |‖p_i‖² − 1| ≤ tol for each (norm_within); NaN and infinity fail
// it. When it fails, the general path tests head by head. add() returns
// false when the epoch already fails (Q30's exact test, below); here the
// verdict waits for within().
template <typename T>
class UnitNorms {
public:
    constexpr bool add(const Quaternion<T>& q) noexcept {
        constexpr T minus_one = constant<T>(-1.0);
        const T e = minus_one + q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z;  // ‖q‖² − 1, one chain
        sum_ = sum_ + e * e;
        return true;
    }
    constexpr bool within(const T& tol) const noexcept { return sum_ <= tol * tol; }

private:
    T sum_ = constant<T>(0.0);
};

// (1, h) ⊗ q renormalised: the combined attitude from the reference q and
// the weighted mean h (combiner.hpp finish): q + d with d = (0, h) ⊗ q,
// renormalised by the core's second-order step (quaternion.hpp
// renormalized_sum: the small terms summed first, q rounded once, in the
// last addition; in float two roundings of the O(1) components would double
// the error). Range: q unit within the core's tolerance; h any result() of
// the accumulator (the bound that matters, Q30's: kernels_q30.hpp).
template <typename T>
constexpr Quaternion<T> apply_left(const Vector3<T>& h, const Quaternion<T>& q) noexcept {
    return renormalized_sum(q, left_increment(h, q));
}

}  // namespace ascorr::combine

#include "kernels_q30.hpp"  // the remaining kernels in Q30
