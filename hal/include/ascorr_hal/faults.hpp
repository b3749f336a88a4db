// ascorr_hal/faults.hpp: the fault flags every acquired temperature carries.
//
// Conventions:
//  - A reading is usable only when its FaultBits are 0; any bit set means the
//    value is withheld (valid = false) and the core skips the thermal stage.
//  - Bits are independent and can combine (e.g. kOpen with kStuck is reported
//    as both). kStale maps to the core's status::kStale, every other bit to
//    status::kTemperatureInvalid; kNoQuorum carries its members' bits and
//    maps through them (alone, it means disagreement: kTemperatureInvalid).
//    See HeadAcquisition::status_bits() in acquisition.hpp.
//  - Freestanding: no heap, no exceptions, no I/O.
#pragma once

#include <cstdint>

namespace ascorr::hal {

using FaultBits = std::uint16_t;

namespace fault {
inline constexpr FaultBits kNoData = 1U;         // no sample for this channel in this sample set
inline constexpr FaultBits kBus = 2U;            // the ADC did not answer (bad null bit, line I/O error)
inline constexpr FaultBits kOpen = 4U;           // thermistor resistance above the open-circuit limit
inline constexpr FaultBits kShort = 8U;          // thermistor resistance below the short-circuit limit
inline constexpr FaultBits kOutOfRange = 16U;    // temperature outside the channel's [t_min, t_max]
inline constexpr FaultBits kRate = 32U;          // |dT/dt| above the channel's max_rate
inline constexpr FaultBits kStuck = 64U;         // identical raw value for stuck_frames sample sets in a row
inline constexpr FaultBits kStale = 128U;        // reading older than stale_us, or time did not advance
inline constexpr FaultBits kNoisy = 256U;        // sample spread (inner half) above max_spread counts
inline constexpr FaultBits kOutvoted = 512U;     // disagrees with the median of its triplet
inline constexpr FaultBits kNoQuorum = 1024U;    // a voted value without two agreeing valid members
inline constexpr FaultBits kConversion = 2048U;  // conversion gave a non-finite value (bad coefficients)
inline constexpr int kCount = 12;
}  // namespace fault

// Short lower-case names of the bits, in bit order, for messages and files.
inline constexpr const char* kFaultNames[fault::kCount] = {"no_data",      "bus",      "open",      "short",
                                                           "out_of_range", "rate",     "stuck",     "stale",
                                                           "noisy",        "outvoted", "no_quorum", "conversion"};

}  // namespace ascorr::hal
