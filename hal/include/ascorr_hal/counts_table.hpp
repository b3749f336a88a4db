// ascorr_hal/counts_table.hpp: the thermistor's counts → °C conversion of
// the fixed-point path (fixed_thermistor.hpp) as a table of breakpoints,
// built from a channel's curve when the firmware is compiled.
//
// Conventions (CMSIS style; temperatures are the core's QCelsius, signed
// Q11.20, fixed_point.hpp):
//  - CountsTable, one per thermistor curve (a channel configuration's
//    Steinhart–Hart coefficients, divider, open/short limits and valid range),
//    built by make_counts_table() from that configuration when the firmware
//    is compiled (constexpr; on the host at run time, the same function):
//      range       the codes whose double Steinhart–Hart temperature lies in
//                  [t_min − 1 °C, t_max + 1 °C], widened until both ends lie
//                  beyond the limits by more than kTableBudgetC (or reach the
//                  open/short codes). A code outside the table gets the
//                  nearer end's value, beyond t_min/t_max: flagged
//                  kOutOfRange, as in floating point (its value is not the
//                  true temperature; an out-of-range reading is withheld).
//      breakpoints (code_i, T_i), T_i the double conversion of code_i rounded
//                  to nearest raw; chosen greedily so that interpolation
//                  stays within kTableBudgetC on every code of each segment,
//                  which is verified code by code with the integer
//                  interpolation itself (worst_error_raw).
//      interpolation, code in [code_i, code_i+1]:
//                  T = T_i + round((s_i·(code − code_i))·2⁻⁸), s_i the
//                  segment's slope in raw per code ·2⁸, rounded to nearest;
//                  product in int64 (|s_i| < 2³¹, code − code_i < 2¹⁶:
//                  < 2⁴⁷, exact), rounded once to nearest, ties towards +∞.
//                  The result lies within 1 raw of [T_i, T_i+1]: no
//                  saturation is needed.
//      worst-case error against the double conversion: worst_error_raw,
//                  ≤ kTableBudgetC = 0.004 °C (generation fails otherwise);
//                  for the Swarm boom channels (10K3A1, 10 kΩ low-side
//                  divider, 12 bits, −60 … 80 °C) 0.0038 °C with 148
//                  breakpoints (one table is 2.0 KiB of flash, sized for
//                  kMaxBreakpoints = 192). Against the float path add float's own error
//                  (5e-5 °C measured): the test bounds the difference by
//                  0.005 °C on every code of [t_min, t_max] (test_hal_fixed:
//                  0.0038 °C).
//      cost        a binary search over ≤ kMaxBreakpoints codes (≤ 8 steps),
//                  one 32 × 32 → 64-bit product, a shift.
//  - Host and compile time only: make_counts_table() and
//    counts_for_celsius() use double. celsius_from_counts() is integer
//    only: no heap, no exceptions, at most 8 steps.
#pragma once

#include <cstdint>

#include "ascorr/core/fixed_point.hpp"
#include "channel_config.hpp"

