// ascorr/calib/common_rotation_memory.hpp: the rule for the rotation common to
// all heads (common_rotation.hpp, "The rule") on board, over the estimator's
// memory of orbits.
//
// The rule's least squares needs, over the orbits, Σ y·rᵀ and Σ r·rᵀ with
// y = Σ_h B_h·c_h(orbit) the bench's motion from the candidate's corrections
// and r = [1, T2 − T̄2, T3 − T̄3]. The candidate changes every orbit, so the
// model-free moments are kept instead and contracted with it when a candidate
// is formed: per head h, S_h = Σ a_h·rᵀ (4 × 3), a_h the head's design row
// [1, T1 − T̄1, D2 − D̄2, D3 − D̄3] (the filter's, Estimator::feed), so that
// Σ c_h·rᵀ = b_hᵀ·S_h with b_h the centred solution (4 unknowns × 3 axes).
// They hold temperatures only, so they are not forgotten with the filter: a
// candidate is re-gauged over every orbit since the last reset, whose wider
// range of T029 and T032 fixes the slopes w2, w3 better than the filter's
// memory of τ (measured: the combined attitude's error 1.263 → 1.257″ on x
// from day 30, test_common_rotation). Bounded: an orbit adds at most
// (ΔT)² ≤ 1.6e5 °C² (temperatures within ±200 °C) per sum, so 10 years of
// 100-minute orbits stay below 1e10, far from double's range or precision.
// A change taken as real (release of the intercepts) leaves them; reset()
// clears them. A further head (D) has orbits without means, and the full set
// then differs: the moments are kept per set of heads in the orbit (the frame
// heads always; 2^(N − 3) sets), and each set's bench weights B_h are those of
// its heads that the candidate solved and the rule weighs.
//
// The bench weights B_h of a set depend only on its heads, their
// orientations and the rule's weights, all fixed between clear()s (N_h is a
// head's reference from its first orbit): each set keeps those of the heads
// of its last solve, so a solve is mostly the contraction.
//
// Double (per orbit, in Estimator::step's phases); fixed trip counts, no
// allocation. Cost per fed orbit: 9 + 12·|heads| multiply-adds; per solve
// 63 multiply-adds per head of each set and about 100 flops for ω, plus
// about 300 to form a set's weights when its heads differ from the last
// solve's (a candidate with a head the active model did not learn: twice
// an orbit until one is adopted; one slot per set keeps RAM at 8 + 72·N B).
#pragma once

#include <cstddef>
#include <cstdint>

#include "../core/model_coefficients.hpp"
#include "../core/model_terms.hpp"
#include "common_rotation.hpp"
#include "estimator_types.hpp"
#include "orbit_window.hpp"

namespace ascorr::calib {

template <std::size_t N = kCalibHeads>
class CommonRotationMemory {
public:
    static constexpr std::size_t kSets = std::size_t{1} << (N - kFrameHeads);

    void clear() noexcept { *this = CommonRotationMemory{}; }

    // The centre of T2 and T3 (°C), fixed before the first orbit (head A's
    // first orbit: the estimator's centre, T1 + D2 and T1 + D3).
    void set_centre(double t2, double t3) noexcept {
        t2_ = t2;
        t3_ = t3;
    }

    // One fed orbit: its heads' design rows (centred as the filter's, centre[h]).
    void add(const OrbitRecord<N>& o, const double (&centre)[N][3]) noexcept {
        Set& s = set_[o.heads() >> kFrameHeads];
        const double r[3] = {1.0, o.t2() - t2_, o.t3() - t3_};
        for (int i = 0; i < 3; ++i) {
            for (int j = 0; j < 3; ++j) {
                s.rr.m[i][j] += r[i] * r[j];
            }
        }
        for (std::size_t h = 0; h < N; ++h) {
            if (!o.has[h]) {
                continue;
            }
            const double a[kUnknowns] = {1.0, o.x[h][0] - centre[h][0], o.x[h][1] - centre[h][1],
                                         o.x[h][2] - centre[h][2]};
            for (std::size_t k = 0; k < kUnknowns; ++k) {
                for (int j = 0; j < 3; ++j) {
                    s.s[h][k][j] += a[k] * r[j];
                }
            }
        }
        ++s.count;
    }

