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

// a ⊗ b (quaternion.hpp's Hamilton product); fixed point has its own below.
template <typename T>
constexpr Quaternion<T> product(const Quaternion<T>& a, const Quaternion<T>& b) noexcept {
    return a * b;
}

// product (above), a ⊗ b in Q30: each component one chain of four exact
// products (SMULL, SMLAL) rounded once to Q30 (≤ 2⁻³¹), without saturation.
// Range: |aᵢ|, |bᵢ| ≤ 1 + 1e-6 (unit quaternions that passed norm_within or
// the mountings' check): each component of a ⊗ b is ≤ ‖a‖‖b‖ ≤ 1 + 2e-6 in
// magnitude, its sum in units 2⁻⁶⁰ below 2⁶¹. A subtracted product is the
// product with the negated operand (exact: |aᵢ| < 2).
constexpr Quaternion<Q30> product(const Quaternion<Q30>& a, const Quaternion<Q30>& b) noexcept {
    using fx::unshared;
    const std::int32_t aw = unshared(a.w.raw);
    const std::int32_t ax = unshared(a.x.raw);
    const std::int32_t ay = unshared(a.y.raw);
    const std::int32_t az = unshared(a.z.raw);
    const std::int32_t bw = unshared(b.w.raw);
    const std::int32_t bx = unshared(b.x.raw);
    const std::int32_t by = unshared(b.y.raw);
    const std::int32_t bz = unshared(b.z.raw);
    return {Q30{fx::narrow<30>(0, aw, bw, -ax, bx, -ay, by, -az, bz)},
            Q30{fx::narrow<30>(0, aw, bx, ax, bw, ay, bz, -az, by)},
            Q30{fx::narrow<30>(0, aw, by, -ax, bz, ay, bw, az, bx)},
            Q30{fx::narrow<30>(0, aw, bz, ax, by, -ay, bx, az, bw)}};
}
template <>
Quaternion<Q30> product<Q30>(const Quaternion<Q30>&, const Quaternion<Q30>&) noexcept = delete;

// q_chu_crf* ⊗ q_chu_icrf: a head's estimate of q_crf_icrf, from its mounting
// factor (CombineFormats<T>::mounting).
template <typename T>
constexpr Quaternion<T> mounting_product(const MountingFactor<T>& conj, const Quaternion<T>& p) noexcept {
    return product(conj, p);
}

// mounting_product (above) in Q30 from the signed matrix: each component one
// chain of four exact products rounded once (≤ 2⁻³¹), without saturation.
// Range: as product() (unit operands, each component ≤ 1 + 2e-6).
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
// the error). Range: q unit within the core's tolerance, |h| ≤ 2⁻⁸ (the
// gross gate).
template <typename T>
constexpr Quaternion<T> apply_left(const Vector3<T>& h, const Quaternion<T>& q) noexcept {
    return renormalized_sum(q, left_increment(h, q));
}

// ---- The remaining kernels in Q30, each with its guard.

// Σ K h in Q30: three int64 sums of exact products of a QGain and a Q30
// (units 2⁻⁵⁵), started at the start's exact value. Range: |K| ≤ 60
// (raw < 2³¹), |h| ≤ 2⁻⁸ (the gross gate: half-angles within 2⁻⁸ of the
// reference after a re-formation) so each product is below 2⁵³ and a sum
// over kMaxHeads heads below 2⁵⁷; the start (the mountings' rounding,
// ≤ 1e-8) adds nothing to that; the result (result()) is at most
// kMaxGainRowSum·2⁻⁸ < 0.24 in magnitude.
template <>
struct Accumulator<Q30> {
    std::int64_t sum[3];
};

// The start in units 2⁻⁵⁵, exact (|start| < 2: below 2⁵⁶).
template <>
constexpr Accumulator<Q30> accumulator_from<Q30>(const Vector3<Q30>& start) noexcept {
    constexpr int kShift = QGain::kFracBits;
    return {{std::int64_t{start.x.raw} * (std::int64_t{1} << kShift),
             std::int64_t{start.y.raw} * (std::int64_t{1} << kShift),
             std::int64_t{start.z.raw} * (std::int64_t{1} << kShift)}};
}

