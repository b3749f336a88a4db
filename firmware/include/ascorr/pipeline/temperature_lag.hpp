// ascorr/pipeline/temperature_lag.hpp: a head's temperatures as the bench
// feels them, through a first-order lag (the first part of issue 40's lagged
// model terms; measured in docs/ground.md, "The bench inside the orbit").
//
// Physics: the bench deforms with temperatures L that lag its thermistors'
// readings T, τ·dL/dt = T − L. Over a step of Δt with T held at the newer
// reading (the recursion `ascorr simulate --bench-lag` uses) the exact
// solution is
//     L ← L + α·(T − L),   α = 1 − e^(−Δt/τ) = −expm1(−Δt/τ).
// Well-scaled form: the state is the deviation D = L − T, not L. With
// ΔT the change of the reading since the channel's last one,
//     D ← (1 − α)·(D − ΔT) = u − α·u,   u = D − ΔT.
// D is what a lagged model term regresses on (L − T), and it stays small
// (about the temperature's rate times τ, a few °C), so each step rounds D,
// not a 20 °C L: in float at 22 Hz and τ = 900 s, 1.9e-5 °C against the
// plain form's 1.6e-4 °C (test TemperatureLag.FloatAt22HzKeepsTheDeviationsPrecision).
//
// Channels: T1 (T_CHU), T2 (THT00029), T3 (THT00032) of HeadTemperatures,
// each with its own last time, so a reading withheld on one channel leaves
// the others running; the channel's next reading advances it over the whole
// interval (its reading held, as across a gap).
// Time: TT µs, a signed 64-bit count (the flight loop's tag; the host passes
// llround(t · 1e6) of a row's t).
// Cost per channel and step: two integer compares of Δt with the channel's
// last two Δt (a head's cadence repeats, or alternates between two values
// when times are rounded, as 45/46 ms at 22 Hz), then two subtractions and
// one multiply-add; only a third Δt forms α, in double by
// calib::expm1_nonpositive (+ − × ÷ alone, so the DPU and the host form the
// same bits, as the estimator's forgetting factor; libm's expm1 is not
// correctly rounded and differs between libraries), rounded once to T.
// No division on the step (1/τ is formed by configure()), no loop on the
// step but α's bounded halvings, no allocation, no exceptions.
// Bad input, each leaves the channel as it was and says why (LagStep):
// a reading not valid or outside the core's domain (±kMaxAbsTemperatureC,
// NaN included) is kHeld; a time not after the channel's last is
// kTimeNotIncreasing, one with |t| ≥ kMaxLagTimeUs (4.6e18 µs) kBadTime; a
// lag never configured (τ in [kMinLagTauS, kMaxLagTauS]) is kNotConfigured.
// configure() with a τ out of range changes nothing and returns false.
// Scalars: double and float. Q30 has no kernel yet: T must be floating point.
#pragma once

#include <cstdint>
#include <type_traits>

#include "../calib/portable_math.hpp"
#include "../core/constants.hpp"
#include "../core/thermal.hpp"

namespace ascorr::pipeline {

inline constexpr double kMinLagTauS = 1.0;      // shorter is no lag at a head's cadence
inline constexpr double kMaxLagTauS = 86400.0;  // as simulate's --bench-lag: one day
// |t| below this (µs), so that t − t_last cannot overflow int64: 1/2 of 2⁶³
// rounded down, about 146 000 years.
inline constexpr std::int64_t kMaxLagTimeUs = 4'611'686'018'427'387'903;

enum class LagStep : std::uint8_t {
    kStarted,            // the channel's first reading: D = 0
    kAdvanced,           // D advanced over Δt
    kHeld,               // reading not valid or outside the domain: channel unchanged
    kTimeNotIncreasing,  // t ≤ the channel's last time: channel unchanged
    kBadTime,            // |t| ≥ kMaxLagTimeUs: channel unchanged
    kNotConfigured,      // configure() has not accepted a τ
};

inline constexpr std::uint8_t kLagChannels = 3;  // T1, T2, T3, as HeadTemperatures

struct LagSteps {
    LagStep channel[kLagChannels];
};

template <typename T>
class TemperatureLag {
    static_assert(std::is_floating_point<T>::value, "temperature_lag.hpp: double or float (no Q30 kernel yet)");

public:
    // τ in seconds, in [kMinLagTauS, kMaxLagTauS]: every channel starts
    // again at its next reading. Otherwise (NaN included) false, and the lag
    // stays as it was.
    bool configure(double tau_s) noexcept {
        if (!(tau_s >= kMinLagTauS && tau_s <= kMaxLagTauS)) {
            return false;
        }
        inv_tau_per_us_ = 1.0 / (tau_s * 1e6);  // in [1.2e-11, 1e-6]
        for (Channel& c : ch_) {
            c = Channel{};
        }
        configured_ = true;
        return true;
    }

