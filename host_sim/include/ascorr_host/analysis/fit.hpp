// ascorr_host/analysis/fit.hpp: calibration of the thermal model (`ascorr fit`).
//
// The paper's procedure (Herceg et al. 2017, section 4), in order:
//  1. selection: rows with flags high-rate (1), bright object (2), invalid (4),
//     confidence > 5, a temperature or the velocity missing are dropped;
//  2. aberration correction by the core;
//  3. at each epoch with all the fit's heads selected, the frame F of two of
//     them (FitOptions::frame_heads, --frame-heads; A and C by default, the
//     paper's eqs. 1–3 with the first in A's role, the second in C's) and
//     each head's rotation relative to it, as the small rotation vector e_i
//     (head axes, arcsec) with R_i·R_Fᵀ = exp([e_i×])·N_i,
//     N_i the head's orientation in F at the first such epoch;
//  4. averages of e_i and of the temperatures over each orbit (the same
//     epochs on both sides, so the linear model holds for the averages);
//  5. least squares by SVD (Eigen BDCSVD, columns centred, scaled, then
//     normalised: fit_terms.hpp) of the 3 orbit-averaged angles per head
//     against each head's [1, T1, T2−T1, T3−T1] (T1 = the head's T_CHU, T2 = T029,
//     T3 = T032), with --terms quadratic also their squares, all heads jointly;
//  6. the model-selection report (fit_terms.hpp): linear and quadratic models
//     fitted on the period without its held-out end (--holdout), their
//     residuals, condition numbers and IBA RMS in and after that part, and
//     which model the data support. The model written is fitted on the whole
//     period with the terms asked for.
// The correction angles (α, β, γ) are e_i: R3(γ)R2(β)R1(α) ≈ I − [e×].
//
// The fit's heads: FitOptions::heads when given (--heads: a mission without
// one of A, B, C; a subset of the heads), else A, B, C, every head with rows
// in the modelling period and F's two (iba.hpp, analysis_heads), up to
// kMaxHeads. The model file has a row per axis of each of them.
//
// What is fitted, precisely, told for three heads (with N: 3·N equations per
// orbit, 12·N linear coefficients, the same 9 unobservable directions). F
// moves with the A and C boresights, hence with their temperatures, and this
// motion shows in every head's e_i alike (as N_i·g in head axes). A per-head
// fit would push A's and C's temperature
// response into B's model, where it does not fit; so F's rotation g_k in each
// orbit is a nuisance parameter, eliminated by projecting each orbit's 9
// equations orthogonally to it. The data then fix the 36 coefficients up to a
// rotation common to all heads that is linear in T029 and T032 (the only
// regressors all heads share): 9 directions that star trackers cannot see and
// that change no IBA. Which of those equivalent models is written is a rule
// (FitOptions::common_rotation, calib/common_rotation.hpp): with the
// mountings, the one that moves the full head set's combined attitude least
// over the orbits of the period (do no harm); without them, the one whose
// corrections are smallest. c0 refers to the mean orientations over the
// period: the absolute mounting is not observable either.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "ascorr_host/analysis/epochs.hpp"
#include "ascorr_host/analysis/fit_lag.hpp"
#include "ascorr_host/analysis/fit_sun.hpp"
#include "ascorr_host/analysis/fit_terms.hpp"
#include "ascorr_host/correct/selection.hpp"
#include "ascorr_host/formats/atomic_file.hpp"
#include "ascorr_host/formats/model_csv.hpp"
#include "ascorr_host/formats/mountings_csv.hpp"
#include "ascorr_host/formats/solutions_csv.hpp"

