// ascorr/core/constants.hpp: physical constants and the validity domain of the core.
//
// Values are doubles; the core converts them to its scalar type with constant<T>().
// The domain limits are where the core's truncated series stop meeting their
// error bounds (stated in aberration.hpp and thermal.hpp); inputs outside them
// are flagged and the stage is skipped, never evaluated.
#pragma once

namespace ascorr {

inline constexpr double kSpeedOfLightKmS = 299792.458;      // km/s (exact)
inline constexpr double kAstronomicalUnitKm = 149597870.7;  // km (IAU 2012, exact)
inline constexpr double kPi = 3.14159265358979323846;
inline constexpr double kArcsecToRad = kPi / (180.0 * 3600.0);
inline constexpr double kRadToArcsec = 1.0 / kArcsecToRad;
inline constexpr double kDegToRad = kPi / 180.0;
inline constexpr double kSecondsPerDay = 86400.0;      // s, the day of Julian dates and of TT
inline constexpr double kJ2000JulianDate = 2451545.0;  // J2000.0 (2000 January 1, 12h TT) as a Julian date
// Schwarzschild radius of the Sun in au (ERFA_SRS), for the solar-potential
// term of stellar aberration.
inline constexpr double kSunSchwarzschildRadiusAu = 1.97412574336e-8;

// Largest observer speed the aberration series accepts: 1000 km/s, 26 times
// what a near-Earth observer reaches (30 km/s orbital + 8 km/s LEO). |v| ≥ c
// and anything non-physical for a spacecraft are rejected by the same test.
inline constexpr double kMaxObserverSpeedKmS = 1000.0;
inline constexpr double kMaxBeta = kMaxObserverSpeedKmS / kSpeedOfLightKmS;  // 3.34e-3

// Heliocentric distance of the observer the aberration stage accepts, au: from
// inside Venus's perihelion (0.72 au) to beyond Neptune (30 au). Swarm sees
// 0.983–1.017 au. The distance enters only the solar-potential term (≤ 4e-7"
// at 1 au, ∝ 1/s), but a corrupted 1/s (1e9) would turn that term into
// hundreds of arcseconds; outside this range the velocity is unusable (4|32).
// Q30 holds 1/s up to 2 − 2⁻³⁰, so the upper end of 1/s must stay below 2.
inline constexpr double kMinSunDistanceAu = 0.6;
inline constexpr double kMaxSunDistanceAu = 40.0;

// Largest thermal rotation angle the small-angle series accepts: 1 degree.
// The paper's angles are below 100"; a model that asks for more than 1° is
// applied to temperatures it was not made for.
inline constexpr double kMaxThermalAngleRad = kPi / 180.0;

// Plausible temperature range of a µASC head or optical-bench thermistor.
// Beyond it a reading is a sensor fault, not a temperature.
inline constexpr double kMaxAbsTemperatureC = 200.0;

}  // namespace ascorr
