// firmware/app/core_entry_float.cpp: the float core, out of line.
#include "core_entry.hpp"

namespace ascorr::app {

CorrectedSolution<float> correct_float(const SolutionInput<float>& in, const CorrectionConfig<float>& cfg) noexcept {
    return correct_solution(in, cfg);
}

}  // namespace ascorr::app
