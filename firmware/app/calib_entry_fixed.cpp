// firmware/app/calib_entry_fixed.cpp: the estimator's per-cycle part in Q30, out of line.
#include "calib_entry.hpp"

namespace ascorr::app {

const ThermalModel<Q30>* calib_model_fixed(FlightEstimator<Q30>& e, std::int64_t t_us) noexcept {
    return e.model_for_cycle(t_us);
}

bool calib_feed_fixed(FlightEstimator<Q30>& e, std::int64_t t_us, const ThermalModel<Q30>* model,
                      const CorrectedSolution<Q30>* corrected, const HeadTemperatures<Q30>* const* temperatures,
                      std::uint8_t further) noexcept {
    return feed_estimator(e, t_us, model, corrected, temperatures, further);
}

bool calib_feed_head_fixed(FlightEstimator<Q30>& e, std::uint8_t h, std::int64_t t_us, const ThermalModel<Q30>* model,
                           const CorrectedSolution<Q30>& corrected,
                           const HeadTemperatures<Q30>& temperatures) noexcept {
    return feed_estimator_head(e, h, t_us, model, corrected, temperatures);
}

}  // namespace ascorr::app