constexpr void accumulate(Accumulator<Q30>& a, const GainMatrix<Q30>& g, const Vector3<Q30>& h) noexcept {
    using fx::unshared;
    const std::int32_t hx = unshared(h.x.raw);
    const std::int32_t hy = unshared(h.y.raw);
    const std::int32_t hz = unshared(h.z.raw);
    // Unrolled: the three sums stay in registers across the heads (the
    // Cortex-M3 spilled them through memory in a loop).
    a.sum[0] = fx::accumulate_products(a.sum[0], g.k[0][0].raw, hx, g.k[0][1].raw, hy, g.k[0][2].raw, hz);
    a.sum[1] = fx::accumulate_products(a.sum[1], g.k[1][0].raw, hx, g.k[1][1].raw, hy, g.k[1][2].raw, hz);
    a.sum[2] = fx::accumulate_products(a.sum[2], g.k[2][0].raw, hx, g.k[2][1].raw, hy, g.k[2][2].raw, hz);
}
template <>
void accumulate<Q30>(Accumulator<Q30>&, const GainMatrix<Q30>&, const Vector3<Q30>&) noexcept = delete;

// The sums rounded once to Q30 (≤ 2⁻³¹), not saturated (range above).
constexpr Vector3<Q30> result(const Accumulator<Q30>& a) noexcept {
    constexpr int kShift = QGain::kFracBits;
    return {Q30{fx::narrow<kShift>(a.sum[0])}, Q30{fx::narrow<kShift>(a.sum[1])}, Q30{fx::narrow<kShift>(a.sum[2])}};
}
template <>
Vector3<Q30> result<Q30>(const Accumulator<Q30>&) noexcept = delete;

// ‖U e‖² in Q30 (the statistic's format above): y = U e with exact products
// of a QGate and a Q30 (units 2⁻³²), rounded once to Q19.12 and saturated;
// the squares summed exactly in uint64. Range: any e (|eᵢ| < 2, each
// product < 2⁶², a sum of three < 2⁶³ as |U| ≤ 2²⁸ keeps it below 1.5·2⁶¹);
// each square ≤ 2⁶², three < 2⁶⁴.
constexpr std::uint64_t gate_value(const GateMatrix<Q30>& u, const Vector3<Q30>& e) noexcept {
    using fx::unshared;
    const std::int32_t ex = unshared(e.x.raw);
    const std::int32_t ey = unshared(e.y.raw);
    const std::int32_t ez = unshared(e.z.raw);
    constexpr int kShift = QGate::kFracBits + Q30::kFracBits - 12;
    const std::int32_t y0 = fx::narrow_sat<kShift>(fx::sum_products(u.u00.raw, ex, u.u01.raw, ey, u.u02.raw, ez));
    const std::int32_t y1 = fx::narrow_sat<kShift>(fx::sum_products(u.u11.raw, ey, u.u12.raw, ez));
    const std::int32_t y2 = fx::narrow_sat<kShift>(fx::mul(u.u22.raw, ez));
    const auto sq = [](std::int32_t y) { return static_cast<std::uint64_t>(fx::mul(y, y)); };
    return sq(y0) + sq(y1) + sq(y2);
}
template <>
std::uint64_t gate_value<Q30>(const GateMatrix<Q30>&, const Vector3<Q30>&) noexcept = delete;

// quick_gate (above) in Q30: ‖e‖² exact in int64 (units 2⁻⁶⁰; |eᵢ| < 2,
// each square ≤ 2⁶², the sum modulo 2⁶⁴ read unsigned: exact below 2⁶⁴).
constexpr bool quick_gate(const Vector3<Q30>& e, std::int64_t bound) noexcept {
    const auto sq = [](Q30 c) { return static_cast<std::uint64_t>(fx::mul(c.raw, c.raw)); };
    return sq(e.x) + sq(e.y) + sq(e.z) <= static_cast<std::uint64_t>(bound);
}
template <>
bool quick_gate<Q30>(const Vector3<Q30>&, const std::int64_t&) noexcept = delete;

// The statistic beyond the gate: ‖y‖² > 1, i.e. > 2²⁴ in units 2⁻²⁴. Exact.
constexpr bool gate_exceeds(std::uint64_t v) noexcept {
    return v > (std::uint64_t{1} << 24);
}

// left_increment (above), (0, h) ⊗ q in Q30, each component one chain of
// three exact products rounded once (≤ 2⁻³¹), without saturation. Range:
// q unit (|qᵢ| ≤ 1 + 1e-6), |hᵢ| < 0.24 (Accumulator's range): each component
// < 0.73 in magnitude.
constexpr Quaternion<Q30> left_increment(const Vector3<Q30>& h, const Quaternion<Q30>& q) noexcept {
    using fx::unshared;
    const std::int32_t hx = unshared(h.x.raw);
    const std::int32_t hy = unshared(h.y.raw);
    const std::int32_t hz = unshared(h.z.raw);
    const std::int32_t qw = unshared(q.w.raw);
    const std::int32_t qx = unshared(q.x.raw);
    const std::int32_t qy = unshared(q.y.raw);
    const std::int32_t qz = unshared(q.z.raw);
    return {Q30{fx::narrow<30>(0, -hx, qx, -hy, qy, -hz, qz)}, Q30{fx::narrow<30>(0, qw, hx, hy, qz, -hz, qy)},
            Q30{fx::narrow<30>(0, qw, hy, hz, qx, -hx, qz)}, Q30{fx::narrow<30>(0, qw, hz, hx, qy, -hy, qx)}};
}
template <>
Quaternion<Q30> left_increment<Q30>(const Vector3<Q30>&, const Quaternion<Q30>&) noexcept = delete;

