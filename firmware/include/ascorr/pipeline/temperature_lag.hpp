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
// Cost per step: the channels that advanced at the lag's last time (all of
// them, but after a withheld reading) share one Δt and so one α, looked up
// once among the lag's last two Δt (a head's cadence repeats, or alternates
// between two values when times are rounded, as 45/46 ms at 22 Hz); then per
// channel two subtractions and one multiply-add. Only a third Δt, or a
// channel catching up over its own interval, forms α, in double by
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
// Scalars: double, float and Q30. Fixed point (Q30, the core's temperatures
// in QCelsius Q11.20, q_formats.hpp): T and L are QCelsius, α is Q30 in
// (0, 1] (rounded to nearest from the double α; α = 1 exact), and the state
// D is held in int64 at 2⁻⁵⁰ °C, the exact scale of a Q30·QCelsius product,
// so that a small α·u is never rounded away. (In QCelsius itself a step with
// |α·u| below half an LSB would not decay at all: a dead band of 0.5/α LSB,
// 0.01 °C at τ = 900 s and 22 Hz, 0.9 °C at a day, measured as such.) One step:
//   u = D − (T − T_last)·2³⁰  exact in int64;
//   D ← u − round(α·u)        α·u formed exactly in two 32×32 → 64 products
//                             (u split at bit 30), rounded to nearest once
//                             (ties towards +∞): error ≤ 2⁻⁵¹ °C.
// Range: round(α·u) lies between 0 and u (α·u does, and u is an integer), so
// the new L = T + D lies between the old L and T: L never leaves the hull of
// the channel's readings, which the domain check keeps within
// ±kMaxAbsTemperatureC (200 °C). So |D| ≤ 400 °C (< 2⁵⁹ at 2⁻⁵⁰), u's high
// part (u >> 30) fits int32 and α·u's low part (< 2⁶⁰) fits int64; L, D
// rounded to QCelsius (≤ 2⁻²¹ °C) and their sum stay within ±200 °C: no
// operation can overflow, none saturates.
// α's own rounding (≤ 2⁻³¹) is a relative error of τ of at most 2⁻³¹·τ/Δt:
// 1e-5 at τ = 900 s and 22 Hz, 9e-4 at a day (below any τ a fit resolves).
#pragma once

#include <cstdint>
#include <type_traits>

#include "../calib/portable_math.hpp"
#include "../core/constants.hpp"
#include "../core/q_formats.hpp"
#include "../core/thermal.hpp"

namespace ascorr::pipeline {

// The step's arithmetic in T's formats: State holds D, input() forms u,
// decay() u − α·u, deviation() D as a temperature (floating point: as
// written, in T; Q30: the int64 state above).
template <typename T>
struct LagArithmetic {
    using C = Celsius<T>;
    using State = C;
    static constexpr State input(State d, C reading, C last) noexcept { return d - (reading - last); }
    static constexpr State decay(T alpha, State u) noexcept { return u - alpha * u; }
    static constexpr C deviation(State d) noexcept { return d; }
    static constexpr C sum(C reading, C d) noexcept { return reading + d; }
};

template <>
struct LagArithmetic<Q30> {
    using C = QCelsius;
    using State = std::int64_t;                    // D·2⁵⁰ (°C)
    static constexpr int kExtra = Q30::kFracBits;  // the state's bits below QCelsius'
    static constexpr State input(State d, C reading, C last) noexcept {
        return d - fx::mul(reading.raw - last.raw, std::int32_t{1} << kExtra);  // ΔT ≤ 400 °C: exact
    }
    static constexpr State decay(Q30 alpha, State u) noexcept {
        const auto hi = static_cast<std::int32_t>(u >> kExtra);  // |u| < 2⁵⁹: fits
        const auto lo = static_cast<std::uint32_t>(u & ((State{1} << kExtra) - 1));
        const std::uint64_t low = static_cast<std::uint64_t>(static_cast<std::uint32_t>(alpha.raw)) * lo;  // < 2⁶⁰
        return u - (fx::mul(alpha.raw, hi) + static_cast<State>((low + (std::uint64_t{1} << (kExtra - 1))) >> kExtra));
    }
    static constexpr C deviation(State d) noexcept { return {static_cast<std::int32_t>(fx::round_shift<kExtra>(d))}; }
    static constexpr C sum(C reading, C d) noexcept { return {reading.raw + d.raw}; }  // |L| ≤ 200 °C: exact
};

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
    using Arithmetic = LagArithmetic<T>;
    using C = Celsius<T>;  // T for floating point, QCelsius for Q30

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
        cache_ = AlphaCache{};
        have_time_ = false;
        configured_ = true;
        return true;
    }

    // One reading of the head's temperatures at t_us; each channel's outcome.
    LagSteps step(std::int64_t t_us, const HeadTemperatures<T>& temps) noexcept {
        if (!configured_) {
            return {{LagStep::kNotConfigured, LagStep::kNotConfigured, LagStep::kNotConfigured}};
        }
        if (!(t_us > -kMaxLagTimeUs && t_us < kMaxLagTimeUs)) {
            return {{LagStep::kBadTime, LagStep::kBadTime, LagStep::kBadTime}};
        }
        // The α of the channels that advanced at the lag's last time.
        const bool ahead = have_time_ && t_us > t_us_;
        const T alpha = ahead ? alpha_for(t_us - t_us_) : T{};
        const LagSteps s{{advance(ch_[0], t_us, temps.t_chu, ahead, alpha),
                          advance(ch_[1], t_us, temps.t_029, ahead, alpha),
                          advance(ch_[2], t_us, temps.t_032, ahead, alpha)}};
        if (!have_time_ || t_us > t_us_) {
            const bool moved = moves(s);
            t_us_ = moved ? t_us : t_us_;
            have_time_ = have_time_ || moved;
        }
        return s;
    }

    // Whether t_us is before the last time a channel started or advanced at.
    bool before_last(std::int64_t t_us) const noexcept { return have_time_ && t_us < t_us_; }

    // step() for a solution (the lag stage, head_lags.hpp): temps stepped in,
    // then each reading the step took (usable, so its channel has started:
    // advanced, started, or at the same t as its last) replaced by L. false,
    // temps unchanged, when t_us is before the lag's last time or not a time,
    // or no τ was configured.
    bool lag_in_place(std::int64_t t_us, HeadTemperatures<T>& temps) noexcept {
        if (before_last(t_us)) {
            return false;
        }
        const LagSteps s = step(t_us, temps);
        if (s.channel[0] == LagStep::kBadTime || s.channel[0] == LagStep::kNotConfigured) {  // every channel's
            return false;
        }
        put(s.channel[0], ch_[0], temps.t_chu);
        put(s.channel[1], ch_[1], temps.t_029);
        put(s.channel[2], ch_[2], temps.t_032);
        return true;
    }

    // Channel k's deviation D = L − T at its last reading (°C), valid once
    // the channel has started: the regressor of a lagged term.
    TemperatureReading<T> deviation(std::uint8_t k) const noexcept {
        const Channel& c = ch_[k < kLagChannels ? k : 0];
        return {Arithmetic::deviation(c.d), k < kLagChannels && c.started};
    }

    // Channel k's lagged temperature L = T + D at its last reading (°C).
    TemperatureReading<T> lagged(std::uint8_t k) const noexcept {
        const TemperatureReading<T> d = deviation(k);
        return {Arithmetic::sum(ch_[k < kLagChannels ? k : 0].t_reading, d.value), d.valid};
    }

