#include "ascorr_host/earth_velocity.hpp"

#include <erfa.h>

#include <cmath>

#include "ascorr/constants.hpp"

namespace ascorr::host {

EarthState earth_state_exact(double t) {
    double pvh[2][3];
    double pvb[2][3];
    constexpr double kJ2000 = 2451545.0;
    // Split the date so that the fraction keeps full precision.
    const double days = t / 86400.0;
    (void)eraEpv00(kJ2000, days, pvh, pvb);  // status 1 (outside 1900–2100) only warns
    constexpr double kAuPerDayToKmS = kAstronomicalUnitKm / 86400.0;
    EarthState s;
    s.v_bary_kms = {pvb[1][0] * kAuPerDayToKmS, pvb[1][1] * kAuPerDayToKmS, pvb[1][2] * kAuPerDayToKmS};
    s.sun_distance_au = std::sqrt(pvh[0][0] * pvh[0][0] + pvh[0][1] * pvh[0][1] + pvh[0][2] * pvh[0][2]);
    return s;
}

const EarthState& EarthVelocity::node(std::int64_t index) {
    Node& n = nodes_[static_cast<std::uint64_t>(index) & 3U];
    if (n.index != index) {
        n.index = index;
        n.state = earth_state_exact(static_cast<double>(index) * kNodeSpacingS);
    }
    return n.state;
}

EarthState EarthVelocity::at(double t) {
    const double u = t / kNodeSpacingS;
    const double fl = std::floor(u);
    const auto i = static_cast<std::int64_t>(fl);
    const double f = u - fl;
    const EarthState a = node(i);
    const EarthState& b = node(i + 1);
    const auto lerp = [f](double x, double y) { return x + f * (y - x); };
    return {{lerp(a.v_bary_kms.x, b.v_bary_kms.x), lerp(a.v_bary_kms.y, b.v_bary_kms.y),
             lerp(a.v_bary_kms.z, b.v_bary_kms.z)},
            lerp(a.sun_distance_au, b.sun_distance_au)};
}

}  // namespace ascorr::host
