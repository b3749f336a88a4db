// ascorr/combine/combiner.hpp: one attitude of the bench (CRF) from the heads of one epoch.
//
// Conventions (mountings.hpp, kernels.hpp; the contract's "Combined attitude"):
//  - each head's corrected solution q_chu_icrf_i gives an estimate of the CRF
//    attitude q_crf_icrf_i = q_chu_crf_i* ⊗ q_chu_icrf_i;
//  - the combined attitude is the information-weighted mean of their small
//    rotations about a reference (the first usable head), in CRF axes:
//      θ̄ = (Σ W_i)⁻¹ Σ W_i θ_i,   q_crf_icrf = Exp(θ̄) ⊗ q_ref,
//    with formal covariance (Σ W_i)⁻¹ (subset_tables.hpp; Bandikova & Flury
//    2014, eq. 4; Romans 2003). Weighted least squares for independent heads
//    whose noise is σc across and σa about their boresight;
//  - q_crf_icrf has w ≥ 0; both signs of every input are the same attitude.
//
// Per epoch, for n heads (the usual epoch; the vote and the gate's rounds
// only when a head is off): n quaternion products (the mountings), n − 1
// half-angle differences to the reference, n − 1 gain products (3 × 3), per
// head a quick gate (‖e‖² against a bound of the gate, three squares; the full
// statistic, six products and three squares, only above it), one quaternion
// update and one renormalisation (a Newton step: no division, no square
// root). Every table is built at construction in double (subset_tables.hpp).
// Instructions per epoch of three heads: docs/figures.md.
//
// Which heads are averaged (in this order):
//  1. Left out, status 4 (not `inconsistent`): an entry whose head index is no
//     head (≥ kMaxHeads; in no mask), a second entry of a head already seen
//     (the first one is kept), an entry the caller marked not usable, a head
//     not in the mountings, and a quaternion that is not unit (the core's
//     tolerance; NaN and infinity included).
//  2. The gross gate (bounded linearisation): every kept head within
//     kGrossAngleRad (2⁻⁸ rad, 806″) of the reference is kept. When one is
//     not, the reference becomes the head within that angle of the most
//     others (the first in input order on a tie); heads farther from it are
//     inconsistent. No two heads within the angle of each other, or a head
//     outside the reference's group near as many others as the reference
//     (e.g. two pairs of four heads): no combination (below).
//  3. The consistency gate, a gross-error gate. Head i's leave-one-out
//     residual r_i = θ_i − θ̂_{S∖i} (its estimate against the others'
//     combination) is normalised by its covariance plus a floor:
//        d_i² = r_iᵀ (C_i + P_{S∖i}⁻¹ + f² I)⁻¹ r_i,
//     and the head is inconsistent when d_i > k (CombinerConfig: k = 6;
//     the floor f by what is known of the rows and the mountings,
//     default_gate below). The floor keeps what the heads' noise does not
//     describe inside the gate: with f = 10″ it never trips below k·f = 60″,
//     so not on the differential aberration of raw rows (up to ~29″), the
//     2–3″ of uncorrected deformation, nor pre-flight mountings a few tens of
//     arcsec off; with f = 2″ (both stages, mountings of the ground) a head
//     40″ off across its boresight is caught (tests: CombineGate). With the
//     covariance, not on noise (5σ of one head gives d² ≤ 25 < 36). With
//     σc = 1.3″, σa = 9″ and f = 10″ it surely trips beyond
//     k·sqrt(σa² + σa² + f²) ≈ 97″ (two heads) and ~82″ (three). With three
//     or more heads,
//     of the heads beyond the gate the one whose removal leaves the others
//     most consistent (the smallest largest d² of the rest, each found by the
//     same tables) is left out, and the gate is run again on the rest: at
//     most kMaxHeads − 2 rounds of at most kMaxHeads trials (when the
//     reference goes, the differences are re-formed about the first
//     remaining head). The largest d_i alone is not enough: a good head
//     whose weak axis the bad head's error lies along can score higher. Two heads
//     that fail the gate (first or after a removal): nothing tells which one
//     is wrong, and averaging would put the gross error into the attitude,
//     so there is no combination: both are inconsistent, status 4 | 8, q the
//     identity. A gap with its reason is safer for the user than an attitude
//     that may be hundreds of arcsec off, and it is what the Swarm product
//     does for an epoch without a consistent pair ("not enough data").
//  4. Status: 1 with two or more heads averaged, 2 with one (its formal σ is
//     large about its boresight), 8 with none (q the identity); 4 whenever a
//     head was left out (combined_status.hpp).
#pragma once

