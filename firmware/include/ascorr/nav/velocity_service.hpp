// ascorr/nav/velocity_service.hpp: the observer velocity of each solution, on board.
//
// Conventions: states in (push_state) are the spacecraft's position (km) and
// velocity (km/s) relative to the Earth's centre, in ITRF (a GNSS receiver,
// ~1 Hz, with gaps) or GCRS (an uplinked state vector, possibly hours old),
// each with a TtTime (tt_time.hpp). Out (velocity_at) is the core's
// ObserverVelocity<T>: β_icrf = (v_earth_icrf + v_sc_gcrs)/c and 1/s (Sun
// distance in au), with status bits for the solution:
//   0        velocity valid;
//   4        no state at or before the solution's time (status::kNoVelocity);
//   4|512    the latest state is more than the horizon old, or the propagation
//            has not reached the solution's time yet (kStale: withheld);
//   4|32     the velocity cannot be formed: the Earth series is outside its
//            span, or the propagated state left the plausible orbit radii
//            (kVelocityInvalid).
// Causal, as on board: a solution's velocity comes from the latest accepted
// state at or before its time, propagated (orbit_propagation.hpp, RK4 in
// double, steps of 10 s anchored at the state) to the start of the velocity
// node [t_state + n·10 s, t_state + (n+1)·10 s) that holds the solution's
// time, and continued over the node by its first-order Taylor series.
//
// Two paths, for the FPU-less Cortex-M3:
//  - push_state() and advance() are double (software on the M3): the frame
//    conversion once per state, one force evaluation per state, one RK4 step
//    per 10 s of flight beyond the latest state (gaps, uplinked states) and one
//    Earth series per minute, bounded by max_steps_per_advance per call (no
//    unbounded loop);
//  - velocity_at() is the per-solution query, in the core's scalar T:
//    β = β₀ + f·Δβ, f = (t − t₀)/10 s from integer microseconds. No double, no
//    division: free of soft-float (tests/target/check-no-soft-float).
// Taylor over a node: ≤ ½·9.5e-3 m/s³·(10 s)² = 0.48 m/s (3e-4″) at its end,
// ≤ 4.8e-3 m/s 1 s after a GNSS state (build_node). Q30 rounds β₀, Δβ and
// f·Δβ to 2⁻³¹: ≤ 3 · 4.7e-10 · c = 0.42 m/s (3e-4″).
//
// Bad states are refused, counted (StateCounts) and reported by verdict; the
// service keeps its latest accepted state, so nothing already known is lost:
//   non-finite component → kNotFinite; |r| outside [kMinOrbitRadiusKm,
//   kMaxOrbitRadiusKm] or |v| > kMaxOrbitSpeedKmS → kImplausible; a time
//   earlier than the latest accepted state's → kTimeBackwards; the same time
//   → kDuplicateTime (the first state of that time is kept).
#pragma once

#include <cstdint>

#include "../core/aberration.hpp"
#include "../core/constants.hpp"
#include "../core/correct.hpp"
#include "../core/fixed_point.hpp"
#include "../core/status.hpp"
#include "../core/vector3.hpp"
#include "earth_frame.hpp"
#include "earth_series.hpp"
#include "orbit_propagation.hpp"
#include "tt_time.hpp"

