// ascorr/combine/usable.hpp: which corrected solution the combination may
// average in (the contract's "Combined attitude": a usable head).
//
// A solution is usable when it is clean (the camera head's own selection:
// flags 0 and confidence ≤ 5″, as in Statistics) and its correction
// neither rejected it (16) nor skipped a stage: no velocity (4), no
// temperatures (8), a model angle out of range (128), no model for the head
// (256). A head corrected otherwise would disagree with the others by the
// stage it lacks (up to 25″ of aberration, the bench's thermal deformation),
// so it is left out (bit 4 of the combined status), never averaged in. One
// rule for the flight loop, the link server (epoch pipeline) and the ground
// (`ascorr combine`, `correct --combined`).
#pragma once

#include "../core/status.hpp"

namespace ascorr::combine {

// A stage the run asked for and could not apply (4, 8, 128, 256).
inline constexpr StatusBits kStageSkipped =
    status::kNoVelocity | status::kNoTemperature | status::kThermalOutOfRange | status::kNoModelForHead;
// The corrected solution's status bits that leave it out.
inline constexpr StatusBits kNotUsable = status::kRejected | kStageSkipped;
// A clean row's largest confidence (arcsec): the contract's Statistics,
// which the ground's readers of files apply (on board the camera head says
// whether its solution is clean).
inline constexpr double kMaxCleanConfidenceArcsec = 5.0;

constexpr bool usable_for_combination(StatusBits corrected, bool clean) noexcept {
    return clean && (corrected & kNotUsable) == 0U;
}

}  // namespace ascorr::combine