#include <cstdint>

#include "../core/heads.hpp"
#include "../core/quaternion.hpp"
#include "../core/scalar_traits.hpp"
#include "combined_status.hpp"
#include "gate_config.hpp"
#include "kernels.hpp"
#include "mountings.hpp"
#include "subset_tables.hpp"

namespace ascorr::combine {

// combine_usual_n's loops run N ≤ kMaxHeads times: unrolled, so that the
// candidates stay in registers (GCC's -O2 keeps them as loops otherwise).
#if defined(__clang__)
#define ASCORR_UNROLL_HEADS _Pragma("unroll")
#else
#define ASCORR_UNROLL_HEADS _Pragma("GCC unroll 4")
#endif

// The gross gate's angle (rad): beyond it the small-angle differences lose
// their bound (kernels.hpp) and a head is judged by vote (step 2 above).
inline constexpr double kGrossAngleRad = 0x1p-8;

// One head's corrected solution at the epoch.
template <typename T>
struct HeadAttitude {
    Quaternion<T> q_chu_icrf;
    std::uint8_t head;  // heads.hpp index
    bool usable;        // the caller's selection (clean, not rejected, stages applied)
};

template <typename T>
struct CombinedAttitude {
    Quaternion<T> q_crf_icrf;  // w ≥ 0; the identity when status has kNoHead
    HeadMask used;             // heads averaged in
    HeadMask left_out;         // present at the epoch but not used
    HeadMask inconsistent;     // of left_out: refused by the gross or the consistency gate
    std::uint8_t subset;       // = used: the index of sigma_arcsec()'s table
    CombinedStatus status;     // combined_status.hpp
};

template <typename T>
class Combiner {
public:
    explicit Combiner(const Mountings& m, const CombinerConfig& cfg = {}) noexcept { build(m, cfg); }

    // The mountings (and the configuration) are usable; combine() returns
    // status 8 for every epoch otherwise.
    bool valid() const noexcept { return problem_ == MountingsProblem::kNone; }
    MountingsProblem problem() const noexcept { return problem_; }
    std::uint8_t problem_head() const noexcept { return problem_head_; }
    // kGateOutOfRange: the head set whose gate of problem_head() is beyond the format.
    HeadMask problem_subset() const noexcept { return problem_subset_; }
    HeadMask mounted() const noexcept { return mounted_; }

    // Formal 1σ about CRF x, y, z (arcsec) of the combination of `subset`
    // (a HeadMask; CombinedAttitude::subset); zeros for 0 or a subset with a
    // head not mounted.
    const double* sigma_arcsec(std::uint8_t subset) const noexcept {
        return sigma_[subset < kSubsetCount ? subset : 0U];
    }

    // Up to kMaxHeads solutions of one epoch, in any order (more are accepted
    // and accounted for: every entry beyond kMaxHeads distinct heads is left out).
    CombinedAttitude<T> combine(const HeadAttitude<T>* heads, std::uint8_t n) const noexcept;

private:
    struct Candidate {
        Quaternion<T> q;  // q_crf_icrf_i
        Vector3<T> h;     // half-angle difference to the reference (kernels.hpp)
        std::uint8_t head;
    };
    struct Epoch {
        Candidate c[kMaxHeads];
        std::uint8_t n;         // candidates
        std::uint8_t ref;       // index of the reference candidate
        std::uint8_t group;     // candidate-index mask of the heads still in
        HeadMask heads;         // the candidates' heads
        HeadMask left_out;      // step 1's
        HeadMask inconsistent;  // steps 2 and 3's
        bool left_out_any;      // also entries that name no head
    };