namespace ascorr {

// Plausible Earth orbit: above 100 km altitude, below 50,000 km (beyond GEO),
// slower than 12 km/s (escape speed at 100 km altitude is 11.1 km/s).
inline constexpr double kMinOrbitRadiusKm = kEarthEquatorialRadiusKm + 100.0;
inline constexpr double kMaxOrbitRadiusKm = 50000.0;
inline constexpr double kMaxOrbitSpeedKmS = 12.0;

inline constexpr std::int64_t kVelocityNodeUs = 10000000;  // kPropagationStepS in µs
static_assert(kPropagationStepS * 1e6 == static_cast<double>(kVelocityNodeUs), "one node per RK4 step");
inline constexpr std::int64_t kEarthNodeUs = 60000000;  // the Earth series' grid (60 s TT)

// The default staleness horizon: 6 h. Measured (test_velocity_service.cpp,
// Propagation.AgainstIntegrationWithJ3J4AndDrag): J2-only propagation against
// an integration with J2–J4 and drag (4.8e-7 m/s²) on a 460 km near-polar
// orbit stays within 0.98 m/s (0.0007″) for 6 h and 2.7 m/s for 12 h. 6 h
// keeps it below a seventh of the 0.005″ (7.25 m/s) budget, leaving room for
// ten times the drag (its along-track error grows as t²) and covers the
// 6 h-old uplinked state; beyond it an unmodelled manoeuvre or a stale
// uplink is more likely than an accurate velocity.
inline constexpr std::int64_t kDefaultHorizonUs = 6LL * 3600LL * kMicrosecondsPerSecond;
// TT − UT1 when UT1 − UTC is not known: TT − UTC = 32.184 s + (TAI − UTC),
// 37 s since 2017-01-01. UT1 − UTC (≤ 0.9 s) is then a ≤ 0.5 m/s error.
inline constexpr std::int64_t kDefaultTtMinusUt1Us = 69184000;

struct VelocityServiceConfig {
    std::int64_t horizon_us;              // a solution later than this after the latest state: 4|512
    std::int64_t tt_minus_ut1_us;         // for the Earth rotation angle (earth_frame.hpp)
    std::uint32_t max_steps_per_advance;  // RK4 steps one advance() may take (≥ 1)
};

constexpr VelocityServiceConfig default_velocity_service_config() noexcept {
    // One advance() can reach the horizon: 2160 steps + 1.
    return {kDefaultHorizonUs, kDefaultTtMinusUt1Us,
            static_cast<std::uint32_t>(kDefaultHorizonUs / kVelocityNodeUs + 1)};
}

enum class StateFrame : std::uint8_t { kItrf, kGcrs };

enum class StateVerdict : std::uint8_t { kAccepted, kNotFinite, kImplausible, kTimeBackwards, kDuplicateTime };

struct StateCounts {
    std::uint32_t accepted;
    std::uint32_t not_finite;
    std::uint32_t implausible;
    std::uint32_t time_backwards;
    std::uint32_t duplicate_time;
};

// The Earth's part: earth_series.hpp on board and on the host; any callable
// bool(double t_tt_j2000_s, EarthBarycentric&) in its place (tests).
struct OnBoardEarth {
    bool operator()(double t_tt_j2000_s, EarthBarycentric& out) const noexcept {
        return earth_series(t_tt_j2000_s, out);
    }
};

template <typename T>
struct ServiceVelocity {
    ObserverVelocity<T> velocity;
    StatusBits status;  // 0, 4, 4|512 or 4|32 (see the top)
};

// f = dt/10 s in the scalar: dt_us in [0, kVelocityNodeUs].
constexpr double node_fraction(std::int32_t dt_us, double /*tag*/) noexcept {
    return static_cast<double>(dt_us) * (1.0 / static_cast<double>(kVelocityNodeUs));
}
constexpr float node_fraction(std::int32_t dt_us, float /*tag*/) noexcept {
    return static_cast<float>(dt_us) * (1.0F / static_cast<float>(kVelocityNodeUs));  // dt_us < 2²⁴: exact
}
// Q30: raw = dt_us · 2³⁰/10⁷, as dt_us · round(2⁶¹/10⁷) · 2⁻³¹ rounded to
// nearest (multiplier 230584300921.37, relative error 1.6e-12; product
// ≤ 10⁷ · 2.31e11 < 2⁶²: no overflow). Integer only.
constexpr Q30 node_fraction(std::int32_t dt_us, Q30 /*tag*/) noexcept {
    constexpr std::int64_t kMul = 230584300921LL;
    return {static_cast<std::int32_t>(fx::round_shift(std::int64_t{dt_us} * kMul, 31))};
}

// double → T at run time (node building, outside the per-solution path):
// rounded to nearest. Q30: x·2³⁰ by one multiplication (fx::raw_from_double
// builds 2³⁰ in a loop, fine for constants, 30 soft-float products on the M3),
// saturated to ±(2 − 2⁻³⁰); the callers' values are ≤ 3.4e-3 (β) and ≤ 10 (1/s: ≤ 1.02).
constexpr double scalar_from_double(double x, double /*tag*/) noexcept {
    return x;
}
constexpr float scalar_from_double(double x, float /*tag*/) noexcept {
    return static_cast<float>(x);
}
constexpr Q30 scalar_from_double(double x, Q30 /*tag*/) noexcept {
    const double s = x * 1073741824.0;
    if (!(s < 2147483647.0)) {
        return {fx::kRawMax};  // also NaN
    }
    if (s <= -2147483647.0) {
        return {-fx::kRawMax};
    }
    return {static_cast<std::int32_t>(s < 0.0 ? s - 0.5 : s + 0.5)};
}

template <typename T>
class VelocityService {
public:
    explicit constexpr VelocityService(const VelocityServiceConfig& cfg) noexcept : cfg_(cfg) {}

