// firmware/app/lag_search_entry.hpp: the self-calibration's search for the
// bench's lag (ascorr/calib/lag_search.hpp) compiled once per scalar for the
// DPU, out of line.
//
// Conventions: as LagSearch::take (TT µs since J2000; the frame heads'
// solutions as the pipeline kept them for the feed, corrected with `model`
// at their temperatures; the lags in the core's scalar, the IBAs and sums in
// double, software floating point on both targets). In their own translation
// units (lag_search_entry_fixed.cpp, lag_search_entry_float.cpp) so that the
// instructions per fed cycle (bench/target_bench.cpp) and the stack
// (-fstack-usage) are the search's alone. Not in the flight image: the loop
// does not search the lag yet.
#pragma once

#include <cstdint>

#include "ascorr/calib/lag_search.hpp"
#include "ascorr/core/fixed_point.hpp"

namespace ascorr::app {

bool lag_search_take_fixed(calib::LagSearch<Q30>& search, std::int64_t t_us, const ThermalModel<Q30>& model,
                           const CorrectedSolution<Q30>* corrected,
                           const HeadTemperatures<Q30>* const* temperatures) noexcept;
bool lag_search_take_float(calib::LagSearch<float>& search, std::int64_t t_us, const ThermalModel<float>& model,
                           const CorrectedSolution<float>* corrected,
                           const HeadTemperatures<float>* const* temperatures) noexcept;

// The entry for scalar T, for code templated on it.
inline bool lag_search_take(calib::LagSearch<Q30>& search, std::int64_t t_us, const ThermalModel<Q30>& model,
                            const CorrectedSolution<Q30>* corrected,
                            const HeadTemperatures<Q30>* const* temperatures) noexcept {
    return lag_search_take_fixed(search, t_us, model, corrected, temperatures);
}
inline bool lag_search_take(calib::LagSearch<float>& search, std::int64_t t_us, const ThermalModel<float>& model,
                            const CorrectedSolution<float>* corrected,
                            const HeadTemperatures<float>* const* temperatures) noexcept {
    return lag_search_take_float(search, t_us, model, corrected, temperatures);
}

}  // namespace ascorr::app
