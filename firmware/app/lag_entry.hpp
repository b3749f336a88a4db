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

void lag_fixed(pipeline::HeadLags<Q30>& lags, std::uint8_t head, std::int64_t t_us,
               HeadTemperatures<Q30>& temps) noexcept;
void lag_float(pipeline::HeadLags<float>& lags, std::uint8_t head, std::int64_t t_us,
               HeadTemperatures<float>& temps) noexcept;

// The entry for scalar T, for code templated on it.
inline void lag(pipeline::HeadLags<Q30>& lags, std::uint8_t head, std::int64_t t_us,
                HeadTemperatures<Q30>& temps) noexcept {
    lag_fixed(lags, head, t_us, temps);
}
inline void lag(pipeline::HeadLags<float>& lags, std::uint8_t head, std::int64_t t_us,
                HeadTemperatures<float>& temps) noexcept {
    lag_float(lags, head, t_us, temps);
}

}  // namespace ascorr::app
