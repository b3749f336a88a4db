// ascorr/combine/combiner_class.hpp: the combiner's types, its class and its per-epoch tables.
// Part of combiner.hpp (the overview, the conventions and the order of the
// steps are there); include that one.
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

// The gross gate's angle (rad): beyond it the small-angle differences lose
// their bound (kernels.hpp) and a head is judged by vote (step 2 of combiner.hpp).
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
    void refer_to(Epoch& e, std::uint8_t r, std::uint8_t near_r) const noexcept;
    std::uint8_t kept_with(const Epoch& e, std::uint8_t r, std::uint8_t near_r) const noexcept;
    std::uint8_t decide(const Epoch& e, const std::uint8_t (&near)[kMaxHeads], const std::uint8_t (&count)[kMaxHeads],
                        std::uint8_t best) const noexcept;
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

}  // namespace ascorr::combine
