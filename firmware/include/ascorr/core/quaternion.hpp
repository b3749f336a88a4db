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

}  // namespace ascorr
