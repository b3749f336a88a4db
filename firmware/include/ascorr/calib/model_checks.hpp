// ascorr/calib/model_checks.hpp: what the on-board estimator (estimator.hpp)
// asks of a model before adopting it: its angles, that its coefficients fit
// the Q30 formats, what residual rotations do to the inter-boresight angles,
// and its residuals over the recent orbits. Pure functions in double, bounded loops, no allocation.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>

#include "../core/constants.hpp"
#include "../core/model_coefficients.hpp"
#include "estimator_types.hpp"
#include "frame.hpp"
#include "orbit_window.hpp"

namespace ascorr::calib {

// Model m's angle (arcsec) for head h and axis a at regressors x = (T1,
// T2 − T1, T3 − T1) in °C (the contract's model, every term of
// core/model_terms.hpp).
inline double model_angle(const ModelCoefficients& m, std::size_t h, std::size_t a,
                          const double (&x)[kRegressors]) noexcept {
    return model_polynomial(m.coefficient[h][a], x);
}

// Whether every linear coefficient of A, B, C is within the Q30 coefficient
// format's range, 2⁻⁵ rad (ScalarTraits<Q30>::max_coefficient); false for NaN.
inline bool coefficients_within_q30(const ModelCoefficients& m) noexcept {
    const double max_coef = 0x1p-5 * kRadToArcsec;
    for (std::size_t h = 0; h < kCalibHeads; ++h) {
        for (std::size_t a = 0; a < 3; ++a) {
            for (std::size_t t = 0; t < kLinearModelTerms; ++t) {
                if (!(std::fabs(m.coefficient[h][a][t]) < max_coef)) {
                    return false;
                }
            }
        }
    }
    return true;
}

// What residual rotations r_h (head frames, arcsec) do to the three IBAs
// (arcsec), to first order: head h's boresight in F is N_hᵀ·e_z, turned by
// r_h into N_hᵀ·(e_z + e_z × r_h); an IBA θ_ij = acos(z_i·z_j) changes by
// −(dz_i·z_j + z_i·dz_j)/sin θ_ij. A rotation common to all heads changes
// none (common_rotation.hpp), a roll about a head's boresight neither.
inline void iba_residuals(const Matrix3 (&n_mat)[kCalibHeads], const double (&r)[9], double (&d)[3]) noexcept {
    double z[kCalibHeads][3];
    double dz[kCalibHeads][3];
    for (std::size_t h = 0; h < kCalibHeads; ++h) {
        const double v[3] = {-r[3 * h + 1], r[3 * h], 0.0};  // e_z × r_h
        for (std::size_t c = 0; c < 3; ++c) {
            z[h][c] = n_mat[h].m[2][c];
            dz[h][c] = n_mat[h].m[0][c] * v[0] + n_mat[h].m[1][c] * v[1];
        }
    }
    constexpr std::size_t kPair[3][2] = {{0, 1}, {0, 2}, {1, 2}};
    for (std::size_t p = 0; p < 3; ++p) {
        const auto& zi = z[kPair[p][0]];
        const auto& zj = z[kPair[p][1]];
        const auto& di = dz[kPair[p][0]];
        const auto& dj = dz[kPair[p][1]];
        const double cx = zi[1] * zj[2] - zi[2] * zj[1];
        const double cy = zi[2] * zj[0] - zi[0] * zj[2];
        const double cz = zi[0] * zj[1] - zi[1] * zj[0];
        const double sin_t = std::sqrt(cx * cx + cy * cy + cz * cz);
        const double num =
            di[0] * zj[0] + di[1] * zj[1] + di[2] * zj[2] + zi[0] * dj[0] + zi[1] * dj[1] + zi[2] * dj[2];
        d[p] = -num / sin_t;
    }
}

// The centred solution b (per head, unknown and axis: the intercept at the
// centre and the slopes, square_root_information.hpp) as a model in the
// contract's form (arcsec, arcsec/°C): c0 = b0 − Σ b_j·centre_j.
inline void centred_to_model(const double (&b)[kCalibHeads][kUnknowns][3], const double (&centre)[kCalibHeads][3],
                             ModelCoefficients& m) noexcept {
    m = ModelCoefficients{};
    for (std::size_t h = 0; h < kCalibHeads; ++h) {
        m.present[h] = true;
        for (std::size_t a = 0; a < 3; ++a) {
            double* c = m.coefficient[h][a];
            c[0] = b[h][0][a];
            for (std::size_t j = 0; j < 3; ++j) {
                c[1 + j] = b[h][1 + j][a];
                c[0] -= b[h][1 + j][a] * centre[h][j];
            }
        }
    }
}

// An orbit's angle residuals (arcsec, per head and axis) against the
// centred solution b.
inline void residual(const double (&b)[kCalibHeads][kUnknowns][3], const double (&centre)[kCalibHeads][3],
                     const OrbitRecord& o, double (&r)[9]) noexcept {
    for (std::size_t h = 0; h < kCalibHeads; ++h) {
        for (std::size_t a = 0; a < 3; ++a) {
            double p = b[h][0][a];
            for (std::size_t j = 0; j < 3; ++j) {
                p += b[h][1 + j][a] * (o.x[h][j] - centre[h][j]);
            }
            r[3 * h + a] = o.e[h][a] - p;
        }
    }
}

// Whether model m may be adopted as to its size: its coefficients fit the Q30
// formats (coefficients_within_q30) and, at the newest orbit's temperatures
// in window ± margin_c (the 8 corners of the box per head), every angle is
// within the core's 1° (kMaxThermalAngleRad). An empty window checks the
// coefficients only.
inline bool within_limits(const ModelCoefficients& m, const OrbitWindow& window, double margin_c) noexcept {
    constexpr double max_arcsec = kMaxThermalAngleRad * kRadToArcsec;
    if (!coefficients_within_q30(m)) {
        return false;
    }
    if (window.size() == 0U) {
        return true;
    }
    const OrbitRecord& o = window.at(window.size() - 1U);
    for (std::size_t h = 0; h < kCalibHeads; ++h) {
        for (std::size_t corner = 0; corner < 8U; ++corner) {
            double x[3];
            for (std::size_t j = 0; j < 3; ++j) {
                x[j] = o.x[h][j] + (((corner >> j) & 1U) != 0U ? margin_c : -margin_c);
            }
            for (std::size_t a = 0; a < 3; ++a) {
                if (!(std::fabs(model_angle(m, h, a, x)) < max_arcsec)) {
                    return false;
                }
            }
        }
    }
    return true;
}

// RMS of model m's IBA residuals (orbit means, arcsec, iba_residuals) over the
// newest orbits (at most max_orbits) of window that are not held back; NaN
// with fewer than two. Not about their mean: within a day the orbit means'
// temperatures hardly move, so a wrong slope shows as an offset there, and so
// does a shifted mount.
inline double window_rms(const ModelCoefficients& m, const OrbitWindow& window, const Matrix3 (&n_mat)[kCalibHeads],
                         std::uint32_t max_orbits) noexcept {
    double sq[3] = {};
    std::uint32_t n = 0;
    for (std::size_t i = window.size(); i-- > 0 && n < max_orbits;) {
        const OrbitRecord& o = window.at(i);
        if (o.held) {
            continue;
        }
        double r[9];
        for (std::size_t h = 0; h < kCalibHeads; ++h) {
            for (std::size_t a = 0; a < 3; ++a) {
                r[3 * h + a] = o.e[h][a] - model_angle(m, h, a, o.x[h]);
            }
        }
        double d[3];
        iba_residuals(n_mat, r, d);
        for (std::size_t k = 0; k < 3; ++k) {
            sq[k] += d[k] * d[k];
        }
        ++n;
    }
    if (n < 2U) {
        return std::numeric_limits<double>::quiet_NaN();
    }
    return std::sqrt((sq[0] + sq[1] + sq[2]) / (3.0 * n));
}

}  // namespace ascorr::calib
