// firmware/app/calib_entry_float.cpp: the estimator's per-cycle part in float, out of line.
#include "calib_entry.hpp"

namespace ascorr::app {

const ThermalModel<float>* calib_model_float(FlightEstimator<float>& e, std::int64_t t_us) noexcept {
    return e.model_for_cycle(t_us);
}

bool calib_feed_float(FlightEstimator<float>& e, std::int64_t t_us, const ThermalModel<float>* model,
                      const CorrectedSolution<float>* corrected, const HeadTemperatures<float>* const* temperatures,
                      std::uint8_t further) noexcept {
    return feed_estimator(e, t_us, model, corrected, temperatures, further);
}

bool calib_feed_head_float(FlightEstimator<float>& e, std::uint8_t h, std::int64_t t_us,
                           const ThermalModel<float>* model, const CorrectedSolution<float>& corrected,
                           const HeadTemperatures<float>& temperatures) noexcept {
    return feed_estimator_head(e, h, t_us, model, corrected, temperatures);
}

}  // namespace ascorr::app