// half_difference (above) in Q30: q ⊗ ref* as product() forms it (each
// component one chain of four exact products rounded once, ≤ 2⁻³¹; the
// conjugate's signs folded into the operands), the sign aligned by negating
// the vector part (exact: |vᵢ| ≤ 1), and ‖h‖² ≤ near2 decided exactly in
// int64 (units 2⁻⁶⁰). Range: q and ref unit (|·ᵢ| ≤ 1 + 1e-6), any result.
// (A matrix of ref* formed once per epoch, as for the mountings, cost more
// than it saved: 1034 against 998 instructions per epoch on the M3.)
constexpr HalfDifference<Q30> half_difference(const Quaternion<Q30>& q, const Quaternion<Q30>& ref,
                                              const Q30& near2) noexcept {
    using fx::unshared;
    const std::int32_t aw = unshared(q.w.raw);
    const std::int32_t ax = unshared(q.x.raw);
    const std::int32_t ay = unshared(q.y.raw);
    const std::int32_t az = unshared(q.z.raw);
    const std::int32_t bw = unshared(ref.w.raw);
    const std::int32_t bx = unshared(ref.x.raw);
    const std::int32_t by = unshared(ref.y.raw);
    const std::int32_t bz = unshared(ref.z.raw);
    // q ⊗ ref*, ref* = (bw, −bx, −by, −bz).
    const std::int32_t w = fx::narrow<30>(0, aw, bw, ax, bx, ay, by, az, bz);
    std::int32_t x = fx::narrow<30>(0, ax, bw, -aw, bx, az, by, -ay, bz);
    std::int32_t y = fx::narrow<30>(0, ay, bw, -aw, by, ax, bz, -az, bx);
    std::int32_t z = fx::narrow<30>(0, az, bw, -aw, bz, ay, bx, -ax, by);
    if (w < 0) {
        x = -x;
        y = -y;
        z = -z;
    }
    const auto sq = [](std::int32_t c) { return static_cast<std::uint64_t>(fx::mul(c, c)); };
    const std::uint64_t n2 = sq(x) + sq(y) + sq(z);
    return {{{x}, {y}, {z}}, n2 <= static_cast<std::uint64_t>(fx::mul(near2.raw, std::int32_t{1} << 30))};
}
template <>
HalfDifference<Q30> half_difference<Q30>(const Quaternion<Q30>&, const Quaternion<Q30>&, const Q30&) noexcept = delete;

// residual (above) in Q30: plain differences, exact. Range: |h| ≤ 2⁻⁸ (the
// gross gate) and |est| < 0.24 (Accumulator's range): no overflow.
constexpr Vector3<Q30> residual(const Vector3<Q30>& h, const Vector3<Q30>& est) noexcept {
    return {{h.x.raw - est.x.raw}, {h.y.raw - est.y.raw}, {h.z.raw - est.z.raw}};
}
template <>
Vector3<Q30> residual<Q30>(const Vector3<Q30>&, const Vector3<Q30>&) noexcept = delete;

// apply_left (above) in Q30: the same calls, each the Q30 kernel
// (left_increment here, renormalized_sum in quaternion.hpp, with its range:
// |dᵢ| ≤ 2⁻⁴, here ≤ 2⁻⁸·(1 + 1e-6)), inlined so that the M3 keeps the
// reference in registers.
[[gnu::always_inline]] constexpr Quaternion<Q30> apply_left(const Vector3<Q30>& h, const Quaternion<Q30>& q) noexcept {
    return renormalized_sum(q, left_increment(h, q));
}
template <>
Quaternion<Q30> apply_left<Q30>(const Vector3<Q30>&, const Quaternion<Q30>&) noexcept = delete;

// UnitNorms (above) in Q30: each input's own exact test (norm_within), as
// (‖p‖² − 1)² would leave int64 in units 2⁻¹²⁰.
template <>
class UnitNorms<Q30> {
public:
    static constexpr bool add(const Quaternion<Q30>& q) noexcept {
        return norm_within(q, ScalarTraits<Q30>::unit_norm_tolerance);
    }
    static constexpr bool within(const Q30& /*tol*/) noexcept { return true; }  // each add() decided
};

}  // namespace ascorr::combine
