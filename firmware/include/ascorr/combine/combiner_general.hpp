// ascorr/combine/combiner_general.hpp: the combiner's general path (steps 1 to 4 of combiner.hpp).
// Part of combiner.hpp (the overview, the conventions and the order of the
// steps are there); include that one.
#pragma once

#include "combiner_class.hpp"

namespace ascorr::combine {

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

// Candidate r as the vote's reference: its group (r and the candidates near
// it), the others inconsistent.
template <typename T>
void Combiner<T>::refer_to(Epoch& e, std::uint8_t r, std::uint8_t near_r) const noexcept {
    const auto group = static_cast<std::uint8_t>(near_r | 1U << r);
    e.ref = r;
    e.inconsistent = static_cast<HeadMask>(e.inconsistent | heads_of(e, static_cast<std::uint8_t>(e.group & ~group)));
    e.group = group;
}

// How many heads the consistency gate keeps with candidate r as the
// reference (0: none, no combination).
template <typename T>
std::uint8_t Combiner<T>::kept_with(const Epoch& e, std::uint8_t r, std::uint8_t near_r) const noexcept {
    Epoch trial = e;
    refer_to(trial, r, near_r);
    static_cast<void>(linearise(trial));
    Vector3<T> est{};
    return gate(trial, &est) ? detail::kHeadCounts.n[heads_of(trial, trial.group)] : std::uint8_t{0};
}

// The vote's reference: `best`, unless a candidate outside its group (and
// every rival's before it) is near as many others; then the candidate whose
// group the consistency gate keeps more heads of, or e.n (none) when no group
// keeps any or two keep as many.
template <typename T>
std::uint8_t Combiner<T>::decide(const Epoch& e, const std::uint8_t (&near)[kMaxHeads],
                                 const std::uint8_t (&count)[kMaxHeads], std::uint8_t best) const noexcept {
    auto tried = static_cast<std::uint8_t>(near[best] | 1U << best);  // each group tried once
    std::uint8_t chosen = best;
    std::uint8_t kept = 0;
    bool rival = false;
    bool tie = false;
    for (std::uint8_t i = 0; i < e.n; ++i) {
        if (in_mask(tried, i) || count[i] != count[best]) {
            continue;
        }
        if (!rival) {
            kept = kept_with(e, best, near[best]);
            rival = true;
        }
        tried = static_cast<std::uint8_t>(tried | near[i] | 1U << i);
        const std::uint8_t k = kept_with(e, i, near[i]);
        tie = k == kept || (k < kept && tie);
        chosen = k > kept ? i : chosen;
        kept = k > kept ? k : kept;
    }
    return rival && (kept == 0 || tie) ? e.n : chosen;
}

// Step 2's vote: the reference becomes the candidate near the most others
// (the first on a tie), the others far from it are inconsistent; false when
// no two candidates are near each other. When a candidate outside the
// reference's group is near as many others (a rival group as large), the
// consistency gate decides: the group it keeps more heads of; false when
// none keeps any, or two keep as many (e.g. two consistent pairs of four
// heads: ambiguous).
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
    if (count[best] == 0) {
        return false;
    }
    const std::uint8_t chosen = decide(e, near, count, best);
    if (chosen >= e.n) {
        return false;  // ambiguous, or no group consistent
    }
    refer_to(e, chosen, near[chosen]);
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
        // Any est of the accumulator's range is within apply_left's (kernels_q30.hpp).
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
