// ascorr_host/analysis/fit_sun.hpp: `ascorr fit --sun-term auto` (the default):
// the thermal model's Sun term (ascorr/core/sun_term.hpp), fitted inside the
// orbit and taken when held-out data support it (issue 40, docs/ground.md,
// "The Sun term").
//
// The polynomial is fitted on orbit averages, which average the Sun's
// direction in the orbital plane away; the Sun term is fitted on what varies
// inside the orbit, after the polynomial (with its lag) has corrected each
// epoch. For each epoch with every fitted head, each head's rotation e_h
// relative to frame F of the corrected attitudes (head axes, arcsec; the
// model's α, β, γ: calib/head_rotation.hpp) and s_h, the Sun's direction in
// the corrected head's frame:
//     e_h(t) = S_h·s_h(t) + N_h·g(t) + b_h(orbit) + noise,
// S_h the head's 3 × 3 coefficients, g(t) F's own rotation at the epoch (a
// nuisance, as per orbit in the polynomial's fit, eliminated by projecting
// each epoch's equations orthogonally to the N_h), b_h a constant per orbit
// and head (eliminated by taking each orbit's mean out of e and s: the orbit
// means are the polynomial's). The normal equations are formed from each
// orbit's sums of s·sᵀ and e·sᵀ (Kronecker structure of the projection), so
// the epochs are read once and not kept. The solution is the pseudo-inverse's
// over the eigen-directions above kSunRankTolerance of the largest: three of
// each head's nine do not vary inside the orbit (the orbit normal's component
// of s, constant over an orbit on a nadir-pointing spacecraft), and of the
// rotation common to every head, which no IBA sees, six more are in the
// plane that does (3H + 6 unseen of 9H, rank 6H − 6: 12 of 27 for three
// heads); the common rotation is then fixed by the fit's rule
// (calib/common_rotation.hpp's three: the smallest coefficients, the full head
// set's combined attitude unmoved by the term for every Sun direction, or a
// head rigid to the bench, its coefficients exactly 0). The term's orbit mean
// along the orbit normal is thereby left to the temperatures' polynomial.
// Selection: the polynomial fitted before t_split (the selection report's, the
// written model's terms, or the linear ones when the part before t_split
// refuses those) is scored on the epochs after it, without and with the Sun
// term fitted on the same epochs before t_split, by the held-out IBA RMS (mean
// over the pairs; fit_terms.hpp's corrected_iba_rms, which evaluates the
// model's Sun term; both sides on the epochs where the Sun's direction is
// known). The term fitted on the whole period is taken when it lowers that
// RMS by more than kSunSelectionMargin and its every axis is within the
// core's domain (sun_axis_problem); otherwise the model is the polynomial's,
// byte for byte.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "ascorr_host/analysis/fit_terms.hpp"
#include "ascorr_host/formats/model_csv.hpp"

namespace ascorr::host {

// The term is taken when the held-out IBA RMS (mean over the pairs) falls by
// more than this fraction, the lag's margin (fit_lag.hpp): 0.3 % of the mean
// square. On the static benches its gain was below 0.01 %.
inline constexpr double kSunSelectionMargin = 0.0015;
// Eigen-directions of the normal equations below this fraction of the
// largest eigenvalue are left out (the pseudo-inverse's rank).
inline constexpr double kSunRankTolerance = 1e-3;

// --sun-term: auto (fitted and taken when supported), none.
enum class SunTermChoice : std::uint8_t { kAuto, kNone };

using SunCoefficients = std::array<std::array<std::array<double, kSunComponents>, kModelAxes>, kMaxHeads>;

struct SunFit {
    SunCoefficients sun{};  // arcsec, by head (the fit's heads)
    std::size_t epochs = 0;
    std::size_t orbits = 0;
    int rank = 0;  // eigen-directions kept, of 9 per head
};

// The Sun term fitted on the epochs with t in [from, to) corrected by the
// polynomial m (its Sun term, if any, is ignored); epochs sorted by t.
SunFit fit_sun_term(const std::vector<FitEpoch>& epochs, double from, double to, const ModelFile& m, HeadMask heads,
                    const std::array<std::uint8_t, 2>& frame_heads, double period, const CommonRotation& rule);

struct SunSelection {
    bool decided = false;  // false: nothing held out, or a pair without held-out epochs
    bool taken = false;
    double none_rms = 0.0;  // held-out IBA RMS, mean over the pairs, the polynomial alone (arcsec)
    double sun_rms = 0.0;   // with the Sun term fitted before t_split
    SunFit fit;             // the whole period's, written when taken
    std::string verdict;    // one sentence: taken or not, and why
};

struct SunSearchInput {
    const std::vector<FitEpoch>* epochs = nullptr;  // sorted by t
    const ModelFile* model = nullptr;               // the polynomial written (the whole period)
    const ModelFile* model_before_split = nullptr;  // the polynomial fitted before t_split; nullptr: none
    std::string no_split;                           // then why not, for the verdict
    HeadMask heads = 0U;
    std::array<std::uint8_t, 2> frame_heads{};
    double period = 0.0;
    double t_split = 0.0;
    CommonRotation rule{};
};

SunSelection select_sun_term(const SunSearchInput& in);

}  // namespace ascorr::host
