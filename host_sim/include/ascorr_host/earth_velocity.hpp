// ascorr_host/earth_velocity.hpp: the Earth's barycentric velocity from ERFA.
//
// eraEpv00 gives the Earth's barycentric and heliocentric position and
// velocity (ICRF/BCRS axes, au and au/day) for a TDB date. Our times are TT;
// TDB − TT ≤ 1.7 ms, in which the Earth's velocity changes by < 1e-8 km/s.
// eraEpv00 is valid from 1900 to 2100 (kEphemerisFirstT, kEphemerisEndT);
// outside that span at() says `valid = false` and the caller flags the row
// (status 4 + 32): a time in milliseconds, say, is not silently corrected.
//
// eraEpv00 sums a few thousand terms (~7 µs here), too slow to call for each
// of a million solutions. So the span is cut into days, and each day's
// velocity and Sun distance are a Chebyshev series of degree kDegree fitted
// at its kDegree + 1 Chebyshev nodes (interpolation at the nodes). The cost of
// a row does not depend on row order or time span: the day's segment is found
// by direct indexing into one table for the whole span, filled on first use
// (kDegree + 1 eraEpv00 calls per day touched, once per process) and shared
// by all threads (a segment is published with a release store after it is
// filled under a mutex; readers check it with an acquire load).
//
// Truncation: the fastest terms of the Earth's barycentric velocity are the
// lunar monthly wobble (0.0126 km/s, 27.3 d) and the yearly motion (30 km/s);
// for a day, ωL/2 ≤ 0.115 and the degree-7 interpolation error is below
// A·(ωL/2)^8/(2^7·8!) ≈ 7e-17 km/s for the Moon's term, so what remains is
// rounding and the series' own short terms: measured ≤ 1.4e-11 km/s (1e-11") against direct calls,
// tests/test_earth_velocity.cpp (bound 1e-10 km/s in the test).
#pragma once

#include <cstdint>

#include "ascorr/vector3.hpp"

namespace ascorr::host {

struct EarthState {
    Vector3<double> v_bary_kms;  // Earth barycentric velocity, ICRF axes, km/s
    double sun_distance_au;      // heliocentric distance of the Earth, au
    bool valid = true;           // false: t outside [kEphemerisFirstT, kEphemerisEndT)
};

// 1900-01-01 0h and 2100-01-01 0h TT, s since J2000.0 (the span of eraEpv00).
inline constexpr double kEphemerisFirstT = (2415020.5 - 2451545.0) * 86400.0;
inline constexpr double kEphemerisEndT = (2488069.5 - 2451545.0) * 86400.0;

// Direct evaluation of eraEpv00 at t (s since J2000.0, TT); valid as above.
EarthState earth_state_exact(double t);

// True when t is inside the span of the ephemeris (false for NaN).
bool in_ephemeris_span(double t) noexcept;

class EarthVelocity {
public:
    static constexpr int kDegree = 7;
    static constexpr double kSegmentS = 86400.0;
    // Thread-safe; all instances share one table.
    EarthState at(double t) const;
};

}  // namespace ascorr::host