namespace ascorr::hal {

inline constexpr std::uint16_t kMaxBreakpoints = 192;
inline constexpr double kTableBudgetC = 0.004;  // °C, table against the double conversion
inline constexpr double kTableMarginC = 1.0;    // °C beyond t_min and t_max covered by the table
inline constexpr int kSlopeShift = 8;           // slopes in raw per code ·2⁸
inline constexpr std::uint16_t kMaxSegment = 1024;
inline constexpr std::uint32_t kMaxLevels = 4096;  // ADCs up to 12 bits (the MCP3208)

// Inclusive run of codes [lo, hi]; empty when lo > hi.
struct CountRange {
    std::uint16_t lo;
    std::uint16_t hi;
    constexpr bool contains(std::uint16_t c) const noexcept { return lo <= c && c <= hi; }
};

// A channel's curve in double: Steinhart–Hart and the divider.
struct Curve {
    double a, b, c;  // Steinhart–Hart, 1/K
    double r_fixed;  // ohm
    std::uint16_t levels;
    bool thermistor_low;
};

template <typename F>
constexpr Curve curve_of(const ChannelConfig<F>& cfg) noexcept {
    return {static_cast<double>(cfg.sh.a),
            static_cast<double>(cfg.sh.b),
            static_cast<double>(cfg.sh.c),
            static_cast<double>(cfg.divider.r_fixed),
            cfg.divider.levels,
            cfg.divider.thermistor_low};
}

struct CountsTable {
    bool ok;                                // false: refused, every counts reading is kConversion
    std::uint16_t n;                        // breakpoints used (≥ 2 when ok)
    std::uint16_t code[kMaxBreakpoints];    // ascending
    std::int32_t celsius[kMaxBreakpoints];  // QCelsius raw at code[i]
    std::int32_t slope[kMaxBreakpoints];    // segment i → i+1, raw per code ·2^kSlopeShift
    CountRange open;                        // kOpen
    CountRange shorted;                     // kShort
    std::int32_t worst_error_raw;           // max |table − double| over every code of the table
    // What the table was built from (compared by fixed_channel()).
    Curve curve;
    double r_open, r_short, t_min, t_max;
};

namespace table_detail {

inline constexpr double kLn2 = 0.69314718055994530942;

// Natural logarithm for x > 0 finite, at compile time: x = m·2ᵉ with m in
// [√½, √2) (exact scalings by 2¹⁶, then by 2), ln m = 2·atanh(z),
// z = (m − 1)/(m + 1), |z| ≤ 0.1716; 12 terms of the series: truncation
// < 0.1716²⁵/25/(1 − z²) < 1e-20, below double's rounding of ln m.
constexpr double ln(double x) noexcept {
    int e = 0;
    for (int i = 0; i < 70 && x >= 65536.0; ++i) {
        x *= 1.0 / 65536.0;
        e += 16;
    }
    for (int i = 0; i < 70 && x < 1.0 / 65536.0; ++i) {
        x *= 65536.0;
        e -= 16;
    }
    for (int i = 0; i < 17 && x >= 1.4142135623730951; ++i) {
        x *= 0.5;
        ++e;
    }
    for (int i = 0; i < 17 && x < 0.70710678118654752; ++i) {
        x *= 2.0;
        --e;
    }
    const double z = (x - 1.0) / (x + 1.0);
    const double z2 = z * z;
    double term = z;
    double sum = 0.0;
    for (int k = 0; k < 12; ++k) {
        sum += term / static_cast<double>(2 * k + 1);
        term *= z2;
    }
    return 2.0 * sum + static_cast<double>(e) * kLn2;
}

// The double Steinhart–Hart temperature of a code (not at a rail).
constexpr double celsius_of_code(const Curve& t, std::uint16_t code) noexcept {
    const double x = static_cast<double>(code) / static_cast<double>(t.levels);
    const double r = t.thermistor_low ? t.r_fixed * x / (1.0 - x) : t.r_fixed * (1.0 - x) / x;
    const double l = ln(r);
    return 1.0 / (t.a + t.b * l + t.c * l * l * l) - kZeroCelsiusK;
}

constexpr std::int32_t raw(double celsius) noexcept {
    return fx::raw_from_double<QCelsius::kFracBits>(celsius);
}

// Slope of a segment, raw per code ·2⁸, rounded to nearest.
constexpr std::int64_t slope_of(std::int32_t t0, std::int32_t t1, std::uint16_t c0, std::uint16_t c1) noexcept {
    const std::int64_t num = (static_cast<std::int64_t>(t1) - t0) * (std::int64_t{1} << kSlopeShift);
    const std::int64_t den = static_cast<std::int64_t>(c1) - c0;
    return num >= 0 ? (num + den / 2) / den : -((-num + den / 2) / den);
}

constexpr std::int32_t interpolate(std::int32_t t0, std::int32_t slope, std::uint16_t c0, std::uint16_t c) noexcept {
    const std::int64_t d = static_cast<std::int64_t>(slope) * static_cast<std::int64_t>(c - c0);
    return static_cast<std::int32_t>(t0 + fx::round_shift<kSlopeShift>(d));
}

// Largest |interpolated − double| (raw) over the codes of segment [c0, c1]
// (every code for stride 0; else at the seven eighths c0 + i·(c1 − c0)/8,
// the estimate the breakpoint search uses, ahead of the verification of every
// code); temp[c]: the double temperature of code c.
constexpr std::int64_t segment_error(const double* temp, std::uint16_t c0, std::uint16_t c1, bool every_code) noexcept {
    const std::int32_t t0 = raw(temp[c0]);
    const std::int32_t t1 = raw(temp[c1]);
    const std::int64_t s = slope_of(t0, t1, c0, c1);
    if (s > INT32_MAX || s < -INT32_MAX) {
        return INT64_MAX;
    }
    std::int64_t worst = 0;
    const std::uint32_t span = static_cast<std::uint32_t>(c1) - c0;
    const std::uint32_t points = every_code ? span + 1U : 7U;
    for (std::uint32_t i = 0; i < points; ++i) {
        const std::uint32_t c = every_code ? c0 + i : c0 + (span * (i + 1U) + 4U) / 8U;
        const double exact = temp[c] * 1048576.0;
        const double e =
            static_cast<double>(interpolate(t0, static_cast<std::int32_t>(s), c0, static_cast<std::uint16_t>(c))) -
            exact;
        const auto ae = static_cast<std::int64_t>(e < 0.0 ? -e + 1.0 : e + 1.0);  // rounded up
        worst = ae > worst ? ae : worst;
    }
    return worst;
}

}  // namespace table_detail

// The table of one channel's curve (see the conventions). F: the
// configuration's floating scalar (float on the DPU, double on the host);
// its resistance_from_counts decides open and short, as on the float path.
template <typename F>
constexpr CountsTable make_counts_table(const ChannelConfig<F>& cfg) noexcept {
    using table_detail::celsius_of_code;
    CountsTable t{};
    t.ok = false;
    t.curve = curve_of(cfg);
    t.r_open = static_cast<double>(cfg.r_open);
    t.r_short = static_cast<double>(cfg.r_short);
    t.t_min = static_cast<double>(cfg.t_min);
    t.t_max = static_cast<double>(cfg.t_max);
    t.open = {1U, 0U};
    t.shorted = {1U, 0U};
    const std::uint32_t levels = cfg.divider.levels;
    if (levels < 4U || levels > kMaxLevels || !(t.curve.r_fixed > 0.0)) {
        return t;
    }
    // Open and short codes, from the float path's own resistance; every code
    // from 0 to 0xFFFF is covered (codes ≥ levels read as the top rail).
    // Required: the usable codes form one run [first_ok, last_ok], and the
    // codes below it (above it) are all of one kind, that of the rail.
    std::uint8_t kind[kMaxLevels + 1] = {};  // 0 usable, 1 open, 2 short
    std::uint32_t first_ok = 0x10000U;
    std::uint32_t last_ok = 0U;
    std::uint32_t usable = 0U;
    for (std::uint32_t c = 0; c <= levels; ++c) {
        const F r = resistance_from_counts(cfg.divider, static_cast<std::uint16_t>(c));
        kind[c] = r >= cfg.r_open ? 1U : (r <= cfg.r_short ? 2U : 0U);
        if (kind[c] == 0U) {
            first_ok = c < first_ok ? c : first_ok;
            last_ok = c;
            ++usable;
        }
    }
    if (usable == 0U || usable != last_ok - first_ok + 1U || last_ok == levels) {
        return t;
    }
    for (std::uint32_t c = 0; c <= levels; ++c) {
        if ((c < first_ok && kind[c] != kind[0]) || (c > last_ok && kind[c] != kind[levels])) {
            return t;
        }
    }
    if (first_ok > 0U) {
        (kind[0] == 1U ? t.open : t.shorted) = {0U, static_cast<std::uint16_t>(first_ok - 1U)};
    }
    (kind[levels] == 1U ? t.open : t.shorted) = {static_cast<std::uint16_t>(last_ok + 1U), 0xFFFFU};
    // Table range: the codes within [t_min − margin, t_max + margin], widened
    // until both ends lie beyond the limits by more than the budget.
    const double lo_c = t.t_min - kTableMarginC;
    const double hi_c = t.t_max + kTableMarginC;
    std::uint32_t lo = 0x10000U;
    std::uint32_t hi = 0U;
    double temp[kMaxLevels + 1] = {};
    for (std::uint32_t c = first_ok; c <= last_ok; ++c) {
        const double x = celsius_of_code(t.curve, static_cast<std::uint16_t>(c));
        temp[c] = x;
        if (!(x == x) || x > 1e4 || x < -1e4) {  // no finite curve
            return t;
        }
        if (x >= lo_c && x <= hi_c) {
            lo = c < lo ? c : lo;
            hi = c;
        }
    }
    if (lo > hi) {
        return t;
    }
    const auto beyond = [&t, &temp](std::uint32_t c) {
        return temp[c] < t.t_min - kTableBudgetC || temp[c] > t.t_max + kTableBudgetC;
    };
    while (lo > first_ok && !beyond(lo)) {
        --lo;
    }
    while (hi < last_ok && !beyond(hi)) {
        ++hi;
    }
    // Monotonic curve over the range (else interpolation and clamping fail).
    const bool rising = temp[hi] > temp[lo];
    for (std::uint32_t c = lo; c < hi; ++c) {
        const double d = temp[c + 1U] - temp[c];
        if (rising ? !(d > 0.0) : !(d < 0.0)) {
            return t;
        }
    }
    // Breakpoints, greedily: the longest segment whose error is within budget
    // (searched on the sampled estimate, then checked on every code).
    const auto budget = static_cast<std::int64_t>(kTableBudgetC * 1048576.0);
    const std::int64_t search_budget = budget - budget / 16;  // room for the codes between the sampled ones
    std::uint32_t a = lo;
    std::uint16_t n = 0;
    t.code[n++] = static_cast<std::uint16_t>(a);
    while (a < hi) {
        if (n >= kMaxBreakpoints) {
            return t;
        }
        std::uint32_t good = a + 1U;
        std::uint32_t top = a + kMaxSegment < hi ? a + kMaxSegment : hi;
        while (good < top) {  // largest end whose segment passes (binary search, ≤ 10 steps)
            const std::uint32_t mid = (good + top + 1U) / 2U;
            if (table_detail::segment_error(temp, static_cast<std::uint16_t>(a), static_cast<std::uint16_t>(mid),
                                            false) <= search_budget) {
                good = mid;
            } else {
                top = mid - 1U;
            }
        }
        // The estimate checked every code: shorten until every code passes
        // (a two-code segment always does: no code between its ends).
        for (int i = 0; i < 64 && good > a + 1U &&
                        table_detail::segment_error(temp, static_cast<std::uint16_t>(a),
                                                    static_cast<std::uint16_t>(good), true) > budget;
             ++i) {
            good = a + 1U + (good - a - 1U) * 7U / 8U;
        }
        a = good;
        t.code[n++] = static_cast<std::uint16_t>(a);
    }
    t.n = n;
    std::int64_t worst = 0;
    for (std::uint16_t i = 0; i < n; ++i) {
        t.celsius[i] = table_detail::raw(temp[t.code[i]]);
    }
    for (std::uint16_t i = 0; i + 1U < n; ++i) {
        t.slope[i] =
            static_cast<std::int32_t>(table_detail::slope_of(t.celsius[i], t.celsius[i + 1], t.code[i], t.code[i + 1]));
        const std::int64_t e = table_detail::segment_error(temp, t.code[i], t.code[i + 1], true);
        worst = e > worst ? e : worst;
    }
    t.slope[n - 1] = 0;
    t.worst_error_raw = static_cast<std::int32_t>(worst);
    t.ok = n >= 2U && worst <= budget;
    return t;
}

// °C of a code that is neither open nor short (the caller checks): the
// table's interpolation, clamped to its ends. Integer only.
constexpr QCelsius celsius_from_counts(const CountsTable& t, std::uint16_t counts) noexcept {
    if (counts <= t.code[0]) {
        return {t.celsius[0]};
    }
    if (counts >= t.code[t.n - 1U]) {
        return {t.celsius[t.n - 1U]};
    }
    std::uint16_t lo = 0;  // code[lo] < counts < code[hi]
    std::uint16_t hi = static_cast<std::uint16_t>(t.n - 1U);
    while (lo + 1 < hi) {  // ≤ log2(kMaxBreakpoints) + 1 = 8 steps
        const auto mid = static_cast<std::uint16_t>((lo + hi) / 2U);
        if (t.code[mid] <= counts) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    return {table_detail::interpolate(t.celsius[lo], t.slope[lo], t.code[lo], counts)};
}

// True when `table` was built from this configuration's curve and limits.
template <typename F>
constexpr bool table_matches(const CountsTable& t, const ChannelConfig<F>& c) noexcept {
    const Curve k = curve_of(c);
    return t.curve.a == k.a && t.curve.b == k.b && t.curve.c == k.c && t.curve.r_fixed == k.r_fixed &&
           t.curve.levels == k.levels && t.curve.thermistor_low == k.thermistor_low &&
           t.r_open == static_cast<double>(c.r_open) && t.r_short == static_cast<double>(c.r_short) &&
           t.t_min == static_cast<double>(c.t_min) && t.t_max == static_cast<double>(c.t_max);
}

// The code an ideal ADC gives for a temperature: the code whose double
// Steinhart–Hart temperature is nearest (bisection over the monotonic curve,
// codes 1 … levels − 2). Host and compile time: emulation and tests.
template <typename F>
constexpr std::uint16_t counts_for_celsius(const ChannelConfig<F>& cfg, double celsius) noexcept {
    const Curve k = curve_of(cfg);
    std::uint32_t lo = 1U;
    std::uint32_t hi = k.levels - 2U;
    const bool rising = table_detail::celsius_of_code(k, static_cast<std::uint16_t>(hi)) >
                        table_detail::celsius_of_code(k, static_cast<std::uint16_t>(lo));
    for (int i = 0; i < 17 && hi - lo > 1U; ++i) {
        const std::uint32_t mid = (lo + hi) / 2U;
        const double t = table_detail::celsius_of_code(k, static_cast<std::uint16_t>(mid));
        ((t < celsius) == rising ? lo : hi) = mid;
    }
    const double dl = table_detail::celsius_of_code(k, static_cast<std::uint16_t>(lo)) - celsius;
    const double dh = table_detail::celsius_of_code(k, static_cast<std::uint16_t>(hi)) - celsius;
    return static_cast<std::uint16_t>((dl < 0.0 ? -dl : dl) <= (dh < 0.0 ? -dh : dh) ? lo : hi);
}

}  // namespace ascorr::hal
