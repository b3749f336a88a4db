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
// The parts: the state gate (state_gate.hpp: the verdicts on each state), the
// Earth on its 60 s grid (earth_grid.hpp), the velocity node and its query
// (velocity_node.hpp); this header composes them with the propagation
// (orbit_propagation.hpp). Two paths, for the FPU-less Cortex-M3:
//  - push_state() and advance() are double (software on the M3): the frame
//    conversion once per state, one force evaluation per state, one RK4 step
//    per 10 s of flight beyond the latest state (gaps, uplinked states) and one
//    Earth series per minute, bounded by max_steps_per_advance per call (no
//    unbounded loop);
//  - velocity_at() is the per-solution query, in the core's scalar T:
//    β = β₀ + f·Δβ, f = (t − t₀)/10 s from integer microseconds. No double, no
//    division: free of soft-float (tests/target/check-no-soft-float). Its
//    error (Taylor and rounding) is velocity_node.hpp's.
// Bad states are refused, counted (StateCounts) and reported by verdict
// (state_gate.hpp); the service keeps its latest accepted state, so nothing
// already known is lost.
#pragma once

#include <cstdint>

#include "../core/aberration.hpp"
#include "../core/scalar_traits.hpp"
#include "../core/status.hpp"
#include "../core/vector3.hpp"
#include "earth_frame.hpp"
#include "earth_grid.hpp"
#include "orbit_propagation.hpp"
#include "state_gate.hpp"
#include "tt_time.hpp"
#include "velocity_node.hpp"

namespace ascorr {

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

// The longest horizon a configuration may have (7 days): beyond it the J2
// propagation is far outside its accuracy, and one advance() of
// horizon / kVelocityNodeUs + 1 RK4 steps (60 481) stays bounded.
inline constexpr std::int64_t kMaxHorizonUs = 7LL * 86400LL * kMicrosecondsPerSecond;

// The configuration for a horizon in (0, kMaxHorizonUs] (the callers check
// it): one advance() can reach the horizon (horizon / 10 s steps + 1).
constexpr VelocityServiceConfig velocity_service_config(std::int64_t horizon_us) noexcept {
    return {horizon_us, kDefaultTtMinusUt1Us, static_cast<std::uint32_t>(horizon_us / kVelocityNodeUs + 1)};
}

constexpr VelocityServiceConfig default_velocity_service_config() noexcept {
    return velocity_service_config(kDefaultHorizonUs);
}

template <typename T>
class VelocityService {
public:
    explicit constexpr VelocityService(const VelocityServiceConfig& cfg) noexcept : cfg_(cfg) {}

    // A state, double, checked (state_gate.hpp) and converted to GCRS once
    // (outside the per-solution path).
    StateVerdict push_state(TtTime t, const Vector3<double>& r_km, const Vector3<double>& v_kms,
                            StateFrame frame) noexcept {
        const StateVerdict verdict = gate_.admit(t, r_km, v_kms);
        if (verdict != StateVerdict::kAccepted) {
            return verdict;
        }
        const CelestialFromTerrestrial m = celestial_from_terrestrial(t, cfg_.tt_minus_ut1_us);
        pole_gcrs_ = m.pole_gcrs;
        if (frame == StateFrame::kItrf) {
            itrf_to_gcrs(m, r_km, v_kms, state_.r_km, state_.v_kms);
        } else {
            state_ = {r_km, v_kms};
        }
        cursor_n_ = -1;
        node_.clear();
        return verdict;
    }

    // The checks of push_state() without changing anything.
    StateVerdict check_state(TtTime t, const Vector3<double>& r_km, const Vector3<double>& v_kms) const noexcept {
        return gate_.check(t, r_km, v_kms);
    }

    // Propagates (double) until the velocity node holding t is ready, taking
    // at most cfg.max_steps_per_advance RK4 steps; true when it is. earth is
    // called as earth(t_tt_j2000_s, EarthBarycentric&) → bool (OnBoardEarth) on a 60 s grid (once
    // per minute of flight, earth_grid.hpp). A t before the current node
    // restarts from the state (same bits).
    template <typename EarthFn>
    bool advance(TtTime t, EarthFn&& earth) noexcept {
        const TtTime state_t = gate_.latest();
        if (!gate_.has_state() || t < state_t || t.us - state_t.us > cfg_.horizon_us) {
            return false;
        }
        if (node_.holds(t)) {
            return true;  // the per-solution common case: integer compares only
        }
        const std::int64_t n_target = (t.us - state_t.us) / kVelocityNodeUs;
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
        // The node at t_n = t_state + n·10 s. A fresh state costs one force
        // evaluation, not an RK4 step: with 1 Hz GNSS states the service never steps.
        const TtTime t_n{state_t.us + cursor_n_ * kVelocityNodeUs};
        EarthBarycentric e{};
        Vector3<double> e_rate{};
        const bool e_ok = earth_.at(t_n, earth, e, e_rate);
        node_.build(t_n, y_n_, a_n_, e, e_rate, e_ok);
        ++nodes_;
        return true;
    }

    // The per-solution query, in T (no double, no division). advance(t) first.
    constexpr ServiceVelocity<T> velocity_at(TtTime t) const noexcept {
        constexpr T zero = constant<T>(0.0);  // constexpr: no conversion at run time (soft-float on the M3)
        constexpr T one = constant<T>(1.0);
        ServiceVelocity<T> out{{{zero, zero, zero}, one, false}, status::kNoVelocity};
        if (!gate_.has_state() || t < gate_.latest()) {
            return out;
        }
        if (t.us - gate_.latest().us > cfg_.horizon_us) {
            out.status = status::kNoVelocity | status::kStale;
            return out;
        }
        node_.query(t, out);
        return out;
    }

    constexpr const StateCounts& counts() const noexcept { return gate_.counts(); }
    constexpr bool has_state() const noexcept { return gate_.has_state(); }
    // RK4 steps taken and velocity nodes built so far (for cost reports).
    constexpr std::uint32_t steps_taken() const noexcept { return steps_; }
    constexpr std::uint32_t nodes_built() const noexcept { return nodes_; }
    constexpr TtTime state_time() const noexcept { return gate_.latest(); }
    // The accepted state in GCRS (for reports and tests).
    constexpr const OrbitState& state_gcrs() const noexcept { return state_; }

private:
    VelocityServiceConfig cfg_;
    StateGate gate_{};
    std::uint32_t steps_ = 0U;
    std::uint32_t nodes_ = 0U;
    OrbitState state_{};
    Vector3<double> pole_gcrs_{0.0, 0.0, 1.0};
    // Propagation cursor: the state at node n and its acceleration.
    std::int64_t cursor_n_ = -1;
    OrbitState y_n_{};
    Vector3<double> a_n_{};
    EarthGrid earth_{};
    VelocityNode<T> node_{};
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
