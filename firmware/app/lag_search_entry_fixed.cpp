// firmware/app/lag_search_entry_fixed.cpp: the lag search (fixed), out of line.
#include "lag_search_entry.hpp"

namespace ascorr::app {

bool lag_search_take_fixed(calib::LagSearch<Q30>& search, std::int64_t t_us, const ThermalModel<Q30>& model,
                           const CorrectedSolution<Q30>* corrected,
                           const HeadTemperatures<Q30>* const* temperatures) noexcept {
    return search.take(t_us, model, corrected, temperatures);
}

}  // namespace ascorr::app