    // The rule's ω for the centred solution b of the heads `solved`, with the
    // weights wt and the heads' orientations n (F → head axes; both the same
    // at every call between clear()s): w[axis] = {w0, w2, w3} about 0 °C.
    // Where T029 and T032 have not varied apart within the memory (the first
    // days), the constant alone (w2 = w3 = 0). false: no set has weighted heads.
    bool solve(const double (&b)[N][kUnknowns][3], const Matrix3 (&n)[N], std::uint8_t solved,
               const CommonRotationWeights& wt, double (&w)[3][3]) noexcept {
        CommonRotationSums sums;
        sums.t2_centre = t2_;
        sums.t3_centre = t3_;
        bool any = false;
        for (std::size_t m = 0; m < kSets; ++m) {
            const auto heads = static_cast<std::uint8_t>((kFrameMask | (m << kFrameHeads)) & solved & wt.heads);
            if (set_[m].count == 0U || heads == 0U) {
                continue;
            }
            const Weights& bw = weights(m, heads, n, wt);
            if (bw.ok) {
                add_set(set_[m], bw, b, sums);
                any = true;
            }
        }
        if (!any) {
            return false;
        }
        if (common_rotation_of(sums, w)) {
            return true;
        }
        for (int ax = 0; ax < 3; ++ax) {  // the constant alone: w0 = −Σy / n
            w[ax][0] = -sums.yr.m[ax][0] / sums.rr.m[0][0];
            w[ax][1] = 0.0;
            w[ax][2] = 0.0;
        }
        return true;
    }

private:
    struct Set {
        Matrix3 rr{};                 // Σ r·rᵀ
        double s[N][kUnknowns][3]{};  // Σ a_h·rᵀ
        std::uint32_t count = 0;      // orbits added (not forgotten)
    };

    // A set's bench weights B_h (bench_weights) for its heads `heads`, by head index.
    struct Weights {
        std::uint8_t heads = 0;  // 0: not formed
        bool ok = false;         // false: Σ A_h·N_h singular (no head weighs)
        Matrix3 b[N]{};
    };

    // Set m's weights for `heads`, formed when its heads differ from the last.
    const Weights& weights(std::size_t m, std::uint8_t heads, const Matrix3 (&n)[N],
                           const CommonRotationWeights& wt) noexcept {
        Weights& c = weights_[m];
        if (c.heads == heads) {
            return c;
        }
        Matrix3 a[N]{};
        Matrix3 nn[N]{};
        Matrix3 bw[N]{};
        std::size_t idx[N]{};
        std::size_t k = 0;
        for (std::size_t h = 0; h < N; ++h) {
            if (((static_cast<unsigned>(heads) >> h) & 1U) != 0U) {
                a[k] = wt.a[h];
                nn[k] = n[h];
                idx[k++] = h;
            }
        }
        c = Weights{};
        c.heads = heads;
        c.ok = bench_weights(a, nn, k, bw);
        for (std::size_t i = 0; i < k && c.ok; ++i) {
            c.b[idx[i]] = bw[i];
        }
        return c;
    }

    // Σ y·rᵀ of one set into sums: Σ_h B_h·(b_hᵀ·S_h) over the heads weighed.
    static void add_set(const Set& s, const Weights& bw, const double (&b)[N][kUnknowns][3],
                        CommonRotationSums& sums) noexcept {
        for (std::size_t h = 0; h < N; ++h) {
            if (((static_cast<unsigned>(bw.heads) >> h) & 1U) == 0U) {
                continue;
            }
            Matrix3 cr{};  // Σ c_h·rᵀ = b_hᵀ·S_h (head axes × r)
            for (int ax = 0; ax < 3; ++ax) {
                for (int j = 0; j < 3; ++j) {
                    for (std::size_t u = 0; u < kUnknowns; ++u) {
                        cr.m[ax][j] += b[h][u][ax] * s.s[h][u][j];
                    }
                }
            }
            const Matrix3 y = product(bw.b[h], cr);
            for (int r = 0; r < 3; ++r) {
                for (int j = 0; j < 3; ++j) {
                    sums.yr.m[r][j] += y.m[r][j];
                }
            }
        }
        for (int r = 0; r < 3; ++r) {
            for (int j = 0; j < 3; ++j) {
                sums.rr.m[r][j] += s.rr.m[r][j];
            }
        }
    }

    double t2_ = 0.0;
    double t3_ = 0.0;
    Set set_[kSets]{};
    Weights weights_[kSets]{};
};

}  // namespace ascorr::calib
