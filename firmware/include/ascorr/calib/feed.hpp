// ascorr/calib/feed.hpp: corrected solutions into the on-board estimator
// (estimator.hpp): one epoch at once (feed_estimator: the flight loop,
// firmware/app/flight_cycle.hpp), or one solution at a time in time order
// (EpochFeed: the link server, ascorr_link/server.hpp, and the host's run over
// a recorded file, host_sim's self_calibration.cpp, which so take the same
// decisions in the same order).
#pragma once

#include <cstdint>

#include "../core/correct.hpp"
#include "../core/quaternion.hpp"
#include "../core/status.hpp"
#include "estimator.hpp"

namespace ascorr::calib {

// The cycle's feed to the estimator. A cycle counts when heads A, B and C all
// have the aberration stage applied and three valid temperatures (the ground
// fit's selection; the loop's solutions carry no flags or confidence). Each
// head's solution without its thermal stage is q_ab = q_th⁻¹ ⊗ q_corr, with
// q_th the stage the core applied (thermal_stage(), correct.hpp, the same
// model and temperatures), formed as the core forms it: the increment
// (q_th⁻¹ − 1) ⊗ q_corr from small terms, one renormalised sum
// (quaternion.hpp). False: the cycle did not count.
template <typename T>
bool feed_estimator(Estimator<T>& e, std::int64_t t_us, const ThermalModel<T>* model,
                    const CorrectedSolution<T>* corrected, const HeadTemperatures<T>* const* temperatures) noexcept {
    CalibCycle<T> c{};
    c.t_us = t_us;
    for (std::uint8_t h = 0; h < kCalibHeads; ++h) {
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

// Solutions one at a time, in time order, grouped into epochs by time tag
// (TT µs): an epoch's first solution takes the epoch's model
// (model_for_cycle: a swap happens there, between epochs, never within one);
// the first solution of each of A, B and C that is usable (clean: the
// source's selection, flags 1, 2, 4 clear and confidence ≤ 5; the aberration
// stage applied, not rejected, three valid temperatures) is kept, and when
// all three are there the epoch feeds the estimator and its per-orbit work
// runs to its end (at most kPhases bounded steps). Later solutions of a head
// in the same epoch are corrected but not fed. Bounded, no allocation.
template <typename T>
class EpochFeed {
public:
    // Estimator::step()'s phases after a closed orbit (kAverages .. kGate).
    static constexpr int kPhases = static_cast<int>(Estimator<T>::Phase::kGate);

    // Forget the current epoch (a restarted estimator).
    void reset() noexcept {
        have_epoch_ = false;
        heads_ = 0U;
        model_ = nullptr;
    }

    // The model for a solution at t_us; nullptr: none (status 256).
    const ThermalModel<T>* model_at(Estimator<T>& e, std::int64_t t_us) noexcept {
        if (!have_epoch_ || t_us != t_us_) {
            have_epoch_ = true;
            t_us_ = t_us;
            heads_ = 0U;
            model_ = e.model_for_cycle(t_us);
            version_ = e.active_version();
        }
        return model_;
    }

    // The version of the current epoch's model (meaningful when it has one).
    std::uint32_t version() const noexcept { return version_; }

    // Head h's solution of the current epoch (model_at() came first), as
    // corrected with model_at()'s model. True: the epoch fed the estimator.
    bool take(Estimator<T>& e, std::uint8_t h, const CorrectedSolution<T>& c, const HeadTemperatures<T>& temperatures,
              bool clean) noexcept {
        if (!clean || !have_epoch_ || h >= kCalibHeads || heads_ == kFed || (heads_ & (1U << h)) != 0U ||
            !usable(c, temperatures)) {
            return false;
        }
        solutions_[h] = c;
        temperatures_[h] = temperatures;
        heads_ = static_cast<std::uint8_t>(heads_ | (1U << h));
        if (heads_ != kAll) {
            return false;
        }
        heads_ = kFed;
        const HeadTemperatures<T>* t[kCalibHeads] = {&temperatures_[0], &temperatures_[1], &temperatures_[2]};
        const bool fed = feed_estimator(e, t_us_, model_, solutions_, t);
        for (int i = 0; i < kPhases && e.step(); ++i) {
        }
        return fed;
    }

private:
    static constexpr std::uint8_t kAll = (1U << kCalibHeads) - 1U;
    static constexpr std::uint8_t kFed = 0x80U;

    static bool usable(const CorrectedSolution<T>& c, const HeadTemperatures<T>& tp) noexcept {
        return (c.status & status::kAberrationApplied) != 0U && (c.status & status::kRejected) == 0U &&
               tp.t_chu.valid && tp.t_029.valid && tp.t_032.valid;
    }

    bool have_epoch_ = false;
    std::int64_t t_us_ = 0;
    std::uint8_t heads_ = 0U;  // bit h: head h kept; kFed: the epoch fed the estimator
    const ThermalModel<T>* model_ = nullptr;
    std::uint32_t version_ = 0U;
    CorrectedSolution<T> solutions_[kCalibHeads]{};
    HeadTemperatures<T> temperatures_[kCalibHeads]{};
};

}  // namespace ascorr::calib
