// The on-board velocity service (tt_time.hpp, earth_frame.hpp,
// orbit_propagation.hpp, velocity_service.hpp) against independent references:
//  - the frame against ERFA's full ITRS → GCRS (eraC2t06a: IAU 2006/2000A
//    precession-nutation, ERA, polar motion, UT1 − UTC);
//  - propagation against this file's own integration (RK4 at 1 s with J2, J3,
//    J4 about ERFA's CIP and a small drag the service does not model);
//  - the Earth's part (the on-board series) against liberfa's eraEpv00;
//  - the corrected attitudes against the same solutions corrected with the
//    true velocity (the reference orbit + eraEpv00), in arcsec.
// The orbits are generated here: a near-polar LEO at 460 km, 24 h of 1 Hz
// GNSS states (ITRF, on .184 s) with gaps of 30 s, 5 min and 30 min, and a
// single uplinked GCRS state 6 h before the last solution.
#include <erfa.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "ascorr/ascorr.hpp"
#include "ascorr/nav/velocity_service.hpp"
#include "test_support.hpp"

namespace ascorr::test {
namespace {

using V3 = Vector3<double>;

constexpr double kAuKm = kAstronomicalUnitKm;
constexpr double kDayS = kSecondsPerDay;
constexpr double kDj00 = kJ2000JulianDate;
// 1.45 m/s of velocity is 0.001" of aberration (v/c in rad).
constexpr double kMsToArcsec = 1e-3 / kSpeedOfLightKmS * kRadToArcsec;

V3 v3(const Eigen::Vector3d& e) {
    return {e.x(), e.y(), e.z()};
}
Eigen::Vector3d ev(const V3& v) {
    return {v.x, v.y, v.z};
}

// ---- References ---------------------------------------------------------

// The Earth's barycentric velocity (km/s, ICRF) and Sun distance (au), eraEpv00.
bool erfa_earth(double t_tt_s, EarthBarycentric& out) {
    double pvh[2][3];
    double pvb[2][3];
    eraEpv00(kDj00, t_tt_s / kDayS, pvh, pvb);
    out.v_earth_icrf_kms = {pvb[1][0] * kAuKm / kDayS, pvb[1][1] * kAuKm / kDayS, pvb[1][2] * kAuKm / kDayS};
    out.sun_distance_au = std::sqrt(pvh[0][0] * pvh[0][0] + pvh[0][1] * pvh[0][1] + pvh[0][2] * pvh[0][2]);
    return true;
}

// The service's Earth is the on-board series (earth_series.hpp, ≤ 0.75 m/s
// from eraEpv00); the true velocity below is eraEpv00's.
using ServiceEarth = OnBoardEarth;

// Earth orientation of the reference world: UT1 − UTC and polar motion that
// the service does not know (it assumes TT − UT1 = 69.184 s, no polar motion).
constexpr double kDut1S = -0.15;
constexpr double kXpRad = 0.12 * kArcsecToRad;
constexpr double kYpRad = 0.35 * kArcsecToRad;

// ERFA's GCRS → ITRS matrix at TT seconds t: eraC2t06a's construction
// (eraC2tcio of eraC2i06a, eraEra00, eraPom00 with eraSp00). The
// celestial-to-intermediate matrix (IAU 2006/2000A, the expensive part) is
// cached for 60 s, in which the CIP moves by < 3e-11 rad (1e-7 m/s).
Eigen::Matrix3d erfa_c2t(double t_tt_s, double dut1_s, double xp, double yp) {
    static double cached_key = std::nan("");
    static double rc2i[3][3];
    const double key = std::floor(t_tt_s / 60.0) * 60.0;
    if (!(key == cached_key)) {
        eraC2i06a(kDj00, key / kDayS, rc2i);
        cached_key = key;
    }
    const double ut1_s = t_tt_s - 69.184 + dut1_s;
    const double era = eraEra00(kDj00, ut1_s / kDayS);
    double rpom[3][3];
    eraPom00(xp, yp, eraSp00(kDj00, t_tt_s / kDayS), rpom);
    double rc2t[3][3];
    eraC2tcio(rc2i, era, rpom, rc2t);
    Eigen::Matrix3d m;
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) {
            m(i, j) = rc2t[i][j];
        }
    }
    return m;
}

// The full eraC2t06a, uncached, for the frame test.
Eigen::Matrix3d erfa_c2t06a(double t_tt_s, double dut1_s, double xp, double yp) {
    double rc2t[3][3];
    const double ut1_s = t_tt_s - 69.184 + dut1_s;
    eraC2t06a(kDj00, t_tt_s / kDayS, kDj00, ut1_s / kDayS, xp, yp, rc2t);
    Eigen::Matrix3d m;
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) {
            m(i, j) = rc2t[i][j];
        }
    }
    return m;
}

