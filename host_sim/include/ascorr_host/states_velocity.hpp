// ascorr_host/states_velocity.hpp: a solution row's velocity from the states,
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

#include "ascorr/velocity_service.hpp"
#include "ascorr_host/states_csv.hpp"

namespace ascorr::host {

// Service configuration for `--max-propagation SECONDS` (> 0, ≤ 7 days;
// InputError-free: the command line checks it): advance() catches up in one call.
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
