// ascorr/combine/usable.hpp: which corrected solutions of an epoch the
// combination may average in, and why each other one is left out (the
// contract's "Combined attitude": a usable head; bit 4 of the combined status).
//
// One rule, in two steps, for every caller (docs/contract.md, "Combined
// attitude"):
//   1. a row alone (left_out_alone): it is in an epoch (|t| within the
//      millisecond key); it is a head of the mountings; its correction did
//      not reject it (16); it is clean (the camera head's own selection:
//      flags 0, confidence ≤ 5″); its correction skipped no stage: no
//      velocity (4), no temperatures (8), a model angle out of range (128), no
//      model for the head (256). A head corrected otherwise would disagree
//      with the others by the stage it lacks (up to 25″ of aberration, the
//      bench's thermal deformation), so it is left out, never averaged in;
//   2. the epoch (select_epoch): every row of a repeated head (Repeated says
//      whether the first stands), whatever step 1 said; a usable row without
//      a stage (1, 2) another usable row of the epoch has; then a usable
//      row whose quaternion is not unit (the combiner's own test).
// The combiner's consistency gate then decides kInconsistent (combiner.hpp).
//
// Callers: the ground (`ascorr combine`, `correct --combined`, `align`) run
// both steps with Repeated::kLeaveAllOut (align refuses a file with a second
// row instead: a mounting estimate must not depend on which row came first).
// The flight loop and the link server (epoch pipeline) know with each
// solution only its status and whether it is clean: they apply step 1's
// status part (usable_for_combination); the combiner tests head, mounting and
// norm itself and keeps the first row of a head (Repeated::kKeepFirst: a
// repeated head is the camera head's retransmission; test_combine holds the
// combiner to this rule), and the flight loop applies one correction
// configuration to every head, so step 2's stage mix cannot arise on board.
#pragma once

#include <cstddef>
#include <cstdint>

#include "../core/heads.hpp"
#include "../core/status.hpp"

