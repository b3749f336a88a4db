// The Earth's velocity: the per-day Chebyshev table against direct eraEpv00
// calls, over the whole span of the ephemeris, in any order, from any thread.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <thread>
#include <vector>

#include "ascorr/core/constants.hpp"
#include "ascorr_host/correct/earth_velocity.hpp"

namespace ascorr::host {
namespace {

double velocity_error(const EarthState& a, const EarthState& b) {
    return std::hypot(a.v_bary_kms.x - b.v_bary_kms.x, a.v_bary_kms.y - b.v_bary_kms.y,
                      a.v_bary_kms.z - b.v_bary_kms.z);
}

TEST(EarthVelocity, TableMatchesDirectCallsOverTheWholeSpan) {
    const EarthVelocity earth;
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<double> t(kEphemerisFirstT, kEphemerisEndT);
    double worst_v = 0.0;
    double worst_s = 0.0;
    for (int i = 0; i < 3000; ++i) {
        // Half anywhere in 1900–2100, half within a few seconds of a segment boundary.
        double ti = t(rng);
        if (i % 2 == 1) {
            const double seg = EarthVelocity::kSegmentS;
            ti = kEphemerisFirstT + std::round((ti - kEphemerisFirstT) / seg) * seg + (t(rng) * 1e-9 - 1.0);
            ti = std::clamp(ti, kEphemerisFirstT, std::nextafter(kEphemerisEndT, 0.0));
        }
        const EarthState a = earth.at(ti);
        const EarthState b = earth_state_exact(ti);
        ASSERT_TRUE(a.valid && b.valid);
        worst_v = std::max(worst_v, velocity_error(a, b));
        worst_s = std::max(worst_s, std::abs(a.sun_distance_au - b.sun_distance_au));
        const double speed = std::hypot(b.v_bary_kms.x, b.v_bary_kms.y, b.v_bary_kms.z);
        ASSERT_GT(speed, 28.5);  // perihelion ~30.3, aphelion ~29.3 km/s, plus the lunar wobble
        ASSERT_LT(speed, 31.0);
        ASSERT_GT(b.sun_distance_au, 0.98);
        ASSERT_LT(b.sun_distance_au, 1.02);
    }
    std::printf("earth velocity table: max %.3g km/s (%.3g arcsec of aberration), sun distance %.3g au\n", worst_v,
                worst_v / kSpeedOfLightKmS * kRadToArcsec, worst_s);
    EXPECT_LT(worst_v, 5e-9);  // 3.4e-9" of aberration (measured 1.8e-9 km/s)
    EXPECT_LT(worst_s, 5e-12);
}

TEST(EarthVelocity, ATimeOutsideTheEphemerisIsInvalid) {
    const EarthVelocity earth;
    const double ms = 7.5e8 * 1000.0;  // 2023 given in milliseconds
    for (const double t : {ms, -ms, kEphemerisEndT, std::nextafter(kEphemerisFirstT, -1e300), std::nan(""), HUGE_VAL}) {
        EXPECT_FALSE(earth.at(t).valid) << t;
        EXPECT_FALSE(in_ephemeris_span(t)) << t;
    }
    EXPECT_TRUE(earth.at(kEphemerisFirstT).valid);
    EXPECT_TRUE(earth.at(std::nextafter(kEphemerisEndT, 0.0)).valid);
}

TEST(EarthVelocity, AnyOrderAndAnyThreadGiveTheSameValues) {
    std::vector<double> ts;
    for (double ti = 4.5e8; ti < 4.5e8 + 3.0 * 86400.0; ti += 7.0) {
        ts.push_back(ti);
    }
    std::mt19937_64 rng(3);
    for (int i = 0; i < 2000; ++i) {
        ts.push_back(std::uniform_real_distribution<double>(-9e8, 9e8)(rng));
    }
    std::vector<EarthState> seq(ts.size());
    std::vector<std::size_t> order(ts.size());
    for (std::size_t i = 0; i < ts.size(); ++i) {
        order[i] = i;
    }
    std::shuffle(order.begin(), order.end(), rng);
    // Four threads fill the table concurrently in shuffled order...
    std::vector<std::vector<EarthState>> got(4, std::vector<EarthState>(ts.size()));
    std::vector<std::thread> threads;
    for (std::size_t k = 0; k < 4; ++k) {
        threads.emplace_back([&, k] {
            const EarthVelocity earth;
            for (std::size_t j = 0; j < order.size(); ++j) {
                const std::size_t i = order[(j + k * 997) % order.size()];
                got[k][i] = earth.at(ts[i]);
            }
        });
    }
    for (auto& t : threads) {
        t.join();
    }
    // ... and agree bit for bit with each other and with a sequential pass.
    const EarthVelocity earth;
    for (std::size_t i = 0; i < ts.size(); ++i) {
        const EarthState s = earth.at(ts[i]);
        for (std::size_t k = 0; k < 4; ++k) {
            ASSERT_EQ(got[k][i].v_bary_kms.x, s.v_bary_kms.x);
            ASSERT_EQ(got[k][i].v_bary_kms.z, s.v_bary_kms.z);
            ASSERT_EQ(got[k][i].sun_distance_au, s.sun_distance_au);
        }
    }
}

}  // namespace
}  // namespace ascorr::host
