// firmware/app/lag_entry.hpp: the lag stage (pipeline/head_lags.hpp) compiled
// once per scalar for the DPU, as out-of-line entry points.
//
// Conventions: as core_entry.hpp, in its own translation units
// (lag_entry_fixed.cpp, lag_entry_float.cpp) with the core's options, so that
// its instructions per solution (bench/target_bench.cpp) are those a lagged
// head adds to the core's.
#pragma once

#include <cstdint>

#include "ascorr/core/fixed_point.hpp"
#include "ascorr/pipeline/head_lags.hpp"

namespace ascorr::app {

// The arguments in this order fill r0–r3 with all but the head (AAPCS: the
// 64-bit time takes an even pair), so that the temperatures' address stays in
// a register.
void lag_fixed(pipeline::HeadLags<Q30>& lags, HeadTemperatures<Q30>& temps, std::int64_t t_us,
               std::uint8_t head) noexcept;
void lag_float(pipeline::HeadLags<float>& lags, HeadTemperatures<float>& temps, std::int64_t t_us,
               std::uint8_t head) noexcept;

// The entry for scalar T, for code templated on it.
inline void lag(pipeline::HeadLags<Q30>& lags, std::uint8_t head, std::int64_t t_us,
                HeadTemperatures<Q30>& temps) noexcept {
    lag_fixed(lags, temps, t_us, head);
}
inline void lag(pipeline::HeadLags<float>& lags, std::uint8_t head, std::int64_t t_us,
                HeadTemperatures<float>& temps) noexcept {
    lag_float(lags, temps, t_us, head);
}

}  // namespace ascorr::app
