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
// them, but after a withheld reading) share one Δt and so one α, formed once;
// then per channel two subtractions and one multiply-add. α in double (the
// host) is calib::expm1_nonpositive (+ − × ÷ alone, so every build forms the
// same bits, as the estimator's forgetting factor; libm's expm1 is not
// correctly rounded and differs between libraries), rounded once to T, and
// kept for the lag's last two Δt (a head's cadence repeats, or alternates
// between two values when times are rounded, as 45/46 ms at 22 Hz). In float
// and Q30 (the targets, whose double is software) α comes from its series in
// T when Δt ≤ τ/256 (LagArithmetic::AlphaSeries, below): a few products
// whatever the times' jitter (22 Hz against any τ from 12 s), of which the
// usual step keeps the last two by Δt; a longer Δt takes the double path and
// its two kept values.
// The usual step (every channel in step, every reading usable) takes a path
// of its own (lag_in_place), the same operations without the bookkeeping:
// measured per solution in bench/target_bench.cpp (docs/figures.md).
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
// [0, 1] (its series, or rounded to nearest from the double α; α = 1
// exact), and the state
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
// Channels: each channel's last time is the lag's (in_step_) or its own
// (Channel::t_us), so that the usual step stores one time, not three.
#pragma once

#include <cmath>
#include <cstddef>
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
// AlphaSeries: α = 1 − e^(−x) = x − x²/2 + x³/6 − …, x = Δt/τ ≤ 2⁻⁸
// (kSeriesFraction): the terms from x⁴/24 on are below 2⁻³²·x/24, under
// float's and Q30's resolution of α. Double has none (its α is expm1's).
inline constexpr double kSeriesFraction = 0x1p-8;

