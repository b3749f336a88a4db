// ascorr/nav/earth_frame.hpp: Earth-fixed (ITRF) → celestial (GCRS) for states.
//
// Conventions: r_sc_itrf, v_sc_itrf are a GNSS receiver's position (km) and
// velocity (km/s) relative to the rotating Earth; r_sc_gcrs, v_sc_gcrs the
// same state in GCRS axes (the solutions' vx,vy,vz frame; ICRF axes), with
//   r_gcrs = Q(X, Y) · R3(−θ) · r_itrf,
//   v_gcrs = Q(X, Y) · R3(−θ) · (v_itrf + ω × r_itrf),   ω = (0, 0, dθ/dt),
// the CIO-based transformation of IERS Conventions 2010 (ch. 5) with:
//  - θ the Earth rotation angle, IAU 2000 (eraEra00), of UT1 = TT − (TT − UT1);
//    TT − UT1 is configured (VelocityServiceConfig), e.g. 69.184 s: TAI − UTC =
//    37 s since 2017, UT1 − UTC left out;
//  - X, Y the CIP's coordinates from the IAU 2006 precession polynomials
//    (frame bias included, eraXy06's polynomial part), and
//    Q = [[1−aX², −aXY, X], [−aXY, 1−aY², Y], [−X, −Y, 1−a(X²+Y²)]],
//    a = 1/2 + (X² + Y²)/8 (IERS 2010 eq. 5.10; the CIO locator s ≤ 0.1″ is left out).
// What is left out, as a velocity error for a LEO spacecraft (7.6 km/s,
// 1.45 m/s = 0.001″ of aberration), measured against ERFA's full
// transformation (eraC2t06a) in tests/test_velocity_service.cpp:
//  - nutation (≤ 17″ in X, Y: ≤ 0.65 m/s; measured 0.35 m/s over 2024–2026);
//  - UT1 − UTC (|·| ≤ 0.9 s: ≤ 0.5 m/s) and polar motion (≤ 0.5″: 0.02 m/s);
//  - the rate of precession-nutation in v (≤ 2e-3 m/s) and s (≤ 4e-3 m/s).
// Everything here is double and runs once per accepted state (1 Hz at most),
// outside the per-solution path. No library calls: sin/cos are the
// polynomials below (divisions by constants as products with their
// reciprocals: soft-float division is slow on the M3), so the host and both
// targets compute the same bits.
#pragma once

#include <cstdint>

#include "../core/constants.hpp"
#include "../core/vector3.hpp"
#include "sincos.hpp"
#include "tt_time.hpp"

namespace ascorr {

// dθ/dt of the Earth rotation angle (IAU 2000): 2π · 1.00273781191135448 per UT1 day.
inline constexpr double kEarthRotationRateRadS = 2.0 * kPi * 1.00273781191135448 / kSecondsPerDay;
inline constexpr double kSecondsPerJulianCentury = 36525.0 * kSecondsPerDay;
inline constexpr std::int64_t kMicrosecondsPerDay = static_cast<std::int64_t>(kSecondsPerDay) * kMicrosecondsPerSecond;

struct Matrix3 {
    Vector3<double> row[3];
};

constexpr Vector3<double> mul(const Matrix3& m, const Vector3<double>& v) noexcept {
    return {dot(m.row[0], v), dot(m.row[1], v), dot(m.row[2], v)};
}

// The Earth rotation angle in turns, in [0, 1), for a UT1 time in µs since
// J2000.0 (JD 2451545.0 UT1). Whole days split off exactly in integers, so the
// fraction keeps double's full resolution (as eraEra00 does with its two-part date).
constexpr double earth_rotation_turns(std::int64_t ut1_us) noexcept {
    std::int64_t day = ut1_us / kMicrosecondsPerDay;
    std::int64_t rem = ut1_us - day * kMicrosecondsPerDay;
    if (rem < 0) {
        rem += kMicrosecondsPerDay;
        --day;
    }
    const double frac_day = static_cast<double>(rem) * (1.0 / static_cast<double>(kMicrosecondsPerDay));
    const double tu = static_cast<double>(day) + frac_day;
    double f = frac_day + 0.7790572732640 + 0.00273781191135448 * tu;
    f -= static_cast<double>(static_cast<std::int64_t>(f));  // truncation towards zero
    if (f < 0.0) {
        f += 1.0;
    }
    return f;
}

// GCRS ← ITRF rotation at TT time t (polar motion left out: ITRF = TIRS).
struct CelestialFromTerrestrial {
    Matrix3 q_gcrs_cirs;        // Q(X, Y)
    SinCos era;                 // θ
    Vector3<double> pole_gcrs;  // the CIP (Earth's rotation axis) in GCRS: Q's third column
};

constexpr CelestialFromTerrestrial celestial_from_terrestrial(TtTime t, std::int64_t tt_minus_ut1_us) noexcept {
    const double tc = tt_seconds(t) * (1.0 / kSecondsPerJulianCentury);
    // IAU 2006 X, Y polynomials (arcsec), eraXy06's polynomial part.
    const double x_as =
        -0.016617 +
        tc * (2004.191898 + tc * (-0.4297829 + tc * (-0.19861834 + tc * (0.000007578 + tc * 0.0000059285))));
    const double y_as =
        -0.006951 + tc * (-0.025896 + tc * (-22.4072747 + tc * (0.00190059 + tc * (0.001112526 + tc * 0.0000001358))));
    const double x = x_as * kArcsecToRad;
    const double y = y_as * kArcsecToRad;
    const double a = 0.5 + 0.125 * (x * x + y * y);
    CelestialFromTerrestrial out{};
    out.q_gcrs_cirs = {
        {{1.0 - a * x * x, -a * x * y, x}, {-a * x * y, 1.0 - a * y * y, y}, {-x, -y, 1.0 - a * (x * x + y * y)}}};
    out.era = sincos_turns(earth_rotation_turns(t.us - tt_minus_ut1_us));
    out.pole_gcrs = {x, y, 1.0 - a * (x * x + y * y)};
    return out;
}

// r_gcrs (km), v_gcrs (km/s) from r_itrf, v_itrf.
constexpr void itrf_to_gcrs(const CelestialFromTerrestrial& m, const Vector3<double>& r_itrf,
                            const Vector3<double>& v_itrf, Vector3<double>& r_gcrs, Vector3<double>& v_gcrs) noexcept {
    const double w = kEarthRotationRateRadS;
    const Vector3<double> v_tirs_inertial{v_itrf.x - w * r_itrf.y, v_itrf.y + w * r_itrf.x, v_itrf.z};  // v + ω × r
    const double c = m.era.c;
    const double s = m.era.s;
    const Vector3<double> r_cirs{c * r_itrf.x - s * r_itrf.y, s * r_itrf.x + c * r_itrf.y, r_itrf.z};
    const Vector3<double> v_cirs{c * v_tirs_inertial.x - s * v_tirs_inertial.y,
                                 s * v_tirs_inertial.x + c * v_tirs_inertial.y, v_tirs_inertial.z};
    r_gcrs = mul(m.q_gcrs_cirs, r_cirs);
    v_gcrs = mul(m.q_gcrs_cirs, v_cirs);
}

}  // namespace ascorr
