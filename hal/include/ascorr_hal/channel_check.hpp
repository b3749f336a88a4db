// ascorr_hal/channel_check.hpp: one channel's sample → temperature + faults.
//
// Conventions, in the order the checks run on each sample set:
//  1. kNoData (no sample) and device faults (kBus) are taken as they come.
//  2. Time must advance: a sample not later than the channel's previous one
//     is kStale (a repeated or reordered replay row, a frozen clock).
//  3. Counts → ohm → °C (thermistor.hpp): kOpen at or above r_open, kShort at
//     or below r_short (no temperature is computed then); kNoisy when the
//     samples' inner-half spread exceeds max_spread; kConversion if the
//     result is not finite; kOutOfRange outside [t_min, t_max].
//  4. kStuck: the raw value (counts with zero spread, or a replayed
//     temperature) identical for stuck_frames sample sets in a row.
//  5. kRate, for an otherwise good reading: |T − T_anchor| > max_rate·Δt, with
//     the anchor the last accepted reading. A rejected reading is kept as a
//     candidate: if the next one agrees with the candidate (within max_rate
//     from it) the step was real and is accepted (re-anchored); if it agrees
//     with the anchor, the candidate was a spike. So a spike costs one
//     reading and a true step costs one reading, never more.
//  Each check is bounded straight-line code; no heap, no exceptions.
//  The temperature type T is float or double here; the fixed-point path
//  (T = QCelsius, counts → °C by table, every check in integers) supplies its
//  own TemperatureMath<QCelsius> and ChannelConfig<QCelsius> in
//  fixed_thermistor.hpp. Both paths run this one class, so the order and the
//  logic of the checks exist once.
#pragma once

#include <cmath>
#include <cstdint>
#include <limits>

#include "channel_config.hpp"
#include "faults.hpp"
#include "sample_set.hpp"
#include "thermistor.hpp"

namespace ascorr::hal {

template <typename T>
struct ChannelReading;

// The arithmetic the checks and the vote need on the temperature type: here
// floating point (NaN for no value); fixed_thermistor.hpp specialises it.
template <typename T>
struct TemperatureMath {
    using Ohm = T;         // the resistance a reading carries
    using CoreScalar = T;  // the core's scalar whose Celsius<> is T
    static constexpr T none() noexcept { return std::numeric_limits<T>::quiet_NaN(); }
    static constexpr Ohm no_ohm() noexcept { return std::numeric_limits<T>::quiet_NaN(); }
    static constexpr T zero() noexcept { return T(0); }
    static bool is_number(T x) noexcept { return std::isfinite(x); }
    static bool less(T a, T b) noexcept { return a < b; }
    static bool equal(T a, T b) noexcept { return a == b; }
    // |a − b| ≤ tol (false for NaN)
    static bool within(T a, T b, T tol) noexcept { return std::fabs(a - b) <= tol; }
    static T mean(T a, T b) noexcept { return T(0.5) * (a + b); }
    // false for max_rate ≤ 0; a NaN limit enables the check (and fails every step)
    static bool rate_enabled(T max_rate) noexcept { return !(max_rate <= T(0)); }
    // |c − from_c| ≤ max_rate·(t_us − from_us)·10⁻⁶
    static bool within_rate(T max_rate, T from_c, std::uint64_t from_us, T c, std::uint64_t t_us) noexcept {
        const T dt = static_cast<T>(t_us - from_us) * T(1e-6);
        return std::fabs(c - from_c) <= max_rate * dt;
    }
    // Counts → ohm → °C with the open and short limits on the resistance.
    // Returns false when no temperature was computed (open, short).
    static bool convert_counts(const ChannelConfig<T>& cfg, std::uint16_t counts, std::uint16_t spread,
                               ChannelReading<T>& r) noexcept {
        r.ohm = resistance_from_counts(cfg.divider, counts);
        if (r.ohm >= cfg.r_open) {
            r.faults |= fault::kOpen;
            return false;
        }
        if (r.ohm <= cfg.r_short) {
            r.faults |= fault::kShort;
            return false;
        }
        if (spread > cfg.max_spread) {
            r.faults |= fault::kNoisy;
        }
        r.celsius = celsius_from_resistance(cfg.sh, r.ohm);
        return true;
    }
};

template <typename T>
struct ChannelReading {
    T celsius;  // NaN (fixed point: TemperatureMath<QCelsius>::none()) when no temperature could be computed
    typename TemperatureMath<T>::Ohm ohm;  // NaN for replayed temperatures, 0/inf at the rails
    std::uint16_t counts;                  // raw median, 0 for replayed temperatures
    FaultBits faults;                      // 0: valid
    std::uint64_t t_us;                    // time of the sample
    bool valid() const noexcept { return faults == 0U; }
};

template <typename T>
class ChannelCheck {
    using Math = TemperatureMath<T>;

public:
    ChannelCheck() noexcept { reset(); }