    void build(const Mountings& m, const CombinerConfig& cfg) noexcept;
    bool build_subset(const Mountings& m, HeadMask s, const CombinerConfig& cfg) noexcept;
    bool build_gate(const Mountings& m, HeadMask s, std::uint8_t h, const CombinerConfig& cfg) noexcept;
    bool combine_usual(const HeadAttitude<T>* heads, std::uint8_t n, CombinedAttitude<T>* out) const noexcept;
    template <std::uint8_t N>
    bool combine_usual_n(const HeadAttitude<T>* heads, CombinedAttitude<T>* out) const noexcept;
    // Out of line: the usual epoch's call stays small (no frame for the general path).
    [[gnu::noinline]] CombinedAttitude<T> combine_general(const HeadAttitude<T>* heads, std::uint8_t n) const noexcept;
    void select(const HeadAttitude<T>* heads, std::uint8_t n, Epoch& e) const noexcept;
    std::uint8_t linearise(Epoch& e) const noexcept;
    bool vote(Epoch& e) const noexcept;
    struct GateResult {
        std::uint8_t failing;  // candidate-index mask beyond the gate
        GateValue<T> largest;  // the largest statistic
    };
    Vector3<T> estimate(const Epoch& e, std::uint8_t group, HeadMask s) const noexcept;
    GateResult gate_group(const Epoch& e, std::uint8_t group, HeadMask s, const Vector3<T>& est) const noexcept;
    std::uint8_t odd_one_out(const Epoch& e, std::uint8_t failing) const noexcept;
    bool gate(Epoch& e, Vector3<T>* est) const noexcept;
    bool combine_group(Epoch& e, Vector3<T>* est) const noexcept;
    HeadMask heads_of(const Epoch& e, std::uint8_t group) const noexcept;
    CombinedAttitude<T> finish(const Epoch& e, bool combined, const Vector3<T>& est) const noexcept;