struct Pv {
    Eigen::Vector3d r;
    Eigen::Vector3d v;
};

// GCRS state → the ITRF state a GNSS receiver reports (ERFA's full transformation).
Pv gcrs_to_itrf(double t_tt_s, const Pv& gcrs, bool full = false) {
    const Eigen::Matrix3d c2t =
        full ? erfa_c2t06a(t_tt_s, kDut1S, kXpRad, kYpRad) : erfa_c2t(t_tt_s, kDut1S, kXpRad, kYpRad);
    const Eigen::Vector3d r = c2t * gcrs.r;
    const Eigen::Vector3d w(0.0, 0.0, kEarthRotationRateRadS);
    return {r, c2t * gcrs.v - w.cross(r)};
}

// The reference orbit: RK4 at 1 s (global error ~(n·h)⁴ ≈ 1.5e-12 relative,
// < 1e-5 m/s in a day), zonal J2, J3, J4 about ERFA's CIP at the epoch, and
// drag ρ·Cd·A/m = 3e-12 kg/m³ · 2.2 · 1 m²/400 kg against the rotating
// atmosphere (4.8e-7 m/s² at 460 km, which the service does not model).
class ReferenceOrbit {
public:
    ReferenceOrbit(double t0_tt_s, const Pv& s0, double span_s) : t0_(t0_tt_s) {
        double rnpb[3][3];
        eraPnm06a(kDj00, t0_tt_s / kDayS, rnpb);
        pole_ = Eigen::Vector3d(rnpb[2][0], rnpb[2][1], rnpb[2][2]);
        const auto n = static_cast<std::size_t>(span_s) + 2;
        grid_.reserve(n);
        grid_.push_back(s0);
        for (std::size_t i = 1; i < n; ++i) {
            grid_.push_back(step(grid_.back(), 1.0));
        }
    }

    Pv at(double t_tt_s) const {
        const double dt = t_tt_s - t0_;
        const double i = std::floor(dt);
        const auto idx = static_cast<std::size_t>(i);
        const double frac = dt - i;
        if (frac == 0.0) {
            return grid_.at(idx);
        }
        return step(grid_.at(idx), frac);
    }

    Eigen::Vector3d accel(const Eigen::Vector3d& r, const Eigen::Vector3d& v) const {
        const double rn = r.norm();
        const Eigen::Vector3d rh = r / rn;
        const double s = rh.dot(pole_);
        const double mu = kEarthGmKm3S2;
        const double re = kEarthEquatorialRadiusKm;
        Eigen::Vector3d a = -mu / (rn * rn) * rh;
        // a_n = −μ J_n Rⁿ / r^(n+2) [P_n'(s)(p − s r̂) − (n+1) P_n(s) r̂]
        const double jn[3] = {1.08262668e-3, -2.53265649e-6, -1.61962159e-6};
        const double p[3] = {0.5 * (3 * s * s - 1), 0.5 * (5 * s * s * s - 3 * s),
                             (35 * s * s * s * s - 30 * s * s + 3) / 8.0};
        const double dp[3] = {3 * s, 0.5 * (15 * s * s - 3), (140 * s * s * s - 60 * s) / 8.0};
        for (int k = 0; k < 3; ++k) {
            const int n = k + 2;
            const double f = -mu * jn[k] * std::pow(re, n) / std::pow(rn, n + 2);
            a += f * (dp[k] * (pole_ - s * rh) - (n + 1) * p[k] * rh);
        }
        const Eigen::Vector3d vrel = v - (kEarthRotationRateRadS * pole_).cross(r);
        const double k_drag = 0.5 * 3e-12 * 2.2 / 400.0 * 1e3;  // 1/km
        a -= k_drag * vrel.norm() * vrel;
        return a;
    }

    Pv step(const Pv& s, double h) const {
        const Eigen::Vector3d k1r = s.v;
        const Eigen::Vector3d k1v = accel(s.r, s.v);
        const Eigen::Vector3d k2r = s.v + 0.5 * h * k1v;
        const Eigen::Vector3d k2v = accel(s.r + 0.5 * h * k1r, k2r);
        const Eigen::Vector3d k3r = s.v + 0.5 * h * k2v;
        const Eigen::Vector3d k3v = accel(s.r + 0.5 * h * k2r, k3r);
        const Eigen::Vector3d k4r = s.v + h * k3v;
        const Eigen::Vector3d k4v = accel(s.r + h * k3r, k4r);
        return {s.r + h / 6.0 * (k1r + 2 * k2r + 2 * k3r + k4r), s.v + h / 6.0 * (k1v + 2 * k2v + 2 * k3v + k4v)};
    }

private:
    double t0_;
    Eigen::Vector3d pole_;
    std::vector<Pv> grid_;
};

