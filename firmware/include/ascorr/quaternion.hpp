// ascorr/quaternion.hpp: attitude quaternions for the core.
//
// Conventions (the same as formats.md and Eigen::Quaternion):
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
    return {a.w * b.w - a.x * b.x - a.y * b.y - a.z * b.z,
            a.w * b.x + a.x * b.w + a.y * b.z - a.z * b.y,
            a.w * b.y - a.x * b.z + a.y * b.w + a.z * b.x,
            a.w * b.z + a.x * b.y - a.y * b.x + a.z * b.w};
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

// The same attitude with w ≥ 0.
template <typename T>
constexpr Quaternion<T> canonical(const Quaternion<T>& q) noexcept {
    return q.w < k<T>(0.0) ? Quaternion<T>{-q.w, -q.x, -q.y, -q.z} : q;
}

// One Newton step towards unit norm: q · (1 + (1 − ‖q‖²)/2).
// For ‖q‖² = 1 + ε the result has ‖q‖² − 1 = O(ε²) (exactly −3ε²/4 − ε³/4),
// so a quaternion within the input tolerance (ε ≤ 1e-5) comes out unit to
// ~1e-10 after one step, and one that is unit to rounding stays so. No sqrt,
// no division: the same code serves fixed point.
template <typename T>
constexpr Quaternion<T> renormalized(const Quaternion<T>& q) noexcept {
    const T g = k<T>(0.5) * (k<T>(1.0) - squared_norm(q));
    return {q.w + q.w * g, q.x + q.x * g, q.y + q.y * g, q.z + q.z * g};
}

// Third row of R(q): the CHU +Z axis (boresight) in the source frame, i.e.
// z_icrf for q = q_chu_icrf. Exact for a unit quaternion.
template <typename T>
constexpr Vector3<T> boresight(const Quaternion<T>& q) noexcept {
    // Doubling by addition: 2 is outside a Q1.30 format's range [-2, 2).
    const T a = q.x * q.z - q.w * q.y;
    const T b = q.y * q.z + q.w * q.x;
    const T c = q.x * q.x + q.y * q.y;
    return {a + a, b + b, k<T>(1.0) - (c + c)};
}

}  // namespace ascorr
