// ascorr/calib/frame.hpp: the frame F of heads A and C (Herceg, Jørgensen &
// Jørgensen 2017, eqs. 1–3), and a rotation matrix as a quaternion.
//
// Conventions (quaternion.hpp): Hamilton, scalar first, q_b_a maps a-components
// into b-components. F's axes, in the components of any frame s in which the
// boresights z_a (head A) and z_c (head C) are given:
//   eq. 1  X_F = (z_a + z_c)/‖z_a + z_c‖
//   eq. 2  Z_F = (z_a × z_c)/‖z_a × z_c‖
//   eq. 3  Y_F = Z_F × X_F (normalised, as the ground fit always did)
// and R_f_s has the rows X_F, Y_F, Z_F. Given ICRF boresights this is
// q_f_icrf; given both boresights in head A's frame (z_a = +Z, z_c the third
// row of R(q_c_a)) it is q_f_a, the form the on-board estimator uses once per
// orbit (estimator.hpp).
//
// Double only: F is formed per epoch on the ground and per orbit on board,
// never in the 22 Hz path. The arithmetic is written operation for operation
// as Eigen's (cross, normalized, toRotationMatrix, Quaternion(Matrix3)), so that
// `ascorr fit`, which used Eigen for it, gives the same bits through this code.
// Domain: the heads' boresights are far from parallel or opposite (the µASC's
// are 60°–120° apart); degenerate inputs give non-finite results, which the
// callers' finiteness checks refuse.
// No allocation, no loop beyond the fixed 3 × 3 (and atan_unit's 8 terms).
#pragma once

#include <cmath>

#include "../core/constants.hpp"
#include "../core/quaternion.hpp"
#include "../core/vector3.hpp"
#include "portable_math.hpp"

namespace ascorr::calib {

struct Matrix3 {
    double m[3][3];  // m[row][column]
};

inline Vector3<double> normalized(const Vector3<double>& v) noexcept {
    const double n = squared_norm(v);
    if (n > 0.0) {
        const double s = std::sqrt(n);
        return {v.x / s, v.y / s, v.z / s};
    }
    return v;
}

// R(q) (quaternion.hpp's rotation_matrix), in Eigen's operation order.
inline Matrix3 rotation_matrix(const Quaternion<double>& q) noexcept {
    const double tx = 2.0 * q.x;
    const double ty = 2.0 * q.y;
    const double tz = 2.0 * q.z;
    const double twx = tx * q.w;
    const double twy = ty * q.w;
    const double twz = tz * q.w;
    const double txx = tx * q.x;
    const double txy = ty * q.x;
    const double txz = tz * q.x;
    const double tyy = ty * q.y;
    const double tyz = tz * q.y;
    const double tzz = tz * q.z;
    return {{{1.0 - (tyy + tzz), txy - twz, txz + twy},
             {txy + twz, 1.0 - (txx + tzz), tyz - twx},
             {txz - twy, tyz + twx, 1.0 - (txx + tyy)}}};
}

// The boresight (+Z of the head) in the source frame: the third row of R(q).
inline Vector3<double> boresight_of(const Quaternion<double>& q) noexcept {
    const Matrix3 r = rotation_matrix(q);
    return {r.m[2][0], r.m[2][1], r.m[2][2]};
}

// The angle between two unit vectors (arcsec; the IBA of two boresights):
// atan2 of |a×b| and a·b, which keeps full precision near 0 and 90°, unlike acos;
// portable_math.hpp's, so that the DPU's Sun learner and lag search score
// the IBAs with the host's bits (libm's atan2 differs in the last bit).
inline double angle_arcsec(const Vector3<double>& a, const Vector3<double>& b) noexcept {
    const Vector3<double> c = cross(a, b);
    return atan2_upper(std::sqrt(squared_norm(c)), dot(a, b)) * kRadToArcsec;
}

// A rotation matrix as a unit quaternion with the same rotation (Shepperd's
// method as Eigen applies it: the largest of w, x, y, z is formed from the
// diagonal, the others from the off-diagonal sums and differences).
inline Quaternion<double> quaternion_from(const Matrix3& r) noexcept {
    const auto& m = r.m;
    const double t = m[0][0] + (m[1][1] + m[2][2]);  // Eigen's unrolled trace
    if (t > 0.0) {
        double s = std::sqrt(t + 1.0);
        const double w = 0.5 * s;
        s = 0.5 / s;
        return {w, (m[2][1] - m[1][2]) * s, (m[0][2] - m[2][0]) * s, (m[1][0] - m[0][1]) * s};
    }
    int i = 0;
    if (m[1][1] > m[0][0]) {
        i = 1;
    }
    if (m[2][2] > m[i][i]) {
        i = 2;
    }
    const int j = (i + 1) % 3;
    const int k = (j + 1) % 3;
    double s = std::sqrt(m[i][i] - m[j][j] - m[k][k] + 1.0);
    double v[3] = {0.0, 0.0, 0.0};
    v[i] = 0.5 * s;
    s = 0.5 / s;
    const double w = (m[k][j] - m[j][k]) * s;
    v[j] = (m[j][i] + m[i][j]) * s;
    v[k] = (m[k][i] + m[i][k]) * s;
    return {w, v[0], v[1], v[2]};
}

// Eigen's cross product order (vector3.hpp's is the same formula).
inline Vector3<double> cross_of(const Vector3<double>& a, const Vector3<double>& b) noexcept {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}

// Eqs. 1–3: q_f_s from the boresights of A and C in frame s.
inline Quaternion<double> q_f_from_boresights(const Vector3<double>& z_a, const Vector3<double>& z_c) noexcept {
    const Vector3<double> z_f = normalized(cross_of(z_a, z_c));
    const Vector3<double> x_f = normalized(z_a + z_c);
    const Vector3<double> y_f = normalized(cross_of(z_f, x_f));
    return quaternion_from(Matrix3{{{x_f.x, x_f.y, x_f.z}, {y_f.x, y_f.y, y_f.z}, {z_f.x, z_f.y, z_f.z}}});
}

// q_f_icrf at one epoch, from q_a_icrf and q_c_icrf.
inline Quaternion<double> q_f_icrf(const Quaternion<double>& q_a_icrf, const Quaternion<double>& q_c_icrf) noexcept {
    return q_f_from_boresights(boresight_of(q_a_icrf), boresight_of(q_c_icrf));
}

// q_f_a from q_c_a (C relative to A): A's boresight is +Z in A; C's is the
// R(q_c_a)ᵀ·e_z, the third row of R(q_c_a) read as a column.
inline Quaternion<double> q_f_a(const Quaternion<double>& q_c_a) noexcept {
    const Matrix3 r = rotation_matrix(q_c_a);
    return q_f_from_boresights({0.0, 0.0, 1.0}, {r.m[2][0], r.m[2][1], r.m[2][2]});
}

}  // namespace ascorr::calib
