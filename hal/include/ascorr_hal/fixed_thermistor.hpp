// ascorr_hal/fixed_thermistor.hpp: the thermistor path in fixed point, for a
// DPU without FPU: counts → °C by a table, every check and the vote in
// integers. ChannelCheck, vote and TemperatureAcquisition (channel_check.hpp,
// voting.hpp, acquisition.hpp) run unchanged with T = QCelsius; this header
// supplies the table, the channel configuration and the arithmetic.
//
// Conventions (CMSIS style):
//  - Temperatures are the core's QCelsius (fixed_point.hpp): signed Q11.20,
//    value = raw·2⁻²⁰ °C, range ±2048 °C, resolution 9.5e-7 °C. "No value" is
//    raw INT32_MIN, which no conversion produces (they saturate symmetrically
//    to ±INT32_MAX).
//  - The counts → °C table (CountsTable, make_counts_table,
//    celsius_from_counts) and its error bounds: counts_table.hpp.
//  - Open and short are judged in counts: the codes where the floating path's
//    resistance_from_counts (in the configuration's own scalar F, evaluated
//    on every code when the table is built) is ≥ r_open or ≤ r_short, so both
//    paths flag exactly the same codes. Each must be one run of codes at a
//    rail (the divider is monotonic); otherwise the table is refused.
//  - A refused table (ok = false: coefficients without a monotonic finite
//    curve, too many breakpoints, open/short codes not at a rail) or a channel
//    without its table makes every counts reading kConversion, as a
//    non-finite float conversion does; the firmware static_asserts ok.
//  - Limits: t_min, t_max, vote_tolerance (°C) and max_rate (°C/s) are
//    rounded from the configuration to the nearest 2⁻²⁰. Rate check:
//    |ΔT|·10⁶ ≤ max_rate·Δt_us, both sides in int64 (|ΔT| < 2³², so the left
//    side < 2⁵²; a product that overflows is larger than any left side:
//    within). Vote: |a − b| ≤ tol in int64; the mean of two is
//    (a + b + 1)·2⁻¹, round to nearest, ties towards +∞, exact range.
//  - Host and compile time only: make_counts_table(), fixed_channel(),
//    fixed_acquisition() and celsius_sample() use double. The run-time
//    functions (celsius_from_counts, TemperatureMath<QCelsius>) are integer
//    only: no heap, no exceptions, bounded loops.
#pragma once

#include <cstdint>

#include "acquisition.hpp"
#include "ascorr/core/fixed_point.hpp"
#include "channel_check.hpp"
#include "channel_config.hpp"
#include "counts_table.hpp"
#include "faults.hpp"
#include "sample_set.hpp"
#include "thermistor.hpp"
#include "voting.hpp"

