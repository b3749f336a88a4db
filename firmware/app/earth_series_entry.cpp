// firmware/app/earth_series_entry.cpp: the Earth ephemeris series, out of line.
#include "earth_series_entry.hpp"

namespace ascorr::app {

bool earth_series_entry(double t_tt_j2000_s, EarthBarycentric& out) noexcept {
    return earth_series(t_tt_j2000_s, out);
}

}  // namespace ascorr::app