    // One reading of the head's temperatures at t_us; each channel's outcome.
    LagSteps step(std::int64_t t_us, const HeadTemperatures<T>& temps) noexcept {
        return {{advance(ch_[0], t_us, temps.t_chu), advance(ch_[1], t_us, temps.t_029),
                 advance(ch_[2], t_us, temps.t_032)}};
    }

    // Channel k's deviation D = L − T at its last reading (°C), valid once
    // the channel has started: the regressor of a lagged term.
    TemperatureReading<T> deviation(std::uint8_t k) const noexcept {
        const Channel& c = ch_[k < kLagChannels ? k : 0];
        return {c.d, k < kLagChannels && c.started};
    }

    // Channel k's lagged temperature L = T + D at its last reading (°C).
    TemperatureReading<T> lagged(std::uint8_t k) const noexcept {
        const TemperatureReading<T> d = deviation(k);
        return {ch_[k < kLagChannels ? k : 0].t_reading + d.value, d.valid};
    }

private:
    struct Channel {
        T d = T(0);          // D = L − T at the last reading, °C
        T t_reading = T(0);  // the last reading, °C
        std::int64_t t_us = 0;
        std::int64_t dt_us[2] = {-1, -1};  // the last two Δt α was formed for; −1 none
        T alpha[2] = {T(0), T(0)};
        std::uint8_t newer = 0;  // the slot used last; a third Δt replaces the other
        bool started = false;
    };

    LagStep advance(Channel& c, std::int64_t t_us, const TemperatureReading<T>& r) const noexcept {
        if (!configured_) {
            return LagStep::kNotConfigured;
        }
        if (!(t_us > -kMaxLagTimeUs && t_us < kMaxLagTimeUs)) {
            return LagStep::kBadTime;
        }
        if (!r.valid || !temperature_in_domain<T>(r.value)) {
            return LagStep::kHeld;
        }
        if (!c.started) {
            c = Channel{};
            c.t_reading = r.value;
            c.t_us = t_us;
            c.started = true;
            return LagStep::kStarted;
        }
        if (t_us <= c.t_us) {
            return LagStep::kTimeNotIncreasing;
        }
        const std::int64_t dt_us = t_us - c.t_us;  // no overflow: both within ±kMaxLagTimeUs
        const T u = c.d - (r.value - c.t_reading);
        c.d = u - alpha_for(c, dt_us) * u;
        c.t_reading = r.value;
        c.t_us = t_us;
        return LagStep::kAdvanced;
    }

    // α = 1 − e^(−Δt/τ) for dt_us > 0, in (0, 1]: one of the channel's last
    // two, or formed into the older slot.
    T alpha_for(Channel& c, std::int64_t dt_us) const noexcept {
        if (dt_us == c.dt_us[c.newer]) {
            return c.alpha[c.newer];
        }
        const std::uint8_t other = c.newer ^ 1U;
        if (dt_us != c.dt_us[other]) {
            c.alpha[other] = static_cast<T>(-calib::expm1_nonpositive(-static_cast<double>(dt_us) * inv_tau_per_us_));
            c.dt_us[other] = dt_us;
        }
        c.newer = other;
        return c.alpha[other];
    }

    Channel ch_[kLagChannels]{};
    double inv_tau_per_us_ = 0.0;  // α is formed in double (alpha_for)
    bool configured_ = false;
};

}  // namespace ascorr::pipeline