namespace ascorr::combine {

// A stage the run asked for and could not apply (4, 8, 128, 256).
inline constexpr StatusBits kSkippedStages =
    status::kNoVelocity | status::kNoTemperature | status::kThermalOutOfRange | status::kNoModelForHead;
// The stages a correction applied (1, 2).
inline constexpr StatusBits kStagesApplied = status::kAberrationApplied | status::kThermalApplied;
// A clean row's largest confidence (arcsec): the contract's Statistics,
// which the ground's readers of files apply (on board the camera head says
// whether its solution is clean).
inline constexpr double kMaxCleanConfidenceArcsec = 5.0;

// Why a head's row of an epoch is not averaged in: step 1's first reason
// (kNoEpoch, kNotAHead, kNotInMountings, kRejected, kFlagged, kConfidence,
// kStageSkipped), then step 2's (kDuplicate over any, kStageMissing,
// kNotUnit), then the combiner's gate (kInconsistent).
enum class LeftOut : std::uint8_t {
    kUsed,
    kFlagged,         // flags != 0
    kConfidence,      // confidence > 5 or not a number
    kRejected,        // status 16
    kStageSkipped,    // status 4, 8, 128 or 256
    kStageMissing,    // a stage other rows of the epoch have (mix)
    kNotAHead,        // chu is no head of heads.hpp
    kNotInMountings,  // a head the mountings do not have
    kDuplicate,       // two rows of one head in one epoch
    kInconsistent,    // refused by the combiner's gates
    kNotUnit,         // a quaternion the combiner refuses (not unit, not finite)
    kNoEpoch,         // |t| beyond the millisecond key (pipeline/epoch_key.hpp): in no epoch
};
inline constexpr std::size_t kLeftOutKinds = static_cast<std::size_t>(LeftOut::kNoEpoch) + 1U;

// The reasons as the summaries name them (index: LeftOut).
inline constexpr const char* kLeftOutNames[kLeftOutKinds] = {"used",
                                                             "flagged",
                                                             "confidence above 5",
                                                             "rejected (16)",
                                                             "stage skipped (4, 8, 128, 256)",
                                                             "stage missing",
                                                             "not a head",
                                                             "not in the mountings",
                                                             "two rows of one head",
                                                             "inconsistent",
                                                             "quaternion not unit",
                                                             "in no epoch"};

constexpr const char* left_out_name(LeftOut why) noexcept {
    return kLeftOutNames[static_cast<std::size_t>(why)];
}
static_assert(kLeftOutNames[kLeftOutKinds - 1U] != nullptr, "a name for every LeftOut");

// A row as the selection sees it: what needs no other row.
struct RowFacts {
    bool in_epoch;      // |t| < kMaxEpochTimeS (pipeline/epoch_key.hpp): a millisecond key
    std::uint8_t head;  // any byte: an index ≥ kMaxHeads is no head
    StatusBits status;  // the correction's status; 0 for a row no stage was asked of
    bool flagged;       // flags != 0
    bool confident;     // confidence ≤ kMaxCleanConfidenceArcsec (false for NaN)
    bool unit;          // norm_within(q, ScalarTraits<T>::unit_norm_tolerance), as the combiner tests (step 2)
};

// Step 1: why the row is left out on its own (kUsed: usable so far).
constexpr LeftOut left_out_alone(const RowFacts& r, HeadMask mounted) noexcept {
    if (!r.in_epoch) {
        return LeftOut::kNoEpoch;
    }
    if (r.head >= kMaxHeads) {
        return LeftOut::kNotAHead;
    }
    if (!has_head(mounted, r.head)) {
        return LeftOut::kNotInMountings;
    }
    if ((r.status & status::kRejected) != 0U) {
        return LeftOut::kRejected;
    }
    if (r.flagged) {
        return LeftOut::kFlagged;
    }
    if (!r.confident) {
        return LeftOut::kConfidence;
    }
    if ((r.status & kSkippedStages) != 0U) {
        return LeftOut::kStageSkipped;
    }
    return LeftOut::kUsed;
}

// Step 1's status part, the on-board pipeline's: whether a solution may be
// averaged in by its status and the camera head's word (clean), the combiner
// testing head and mounting itself. One mask test: written through
// left_out_alone, GCC 12 inlines the targets' link server differently.
constexpr bool usable_for_combination(StatusBits corrected, bool clean) noexcept {
    return clean && (corrected & (status::kRejected | kSkippedStages)) == 0U;
}

// usable_for_combination against left_out_alone on no status bit and on every
// single bit and pair of bits, clean or not (both test sets of bits; a rule
// that needed three bits together would also differ on a pair).
constexpr bool usable_agrees_with_left_out_alone() noexcept {
    constexpr unsigned kBits = 8U * sizeof(StatusBits);
    for (unsigned a = 0; a <= kBits; ++a) {
        for (unsigned b = a; b <= kBits; ++b) {
            const unsigned bits = (a == 0U ? 0U : 1U << (a - 1U)) | (b == 0U ? 0U : 1U << (b - 1U));
            const auto s = static_cast<StatusBits>(bits);
            for (unsigned c = 0; c < 2U; ++c) {
                const bool clean = c != 0U;
                const RowFacts f{true, 0U, s, !clean, true, true};
                if (usable_for_combination(s, clean) != (left_out_alone(f, head_bit(0U)) == LeftOut::kUsed)) {
                    return false;
                }
            }
        }
    }
    return true;
}
static_assert(usable_agrees_with_left_out_alone(), "one rule: usable_for_combination is left_out_alone's status part");

// Which rows of a head repeated in an epoch stand.
enum class Repeated : std::uint8_t {
    kLeaveAllOut,  // the ground: none can be told right, every one is kDuplicate
    kKeepFirst,    // on board: the first stands, the later ones are kDuplicate
};

// Step 2 over an epoch's rows (`why` holds step 1's answers and receives the
// epoch's): the rows of a repeated head by `rule` (kKeepFirst: the first in
// `rows`' order stands), whatever step 1 said of them; then each usable row
// whose stages (status & 3) are not all of the epoch's, the stages of its
// usable rows; then each usable row that is not unit. Returns the epoch's
// stages (they choose the consistency gate, gate_config.hpp). O(n²) in the
// rows: a few heads.
constexpr StatusBits select_epoch(const RowFacts* rows, LeftOut* why, std::size_t n, Repeated rule) noexcept {
    for (std::size_t j = 1; j < n; ++j) {
        for (std::size_t i = 0; i < j; ++i) {
            if (rows[i].head == rows[j].head && rows[j].head < kMaxHeads) {
                why[j] = LeftOut::kDuplicate;
                why[i] = rule == Repeated::kLeaveAllOut ? LeftOut::kDuplicate : why[i];
                break;
            }
        }
    }
    StatusBits stages = 0U;
    for (std::size_t i = 0; i < n; ++i) {
        stages = static_cast<StatusBits>(stages | (why[i] == LeftOut::kUsed ? (rows[i].status & kStagesApplied) : 0U));
    }
    for (std::size_t i = 0; i < n; ++i) {
        if (why[i] == LeftOut::kUsed && (rows[i].status & kStagesApplied) != stages) {
            why[i] = LeftOut::kStageMissing;
        }
        why[i] = why[i] == LeftOut::kUsed && !rows[i].unit ? LeftOut::kNotUnit : why[i];
    }
    return stages;
}

}  // namespace ascorr::combine
