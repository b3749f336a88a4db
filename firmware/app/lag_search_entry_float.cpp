// firmware/app/lag_search_entry_float.cpp: the lag search (float), out of line.
#include "lag_search_entry.hpp"

namespace ascorr::app {

bool lag_search_take_float(calib::LagSearch<float>& search, std::int64_t t_us, const ThermalModel<float>& model,
                           const CorrectedSolution<float>* corrected,
                           const HeadTemperatures<float>* const* temperatures) noexcept {
    return search.take(t_us, model, corrected, temperatures);
}

}  // namespace ascorr::app
