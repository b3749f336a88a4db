// firmware/app/core_entry.hpp: the correction core compiled once per scalar for
// the DPU, as out-of-line entry points.
//
// Conventions: each entry is correct_solution() of the core (correct.hpp)
// instantiated for one scalar, in its own translation unit
// (core_entry_fixed.cpp, core_entry_float.cpp) so that the core's flash
// (.text/.rodata of that object) and its worst-case stack (-fstack-usage) are
// measured alone. The core has no static data: its RAM is the caller's.
#pragma once

#include "ascorr/core/correct.hpp"
#include "ascorr/core/fixed_point.hpp"

namespace ascorr::app {

CorrectedSolution<Q30> correct_fixed(const SolutionInput<Q30>& in, const CorrectionConfig<Q30>& cfg) noexcept;
CorrectedSolution<float> correct_float(const SolutionInput<float>& in, const CorrectionConfig<float>& cfg) noexcept;

// The entry for scalar T, for code templated on it.
inline CorrectedSolution<Q30> correct(const SolutionInput<Q30>& in, const CorrectionConfig<Q30>& cfg) noexcept {
    return correct_fixed(in, cfg);
}
inline CorrectedSolution<float> correct(const SolutionInput<float>& in, const CorrectionConfig<float>& cfg) noexcept {
    return correct_float(in, cfg);
}

}  // namespace ascorr::app
