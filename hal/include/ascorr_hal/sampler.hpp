// ascorr_hal/sampler.hpp: settle, several conversions, a robust average.
//
// Conventions:
//  - For one channel: one conversion that selects the channel and is thrown
//    away, a settle wait (settle_us, on the injected Clock) so that the input
//    filter and the sample-and-hold follow the multiplexer, then `samples`
//    conversions (1 … kMaxSamples).
//  - The value is the median of the samples (lower median for an even count);
//    the spread is the inner half's range, s[n−1−n/4] − s[n/4], so that one
//    glitch among 8 or more samples neither moves the value nor raises kNoisy.
//  - Any failed conversion makes the whole channel a bus fault (kBus).
//  - Freestanding: fixed-size arrays, bounded loops, no heap, no exceptions.
#pragma once

#include <cstdint>

#include "clock.hpp"
#include "faults.hpp"
#include "mcp3208.hpp"

namespace ascorr::hal {

inline constexpr std::uint8_t kMaxSamples = 16;

struct SamplerSettings {
    std::uint32_t settle_us;  // wait after selecting the channel
    std::uint8_t samples;     // conversions averaged, 1 … kMaxSamples
    std::uint32_t gap_us;     // wait between conversions
};

struct RobustSample {
    std::uint16_t counts;  // median
    std::uint16_t spread;  // range of the inner half, counts
    FaultBits faults;      // kBus or 0
};

// Median and inner-half spread of n values (sorted in place, insertion sort).
inline RobustSample robust_average(std::uint16_t* s, std::uint8_t n) noexcept {
    for (std::uint8_t i = 1; i < n; ++i) {
        const std::uint16_t v = s[i];
        std::uint8_t j = i;
        for (; j > 0 && s[j - 1] > v; --j) {
            s[j] = s[j - 1];
        }
        s[j] = v;
    }
    const std::uint8_t lo = static_cast<std::uint8_t>(n / 4U);
    const std::uint8_t hi = static_cast<std::uint8_t>(n - 1U - n / 4U);
    return {s[(n - 1U) / 2U], static_cast<std::uint16_t>(s[hi] - s[lo]), 0U};
}

inline RobustSample sample_channel(AdcPort& adc, Clock& clock, const SamplerSettings& st,
                                   std::uint8_t channel) noexcept {
    std::uint16_t buf[kMaxSamples] = {};
    const std::uint8_t n = st.samples == 0U ? 1U : (st.samples > kMaxSamples ? kMaxSamples : st.samples);
    std::uint16_t discard = 0;
    if (!adc.convert(channel, discard)) {
        return {0U, 0U, fault::kBus};
    }
    clock.wait_us(st.settle_us);
    for (std::uint8_t i = 0; i < n; ++i) {
        if (i != 0U && st.gap_us != 0U) {
            clock.wait_us(st.gap_us);
        }
        if (!adc.convert(channel, buf[i])) {
            return {0U, 0U, fault::kBus};
        }
    }
    return robust_average(buf, n);
}

}  // namespace ascorr::hal
