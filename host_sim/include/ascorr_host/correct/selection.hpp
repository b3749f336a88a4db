// ascorr_host/correct/selection.hpp: the rows a thermal-model estimate learns
// from: the ground fit's selection (`ascorr fit`), which the on-board
// estimator's run over a file (self_calibration.hpp) applies too.
//
// A row is selected when it is clean as docs/contract.md's Statistics says
// (flags 0, confidence <= 5 arcsec, the three temperatures and the velocity
// present); the caller adds the last condition, that the core applied the
// aberration stage (Drop::kRejected otherwise).
#pragma once

#include <cstddef>

#include "ascorr/combine/usable.hpp"
#include "ascorr_host/formats/solutions_csv.hpp"

namespace ascorr::host {

// The confidence test of a clean row, one rule for `stats`, `plot`, `fit`,
// self-calibration and the Python module (docs/contract.md, section 5): the
// row's confidence is a number <= 5 arcsec. A confidence that is not given (no
// column, an empty field, `nan`; NaN or None in Python, where NaN is "not
// available" as in read_solutions()) is not one: such a row is not clean.
inline bool confidence_clean(const SolutionRecord& rec) noexcept {
    return rec.confidence_present && rec.confidence <= combine::kMaxCleanConfidenceArcsec;
}

// Why a row is left out of the fit (the first reason that applies).
enum class Drop { kNone, kHighRate, kBrightObject, kInvalid, kConfidence, kTemperature, kVelocity, kRejected };
inline constexpr std::size_t kDropKinds = 8;
Drop fit_selection(const SolutionRecord& rec) noexcept;
const char* drop_name(Drop d) noexcept;

// The clean epochs of docs/contract.md's Statistics, which self-calibration
// learns from: the fit's selection (confidence_clean included) and no flag bit
// at all (what the camera head says of its solution: on board it is known with
// the solution, over the link it is SOLUTION_IN's kCalibClean).
inline bool calibration_clean(const SolutionRecord& rec) noexcept {
    return fit_selection(rec) == Drop::kNone && rec.flags == 0;
}

}  // namespace ascorr::host
