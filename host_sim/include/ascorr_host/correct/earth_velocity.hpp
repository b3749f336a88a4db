// ascorr_host/correct/earth_velocity.hpp: the Earth's barycentric velocity from ERFA.
//
// eraEpv00 gives the Earth's barycentric and heliocentric position and
// velocity (ICRF/BCRS axes, au and au/day) for a TDB date. Our times are TT;
// TDB − TT ≤ 1.7 ms, in which the Earth's velocity changes by < 1e-8 km/s.
// eraEpv00 is valid from 1900 to 2100 (kEphemerisFirstT, kEphemerisEndT);
// outside that span at() says `valid = false` and the caller flags the row
// (status 4 + 32): a time in milliseconds, say, is not silently corrected.
//
// eraEpv00 sums a few thousand terms (~7 µs here), too slow to call for each
// of a million solutions. So the span is cut into segments of kSegmentS (16
// days), and each segment's velocity and Sun distance are a Chebyshev series
// of degree kDegree, interpolating eraEpv00 at its kDegree + 1 Chebyshev
// nodes. The cost of a row does not depend on row order or time span: its
// segment is found by direct indexing into one table for the whole span,
// filled on first use (kDegree + 1 = 16 eraEpv00 calls per segment touched,
// one per day, once per process) and shared by all threads (a segment is
// filled under one of 64 striped mutexes and published with a release store;
// readers check it with an acquire load). The heads of one epoch share their
// t: each thread keeps the last t it was asked and its answer.
//
// Truncation: the fastest terms of the Earth's barycentric velocity are the
// lunar ones (monthly, 0.0126 km/s; half-monthly, ~1e-4 km/s); for
// L = 16 days and the half-monthly term ωL/2 ≈ 3.7, the degree-15 error
// bound A·(ωL/2)^16/(2^15·16!) is ~3e-9 km/s. Measured against direct calls:
// ≤ 1.8e-9 km/s (1.2e-9" of aberration) and 7.5e-13 au; the test,
// tests/test_earth_velocity.cpp, bounds them at 5e-9 km/s and 5e-12 au.
// (Other choices measured: 1 day/degree 7, 7e-12 km/s at 8 calls a day;
// 8 days/degree 11, 1.3e-10 km/s at 1.5; 32 days/degree 19, 4.6e-7 km/s.)
#pragma once

#include <cstdint>

#include "ascorr/core/constants.hpp"
#include "ascorr/core/vector3.hpp"

namespace ascorr::host {

struct EarthState {
    Vector3<double> v_bary_kms;  // Earth barycentric velocity, ICRF axes, km/s
    double sun_distance_au;      // heliocentric distance of the Earth, au
    bool valid = true;           // false: t outside [kEphemerisFirstT, kEphemerisEndT)
};

// 1900-01-01 0h and 2100-01-01 0h TT, s since J2000.0 (the span of eraEpv00).
inline constexpr double kEphemerisFirstT = (2415020.5 - kJ2000JulianDate) * kSecondsPerDay;
inline constexpr double kEphemerisEndT = (2488069.5 - kJ2000JulianDate) * kSecondsPerDay;

// Direct evaluation of eraEpv00 at t (s since J2000.0, TT); valid as above.
EarthState earth_state_exact(double t);

// True when t is inside the span of the ephemeris (false for NaN).
bool in_ephemeris_span(double t) noexcept;

class EarthVelocity {
public:
    static constexpr int kDegree = 15;
    static constexpr double kSegmentS = 16.0 * kSecondsPerDay;
    // Thread-safe; all instances share one table.
    EarthState at(double t) const;
};

}  // namespace ascorr::host
