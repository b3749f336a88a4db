// ascorr/combine/kernels_q30.hpp: the combination's per-epoch arithmetic in
// Q30 that kernels.hpp does not hold beside its generic version. Part of
// kernels.hpp (its conventions are there); include that one.
#pragma once

#include <cstdint>

#include "kernels.hpp"

namespace ascorr::combine {

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
// (left_increment here, renormalized_sum in quaternion.hpp), inlined so that
// the M3 keeps the reference in registers. renormalized_sum's range holds for
// any h of the accumulator's range (|hᵢ| < 0.24, ‖h‖ < 0.42): d = (0, h) ⊗ q
// is orthogonal to q, so ε = ‖q‖² − 1 + ‖d‖² ≤ 1e-6 + 0.18 and
// |sᵢ| ≤ |qᵢ| + ‖d‖ < 1.43. The result is unit to 2⁻³⁰ (5ε³/8) for
// ‖h‖ ≤ 0.033, far above what the gates let through.
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
