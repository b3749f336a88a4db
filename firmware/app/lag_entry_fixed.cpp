// firmware/app/lag_entry_fixed.cpp: the fixed-point (Q30) lag stage, out of line.
#include "lag_entry.hpp"

namespace ascorr::app {

void lag_fixed(pipeline::HeadLags<Q30>& lags, std::uint8_t head, std::int64_t t_us,
               HeadTemperatures<Q30>& temps) noexcept {
    lags.apply(head, t_us, temps);
}

}  // namespace ascorr::app
