// ascorr_host/correct/states_velocity.hpp: a solution row's velocity from the states,
// by the on-board service (velocity_service.hpp) in the row's scalar.
//
// The service's answer for a time depends only on the latest accepted state at
// or before it (the propagation grid is anchored at the state), so the host
// may jump: for each row it picks that state by binary search, restarts the
// service from it when it changed, and advances. A DPU fed the same states in
// time order gives the same bits (tests/test_states_cli.cpp checks the jumps
// against a sequential service).
#pragma once

#include <algorithm>
#include <cstddef>

#include "ascorr/nav/velocity_service.hpp"
#include "ascorr_host/formats/states_csv.hpp"

namespace ascorr::host {

// The longest `--max-propagation` the host accepts (7 days): beyond it the J2
// propagation is far outside its accuracy (0.98 m/s after 6 h), and one
// advance() of horizon/10 s RK4 steps stays bounded.
inline constexpr double kMaxPropagationLimitS = 7.0 * kSecondsPerDay;

// Whether `--max-propagation` (or the Python module's max_propagation) is
// acceptable: above 0 and at most kMaxPropagationLimitS; NaN is not.
inline bool max_propagation_acceptable(double max_propagation_s) {
    return max_propagation_s > 0.0 && max_propagation_s <= kMaxPropagationLimitS;
}

// The refusal text for an unacceptable value, one wording for CLI and Python.
inline constexpr const char* kMaxPropagationRule = "must be above 0 and at most 604800 s (7 days)";
static_assert(kMaxPropagationLimitS == 604800.0, "kMaxPropagationRule states the limit in seconds");

// Service configuration for `--max-propagation SECONDS` (max_propagation_acceptable;
// InputError-free: the callers check it): advance() catches up in one call.
inline VelocityServiceConfig service_config(double max_propagation_s) {
    VelocityServiceConfig c = default_velocity_service_config();
    c.horizon_us = static_cast<std::int64_t>(std::llround(max_propagation_s * 1e6));
    c.max_steps_per_advance = static_cast<std::uint32_t>(c.horizon_us / kVelocityNodeUs + 1);
    return c;
}

template <typename T>
class StatesVelocity {
public:
    StatesVelocity(const StatesFile& states, const VelocityServiceConfig& cfg)
        : states_(states), cfg_(cfg), svc_(cfg) {}

    ServiceVelocity<T> at(double t_s) {
        TtTime t{};
        if (!tt_from_seconds(t_s, t)) {
            ServiceVelocity<T> out = VelocityService<T>(cfg_).velocity_at(TtTime{0});
            out.status = status::kNoVelocity | status::kVelocityInvalid;
            return out;
        }
        const auto& a = states_.accepted;
        const auto it =
            std::upper_bound(a.begin(), a.end(), t, [](const TtTime& x, const StateRecord& s) { return x < s.t; });
        if (it == a.begin()) {
            return VelocityService<T>(cfg_).velocity_at(t);  // no state yet: status 4
        }
        const auto idx = static_cast<std::size_t>(it - a.begin()) - 1;
        if (idx != current_) {
            svc_ = VelocityService<T>(cfg_);
            svc_.push_state(a[idx].t, a[idx].r_km, a[idx].v_kms, states_.frame);
            current_ = idx;
        }
        svc_.advance(t, OnBoardEarth{});
        return svc_.velocity_at(t);
    }

private:
    const StatesFile& states_;
    VelocityServiceConfig cfg_;
    VelocityService<T> svc_;
    std::size_t current_ = static_cast<std::size_t>(-1);
};

}  // namespace ascorr::host
