// The Sun's geocentric direction (ascorr/nav/sun_direction.hpp) against
// liberfa: −(the Earth's heliocentric position) from eraEpv00 over the whole
// span, the unit norm, the refusals, and a mutation check (the precession to
// the J2000 equinox left out).
#include <erfa.h>
#include <erfam.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <initializer_list>
#include <limits>
#include <random>
#include <vector>

#include "ascorr/core/constants.hpp"
#include "ascorr/core/vector3.hpp"
#include "ascorr/nav/earth_series.hpp"
#include "ascorr/nav/sun_direction.hpp"

namespace ascorr::nav {
namespace {

constexpr double kDay = kSecondsPerDay;
// Measured 41.49" (at 2025-09-29, the AA formula's own longitude error) over
// every 0.5 day of the span and 20,000 random epochs; asserted with a margin.
constexpr double kBoundArcsec = 60.0;

struct Reference {
    double t;
    Vector3<double> s;  // unit, Earth -> Sun, ICRF axes
};

// eraEpv00 takes TDB; TT for TDB (<= 1.7 ms) moves the Sun by 7e-5".
Reference erfa_reference(double t) {
    double pvh[2][3];
    double pvb[2][3];
    (void)eraEpv00(ERFA_DJ00, t / kDay, pvh, pvb);  // status 1 (outside 1900-2100) cannot occur in the span
    const double r = std::sqrt(pvh[0][0] * pvh[0][0] + pvh[0][1] * pvh[0][1] + pvh[0][2] * pvh[0][2]);
    return {t, {-pvh[0][0] / r, -pvh[0][1] / r, -pvh[0][2] / r}};  // the Sun as seen from the Earth
}

// The span every `step` from its first instant, its last instant, and `random`
// random epochs (fixed seed).
std::vector<Reference> references(double step, int random) {
    std::vector<Reference> r;
    for (double t = kEarthSeriesFirstTt; t < kEarthSeriesLastTt; t += step) {
        r.push_back(erfa_reference(t));
    }
    r.push_back(erfa_reference(kEarthSeriesLastTt));
    std::mt19937_64 rng(2051);
    std::uniform_real_distribution<double> u(kEarthSeriesFirstTt, kEarthSeriesLastTt);
    for (int i = 0; i < random; ++i) {
        r.push_back(erfa_reference(u(rng)));
    }
    return r;
}

// The angle between two unit vectors, arcseconds (atan2: accurate near 0).
double angle_arcsec(const Vector3<double>& a, const Vector3<double>& b) {
    const Vector3<double> c = cross(a, b);
    return std::atan2(std::sqrt(squared_norm(c)), dot(a, b)) * kRadToArcsec;
}

// The AA formula as published, on the mean equinox and ecliptic of date (the
// mutant: sun_direction_icrf without the precession to J2000), written out
// here with the library's sin and cos, independently of the header.
Vector3<double> sun_direction_of_date(double t) {
    const double n = t / kDay;
    const double g = std::remainder(357.528 + 0.9856003 * n, 360.0) * kDegToRad;
    const double lambda =
        std::remainder(280.460 + 0.9856474 * n + 1.915 * std::sin(g) + 0.020 * std::sin(2.0 * g), 360.0) * kDegToRad;
    const double eps = (23.439 - 4e-7 * n) * kDegToRad;
    return {std::cos(lambda), std::cos(eps) * std::sin(lambda), std::sin(eps) * std::sin(lambda)};
}

// "YYYY-MM-DD" of t, for the messages.
void print_date(const char* what, double t) {
    int year = 0;
    int month = 0;
    int day = 0;
    double fraction = 0.0;
    (void)eraJd2cal(ERFA_DJ00, t / kDay, &year, &month, &day, &fraction);
    std::printf("%s at t = %.0f s (%04d-%02d-%02d)\n", what, t, year, month, day);
}

TEST(SunDirection, MatchesErfaEpv00OverTheWholeSpan) {
    // Every half day and 20,000 random epochs: 57,257 eraEpv00 calls.
    const std::vector<Reference> refs = references(0.5 * kDay, 20000);
    double worst = 0.0;
    double t_worst = 0.0;
    for (const Reference& r : refs) {
        Vector3<double> s{};
        ASSERT_TRUE(sun_direction_icrf(r.t, s)) << "t = " << r.t;
        const double a = angle_arcsec(s, r.s);
        if (a > worst) {
            worst = a;
            t_worst = r.t;
        }
    }
    std::printf("sun direction vs eraEpv00, %zu epochs: max %.2f arcsec (%.4f deg)\n", refs.size(), worst,
                worst / 3600.0);
    print_date("  worst", t_worst);
    EXPECT_LT(worst, kBoundArcsec);
}

TEST(SunDirection, HasUnitNorm) {
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> u(kEarthSeriesFirstTt, kEarthSeriesLastTt);
    double worst = 0.0;
    for (int i = 0; i < 100000; ++i) {
        Vector3<double> s{};
        ASSERT_TRUE(sun_direction_icrf(u(rng), s));
        worst = std::max(worst, std::abs(std::sqrt(squared_norm(s)) - 1.0));
    }
    std::printf("| |s| - 1 | max %.3g\n", worst);
    EXPECT_LE(worst, 1e-15);
}

// A refusal: false, and the output untouched (bit for bit).
void expect_refused(double t) {
    const auto bits = [](double x) {
        std::uint64_t b = 0;
        std::memcpy(&b, &x, sizeof b);
        return b;
    };
    const double sentinel = std::numeric_limits<double>::quiet_NaN();  // any write would show
    Vector3<double> out{sentinel, -2.5, -0.0};
    EXPECT_FALSE(sun_direction_icrf(t, out)) << "t = " << t;
    EXPECT_EQ(bits(out.x), bits(sentinel)) << "output changed for t = " << t;
    EXPECT_EQ(bits(out.y), bits(-2.5)) << "t = " << t;
    EXPECT_EQ(bits(out.z), bits(-0.0)) << "t = " << t;
}

TEST(SunDirection, RefusesNonFiniteAndOutOfSpanTimes) {
    for (double t : {std::numeric_limits<double>::quiet_NaN(), -std::numeric_limits<double>::quiet_NaN(),
                     std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity(),
                     kEarthSeriesFirstTt - 1.0, kEarthSeriesLastTt + 1.0}) {
        expect_refused(t);
    }
    // Both ends are inside.
    Vector3<double> out{};
    EXPECT_TRUE(sun_direction_icrf(kEarthSeriesFirstTt, out));
    EXPECT_TRUE(sun_direction_icrf(kEarthSeriesLastTt, out));
}

// Mutation check: without the precession to the J2000 equinox the Sun is off
// by p_A = 5028.8" T along the ecliptic, 0.7 deg in 2050. Over 2050 (every 5
// days) ours stays within the bound, and the formula of date is more than 10
// times the bound away: the whole-span test would catch the mutant.
TEST(SunDirection, MutationDroppingThePrecessionBreaksTheBound) {
    const double first = (50 * 365 + 13 - 0.5) * kDay;  // 2050-01-01 00:00 TT
    ASSERT_LE(first + 360.0 * kDay, kEarthSeriesLastTt);
    double ours = 0.0;
    double mutant = std::numeric_limits<double>::infinity();
    for (int i = 0; i <= 72; ++i) {
        const Reference r = erfa_reference(first + 5.0 * i * kDay);
        Vector3<double> s{};
        ASSERT_TRUE(sun_direction_icrf(r.t, s));
        ours = std::max(ours, angle_arcsec(s, r.s));
        mutant = std::min(mutant, angle_arcsec(sun_direction_of_date(r.t), r.s));
    }
    std::printf("2050: ours max %.1f arcsec; equinox of date min %.1f arcsec (%.3f deg)\n", ours, mutant,
                mutant / 3600.0);
    EXPECT_LT(ours, kBoundArcsec);
    EXPECT_GT(mutant, 10.0 * kBoundArcsec);
}

}  // namespace
}  // namespace ascorr::nav
