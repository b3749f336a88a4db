// firmware/app/lag_entry_fixed.cpp: the fixed-point (Q30) lag stage, out of line.
#include "lag_entry.hpp"

namespace ascorr::app {

void lag_fixed(pipeline::HeadLags<Q30>& lags, HeadTemperatures<Q30>& temps, std::int64_t t_us,
               std::uint8_t head) noexcept {
    lags.apply(head, t_us, temps);
}

}  // namespace ascorr::app
