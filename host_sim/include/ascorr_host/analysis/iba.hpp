// ascorr_host/analysis/iba.hpp: inter-boresight angles and their statistics.
//
// Conventions (docs/contract.md, "Statistics"):
//  - the heads of an analysis are a HeadMask (bit h: head h of heads.hpp); its
//    pairs are every two of them in heads.hpp's order, pairs_of() below, the
//    one place that derives them: A–B, A–C, A–D, B–C, B–D, C–D for A–D, the
//    paper's A–B, A–C, B–C for A, B, C. Results are indexed by the position of
//    the pair in that list;
//  - which heads an analysis holds: analysis_heads() below;
//  - the IBA of a pair is the angle between the two boresights (the third rows
//    of R(q_chu_icrf)) at the same epoch, in arcsec;
//  - RMS is about the mean; the smoothed RMS is that of the running mean over
//    a centred window (200 s by default) of the same samples, which removes
//    the short-term star-tracker noise and keeps the thermal signal.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "ascorr/core/heads.hpp"
#include "ascorr/core/quaternion.hpp"
#include "ascorr/core/vector3.hpp"
#include "ascorr/pipeline/epoch_key.hpp"

namespace ascorr::host {

// A set of heads is the core's HeadMask (bit h: head h; heads.hpp), with its
// head_bit, has_head and head_count; the analyses' own sets follow.
inline constexpr HeadMask kAllHeads = static_cast<HeadMask>((1U << kMaxHeads) - 1U);
// A, B and C, the paper's heads: always in an analysis, so that a missing one is
// named (no rows, no clean rows) rather than silently left out.
inline constexpr HeadMask kPaperHeads = 0x7U;
static_assert(kMaxHeads >= 3, "the paper's three heads");

// The heads an analysis holds: the paper's A, B, C, every head with rows in
// the data (with_rows), and the heads it needs besides (e.g. frame F's).
constexpr HeadMask analysis_heads(HeadMask with_rows, HeadMask needed = 0U) noexcept {
    return static_cast<HeadMask>((kPaperHeads | with_rows | needed) & kAllHeads);
}

inline constexpr std::size_t kMaxPairs = std::size_t{kMaxHeads} * (kMaxHeads - 1U) / 2U;

struct HeadPair {
    std::uint8_t first = 0;  // first < second
    std::uint8_t second = 0;
    char name[4] = {};  // "A-B"
};

// The heads of a set in heads.hpp's order, and its pairs.
struct HeadList {
    std::array<std::uint8_t, kMaxHeads> head{};
    std::size_t count = 0;
};
struct PairList {
    std::array<HeadPair, kMaxPairs> pair{};
    std::size_t count = 0;
};

constexpr HeadList heads_of(HeadMask s) noexcept {
    HeadList l{};
    for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
        if (has_head(s, h)) {
            l.head[l.count++] = h;
        }
    }
    return l;
}

// Every two heads of s, in heads.hpp's order (the one place pairs are derived).
constexpr PairList pairs_of(HeadMask s) noexcept {
    PairList l{};
    for (std::uint8_t i = 0; i < kMaxHeads; ++i) {
        for (std::uint8_t j = i + 1U; j < kMaxHeads; ++j) {
            if (has_head(s, i) && has_head(s, j)) {
                HeadPair& p = l.pair[l.count++];
                p.first = i;
                p.second = j;
                p.name[0] = kHeadLetters[i];
                p.name[1] = '-';
                p.name[2] = kHeadLetters[j];
                p.name[3] = '\0';
            }
        }
    }
    return l;
}

inline constexpr PairList kPaperPairs = pairs_of(kPaperHeads);  // A-B, A-C, B-C

// The pair's name ("A-B") as a string.
std::string pair_name(const HeadPair& p);

// The letters of the heads of s, "ABD"; and in words, "A, B and D" (last: " or ": "A, B or D").
std::string head_letters(HeadMask s);
std::string head_words(HeadMask s, const char* last = " and ");
// The set named by letters ("ABCD": each a head of heads.hpp, in its order, none
// twice); std::nullopt for anything else.
std::optional<HeadMask> parse_head_letters(const std::string& letters);

inline constexpr double kSmoothingWindowS = 200.0;

// Angle between two unit vectors in arcsec, precise for any angle.
double angle_arcsec(const Vector3<double>& a, const Vector3<double>& b) noexcept;

// Epoch key: t rounded to the millisecond, as rows are matched. Only for
// |t| < kMaxEpochTimeS (the key is a 64-bit count of milliseconds); a row
// beyond it (1e300 s: far outside any ephemeris) belongs to no epoch. The
// firmware's, the one rule of every grouper (ascorr/pipeline/epoch_key.hpp).
using pipeline::epoch_key;
using pipeline::kMaxEpochTimeS;

struct Rms {
    double rms = 0.0;           // about the mean, arcsec
    double rms_smoothed = 0.0;  // of the running mean over the window
    std::size_t n = 0;
};

// RMS of v about its mean, and after a running mean of width window_s
// (samples with |t_j − t_i| ≤ window_s/2). t must be non-decreasing.
Rms rms_about_mean(const std::vector<double>& t, const std::vector<double>& v, double window_s = kSmoothingWindowS);

}  // namespace ascorr::host
