// firmware/app/calib_entry.hpp: the on-board estimator of the thermal model
// (ascorr/calib/estimator.hpp) in the flight loop, compiled once per scalar as
// out-of-line entry points.
//
// Conventions: two translation units per scalar, so that each part is
// measured and checked alone:
//  - calib_entry_<scalar>.cpp, the per-cycle part: the cycle's model (a
//    pending swap applied between solutions) and the cycle's feed
//    (feed_estimator, ascorr/calib/feed.hpp: the selection, each head's aberration-corrected
//    solution, the orbit accumulation). Integer code on the M3: checked free
//    of soft-float with the core's entry (tests/target/target-tests.cmake).
//  - calib_idle_<scalar>.cpp, the idle-time part: one step() of the per-orbit
//    update (double; one bounded phase per call).
#pragma once

#include <cstdint>

#include "ascorr/calib/estimator.hpp"
#include "ascorr/calib/feed.hpp"
#include "ascorr/core/correct.hpp"
#include "ascorr/core/fixed_point.hpp"

namespace ascorr::app {

// The flight loop's estimator: every head of the loop (kMaxHeads), A, B and C
// from the cycles they all pass the selection, a further head from those of
// them it passes too (estimator_types.hpp).
template <typename T>
using FlightEstimator = calib::Estimator<T, kMaxHeads>;

// Per cycle (calib_entry_<scalar>.cpp).
const ThermalModel<Q30>* calib_model_fixed(FlightEstimator<Q30>& e, std::int64_t t_us) noexcept;
const ThermalModel<float>* calib_model_float(FlightEstimator<float>& e, std::int64_t t_us) noexcept;
bool calib_feed_fixed(FlightEstimator<Q30>& e, std::int64_t t_us, const ThermalModel<Q30>* model,
                      const CorrectedSolution<Q30>* corrected, const HeadTemperatures<Q30>* const* temperatures,
                      std::uint8_t further) noexcept;
bool calib_feed_float(FlightEstimator<float>& e, std::int64_t t_us, const ThermalModel<float>* model,
                      const CorrectedSolution<float>* corrected, const HeadTemperatures<float>* const* temperatures,
                      std::uint8_t further) noexcept;
// A further head that comes after the cycle's feed (feed_estimator_head).
bool calib_feed_head_fixed(FlightEstimator<Q30>& e, std::uint8_t h, std::int64_t t_us, const ThermalModel<Q30>* model,
                           const CorrectedSolution<Q30>& corrected, const HeadTemperatures<Q30>& temperatures) noexcept;
bool calib_feed_head_float(FlightEstimator<float>& e, std::uint8_t h, std::int64_t t_us,
                           const ThermalModel<float>* model, const CorrectedSolution<float>& corrected,
                           const HeadTemperatures<float>& temperatures) noexcept;
// Idle time (calib_idle_<scalar>.cpp): one phase of the per-orbit update; false: nothing left.
bool calib_step_fixed(FlightEstimator<Q30>& e) noexcept;
bool calib_step_float(FlightEstimator<float>& e) noexcept;

// The entries for scalar T, for code templated on it.
inline const ThermalModel<Q30>* calib_model(FlightEstimator<Q30>& e, std::int64_t t_us) noexcept {
    return calib_model_fixed(e, t_us);
}
inline const ThermalModel<float>* calib_model(FlightEstimator<float>& e, std::int64_t t_us) noexcept {
    return calib_model_float(e, t_us);
}
inline bool calib_feed(FlightEstimator<Q30>& e, std::int64_t t_us, const ThermalModel<Q30>* model,
                       const CorrectedSolution<Q30>* corrected, const HeadTemperatures<Q30>* const* temperatures,
                       std::uint8_t further) noexcept {
    return calib_feed_fixed(e, t_us, model, corrected, temperatures, further);
}
inline bool calib_feed(FlightEstimator<float>& e, std::int64_t t_us, const ThermalModel<float>* model,
                       const CorrectedSolution<float>* corrected, const HeadTemperatures<float>* const* temperatures,
                       std::uint8_t further) noexcept {
    return calib_feed_float(e, t_us, model, corrected, temperatures, further);
}
inline bool calib_feed_head(FlightEstimator<Q30>& e, std::uint8_t h, std::int64_t t_us, const ThermalModel<Q30>* model,
                            const CorrectedSolution<Q30>& corrected,
                            const HeadTemperatures<Q30>& temperatures) noexcept {
    return calib_feed_head_fixed(e, h, t_us, model, corrected, temperatures);
}
inline bool calib_feed_head(FlightEstimator<float>& e, std::uint8_t h, std::int64_t t_us,
                            const ThermalModel<float>* model, const CorrectedSolution<float>& corrected,
                            const HeadTemperatures<float>& temperatures) noexcept {
    return calib_feed_head_float(e, h, t_us, model, corrected, temperatures);
}
inline bool calib_step(FlightEstimator<Q30>& e) noexcept {
    return calib_step_fixed(e);
}
inline bool calib_step(FlightEstimator<float>& e) noexcept {
    return calib_step_float(e);
}

}  // namespace ascorr::app
