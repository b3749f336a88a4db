// ascorr_hal/voting.hpp: one temperature from a triplet (or pair, or single).
//
// Conventions:
//  - Swarm's boom thermistors come in triplets reading almost the same
//    temperature: T2 = THT00029 with THT00057/87, T3 = THT00032 with
//    THT00060/90 (Herceg et al. 2017).
//  - Only valid members vote. Three valid: the value is the median; a member
//    farther than `tolerance` from it is flagged kOutvoted. Two valid: their
//    mean if they agree within tolerance, otherwise neither is trusted. One
//    valid: its value.
//  - The voted value is valid when at least `quorum` valid members agree
//    (the median and those within tolerance of it); otherwise it carries
//    kNoQuorum plus the union of its members' faults, so the reason (kStale,
//    kOpen, …) reaches the caller. A lone configured channel votes with
//    itself (quorum 1 is implied).
//  - Fixed sizes, no heap, no exceptions.
#pragma once

#include <cmath>
#include <cstdint>
#include <limits>

#include "channel_check.hpp"
#include "faults.hpp"

namespace ascorr::hal {

inline constexpr std::uint8_t kMaxVoters = 3;

template <typename T>
struct VotedTemperature {
    T celsius;              // NaN (TemperatureMath<T>::none()) when not valid
    FaultBits faults;       // 0: valid
    std::uint64_t t_us;     // oldest sample used
    std::uint8_t members;   // configured members
    std::uint8_t agreeing;  // valid members that agree with the value
    bool valid() const noexcept { return faults == 0U; }
};

namespace detail {

// Three valid members (indices v[0..2]): the median is the value; each outer
// member within tolerance of it agrees, the others are outvoted.
template <typename T>
void vote_three(ChannelReading<T>* m, const std::uint8_t* v, T tolerance, VotedTemperature<T>& out) noexcept {
    using Math = TemperatureMath<T>;
    // Sort the three indices by value.
    std::uint8_t a = v[0], b = v[1], c = v[2], t = 0;
    if (Math::less(m[b].celsius, m[a].celsius)) {
        t = a;
        a = b;
        b = t;
    }
    if (Math::less(m[c].celsius, m[b].celsius)) {
        t = b;
        b = c;
        c = t;
    }
    if (Math::less(m[b].celsius, m[a].celsius)) {
        t = a;
        a = b;
        b = t;
    }
    const T med = m[b].celsius;
    out.celsius = med;
    out.agreeing = 1U;
    out.t_us = m[b].t_us;
    const std::uint8_t outer[2] = {a, c};
    for (const std::uint8_t k : outer) {
        if (Math::within(m[k].celsius, med, tolerance)) {
            ++out.agreeing;
            out.t_us = m[k].t_us < out.t_us ? m[k].t_us : out.t_us;
        } else {
            m[k].faults |= fault::kOutvoted;
        }
    }
}

// Two valid members: their mean when they agree, no value otherwise.
template <typename T>
void vote_two(const ChannelReading<T>& x, const ChannelReading<T>& y, T tolerance, VotedTemperature<T>& out) noexcept {
    using Math = TemperatureMath<T>;
    if (Math::within(x.celsius, y.celsius, tolerance)) {
        out.celsius = Math::mean(x.celsius, y.celsius);
        out.agreeing = 2U;
        out.t_us = x.t_us < y.t_us ? x.t_us : y.t_us;
    }
}

}  // namespace detail

// Votes `n` (≤ kMaxVoters) readings; sets kOutvoted on disagreeing members.
// Out of line: split into the helpers above, GCC would inline it into the
// flight loop's temperature update (+960 B of flash on each target).
template <typename T>
[[gnu::noinline]] VotedTemperature<T> vote(ChannelReading<T>* m, std::uint8_t n, T tolerance,
                                           std::uint8_t quorum) noexcept {
    using Math = TemperatureMath<T>;
    const T nan = Math::none();
    VotedTemperature<T> out{nan, 0U, 0U, n, 0U};
    std::uint8_t valid[kMaxVoters] = {};
    std::uint8_t nv = 0;
    FaultBits all = 0U;
    for (std::uint8_t i = 0; i < n && i < kMaxVoters; ++i) {
        all |= m[i].faults;
        if (m[i].valid()) {
            valid[nv++] = i;
        }
    }
    const std::uint8_t need = n <= 1U ? 1U : (quorum == 0U ? 1U : quorum);
    if (nv == 3U) {
        detail::vote_three(m, valid, tolerance, out);
    } else if (nv == 2U) {
        detail::vote_two(m[valid[0]], m[valid[1]], tolerance, out);
    } else if (nv == 1U) {
        out.celsius = m[valid[0]].celsius;
        out.agreeing = 1U;
        out.t_us = m[valid[0]].t_us;
    }
    if (n == 0U) {
        out.faults = fault::kNoData;
    } else if (out.agreeing < need || out.agreeing == 0U) {
        out.faults = n == 1U ? all : static_cast<FaultBits>(fault::kNoQuorum | all);
        out.celsius = nan;
    }
    return out;
}

}  // namespace ascorr::hal
