// ascorr/core/vector3.hpp: a fixed-size 3-vector for the core.
//
// Conventions: plain Cartesian components, no implied frame. The frame is
// named in the variable (z_chu_icrf: the CHU boresight, ICRF components).
// A trivially copyable aggregate of three scalars: no alignment requirement,
// no heap, usable in static storage on the DPU.
#pragma once

#include <cstdint>

#include "q_formats.hpp"

namespace ascorr {

template <typename T>
struct Vector3 {
    T x;
    T y;
    T z;
};

template <typename T>
constexpr Vector3<T> operator+(const Vector3<T>& a, const Vector3<T>& b) noexcept {
    return {a.x + b.x, a.y + b.y, a.z + b.z};
}

template <typename T>
constexpr Vector3<T> operator-(const Vector3<T>& a, const Vector3<T>& b) noexcept {
    return {a.x - b.x, a.y - b.y, a.z - b.z};
}

template <typename T>
constexpr Vector3<T> operator*(const T& s, const Vector3<T>& a) noexcept {
    return {s * a.x, s * a.y, s * a.z};
}

template <typename T>
constexpr T dot(const Vector3<T>& a, const Vector3<T>& b) noexcept {
    return a.x * b.x + a.y * b.y + a.z * b.z;
}

template <typename T>
constexpr Vector3<T> cross(const Vector3<T>& a, const Vector3<T>& b) noexcept {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}

template <typename T>
constexpr T squared_norm(const Vector3<T>& a) noexcept {
    return dot(a, a);
}

// ---- In Q30 (q_formats.hpp): sums of products, rounded once. These overloads
// (found by argument-dependent lookup, preferred to the templates above)
// accumulate their exact products in int64 and round and saturate once, as
// CMSIS's q31 dot products do: fewer roundings (≤ 2⁻³¹ per result instead of
// per product) and fewer instructions.
// Range: a product of two Q30 raws has |·| ≤ 2⁶², a sum or difference of two
// (mac2, msub2) |·| < 2⁶³, except a·b + c·d with all four −2 (raw INT32_MIN),
// which wraps (unsigned arithmetic, no undefined behaviour) to −2⁶³; neither
// conversions nor the core's data (validated unit quaternions, small terms)
// produce that. Four-term sums add the halves of two such sums (half_sum: each
// halved by an arithmetic shift, |·| < 2⁶², no overflow), losing at most
// 2⁻⁶⁰, far below the final rounding (fx::narrow_sat<29>: ≤ 2⁻³¹, saturated).
//
// Guards: each Q30 overload is followed by the deletion of its template's Q30
// specialisation. Overload resolution prefers a non-template only while its
// signature matches the call; one that drifts (a parameter's type or
// reference changed) would silently lose to the template, which rounds per
// product and saturates per operation. With the specialisation deleted such
// a call does not compile (tests/compile_fail/q30_guards.cpp checks every
// guard of the core, and, as its control, that the same calls compile for
// float). The same holds in quaternion.hpp, aberration.hpp and thermal.hpp.

namespace fx {

// a·b + c·d and a·b − c·d, units 2⁻⁶⁰ (see the range note above).
constexpr std::int64_t mac2(Q30 a, Q30 b, Q30 c, Q30 d) noexcept {
    return static_cast<std::int64_t>(static_cast<std::uint64_t>(std::int64_t{a.raw} * b.raw) +
                                     static_cast<std::uint64_t>(std::int64_t{c.raw} * d.raw));
}
constexpr std::int64_t msub2(Q30 a, Q30 b, Q30 c, Q30 d) noexcept {
    return static_cast<std::int64_t>(static_cast<std::uint64_t>(std::int64_t{a.raw} * b.raw) -
                                     static_cast<std::uint64_t>(std::int64_t{c.raw} * d.raw));
}

// (x + y)/2 for |x|, |y| < 2⁶³, without overflow; error ≤ 1 (units of x).
// Of two sums in units 2⁻⁶⁰ it is their sum in units 2⁻⁵⁹.
constexpr std::int64_t half_sum(std::int64_t x, std::int64_t y) noexcept {
    return (x >> 1) + (y >> 1);
}

}  // namespace fx

constexpr Q30 dot(const Vector3<Q30>& a, const Vector3<Q30>& b) noexcept {
    return Q30{fx::narrow_sat<29>(fx::half_sum(fx::mac2(a.x, b.x, a.y, b.y), std::int64_t{a.z.raw} * b.z.raw))};
}
template <>
Q30 dot<Q30>(const Vector3<Q30>&, const Vector3<Q30>&) noexcept = delete;

constexpr Q30 squared_norm(const Vector3<Q30>& a) noexcept {
    return dot(a, a);
}
template <>
Q30 squared_norm<Q30>(const Vector3<Q30>&) noexcept = delete;

constexpr Vector3<Q30> cross(const Vector3<Q30>& a, const Vector3<Q30>& b) noexcept {
    return {Q30{fx::narrow_sat<30>(fx::msub2(a.y, b.z, a.z, b.y))},
            Q30{fx::narrow_sat<30>(fx::msub2(a.z, b.x, a.x, b.z))},
            Q30{fx::narrow_sat<30>(fx::msub2(a.x, b.y, a.y, b.x))}};
}
template <>
Vector3<Q30> cross<Q30>(const Vector3<Q30>&, const Vector3<Q30>&) noexcept = delete;

}  // namespace ascorr
