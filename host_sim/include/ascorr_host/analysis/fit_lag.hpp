// ascorr_host/analysis/fit_lag.hpp: `ascorr fit --lag auto` (the default): the
// bench's lag per head, chosen on held-out data (issue 40, "The bench inside
// the orbit", docs/ground.md).
//
// A lag changes what the terms take (lagged_temperatures.hpp), not how many
// coefficients there are: one number per head, which shows inside the orbit.
// Each candidate is scored as the quadratic terms are (fit_terms.hpp,
// select_terms): the linear model of the candidate's lagged temperatures
// (whatever --terms: the lag is the bench's, and quadratic terms extrapolate
// into the held-out part worse) fitted on the orbits before t_split, its IBA
// RMS on the epochs after it (held out), mean over the pairs.
// The search: no lag; one τ for every head on a grid 300·2^(k/3) s (300 …
// 6048 s, a third of an octave apart), refined by golden section between the
// best point's neighbours; then each head in turn on the grid within an
// octave of it, the others held. A head departs from the common τ (to its
// own, refined, or to none) only when that lowers the held-out RMS by more
// than kLagSelectionMargin: on a short period the heads' own minima scatter
// with the noise (60 days: 2× the residual of the common τ). The lags found
// are taken when together they lower the held-out RMS by more than
// kLagSelectionMargin; otherwise no head lags and the model written is the
// fit's without a lag, byte for byte.
#pragma once

#include <array>
#include <cstddef>
#include <string>
#include <vector>

#include "ascorr_host/analysis/fit_terms.hpp"
#include "ascorr_host/correct/lagged_temperatures.hpp"

namespace ascorr::host {

// The lags are taken when the held-out IBA RMS (mean over the pairs) falls by
// more than this fraction: 0.3 % of the mean square, (0.12″)² of a 2.1″ noise
// floor per pair. A lag adds no coefficient, but the held-out part is the end
// of the period, where a model extrapolates: on static benches of 40 days
// (seeds 1, 2, 4, 5) a lag of one head lowered it by up to 0.087 % there (and
// by 1.3 % with quadratic terms, hence the linear search below), while the
// benches that lag by 900 or 1800 s gain 0.25 … 0.55 % (60 … 150 days).
inline constexpr double kLagSelectionMargin = 0.0015;

struct LagSelection {
    bool decided = false;                        // false: no held-out part, or a pair without held-out epochs
    std::array<double, kMaxHeads> lag_s{};       // taken (all 0: none), s, whole seconds
    std::array<double, kMaxHeads> best_lag_s{};  // taken: lag_s; otherwise the candidate that scored best
    double none_rms = 0.0;                       // held-out IBA RMS, mean over the pairs, without a lag (arcsec)
    double best_rms = 0.0;                       // with best_lag_s
    std::size_t trials = 0;                      // candidates scored
    std::string verdict;                         // one sentence: what is taken, and why
};

// What the search needs of the fit's pass without a lag.
struct LagSearchInput {
    const std::vector<OrbitAverage>* orbits = nullptr;  // the pass's orbit averages (their e; x is recomputed)
    double period = 0.0;                                // s, bins the epochs into those orbits
    std::vector<FitEpoch>* epochs = nullptr;            // sorted by t; their temperatures are lagged and restored
    const std::vector<LagReading>* readings = nullptr;  // every row of the fit's heads, sorted by lag_order
    HeadOrientations n_ref{};
    HeadMask heads = 0U;
    double t_split = 0.0;  // held out: t ≥ t_split (select_terms')
    double max_condition = 0.0;
    double min_range_c = 0.0;
    CommonRotation rule{};
};

LagSelection select_lags(const LagSearchInput& in);

}  // namespace ascorr::host
