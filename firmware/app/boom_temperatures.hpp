// firmware/app/boom_temperatures.hpp: the flight loop's temperatures through
// the HAL (hal/): thermistor acquisition, fault checks and triplet voting, on
// any hal::Clock.
//
// Where each reading comes from:
//  - T_CHU (T1) is the camera head's own CCD temperature, reported by the head
//    itself, not by a boom thermistor: it is taken from the heads' housekeeping
//    (here a stepped profile). Head D has no camera: its T_CHU is invalid.
//  - THT00029/57/87 (T2) and THT00032/60/90 (T3) are thermistors on the boom,
//    read at 1 Hz through an MCP3208 behind hal::AdcPort, converted, checked and
//    voted by hal::TemperatureAcquisition exactly as on the DPU: in float on
//    the FPU target (Cortex-M4F), in fixed point on the target without FPU
//    (Cortex-M3: counts → °C by a table built at compile time, checks and vote
//    in integers; hal/include/ascorr_hal/fixed_thermistor.hpp). Both take the
//    same configuration and the same emulated ADC with the same injected
//    faults (boom_channels.hpp): THT00057 open in seconds 4–6 (outvoted),
//    THT00032 and THT00060 open in seconds 9–10 (T3 without quorum).
//
// The clock is the caller's: SysTick on the DPU (hal_temperatures.cpp), a
// test double on the host (tests/target/flight_expectation.cpp), which thereby
// runs this very acquisition to predict the loop's solutions. Time enters only
// the settle waits, staleness (3 s, against 1 Hz polls) and the rate check
// (0.5 °C/s against profiles of at most 0.375 °C/s): decisions with margins
// far beyond the microseconds by which the two clocks differ.
#pragma once

#include <cstdint>

#include "app_scalar.hpp"
#include "ascorr/core/status.hpp"
#include "ascorr/core/thermal.hpp"
#include "ascorr_hal/acquisition.hpp"
#include "ascorr_hal/clock.hpp"
#include "boom_channels.hpp"

namespace ascorr::app {

// T_CHU from each head's housekeeping (°C, a stepped profile of 16 seconds,
// a sawtooth of 4 s unlike the boom's ramps, boom_channels.hpp; head D: none),
// in the core's format at compile time.
constexpr double chu_celsius(std::uint32_t head, std::uint32_t s) {
    return 10.0 + 2.5 * static_cast<double>(head) + 0.5 * static_cast<double>(s % 4U);
}

struct ChuProfile {
    Celsius<Scalar> t[kMaxHeads][boom::kProfileSeconds];
};

constexpr ChuProfile make_chu_profile() {
    ChuProfile p{};
    for (std::uint32_t h = 0; h < kMaxHeads; ++h) {
        for (std::uint32_t s = 0; s < boom::kProfileSeconds; ++s) {
            p.t[h][s] = ScalarTraits<Scalar>::celsius(chu_celsius(h, s));
        }
    }
    return p;
}

inline constexpr ChuProfile kChuProfile = make_chu_profile();

class BoomTemperatures {
public:
    using HalScalar = boom::HalScalar;
    static constexpr hal::AcquisitionConfig<HalScalar> kConfig = boom::Config<HalScalar>::of(boom::kFloatConfig);

    explicit BoomTemperatures(hal::Clock& clock) noexcept : clock_(clock), source_(adc_, clock, kConfig) {}

    // Refreshes the readings for cycle `cycle` of a loop at `rate_hz`, the
    // clock already at the cycle's start. Bounded time, never blocks.
    void update(std::uint32_t cycle, std::uint32_t rate_hz) noexcept {
        const std::uint32_t second = cycle / rate_hz;
        if (cycle % rate_hz == 0U) {  // 1 Hz acquisition
            adc_.set_second(second);
            (void)acquisition_.poll(source_);
        }
        const std::uint64_t now = clock_.now_us();
        for (std::uint8_t h = 0; h < kMaxHeads; ++h) {  // fixed trip count
            hal::HeadAcquisition<HalScalar> a = acquisition_.head(h, now);
            const bool has_camera = h < 3U;
            a.temperatures.t_chu = {kChuProfile.t[h][second % boom::kProfileSeconds], has_camera};
            a.faults_chu = has_camera ? hal::FaultBits{0U} : a.faults_chu;
            heads_[h] = a;
        }
    }

    // The readings of `head`; head ≥ kMaxHeads gets an entry whose readings are all invalid.
    const HeadTemperatures<Scalar>& of(std::uint8_t head) const noexcept {
        return heads_[head < kMaxHeads ? head : kMaxHeads].temperatures;
    }

    // The core's status with the acquisition's reasons (64 fault, 512 stale) added.
    StatusBits merge_status(std::uint8_t head, StatusBits core) const noexcept {
        return hal::merge_status(core, heads_[head < kMaxHeads ? head : kMaxHeads]);
    }

private:
    hal::Clock& clock_;
    boom::EmulatedBoomAdc adc_;
    hal::AdcSampleSetSource<HalScalar> source_;
    hal::TemperatureAcquisition<HalScalar> acquisition_{kConfig};
    hal::HeadAcquisition<HalScalar> heads_[kMaxHeads + 1]{};  // the last entry: all invalid
};

}  // namespace ascorr::app
