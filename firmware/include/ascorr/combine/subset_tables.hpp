// ascorr/combine/subset_tables.hpp: what depends only on the head set, in double.
//
// For a subset S of the mounted heads (a HeadMask), with W_i and C_i = W_i⁻¹
// the heads' information and covariance in CRF axes (mountings.hpp,
// arcsec units), P_S = Σ_{j∈S} W_j:
//  - gains       K_{S,i} = P_S⁻¹ W_i, i ∈ S (dimensionless; Σ_i K_{S,i} = I):
//                the combined small rotation is Σ_i K_{S,i} θ_i, the
//                information-weighted mean (weighted least squares, the
//                heads' errors independent, Gaussian, with covariances C_i);
//  - formal σ    sqrt(diag(P_S⁻¹)) (arcsec), the 1σ about the CRF axes; the
//                whole P_S⁻¹ (arcsec²) is subset_covariance's;
//  - gate factor U_{S,i}, upper triangular, for |S| ≥ 2 (combiner.hpp's gate).
//    Head i's leave-one-out residual r_i = θ_i − θ̂_{S∖i} has covariance
//    C_i + P_{S∖i}⁻¹; the gate adds the floor f² I (arcsec²) and divides by k²:
//      G = (C_i + P_{S∖i}⁻¹ + f² I)⁻¹ / k²,  d_i² = r_iᵀ G r_i.
//    r_i follows from the full set's residual e_i = θ_i − θ̂_S without a
//    second estimate: P_{S∖i}(θ_i − θ̂_{S∖i}) = P_S θ_i − W_i θ_i − (P_S θ̂_S −
//    W_i θ_i) = P_S e_i, so r_i = A_i e_i with A_i = (P_S − W_i)⁻¹ P_S, and
//      d_i² = e_iᵀ A_iᵀ G A_i e_i = ‖U_{S,i} e_i‖²,  U_{S,i}ᵀU_{S,i} = A_iᵀ G A_i
//    (Cholesky). Per epoch that is six products and three squares per head.
//    U is returned per radian of the half-angle vector the combiner works in
//    (θ/2, combiner.hpp): U_rad = 2 · kRadToArcsec · U_arcsec.
// Construction time only (division and sqrt; matrix3.hpp's bit-reproducible
// operations), never per epoch.
#pragma once

#include <cmath>
#include <cstdint>

#include "../core/constants.hpp"
#include "../core/heads.hpp"
#include "matrix3.hpp"
#include "mountings.hpp"

namespace ascorr::combine {

// P_S = Σ_{j∈S} W_j (1/arcsec²).
inline Matrix3 subset_information(const Mountings& m, HeadMask s) noexcept {
    Matrix3 p = zero_matrix();
    for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
        if ((s & head_bit(h)) != 0U) {
            p = p + information(m.head[h]);
        }
    }
    return p;
}

struct SubsetGains {
    Matrix3 gain[kMaxHeads];  // K_{S,i}; zero for i ∉ S
    double sigma_arcsec[3];   // formal 1σ about CRF x, y, z
    double max_row_sum;       // max over rows of Σ_{i∈S} Σ_c |K_{S,i}[row][c]|
};

// The formal covariance P_S⁻¹ of subset s's combination (arcsec², CRF axes);
// false when P_S is singular to matrix3.hpp's inverse_spd.
inline bool subset_covariance(const Mountings& m, HeadMask s, Matrix3* cov) noexcept {
    return inverse_spd(subset_information(m, s), cov);
}

// The gains and formal σ of subset s (non-empty, of usable mounted heads);
// false when P_S is singular to matrix3.hpp's inverse_spd.
inline bool subset_gains(const Mountings& m, HeadMask s, SubsetGains* out) noexcept {
    Matrix3 cov{};
    if (!subset_covariance(m, s, &cov)) {
        return false;
    }
    SubsetGains g{};
    double row_sum[3] = {0.0, 0.0, 0.0};
    for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
        g.gain[h] = zero_matrix();
        if ((s & head_bit(h)) == 0U) {
            continue;
        }
        g.gain[h] = cov * information(m.head[h]);
        for (int r = 0; r < 3; ++r) {
            row_sum[r] += std::fabs(g.gain[h].m[r][0]) + std::fabs(g.gain[h].m[r][1]) + std::fabs(g.gain[h].m[r][2]);
        }
    }
    g.max_row_sum = std::fmax(row_sum[0], std::fmax(row_sum[1], row_sum[2]));
    for (int a = 0; a < 3; ++a) {
        g.sigma_arcsec[a] = std::sqrt(cov.m[a][a]);
    }
    *out = g;
    return true;
}

