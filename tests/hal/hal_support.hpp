// tests/hal/hal_support.hpp: shared helpers of the HAL tests.
#pragma once

#include <cstdint>
#include <cstring>

#include "ascorr_hal/acquisition.hpp"

namespace ascorr::test {

// The 10K3A1 curve (Campbell Scientific 109SS instruction manual, Appendix C,
// Therm109(): A = 1.129241e-3, B = 2.341077e-4, C = 8.775468e-8).
inline constexpr hal::SteinhartHart<double> k10K3A1{1.129241e-3, 2.341077e-4, 8.775468e-8};

inline hal::ChannelConfig<double> channel(const char* name, hal::Role role, std::uint8_t adc) {
    hal::ChannelConfig<double> c{};
    std::strncpy(c.name, name, hal::kNameLength - 1);
    c.role = role;
    c.adc_channel = adc;
    c.divider = {true, 10000.0, 4096U};
    c.sh = k10K3A1;
    c.r_open = 2.0e6;
    c.r_short = 100.0;
    c.t_min = -60.0;
    c.t_max = 80.0;
    c.max_rate = 0.5;
    c.stuck_frames = 5U;
    c.max_spread = 8U;
    return c;
}

// The Swarm layout: THT00029/57/87 (T2), THT00032/60/90 (T3), CHU A and B.
inline hal::AcquisitionConfig<double> swarm_config() {
    hal::AcquisitionConfig<double> a{};
    const char* names[8] = {"THT00029", "THT00057", "THT00087", "THT00032", "THT00060", "THT00090", "CHU_A", "CHU_B"};
    const hal::Role roles[8] = {hal::Role::kT029, hal::Role::kT029, hal::Role::kT029, hal::Role::kT032,
                                hal::Role::kT032, hal::Role::kT032, hal::Role::kChuA, hal::Role::kChuB};
    for (std::uint8_t i = 0; i < 8; ++i) {
        a.channel[i] = channel(names[i], roles[i], i);
    }
    a.channels = 8;
    a.sampler = {2000U, 9U, 0U};
    a.stale_us = 5000000U;
    a.vote_tolerance = 1.0;
    a.quorum = 2U;
    return a;
}

inline std::uint16_t counts_at(const hal::ChannelConfig<double>& c, double celsius) {
    return hal::counts_from_resistance(c.divider, hal::resistance_from_celsius(c.sh, celsius));
}

}  // namespace ascorr::test
