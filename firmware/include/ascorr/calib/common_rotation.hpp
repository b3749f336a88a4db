// ascorr/calib/common_rotation.hpp: what the inter-boresight angles cannot
// see, and the projection that removes it per orbit.
//
// Conventions: an orbit's equations stack the three heads' small angles e_h
// (head_rotation.hpp), each in its head's frame: y = [e_A; e_B; e_C] (9).
// A small rotation ω of the frame F common to all heads appears in head h as
// N_h·ω, N_h = R(reference of head h in F) (3 × 3, orthonormal), so it spans
// the columns of G = [N_A; N_B; N_C] (9 × 3). GᵀG = 3·I, hence
//   P = I − G·Gᵀ/3
// is the orthogonal projector onto what the inter-boresight angles see; the
// ground fit applies P to each orbit's equations and treats F's own rotation
// as a nuisance (calib/README.md, "The estimator").
// The model's regressors are per head [1, T1, T2 − T1, T3 − T1]; only T2 and
// T3 (THT00029, THT00032) are shared by all heads, so a common rotation
// w0 + w2·T2 + w3·T3 (3 × 3 = 9 numbers) changes no IBA: 9 of the 36 linear
// coefficients are unobservable and 27 observable. Which of the equivalent
// models is written is a rule (below, "The rule"), not something the data say.
// Double only (per orbit); fixed trip counts, no allocation.
#pragma once

#include "../core/model_terms.hpp"
#include "frame.hpp"

namespace ascorr::calib {

// y ← P·y, P = I − G·Gᵀ/H, for H heads (see the top; H = 3 there).
template <std::size_t H>
void remove_common_rotation(const Matrix3 (&n)[H], double (&y)[3 * H]) noexcept {
    double g[3] = {0.0, 0.0, 0.0};  // Gᵀ·y
    for (std::size_t h = 0; h < H; ++h) {
        for (std::size_t r = 0; r < 3; ++r) {
            for (std::size_t c = 0; c < 3; ++c) {
                g[c] += n[h].m[r][c] * y[3 * h + r];
            }
        }
    }
    for (std::size_t h = 0; h < H; ++h) {
        for (std::size_t r = 0; r < 3; ++r) {
            double s = 0.0;
            for (std::size_t c = 0; c < 3; ++c) {
                s += n[h].m[r][c] * g[c];
            }
            y[3 * h + r] -= s / static_cast<double>(H);
        }
    }
}

// The projector for any number of heads (the ground fit's heads, two or
// more): n[0 … heads − 1], G = [N_0; …], GᵀG = heads·I, P = I − G·Gᵀ/heads,
// written row-major into p[(3·heads)²]. Trip counts fixed by `heads`.
inline void common_rotation_projector(const Matrix3* n, std::size_t heads, double* p) noexcept {
    const std::size_t rows = 3 * heads;
    for (std::size_t i = 0; i < rows; ++i) {
        for (std::size_t j = 0; j < rows; ++j) {
            double s = 0.0;
            for (std::size_t c = 0; c < 3; ++c) {
                s += n[i / 3].m[i % 3][c] * n[j / 3].m[j % 3][c];
            }
            p[i * rows + j] = (i == j ? 1.0 : 0.0) - s / static_cast<double>(heads);
        }
    }
}

// The projector P itself (3H × 3H) of H heads, for a design built column by column.
template <std::size_t H>
void common_rotation_projector(const Matrix3 (&n)[H], double (&p)[3 * H][3 * H]) noexcept {
    common_rotation_projector(n, H, &p[0][0]);
}

// ---- The rule (docs/contract.md, "The common rotation")
//
// Adding a common rotation ω (F axes) to a model adds N_h·ω to every head's
// correction c_h (head axes) and changes no IBA. What it does change is the
// attitude of the bench that the heads give together. With per-head weights
// B_h (3 × 3, head axes → F axes) normalised so that Σ_h B_h·N_h = I, the
// bench's motion from the correction at an orbit is y = Σ_h B_h·c_h, and the
// common rotation moves it by exactly ω. The rule takes, of the models
// c_h + N_h·ω with ω = w·r, r = [1, T2 − T̄2, T3 − T̄3] (the 9 numbers w), the
// one minimising Σ_orbits ‖y + ω‖²: w = −(Σ y·rᵀ)(Σ r·rᵀ)⁻¹, least squares
// over the data used. The weights say whose motion counts:
//   - the combined attitude (do no harm, the default with mountings):
//     A_h = M_hᵀ·diag(1/σc², 1/σc², 1/σa²), M_h = R(q_chu_crf): head h's
//     share of the combined attitude up to the full set's common factor
//     P⁻¹ (combine/mountings.hpp, motion_weight), which cancels in B_h;
//   - the smallest correction (without mountings): A_h = N_hᵀ;
//   - head X rigid to the bench: A_X = I, the others 0 (X's correction
//     keeps no part that a common rotation could take);
// and B_h = (Σ_j A_j·N_j)⁻¹·A_h, so that Σ_h B_h·N_h = I.

// a·b.
inline Matrix3 product(const Matrix3& a, const Matrix3& b) noexcept {
    Matrix3 r{};
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) {
            r.m[i][j] = a.m[i][0] * b.m[0][j] + a.m[i][1] * b.m[1][j] + a.m[i][2] * b.m[2][j];
        }
    }
    return r;
}

