// ascorr_hal/channel_defaults.hpp: the one source of the thermistor channel
// defaults (curve, divider, limits, checks) and of the acquisition defaults.
//
// Conventions:
//  - Every other place derives from here, never copies: the board
//    configuration file's optional keys (hal/linux/src/config_file.cpp), the
//    flight image's boom channels (firmware/app/boom_channels.hpp), the HAL
//    tests' Swarm layout (tests/hal/hal_support.hpp). The example file
//    hal/examples/board.cfg spells the curve out as text; the test
//    HalDefaults.EveryCopyDerivesFromTheOneSource checks it and every derived
//    copy against this header.
//  - A thermistor type is a named Steinhart–Hart curve here (k10K3A1), with
//    its source; a channel of that type starts from default_channel() and
//    sets its curve.
//  - Units as in channel_config.hpp: ohm, °C, °C/s, µs, counts. Templated on
//    the configuration's scalar (float on the DPU, double on the host);
//    constexpr, freestanding: no heap, no exceptions.
#pragma once

#include <cstdint>

#include "channel_config.hpp"
#include "thermistor.hpp"

namespace ascorr::hal {

// The 10K3A1 curve, a 10 kΩ NTC (Campbell Scientific 109SS instruction
// manual, Appendix C, Therm109(): A = 1.129241e-3, B = 2.341077e-4,
// C = 8.775468e-8): the Swarm boom thermistors of this project.
template <typename T>
inline constexpr SteinhartHart<T> k10K3A1{static_cast<T>(1.129241e-3), static_cast<T>(2.341077e-4),
                                          static_cast<T>(8.775468e-8)};

// A channel before its name, role and ADC input are set: the 10K3A1 curve in
// a divider with 10 kΩ to the ADC reference (thermistor to ground), 12 bits;
// open at 2 MΩ and short at 100 Ω (the curve gives 1.40 MΩ at −60 °C and
// 1.26 kΩ at 80 °C, so both lie beyond the valid range); valid −60 … 80 °C; at most 0.5 °C/s; no stuck check (0: a
// noise-free source would trip it on a steady reading); kNoisy above 8 counts of spread.
template <typename T>
constexpr ChannelConfig<T> default_channel() noexcept {
    ChannelConfig<T> c{};
    c.role = Role::kMonitor;
    c.adc_channel = 0U;
    c.divider = {true, static_cast<T>(10000.0), 4096U};
    c.sh = k10K3A1<T>;
    c.r_open = static_cast<T>(2.0e6);
    c.r_short = static_cast<T>(100.0);
    c.t_min = static_cast<T>(-60.0);
    c.t_max = static_cast<T>(80.0);
    c.max_rate = static_cast<T>(0.5);
    c.stuck_frames = 0U;
    c.max_spread = 8U;
    return c;
}

// The acquisition without channels: 2 ms settle, median of 9 conversions
// without gaps, stale after 5 s, members within 1 °C of the median, two
// agreeing members for a voted value.
template <typename T>
constexpr AcquisitionConfig<T> default_acquisition() noexcept {
    AcquisitionConfig<T> a{};
    a.channels = 0U;
    a.sampler = {2000U, 9U, 0U};
    a.stale_us = 5000000U;
    a.vote_tolerance = static_cast<T>(1.0);
    a.quorum = 2U;
    return a;
}

}  // namespace ascorr::hal