    // A state, double, checked and converted to GCRS once (outside the per-solution path).
    StateVerdict push_state(TtTime t, const Vector3<double>& r_km, const Vector3<double>& v_kms,
                            StateFrame frame) noexcept {
        const StateVerdict verdict = check_state(t, r_km, v_kms);
        switch (verdict) {
            case StateVerdict::kAccepted:
                break;
            case StateVerdict::kNotFinite:
                ++counts_.not_finite;
                return verdict;
            case StateVerdict::kImplausible:
                ++counts_.implausible;
                return verdict;
            case StateVerdict::kTimeBackwards:
                ++counts_.time_backwards;
                return verdict;
            case StateVerdict::kDuplicateTime:
                ++counts_.duplicate_time;
                return verdict;
        }
        ++counts_.accepted;
        const CelestialFromTerrestrial m = celestial_from_terrestrial(t, cfg_.tt_minus_ut1_us);
        pole_gcrs_ = m.pole_gcrs;
        if (frame == StateFrame::kItrf) {
            itrf_to_gcrs(m, r_km, v_kms, state_.r_km, state_.v_kms);
        } else {
            state_ = {r_km, v_kms};
        }
        state_t_ = t;
        has_state_ = true;
        cursor_n_ = -1;
        node_present_ = false;
        return verdict;
    }

    // The checks of push_state() without changing anything.
    constexpr StateVerdict check_state(TtTime t, const Vector3<double>& r_km,
                                       const Vector3<double>& v_kms) const noexcept {
        const double rr = squared_norm(r_km);
        const double vv = squared_norm(v_kms);
        if (!(is_finite(r_km.x) && is_finite(r_km.y) && is_finite(r_km.z) && is_finite(v_kms.x) && is_finite(v_kms.y) &&
              is_finite(v_kms.z))) {
            return StateVerdict::kNotFinite;
        }
        if (!(rr >= kMinOrbitRadiusKm * kMinOrbitRadiusKm && rr <= kMaxOrbitRadiusKm * kMaxOrbitRadiusKm &&
              vv <= kMaxOrbitSpeedKmS * kMaxOrbitSpeedKmS)) {
            return StateVerdict::kImplausible;
        }
        if (has_state_ && t == state_t_) {
            return StateVerdict::kDuplicateTime;
        }
        if (has_state_ && t < state_t_) {
            return StateVerdict::kTimeBackwards;
        }
        return StateVerdict::kAccepted;
    }

    // Propagates (double) until the velocity node holding t is ready, taking
    // at most cfg.max_steps_per_advance RK4 steps; true when it is. earth is
    // called as earth(t_tt_j2000_s, EarthBarycentric&) → bool (OnBoardEarth) on a 60 s grid (once
    // per minute of flight, see earth_at). A t before the current node
    // restarts from the state (same bits).
    template <typename EarthFn>
    bool advance(TtTime t, EarthFn&& earth) noexcept {
        if (!has_state_ || t < state_t_ || t.us - state_t_.us > cfg_.horizon_us) {
            return false;
        }
        if (node_present_ && node_t0_ <= t && t.us - node_t0_.us < kVelocityNodeUs) {
            return true;  // the per-solution common case: integer compares only
        }
        const std::int64_t n_target = (t.us - state_t_.us) / kVelocityNodeUs;
        if (cursor_n_ < 0 || cursor_n_ > n_target) {
            cursor_n_ = 0;
            y_n_ = state_;
            a_n_ = gravity_j2(y_n_.r_km, pole_gcrs_);
        }
        for (std::uint32_t steps = 0U; cursor_n_ < n_target; ++steps) {
            if (steps >= cfg_.max_steps_per_advance) {
                return false;  // the next call continues from here
            }
            y_n_ = rk4_step(y_n_, a_n_, pole_gcrs_, kPropagationStepS);
            a_n_ = gravity_j2(y_n_.r_km, pole_gcrs_);
            ++cursor_n_;
            ++steps_;
        }
        build_node(earth);
        return true;
    }

