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
// coefficients are unobservable and 27 observable. Of the equivalent models,
// the ground fit writes the one with the smallest corrections.
// Double only (per orbit); fixed trip counts, no allocation.
#pragma once

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

}  // namespace ascorr::calib