// A near-polar (87.4°) circular orbit at 460 km, GCRS.
Pv initial_leo() {
    const double r = kEarthEquatorialRadiusKm + 460.0;
    const double v = std::sqrt(kEarthGmKm3S2 / r);
    const double inc = 87.4 * kPi / 180.0;
    const double raan = 0.7;
    const Eigen::Vector3d node(std::cos(raan), std::sin(raan), 0.0);
    const Eigen::Vector3d normal(std::sin(raan) * std::sin(inc), -std::cos(raan) * std::sin(inc), std::cos(inc));
    return {r * node, v * normal.cross(node)};
}

// 2025-06-01 12:00 TT + .184: GNSS states fall on .184.
constexpr double kT0 = 801964800.184;

TtTime tt(double t_s) {
    TtTime t{};
    EXPECT_TRUE(tt_from_seconds(t_s, t));
    return t;
}

// The true observer velocity at t (km/s, ICRF) and 1/s.
struct TrueVelocity {
    Eigen::Vector3d v_kms;
    double inv_s;
};
TrueVelocity true_velocity(const ReferenceOrbit& orbit, double t_s, EarthBarycentric& e) {
    erfa_earth(t_s, e);
    return {orbit.at(t_s).v + ev(e.v_earth_icrf_kms), 1.0 / e.sun_distance_au};
}

template <typename T>
Quaternion<T> to_t(const Eigen::Quaterniond& q) {
    using Tr = ScalarTraits<T>;
    return {Tr::from_double(q.w()), Tr::from_double(q.x()), Tr::from_double(q.y()), Tr::from_double(q.z())};
}
template <typename T>
Eigen::Quaterniond widen(const Quaternion<T>& q) {
    using Tr = ScalarTraits<T>;
    return {Tr::to_double(q.w), Tr::to_double(q.x), Tr::to_double(q.y), Tr::to_double(q.z)};
}

// q corrected for aberration only, with the given velocity.
template <typename T>
CorrectedSolution<T> correct_with(const Eigen::Quaterniond& q, const ObserverVelocity<T>& v) {
    SolutionInput<T> in{};
    in.q_chu_icrf = to_t<T>(q);
    in.head = 0;
    in.velocity = v;
    return correct_solution(in, CorrectionConfig<T>{true, nullptr});
}

ObserverVelocity<double> observer(const TrueVelocity& tv) {
    return {v3(tv.v_kms / kSpeedOfLightKmS), tv.inv_s, true};
}

// ---- Time ---------------------------------------------------------------

TEST(TtTime, MicrosecondsExactForGnssAndBoundedOtherwise) {
    TtTime t{};
    ASSERT_TRUE(tt_from_seconds(kT0, t));
    EXPECT_EQ(t.us, 801964800184000LL);
    ASSERT_TRUE(tt_from_seconds(-kT0, t));
    EXPECT_EQ(t.us, -801964800184000LL);
    EXPECT_FALSE(tt_from_seconds(std::nan(""), t));
    EXPECT_FALSE(tt_from_seconds(INFINITY, t));
    EXPECT_FALSE(tt_from_seconds(2e11, t));
    EXPECT_EQ(t.us, -801964800184000LL);  // untouched on refusal
    // A 22 Hz solution time: rounded by at most 0.5 µs (+ double's own 6e-8 s here).
    const double t22 = kT0 + 13.0 / 22.0;
    ASSERT_TRUE(tt_from_seconds(t22, t));
    EXPECT_LE(std::fabs(tt_seconds(t) - t22), 0.5e-6 + 1.2e-7);
}

TEST(TtTime, NodeFractionInEveryScalar) {
    for (std::int32_t us = 0; us <= kVelocityNodeUs; us += 9973) {
        const double f = us / 1e7;
        EXPECT_NEAR(node_fraction(us, 0.0), f, 2.3e-16);
        EXPECT_NEAR(static_cast<double>(node_fraction(us, 0.0F)), f, 6e-8);
        EXPECT_NEAR(ScalarTraits<Q30>::to_double(node_fraction(us, Q30{})), f,
                    0x1p-31 * 1.003);  // half an LSB + the multiplier's ≤ 1.6e-3 LSB
    }
    EXPECT_EQ(node_fraction(static_cast<std::int32_t>(kVelocityNodeUs), Q30{}).raw, 1 << 30);
}

// ---- Frame --------------------------------------------------------------