private:
    struct Channel {
        typename Arithmetic::State d{};  // D = L − T at the last reading, °C
        C t_reading{};                   // the last reading, °C
        std::int64_t t_us = 0;           // the time of the last reading
        bool started = false;
    };
    // The last two Δt an α was formed for (−1: none), and which was used last.
    struct AlphaCache {
        std::int64_t dt_us[2] = {-1, -1};
        T alpha[2]{};
        std::uint8_t newer = 0;
    };

    static void put(LagStep s, const Channel& c, TemperatureReading<T>& r) noexcept {
        if (s != LagStep::kHeld) {
            r.value = Arithmetic::sum(c.t_reading, Arithmetic::deviation(c.d));
        }
    }

    static bool moves(const LagSteps& s) noexcept {
        bool m = false;
        for (const LagStep k : s.channel) {
            m = m || k == LagStep::kStarted || k == LagStep::kAdvanced;
        }
        return m;
    }

    // ahead: t_us is after the lag's last time, whose channels take `alpha`.
    LagStep advance(Channel& c, std::int64_t t_us, const TemperatureReading<T>& r, bool ahead, T alpha) const noexcept {
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
        // No overflow: both times within ±kMaxLagTimeUs. A channel that was
        // withheld since catches up over its own interval.
        const T a = ahead && c.t_us == t_us_ ? alpha : alpha_of(t_us - c.t_us);
        const typename Arithmetic::State u = Arithmetic::input(c.d, r.value, c.t_reading);
        c.d = Arithmetic::decay(a, u);
        c.t_reading = r.value;
        c.t_us = t_us;
        return LagStep::kAdvanced;
    }

    // α = 1 − e^(−Δt/τ) for dt_us > 0, in (0, 1], in double by
    // expm1_nonpositive, rounded once to T.
    T alpha_of(std::int64_t dt_us) const noexcept {
        return ScalarTraits<T>::from_double(-calib::expm1_nonpositive(-static_cast<double>(dt_us) * inv_tau_per_us_));
    }

    // alpha_of(dt_us): one of the last two, or formed into the older slot.
    T alpha_for(std::int64_t dt_us) noexcept {
        AlphaCache& k = cache_;
        if (dt_us == k.dt_us[k.newer]) {
            return k.alpha[k.newer];
        }
        const std::uint8_t other = k.newer ^ 1U;
        if (dt_us != k.dt_us[other]) {
            k.alpha[other] = alpha_of(dt_us);
            k.dt_us[other] = dt_us;
        }
        k.newer = other;
        return k.alpha[other];
    }

    Channel ch_[kLagChannels]{};
    AlphaCache cache_{};
    std::int64_t t_us_ = 0;  // the last time a channel started or advanced at (have_time_)
    bool have_time_ = false;
    double inv_tau_per_us_ = 0.0;  // α is formed in double (alpha_of)
    bool configured_ = false;
};

}  // namespace ascorr::pipeline
