// ascorr/calib/head_rotation.hpp: a head's rotation relative to the frame F
// (frame.hpp), and small rotations as angle vectors.
//
// Conventions (quaternion.hpp): q_head_f = q_head_s ⊗ q_f_s⁻¹ for any common
// source frame s (ICRF on the ground, head A on board). The paper's thermal
// deformation of head h (eqs. 4–6) is the small rotation of q_head_f from a
// reference orientation N_h of the head in F:
//   a = canonical(q_head_f ⊗ N_h⁻¹),  e = 2·vec(a)  (rad),
// which equals the rotation vector to O(θ³/24) (2.5e-16 rad for 10″). e is
// bilinear in (q_head_f, N_h⁻¹), so an orbit's sum of a (as unnormalised
// quaternions) gives the orbit's sum of e exactly when the reference changes
// afterwards (the ground fit's re-basing, host fit.cpp). Its components are
// the model's α, β, γ (thermal.hpp): the correction turns the head back by e.
#pragma once

#include "../core/quaternion.hpp"

namespace ascorr::calib {

// a ⊗ b in double, its terms grouped as Eigen's vectorised product groups
// them (Eigen/src/Geometry/arch/Geometry_SIMD.h, two lanes at a time), so that
// the ground fit, which formed these products with Eigen, keeps its bits. The
// same value as quaternion.hpp's operator* to rounding.
inline Quaternion<double> hamilton_product(const Quaternion<double>& a, const Quaternion<double>& b) noexcept {
    return {(a.w * b.w - a.y * b.y) - (a.z * b.z + a.x * b.x), (a.w * b.x + a.y * b.z) - (a.z * b.y - a.x * b.w),
            (a.w * b.y + a.y * b.w) + (a.z * b.x - a.x * b.z), (a.w * b.z - a.y * b.x) + (a.z * b.w + a.x * b.y)};
}

// q_head_f from q_head_s and q_f_s.
template <typename T>
constexpr Quaternion<T> q_head_f(const Quaternion<T>& q_head_s, const Quaternion<T>& q_f_s) noexcept {
    return q_head_s * conjugate(q_f_s);
}

inline Quaternion<double> q_head_f(const Quaternion<double>& q_head_s, const Quaternion<double>& q_f_s) noexcept {
    return hamilton_product(q_head_s, conjugate(q_f_s));
}

// canonical(q ⊗ ref⁻¹): q relative to ref, with w ≥ 0.
template <typename T>
constexpr Quaternion<T> relative_to(const Quaternion<T>& q, const Quaternion<T>& ref) noexcept {
    return canonical(q * conjugate(ref));
}
inline Quaternion<double> relative_to(const Quaternion<double>& q, const Quaternion<double>& ref) noexcept {
    return canonical(hamilton_product(q, conjugate(ref)));
}

// e = 2·vec(a) of a (near-)unit quaternion a close to the identity (rad).
inline Vector3<double> small_angle(const Quaternion<double>& a) noexcept {
    return {2.0 * a.x, 2.0 * a.y, 2.0 * a.z};
}

}  // namespace ascorr::calib
