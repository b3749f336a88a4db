// ascorr_host/analysis/fit_sun.hpp: `ascorr fit --sun-term auto` (the default):
// the thermal model's Sun term (ascorr/core/sun_term.hpp), fitted inside the
// orbit and taken when held-out data support it (issue 40, docs/ground.md,
// "The Sun term").
//
// The least squares inside the orbit are calib/sun_moments.hpp's, shared with
// the self-calibration's learner (calib/sun_learner.hpp): after the
// polynomial (with its lag) has corrected each epoch, each head's rotation
// relative to frame F against the Sun's direction in the head's frame, about
// each orbit's mean and with F's own rotation projected out, every orbit
// kept (no forgetting); the common rotation, which no IBA sees, fixed by the
// fit's rule (CommonRotation: the smallest coefficients, the full head set's
// combined attitude unmoved by the term for every Sun direction, or a head
// rigid to the bench, its coefficients exactly 0).
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

#include "ascorr/calib/sun_moments.hpp"
#include "ascorr_host/analysis/fit_terms.hpp"
#include "ascorr_host/formats/model_csv.hpp"

namespace ascorr::host {

// The term is taken when the held-out IBA RMS (mean over the pairs) falls by
// more than calib::kSunSelectionMargin (the lag's margin, fit_lag.hpp).
using calib::kSunSelectionMargin;

// --sun-term: auto (fitted and taken when supported), none.
enum class SunTermChoice : std::uint8_t { kAuto, kNone };

using SunCoefficients = std::array<std::array<std::array<double, kSunComponents>, kModelAxes>, kMaxHeads>;

// A fit's coefficients as a model's `sun` (arcsec): those of `heads` it
// fitted, 0 elsewhere and where it was not solved.
SunCoefficients sun_coefficients_of(const calib::SunTermFit& f, HeadMask heads);

// The Sun term fitted on the epochs with t in [from, to) corrected by the
// polynomial m (its Sun term, if any, is ignored); epochs sorted by t.
calib::SunTermFit fit_sun_term(const std::vector<FitEpoch>& epochs, double from, double to, const ModelFile& m,
                               HeadMask heads, const std::array<std::uint8_t, 2>& frame_heads, double period,
                               const CommonRotation& rule);

struct SunSelection {
    bool decided = false;  // false: nothing held out, or a pair without held-out epochs
    bool taken = false;
    double none_rms = 0.0;  // held-out IBA RMS, mean over the pairs, the polynomial alone (arcsec)
    double sun_rms = 0.0;   // with the Sun term fitted before t_split
    calib::SunTermFit fit;  // the whole period's, written when taken
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
