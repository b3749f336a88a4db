// tests/hal/hal_support.hpp: shared helpers of the HAL tests.
#pragma once

#include <cstdint>
#include <cstring>

#include "ascorr_hal/acquisition.hpp"
#include "ascorr_hal/channel_defaults.hpp"

namespace ascorr::test {

// The 10K3A1 curve (hal/include/ascorr_hal/channel_defaults.hpp).
inline constexpr hal::SteinhartHart<double> k10K3A1 = hal::k10K3A1<double>;

// The HAL's default channel (channel_defaults.hpp) with a stuck check after 5
// identical frames, which the tests exercise.
inline hal::ChannelConfig<double> channel(const char* name, hal::Role role, std::uint8_t adc) {
    hal::ChannelConfig<double> c = hal::default_channel<double>();
    std::strncpy(c.name, name, hal::kNameLength - 1);
    c.role = role;
    c.adc_channel = adc;
    c.stuck_frames = 5U;
    return c;
}

// The Swarm layout: THT00029/57/87 (T2), THT00032/60/90 (T3), CHU A and B.
inline hal::AcquisitionConfig<double> swarm_config() {
    hal::AcquisitionConfig<double> a = hal::default_acquisition<double>();
    const char* names[8] = {"THT00029", "THT00057", "THT00087", "THT00032", "THT00060", "THT00090", "CHU_A", "CHU_B"};
    const hal::Role roles[8] = {hal::Role::kT029, hal::Role::kT029, hal::Role::kT029, hal::Role::kT032,
                                hal::Role::kT032, hal::Role::kT032, hal::Role::kChuA, hal::Role::kChuB};
    for (std::uint8_t i = 0; i < 8; ++i) {
        a.channel[i] = channel(names[i], roles[i], i);
    }
    a.channels = 8;
    return a;
}

inline std::uint16_t counts_at(const hal::ChannelConfig<double>& c, double celsius) {
    return hal::counts_from_resistance(c.divider, hal::resistance_from_celsius(c.sh, celsius));
}

}  // namespace ascorr::test
