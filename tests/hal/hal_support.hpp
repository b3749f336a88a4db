// tests/hal/hal_support.hpp: shared helpers of the HAL tests.
#pragma once

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <iterator>

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

// The floating configuration in float, as on the DPU.
inline hal::AcquisitionConfig<float> to_float(const hal::AcquisitionConfig<double>& d) {
    hal::AcquisitionConfig<float> f{};
    for (std::uint8_t i = 0; i < hal::kMaxChannels; ++i) {
        const hal::ChannelConfig<double>& c = d.channel[i];
        hal::ChannelConfig<float>& o = f.channel[i];
        std::copy(std::begin(c.name), std::end(c.name), std::begin(o.name));
        o.role = c.role;
        o.adc_channel = c.adc_channel;
        o.divider = {c.divider.thermistor_low, static_cast<float>(c.divider.r_fixed), c.divider.levels};
        o.sh = {static_cast<float>(c.sh.a), static_cast<float>(c.sh.b), static_cast<float>(c.sh.c)};
        o.r_open = static_cast<float>(c.r_open);
        o.r_short = static_cast<float>(c.r_short);
        o.t_min = static_cast<float>(c.t_min);
        o.t_max = static_cast<float>(c.t_max);
        o.max_rate = static_cast<float>(c.max_rate);
        o.stuck_frames = c.stuck_frames;
        o.max_spread = c.max_spread;
    }
    f.channels = d.channels;
    f.sampler = d.sampler;
    f.stale_us = d.stale_us;
    f.vote_tolerance = static_cast<float>(d.vote_tolerance);
    f.quorum = d.quorum;
    return f;
}

}  // namespace ascorr::test
