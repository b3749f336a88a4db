// ascorr/core/quaternion.hpp: attitude quaternions for the core.
//
// Conventions (the same as docs/contract.md and Eigen::Quaternion):
//  - Hamilton algebra (i² = j² = k² = ijk = −1), scalar first: q = (w, x, y, z).
//  - rotation_matrix(q) is the usual active rotation matrix of q, equal to
//    Eigen::Quaterniond(w, x, y, z).toRotationMatrix().
//  - Names say which frame maps to which: q_chu_icrf maps ICRF components into
//    CHU components, v_chu = R(q_chu_icrf) · v_icrf.
//  - Composition: R(a ⊗ b) = R(a) · R(b), so q_c_a = q_c_b ⊗ q_b_a.
//  - q and −q are the same attitude; canonical() picks w ≥ 0.
#pragma once

#include <cstdint>

#include "q_formats.hpp"
#include "scalar_traits.hpp"
#include "vector3.hpp"

namespace ascorr {

template <typename T>
struct Quaternion {
    T w;
    T x;
    T y;
    T z;
};

// Hamilton product a ⊗ b.
template <typename T>
constexpr Quaternion<T> operator*(const Quaternion<T>& a, const Quaternion<T>& b) noexcept {
    return {a.w * b.w - a.x * b.x - a.y * b.y - a.z * b.z, a.w * b.x + a.x * b.w + a.y * b.z - a.z * b.y,
            a.w * b.y - a.x * b.z + a.y * b.w + a.z * b.x, a.w * b.z + a.x * b.y - a.y * b.x + a.z * b.w};
}

template <typename T>
constexpr Quaternion<T> conjugate(const Quaternion<T>& q) noexcept {
    return {q.w, -q.x, -q.y, -q.z};
}

template <typename T>
constexpr T squared_norm(const Quaternion<T>& q) noexcept {
    return q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z;
}

template <typename T>
constexpr bool is_finite(const Quaternion<T>& q) noexcept {
    return is_finite(q.w) && is_finite(q.x) && is_finite(q.y) && is_finite(q.z);
}

// |‖q‖² − 1| ≤ tol: q is a unit quaternion to within tol. False for a
// non-finite q (NaN fails the comparison, an infinity exceeds it). A
// fixed-point scalar overloads this with an exact test.
template <typename T>
constexpr bool norm_within(const Quaternion<T>& q, const T& tol) noexcept {
    constexpr T one = constant<T>(1.0);
    return abs_within(squared_norm(q) - one, tol);
}

// The same attitude with w ≥ 0.
// q's components in double (ScalarTraits<T>::to_double), for the ground's
// and the side learners' double arithmetic.
template <typename T>
constexpr Quaternion<double> in_double(const Quaternion<T>& q) noexcept {
    using S = ScalarTraits<T>;
    return {S::to_double(q.w), S::to_double(q.x), S::to_double(q.y), S::to_double(q.z)};
}

template <typename T>
constexpr Quaternion<T> canonical(const Quaternion<T>& q) noexcept {
    constexpr T zero = constant<T>(0.0);
    return q.w < zero ? Quaternion<T>{-q.w, -q.x, -q.y, -q.z} : q;
}

template <typename T>
constexpr Quaternion<T> operator+(const Quaternion<T>& a, const Quaternion<T>& b) noexcept {
    return {a.w + b.w, a.x + b.x, a.y + b.y, a.z + b.z};
}

template <typename T>
constexpr T dot(const Quaternion<T>& a, const Quaternion<T>& b) noexcept {
    return a.w * b.w + a.x * b.x + a.y * b.y + a.z * b.z;
}

// A rotation close to the identity, stored as its difference from it:
// q = (1 + dw, v). Corrections are 1e-4 rad; kept this way they carry full
// relative precision, and an attitude is rounded once, when the sum of all
// small terms is added to it (see renormalized_sum). In float that halves the
// error of applying two corrections to a stored quaternion.
// q may be a positive multiple 1 + O(θ²) of the unit quaternion (the thermal
// rotation without double precision, thermal.hpp): the same rotation, whose
// scale the final renormalisation takes out.
template <typename T>
struct SmallRotation {
    T dw;  // w − 1
    Vector3<T> v;
};

template <typename T>
constexpr SmallRotation<T> conjugate(const SmallRotation<T>& r) noexcept {
    return {r.dw, {-r.v.x, -r.v.y, -r.v.z}};
}

// r − 1 as a quaternion: the increment that r ⊗ q or q ⊗ r adds to q.
template <typename T>
constexpr Quaternion<T> increment(const SmallRotation<T>& r) noexcept {
    return {r.dw, r.v.x, r.v.y, r.v.z};
}

template <typename T>
constexpr Quaternion<T> to_quaternion(const SmallRotation<T>& r) noexcept {
    constexpr T one = constant<T>(1.0);
    return {one + r.dw, r.v.x, r.v.y, r.v.z};
}

// The increment after applying r on the right of the attitude q:
// q ⊗ (r − 1), so that q ⊗ r = q + result.
template <typename T>
constexpr Quaternion<T> right_increment(const Quaternion<T>& q, const SmallRotation<T>& r) noexcept {
    return q * increment(r);
}

// The increment after applying r on the left of the attitude q + d:
// d + (r − 1) ⊗ (q + d), so that r ⊗ (q + d) = q + result.
template <typename T>
constexpr Quaternion<T> add_left_increment(const Quaternion<T>& d, const SmallRotation<T>& r,
                                           const Quaternion<T>& q) noexcept {
    return d + increment(r) * (q + d);
}

// (q + d) brought to unit norm by one Newton step, rounded once:
//   q + [d + (q + d)·g],  g = (1 − ‖q + d‖²)/2,
// with ‖q + d‖² − 1 = (‖q‖² − 1) + 2 q·d + ‖d‖² formed from small terms.
// For ‖q + d‖² = 1 + ε the result has ‖·‖² − 1 = −3ε²/4 + ε³/4, so an input
// within the tolerance (ε ≤ 1e-5) comes out unit to ~1e-10, and one unit to
// rounding stays so. The step scales, it does not rotate: its own rounding
// does not move the attitude. No sqrt, no division: the same code serves
// fixed point.
template <typename T>
constexpr Quaternion<T> renormalized_sum(const Quaternion<T>& q, const Quaternion<T>& d) noexcept {
    const T two_qd = dot(q, d) + dot(q, d);
    constexpr T one = constant<T>(1.0);
    constexpr T half = constant<T>(0.5);
    const T eps = (squared_norm(q) - one) + two_qd + squared_norm(d);
    const T g = -(half * eps);
    const Quaternion<T> qd = q + d;
    const Quaternion<T> e = d + Quaternion<T>{qd.w * g, qd.x * g, qd.y * g, qd.z * g};
    return q + e;
}

template <typename T>
constexpr Quaternion<T> renormalized(const Quaternion<T>& q) noexcept {
    constexpr T zero = constant<T>(0.0);
    return renormalized_sum(q, Quaternion<T>{zero, zero, zero, zero});
}

// Third row of R(q): the CHU +Z axis (boresight) in the source frame, i.e.
// z_icrf for q = q_chu_icrf. Exact for a unit quaternion.
template <typename T>
constexpr Vector3<T> boresight(const Quaternion<T>& q) noexcept {
    // Doubling by addition: 2 is outside a Q1.30 format's range [-2, 2).
    const T a = q.x * q.z - q.w * q.y;
    const T b = q.y * q.z + q.w * q.x;
    const T c = q.x * q.x + q.y * q.y;
    constexpr T one = constant<T>(1.0);
    return {a + a, b + b, one - (c + c)};
}

// ---- In Q30 (q_formats.hpp): sums of products rounded once (vector3.hpp's
// mac2, msub2, half_sum), each overload followed by its guard (vector3.hpp).
constexpr Q30 dot(const Quaternion<Q30>& a, const Quaternion<Q30>& b) noexcept {
    return Q30{fx::narrow_sat<29>(fx::half_sum(fx::mac2(a.w, b.w, a.x, b.x), fx::mac2(a.y, b.y, a.z, b.z)))};
}
template <>
Q30 dot<Q30>(const Quaternion<Q30>&, const Quaternion<Q30>&) noexcept = delete;

constexpr Q30 squared_norm(const Quaternion<Q30>& q) noexcept {
    return dot(q, q);
}
template <>
Q30 squared_norm<Q30>(const Quaternion<Q30>&) noexcept = delete;

// Hamilton product a ⊗ b (above), each component rounded once.
constexpr Quaternion<Q30> operator*(const Quaternion<Q30>& a, const Quaternion<Q30>& b) noexcept {
    using fx::half_sum;
    using fx::mac2;
    using fx::msub2;
    return {Q30{fx::narrow_sat<29>(half_sum(msub2(a.w, b.w, a.x, b.x), -mac2(a.y, b.y, a.z, b.z)))},
            Q30{fx::narrow_sat<29>(half_sum(mac2(a.w, b.x, a.x, b.w), msub2(a.y, b.z, a.z, b.y)))},
            Q30{fx::narrow_sat<29>(half_sum(msub2(a.w, b.y, a.x, b.z), mac2(a.y, b.w, a.z, b.x)))},
            Q30{fx::narrow_sat<29>(half_sum(mac2(a.w, b.z, a.x, b.y), msub2(a.z, b.w, a.y, b.x)))}};
}
template <>
Quaternion<Q30> operator*<Q30>(const Quaternion<Q30>&, const Quaternion<Q30>&) noexcept = delete;

// The correction's kernels in Q30: the functions correct_solution() calls
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

// boresight (above), the third row of R(q), in Q30: each component
// a sum of two products, exact, doubled exactly (read in units 2⁻⁵⁹) and
// rounded once. Range: q passed norm_within() (|qᵢ| ≤ 1 + 5e-7); then every
// component is ≤ 1 + 1e-6 in magnitude.
constexpr Vector3<Q30> boresight(const Quaternion<Q30>& q) noexcept {
    using fx::unshared;
    const std::int32_t qw = unshared(q.w.raw);
    const std::int32_t qx = unshared(q.x.raw);
    const std::int32_t qy = unshared(q.y.raw);
    const std::int32_t qz = unshared(q.z.raw);
    // In units 2⁻⁵⁹ (the products doubled), rounded to Q30 by a shift of 29.
    return {Q30{fx::narrow<29>(0, qx, qz, -qw, qy)}, Q30{fx::narrow<29>(0, qy, qz, qw, qx)},
            Q30{fx::narrow<29>(std::int64_t{1} << 59, -qx, qx, -qy, qy)}};
}
template <>
Vector3<Q30> boresight<Q30>(const Quaternion<Q30>&) noexcept = delete;

// conjugate (above) of a SmallRotation in Q30: plain negation, exact,
// since a rotation's vector part is within ±1 (never −2).
constexpr SmallRotation<Q30> conjugate(const SmallRotation<Q30>& r) noexcept {
    return {r.dw, {{-r.v.x.raw}, {-r.v.y.raw}, {-r.v.z.raw}}};
}
template <>
SmallRotation<Q30> conjugate<Q30>(const SmallRotation<Q30>&) noexcept = delete;

// norm_within (above) in Q30, exact and for any input: ‖q‖² − 1 in
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
template <>
bool norm_within<Q30>(const Quaternion<Q30>&, const Q30&) noexcept = delete;

// right_increment (above): q ⊗ (r − 1) in Q30, each component
// rounded once. Range: q passed norm_within() (|qᵢ| ≤ 1 + 5e-7) and the
// components of r − 1 are within ±2⁻⁴ (aberration: ≤ 1.7e-3); each
// product ≤ 2⁵⁷, each result ≤ 2⁻² in magnitude.
constexpr Quaternion<Q30> right_increment(const Quaternion<Q30>& q, const SmallRotation<Q30>& r) noexcept {
    using fx::unshared;
    const std::int32_t qw = unshared(q.w.raw);
    const std::int32_t qx = unshared(q.x.raw);
    const std::int32_t qy = unshared(q.y.raw);
    const std::int32_t qz = unshared(q.z.raw);
    const std::int32_t aw = unshared(r.dw.raw);
    const std::int32_t ax = unshared(r.v.x.raw);
    const std::int32_t ay = unshared(r.v.y.raw);
    const std::int32_t az = unshared(r.v.z.raw);
    return {Q30{fx::narrow<30>(0, qw, aw, qx, -ax, qy, -ay, qz, -az)},
            Q30{fx::narrow<30>(0, qw, ax, qx, aw, qy, az, qz, -ay)},
            Q30{fx::narrow<30>(0, qw, ay, qx, -az, qy, aw, qz, ax)},
            Q30{fx::narrow<30>(0, qw, az, qx, ay, qy, -ax, qz, aw)}};
}
template <>
Quaternion<Q30> right_increment<Q30>(const Quaternion<Q30>&, const SmallRotation<Q30>&) noexcept = delete;

// add_left_increment (above): d + (r − 1) ⊗ (q + d) in Q30, each
// component dᵢ·2³⁰ + Σ (r − 1)ⱼ·(q + d)ₖ exact in int64 and rounded once.
// Range: q passed norm_within(), |dᵢ| ≤ 2⁻⁴ (the aberration increment,
// ≤ 1.7e-3), the components of r − 1 within ±2⁻⁴ (thermal, angles ≤ 1°:
// ≤ 0.016); then |q + d| < 1.07, each product < 2⁵⁷ and each result ≤ 2⁻³.
constexpr Quaternion<Q30> add_left_increment(const Quaternion<Q30>& d, const SmallRotation<Q30>& r,
                                             const Quaternion<Q30>& q) noexcept {
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
    return {Q30{fx::narrow<30>(units60(d.w), aw, sw, -ax, sx, -ay, sy, -az, sz)},
            Q30{fx::narrow<30>(units60(d.x), aw, sx, ax, sw, ay, sz, -az, sy)},
            Q30{fx::narrow<30>(units60(d.y), aw, sy, -ax, sz, ay, sw, az, sx)},
            Q30{fx::narrow<30>(units60(d.z), aw, sz, ax, sy, -ay, sx, az, sw)}};
}
template <>
Quaternion<Q30> add_left_increment<Q30>(const Quaternion<Q30>&, const SmallRotation<Q30>&,
                                        const Quaternion<Q30>&) noexcept = delete;

// renormalized_sum (above) in Q30: s = q + d (exact), ε = ‖s‖² − 1
// exact in int64, and each component sᵢ·(1 + g) with the Newton step taken to
// second order, g = −ε/2 + 3ε²/8 (1/√(1 + ε) = 1 − ε/2 + 3ε²/8 − …): then
// ‖result‖² − 1 = 5ε³/8 + O(ε⁴), which stays below 2⁻³⁰ for |ε| ≤ 1.1e-3,
// four times what the thermal rotation's scale (≤ 2.3e-4) and the input's
// tolerance (1e-6) add. g and each sᵢ·g are rounded once.
// Range (the one statement; callers show they meet it): |sᵢ| < 1.5 and
// |ε| ≤ 0.27. Then ‖s‖² < 1.27 (< 2⁶³ in units 2⁻⁶⁰), |g| < 0.17 and every
// result below 1.8 in magnitude: no sum overflows, no result leaves Q30.
// The correction's increments (correct.hpp): q passed norm_within() and
// |dᵢ| ≤ 2⁻⁴ (they are ≤ 0.017), so ‖s‖ ≤ 1 + ‖d‖ ≤ 1.125: |sᵢ| < 1.07,
// |ε| ≤ 0.27 (0.07 for the actual increments). The combination's: see
// apply_left (combine/kernels_q30.hpp).
constexpr Quaternion<Q30> renormalized_sum(const Quaternion<Q30>& q, const Quaternion<Q30>& d) noexcept {
    using fx::unshared;
    const std::int32_t sw = unshared(q.w.raw + d.w.raw);
    const std::int32_t sx = unshared(q.x.raw + d.x.raw);
    const std::int32_t sy = unshared(q.y.raw + d.y.raw);
    const std::int32_t sz = unshared(q.z.raw + d.z.raw);
    const std::int64_t eps = fx::accumulate_products(-(std::int64_t{1} << 60), sw, sw, sx, sx, sy, sy, sz, sz);
    const std::int32_t e = fx::narrow<30>(eps);  // ε, Q30
    const std::int32_t g = fx::narrow<33>(3 * fx::mul(e, e)) - fx::narrow<31>(eps);
    const auto step = [g](std::int32_t s) { return s + fx::narrow<30>(0, s, g); };
    return {{step(sw)}, {step(sx)}, {step(sy)}, {step(sz)}};
}
template <>
Quaternion<Q30> renormalized_sum<Q30>(const Quaternion<Q30>&, const Quaternion<Q30>&) noexcept = delete;

}  // namespace ascorr
