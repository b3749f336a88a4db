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

// Whether a corrected solution may feed the estimator: the aberration stage
// applied, not rejected, three valid temperatures (the ground fit's
// selection; the loop's solutions carry no flags or confidence). The epoch
// pipeline's feed stage and selected_solution test it; feed_estimator's loop
// over the frame heads writes it out (its comment says why).
template <typename T>
constexpr bool feeds_estimator(const CorrectedSolution<T>& s, const HeadTemperatures<T>& tp) noexcept {
    return (s.status & status::kAberrationApplied) != 0U && (s.status & status::kRejected) == 0U && tp.t_chu.valid &&
           tp.t_029.valid && tp.t_032.valid;
}

// Head h's solution as the estimator takes it: false when it does not pass
// the selection (feeds_estimator). Its quaternion without the thermal stage is q_ab = q_th⁻¹ ⊗
// q_corr, with q_th the stage the core applied (thermal_stage(), correct.hpp,
// the same model and temperatures), formed as the core forms it: the increment
// (q_th⁻¹ − 1) ⊗ q_corr from small terms, one renormalised sum (quaternion.hpp).
template <typename T>
bool selected_solution(std::uint8_t h, const ThermalModel<T>* model, const CorrectedSolution<T>& s,
                       const HeadTemperatures<T>& tp, Quaternion<T>& q_ab) noexcept {
    if (!feeds_estimator(s, tp)) {
        return false;
    }
    q_ab = s.q_chu_icrf;
    if ((s.status & status::kThermalApplied) != 0U && model != nullptr) {
        const ThermalStage<T> th = thermal_stage(*model, h, tp);
        q_ab = renormalized_sum(s.q_chu_icrf, increment(conjugate(th.q_th)) * s.q_chu_icrf);
    }
    return true;
}

// The cycle's feed to the estimator: it counts when heads A, B and C all pass
// the selection (selected_solution); a further head h < N goes with it when
// bit h of `further` is set (the caller kept its solution) and it passes too.
// False: the cycle did not count.
template <typename T, std::size_t N>
bool feed_estimator(Estimator<T, N>& e, std::int64_t t_us, const ThermalModel<T>* model,
                    const CorrectedSolution<T>* corrected, const HeadTemperatures<T>* const* temperatures,
                    std::uint8_t further = 0U) noexcept {
    CalibCycle<T, N> c;  // not zeroed: the estimator reads the frame heads and those in c.heads, set below
    c.t_us = t_us;
    // The frame heads: selected_solution's body, written out (the M3's and
    // M4F's per-cycle cost; the loop is the one the three-head estimator had).
    // Calling it instead, even always_inline, costs the M3 13 instructions per
    // cycle (1218 → 1231, flight report; M4F unchanged); its test as
    // feeds_estimator(s, tp), the M4F 9 (correction 711 → 720: GCC 12 then
    // inlines this function into the flight image's calib entry). The test
    // below is feeds_estimator's, term for term: change both together.
    for (std::uint8_t h = 0; h < kFrameHeads; ++h) {
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
    if constexpr (N > kFrameHeads) {
        for (std::uint8_t h = kFrameHeads; h < N; ++h) {
            if (((static_cast<unsigned>(further) >> h) & 1U) != 0U &&
                selected_solution(h, model, corrected[h], *temperatures[h], c.q_chu_icrf[h])) {
                c.temperatures[h] = *temperatures[h];
                c.heads = static_cast<std::uint8_t>(c.heads | (1U << h));
            }
        }
    } else {
        (void)further;
    }
    e.accumulate(c);
    return true;
}

// Further head h's solution of a cycle fed already (it came after A, B and
// C); false: not taken (not selected, or no such cycle, Estimator::accumulate_head).
template <typename T, std::size_t N>
bool feed_estimator_head(Estimator<T, N>& e, std::uint8_t h, std::int64_t t_us, const ThermalModel<T>* model,
                         const CorrectedSolution<T>& corrected, const HeadTemperatures<T>& temperatures) noexcept {
    Quaternion<T> q{};
    return selected_solution(h, model, corrected, temperatures, q) && e.accumulate_head(h, t_us, q, temperatures);
}

}  // namespace ascorr::calib