// The inverse by cofactors, after scaling rows and columns by the diagonal's
// roots (an SPD matrix's columns may differ by orders of magnitude: °C² sums
// beside counts); false when the scaled determinant is below 1e-12 (the rows
// are dependent to double's precision: T029 and T032 that never vary apart)
// or a diagonal entry is not positive.
inline bool inverse_scaled(const Matrix3& a, bool spd, Matrix3* inv) noexcept {
    double s[3] = {1.0, 1.0, 1.0};
    for (int i = 0; spd && i < 3; ++i) {
        if (!(a.m[i][i] > 0.0)) {
            return false;
        }
        s[i] = 1.0 / std::sqrt(a.m[i][i]);
    }
    Matrix3 b{};
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) {
            b.m[i][j] = s[i] * a.m[i][j] * s[j];
        }
    }
    const double c00 = b.m[1][1] * b.m[2][2] - b.m[1][2] * b.m[2][1];
    const double c01 = b.m[1][2] * b.m[2][0] - b.m[1][0] * b.m[2][2];
    const double c02 = b.m[1][0] * b.m[2][1] - b.m[1][1] * b.m[2][0];
    const double det = b.m[0][0] * c00 + b.m[0][1] * c01 + b.m[0][2] * c02;
    if (!(std::fabs(det) > 1e-12) || !std::isfinite(det)) {
        return false;
    }
    const double c[3][3] = {
        {c00, b.m[0][2] * b.m[2][1] - b.m[0][1] * b.m[2][2], b.m[0][1] * b.m[1][2] - b.m[0][2] * b.m[1][1]},
        {c01, b.m[0][0] * b.m[2][2] - b.m[0][2] * b.m[2][0], b.m[0][2] * b.m[1][0] - b.m[0][0] * b.m[1][2]},
        {c02, b.m[0][1] * b.m[2][0] - b.m[0][0] * b.m[2][1], b.m[0][0] * b.m[1][1] - b.m[0][1] * b.m[1][0]}};
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) {
            inv->m[i][j] = s[i] * (c[i][j] / det) * s[j];
        }
    }
    return true;
}

// B_h = (Σ_j A_j·N_j)⁻¹·A_h for `heads` heads (a[], n[], b[] by position);
// false when Σ_j A_j·N_j is singular (no head carries weight).
inline bool bench_weights(const Matrix3* a, const Matrix3* n, std::size_t heads, Matrix3* b) noexcept {
    Matrix3 g{};
    for (std::size_t h = 0; h < heads; ++h) {
        const Matrix3 an = product(a[h], n[h]);
        for (int i = 0; i < 3; ++i) {
            for (int j = 0; j < 3; ++j) {
                g.m[i][j] += an.m[i][j];
            }
        }
    }
    // B_h does not depend on the weights' scale (1/σ² spans 1e-6 to 1e6):
    // g is inverted at unit mean diagonal.
    const double scale = (std::fabs(g.m[0][0]) + std::fabs(g.m[1][1]) + std::fabs(g.m[2][2])) / 3.0;
    if (!(scale > 0.0) || !std::isfinite(scale)) {
        return false;
    }
    for (auto& row : g.m) {
        for (double& v : row) {
            v /= scale;
        }
    }
    Matrix3 g_inv{};
    if (!inverse_scaled(g, false, &g_inv)) {
        return false;
    }
    for (std::size_t h = 0; h < heads; ++h) {
        b[h] = product(g_inv, a[h]);
        for (auto& row : b[h].m) {
            for (double& v : row) {
                v /= scale;
            }
        }
    }
    return true;
}

