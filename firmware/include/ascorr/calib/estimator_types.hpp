// ascorr/calib/estimator_types.hpp: what the on-board estimator
// (estimator.hpp) is given and gives: its configuration and limits, the
// reasons it refuses a candidate, its report, and one cycle's solutions.
// Plain data, no allocation; the link (ascorr_link/calib_messages.hpp) and the
// host read them without the estimator's state.
#pragma once

#include <cstddef>
#include <cstdint>

#include "../core/heads.hpp"
#include "../core/quaternion.hpp"
#include "../core/thermal.hpp"
#include "frame.hpp"

namespace ascorr::calib {

// The estimator learns heads 0 … N − 1, N from kMinCalibHeads to the core's
// kMaxHeads (heads.hpp): F needs A and C, the IBAs all N. kCalibHeads is the
// templates' default (A, B and C); the link and the flight loop learn kMaxHeads.
//
// Per-head selection: the frame heads 0 … kFrameHeads − 1 (A, B, C) learn
// from the epochs in which all three pass the selection (a cycle counts then,
// docs/contract.md), whatever the further heads do. A further head h (D, …)
// learns from the counted epochs in which it passes the selection too: its
// rotation is taken relative to A, in F (A and C), and its IBAs pair it with
// A, B and C. It joins a model once its own orbits reach min_orbits and its
// condition is within max_condition; until then, or in a file without it, an
// adopted model keeps the active model's coefficients for it (Estimator::gate),
// so a head with a model never loses it to an adoption.
inline constexpr std::size_t kMinCalibHeads = 3;
inline constexpr std::size_t kFrameHeads = 3;
inline constexpr std::size_t kCalibHeads = 3;
template <std::size_t N>
inline constexpr bool kCalibHeadCountOk = N >= kMinCalibHeads&& N <= kMaxHeads&& N <= 8U;
// The frame heads' bits of a head mask (bit h: head h).
inline constexpr std::uint8_t kFrameMask = (1U << kFrameHeads) - 1U;
// Whether a mask of learnt heads (Estimator::active_learnt) has head h.
constexpr bool learns_head(std::size_t h, std::uint32_t learnt_mask) noexcept {
    return h < 32U && ((learnt_mask >> h) & 1U) != 0U;
}
// The inter-boresight angles of N heads: pairs (i, j), i < j, in the order
// (0,1), (0,2), …, (0,N−1), (1,2), …
constexpr std::size_t iba_pairs(std::size_t n_heads) noexcept {
    return n_heads * (n_heads - 1U) / 2U;
}
// The estimator learns the linear terms of core/model_terms.hpp per axis,
// [1, T1, T2 − T1, T3 − T1] (its design row, Estimator::feed).
inline constexpr std::size_t kUnknowns = kLinearModelTerms;
static_assert(kUnknowns == 4, "Estimator::feed's design row lists the linear terms of kModelTermTable");
inline constexpr std::size_t kWindow = 32;  // recent orbits kept (gate and held-back orbits)

// The orbit periods and time constants the estimator is meant for: an orbit
// of 10 min to a day (an Earth orbit's period is 88 min to 24 h; shorter bins
// would hold too few epochs), a forgetting time constant of a day to
// 10 000 days (beyond, forgetting is nil within any mission). The link's
// CALIB_START and the host's options refuse others.
inline constexpr std::int64_t kMinOrbitPeriodUs = 600'000'000;
inline constexpr std::int64_t kMaxOrbitPeriodUs = 86'400'000'000;
inline constexpr double kMinTimeConstantDays = 1.0;
inline constexpr double kMaxTimeConstantDays = 10000.0;
constexpr bool time_constant_acceptable(double days) noexcept {
    return days >= kMinTimeConstantDays && days <= kMaxTimeConstantDays;  // false for NaN
}
constexpr bool configuration_acceptable(std::int64_t orbit_period_us, double time_constant_days) noexcept {
    return orbit_period_us >= kMinOrbitPeriodUs && orbit_period_us <= kMaxOrbitPeriodUs &&
           time_constant_acceptable(time_constant_days);
}

// The rule for the rotation common to all heads on board
// (common_rotation_memory.hpp; common_rotation.hpp, "The rule"), by head
// index: A_h (head axes → bench, 1/arcsec²; combine/mountings.hpp's
// motion_weight, from the mountings the DPU combines with) for the heads of
// `heads`. heads 0, the default: no rule; the models keep the estimator's own
// frame (F of A and C as in the first orbit learnt).
struct CommonRotationWeights {
    std::uint8_t heads = 0;  // bit h: head h weighs a[h]
    Matrix3 a[kMaxHeads]{};
};

struct EstimatorConfig {
    std::int64_t orbit_period_us = 5'640'000'000;  // orbits are bins floor(t / period)
    double time_constant_days = 30.0;              // τ of the forgetting (chosen: docs/ground.md, Self-calibration)
    std::uint32_t min_orbits = 30;                 // orbits in the filter before a first model
    std::uint32_t min_epochs_per_orbit = 4;        // fewer: the orbit is not used
    // ... nor below this fraction of a typical orbit's count. The model is linear in the
    // temperatures, so a partial orbit's means obey it as a whole orbit's do; 0.3, not
    // 0.5: a head blinded for most of each orbit for days (the Moon) must not blind the
    // estimator to a settling then (issue 31: 1.216 → 1.091 on such a mission).
    double min_coverage = 0.3;
    double max_condition = 1e4;          // per head, equilibrated information matrix
    double adoption_margin = 0.03;       // a candidate must beat the active model by 3 %
    std::uint32_t window_orbits = 30;    // orbits of the residual comparison (≤ kWindow)
    double angle_check_margin_c = 30.0;  // °C around the recent temperatures
    double outlier_gate = 3.0;           // innovation RMS over the running RMS
    // Held back in a row: a real change (≤ kWindow). Each orbit of a step not followed
    // costs its whole size: 3 orbits of a 5" step are 1.08 of the floor over 30 days.
    // Shorter outlier runs are refused; longer ones are followed and, at their end,
    // undone the same way (README.md, "Outliers and changes").
    std::uint32_t persistence_orbits = 3;
    CommonRotationWeights common_rotation{};  // the rule's weights (none: the estimator's frame)
    // With the rule: an orbit that adopts no candidate re-gauges the active
    // adopted model over the rule's memory, which has grown since it was
    // adopted; it becomes a new version (same IBAs) when that moves the
    // bench by more than this at the orbit's T029 and T032 (arcsec, 1/40 of
    // the 2" noise of an IBA: below what the combined attitude shows, above
    // rounding; on the 120-day mission of test_common_rotation 0.05, 0.1 and
    // 0.2 give 1.230, 1.231 and 1.235" on x from day 30, and 77, 43 and 33
    // versions, 24 without). +inf: never (each adopted model keeps its gauge).
    double regauge_arcsec = 0.05;
};

// The orbit of time t_us: floor(t_us / period_us) (EstimatorConfig's bins),
// for t_us of any sign; period_us > 0 (every caller's: an accepted period).
constexpr std::int64_t orbit_bin(std::int64_t t_us, std::int64_t period_us) noexcept {
    const std::int64_t q = t_us / period_us;
    return (t_us % period_us != 0 && ((t_us < 0) != (period_us < 0))) ? q - 1 : q;
}

enum class Refusal : std::uint8_t {
    kNone = 0,
    kFewOrbits = 1,
    kCondition = 2,
    kAngleLimit = 3,
    kNoGain = 4,
};
inline constexpr std::size_t kRefusalKinds = 5;

inline const char* refusal_name(Refusal r) noexcept {
    switch (r) {
        case Refusal::kNone:
            return "none";
        case Refusal::kFewOrbits:
            return "too few orbits";
        case Refusal::kCondition:
            return "condition number";
        case Refusal::kAngleLimit:
            return "angle beyond the core's limits";
        case Refusal::kNoGain:
            return "no gain over the active model";
    }
    return "?";
}

struct EstimatorReport {
    std::uint32_t orbits_used;              // orbits in the filter since start or reset
    std::uint32_t orbits_short;             // closed with too few epochs
    std::uint32_t orbits_held;              // held back as outliers (some fed later)
    std::uint32_t orbits_late;              // closed while the previous was still being processed
    std::uint32_t changes;                  // persistent changes taken as real (intercepts released)
    double condition;                       // the worst head's, of the last candidate
    double residual_rms_arcsec;             // the active model over the window (NaN: none)
    double candidate_rms_arcsec;            // the last candidate over the window (NaN: none)
    bool has_active;                        // false: no model (status 256)
    std::uint32_t active_version;           // 0: the model given at start
    std::uint32_t active_crc;               // model_crc() of the active model (0: none)
    Refusal last_refusal;                   // of the last candidate
    std::uint32_t refusals[kRefusalKinds];  // counts per reason (index 0 unused)
    bool frozen;
};

// The rule's re-gauges of the active model since construction (estimator.hpp;
// not in the report, whose words the link carries: a re-gauge is a version).
struct RegaugeCounts {
    std::uint32_t made = 0;           // new versions
    std::uint32_t beyond_limits = 0;  // not made: the re-gauged model beyond the core's limits
};

// One counted cycle's selected solutions at the same instant: the frame
// heads always, a further head h when bit h of `heads` is set.
template <typename T, std::size_t N = kCalibHeads>
struct CalibCycle {
    static_assert(kCalibHeadCountOk<N>, "the estimator learns 3 to kMaxHeads heads");
    std::int64_t t_us;                    // time of the epoch, µs
    Quaternion<T> q_chu_icrf[N];          // aberration-corrected, unit
    HeadTemperatures<T> temperatures[N];  // all valid
    std::uint8_t heads = kFrameMask;      // bit h: head h selected (the frame heads' bits always)
};

}  // namespace ascorr::calib
