// firmware/app/lag_entry_float.cpp: the float lag stage, out of line.
#include "lag_entry.hpp"

namespace ascorr::app {

void lag_float(pipeline::HeadLags<float>& lags, HeadTemperatures<float>& temps, std::int64_t t_us,
               std::uint8_t head) noexcept {
    lags.apply(head, t_us, temps);
}

}  // namespace ascorr::app
