// firmware/app/loop_rate.hpp: the flight loop's rate, one definition for the
// loop (main.cpp: SysTick's period), its cycle (flight_cycle.hpp: the solution
// times) and the boom acquisition's clock (hal_temperatures.cpp), so the
// host's prediction of the loop (tests/target/flight_expectation.cpp) and the
// DPU use the same rate.
#pragma once

#include <cstdint>

namespace ascorr::app {

inline constexpr std::uint32_t kRateHz = 22U;  // solutions per second and head

}  // namespace ascorr::app