TEST(EarthFrame, SinCosAndRotationAngleAgainstLibm) {
    for (int i = 0; i <= 4850; ++i) {
        const double f = -3.0 + 0.001237 * i;
        const SinCos sc = sincos_turns(f);
        const double x = 2 * kPi * (f - std::round(f));  // exact reduction, then ≤ 4.4e-16 rounding
        EXPECT_NEAR(sc.s, std::sin(x), 8e-16) << f;
        EXPECT_NEAR(sc.c, std::cos(x), 8e-16) << f;
    }
    for (int i = 0; i <= 90; ++i) {
        const double t = -1e9 + (3.3e7 + 0.123456) * i;
        TtTime ut1{};
        ASSERT_TRUE(tt_from_seconds(t, ut1));
        const double days = std::floor(t / kDayS);  // whole days in the first part: ERFA keeps precision
        const double era = eraEra00(kDj00 + days, (t - days * kDayS) / kDayS);
        const double got = 2 * kPi * earth_rotation_turns(ut1.us);
        EXPECT_NEAR(std::remainder(got - era, 2 * kPi), 0.0, 1e-11) << t;  // 2e-6", 7e-8 m/s
    }
}

// Velocity error of the service's ITRF → GCRS against ERFA's full one over
// 2000–2050, for a LEO state: the nutation left out is ≤ 17" (≤ 0.65 m/s);
// UT1 − UTC (−0.15 s here: 0.08 m/s) and polar motion (0.37") add to it.
TEST(EarthFrame, ItrfToGcrsAgainstErfaC2t06a) {
    const Pv leo = initial_leo();
    double worst_v = 0.0;
    double worst_r = 0.0;
    double worst_v_no_precession = 1e9;
    for (int i = 0; i <= 135; ++i) {
        const double year = 2000.0 + 0.37 * i;
        const double t = (year - 2000.0) * 365.25 * kDayS + 0.184;
        const Pv itrf = gcrs_to_itrf(t, leo, true);
        const CelestialFromTerrestrial m = celestial_from_terrestrial(tt(t), kDefaultTtMinusUt1Us);
        V3 r{};
        V3 v{};
        itrf_to_gcrs(m, v3(itrf.r), v3(itrf.v), r, v);
        worst_v = std::max(worst_v, (ev(v) - leo.v).norm() * 1e3);
        worst_r = std::max(worst_r, (ev(r) - leo.r).norm());
        // Mutation: without precession (Q = I) the test must see it (beyond 2003).
        if (year > 2003.0) {
            CelestialFromTerrestrial no_p = m;
            no_p.q_gcrs_cirs = {{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};
            itrf_to_gcrs(no_p, v3(itrf.r), v3(itrf.v), r, v);
            worst_v_no_precession = std::min(worst_v_no_precession, (ev(v) - leo.v).norm() * 1e3);
        }
    }
    std::printf("ITRF->GCRS vs eraC2t06a 2000-2050: %.3f m/s (%.5f\"), %.3f km; without precession >= %.1f m/s\n",
                worst_v, worst_v * kMsToArcsec, worst_r, worst_v_no_precession);
    EXPECT_LE(worst_v, 0.9);  // 0.0006"
    EXPECT_LE(worst_r, 0.7);  // 21" of nutation at 6838 km
    EXPECT_GT(worst_v_no_precession, 2.0);
}

// ---- Propagation --------------------------------------------------------

// The service's J2 RK4 against the reference (J2–J4, drag) from one exact
// GCRS state: velocity error after 1, 6, 12 h. Sets the default horizon.
TEST(Propagation, AgainstIntegrationWithJ3J4AndDrag) {
    const double span = 12 * 3600.0;
    const ReferenceOrbit orbit(kT0, initial_leo(), span);
    VelocityService<double> svc(default_velocity_service_config());
    const Pv s0 = orbit.at(kT0);
    ASSERT_EQ(svc.push_state(tt(kT0), v3(s0.r), v3(s0.v), StateFrame::kGcrs), StateVerdict::kAccepted);
    OrbitState y{v3(s0.r), v3(s0.v)};
    const V3 pole = celestial_from_terrestrial(tt(kT0), kDefaultTtMinusUt1Us).pole_gcrs;
    double err1 = 0;
    double err6 = 0;
    double err12 = 0;
    for (int n = 1; n <= 4320; ++n) {
        y = rk4_step(y, gravity_j2(y.r_km, pole), pole, kPropagationStepS);
        const double e = (ev(y.v_kms) - orbit.at(kT0 + n * kPropagationStepS).v).norm() * 1e3;
        if (n <= 360) {
            err1 = std::max(err1, e);
        }
        if (n <= 2160) {
            err6 = std::max(err6, e);
        }
        err12 = std::max(err12, e);
    }
    std::printf("J2 propagation vs J2-J4+drag: max %.3f m/s in 1 h, %.3f m/s in 6 h, %.3f m/s in 12 h\n", err1, err6,
                err12);
    EXPECT_LE(err6, 1.5);   // 0.001" (measured 0.98 m/s): the default horizon, 6 h
    EXPECT_LE(err12, 4.0);  // measured 2.7 m/s
    EXPECT_GT(err12, 0.1);  // the reference really differs from the service's model
}

// ---- The service on the 24 h orbit ---------------------------------------

struct Errors {
    double d = 0;     // double service vs double true velocity, arcsec
    double f = 0;     // float service vs double true
    double q = 0;     // Q30 service vs double true
    double held = 0;  // mutation: the velocity of the latest state, not propagated
    std::size_t n = 0;
};

struct Feed {
    std::vector<double> t;
    std::vector<Pv> itrf;
};

// 1 Hz ITRF states on .184 from t0 to t0 + span, with gaps [from, from + len).
Feed gnss_feed(const ReferenceOrbit& orbit, double t0, double span,
               const std::vector<std::pair<double, double>>& gaps) {
    Feed f;
    for (int k = 0; k <= static_cast<int>(span); ++k) {
        const double t = t0 + k;
        bool in_gap = false;
        for (const auto& g : gaps) {
            in_gap = in_gap || (t >= t0 + g.first && t < t0 + g.first + g.second);
        }
        if (!in_gap) {
            f.t.push_back(t);
            f.itrf.push_back(gcrs_to_itrf(t, orbit.at(t)));
        }
    }
    return f;
}

// Solutions at irregular times after the first state; each corrected with
// the true velocity (double) and with the service's in double, float and Q30.
Errors run_solutions(const ReferenceOrbit& orbit, const Feed& feed, StateFrame frame, double from, double to,
                     double spacing) {
    VelocityService<double> sd(default_velocity_service_config());
    VelocityService<float> sf(default_velocity_service_config());
    VelocityService<Q30> sq(default_velocity_service_config());
    std::mt19937_64 rng(12);
    std::uniform_real_distribution<double> jitter(0.0, spacing);
    Errors e;
    std::size_t next_state = 0;
    Eigen::Vector3d held_v(0, 0, 0);
    const auto n = static_cast<int>(std::ceil((to - from) / spacing));
    for (int i = 0; i < n; ++i) {
        const double base = from + spacing * i;
        const TtTime t = tt(std::min(base + jitter(rng), to));
        while (next_state < feed.t.size() && tt(feed.t[next_state]) <= t) {
            const V3 r = v3(feed.itrf[next_state].r);
            const V3 v = v3(feed.itrf[next_state].v);
            const TtTime ts = tt(feed.t[next_state]);
            EXPECT_EQ(sd.push_state(ts, r, v, frame), StateVerdict::kAccepted);
            EXPECT_EQ(sf.push_state(ts, r, v, frame), StateVerdict::kAccepted);
            EXPECT_EQ(sq.push_state(ts, r, v, frame), StateVerdict::kAccepted);
            held_v = orbit.at(feed.t[next_state]).v;
            ++next_state;
        }
        const double ts = tt_seconds(t);
        const ServiceEarth earth;
        EXPECT_TRUE(sd.advance(t, earth));
        EXPECT_TRUE(sf.advance(t, earth));
        EXPECT_TRUE(sq.advance(t, earth));
        const ServiceVelocity<double> vd = sd.velocity_at(t);
        const ServiceVelocity<float> vf = sf.velocity_at(t);
        const ServiceVelocity<Q30> vq = sq.velocity_at(t);
        EXPECT_EQ(vd.status, 0U);
        EXPECT_EQ(vf.status, 0U);
        EXPECT_EQ(vq.status, 0U);
        const Eigen::Quaterniond q = random_attitude(rng);
        EarthBarycentric es{};
        const TrueVelocity tv = true_velocity(orbit, ts, es);
        const auto ref = correct_with<double>(q, observer(tv));
        EXPECT_EQ(ref.status, status::kAberrationApplied);
        const Eigen::Quaterniond qr = widen(ref.q_chu_icrf);
        e.d = std::max(e.d, angle_arcsec(qr, widen(correct_with<double>(q, vd.velocity).q_chu_icrf)));
        e.f = std::max(e.f, angle_arcsec(qr, widen(correct_with<float>(q, vf.velocity).q_chu_icrf)));
        e.q = std::max(e.q, angle_arcsec(qr, widen(correct_with<Q30>(q, vq.velocity).q_chu_icrf)));
        const ObserverVelocity<double> held{v3((held_v + ev(es.v_earth_icrf_kms)) / kSpeedOfLightKmS), tv.inv_s, true};
        e.held = std::max(e.held, angle_arcsec(qr, widen(correct_with<double>(q, held).q_chu_icrf)));
        ++e.n;
    }
    return e;
}

// The service's errors printed and within their bounds: double 0.005", float
// 0.05", Q30 0.01"; the held velocity beyond (mutation: without propagation
// the bound fails).
void expect_within_bounds(const Errors& e, const char* what) {
    std::printf(
        "%s, %zu solutions: service adds %.5f\" (double), float %.4f\", Q30 %.5f\" vs double with the true "
        "velocity; held (not propagated) %.4f\"\n",
        what, e.n, e.d, e.f, e.q, e.held);
    EXPECT_LE(e.d, 0.005);
    EXPECT_LE(e.f, 0.05);
    EXPECT_LE(e.q, 0.01);
    EXPECT_GT(e.held, 0.005);
}

// One reference orbit for the day, shared by the tests below.
const ReferenceOrbit& day_orbit() {
    static const ReferenceOrbit orbit(kT0, initial_leo(), kDayS + 10.0);
    return orbit;
}

// Done-when: 24 h of GNSS states with gaps of 30 s, 5 min and 30 min.
TEST(VelocityService, DayOfGnssStatesWithGaps) {
    const Feed feed =
        gnss_feed(day_orbit(), kT0, kDayS, {{3 * 3600.0, 30.0}, {8 * 3600.0, 300.0}, {14 * 3600.0, 1800.0}});
    const Errors e = run_solutions(day_orbit(), feed, StateFrame::kItrf, kT0, kT0 + kDayS, 4.3);
    expect_within_bounds(e, "24 h, ITRF states with gaps");
}

// Done-when: a single uplinked GCRS state 6 h before the last solution.
TEST(VelocityService, UplinkedStateSixHoursOld) {
    const double t_last = kT0 + kDayS;
    const double t_state = t_last - 6 * 3600.0;
    Feed feed;
    feed.t.push_back(t_state);
    feed.itrf.push_back(day_orbit().at(t_state));  // GCRS
    const Errors e = run_solutions(day_orbit(), feed, StateFrame::kGcrs, t_state, t_last, 3.1);
    expect_within_bounds(e, "uplinked GCRS state, solutions up to 6 h later");
}

// ---- Staleness, missing, bad states ---------------------------------------

Pv leo_itrf(double t) {
    return gcrs_to_itrf(t, day_orbit().at(t));
}

TEST(VelocityService, BeforeTheFirstStateIsStatus4) {
    VelocityService<double> svc(default_velocity_service_config());
    const ServiceEarth earth;
    EXPECT_FALSE(svc.advance(tt(kT0), earth));
    ServiceVelocity<double> v = svc.velocity_at(tt(kT0));
    EXPECT_FALSE(v.velocity.valid);
    EXPECT_EQ(v.status, status::kNoVelocity);
    const Pv s = leo_itrf(kT0 + 100.0);
    ASSERT_EQ(svc.push_state(tt(kT0 + 100.0), v3(s.r), v3(s.v), StateFrame::kItrf), StateVerdict::kAccepted);
    EXPECT_FALSE(svc.advance(tt(kT0 + 99.999999), earth));
    v = svc.velocity_at(tt(kT0 + 99.999999));
    EXPECT_EQ(v.status, status::kNoVelocity);
    // Through the core: status 4, aberration skipped, quaternion only renormalised.
    const auto out = correct_with<double>(Eigen::Quaterniond::Identity(), v.velocity);
    EXPECT_EQ(with_service_status(out.status, v.status, true), status::kNoVelocity);
    EXPECT_TRUE(svc.advance(tt(kT0 + 100.0), earth));
    EXPECT_EQ(svc.velocity_at(tt(kT0 + 100.0)).status, 0U);
}

TEST(VelocityService, BeyondTheHorizonIsStale) {
    VelocityServiceConfig cfg = default_velocity_service_config();
    cfg.horizon_us = 60 * kMicrosecondsPerSecond;
    VelocityService<float> svc(cfg);
    const ServiceEarth earth;
    const Pv s = leo_itrf(kT0);
    ASSERT_EQ(svc.push_state(tt(kT0), v3(s.r), v3(s.v), StateFrame::kItrf), StateVerdict::kAccepted);
    EXPECT_TRUE(svc.advance(tt(kT0 + 60.0), earth));
    EXPECT_EQ(svc.velocity_at(tt(kT0 + 60.0)).status, 0U);  // at the horizon: still valid
    EXPECT_FALSE(svc.advance(tt(kT0 + 60.000001), earth));
    const ServiceVelocity<float> v = svc.velocity_at(tt(kT0 + 60.000001));
    EXPECT_FALSE(v.velocity.valid);
    EXPECT_EQ(v.status, status::kNoVelocity | status::kStale);
    const auto out = correct_with<float>(Eigen::Quaterniond::Identity(), v.velocity);
    EXPECT_EQ(with_service_status(out.status, v.status, true), status::kNoVelocity | status::kStale);
    // Default horizon: 6 h is valid, 6 h + 1 µs stale.
    VelocityService<double> d(default_velocity_service_config());
    ASSERT_EQ(d.push_state(tt(kT0), v3(s.r), v3(s.v), StateFrame::kItrf), StateVerdict::kAccepted);
    EXPECT_TRUE(d.advance(tt(kT0 + 6 * 3600.0), earth));
    EXPECT_EQ(d.velocity_at(tt(kT0 + 6 * 3600.0)).status, 0U);
    EXPECT_FALSE(d.advance(tt(kT0 + 6 * 3600.0 + 1e-6), earth));
    EXPECT_EQ(d.velocity_at(tt(kT0 + 6 * 3600.0 + 1e-6)).status, status::kNoVelocity | status::kStale);
}

// A bounded advance() that has not reached the solution's time withholds the
// velocity (4|512); once caught up it gives the same bits as an unbounded one.
TEST(VelocityService, BoundedCatchUpIsStaleThenIdentical) {
    VelocityServiceConfig cfg = default_velocity_service_config();
    cfg.max_steps_per_advance = 5;
    VelocityService<Q30> slow(cfg);
    VelocityService<Q30> fast(default_velocity_service_config());
    const ServiceEarth earth;
    const Pv s = day_orbit().at(kT0);
    ASSERT_EQ(slow.push_state(tt(kT0), v3(s.r), v3(s.v), StateFrame::kGcrs), StateVerdict::kAccepted);
    ASSERT_EQ(fast.push_state(tt(kT0), v3(s.r), v3(s.v), StateFrame::kGcrs), StateVerdict::kAccepted);
    const TtTime t = tt(kT0 + 3600.0 + 0.37);
    int calls = 1;
    while (!slow.advance(t, earth)) {
        EXPECT_EQ(slow.velocity_at(t).status, status::kNoVelocity | status::kStale);
        ++calls;
        ASSERT_LE(calls, 100);
    }
    EXPECT_EQ(calls, 72);  // 360 steps, 5 per call
    ASSERT_TRUE(fast.advance(t, earth));
    const ServiceVelocity<Q30> a = slow.velocity_at(t);
    const ServiceVelocity<Q30> b = fast.velocity_at(t);
    EXPECT_EQ(a.status, 0U);
    EXPECT_EQ(a.velocity.beta_icrf.x.raw, b.velocity.beta_icrf.x.raw);
    EXPECT_EQ(a.velocity.beta_icrf.y.raw, b.velocity.beta_icrf.y.raw);
    EXPECT_EQ(a.velocity.beta_icrf.z.raw, b.velocity.beta_icrf.z.raw);
    // Going back in time restarts from the state: again the same bits.
    const TtTime t_early = tt(kT0 + 15.5);
    ASSERT_TRUE(fast.advance(t_early, earth));
    VelocityService<Q30> fresh(default_velocity_service_config());
    ASSERT_EQ(fresh.push_state(tt(kT0), v3(s.r), v3(s.v), StateFrame::kGcrs), StateVerdict::kAccepted);
    ASSERT_TRUE(fresh.advance(t_early, earth));
    EXPECT_EQ(fast.velocity_at(t_early).velocity.beta_icrf.x.raw, fresh.velocity_at(t_early).velocity.beta_icrf.x.raw);
}

// Earth series outside its span, or a propagation that leaves the plausible
// radii: 4|32.
TEST(VelocityService, UnformableVelocityIsInvalid) {
    VelocityService<double> svc(default_velocity_service_config());
    const Pv s = day_orbit().at(kT0);
    ASSERT_EQ(svc.push_state(tt(kT0), v3(s.r), v3(s.v), StateFrame::kGcrs), StateVerdict::kAccepted);
    const auto no_earth = [](double, EarthBarycentric&) { return false; };
    EXPECT_TRUE(svc.advance(tt(kT0 + 5.0), no_earth));
    ServiceVelocity<double> v = svc.velocity_at(tt(kT0 + 5.0));
    EXPECT_FALSE(v.velocity.valid);
    EXPECT_EQ(v.status, status::kNoVelocity | status::kVelocityInvalid);
    // A plausible state on a suborbital path: after 30 min it is below 100 km.
    VelocityService<double> fall(default_velocity_service_config());
    const V3 r{kMinOrbitRadiusKm + 5.0, 0.0, 0.0};
    const V3 vv{0.0, 1.0, 0.0};
    ASSERT_EQ(fall.push_state(tt(kT0), r, vv, StateFrame::kGcrs), StateVerdict::kAccepted);
    const ServiceEarth earth;
    EXPECT_TRUE(fall.advance(tt(kT0 + 1800.0), earth));
    EXPECT_EQ(fall.velocity_at(tt(kT0 + 1800.0)).status, status::kNoVelocity | status::kVelocityInvalid);
}

// Every bad state is refused with its verdict and counted; the service keeps
// the latest accepted state, so the velocities after them are bit for bit
// those of the good states alone (nothing lost, nothing changed).
TEST(VelocityService, BadStatesRefusedCountedNothingLost) {
    VelocityService<double> svc(default_velocity_service_config());
    VelocityService<double> clean(default_velocity_service_config());
    const ServiceEarth earth;
    const double nan = std::nan("");
    const double inf = INFINITY;
    const Pv a = leo_itrf(kT0);
    const Pv b = leo_itrf(kT0 + 1.0);
    const Pv c = leo_itrf(kT0 + 2.0);
    ASSERT_EQ(svc.push_state(tt(kT0), v3(a.r), v3(a.v), StateFrame::kItrf), StateVerdict::kAccepted);
    ASSERT_EQ(clean.push_state(tt(kT0), v3(a.r), v3(a.v), StateFrame::kItrf), StateVerdict::kAccepted);
    ASSERT_EQ(svc.push_state(tt(kT0 + 1.0), v3(b.r), v3(b.v), StateFrame::kItrf), StateVerdict::kAccepted);
    ASSERT_EQ(clean.push_state(tt(kT0 + 1.0), v3(b.r), v3(b.v), StateFrame::kItrf), StateVerdict::kAccepted);
    const TtTime t_bad = tt(kT0 + 1.5);
    const V3 r = v3(c.r);
    const V3 v = v3(c.v);
    // Non-finite, in each component of r and v.
    for (int i = 0; i < 6; ++i) {
        V3 rr = r;
        V3 vv = v;
        double* p = i < 3 ? &rr.x : &vv.x;
        p[i % 3] = (i % 2) != 0 ? nan : -inf;
        EXPECT_EQ(svc.push_state(t_bad, rr, vv, StateFrame::kItrf), StateVerdict::kNotFinite) << i;
    }
    // Implausible: at the Earth's centre, underground, beyond 50,000 km, 20 km/s.
    EXPECT_EQ(svc.push_state(t_bad, {0, 0, 0}, v, StateFrame::kItrf), StateVerdict::kImplausible);
    EXPECT_EQ(svc.push_state(t_bad, {6000, 0, 0}, v, StateFrame::kItrf), StateVerdict::kImplausible);
    EXPECT_EQ(svc.push_state(t_bad, {1e6, 0, 0}, v, StateFrame::kGcrs), StateVerdict::kImplausible);
    EXPECT_EQ(svc.push_state(t_bad, r, {20, 0, 0}, StateFrame::kItrf), StateVerdict::kImplausible);
    EXPECT_EQ(svc.push_state(t_bad, r, {1e300, 1e300, 0}, StateFrame::kItrf), StateVerdict::kImplausible);
    // Time: the same time as the latest state (even with other values), earlier.
    EXPECT_EQ(svc.push_state(tt(kT0 + 1.0), r, v, StateFrame::kItrf), StateVerdict::kDuplicateTime);
    EXPECT_EQ(svc.push_state(tt(kT0 + 0.5), r, v, StateFrame::kItrf), StateVerdict::kTimeBackwards);
    EXPECT_EQ(svc.push_state(tt(kT0 - 3600.0), v3(a.r), v3(a.v), StateFrame::kItrf), StateVerdict::kTimeBackwards);
    const StateCounts& n = svc.counts();
    EXPECT_EQ(n.accepted, 2U);
    EXPECT_EQ(n.not_finite, 6U);
    EXPECT_EQ(n.implausible, 5U);
    EXPECT_EQ(n.duplicate_time, 1U);
    EXPECT_EQ(n.time_backwards, 2U);
    EXPECT_EQ(svc.state_time().us, tt(kT0 + 1.0).us);
    ASSERT_TRUE(svc.advance(t_bad, earth));
    ASSERT_TRUE(clean.advance(t_bad, earth));
    const ServiceVelocity<double> got = svc.velocity_at(t_bad);
    const ServiceVelocity<double> want = clean.velocity_at(t_bad);
    EXPECT_EQ(got.status, 0U);
    EXPECT_EQ(got.velocity.beta_icrf.x, want.velocity.beta_icrf.x);
    EXPECT_EQ(got.velocity.beta_icrf.y, want.velocity.beta_icrf.y);
    EXPECT_EQ(got.velocity.beta_icrf.z, want.velocity.beta_icrf.z);
    // And the next good state is taken as usual.
    EXPECT_EQ(svc.push_state(tt(kT0 + 2.0), r, v, StateFrame::kItrf), StateVerdict::kAccepted);
    EXPECT_EQ(svc.counts().accepted, 3U);
}

}  // namespace
}  // namespace ascorr::test