namespace ascorr::host {

inline constexpr double kDefaultMinSpanDays = 267.0;  // one thermal period of Swarm Alpha
inline constexpr std::size_t kDefaultMinOrbits = 100;
inline constexpr double kDefaultMaxCondition = 1e6;                     // of the column-scaled design
inline constexpr std::array<std::uint8_t, 2> kDefaultFrameHeads{0, 2};  // A and C, the paper's

// Frame F's heads as the command line writes them ("AC"), and as a set.
inline std::string frame_heads_text(const std::array<std::uint8_t, 2>& f) {
    return {head_letter(f[0]), head_letter(f[1])};
}
constexpr HeadMask frame_set(const std::array<std::uint8_t, 2>& f) noexcept {
    return head_bit(f[0]) | head_bit(f[1]);
}

struct FitOptions {
    std::string in;
    std::string out;
    std::optional<double> from;
    std::optional<double> to;
    double min_span_days = kDefaultMinSpanDays;
    std::size_t min_orbits = kDefaultMinOrbits;
    double max_condition = kDefaultMaxCondition;
    std::optional<double> orbit_period_s;  // default: 2πμ/|v|³ of the first selected row (circular orbit)
    Terms terms = Terms::kLinear;
    double holdout = kDefaultHoldout;  // fraction of the period (its end) held out for the selection report
    double min_temperature_range_c = kDefaultMinTemperatureRange;  // of each regressor, for quadratic terms
    bool selection_report = true;  // false: skip the model-selection report (two more fits), e.g. in tests
    // The heads of frame F (eqs. 1–3): the first in head A's role, the second
    // in C's; two different heads (--frame-heads, default AC).
    std::array<std::uint8_t, 2> frame_heads = kDefaultFrameHeads;
    // The fit's heads (--heads), two or more, F's among them; rows of other
    // heads are left out. Default: A, B, C, F's two and every head with rows
    // in the modelling period (analysis_heads).
    std::optional<HeadMask> heads;
    // The mountings (--mountings): the combination's weights for the rule
    // `combined`; every head fitted must be in them, with its sigmas.
    std::optional<MountingsFile> mountings;
    std::string mountings_name;  // where they were read, for messages
    // The rule for the common rotation (--common-rotation): default
    // `combined` with mountings, `smallest` without. Its `motion` is filled
    // from the mountings by the fit.
    std::optional<CommonRotation> common_rotation;
    // The bench's lag per head in s (--lag): the fit's terms take each head's
    // temperatures through it, as `correct` does with the model written (its
    // lag_s; lagged_temperatures.hpp); 0 none. nullopt (--lag auto, the
    // default): chosen on the held-out part (fit_lag.hpp), none without one
    // (holdout 0 or no selection report).
    std::optional<std::array<double, kMaxHeads>> lag_s;
    // --sun-term: auto (the default) fits the Sun term inside the orbit and
    // takes it when the held-out part supports it (fit_sun.hpp; never without
    // one: holdout 0 or no selection report); none: no Sun term.
    SunTermChoice sun_term = SunTermChoice::kAuto;
};

// --lag's text: "auto" (nullopt), "TAU" (every head) or "X:TAU,Y:TAU" (heads
// named, the others 0), each TAU 0 or within the lag's range
// (lag_range_text). Throws FitRefused naming what is wrong.
std::optional<std::array<double, kMaxHeads>> parse_lags(std::string_view text);

// The rule a fit with these options uses (the default above); the rule
// `combined` without mountings is refused (FitRefused).
CommonRotation common_rotation_rule(const FitOptions& opt);

// Three heads, linear: 3 heads × 3 axes × (c0, c1, c2, c3), 36; quadratic: 63.
inline constexpr int kUnknowns = 3 * kModelAxes * kLinearModelTerms;
inline constexpr int kGaugeDims = 9;  // a common rotation linear in T029, T032

struct FitReport {
    double t_first = 0.0;
    double t_last = 0.0;
    double orbit_period_s = 0.0;
    std::size_t rows = 0;              // of the heads fitted, in [from, to]
    std::size_t rows_other_heads = 0;  // of other heads in [from, to], left out (FitOptions::heads)
    std::array<std::size_t, kDropKinds> dropped{};
    HeadMask heads = kPaperHeads;                                  // the heads fitted
    std::array<std::uint8_t, 2> frame_heads = kDefaultFrameHeads;  // F's
    std::size_t epochs = 0;                                        // with all of them selected
    std::size_t orbits_used = 0;
    std::size_t orbits_left_out = 0;
    Terms terms = Terms::kLinear;
    std::vector<double> singular_values;    // of the joint design with unit-norm columns, descending
    double condition = 0.0;                 // largest / smallest observable singular value
    std::array<HeadFit, kMaxHeads> head{};  // by head index
    ModelFile model;
    CommonRotation common_rotation;  // the rule that fixed the 9 unobservable directions
    TermsFit fit;                    // the written model's fit: centring, rank
    Selection selection;             // the model-selection report
    LagSelection lag;                // --lag auto's choice (verdict empty with a --lag given)
    SunSelection sun;                // --sun-term auto's choice (verdict empty with none)
};

// Refusal of the data given (too short, too few orbits, rank-deficient, for
// quadratic terms a temperature range too small).
class FitRefused : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

// Fits and writes opt.out (atomically). Throws FitRefused, InputError.
FitReport fit_model(const FitOptions& opt);
// The same into outputs["--out"] (atomic_file.hpp's OutputSet, committed by the caller).
FitReport fit_model(const FitOptions& opt, OutputSet& outputs);
// The same on rows from elsewhere (opt.in names them in messages); writes nothing.
FitReport fit_model(const FitOptions& opt, const RowSource& rows);

std::string describe(const FitReport& r);

}  // namespace ascorr::host
