// firmware/app/temperature_source.hpp: where the correction loop takes its
// temperatures from.
//
// Conventions: one table in static storage, HeadTemperatures per head (T_CHU,
// THT00029, THT00032 in the core's Celsius format, each with a valid flag).
// The producer refreshes it once per 22 Hz cycle, before the heads are
// corrected, in the same execution context as the loop (no locking). A reading
// the producer could not make or withholds as stale has valid = false; the core
// then skips the thermal stage and flags it (status 8). Producer: the HAL's
// thermistor acquisition (hal_temperatures.cpp; float on the FPU target, fixed
// point on the target without FPU).
#pragma once

#include <cstdint>

#include "app_scalar.hpp"
#include "ascorr/core/status.hpp"
#include "ascorr/core/thermal.hpp"

namespace ascorr::app {

// Refreshes the readings for cycle `cycle`. Bounded time, never blocks.
void temperatures_update(std::uint32_t cycle) noexcept;

// The readings of `head` for the current cycle; head ≥ kMaxHeads gets a
// table entry whose readings are all invalid.
const HeadTemperatures<Scalar>& temperatures_of(std::uint8_t head) noexcept;

// The core's status with the producer's reasons added where the core skipped
// the thermal stage for missing temperatures (64 for a fault, 512 for stale).
StatusBits temperatures_merge_status(std::uint8_t head, StatusBits core) noexcept;

}  // namespace ascorr::app
