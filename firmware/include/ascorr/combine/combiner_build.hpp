// ascorr/combine/combiner_build.hpp: the combiner's construction (double; division and sqrt allowed, never per epoch).
// Part of combiner.hpp (the overview, the conventions and the order of the
// steps are there); include that one.
#pragma once

#include "combiner_class.hpp"

namespace ascorr::combine {

// The rotation by which a mounting rounded to T turns a head's estimate, as
// the half-angle vector in CRF axes: q_chu_crf* rounded is E ⊗ q_chu_crf* with
// E = rounded ⊗ q_chu_crf (exact, double), so every estimate of that head
// carries E on the left, and the combination Σ_i K_{S,i} vec(E_i) (Σ K = I
// makes the reference's own part cancel to that too). Taken out per subset
// (SubsetTable::start, the sums' start): in float the rounding of a mounting (≤ 2⁻²⁵ per component) would
// otherwise put up to 0.02″ of constant error per head set into the
// attitude, a step at every head-set change; in Q30 (2⁻³¹) 3e-4″; zero in double.
template <typename T>
Vector3<double> rounding_rotation(const HeadMounting& h, const Quaternion<T>& conj_rounded) noexcept {
    using Tr = ScalarTraits<T>;
    const Quaternion<double> q = unit_mounting(h);
    const Quaternion<double> r{Tr::to_double(conj_rounded.w), Tr::to_double(conj_rounded.x),
                               Tr::to_double(conj_rounded.y), Tr::to_double(conj_rounded.z)};
    const Quaternion<double> e = r * q;  // rounded conj ⊗ q_chu_crf: the identity but for the rounding
    const double sign = e.w < 0.0 ? -1.0 : 1.0;
    return {sign * e.x, sign * e.y, sign * e.z};
}

// The quick gate's bound on ‖e‖² (kernels.hpp quick_gate): 1/λ_max(UᵀU),
// capped at a fifth of sin²(kGrossAngleRad/2), so that heads that all pass
// it are within the gross gate of each other (‖h_i‖ ≤ ‖e_i‖ + ‖e_ref‖ ≤
// 2/√5·sin(φ_max/2), with margin for rounding): combine_usual() needs no
// separate gross test. The cap only sends a head to the full statistic
// sooner; it decides nothing (the default gate's bounds are ~1e-8 rad²,
// the cap 7.6e-7).
inline double quick_bound(const Matrix3& u) noexcept {
    const double s = 0.5 * kGrossAngleRad;
    const double cap = 0.2 * s * s * (1.0 - s * s / 3.0);
    const double b = 1.0 / gate_norm_bound(u);
    return b < cap ? b : cap;
}

template <typename T>
void Combiner<T>::build(const Mountings& m, const CombinerConfig& cfg) noexcept {
    problem_ = check_mountings(m, &problem_head_);
    if (problem_ != MountingsProblem::kNone) {
        return;
    }
    if (!gate_config_valid(cfg)) {
        problem_ = MountingsProblem::kGateConfig;
        return;
    }
    mounted_ = mounted_heads(m);
    const double s = 0.5 * kGrossAngleRad;  // sin² and cos² of s by their series (s = 2⁻⁹)
    const double sin2 = s * s * (1.0 - s * s / 3.0);
    near2_ = ScalarTraits<T>::from_double(sin2);
    one_minus_near2_ = ScalarTraits<T>::from_double(1.0 - sin2);
    for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
        if (m.head[h].present) {
            const Quaternion<double> q = unit_mounting(m.head[h]);
            mount_conj_[h] = {ScalarTraits<T>::from_double(q.w), ScalarTraits<T>::from_double(-q.x),
                              ScalarTraits<T>::from_double(-q.y), ScalarTraits<T>::from_double(-q.z)};
            mount_factor_[h] = CombineFormats<T>::mounting_from(mount_conj_[h]);
        }
    }
    for (unsigned sub = 1; sub < kSubsetCount; ++sub) {
        if ((sub & ~unsigned{mounted_}) == 0U && !build_subset(m, static_cast<HeadMask>(sub), cfg)) {
            problem_ = MountingsProblem::kGateOutOfRange;  // problem_head_ set by build_subset
            problem_subset_ = static_cast<HeadMask>(sub);
            return;
        }
    }
}

// The gate factor of head h in subset s (|s| ≥ 2), its quick bound, in T;
// false when a matrix is singular or a factor beyond kMaxGateFactor.
template <typename T>
bool Combiner<T>::build_gate(const Mountings& m, HeadMask s, std::uint8_t h, const CombinerConfig& cfg) noexcept {
    using F = CombineFormats<T>;
    Matrix3 u{};
    if (!subset_gate(m, s, h, cfg.gate_sigmas, cfg.gate_floor_arcsec, &u) || !gate_factors_fit(u)) {
        return false;
    }
    table_[s].quick[h] = F::quick_from_double(quick_bound(u));
    table_[s].gate[h] = {F::gate_from_double(u.m[0][0]), F::gate_from_double(u.m[0][1]),
                         F::gate_from_double(u.m[0][2]), F::gate_from_double(u.m[1][1]),
                         F::gate_from_double(u.m[1][2]), F::gate_from_double(u.m[2][2])};
    return true;
}

template <typename T>
bool Combiner<T>::build_subset(const Mountings& m, HeadMask s, const CombinerConfig& cfg) noexcept {
    using F = CombineFormats<T>;
    SubsetGains g{};
    if (!subset_gains(m, s, &g)) {
        return false;  // check_mountings() has accepted every subset: not reached
    }
    for (int a = 0; a < 3; ++a) {
        sigma_[s][a] = g.sigma_arcsec[a];
    }
    double bias[3] = {0.0, 0.0, 0.0};
    const bool several = head_count(s) >= 2;
    for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
        if ((s & head_bit(h)) == 0U) {
            continue;
        }
        const Vector3<double> e = rounding_rotation(m.head[h], mount_conj_[h]);
        for (int r = 0; r < 3; ++r) {
            for (int c = 0; c < 3; ++c) {
                table_[s].gain[h].k[r][c] = F::gain_from_double(g.gain[h].m[r][c]);
            }
            bias[r] += g.gain[h].m[r][0] * e.x + g.gain[h].m[r][1] * e.y + g.gain[h].m[r][2] * e.z;
        }
        if (several && !build_gate(m, s, h, cfg)) {
            problem_head_ = h;
            return false;
        }
    }
    table_[s].start =
        accumulator_from(Vector3<T>{ScalarTraits<T>::from_double(-bias[0]), ScalarTraits<T>::from_double(-bias[1]),
                                    ScalarTraits<T>::from_double(-bias[2])});
    return true;
}

}  // namespace ascorr::combine
