// firmware/app/sun_entry.hpp: the correction core with the heads' Sun terms
// folded into its thermal stage (core/correct.hpp, the flight form of
// core/sun_term.hpp), compiled once per scalar for the DPU, as out-of-line
// entry points.
//
// Conventions: as core_entry.hpp, in its own translation units
// (sun_entry_fixed.cpp, sun_entry_float.cpp) with the core's options, so
// that its instructions per solution (bench/target_bench.cpp) less the
// core's are what a head with a Sun term adds. Linked into the flight image
// for a fixed model's term (the pipeline's stage needs it: TakesSunTerm);
// a model version's learnt term is applied in the contract's form there
// (flight_cycle.hpp).
#pragma once

#include "ascorr/core/correct.hpp"
#include "ascorr/core/fixed_point.hpp"

namespace ascorr::app {

// correct_solution(in, cfg, sun); sun.s_icrf is formed at the velocity
// service's rate, not per solution.
CorrectedSolution<Q30> correct_sun_fixed(const SolutionInput<Q30>& in, const CorrectionConfig<Q30>& cfg,
                                         const SunTermInput<Q30>& sun) noexcept;
CorrectedSolution<float> correct_sun_float(const SolutionInput<float>& in, const CorrectionConfig<float>& cfg,
                                           const SunTermInput<float>& sun) noexcept;

// The entry for scalar T, for code templated on it.
inline CorrectedSolution<Q30> correct(const SolutionInput<Q30>& in, const CorrectionConfig<Q30>& cfg,
                                      const SunTermInput<Q30>& sun) noexcept {
    return correct_sun_fixed(in, cfg, sun);
}
inline CorrectedSolution<float> correct(const SolutionInput<float>& in, const CorrectionConfig<float>& cfg,
                                        const SunTermInput<float>& sun) noexcept {
    return correct_sun_float(in, cfg, sun);
}

}  // namespace ascorr::app
