// firmware/app/sun_entry_fixed.cpp: the fixed core with the Sun term, out of line.
#include "sun_entry.hpp"

namespace ascorr::app {

CorrectedSolution<Q30> correct_sun_fixed(const SolutionInput<Q30>& in, const CorrectionConfig<Q30>& cfg,
                                         const SunTermInput<Q30>& sun) noexcept {
    return correct_solution(in, cfg, sun);
}

}  // namespace ascorr::app
