// ascorr/calib/feed.hpp: one epoch's corrected solutions into the on-board
// estimator (estimator.hpp): the epoch pipeline's feed stage
// (pipeline/epoch_pipeline.hpp, which picks the solutions and the epochs).
#pragma once

#include <cstdint>

#include "../core/correct.hpp"
#include "../core/quaternion.hpp"
#include "../core/status.hpp"
#include "estimator.hpp"

namespace ascorr::calib {

// The cycle's feed to the estimator. A cycle counts when heads 0 … N − 1 all
// have the aberration stage applied and three valid temperatures (the ground
// fit's selection; the loop's solutions carry no flags or confidence). Each
// head's solution without its thermal stage is q_ab = q_th⁻¹ ⊗ q_corr, with
// q_th the stage the core applied (thermal_stage(), correct.hpp, the same
// model and temperatures), formed as the core forms it: the increment
// (q_th⁻¹ − 1) ⊗ q_corr from small terms, one renormalised sum
// (quaternion.hpp). False: the cycle did not count.
template <typename T, std::size_t N>
bool feed_estimator(Estimator<T, N>& e, std::int64_t t_us, const ThermalModel<T>* model,
                    const CorrectedSolution<T>* corrected, const HeadTemperatures<T>* const* temperatures) noexcept {
    CalibCycle<T, N> c{};
    c.t_us = t_us;
    for (std::uint8_t h = 0; h < N; ++h) {
        const CorrectedSolution<T>& s = corrected[h];
        const HeadTemperatures<T>& tp = *temperatures[h];
        if ((s.status & status::kAberrationApplied) == 0U || (s.status & status::kRejected) != 0U ||
            !(tp.t_chu.valid && tp.t_029.valid && tp.t_032.valid)) {
            return false;
        }
        c.q_chu_icrf[h] = s.q_chu_icrf;
        if ((s.status & status::kThermalApplied) != 0U && model != nullptr) {
            const ThermalStage<T> th = thermal_stage(*model, h, tp);
            c.q_chu_icrf[h] = renormalized_sum(s.q_chu_icrf, increment(conjugate(th.q_th)) * s.q_chu_icrf);
        }
        c.temperatures[h] = tp;
    }
    e.accumulate(c);
    return true;
}

}  // namespace ascorr::calib
