// ascorr/pipeline/head_lags.hpp: the lag stage, each lagged head's
// temperatures as its model's terms take them (a model's lag_s, issue 40;
// docs/contract.md, "The bench's lag").
//
// Conventions: a head with a lag τ (configure) has its three channels
// stepped through a TemperatureLag<T> (temperature_lag.hpp) at each of its
// solutions' times, in the order the solutions come (on board: time order);
// the solution's terms then take L in place of each usable reading, as the
// host's `correct` does (ascorr_host/correct/lagged_temperatures.hpp):
//  - a reading the solution has (valid, within the core's domain) becomes L
//    once its channel has started; otherwise the reading stays as it came,
//    so the core says why it cannot use it, as without a lag;
//  - a solution at the head's last time takes the state at that time (each
//    channel advanced at its first usable reading there);
//  - a solution earlier than the head's last time, or with no time at all,
//    has no lagged temperatures: its channels are marked missing (status 8,
//    no thermal stage), never the unlagged readings.
// A head without a lag keeps its readings. Bounded and allocation-free: no
// loop but over the three channels (and TemperatureLag's bounded α).
#pragma once

#include <cstdint>

#include "../core/heads.hpp"
#include "../core/thermal.hpp"
#include "temperature_lag.hpp"

namespace ascorr::pipeline {

// Whether any of kMaxHeads τ (tau_s[h] for head h, 0 for none) lags a head:
// the one test of "a head lags" for a model, CALIB_START and the host.
template <typename Taus>
constexpr bool any_lagged(const Taus& tau_s) noexcept {
    bool any = false;
    for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
        any = any || tau_s[h] != 0.0;
    }
    return any;
}

template <typename T>
class HeadLags {
public:
    // Head h's τ in seconds: 0 for none, otherwise within [kMinLagTauS,
    // kMaxLagTauS]; an accepted τ starts the head's lag afresh. A head or τ
    // out of range: false, nothing changed.
    bool configure(std::uint8_t h, double tau_s) noexcept {
        if (h >= kMaxHeads) {
            return false;
        }
        if (tau_s == 0.0) {
            on_[h] = false;
            return true;
        }
        if (!lag_[h].configure(tau_s)) {
            return false;
        }
        on_[h] = true;
        return true;
    }

    // Every head's τ at once (tau_s[h] for head h, as configure()); false
    // when one is refused (that head unchanged, the others configured).
    template <typename Taus>
    bool configure_all(const Taus& tau_s) noexcept {
        bool ok = true;
        for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
            ok = configure(h, tau_s[h]) && ok;
        }
        return ok;
    }

    bool lags(std::uint8_t h) const noexcept { return h < kMaxHeads && on_[h]; }
    bool any() const noexcept {
        bool a = false;
        for (const bool on : on_) {
            a = a || on;
        }
        return a;
    }

    // The stage for a solution of head h at t_us (TT µs): temps as its
    // terms take them (above).
    void apply(std::uint8_t h, std::int64_t t_us, HeadTemperatures<T>& temps) noexcept {
        if (!lags(h)) {
            return;
        }
        if (!lag_[h].lag_in_place(t_us, temps)) {  // earlier than the head's last, or no time
            without_time(h, temps);
        }
    }

    // A solution of head h with no time: no lagged temperatures (above).
    void without_time(std::uint8_t h, HeadTemperatures<T>& temps) const noexcept {
        if (lags(h)) {
            temps.t_chu.valid = false;
            temps.t_029.valid = false;
            temps.t_032.valid = false;
        }
    }

private:
    TemperatureLag<T> lag_[kMaxHeads]{};
    bool on_[kMaxHeads] = {};
};

}  // namespace ascorr::pipeline