// The sums of the rule's least squares over orbits (or epochs), about a
// centre of T2 and T3 fixed before the first is added (the regressors are
// then nearly orthogonal to the constant).
struct CommonRotationSums {
    double t2_centre = 0.0;  // °C
    double t3_centre = 0.0;
    Matrix3 rr{};  // Σ r·rᵀ
    Matrix3 yr{};  // Σ y·rᵀ, a row per F axis (arcsec)
};

// Adds one orbit: y the bench's motion (arcsec, F axes), t2, t3 its T029 and T032 (°C).
inline void add_to_common_rotation(CommonRotationSums& s, const double (&y)[3], double t2, double t3) noexcept {
    const double r[3] = {1.0, t2 - s.t2_centre, t3 - s.t3_centre};
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) {
            s.rr.m[i][j] += r[i] * r[j];
            s.yr.m[i][j] += y[i] * r[j];
        }
    }
}

// How far T029 and T032 have varied apart over the sums: 1 − ρ², ρ their
// correlation about their own mean (so where the centre lies does not
// matter); 0 when either has not varied.
inline double common_rotation_independence(const CommonRotationSums& s) noexcept {
    const double n = s.rr.m[0][0];
    if (!(n > 0.0)) {
        return 0.0;
    }
    const double m2 = s.rr.m[0][1] / n;
    const double m3 = s.rr.m[0][2] / n;
    const double c22 = s.rr.m[1][1] - n * m2 * m2;
    const double c33 = s.rr.m[2][2] - n * m3 * m3;
    const double c23 = s.rr.m[1][2] - n * m2 * m3;
    if (!(c22 > 0.0 && c33 > 0.0)) {
        return 0.0;
    }
    return 1.0 - c23 * c23 / (c22 * c33);
}

// Below it (1 − ρ², |ρ| > 0.99995) the slopes on T029 and T032 are not fixed
// apart by the data: the rule then fixes the constant alone (on board) or is
// refused (the ground fit). One threshold for both.
inline constexpr double kMinTemperatureIndependence = 1e-4;

// The common rotation the rule adds, ω(T2, T3) = w0 + w2·T2 + w3·T3 (arcsec,
// F axes; w[axis] = {w0, w2, w3}, about 0 °C, not the centre): w = −(Σ y·rᵀ)(Σ r·rᵀ)⁻¹.
// false when T029 and T032 do not vary independently over the sums
// (common_rotation_independence below kMinTemperatureIndependence: the rule
// is then not unique).
inline bool common_rotation_of(const CommonRotationSums& s, double (&w)[3][3]) noexcept {
    Matrix3 rr_inv{};
    if (!(common_rotation_independence(s) >= kMinTemperatureIndependence) || !inverse_scaled(s.rr, true, &rr_inv)) {
        return false;
    }
    const Matrix3 wc = product(s.yr, rr_inv);
    for (int i = 0; i < 3; ++i) {
        w[i][1] = -wc.m[i][1];
        w[i][2] = -wc.m[i][2];
        w[i][0] = -wc.m[i][0] - w[i][1] * s.t2_centre - w[i][2] * s.t3_centre;
    }
    return true;
}

// Adds the common rotation ω = w0 + w2·T2 + w3·T3 (F axes, arcsec; w[axis] =
// {w0, w2, w3}) to one head's coefficients c[axis][term] (arcsec, head axes,
// the terms of core/model_terms.hpp): N_h·ω, with T2 = T1 + (T2 − T1) and
// likewise T3 (the model's regressors). C: any array of axes of terms.
template <typename C>
void add_common_rotation(const Matrix3& n_h, const double (&w)[3][3], C& c) noexcept {
    for (std::size_t ax = 0; ax < 3; ++ax) {
        double nw[3] = {0.0, 0.0, 0.0};  // N_h·w0, N_h·w2, N_h·w3, axis ax
        for (std::size_t j = 0; j < 3; ++j) {
            nw[j] = n_h.m[ax][0] * w[0][j] + n_h.m[ax][1] * w[1][j] + n_h.m[ax][2] * w[2][j];
        }
        c[ax][term_index(Regressor::kOne, 0)] += nw[0];
        c[ax][term_index(Regressor::kT1, 1)] += nw[1] + nw[2];
        c[ax][term_index(Regressor::kT2MinusT1, 1)] += nw[1];
        c[ax][term_index(Regressor::kT3MinusT1, 1)] += nw[2];
    }
}

}  // namespace ascorr::calib
