// ascorr/core/status.hpp: status bits reported with every corrected solution.
//
// Bits 1–16 are the data contract (docs/contract.md, "Status bits"); bits from
// 32 on are ascorr's extensions. The rule, for every bit:
//  - bit 1 (2) is set exactly when the aberration (thermal) stage was applied,
//    so whether a stage was applied never depends on an extension bit;
//  - an extension bit that refines a contract bit always comes with it:
//    32 with 4 (velocity given but unusable), 64 with 8 (temperature given but
//    unusable), 512 with 4 or 8 (the input a caller withheld as stale);
//  - 128 and 256 say why the thermal stage was skipped when its inputs were all
//    present (the model's angle is out of the domain, or the model has no such
//    head): no contract bit describes them, so they stand alone (bit 2 absent);
//  - 16 (rejected) stands alone: nothing else was evaluated.
// A reader that knows only the contract bits thus still sees what was applied
// and, for a missing input, which one. Each bit's name is defined once, here
// (kStatusBitNames), for messages and summaries.
#pragma once

#include <cstdint>

namespace ascorr {

using StatusBits = std::uint16_t;

namespace status {
inline constexpr StatusBits kAberrationApplied = 1U;  // contract
inline constexpr StatusBits kThermalApplied = 2U;     // contract
inline constexpr StatusBits kNoVelocity = 4U;         // contract: aberration skipped
inline constexpr StatusBits kNoTemperature = 8U;      // contract: thermal skipped
inline constexpr StatusBits kRejected = 16U;          // contract: quaternion unchanged
// Extensions.
inline constexpr StatusBits kVelocityInvalid =
    32U;  // with kNoVelocity: non-finite, |v| > kMaxObserverSpeedKmS (includes |v| >= c), 1/s out of domain
inline constexpr StatusBits kTemperatureInvalid =
    64U;  // with kNoTemperature: non-finite or outside ±kMaxAbsTemperatureC
inline constexpr StatusBits kThermalOutOfRange = 128U;  // alone: a model angle beyond kMaxThermalAngleRad
inline constexpr StatusBits kNoModelForHead = 256U;     // alone: the model has no coefficients for this head
inline constexpr StatusBits kStale = 512U;              // with 4 or 8: an input withheld as stale by the caller

// Name of each bit, index = bit position (1 << i), for messages and summaries.
inline constexpr int kStatusBitCount = 10;
inline constexpr const char* kStatusBitNames[kStatusBitCount] = {
    "aberration applied",    // 1
    "thermal applied",       // 2
    "no velocity",           // 4
    "temperatures missing",  // 8
    "rejected",              // 16
    "velocity invalid",      // 32
    "temperature invalid",   // 64
    "thermal out of range",  // 128
    "no model for head",     // 256
    "stale",                 // 512
};

// True when `s` follows the rule above (used by tests and by callers that
// merge their own bits into a core status, e.g. the HAL's kStale).
constexpr bool status_consistent(StatusBits s) noexcept {
    const bool applied_ab = (s & kAberrationApplied) != 0U;
    const bool applied_th = (s & kThermalApplied) != 0U;
    const bool no_v = (s & kNoVelocity) != 0U;
    const bool no_t = (s & kNoTemperature) != 0U;
    if ((s & kRejected) != 0U) {
        return s == kRejected;
    }
    if (s >= (1U << kStatusBitCount)) {
        return false;  // undefined bits
    }
    if ((applied_ab && no_v) || (applied_th && (no_t || (s & (kThermalOutOfRange | kNoModelForHead)) != 0U))) {
        return false;  // a stage both applied and skipped
    }
    if (((s & kVelocityInvalid) != 0U && !no_v) || ((s & kTemperatureInvalid) != 0U && !no_t) ||
        ((s & kStale) != 0U && !no_v && !no_t)) {
        return false;  // a refinement without its contract bit
    }
    // At most one reason for a skipped thermal stage.
    const int th_reasons =
        (no_t ? 1 : 0) + ((s & kThermalOutOfRange) != 0U ? 1 : 0) + ((s & kNoModelForHead) != 0U ? 1 : 0);
    return th_reasons <= 1;
}
}  // namespace status

}  // namespace ascorr
