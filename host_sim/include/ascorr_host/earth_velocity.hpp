// ascorr_host/earth_velocity.hpp: the Earth's barycentric velocity from ERFA.
//
// eraEpv00 gives the Earth's barycentric and heliocentric position and
// velocity (ICRF/BCRS axes, au and au/day) for a TDB date. Our times are TT;
// TDB − TT ≤ 1.7 ms, in which the Earth's velocity changes by < 1e-8 km/s.
//
// eraEpv00 sums a few thousand terms (~7 µs here), too slow to call for each
// of a million solutions, so EarthVelocity evaluates it on a 600 s grid and
// interpolates linearly. The interpolation error is ≤ v·ω²·h²/8 from the
// yearly motion (5e-8 km/s) plus the lunar wobble (4e-9 km/s): below 2e-13 rad,
// 4e-8", of aberration. tests/test_earth_velocity.cpp checks it against direct
// calls.
#pragma once

#include <cstdint>

#include "ascorr/vector3.hpp"

namespace ascorr::host {

struct EarthState {
    Vector3<double> v_bary_kms;  // Earth barycentric velocity, ICRF axes, km/s
    double sun_distance_au;      // heliocentric distance of the Earth, au
};

// Direct evaluation of eraEpv00 at t (s since J2000.0, TT).
EarthState earth_state_exact(double t);

class EarthVelocity {
public:
    static constexpr double kNodeSpacingS = 600.0;
    EarthState at(double t);

private:
    struct Node {
        std::int64_t index = INT64_MIN;
        EarthState state{};
    };
    const EarthState& node(std::int64_t index);
    Node nodes_[4];  // small direct-mapped cache: sequential data hits it
};

}  // namespace ascorr::host
