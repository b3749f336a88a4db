// firmware/app/sun_entry_float.cpp: the float core with the Sun term, out of line.
#include "sun_entry.hpp"

namespace ascorr::app {

CorrectedSolution<float> correct_sun_float(const SolutionInput<float>& in, const CorrectionConfig<float>& cfg,
                                           const SunTermInput<float>& sun) noexcept {
    return correct_solution(in, cfg, sun);
}

}  // namespace ascorr::app
