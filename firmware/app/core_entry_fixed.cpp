// firmware/app/core_entry_fixed.cpp: the fixed-point (Q30) core, out of line.
#include "core_entry.hpp"

namespace ascorr::app {

CorrectedSolution<Q30> correct_fixed(const SolutionInput<Q30>& in, const CorrectionConfig<Q30>& cfg) noexcept {
    return correct_solution(in, cfg);
}

}  // namespace ascorr::app
