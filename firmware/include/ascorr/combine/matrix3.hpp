// ascorr/combine/matrix3.hpp: 3 × 3 matrices in double, for the combination's
// construction-time tables (subset_tables.hpp) only.
//
// Conventions: row-major, m[row][column]; components in CRF axes unless a name
// says otherwise. Built from + − × ÷ and std::sqrt only, each correctly
// rounded in IEEE 754, so the host and the DPU (software double on the
// Cortex-M3, no fused multiply-add) compute the same tables bit for bit.
// Never on the per-epoch path.
#pragma once

#include <cmath>

#include "../core/quaternion.hpp"

namespace ascorr::combine {

struct Matrix3 {
    double m[3][3];
};

constexpr Matrix3 zero_matrix() noexcept {
    return {{{0.0, 0.0, 0.0}, {0.0, 0.0, 0.0}, {0.0, 0.0, 0.0}}};
}

constexpr Matrix3 diagonal(double a, double b, double c) noexcept {
    return {{{a, 0.0, 0.0}, {0.0, b, 0.0}, {0.0, 0.0, c}}};
}

constexpr Matrix3 operator+(const Matrix3& a, const Matrix3& b) noexcept {
    Matrix3 r{};
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) {
            r.m[i][j] = a.m[i][j] + b.m[i][j];
        }
    }
    return r;
}

constexpr Matrix3 operator-(const Matrix3& a, const Matrix3& b) noexcept {
    Matrix3 r{};
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) {
            r.m[i][j] = a.m[i][j] - b.m[i][j];
        }
    }
    return r;
}

constexpr Matrix3 operator*(const Matrix3& a, const Matrix3& b) noexcept {
    Matrix3 r{};
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) {
            r.m[i][j] = a.m[i][0] * b.m[0][j] + a.m[i][1] * b.m[1][j] + a.m[i][2] * b.m[2][j];
        }
    }
    return r;
}

constexpr Matrix3 transpose(const Matrix3& a) noexcept {
    Matrix3 r{};
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) {
            r.m[i][j] = a.m[j][i];
        }
    }
    return r;
}

// The active rotation matrix of a unit quaternion (quaternion.hpp's
// convention): v_a = R(q_a_b) v_b.
constexpr Matrix3 rotation_matrix(const Quaternion<double>& q) noexcept {
    const double w = q.w;
    const double x = q.x;
    const double y = q.y;
    const double z = q.z;
    return {{{1.0 - 2.0 * (y * y + z * z), 2.0 * (x * y - w * z), 2.0 * (x * z + w * y)},
             {2.0 * (x * y + w * z), 1.0 - 2.0 * (x * x + z * z), 2.0 * (y * z - w * x)},
             {2.0 * (x * z - w * y), 2.0 * (y * z + w * x), 1.0 - 2.0 * (x * x + y * y)}}};
}

// The inverse by cofactors; false (and *inv untouched) when the determinant
// is not positive and finite relative to the matrix's scale: the matrices
// inverted here are symmetric positive definite (sums of information and
// covariance matrices), so anything else is a degenerate input.
inline bool inverse_spd(const Matrix3& a, Matrix3* inv) noexcept {
    const auto& m = a.m;
    const double c00 = m[1][1] * m[2][2] - m[1][2] * m[2][1];
    const double c01 = m[1][2] * m[2][0] - m[1][0] * m[2][2];
    const double c02 = m[1][0] * m[2][1] - m[1][1] * m[2][0];
    const double det = m[0][0] * c00 + m[0][1] * c01 + m[0][2] * c02;
    const double scale = m[0][0] * m[1][1] * m[2][2];
    // det ≤ the product of the diagonal for an SPD matrix (Hadamard); 1e-12 of
    // it: a condition number beyond ~1e12 is refused as singular.
    if (!(det > 1e-12 * scale) || !std::isfinite(det) || !(scale > 0.0)) {
        return false;
    }
    const double d = 1.0 / det;
    *inv = {{{c00 * d, (m[0][2] * m[2][1] - m[0][1] * m[2][2]) * d, (m[0][1] * m[1][2] - m[0][2] * m[1][1]) * d},
             {c01 * d, (m[0][0] * m[2][2] - m[0][2] * m[2][0]) * d, (m[0][2] * m[1][0] - m[0][0] * m[1][2]) * d},
             {c02 * d, (m[0][1] * m[2][0] - m[0][0] * m[2][1]) * d, (m[0][0] * m[1][1] - m[0][1] * m[1][0]) * d}}};
    return true;
}

// Upper-triangular U with UᵀU = a (Cholesky), for a symmetric positive
// definite a; false when a pivot is not positive.
inline bool cholesky_upper(const Matrix3& a, Matrix3* u) noexcept {
    Matrix3 r = zero_matrix();
    for (int i = 0; i < 3; ++i) {
        double d = a.m[i][i];
        for (int k = 0; k < i; ++k) {
            d -= r.m[k][i] * r.m[k][i];
        }
        if (!(d > 0.0) || !std::isfinite(d)) {
            return false;
        }
        r.m[i][i] = std::sqrt(d);
        for (int j = i + 1; j < 3; ++j) {
            double s = a.m[i][j];
            for (int k = 0; k < i; ++k) {
                s -= r.m[k][i] * r.m[k][j];
            }
            r.m[i][j] = s / r.m[i][i];
        }
    }
    *u = r;
    return true;
}

}  // namespace ascorr::combine
