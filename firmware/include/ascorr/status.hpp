// ascorr/status.hpp: status bits reported with every corrected solution.
//
// Bits 1–16 are the data contract (formats.md, "Corrected file"); bits from 32
// on are ascorr's extension and always come with the contract bit that says
// what was skipped, so a reader that knows only the contract bits still sees
// the right outcome.
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
    32U;  // with kNoVelocity: non-finite, or |v| > kMaxObserverSpeedKmS (includes |v| >= c)
inline constexpr StatusBits kTemperatureInvalid =
    64U;  // with kNoTemperature: non-finite or outside ±kMaxAbsTemperatureC
inline constexpr StatusBits kThermalOutOfRange = 128U;  // thermal skipped: a model angle beyond kMaxThermalAngleRad
inline constexpr StatusBits kNoModelForHead = 256U;     // thermal skipped: the model has no coefficients for this head
inline constexpr StatusBits kStale = 512U;              // set by callers (HAL, firmware) for stale inputs they withheld
}  // namespace status

}  // namespace ascorr