template <typename T>
struct LagArithmetic {
    using C = Celsius<T>;
    using State = C;
    // Float: x = Δt·(1/τ) in T (Δt ≤ τ/256 < 2³¹ µs); each operation rounds
    // to 2⁻²⁴ relative, so α's relative error is a few 2⁻²⁴.
    struct AlphaSeries {
        T inv_tau_per_us{};
        static AlphaSeries of(double tau_us) noexcept { return {static_cast<T>(1.0 / tau_us)}; }
        T operator()(std::int32_t dt_us) const noexcept {
            const T x = static_cast<T>(dt_us) * inv_tau_per_us;
            return x * (T(1) - x * (T(0.5) - x * T(1.0 / 6.0)));
        }
    };
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
    // Q30: x = Δt·k·2⁻⁵¹ (k = 2⁵¹/τ in µs, rounded at configure: from
    // 2.3e9 at τ = 1 s down to 26 062 at a day, so k's rounding is a
    // relative error of τ below 2e-5, under α's own at a day, 9e-4). Δt <
    // 2²⁹ µs (τ/256 ≤ 3.4e8), so Δt·k < 2⁶¹ in uint64. The series is summed
    // at 2⁻⁴⁶ (x ≤ 2⁻⁸: x·2⁴⁶ ≤ 2³⁸; x², x³ from x rounded to Q30, ≤ 2²²
    // raw, an error below 2⁻³⁸ in them) and rounded to Q30 once: α within
    // half an LSB (4.7e-10) plus 2⁻⁴⁴ and k's rounding.
    struct AlphaSeries {
        std::uint32_t k = 0;
        static AlphaSeries of(double tau_us) noexcept {
            return {static_cast<std::uint32_t>(0x1p51 / tau_us + 0.5)};  // τ ≥ 1 s: < 2³²
        }
        Q30 operator()(std::int32_t dt_us) const noexcept {
            const std::uint64_t p = std::uint64_t{static_cast<std::uint32_t>(dt_us)} * k;
            const std::uint64_t x46 = (p + 16U) >> 5U;                                              // x·2⁴⁶
            const auto x30 = static_cast<std::uint32_t>((x46 + (1U << 15U)) >> 16U);                // ≤ 2²²
            const std::uint64_t sq = std::uint64_t{x30} * x30;                                      // x²·2⁶⁰
            const std::uint64_t cube = std::uint64_t{static_cast<std::uint32_t>(sq >> 30U)} * x30;  // x³·2⁶⁰
            const std::uint64_t a46 = x46 - (sq >> 15U) + static_cast<std::uint32_t>(cube >> 14U) / 6U;
            return {static_cast<std::int32_t>((a46 + (1U << 15U)) >> 16U)};
        }
    };
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

// The lags a search tries (`fit --lag auto`, host_sim's fit_lag.cpp; the
// self-calibration's, calib/lag_search.hpp): 300·2^(k/3) s rounded to whole
// seconds, k = 0 … 13, a third of an octave apart from 300 to 6048 s (the
// bench lags of the orbit's order, ωτ from 0.3 to 7 at 95 min).
inline constexpr double kLagGridBaseS = 300.0;
inline constexpr double kLagGridPerOctave = 3.0;
inline constexpr std::size_t kLagGridPoints = 14;
inline constexpr double kLagGridS[kLagGridPoints] = {300.0,  378.0,  476.0,  600.0,  756.0,  952.0,  1200.0,
                                                     1512.0, 1905.0, 2400.0, 3024.0, 3810.0, 4800.0, 6048.0};
// The index k of the grid point nearest τ (s) on the grid's log scale,
// round(3·log2(τ/300)); outside [0, kLagGridPoints) for a τ beyond the grid.
inline int lag_grid_index(double tau_s) noexcept {
    return static_cast<int>(std::lround(kLagGridPerOctave * std::log2(tau_s / kLagGridBaseS)));
}

inline constexpr double kMinLagTauS = 1.0;      // shorter is no lag at a head's cadence
inline constexpr double kMaxLagTauS = 86400.0;  // as simulate's --bench-lag: one day
// |t| below this (µs), so that t − t_last cannot overflow int64: 2⁶², 1/2 of
// 2⁶³ (t < 2⁶² is one compare of t's upper word), about 146 000 years.
inline constexpr std::int64_t kMaxLagTimeUs = std::int64_t{1} << 62U;

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
        series_ = Arithmetic::AlphaSeries::of(tau_s * 1e6);
        series_max_us_ = static_cast<std::uint32_t>(tau_s * 1e6 * kSeriesFraction);  // ≤ 3.4e8 µs
        for (Channel& c : ch_) {
            c = Channel{};
        }
        cache_ = AlphaCache{};
        series_cache_ = SeriesCache{};
        have_time_ = false;
        in_step_ = 0U;
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
        // Each channel's last time, and the α of those in step (whose last
        // time is the lag's).
        const std::int64_t last[kLagChannels] = {time_of(0), time_of(1), time_of(2)};
        const bool ahead = have_time_ && t_us > t_us_;
        const T alpha = ahead ? alpha_for(t_us - t_us_) : T{};
        const LagSteps s{{advance(ch_[0], last[0], t_us, temps.t_chu, ahead && in_step(0), alpha),
                          advance(ch_[1], last[1], t_us, temps.t_029, ahead && in_step(1), alpha),
                          advance(ch_[2], last[2], t_us, temps.t_032, ahead && in_step(2), alpha)}};
        if (moves(s) && (!have_time_ || t_us > t_us_)) {
            t_us_ = t_us;
            have_time_ = true;
        }
        // Which channels are in step now; the others keep their own time.
        std::uint8_t bits = 0U;
        for (std::uint8_t k = 0; k < kLagChannels; ++k) {
            const std::int64_t tk = moved(s.channel[k]) ? t_us : last[k];
            const bool step_k = ch_[k].started && tk == t_us_;
            bits = static_cast<std::uint8_t>(bits | (step_k ? 1U << k : 0U));
            ch_[k].t_us = tk;
        }
        in_step_ = bits;
        return s;
    }

    // Whether t_us is before the last time a channel started or advanced at.
    bool before_last(std::int64_t t_us) const noexcept { return have_time_ && t_us < t_us_; }

    // step() for a solution (the lag stage, head_lags.hpp): temps stepped in,
    // then each reading the step took (usable, so its channel has started:
    // advanced, started, or at the same t as its last) replaced by L. false,
    // temps unchanged, when t_us is before the lag's last time or not a time,
    // or no τ was configured.
    // The usual step, every channel in step and every reading usable, takes
    // a path of its own: the same operations as step()'s, straight.
    [[gnu::always_inline]] bool lag_in_place(std::int64_t t_us, HeadTemperatures<T>& temps) noexcept {
        // Δt modulo 2⁶⁴: the usual step's test needs no signed 64-bit compare.
        const std::uint64_t dt = static_cast<std::uint64_t>(t_us) - static_cast<std::uint64_t>(t_us_);
        if (in_step_ == kAllInStep && usual_dt(t_us, dt) && usable(temps.t_chu) && usable(temps.t_029) &&
            usable(temps.t_032)) {
            const T alpha = usual_alpha(dt);
            advance_in_place(ch_[0], temps.t_chu, alpha);
            advance_in_place(ch_[1], temps.t_029, alpha);
            advance_in_place(ch_[2], temps.t_032, alpha);
            t_us_ = t_us;
            return true;
        }
        return lag_in_place_in_general(t_us, temps);
    }

    // Channel k's deviation D = L − T at its last reading (°C), valid once
    // the channel has started: the regressor of a lagged term.
    TemperatureReading<T> deviation(std::uint8_t k) const noexcept {
        const Channel& c = ch_[k < kLagChannels ? k : 0];
        return {Arithmetic::deviation(c.d), k < kLagChannels && c.started};
    }

    // Channel k's lagged temperature L = T + D at its last reading (°C).
    TemperatureReading<T> lagged(std::uint8_t k) const noexcept {
        return {lagged_of(ch_[k < kLagChannels ? k : 0]), k < kLagChannels && ch_[k].started};
    }