    // The per-solution query, in T (no double, no division). advance(t) first.
    constexpr ServiceVelocity<T> velocity_at(TtTime t) const noexcept {
        constexpr T zero = constant<T>(0.0);  // constexpr: no conversion at run time (soft-float on the M3)
        constexpr T one = constant<T>(1.0);
        ServiceVelocity<T> out{{{zero, zero, zero}, one, false}, status::kNoVelocity};
        if (!has_state_ || t < state_t_) {
            return out;
        }
        const std::int64_t dt = t.us - node_t0_.us;
        if (t.us - state_t_.us > cfg_.horizon_us || !node_present_ || dt < 0 || dt > kVelocityNodeUs) {
            out.status = status::kNoVelocity | status::kStale;
            return out;
        }
        if (node_status_ != 0U) {
            out.status = node_status_;
            return out;
        }
        const T f = node_fraction(static_cast<std::int32_t>(dt), T{});
        out.velocity = {beta0_ + f * dbeta_, inv_sun_distance_, true};
        out.status = 0U;
        return out;
    }

    constexpr const StateCounts& counts() const noexcept { return counts_; }
    constexpr bool has_state() const noexcept { return has_state_; }
    // RK4 steps taken and velocity nodes built so far (for cost reports).
    constexpr std::uint32_t steps_taken() const noexcept { return steps_; }
    constexpr std::uint32_t nodes_built() const noexcept { return nodes_; }
    constexpr TtTime state_time() const noexcept { return state_t_; }
    // The accepted state in GCRS (for reports and tests).
    constexpr const OrbitState& state_gcrs() const noexcept { return state_; }

private:
    constexpr TtTime node_start(std::int64_t n) const noexcept { return {state_t_.us + n * kVelocityNodeUs}; }

    static constexpr bool plausible(const OrbitState& s) noexcept {
        const double rr = squared_norm(s.r_km);
        return rr >= kMinOrbitRadiusKm * kMinOrbitRadiusKm && rr <= kMaxOrbitRadiusKm * kMaxOrbitRadiusKm &&
               squared_norm(s.v_kms) <= kMaxOrbitSpeedKmS * kMaxOrbitSpeedKmS;  // false for NaN
    }

    // The Earth at t, linear between evaluations of the series on a 60 s TT
    // grid anchored at J2000 (so again one function of t, whatever the path):
    // |v''| ≤ 1.4e-9 m/s³ (earth_series.hpp), so the error is ≤ 60²/8 · 1.4e-9
    // = 6.3e-7 m/s; the series runs once per minute of flight, not per state.
    template <typename EarthFn>
    bool earth_at(TtTime t, EarthFn& earth, EarthBarycentric& out, Vector3<double>& rate_kms2) noexcept {
        std::int64_t k = t.us / kEarthNodeUs;
        if (k * kEarthNodeUs > t.us) {
            --k;  // floor for negative times
        }
        if (!earth_grid_valid_ || k != earth_k_) {
            if (earth_grid_valid_ && k == earth_k_ + 1) {
                earth_a_ = earth_b_;
                earth_a_ok_ = earth_b_ok_;
            } else {
                earth_a_ok_ = earth(tt_seconds(TtTime{k * kEarthNodeUs}), earth_a_);
            }
            earth_b_ok_ = earth(tt_seconds(TtTime{(k + 1) * kEarthNodeUs}), earth_b_);
            earth_k_ = k;
            earth_grid_valid_ = true;
        }
        const double f = static_cast<double>(t.us - k * kEarthNodeUs) * (1.0 / static_cast<double>(kEarthNodeUs));
        const Vector3<double> chord = earth_b_.v_earth_icrf_kms - earth_a_.v_earth_icrf_kms;
        rate_kms2 = (static_cast<double>(kMicrosecondsPerSecond) / static_cast<double>(kEarthNodeUs)) * chord;
        out.v_earth_icrf_kms = earth_a_.v_earth_icrf_kms + f * chord;
        out.sun_distance_au = earth_a_.sun_distance_au + f * (earth_b_.sun_distance_au - earth_a_.sun_distance_au);
        return earth_a_ok_ && earth_b_ok_;
    }