    MountingsProblem problem_ = MountingsProblem::kNoHead;
    std::uint8_t problem_head_ = kUnknownHead;
    HeadMask problem_subset_ = 0;
    HeadMask mounted_ = 0;
    T near2_{};                                    // sin²(kGrossAngleRad/2)
    T one_minus_near2_{};                          // cos²(kGrossAngleRad/2)
    Quaternion<T> mount_conj_[kMaxHeads]{};        // q_chu_crf* (unit, rounded to T)
    MountingFactor<T> mount_factor_[kMaxHeads]{};  // the same, as mounting_product() takes it
    // What an epoch of one head subset reads, together (one base address).
    struct SubsetTable {
        Accumulator<T> start;            // −Σ K_{S,i} vec(E_i): the mountings' rounding to T, the sums' start
        GainMatrix<T> gain[kMaxHeads];   // K_{S,i}
        QuickBound<T> quick[kMaxHeads];  // 1/λ_max bound of UᵀU, capped (quick_bound; kernels.hpp quick_gate)
        GateMatrix<T> gate[kMaxHeads];   // U_{S,i}
    };
    SubsetTable table_[kSubsetCount]{};
    double sigma_[kSubsetCount][3]{};
};

// ---- Construction (double; division and sqrt allowed, never per epoch).

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

// ---- Per epoch.

namespace detail {
struct HeadCounts {
    std::uint8_t n[kSubsetCount];
};
constexpr HeadCounts make_head_counts() noexcept {
    HeadCounts t{};
    for (unsigned s = 0; s < kSubsetCount; ++s) {
        t.n[s] = head_count(static_cast<HeadMask>(s));
    }
    return t;
}
// The number of heads of each mask: a table, as Armv7-M has no population count.
inline constexpr HeadCounts kHeadCounts = make_head_counts();
// head_bit() of every uint8_t head index, 0 for those that are no head: one load
// instead of a range test and a shift (the usual pass, per entry).
struct HeadBits {
    std::uint8_t bit[256];
};
constexpr HeadBits make_head_bits() noexcept {
    HeadBits t{};
    for (unsigned h = 0; h < kMaxHeads; ++h) {
        t.bit[h] = head_bit(static_cast<std::uint8_t>(h));
    }
    return t;
}
inline constexpr HeadBits kHeadBits = make_head_bits();
}  // namespace detail

template <typename T>
HeadMask Combiner<T>::heads_of(const Epoch& e, std::uint8_t group) const noexcept {
    HeadMask s = 0;
    for (std::uint8_t i = 0; i < e.n; ++i) {
        if (in_mask(group, i)) {
            s = static_cast<HeadMask>(s | head_bit(e.c[i].head));
        }
    }
    return s;
}

// The usual epoch in one pass: n ≥ 2 entries, each a distinct, usable,
// mounted head with a unit quaternion, every head within the quick gate
// (which implies the gross gate: quick_bound). The same operations in the
// same order as the general path (select, combine_group, finish), so the
// answer is that path's bit for bit; false, and *out untouched, for any
// other epoch.
template <typename T>
bool Combiner<T>::combine_usual(const HeadAttitude<T>* heads, std::uint8_t n, CombinedAttitude<T>* out) const noexcept {
    static_assert(kMaxHeads == 4, "one instance per head count from 2 to kMaxHeads");
    switch (n) {
        case 2:
            return combine_usual_n<2>(heads, out);
        case 3:
            return combine_usual_n<3>(heads, out);
        case 4:
            return combine_usual_n<4>(heads, out);
        default:
            return false;
    }
}

// combine_usual for N entries: the loops unrolled, the candidates in registers.
template <typename T>
template <std::uint8_t N>
bool Combiner<T>::combine_usual_n(const HeadAttitude<T>* heads, CombinedAttitude<T>* out) const noexcept {
    constexpr T tol = ScalarTraits<T>::unit_norm_tolerance;
    constexpr std::uint8_t n = N;
    HeadMask s = 0;
    UnitNorms<T> unit;
    Quaternion<T> ref{};
    Vector3<T> h[kMaxHeads];  // half-angle differences to the reference (h[0], zero, unused)
    ASCORR_UNROLL_HEADS
    for (std::uint8_t i = 0; i < n; ++i) {
        const HeadAttitude<T>& a = heads[i];
        const unsigned bit = detail::kHeadBits.bit[a.head];  // 0 for an index that is no head
        if ((bit & mounted_ & ~unsigned{s}) == 0U || !a.usable || !unit.add(a.q_chu_icrf)) {
            return false;
        }
        s = static_cast<HeadMask>(s | bit);
        const Quaternion<T> q = mounting_product(mount_factor_[a.head], a.q_chu_icrf);
        if (i == 0) {
            ref = q;
        } else {
            h[i] = half_difference(q, CombineFormats<T>::reference_from(ref), near2_).h;
        }
    }
    if (!unit.within(tol)) {
        return false;
    }
    Accumulator<T> acc = table_[s].start;
    ASCORR_UNROLL_HEADS
    for (std::uint8_t i = 1; i < n; ++i) {
        accumulate(acc, table_[s].gain[heads[i].head], h[i]);
    }
    const Vector3<T> est = result(acc);
    // The reference's residual is 0 − est: its square is est's, bit for bit.
    if (!quick_gate(est, table_[s].quick[heads[0].head])) {
        return false;
    }
    ASCORR_UNROLL_HEADS
    for (std::uint8_t i = 1; i < n; ++i) {
        if (!quick_gate(residual(h[i], est), table_[s].quick[heads[i].head])) {
            return false;
        }
    }
    out->q_crf_icrf = canonical(apply_left(est, ref));
    out->used = s;
    out->left_out = 0;
    out->inconsistent = 0;
    out->subset = s;
    out->status = combined_status::kTwoOrMoreHeads;
    return true;
}

// Step 1: the candidates, each as its CRF estimate q_crf_icrf_i.
template <typename T>
void Combiner<T>::select(const HeadAttitude<T>* heads, std::uint8_t n, Epoch& e) const noexcept {
    constexpr T tol = ScalarTraits<T>::unit_norm_tolerance;
    HeadMask seen = 0;
    HeadMask taken = 0;
    HeadMask left_out = 0;
    std::uint8_t count = 0;
    bool unknown = false;
    for (std::uint8_t k = 0; k < n; ++k) {
        const HeadAttitude<T>& a = heads[k];
        if (a.head >= kMaxHeads) {
            unknown = true;
            continue;
        }
        const HeadMask bit = head_bit(a.head);
        const bool first = (seen & bit) == 0U;
        seen = static_cast<HeadMask>(seen | bit);
        if (!first || !a.usable || (mounted_ & bit) == 0U || !norm_within(a.q_chu_icrf, tol)) {
            left_out = static_cast<HeadMask>(left_out | bit);
            continue;
        }
        Candidate& c = e.c[count];
        c.q = mounting_product(mount_factor_[a.head], a.q_chu_icrf);
        c.head = a.head;
        taken = static_cast<HeadMask>(taken | bit);
        ++count;
    }
    e.n = count;
    e.heads = taken;
    e.left_out = left_out;
    e.left_out_any = unknown;
}

// Half-angle differences of the group to the reference; returns the
// candidate-index mask of those within the gross gate (the reference included).
template <typename T>
std::uint8_t Combiner<T>::linearise(Epoch& e) const noexcept {
    constexpr T zero = constant<T>(0.0);
    auto near = static_cast<std::uint8_t>(1U << e.ref);
    e.c[e.ref].h = {zero, zero, zero};
    const ReferenceFactor<T> rf = CombineFormats<T>::reference_from(e.c[e.ref].q);
    for (std::uint8_t i = 0; i < e.n; ++i) {
        if (i == e.ref || !in_mask(e.group, i)) {
            continue;
        }
        const HalfDifference<T> d = half_difference(e.c[i].q, rf, near2_);
        e.c[i].h = d.h;
        near = static_cast<std::uint8_t>(near | (d.near ? 1U << i : 0U));
    }
    return near;
}

// Step 2's vote: the reference becomes the candidate near the most others
// (the first on a tie), the others far from it are inconsistent; false when
// no two candidates are near each other, or a candidate outside the
// reference's group is near as many others (ambiguous).
template <typename T>
bool Combiner<T>::vote(Epoch& e) const noexcept {
    std::uint8_t near[kMaxHeads] = {};  // candidate-index masks, self excluded
    std::uint8_t count[kMaxHeads] = {};
    for (std::uint8_t i = 0; i < e.n; ++i) {
        for (auto j = static_cast<std::uint8_t>(i + 1); j < e.n; ++j) {
            if (near_each_other(e.c[i].q, e.c[j].q, one_minus_near2_)) {
                near[i] = static_cast<std::uint8_t>(near[i] | 1U << j);
                near[j] = static_cast<std::uint8_t>(near[j] | 1U << i);
                ++count[i];
                ++count[j];
            }
        }
    }
    std::uint8_t best = 0;
    for (std::uint8_t i = 1; i < e.n; ++i) {
        best = count[i] > count[best] ? i : best;
    }
    const auto group = static_cast<std::uint8_t>(near[best] | 1U << best);
    for (std::uint8_t i = 0; i < e.n; ++i) {
        if (!in_mask(group, i) && count[i] == count[best]) {
            return false;  // a group outside as large: ambiguous
        }
    }
    if (count[best] == 0) {
        return false;
    }
    e.ref = best;
    e.inconsistent = static_cast<HeadMask>(e.inconsistent | heads_of(e, static_cast<std::uint8_t>(e.group & ~group)));
    e.group = group;
    return true;
}

// Σ K_{S,i} h_i over the group (s: its heads).
template <typename T>
Vector3<T> Combiner<T>::estimate(const Epoch& e, std::uint8_t group, HeadMask s) const noexcept {
    Accumulator<T> acc = table_[s].start;
    for (std::uint8_t i = 0; i < e.n; ++i) {
        if (i != e.ref && in_mask(group, i)) {  // the reference's difference is zero
            accumulate(acc, table_[s].gain[e.c[i].head], e.c[i].h);
        }
    }
    return result(acc);
}

// The gate of the heads of `group` (s: its heads) about their estimate
// `est`: the mask of those beyond it, and the largest statistic.
template <typename T>
typename Combiner<T>::GateResult Combiner<T>::gate_group(const Epoch& e, std::uint8_t group, HeadMask s,
                                                         const Vector3<T>& est) const noexcept {
    GateResult r{0, {}};
    for (std::uint8_t i = 0; i < e.n; ++i) {
        if (!in_mask(group, i)) {
            continue;
        }
        const GateValue<T> v = gate_value(table_[s].gate[e.c[i].head], residual(e.c[i].h, est));
        r.largest = r.largest < v ? v : r.largest;
        r.failing = static_cast<std::uint8_t>(r.failing | (gate_exceeds(v) ? 1U << i : 0U));
    }
    return r;
}

// Of the failing heads, the one whose removal leaves the rest most
// consistent (the smallest largest statistic of the rest): with one head in
// error, removing a good one leaves it in, and the rest still fails.
template <typename T>
std::uint8_t Combiner<T>::odd_one_out(const Epoch& e, std::uint8_t failing) const noexcept {
    std::uint8_t best = 0xFF;
    GateValue<T> best_value{};
    for (std::uint8_t i = 0; i < e.n; ++i) {
        if (!in_mask(failing, i)) {
            continue;
        }
        const auto rest = static_cast<std::uint8_t>(e.group & ~(1U << i));
        const HeadMask s = heads_of(e, rest);
        const GateValue<T> v = gate_group(e, rest, s, estimate(e, rest, s)).largest;
        if (best == 0xFF || v < best_value) {
            best = i;
            best_value = v;
        }
    }
    return best;
}

// Step 3: the consistency gate, round after round; *est receives the
// group's combined half-angle vector. False: two heads left that disagree
// (no combination).
template <typename T>
bool Combiner<T>::gate(Epoch& e, Vector3<T>* est) const noexcept {
    for (std::uint8_t round = 0; round < kMaxHeads; ++round) {
        const HeadMask s = heads_of(e, e.group);
        *est = estimate(e, e.group, s);
        const std::uint8_t size = detail::kHeadCounts.n[s];
        if (size < 2) {
            return true;
        }
        const GateResult g = gate_group(e, e.group, s, *est);
        if (g.failing == 0U) {
            return true;
        }
        if (size == 2) {
            return false;
        }
        const std::uint8_t odd = odd_one_out(e, g.failing);
        e.group = static_cast<std::uint8_t>(e.group & ~(1U << odd));
        e.inconsistent = static_cast<HeadMask>(e.inconsistent | head_bit(e.c[odd].head));
        if (odd == e.ref) {  // re-form the differences about a head that stays
            for (std::uint8_t i = 0; i < e.n; ++i) {
                if (in_mask(e.group, i)) {
                    e.ref = i;
                    break;
                }
            }
            static_cast<void>(linearise(e));
        }
    }
    return true;  // not reached: each round removes a head
}

// Steps 2 and 3 for the candidates of an epoch (e.n ≥ 1). The usual epoch
// (every head within the gross gate of the first, none beyond the
// consistency gate) is one pass over the candidates for the differences and
// the estimate and one for the gate; the vote and the rounds run only when a
// head is off. False: no combination.
template <typename T>
bool Combiner<T>::combine_group(Epoch& e, Vector3<T>* est) const noexcept {
    constexpr T zero = constant<T>(0.0);
    e.ref = 0;
    e.group = static_cast<std::uint8_t>((1U << e.n) - 1U);
    const ReferenceFactor<T> ref = CombineFormats<T>::reference_from(e.c[0].q);
    e.c[0].h = {zero, zero, zero};
    bool near = true;
    Accumulator<T> acc = table_[e.heads].start;
    for (std::uint8_t i = 1; i < e.n; ++i) {
        const HalfDifference<T> d = half_difference(e.c[i].q, ref, near2_);
        e.c[i].h = d.h;
        near = near && d.near;
        accumulate(acc, table_[e.heads].gain[e.c[i].head], d.h);
    }
    if (near) {
        *est = result(acc);
        bool failing = false;
        for (std::uint8_t i = 0; i < e.n && e.n >= 2; ++i) {
            const Vector3<T> r = residual(e.c[i].h, *est);
            const std::uint8_t h = e.c[i].head;
            failing = failing || (!quick_gate(r, table_[e.heads].quick[h]) &&
                                  gate_exceeds(gate_value(table_[e.heads].gate[h], r)));
        }
        if (!failing) {
            return true;
        }
        return gate(e, est);
    }
    if (!vote(e)) {
        return false;
    }
    static_cast<void>(linearise(e));
    return gate(e, est);
}

// Step 4: the combined attitude and its masks and status.
template <typename T>
CombinedAttitude<T> Combiner<T>::finish(const Epoch& e, bool combined, const Vector3<T>& est) const noexcept {
    constexpr T zero = constant<T>(0.0);
    constexpr T one = constant<T>(1.0);
    CombinedAttitude<T> out{{one, zero, zero, zero}, 0, 0, 0, 0, 0};
    if (combined) {
        out.used = e.group == (1U << e.n) - 1U ? e.heads : heads_of(e, e.group);
        const Quaternion<T>& ref = e.c[e.ref].q;
        // d = (0, est) ⊗ ref is orthogonal to ref, so ‖ref + d‖² − 1 = ‖est‖²
        // (+ ref's own ≤ 1e-6): within Q30's range of renormalized_sum for any
        // est of the accumulator's range (|estᵢ| < 0.24: ε < 0.18, |sᵢ| < 1.5),
        // unit to 2⁻³⁰ for ‖est‖ ≤ 0.033 rad, which the gates keep it far below.
        out.q_crf_icrf = canonical(apply_left(est, ref));
        out.inconsistent = e.inconsistent;
    } else {
        out.inconsistent = static_cast<HeadMask>(e.inconsistent | e.heads);  // no combination: all refused
    }
    out.left_out = static_cast<HeadMask>(e.left_out | (e.heads & ~out.used));
    out.subset = out.used;
    const std::uint8_t used = detail::kHeadCounts.n[out.used];
    out.status = used >= 2 ? combined_status::kTwoOrMoreHeads
                           : (used == 1 ? combined_status::kOneHead : combined_status::kNoHead);
    if (e.left_out_any || out.left_out != 0U) {
        out.status = static_cast<CombinedStatus>(out.status | combined_status::kHeadLeftOut);
    }
    return out;
}

template <typename T>
CombinedAttitude<T> Combiner<T>::combine(const HeadAttitude<T>* heads, std::uint8_t n) const noexcept {
    CombinedAttitude<T> out;  // one object, returned in place
    if (!valid() || !combine_usual(heads, n, &out)) {
        out = combine_general(heads, n);
    }
    return out;
}

template <typename T>
CombinedAttitude<T> Combiner<T>::combine_general(const HeadAttitude<T>* heads, std::uint8_t n) const noexcept {
    constexpr T zero = constant<T>(0.0);
    Epoch e;  // the candidates are written as they are found
    e.n = 0;
    e.ref = 0;
    e.group = 0;
    e.heads = 0;
    e.left_out = 0;
    e.inconsistent = 0;
    e.left_out_any = false;
    if (valid()) {
        select(heads, n, e);
    } else {
        for (std::uint8_t k = 0; k < n; ++k) {
            e.left_out = static_cast<HeadMask>(e.left_out | (heads[k].head < kMaxHeads ? head_bit(heads[k].head) : 0U));
        }
        e.left_out_any = n > 0;
    }
    Vector3<T> est{zero, zero, zero};
    const bool combined = e.n > 0 && combine_group(e, &est);
    return finish(e, combined, est);
}

}  // namespace ascorr::combine

#undef ASCORR_UNROLL_HEADS
