// ascorr/combine/combiner_usual.hpp: the usual epoch of the combiner in one pass.
// Part of combiner.hpp (the overview, the conventions and the order of the
// steps are there); include that one.
#pragma once

#include "combiner_class.hpp"

namespace ascorr::combine {

// combine_usual_n's loops run N ≤ kMaxHeads times: unrolled, so that the
// candidates stay in registers (GCC's -O2 keeps them as loops otherwise).
#if defined(__clang__)
#define ASCORR_UNROLL_HEADS _Pragma("unroll")
#else
#define ASCORR_UNROLL_HEADS _Pragma("GCC unroll 4")
#endif

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

#undef ASCORR_UNROLL_HEADS

}  // namespace ascorr::combine
