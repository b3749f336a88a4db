// The Earth's velocity: interpolated grid against direct eraEpv00 calls.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "ascorr/constants.hpp"
#include "ascorr_host/earth_velocity.hpp"

namespace ascorr::host {
namespace {

TEST(EarthVelocity, InterpolationMatchesDirectCalls) {
    EarthVelocity earth;
    std::mt19937_64 rng(11);
    // 2013 (Swarm launch) to 2030, seconds since J2000 TT.
    std::uniform_real_distribution<double> t(13.9 * 365.25 * 86400.0, 30.0 * 365.25 * 86400.0);
    double worst_v = 0.0;
    double worst_s = 0.0;
    for (int i = 0; i < 20000; ++i) {
        const double ti = t(rng);
        const EarthState a = earth.at(ti);
        const EarthState b = earth_state_exact(ti);
        const double dv = std::hypot(a.v_bary_kms.x - b.v_bary_kms.x, a.v_bary_kms.y - b.v_bary_kms.y,
                                     a.v_bary_kms.z - b.v_bary_kms.z);
        worst_v = std::max(worst_v, dv);
        worst_s = std::max(worst_s, std::abs(a.sun_distance_au - b.sun_distance_au));
        const double speed = std::hypot(b.v_bary_kms.x, b.v_bary_kms.y, b.v_bary_kms.z);
        ASSERT_GT(speed, 28.5);  // perihelion ~30.3, aphelion ~29.3 km/s, plus the lunar wobble
        ASSERT_LT(speed, 31.0);
        ASSERT_GT(b.sun_distance_au, 0.98);
        ASSERT_LT(b.sun_distance_au, 1.02);
    }
    std::printf("earth velocity interpolation: max %.3g km/s (%.3g arcsec of aberration)\n", worst_v,
                worst_v / kSpeedOfLightKmS * kRadToArcsec);
    EXPECT_LT(worst_v, 1e-6);  // 7e-7" of aberration; the stated bound is 6e-8 km/s
    EXPECT_LT(worst_s, 1e-9);
}

TEST(EarthVelocity, SequentialAccessAgreesWithRandomAccess) {
    EarthVelocity seq;
    for (double ti = 4.5e8; ti < 4.5e8 + 7200.0; ti += 1.0) {
        const EarthState a = seq.at(ti);
        EarthVelocity one;
        const EarthState b = one.at(ti);
        ASSERT_EQ(a.v_bary_kms.x, b.v_bary_kms.x);
        ASSERT_EQ(a.sun_distance_au, b.sun_distance_au);
    }
}

}  // namespace
}  // namespace ascorr::host
