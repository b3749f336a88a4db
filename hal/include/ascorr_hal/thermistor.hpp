// ascorr_hal/thermistor.hpp: ADC counts → resistance → °C for an NTC thermistor.
//
// Conventions:
//  - Divider: a fixed resistor r_fixed and the thermistor in series between
//    the ADC reference and ground; the ADC reads the midpoint.
//      thermistor low  (r_fixed to Vref, thermistor to GND): x = Rt/(Rf + Rt)
//      thermistor high (thermistor to Vref, r_fixed to GND): x = Rf/(Rf + Rt)
//    with x = counts / levels the ideal transfer of an N-bit ADC whose
//    reference is the divider's supply (ratiometric: Vref cancels), first
//    code transition at ½ LSB, so code k is centred on k·LSB (the inverse,
//    counts_from_resistance, rounds to nearest). ADC offset and gain errors
//    and the thermistor's self-heating are not modelled; calibrate them into
//    r_fixed and the Steinhart–Hart coefficients if they matter.
//  - Steinhart–Hart: 1/T = A + B·ln R + C·(ln R)³, T in kelvin, R in ohm.
//  - Open and short circuits are judged on the resistance (r_open, r_short),
//    so the same limits hold for either divider orientation; counts at a rail
//    give R = 0 or +inf, never a division by zero.
//  - Templated on a floating scalar (float on the DPU, double on ground); uses
//    std::log/std::exp only. Freestanding: no heap, no exceptions.
#pragma once

#include <cmath>
#include <cstdint>
#include <limits>

namespace ascorr::hal {

template <typename T>
struct SteinhartHart {
    T a;  // 1/K
    T b;  // 1/K per ln(ohm)
    T c;  // 1/K per ln(ohm)³
};

template <typename T>
struct Divider {
    bool thermistor_low;   // true: thermistor between the ADC input and ground
    T r_fixed;             // ohm
    std::uint16_t levels;  // 4096 for a 12-bit ADC
};

inline constexpr double kZeroCelsiusK = 273.15;

// Thermistor resistance from a count; 0 or +inf at the rails.
template <typename T>
constexpr T resistance_from_counts(const Divider<T>& d, std::uint16_t counts) noexcept {
    const T inf = std::numeric_limits<T>::infinity();
    const T zero = T(0);
    if (counts == 0U) {
        return d.thermistor_low ? zero : inf;
    }
    if (counts >= d.levels) {
        return d.thermistor_low ? inf : zero;
    }
    const T x = static_cast<T>(counts) / static_cast<T>(d.levels);
    return d.thermistor_low ? d.r_fixed * x / (T(1) - x) : d.r_fixed * (T(1) - x) / x;
}

// The count an ideal ADC gives for a resistance (for simulation and tests),
// rounded to nearest and clamped to [0, levels − 1].
template <typename T>
std::uint16_t counts_from_resistance(const Divider<T>& d, T r) noexcept {
    if (!(r >= T(0))) {
        return 0U;
    }
    const T x = d.thermistor_low ? (std::isinf(r) ? T(1) : r / (d.r_fixed + r))
                                 : (std::isinf(r) ? T(0) : d.r_fixed / (d.r_fixed + r));
    const T c = std::floor(x * static_cast<T>(d.levels) + T(0.5));
    const T top = static_cast<T>(d.levels - 1U);
    return static_cast<std::uint16_t>(c < T(0) ? T(0) : (c > top ? top : c));
}

// °C from ohm; NaN for R ≤ 0 or non-finite.
template <typename T>
T celsius_from_resistance(const SteinhartHart<T>& sh, T r) noexcept {
    if (!(r > T(0)) || std::isinf(r)) {
        return std::numeric_limits<T>::quiet_NaN();
    }
    const T l = std::log(r);
    const T inv_k = sh.a + sh.b * l + sh.c * l * l * l;
    return T(1) / inv_k - static_cast<T>(kZeroCelsiusK);
}

// Where a Steinhart–Hart curve fails to be a thermistor curve on the
// resistances [r_lo, r_hi] (ohm, 0 < r_lo < r_hi): 1/T must be positive and
// rise strictly with ln R, i.e. T fall strictly with R (an NTC). With
// L = ln R, d(1/T)/dL = B + 3·C·L², so the set where it is ≤ 0 is found in
// closed form: all L (C = 0, B ≤ 0); |L| ≤ √(−B/(3C)) (C > 0, B ≤ 0);
// |L| ≥ √(−B/(3C)) (C < 0, B > 0); all L (C < 0, B ≤ 0). Where it rises,
// 1/T is smallest at r_lo. Returns ok, or the first failing resistance
// range [r_from, r_to] within [r_lo, r_hi] (host and configuration checks).
template <typename T>
struct CurveCheck {
    bool ok;
    bool no_temperature;  // monotonic, but 1/T ≤ 0 (or not finite) at r_from
    T r_from;
    T r_to;
};

template <typename T>
CurveCheck<T> check_curve(const SteinhartHart<T>& sh, T r_lo, T r_hi) noexcept {
    const T l_lo = std::log(r_lo);
    const T l_hi = std::log(r_hi);
    const T inf = std::numeric_limits<T>::infinity();
    // The set where B + 3·C·L² ≤ 0 as up to two intervals of L.
    T from[2] = {inf, inf};
    T to[2] = {-inf, -inf};
    if (sh.b <= T(0) && sh.c >= T(0)) {
        const T s = sh.c == T(0) ? inf : std::sqrt(-sh.b / (T(3) * sh.c));
        from[0] = -s;
        to[0] = s;
    } else if (sh.c < T(0)) {
        const T s = sh.b <= T(0) ? T(0) : std::sqrt(-sh.b / (T(3) * sh.c));
        from[0] = -inf;
        to[0] = -s;
        from[1] = s;
        to[1] = inf;
    }
    for (int k = 0; k < 2; ++k) {
        const T a = from[k] > l_lo ? from[k] : l_lo;
        const T b = to[k] < l_hi ? to[k] : l_hi;
        if (a <= b) {
            return {false, false, std::exp(a), std::exp(b)};
        }
    }
    const T inv_k = sh.a + sh.b * l_lo + sh.c * l_lo * l_lo * l_lo;
    if (!(inv_k > T(0)) || !std::isfinite(T(1) / inv_k)) {
        return {false, true, r_lo, r_lo};
    }
    return {true, false, r_lo, r_hi};
}

// Ohm from °C, the closed-form inverse of Steinhart–Hart (simulation, tests):
//   x = (A − 1/T)/C, y = sqrt((B/(3C))³ + x²/4), ln R = cbrt(y − x/2) − cbrt(y + x/2).
template <typename T>
T resistance_from_celsius(const SteinhartHart<T>& sh, T celsius) noexcept {
    const T inv_k = T(1) / (celsius + static_cast<T>(kZeroCelsiusK));
    if (sh.c == T(0)) {
        return std::exp((inv_k - sh.a) / sh.b);
    }
    const T x = (sh.a - inv_k) / sh.c;
    const T b3c = sh.b / (T(3) * sh.c);
    const T y = std::sqrt(b3c * b3c * b3c + x * x / T(4));
    return std::exp(std::cbrt(y - x / T(2)) - std::cbrt(y + x / T(2)));
}

}  // namespace ascorr::hal
