// ascorr/core/vector3.hpp: a fixed-size 3-vector for the core.
//
// Conventions: plain Cartesian components, no implied frame. The frame is
// named in the variable (z_chu_icrf: the CHU boresight, ICRF components).
// A trivially copyable aggregate of three scalars: no alignment requirement,
// no heap, usable in static storage on the DPU.
#pragma once

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

}  // namespace ascorr