namespace ascorr::hal {

// A channel of the fixed-point path (compare ChannelConfig<F>).
template <>
struct ChannelConfig<QCelsius> {
    char name[kNameLength];
    Role role;
    std::uint8_t adc_channel;    // 0 … 7
    const CountsTable* table;    // its curve; nullptr or refused: every counts reading is kConversion
    QCelsius t_min;              // outside [t_min, t_max], kOutOfRange
    QCelsius t_max;              //
    QCelsius max_rate;           // °C/s as Q11.20, ≤ 0: no rate check
    std::uint16_t stuck_frames;  // identical raw values in a row for kStuck, 0: no check
    std::uint16_t max_spread;    // counts: inner-half spread above this, kNoisy
};

template <>
struct TemperatureMath<QCelsius> {
    struct Ohm {};  // not computed: open and short are judged in counts
    using CoreScalar = Q30;
    static constexpr QCelsius none() noexcept { return {INT32_MIN}; }
    static constexpr Ohm no_ohm() noexcept { return {}; }
    static constexpr QCelsius zero() noexcept { return {0}; }
    static constexpr bool is_number(QCelsius x) noexcept { return x.raw != INT32_MIN; }
    static constexpr bool less(QCelsius a, QCelsius b) noexcept { return a.raw < b.raw; }
    static constexpr bool equal(QCelsius a, QCelsius b) noexcept { return a.raw == b.raw; }
    static constexpr bool within(QCelsius a, QCelsius b, QCelsius tol) noexcept {
        const std::int64_t d = static_cast<std::int64_t>(a.raw) - b.raw;
        return (d < 0 ? -d : d) <= tol.raw;
    }
    static constexpr QCelsius mean(QCelsius a, QCelsius b) noexcept {
        return {static_cast<std::int32_t>((static_cast<std::int64_t>(a.raw) + b.raw + 1) >> 1)};
    }
    static constexpr bool rate_enabled(QCelsius max_rate) noexcept { return max_rate.raw > 0; }
    static bool within_rate(QCelsius max_rate, QCelsius from_c, std::uint64_t from_us, QCelsius c,
                            std::uint64_t t_us) noexcept {
        const std::int64_t d = static_cast<std::int64_t>(c.raw) - from_c.raw;
        const auto lhs = static_cast<std::uint64_t>(d < 0 ? -d : d) * 1000000U;  // < 2⁵²
        std::uint64_t rhs = 0;
        if (__builtin_mul_overflow(static_cast<std::uint64_t>(max_rate.raw), t_us - from_us, &rhs)) {
            return true;  // the allowed change exceeds 2⁶⁴ > lhs
        }
        return lhs <= rhs;
    }
    static constexpr bool convert_counts(const ChannelConfig<QCelsius>& cfg, std::uint16_t counts, std::uint16_t spread,
                                         ChannelReading<QCelsius>& r) noexcept {
        if (cfg.table == nullptr || !cfg.table->ok) {
            return true;  // r.celsius stays none(): kConversion
        }
        if (cfg.table->open.contains(counts)) {
            r.faults |= fault::kOpen;
            return false;
        }
        if (cfg.table->shorted.contains(counts)) {
            r.faults |= fault::kShort;
            return false;
        }
        if (spread > cfg.max_spread) {
            r.faults |= fault::kNoisy;
        }
        r.celsius = celsius_from_counts(*cfg.table, counts);
        return true;
    }
};

// A temperature for the fixed-point path from double (host, compile time):
// NaN → none(), else rounded to nearest and saturated (ScalarTraits<Q30>).
constexpr QCelsius celsius_sample(double celsius) noexcept {
    return celsius == celsius ? ScalarTraits<Q30>::celsius(celsius) : TemperatureMath<QCelsius>::none();
}

// The fixed-point channel of a floating one; `table` must have been built
// from it (make_counts_table), else the channel gets none (kConversion).
template <typename F>
constexpr ChannelConfig<QCelsius> fixed_channel(const ChannelConfig<F>& c, const CountsTable* table) noexcept {
    ChannelConfig<QCelsius> q{};
    for (std::uint8_t i = 0; i < kNameLength; ++i) {
        q.name[i] = c.name[i];
    }
    q.role = c.role;
    q.adc_channel = c.adc_channel;
    q.table = table != nullptr && table_matches(*table, c) ? table : nullptr;
    q.t_min = celsius_sample(static_cast<double>(c.t_min));
    q.t_max = celsius_sample(static_cast<double>(c.t_max));
    q.max_rate = celsius_sample(static_cast<double>(c.max_rate));
    q.stuck_frames = c.stuck_frames;
    q.max_spread = c.max_spread;
    return q;
}

// The fixed-point acquisition of a floating one; tables[i] is channel i's.
template <typename F>
constexpr AcquisitionConfig<QCelsius> fixed_acquisition(const AcquisitionConfig<F>& a,
                                                        const CountsTable* const (&tables)[kMaxChannels]) noexcept {
    AcquisitionConfig<QCelsius> q{};
    for (std::uint8_t i = 0; i < kMaxChannels; ++i) {
        q.channel[i] = fixed_channel(a.channel[i], tables[i]);
    }
    q.channels = a.channels;
    q.sampler = a.sampler;
    q.stale_us = a.stale_us;
    q.vote_tolerance = celsius_sample(static_cast<double>(a.vote_tolerance));
    q.quorum = a.quorum;
    return q;
}

}  // namespace ascorr::hal
