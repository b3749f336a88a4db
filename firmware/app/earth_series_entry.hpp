// firmware/app/earth_series_entry.hpp: the Earth ephemeris series
// (ascorr/nav/earth_series.hpp) compiled once for the DPU, out of line.
//
// Conventions: as earth_series() (TT seconds since J2000.0; ICRF axes, km/s;
// au). In its own translation unit (earth_series_entry.cpp) so that its flash
// (.text/.rodata of that object: code and coefficient table) and its stack
// (-fstack-usage) are measured alone; it calls libm's sin, cos and remainder.
#pragma once

#include "ascorr/nav/earth_series.hpp"

namespace ascorr::app {

bool earth_series_entry(double t_tt_j2000_s, EarthBarycentric& out) noexcept;

}  // namespace ascorr::app
