// ascorr/nav/velocity_node.hpp: the observer velocity over one 10 s node, and
// its per-solution query.
//
// Conventions: a node starts at t₀ = t_state + n·10 s (kVelocityNodeUs, one
// RK4 step of orbit_propagation.hpp) and holds, in the core's scalar T,
//   β(t) = β₀ + f·Δβ,  f = (t − t₀)/10 s,  for t in [t₀, t₀ + 10 s],
// the first-order Taylor series of β_icrf = (v_earth_icrf + v_sc_gcrs)/c:
// β₀ from the propagated velocity and the Earth's (earth_grid.hpp), Δβ from the
// J2 acceleration and the Earth's rate, over one node; and 1/s (Sun distance
// in au) at t₀.
// Truncation: ½·|jerk|·dt² with |jerk| = n·|a| ≤ 1.13e-3 · 8.4 = 9.5e-3 m/s³
// in LEO: ≤ 4.8e-3 m/s 1 s after a state, ≤ 0.48 m/s (3e-4″) at the end of a
// node in a gap. Q30 rounds β₀, Δβ and f·Δβ to 2⁻³¹: ≤ 3 · 4.7e-10 · c
// = 0.42 m/s (3e-4″).
// build() is double (software on the Cortex-M3), once per node. query() is
// the per-solution query (VelocityService::velocity_at): integer microseconds to f, one product and
// one sum per component in T; no double, no division: free of soft-float
// (tests/target/check-no-soft-float).
#pragma once

#include <cstdint>

#include "../core/aberration.hpp"
#include "../core/constants.hpp"
#include "../core/correct.hpp"
#include "../core/fixed_point.hpp"
#include "../core/fx.hpp"
#include "../core/status.hpp"
#include "../core/vector3.hpp"
#include "earth_series.hpp"
#include "orbit_propagation.hpp"
#include "state_gate.hpp"
#include "tt_time.hpp"

namespace ascorr {

template <typename T>
struct ServiceVelocity {
    ObserverVelocity<T> velocity;
    StatusBits status;  // 0, 4, 4|512 or 4|32 (velocity_service.hpp)
};

inline constexpr std::int64_t kVelocityNodeUs = 10000000;  // kPropagationStepS in µs
static_assert(kPropagationStepS * 1e6 == static_cast<double>(kVelocityNodeUs), "one node per RK4 step");

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
    return {fx::narrow<31>(std::int64_t{dt_us} * kMul)};
}

template <typename T>
class VelocityNode {
public:
    // The node at t0 from the state y propagated to t0 (a_kms2: its J2
    // acceleration) and the Earth there (e, e_rate_kms2; earth_ok: the series
    // was inside its span). A node whose state left the plausible orbit
    // (state_gate.hpp), whose Earth is unknown or whose β, Δβ or 1/s are out
    // of range answers 4|32 (status::kVelocityInvalid).
    void build(TtTime t0, const OrbitState& y, const Vector3<double>& a_kms2, const EarthBarycentric& e,
               const Vector3<double>& e_rate_kms2, bool earth_ok) noexcept {
        t0_ = t0;
        present_ = true;
        status_ = 0U;
        if (!(earth_ok && plausible_orbit(y))) {
            status_ = status::kNoVelocity | status::kVelocityInvalid;
            return;
        }
        constexpr double inv_c = 1.0 / kSpeedOfLightKmS;
        const Vector3<double> b0 = inv_c * (e.v_earth_icrf_kms + y.v_kms);
        const Vector3<double> db = (inv_c * kPropagationStepS) * (e_rate_kms2 + a_kms2);  // over one node
        const double inv_s = 1.0 / e.sun_distance_au;
        if (!(squared_norm(b0) <= kMaxBeta * kMaxBeta && squared_norm(db) <= 1e-12 && inv_s > 0.1 && inv_s < 10.0)) {
            status_ = status::kNoVelocity | status::kVelocityInvalid;
            return;
        }
        // To T, rounded to nearest (ScalarTraits<T>::from_double): β ≤ 3.4e-3
        // and Δβ ≤ 1e-6 are inside every scalar's range; 1/s ≤ 1.02 on the
        // Earth's orbit (the check above admits < 10; Q30 saturates at 2).
        const auto to_t = [](double x) { return ScalarTraits<T>::from_double(x); };
        beta0_ = {to_t(b0.x), to_t(b0.y), to_t(b0.z)};
        dbeta_ = {to_t(db.x), to_t(db.y), to_t(db.z)};
        inv_sun_distance_ = to_t(inv_s);
    }

    // t in [t₀, t₀ + 10 s): this node is the one to build β at t from
    // (integer compares only).
    constexpr bool holds(TtTime t) const noexcept { return present_ && t0_ <= t && t.us - t0_.us < kVelocityNodeUs; }

    // The per-solution query, in T (no double, no division): out.status
    // 4|512 when there is no node or t is outside [t₀, t₀ + 10 s], the node's
    // 4|32 when build() refused it, else 0 with out.velocity = β₀ + f·Δβ.
    constexpr void query(TtTime t, ServiceVelocity<T>& out) const noexcept {
        const std::int64_t dt = t.us - t0_.us;
        if (!present_ || dt < 0 || dt > kVelocityNodeUs) {
            out.status = status::kNoVelocity | status::kStale;
            return;
        }
        if (status_ != 0U) {
            out.status = status_;
            return;
        }
        const T f = node_fraction(static_cast<std::int32_t>(dt), T{});
        out.velocity = {beta0_ + f * dbeta_, inv_sun_distance_, true};
        out.status = 0U;
    }

    // Forgets the node (a new state was accepted).
    constexpr void clear() noexcept { present_ = false; }

private:
    bool present_ = false;
    TtTime t0_{0};
    Vector3<T> beta0_{};
    Vector3<T> dbeta_{};
    T inv_sun_distance_{};
    StatusBits status_ = 0U;
};

}  // namespace ascorr