// U_{S,i} per radian of half-angle (above), for head i in s, |s| ≥ 2, gate
// with k sigmas and a floor of `floor_arcsec`; false when a matrix is singular.
inline bool subset_gate(const Mountings& m, HeadMask s, std::uint8_t i, double k, double floor_arcsec,
                        Matrix3* u) noexcept {
    const auto rest = static_cast<HeadMask>(s & ~head_bit(i));
    const Matrix3 p = subset_information(m, s);
    Matrix3 p_rest_inv{};
    if (!inverse_spd(subset_information(m, rest), &p_rest_inv)) {
        return false;
    }
    const double f2 = floor_arcsec * floor_arcsec;
    Matrix3 g{};
    if (!inverse_spd(covariance(m.head[i]) + p_rest_inv + diagonal(f2, f2, f2), &g)) {
        return false;
    }
    const Matrix3 a = p_rest_inv * p;
    Matrix3 h = transpose(a) * g * a;
    const double scale = 1.0 / (k * k);
    for (auto& row : h.m) {
        for (double& x : row) {
            x *= scale;
        }
    }
    // Symmetrise exactly (the products leave rounding asymmetry).
    for (int r = 0; r < 3; ++r) {
        for (int c = r + 1; c < 3; ++c) {
            const double mean = 0.5 * (h.m[r][c] + h.m[c][r]);
            h.m[r][c] = mean;
            h.m[c][r] = mean;
        }
    }
    Matrix3 chol{};
    if (!cholesky_upper(h, &chol)) {
        return false;
    }
    constexpr double kPerHalfRad = 2.0 * kRadToArcsec;
    for (auto& row : chol.m) {
        for (double& x : row) {
            x *= kPerHalfRad;
        }
    }
    *u = chol;
    return true;
}

// An upper bound of λ_max(UᵀU) for U of subset_gate: the smaller of the trace
// and the largest absolute row sum (Gershgorin) of UᵀU, both ≥ λ_max.
inline double gate_norm_bound(const Matrix3& u) noexcept {
    const Matrix3 h = transpose(u) * u;
    double rows = 0.0;
    for (const auto& row : h.m) {
        rows = std::fmax(rows, std::fabs(row[0]) + std::fabs(row[1]) + std::fabs(row[2]));
    }
    return std::fmin(h.m[0][0] + h.m[1][1] + h.m[2][2], rows);
}

// Mountings usable for the combination? kNone, or the first problem found
// (mountings.hpp's MountingsProblem): each present head in index order
// (quaternion, then sigma_cross, then sigma_about), then no head at all, then
// every subset of the present heads (ill-conditioned). *head receives the
// head concerned (kUnknownHead for kNoHead; the lowest head of the subset for
// kIllConditioned), *subset (when given) the subset for kIllConditioned.
inline MountingsProblem check_mountings(const Mountings& m, std::uint8_t* head, HeadMask* subset = nullptr) noexcept {
    *head = kUnknownHead;
    if (subset != nullptr) {
        *subset = 0;
    }
    for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
        if (!m.head[h].present) {
            continue;
        }
        const MountingsProblem p = detail::head_problem(m.head[h]);
        if (p != MountingsProblem::kNone) {
            *head = h;
            return p;
        }
    }
    const HeadMask mounted = mounted_heads(m);
    if (mounted == 0U) {
        return MountingsProblem::kNoHead;
    }
    for (unsigned s = 1; s < kSubsetCount; ++s) {
        if ((s & ~unsigned{mounted}) != 0U) {
            continue;
        }
        SubsetGains g{};
        if (!subset_gains(m, static_cast<HeadMask>(s), &g) || !(g.max_row_sum <= kMaxGainRowSum)) {
            for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
                if ((s & head_bit(h)) != 0U) {
                    *head = h;
                    break;
                }
            }
            if (subset != nullptr) {
                *subset = static_cast<HeadMask>(s);
            }
            return MountingsProblem::kIllConditioned;
        }
    }
    return MountingsProblem::kNone;
}

}  // namespace ascorr::combine