private:
    // lag_in_place() but for the usual step (out of line: the usual one
    // keeps a small frame).
    [[gnu::noinline]] bool lag_in_place_in_general(std::int64_t t_us, HeadTemperatures<T>& temps) noexcept {
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

    struct Channel {
        typename Arithmetic::State d{};  // D = L − T at the last reading, °C
        C t_reading{};                   // the last reading, °C
        std::int64_t t_us = 0;           // the time of the last reading, unless in step (time_of)
        bool started = false;
    };
    // The last two Δt an α was formed for (−1: none), and which was used last.
    struct AlphaCache {
        std::int64_t dt_us[2] = {-1, -1};
        T alpha[2]{};
        std::uint8_t newer = 0;
    };

    // L = T + D of a channel at its last reading.
    static C lagged_of(const Channel& c) noexcept { return Arithmetic::sum(c.t_reading, Arithmetic::deviation(c.d)); }

    static void put(LagStep s, const Channel& c, TemperatureReading<T>& r) noexcept {
        if (s != LagStep::kHeld) {
            r.value = lagged_of(c);
        }
    }

    // Whether a channel took the step's reading as its last.
    static bool moved(LagStep k) noexcept { return k == LagStep::kStarted || k == LagStep::kAdvanced; }
    static bool moves(const LagSteps& s) noexcept {
        return moved(s.channel[0]) || moved(s.channel[1]) || moved(s.channel[2]);
    }

    // A reading the lag takes: valid, and within the core's domain (float: on
    // its bit pattern, abs_within_bits_at, exactly temperature_in_domain's
    // verdict at one instruction fewer a channel on the M4F).
    static bool usable(const TemperatureReading<T>& r) noexcept {
        if constexpr (std::is_same_v<T, float>) {
            return r.valid && abs_within_bits_at(r.value, ScalarTraits<float>::celsius(kMaxAbsTemperatureC));
        } else {
            return r.valid && temperature_in_domain<T>(r.value);
        }
    }

    bool in_step(std::uint8_t k) const noexcept { return ((in_step_ >> k) & 1U) != 0U; }
    // Channel k's last time (once started).
    std::int64_t time_of(std::uint8_t k) const noexcept { return in_step(k) ? t_us_ : ch_[k].t_us; }

    // One channel whose last time is `last`; shared: it was in step, and
    // t_us is after the lag's last time, so it takes the step's `alpha`.
    LagStep advance(Channel& c, std::int64_t last, std::int64_t t_us, const TemperatureReading<T>& r, bool shared,
                    T alpha) const noexcept {
        if (!usable(r)) {
            return LagStep::kHeld;
        }
        if (!c.started) {
            c = Channel{};
            c.t_reading = r.value;
            c.started = true;
            return LagStep::kStarted;
        }
        if (t_us <= last) {
            return LagStep::kTimeNotIncreasing;
        }
        // No overflow: both times within ±kMaxLagTimeUs. A channel that was
        // withheld since catches up over its own interval.
        const T a = shared ? alpha : alpha_of(t_us - last);
        const typename Arithmetic::State u = Arithmetic::input(c.d, r.value, c.t_reading);
        c.d = Arithmetic::decay(a, u);
        c.t_reading = r.value;
        return LagStep::kAdvanced;
    }

    // The usual step of a channel in step (lag_in_place): advanced with the
    // step's α, and the reading replaced by L. The reading is read once: a
    // store to the channel (the same type) would otherwise force a load again.
    [[gnu::always_inline]] static void advance_in_place(Channel& c, TemperatureReading<T>& r, T alpha) noexcept {
        const C reading = r.value;
        const typename Arithmetic::State d = Arithmetic::decay(alpha, Arithmetic::input(c.d, reading, c.t_reading));
        c.d = d;
        c.t_reading = reading;
        r.value = Arithmetic::sum(reading, Arithmetic::deviation(d));
    }

    // Whether a step at t_us, dt = t_us − t_us_ modulo 2⁶⁴, may take the
    // usual path: after the lag's last time and below kMaxLagTimeUs (t_us_ is
    // above −kMaxLagTimeUs); in float and Q30 also 0 < Δt ≤ τ/256, tested on
    // dt's words (a t_us not after t_us_ wraps to an upper word ≠ 0), so α is
    // its series. A longer Δt takes step(), which forms the same α (alpha_for).
    bool usual_dt(std::int64_t t_us, std::uint64_t dt) const noexcept {
        if constexpr (ScalarTraits<T>::double_precision) {
            return t_us > t_us_ && t_us < kMaxLagTimeUs;
        } else {
            // τ/256 < 2³²: Δt's upper word is 0, its lower within (0, τ/256].
            return (dt >> 32U) == 0U && static_cast<std::uint32_t>(dt) - 1U < series_max_us_ && t_us < kMaxLagTimeUs;
        }
    }
    // The usual step's α (usual_dt true): alpha_for's, without its test.
    // Float and Q30 keep the series' last two values by Δt (a head's cadence
    // repeats or alternates, as 45/46 ms at 22 Hz): a hit is a few
    // instructions, where the series takes about 10 on the M4F and its 64-bit
    // products about 30 on the M3. The value is the series' either way, so
    // the step's bits are too.
    T usual_alpha(std::uint64_t dt) noexcept {
        if constexpr (ScalarTraits<T>::double_precision) {
            return alpha_for(static_cast<std::int64_t>(dt));
        } else {
            const auto d = static_cast<std::uint32_t>(dt);  // in (0, τ/256]: usual_dt
            SeriesCache& k = series_cache_;
            if (d == k.dt_us[0]) {
                return k.alpha[0];
            }
            if (d == k.dt_us[1]) {
                return k.alpha[1];
            }
            const std::uint8_t slot = k.next;
            k.next ^= 1U;
            k.dt_us[slot] = d;
            k.alpha[slot] = series_(static_cast<std::int32_t>(d));
            return k.alpha[slot];
        }
    }

    // α = 1 − e^(−Δt/τ) for dt_us > 0, in [0, 1] (0 only when Q30 rounds a
    // Δt of a few µs against a day away, which leaves D as it was): in float
    // and Q30 its series when Δt ≤ τ/256, otherwise in double by
    // expm1_nonpositive, rounded once to T.
    T alpha_of(std::int64_t dt_us) const noexcept {
        return by_series(dt_us) ? series_(static_cast<std::int32_t>(dt_us)) : alpha_in_double(dt_us);
    }
    // Whether α of dt_us > 0 comes from the series: float and Q30, Δt ≤ τ/256.
    bool by_series(std::int64_t dt_us) const noexcept {
        return !ScalarTraits<T>::double_precision && dt_us <= std::int64_t{series_max_us_};
    }
    [[gnu::noinline]] T alpha_in_double(std::int64_t dt_us) const noexcept {
        return ScalarTraits<T>::from_double(-calib::expm1_nonpositive(-static_cast<double>(dt_us) * inv_tau_per_us_));
    }

    // The step's shared α: in float and Q30 its series when Δt ≤ τ/256;
    // otherwise one of the last two formed, or formed (in double) into the
    // older slot.
    T alpha_for(std::int64_t dt_us) noexcept {
        if (by_series(dt_us)) {
            return series_(static_cast<std::int32_t>(dt_us));
        }
        AlphaCache& k = cache_;
        if (dt_us == k.dt_us[k.newer]) {
            return k.alpha[k.newer];
        }
        const std::uint8_t other = k.newer ^ 1U;
        if (dt_us != k.dt_us[other]) {
            k.alpha[other] = alpha_in_double(dt_us);
            k.dt_us[other] = dt_us;
        }
        k.newer = other;
        return k.alpha[other];
    }

    // The series' last two α by Δt (µs; 0: none) for the usual step in
    // float and Q30 (usual_alpha), and the slot the next one goes to.
    struct SeriesCache {
        std::uint32_t dt_us[2] = {0U, 0U};
        T alpha[2]{};
        std::uint8_t next = 0U;
    };

    Channel ch_[kLagChannels]{};
    AlphaCache cache_{};
    std::int64_t t_us_ = 0;  // the last time a channel started or advanced at (have_time_)
    bool have_time_ = false;
    // Bit k: channel k's last reading was at t_us_ (its own t_us is then stale).
    static constexpr std::uint8_t kAllInStep = (1U << kLagChannels) - 1U;
    std::uint8_t in_step_ = 0U;
    double inv_tau_per_us_ = 0.0;  // α in double (alpha_in_double)
    typename Arithmetic::AlphaSeries series_{};
    std::uint32_t series_max_us_ = 0U;  // the longest Δt of the series: τ/256
    bool configured_ = false;
    SeriesCache series_cache_{};  // last: float's layout as without it
};

}  // namespace ascorr::pipeline
