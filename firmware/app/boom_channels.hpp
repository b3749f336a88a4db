// firmware/app/boom_channels.hpp: the boom thermistors of the flight image and
// the emulated ADC that stands in for the MCP3208 under QEMU.
//
// Conventions:
//  - One configuration, kFloatConfig (AcquisitionConfig<float>: Steinhart–Hart
//    coefficients, divider, limits), is the source of truth. The float build
//    (FPU) acquires with it; the fixed-point build (no FPU) with kFixedConfig,
//    derived from it at compile time: the counts → °C table (kBoomTable,
//    hal/include/ascorr_hal/fixed_thermistor.hpp) and the limits in QCelsius.
//    HalScalar is the HAL's temperature type of the build (float or QCelsius).
//  - Channels 0–5: THT00029/57/87 (T2) and THT00032/60/90 (T3), in a divider
//    with 10 kΩ to the ADC reference (thermistor to ground), 12 bits.
//    make_config(8) adds CHU_A and CHU_B (channels 6, 7) for the acquisition
//    benchmark's eight-channel sample set; the flight image reads six.
//  - EmulatedBoomAdc: QEMU's MPS2 board has no ADC, so this AdcPort returns
//    the codes an ideal ADC gives for a boom temperature profile (16 points,
//    one per second, computed at compile time: no arithmetic at run time),
//    with faults injected at fixed seconds of each 16-s period:
//      seconds 4–6:  THT00057 open (outvoted: T2 stays valid from 29 and 87),
//      seconds 9–10: THT00032 and THT00060 open (no quorum: T3 withheld, the
//                    thermal stage is skipped with status 8 + 64).
//    The same port and scenario serve both images.
#pragma once

#include <cstdint>

#include "app_scalar.hpp"
#include "ascorr_hal/acquisition.hpp"
#include "ascorr_hal/channel_defaults.hpp"
#include "ascorr_hal/fixed_thermistor.hpp"