    // The node at t_n = t_state + n·10 s: β(t) = β_n + (t − t_n)·β'_n, the
    // first-order Taylor series of the propagated state (velocity y_n.v and
    // acceleration a_n, the J2 force) plus the Earth's (its grid chord).
    // Truncation: ½·|jerk|·dt² with |jerk| = n·|a| ≤ 1.13e-3 · 8.4 = 9.5e-3 m/s³
    // in LEO: ≤ 4.8e-3 m/s 1 s after a state, ≤ 0.48 m/s (0.0003″) at the end
    // of a node in a gap. A fresh state costs one force evaluation, not an RK4
    // step: with 1 Hz GNSS states the service never steps.
    template <typename EarthFn>
    void build_node(EarthFn& earth) noexcept {
        EarthBarycentric e{};
        Vector3<double> e_rate{};
        const bool e_ok = earth_at(node_start(cursor_n_), earth, e, e_rate);
        node_t0_ = node_start(cursor_n_);
        node_present_ = true;
        ++nodes_;
        node_status_ = 0U;
        if (!(e_ok && plausible(y_n_))) {
            node_status_ = status::kNoVelocity | status::kVelocityInvalid;
            return;
        }
        constexpr double inv_c = 1.0 / kSpeedOfLightKmS;
        const Vector3<double> b0 = inv_c * (e.v_earth_icrf_kms + y_n_.v_kms);
        const Vector3<double> db = (inv_c * kPropagationStepS) * (e_rate + a_n_);  // over one node
        const double inv_s = 1.0 / e.sun_distance_au;
        if (!(squared_norm(b0) <= kMaxBeta * kMaxBeta && squared_norm(db) <= 1e-12 && inv_s > 0.1 && inv_s < 10.0)) {
            node_status_ = status::kNoVelocity | status::kVelocityInvalid;
            return;
        }
        beta0_ = {scalar_from_double(b0.x, T{}), scalar_from_double(b0.y, T{}), scalar_from_double(b0.z, T{})};
        dbeta_ = {scalar_from_double(db.x, T{}), scalar_from_double(db.y, T{}), scalar_from_double(db.z, T{})};
        inv_sun_distance_ = scalar_from_double(inv_s, T{});
    }

    VelocityServiceConfig cfg_;
    StateCounts counts_{};
    std::uint32_t steps_ = 0U;
    std::uint32_t nodes_ = 0U;
    bool has_state_ = false;
    TtTime state_t_{0};
    OrbitState state_{};
    Vector3<double> pole_gcrs_{0.0, 0.0, 1.0};
    // Propagation cursor: the state at node n and its acceleration.
    std::int64_t cursor_n_ = -1;
    OrbitState y_n_{};
    Vector3<double> a_n_{};
    // The Earth on its 60 s grid: samples at k and k + 1.
    bool earth_grid_valid_ = false;
    std::int64_t earth_k_ = 0;
    EarthBarycentric earth_a_{};
    EarthBarycentric earth_b_{};
    bool earth_a_ok_ = false;
    bool earth_b_ok_ = false;
    // The node the per-solution query reads.
    bool node_present_ = false;
    TtTime node_t0_{0};
    Vector3<T> beta0_{};
    Vector3<T> dbeta_{};
    T inv_sun_distance_{};
    StatusBits node_status_ = 0U;
};

// The corrected solution's status with the service's: the solution keeps the
// core's bits and gains 512 (stale) or 32 (invalid) when the service withheld
// the velocity, unless the solution was rejected or aberration is off.
constexpr StatusBits with_service_status(StatusBits corrected, StatusBits service, bool aberration) noexcept {
    if (!aberration || (corrected & status::kRejected) != 0U) {
        return corrected;
    }
    return static_cast<StatusBits>(corrected | service);
}

}  // namespace ascorr
