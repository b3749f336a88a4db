// The on-board Earth ephemeris series (ascorr/nav/earth_series.hpp) against
// liberfa's eraEpv00: barycentric velocity and Sun distance over the whole
// span, the refusals, a mutation check, and linear interpolation between
// evaluations N seconds apart (how the velocity service uses it).
#include <erfa.h>
#include <erfam.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include "ascorr/core/constants.hpp"
#include "ascorr/nav/earth_series.hpp"

namespace ascorr {
namespace {

constexpr double kDay = kSecondsPerDay;
constexpr double kKmPerAu = kAstronomicalUnitKm;
constexpr double kVelocityBoundMs = 3.0;   // the requirement
constexpr double kDistanceBoundAu = 1e-5;  // the issue asks 1e-4 au; the series reaches 9.1e-6
constexpr double kInterpolationBoundMs = 0.01;

struct Reference {
    double t;
    double v_kms[3];
    double s_au;
};

Reference erfa_reference(double t) {
    double pvh[2][3];
    double pvb[2][3];
    (void)eraEpv00(ERFA_DJ00, t / kDay, pvh, pvb);  // status 1 (outside 1900-2100) cannot occur in the span
    Reference r{t, {}, std::sqrt(pvh[0][0] * pvh[0][0] + pvh[0][1] * pvh[0][1] + pvh[0][2] * pvh[0][2])};
    for (int i = 0; i < 3; ++i) {
        r.v_kms[i] = pvb[1][i] * kKmPerAu / kDay;  // au/day -> km/s
    }
    return r;
}

// The span sampled every `step` (offset by 0.123 day, so that the grid is
// not the generator's one-day fitting grid), both ends, and `random` random
// epochs.
std::vector<Reference> references(double step, int random) {
    std::vector<Reference> r;
    for (double t = kEarthSeriesFirstTt + 0.123 * kDay; t < kEarthSeriesLastTt; t += step) {
        r.push_back(erfa_reference(t));
    }
    r.push_back(erfa_reference(kEarthSeriesFirstTt));
    r.push_back(erfa_reference(kEarthSeriesLastTt));
    std::mt19937_64 rng(12);
    std::uniform_real_distribution<double> u(kEarthSeriesFirstTt, kEarthSeriesLastTt);
    for (int i = 0; i < random; ++i) {
        r.push_back(erfa_reference(u(rng)));
    }
    return r;
}

struct Errors {
    double dv_ms = 0.0;  // largest |Δv|, m/s
    double ds_au = 0.0;  // largest |Δs|, au
    double t_dv = 0.0;   // where
};

// `omitted`: a term of the series left out (-1: none).
Errors max_errors(const std::vector<Reference>& refs, int omitted) {
    Errors e;
    for (const Reference& r : refs) {
        EarthBarycentric b{};
        EXPECT_TRUE(detail::earth_series_omitting(r.t, b, omitted)) << "t = " << r.t;
        const double dv = 1000.0 * std::hypot(b.v_earth_icrf_kms.x - r.v_kms[0], b.v_earth_icrf_kms.y - r.v_kms[1],
                                              b.v_earth_icrf_kms.z - r.v_kms[2]);
        if (dv > e.dv_ms) {
            e.dv_ms = dv;
            e.t_dv = r.t;
        }
        e.ds_au = std::max(e.ds_au, std::abs(b.sun_distance_au - r.s_au));
    }
    return e;
}

TEST(EarthSeries, MatchesErfaEpv00OverTheWholeSpan) {
    // At least 2000-01-01 00:00 .. 2050-12-31 24:00 TT (the issue), in TT seconds
    // since J2000.0 (2000-01-01 12:00 TT): 51 years with 13 leap days.
    EXPECT_LE(kEarthSeriesFirstTt, -0.5 * kDay);
    EXPECT_GE(kEarthSeriesLastTt, (51 * 365 + 13 - 0.5) * kDay);
    // Every half day and 20,000 random epochs: 57,258 eraEpv00 calls.
    const std::vector<Reference> refs = references(0.5 * kDay, 20000);
    const Errors e = max_errors(refs, -1);
    std::printf("earth series vs eraEpv00, %zu epochs: |dv| max %.3f m/s (at t = %.0f s), |ds| max %.3g au\n",
                refs.size(), e.dv_ms, e.t_dv, e.ds_au);
    EXPECT_LT(e.dv_ms, kVelocityBoundMs);
    EXPECT_LT(e.ds_au, kDistanceBoundAu);
}

TEST(EarthSeries, OneEpochAgainstValuesWrittenOut) {
    // 2020-06-01 00:00 TT (JD 2459001.5, 7456.5 days after J2000.0): eraEpv00
    // through python3-erfa, written out, so that the reference helper above is
    // checked too (units, barycentric not heliocentric).
    const double t = 7456.5 * kDay;
    const double v_kms[3] = {27.61277957, -9.13221031, -3.95824084};
    const double s_au = 1.014052985454039;
    const Reference r = erfa_reference(t);
    EarthBarycentric b{};
    ASSERT_TRUE(earth_series(t, b));
    const double series[3] = {b.v_earth_icrf_kms.x, b.v_earth_icrf_kms.y, b.v_earth_icrf_kms.z};
    for (int i = 0; i < 3; ++i) {
        EXPECT_NEAR(r.v_kms[i], v_kms[i], 1e-8);
        EXPECT_NEAR(series[i], v_kms[i], kVelocityBoundMs / 1000.0);
    }
    EXPECT_NEAR(r.s_au, s_au, 1e-12);
    EXPECT_NEAR(b.sun_distance_au, s_au, kDistanceBoundAu);
}

// Refusals: false, and the output untouched (bit for bit).
TEST(EarthSeries, RefusesNonFiniteAndOutOfSpanTimes) {
    const double bad[] = {std::numeric_limits<double>::quiet_NaN(),
                          -std::numeric_limits<double>::quiet_NaN(),
                          std::numeric_limits<double>::infinity(),
                          -std::numeric_limits<double>::infinity(),
                          std::nextafter(kEarthSeriesFirstTt, -1e300),
                          std::nextafter(kEarthSeriesLastTt, 1e300),
                          kEarthSeriesFirstTt - kDay,
                          kEarthSeriesLastTt + kDay,
                          -1e300,
                          1e300,
                          std::numeric_limits<double>::max(),
                          -std::numeric_limits<double>::denorm_min() - 1e10};
    const auto bits = [](double x) {
        std::uint64_t b = 0;
        std::memcpy(&b, &x, sizeof b);
        return b;
    };
    for (double t : bad) {
        const double sentinel = std::numeric_limits<double>::quiet_NaN();  // any write would show
        EarthBarycentric out{{sentinel, -2.5, 3.5}, -0.0};
        EXPECT_FALSE(earth_series(t, out)) << "t = " << t;
        EXPECT_EQ(bits(out.v_earth_icrf_kms.x), bits(sentinel)) << "output changed for t = " << t;
        EXPECT_EQ(bits(out.v_earth_icrf_kms.y), bits(-2.5)) << "t = " << t;
        EXPECT_EQ(bits(out.v_earth_icrf_kms.z), bits(3.5)) << "t = " << t;
        EXPECT_EQ(bits(out.sun_distance_au), bits(-0.0)) << "t = " << t;
    }
    // Both ends are inside.
    EarthBarycentric out{};
    EXPECT_TRUE(earth_series(kEarthSeriesFirstTt, out));
    EXPECT_TRUE(earth_series(kEarthSeriesLastTt, out));
    EXPECT_TRUE(earth_series(0.0, out));
}

// Mutation check: the bound is not vacuous. Leaving out the largest lunar term
// (the Earth about the Earth-Moon barycentre, 12.4 m/s) or the largest Jupiter
// term (the Sun's reflex motion, 12.1 m/s) must break it.
TEST(EarthSeries, MutationDroppingTheLunarOrJupiterTermBreaksTheBound) {
    namespace tb = earth_series_table;
    // Arguments by their rate: monthly (> 2e-6 rad/s: D, l, F) and Jupiter's
    // (period 11.86 yr).
    const double jupiter_rate = 2.0 * kPi / (11.862 * 365.25 * kDay);
    int lunar = -1;
    int jupiter = -1;
    for (int k = 1; k < tb::kTerms; ++k) {  // terms are in decreasing amplitude
        int monthly = 0;
        int others = 0;
        int jup = 0;
        for (int j = 0; j < tb::kArguments; ++j) {
            if (tb::kMultiple[k][j] == 0) {
                continue;
            }
            if (tb::kRateRadS[j] > 2e-6) {
                ++monthly;
            } else if (std::abs(tb::kRateRadS[j] / jupiter_rate - 1.0) < 1e-3) {
                ++jup;
            } else {
                ++others;
            }
        }
        if (lunar < 0 && monthly > 0) {
            lunar = k;
        }
        if (jupiter < 0 && jup > 0 && monthly == 0 && others == 0) {
            jupiter = k;
        }
    }
    ASSERT_GE(lunar, 1);
    ASSERT_GE(jupiter, 1);
    // Every 2 days (the lunar term's period is 27 days, Jupiter's 12 years).
    const std::vector<Reference> refs = references(2.0 * kDay, 0);
    EXPECT_LT(max_errors(refs, -1).dv_ms, kVelocityBoundMs);  // the same grid passes with every term
    const Errors no_moon = max_errors(refs, lunar);
    const Errors no_jupiter = max_errors(refs, jupiter);
    std::printf("without term %d (largest lunar): %.2f m/s; without term %d (Jupiter): %.2f m/s\n", lunar,
                no_moon.dv_ms, jupiter, no_jupiter.dv_ms);
    EXPECT_GT(no_moon.dv_ms, kVelocityBoundMs);
    EXPECT_GT(no_jupiter.dv_ms, kVelocityBoundMs);
}

// The velocity service evaluates the series every N seconds and interpolates
// linearly between evaluations. Chord error at the worst point of each of
// 20,000 random intervals (the midpoint and two others) against the series
// itself, for N = 3600 s (recommended) and N = 600 s.
TEST(EarthSeries, LinearInterpolationBetweenEvaluationsIsNegligible) {
    std::mt19937_64 rng(1212);
    for (double n : {600.0, 3600.0}) {
        std::uniform_real_distribution<double> u(kEarthSeriesFirstTt, kEarthSeriesLastTt - n);
        double worst_v = 0.0;
        double worst_s = 0.0;
        for (int i = 0; i < 20000; ++i) {
            const double t0 = u(rng);
            EarthBarycentric a{};
            EarthBarycentric b{};
            ASSERT_TRUE(earth_series(t0, a));
            ASSERT_TRUE(earth_series(t0 + n, b));
            for (double f : {0.25, 0.5, 0.75}) {
                EarthBarycentric m{};
                ASSERT_TRUE(earth_series(t0 + f * n, m));
                const auto lerp = [f](double x, double y) { return x + f * (y - x); };
                const double dv =
                    1000.0 * std::hypot(lerp(a.v_earth_icrf_kms.x, b.v_earth_icrf_kms.x) - m.v_earth_icrf_kms.x,
                                        lerp(a.v_earth_icrf_kms.y, b.v_earth_icrf_kms.y) - m.v_earth_icrf_kms.y,
                                        lerp(a.v_earth_icrf_kms.z, b.v_earth_icrf_kms.z) - m.v_earth_icrf_kms.z);
                worst_v = std::max(worst_v, dv);
                worst_s = std::max(worst_s, std::abs(lerp(a.sun_distance_au, b.sun_distance_au) - m.sun_distance_au));
            }
        }
        std::printf("linear interpolation, N = %.0f s: |dv| max %.3g m/s, |ds| max %.3g au\n", n, worst_v, worst_s);
        // The chord bounds N^2/8 * max|y''| of earth_series.hpp: |v''| <= 1.4e-9 m/s^3,
        // |s''| <= 1.0e-15 au/s^2.
        EXPECT_LT(worst_v, n * n / 8.0 * 1.4e-9);
        EXPECT_LT(worst_v, kInterpolationBoundMs);
        EXPECT_LT(worst_s, n * n / 8.0 * 1.0e-15);
    }
}

}  // namespace
}  // namespace ascorr
