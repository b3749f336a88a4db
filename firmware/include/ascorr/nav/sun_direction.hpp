// ascorr/nav/sun_direction.hpp: the Sun's geocentric direction, low precision,
// as a regressor of the thermal model (the Sun heating one side of the
// spacecraft), which needs about 0.01°.
//
// Conventions:
//  - Time: t_tt_j2000_s, TT seconds since J2000.0 (2000-01-01 12:00 TT), as
//    everywhere in ascorr; n = t/86400 days, T = n/36525 Julian centuries.
//    At 0.01° any of TT, TDB and UT1 would do: 70 s move the Sun by 2.9″.
//  - Frame: s_icrf, a unit vector in ICRF axes, taken as the mean equator and
//    equinox of J2000.0 (they differ by the frame bias, 0.023″).
//  - What: the geometric direction from the Earth's centre to the Sun's centre
//    at t: no light-time, no aberration, no nutation. It is what the reference
//    −(eraEpv00's heliocentric Earth position) points to.
//  - Span: that of the Earth series, kEarthSeriesFirstTt .. kEarthSeriesLastTt
//    (earth_series.hpp; 2000-01-01 00:00 TT .. 2051-01-01 00:00 TT, both
//    included). Outside, and for NaN or ±inf, sun_direction_icrf() returns
//    false and leaves its output untouched.
//
// The method: the Astronomical Almanac, section C5, "Low precision formulas
// for the Sun" (0.01° over 1950–2050), its ecliptic longitude λ on the mean
// equinox of date, moved to the fixed J2000 equinox by subtracting the general
// precession in longitude p_A, then turned to the equator by the J2000
// obliquity ε₀. The ecliptic latitude is taken as zero; left out:
//  - the ecliptic's own precession: the ecliptic of date is tilted from that
//    of J2000 by π_A = 47.0″ T, so the Sun's latitude over the J2000 ecliptic
//    grows to 24″ at the end of the span (the Sun's latitude over the ecliptic
//    of date, the Moon's and the planets' pull, adds ≤ 1.2″);
//  - the annual aberration (−20.5″ in longitude), which the AA's λ includes
//    (its coordinates are apparent): restoring it would move the mean
//    longitude error from +12.5″ to −8″ and raise the maximum from 41.5″ to
//    42.5″, since the formula's own longitude error (−19″ .. +41″) dominates.
//
// Error against liberfa (tests/test_sun_direction.cpp: every 0.5 day of the
// span and 20,000 random epochs, angle to −eraEpv00's heliocentric position):
// 41.5″ (0.0115°) measured, at 2025-09-29, 60″ asserted.
//
// No allocation, no exceptions, no loops; std::remainder is called with
// finite arguments only; sin and cos come from sincos.hpp (the same bits on
// every platform, as for the rest of nav/), divisions by constants are
// products with their reciprocals (soft-float division is slow on the M3).
#pragma once

#include <cmath>

#include "../core/constants.hpp"
#include "../core/vector3.hpp"
#include "earth_series.hpp"
#include "sincos.hpp"

namespace ascorr::nav {

namespace detail {

// General precession in longitude, IAU 2006 (Capitaine et al. 2003, P03: p_A =
// 5028.796195″ T + 1.105″ T² + …; the T² term is ≤ 0.3″ over the span), °/century.
inline constexpr double kGeneralPrecessionDegPerCentury = 5028.796195 / 3600.0;

// Mean obliquity of the ecliptic at J2000.0, IAU 2006 (Capitaine et al. 2003):
// ε₀ = 84381.406″ = 23.4392794°, as sine and cosine.
inline constexpr SinCos kObliquityJ2000 = sincos_turns(84381.406 / (3600.0 * 360.0));

// sin and cos of an angle in degrees, reduced exactly (IEEE remainder) to
// [−180°, 180°] first, so that sincos_turns sees |f| ≤ 1/2.
inline SinCos sincos_deg(double deg) noexcept {
    return sincos_turns(std::remainder(deg, 360.0) * (1.0 / 360.0));
}

// The Sun's ecliptic longitude, mean equinox of date, degrees, not reduced;
// n TT days from J2000.0. Astronomical Almanac, section C5:
//     g = 357.528° + 0.9856003° n   (mean anomaly)
//     L = 280.460° + 0.9856474° n   (mean longitude, aberration included)
//     λ = L + 1.915° sin g + 0.020° sin 2g   (equation of the centre).
inline double sun_longitude_of_date_deg(double n_days) noexcept {
    const SinCos g = sincos_deg(357.528 + 0.9856003 * n_days);
    const double sin_2g = 2.0 * g.s * g.c;  // one sincos for both harmonics
    return 280.460 + 0.9856474 * n_days + 1.915 * g.s + 0.020 * sin_2g;
}

// The same longitude on the fixed J2000 equinox: λ_J2000 = λ_date − p_A(T),
// the equinox having moved p_A along the ecliptic since J2000.0.
inline double sun_longitude_j2000_deg(double n_days) noexcept {
    const double centuries = n_days * (1.0 / 36525.0);
    return sun_longitude_of_date_deg(n_days) - kGeneralPrecessionDegPerCentury * centuries;
}

}  // namespace detail

// true, and the unit vector s_icrf, for a finite t within the Earth series' span
// [kEarthSeriesFirstTt, kEarthSeriesLastTt] (earth_series.hpp); false otherwise, s_icrf untouched.
inline bool sun_direction_icrf(double t_tt_j2000_s, Vector3<double>& s_icrf) noexcept {
    // NaN fails both comparisons; ±inf fails one.
    if (!(t_tt_j2000_s >= kEarthSeriesFirstTt && t_tt_j2000_s <= kEarthSeriesLastTt)) {
        return false;
    }
    const SinCos lambda = detail::sincos_deg(detail::sun_longitude_j2000_deg(t_tt_j2000_s * (1.0 / kSecondsPerDay)));
    // Ecliptic (cos λ, sin λ, 0) turned about x by −ε₀ to the equator; unit
    // norm to rounding, since cos² + sin² = 1 for both angles.
    constexpr SinCos eps = detail::kObliquityJ2000;
    s_icrf = {lambda.c, eps.c * lambda.s, eps.s * lambda.s};
    return true;
}

}  // namespace ascorr::nav