namespace ascorr::app::boom {

#if defined(ASCORR_APP_FIXED)
using HalScalar = QCelsius;
#else
using HalScalar = float;
#endif

inline constexpr std::uint8_t kBoomChannels = 6;
inline constexpr std::uint32_t kProfileSeconds = 16;

// A boom channel: the HAL's default channel (hal/include/ascorr_hal/
// channel_defaults.hpp: the 10K3A1 curve, 10 kΩ to the ADC reference with the
// thermistor to ground, 12 bits, limits; stuck check off, as the emulated ADC
// has no noise and a steady reading would trip it) with its name, role, input.
constexpr hal::ChannelConfig<float> channel(const char (&name)[9], hal::Role role, std::uint8_t adc) {
    hal::ChannelConfig<float> c = hal::default_channel<float>();
    for (std::uint8_t i = 0; i < 9; ++i) {
        c.name[i] = name[i];
    }
    c.role = role;
    c.adc_channel = adc;
    return c;
}

// The HAL's default acquisition (2 ms settle, median of 9, 1 °C vote
// tolerance, quorum 2) with the boom channels and a 3 s staleness limit.
constexpr hal::AcquisitionConfig<float> make_config(std::uint8_t channels) {
    hal::AcquisitionConfig<float> a = hal::default_acquisition<float>();
    a.channel[0] = channel("THT00029", hal::Role::kT029, 0);
    a.channel[1] = channel("THT00057", hal::Role::kT029, 1);
    a.channel[2] = channel("THT00087", hal::Role::kT029, 2);
    a.channel[3] = channel("THT00032", hal::Role::kT032, 3);
    a.channel[4] = channel("THT00060", hal::Role::kT032, 4);
    a.channel[5] = channel("THT00090", hal::Role::kT032, 5);
    a.channel[6] = channel("CHU_A\0\0\0", hal::Role::kChuA, 6);
    a.channel[7] = channel("CHU_B\0\0\0", hal::Role::kChuB, 7);
    a.channels = channels;
    a.stale_us = 3000000U;  // a reading older than 3 s (three missed 1 Hz polls) is withheld
    return a;
}

inline constexpr hal::AcquisitionConfig<float> kFloatConfig = make_config(kBoomChannels);

// Every channel has the same curve and limits: one table serves them all
// (fixed_channel() checks that it was built from each).
inline constexpr hal::CountsTable kBoomTable = hal::make_counts_table(kFloatConfig.channel[0]);
static_assert(kBoomTable.ok, "the boom channels' counts -> degC table was refused");
static_assert(kBoomTable.worst_error_raw <= static_cast<std::int32_t>(hal::kTableBudgetC * 1048576.0),
              "table error beyond its budget");
inline constexpr const hal::CountsTable* kBoomTables[hal::kMaxChannels] = {
    &kBoomTable, &kBoomTable, &kBoomTable, &kBoomTable, &kBoomTable, &kBoomTable, &kBoomTable, &kBoomTable};

constexpr hal::AcquisitionConfig<QCelsius> fixed_config(const hal::AcquisitionConfig<float>& f) {
    return hal::fixed_acquisition(f, kBoomTables);
}

// The build's configuration, in its HAL scalar.
template <typename T>
struct Config;
template <>
struct Config<float> {
    static constexpr hal::AcquisitionConfig<float> of(const hal::AcquisitionConfig<float>& f) { return f; }
};
template <>
struct Config<QCelsius> {
    static constexpr hal::AcquisitionConfig<QCelsius> of(const hal::AcquisitionConfig<float>& f) {
        return fixed_config(f);
    }
};

// The profiles' common shape: 0.75 °C per second up for 8 s, then down.
constexpr double ramp(std::uint32_t s) {
    return 0.75 * static_cast<double>(s < 8U ? s : kProfileSeconds - s);
}

// The boom's temperature at second s of the profile, per channel (°C):
// triplet members read almost the same. THT00032's triplet runs 4 s behind
// THT00029's, and T_CHU has a shape of its own (boom_temperatures.hpp), so
// that the thermal model's regressors [1, T1, T2 − T1, T3 − T1] are linearly
// independent over the 16 s: the on-board estimator can identify the bench's
// deformation from them (flight_bench.hpp).
constexpr double profile_celsius(std::uint8_t channel, std::uint32_t s) {
    const double spread = 0.05 * static_cast<double>(channel % 3U);
    if (channel < 3U) {
        return -6.5 + 0.5 * ramp(s) + spread;
    }
    if (channel < 6U) {
        return -20.0 + 0.25 * ramp((s + kProfileSeconds - 4U) % kProfileSeconds) + spread;
    }
    const double r = ramp(s);
    return 10.0 + 2.5 * static_cast<double>(channel - 6U) + r;  // CHU_A, CHU_B (benchmark only)
}

struct CountsProfile {
    std::uint16_t counts[hal::kMaxChannels][kProfileSeconds];
};

constexpr CountsProfile make_counts_profile() {
    CountsProfile p{};
    const hal::AcquisitionConfig<float> all = make_config(hal::kMaxChannels);
    for (std::uint8_t ch = 0; ch < hal::kMaxChannels; ++ch) {
        for (std::uint32_t s = 0; s < kProfileSeconds; ++s) {
            p.counts[ch][s] = hal::counts_for_celsius(all.channel[ch], profile_celsius(ch, s));
        }
    }
    return p;
}

inline constexpr CountsProfile kCountsProfile = make_counts_profile();

constexpr bool injected_open(std::uint8_t channel, std::uint32_t second) noexcept {
    const std::uint32_t s = second % kProfileSeconds;
    return (channel == 1U && s >= 4U && s <= 6U) || ((channel == 3U || channel == 4U) && (s == 9U || s == 10U));
}

class EmulatedBoomAdc final : public hal::AdcPort {
public:
    void set_second(std::uint32_t second) noexcept { second_ = second; }
    bool convert(std::uint8_t channel, std::uint16_t& counts) noexcept override {
        if (channel >= hal::kMaxChannels) {
            return false;
        }
        counts = injected_open(channel, second_) ? std::uint16_t{4095U}
                                                 // open thermistor to ground: the input sits at the reference
                                                 : kCountsProfile.counts[channel][second_ % kProfileSeconds];
        return true;
    }

private:
    std::uint32_t second_ = 0U;
};

}  // namespace ascorr::app::boom
