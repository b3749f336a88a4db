// ascorr/nav/tt_time.hpp: time tags of solutions and spacecraft states.
//
// Conventions: TT, counted in whole microseconds since J2000.0
// (2000-01-01T12:00:00 TT), in a signed 64-bit integer. A double of seconds
// since J2000 keeps ~0.1 µs today, a float 64 s and a Q30 nothing: the core
// never holds an absolute time in its scalar. Only differences that are small
// by construction (a solution's offset into a velocity node, ≤ 10 s) reach the
// scalar, as a fraction in [0, 1] (velocity_service.hpp).
//
//  - Range: ±2⁶³ µs = ±292,000 years; the readers accept |t| ≤ kMaxAbsTtSeconds.
//  - Resolution: 1 µs. A GNSS state (whole GPS seconds = TT − 51.184 s, so on
//    .184) is exact. A 22 Hz solution time is rounded by ≤ 0.5 µs, which moves
//    a LEO velocity by ≤ 8.4 m/s² · 0.5 µs = 4.2e-6 m/s (3e-9″).
//  - Arithmetic is integer only: on the FPU-less Cortex-M3 comparing and
//    subtracting time tags costs no soft-float.
#pragma once

#include <cstdint>

namespace ascorr {

struct TtTime {
    std::int64_t us;  // TT microseconds since J2000.0
};

inline constexpr std::int64_t kMicrosecondsPerSecond = 1000000;
// The readers' limit: ±10¹¹ s (±3169 years) around J2000; far beyond any
// mission, and well inside int64 µs and double's exact integers (2⁵³ µs).
inline constexpr double kMaxAbsTtSeconds = 1e11;

// Seconds since J2000 (TT) → TtTime, rounded to the nearest microsecond.
// False (out untouched) for a non-finite t or |t| > kMaxAbsTtSeconds.
// Floating point: host and the firmware's state intake, not the per-solution path.
constexpr bool tt_from_seconds(double t_s, TtTime& out) noexcept {
    if (!(t_s >= -kMaxAbsTtSeconds && t_s <= kMaxAbsTtSeconds)) {  // false for NaN
        return false;
    }
    const double us = t_s * 1e6;
    out.us = static_cast<std::int64_t>(us < 0.0 ? us - 0.5 : us + 0.5);
    return true;
}

// TtTime → seconds since J2000 (exact below 2⁵³ µs, i.e. ±285 years).
constexpr double tt_seconds(TtTime t) noexcept {
    return static_cast<double>(t.us) * 1e-6;
}

constexpr bool operator<(TtTime a, TtTime b) noexcept {
    return a.us < b.us;
}
constexpr bool operator<=(TtTime a, TtTime b) noexcept {
    return a.us <= b.us;
}
constexpr bool operator==(TtTime a, TtTime b) noexcept {
    return a.us == b.us;
}

}  // namespace ascorr