    void reset() noexcept {
        have_time_ = false;
        have_anchor_ = false;
        have_candidate_ = false;
        run_ = 0;
        have_raw_ = false;
        last_ = {Math::none(), Math::no_ohm(), 0U, fault::kNoData, 0U};
        have_reading_ = false;
    }

    // Processes one sample. A kNone sample keeps the previous reading (it ages
    // and turns stale); every other sample replaces it.
    const ChannelReading<T>& update(const ChannelConfig<T>& cfg, const ChannelSample<T>& s,
                                    std::uint64_t t_us) noexcept {
        if (s.kind == SampleKind::kNone) {
            if (!have_reading_) {
                last_.faults = static_cast<FaultBits>(fault::kNoData | s.faults);
                last_.t_us = t_us;
            }
            return last_;
        }
        ChannelReading<T> r{Math::none(), Math::no_ohm(), 0U, s.faults, t_us};
        if (have_time_ && t_us <= last_time_) {
            r.faults |= fault::kStale;
        } else {
            last_time_ = t_us;
            have_time_ = true;
        }
        if ((s.faults & fault::kBus) == 0U) {
            convert(cfg, s, r);
            check_stuck(cfg, s, r);
            if (r.faults == 0U) {
                check_rate(cfg, r);
            }
        }
        last_ = r;
        have_reading_ = true;
        return last_;
    }

    // The latest reading as seen at now_us: kStale when older than stale_us.
    ChannelReading<T> at(std::uint64_t now_us, std::uint64_t stale_us) const noexcept {
        ChannelReading<T> r = last_;
        if (have_reading_ && (now_us < r.t_us || now_us - r.t_us > stale_us)) {
            r.faults |= fault::kStale;
        }
        return r;
    }

private:
    static void convert(const ChannelConfig<T>& cfg, const ChannelSample<T>& s, ChannelReading<T>& r) noexcept {
        if (s.kind == SampleKind::kCounts) {
            r.counts = s.counts;
            if (!Math::convert_counts(cfg, s.counts, s.spread, r)) {
                return;
            }
        } else {
            r.celsius = s.celsius;
        }
        if (!Math::is_number(r.celsius)) {
            r.faults |= fault::kConversion;
            return;
        }
        if (Math::less(r.celsius, cfg.t_min) || Math::less(cfg.t_max, r.celsius)) {
            r.faults |= fault::kOutOfRange;
        }
    }

    void check_stuck(const ChannelConfig<T>& cfg, const ChannelSample<T>& s, ChannelReading<T>& r) noexcept {
        const bool counts = s.kind == SampleKind::kCounts;
        const bool same = have_raw_ && raw_is_counts_ == counts &&
                          (counts ? (s.counts == raw_counts_ && s.spread == 0U) : Math::equal(s.celsius, raw_celsius_));
        run_ = same ? (run_ < 0xFFFFU ? static_cast<std::uint16_t>(run_ + 1U) : run_) : 1U;
        have_raw_ = true;
        raw_is_counts_ = counts;
        raw_counts_ = s.counts;
        raw_celsius_ = s.celsius;
        if (cfg.stuck_frames != 0U && run_ >= cfg.stuck_frames) {
            r.faults |= fault::kStuck;
        }
    }

    static bool within_rate(const ChannelConfig<T>& cfg, T from_c, std::uint64_t from_us, const ChannelReading<T>& r) {
        return Math::within_rate(cfg.max_rate, from_c, from_us, r.celsius, r.t_us);
    }

    void check_rate(const ChannelConfig<T>& cfg, ChannelReading<T>& r) noexcept {
        if (!Math::rate_enabled(cfg.max_rate) || !have_anchor_ || within_rate(cfg, anchor_c_, anchor_us_, r) ||
            (have_candidate_ && within_rate(cfg, candidate_c_, candidate_us_, r))) {
            anchor_c_ = r.celsius;
            anchor_us_ = r.t_us;
            have_anchor_ = true;
            have_candidate_ = false;
            return;
        }
        r.faults |= fault::kRate;
        candidate_c_ = r.celsius;
        candidate_us_ = r.t_us;
        have_candidate_ = true;
    }

    ChannelReading<T> last_;
    bool have_reading_;
    bool have_time_;
    std::uint64_t last_time_ = 0;
    bool have_anchor_;
    T anchor_c_ = Math::zero();
    std::uint64_t anchor_us_ = 0;
    bool have_candidate_;
    T candidate_c_ = Math::zero();
    std::uint64_t candidate_us_ = 0;
    bool have_raw_;
    bool raw_is_counts_ = false;
    std::uint16_t raw_counts_ = 0;
    T raw_celsius_ = Math::zero();
    std::uint16_t run_;
};

}  // namespace ascorr::hal
