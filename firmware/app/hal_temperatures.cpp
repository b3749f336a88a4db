// firmware/app/hal_temperatures.cpp: the flight loop's temperatures through
// the HAL (hal/): thermistor acquisition, fault checks and triplet voting.
//
// Where each reading comes from:
//  - T_CHU (T1) is the camera head's own CCD temperature, reported by the head
//    itself, not by a boom thermistor: it is taken from the heads' housekeeping
//    (here a stepped profile, as in simulated_temperatures.cpp). Head D has no
//    camera: its T_CHU is invalid.
//  - THT00029/57/87 (T2) and THT00032/60/90 (T3) are thermistors on the boom,
//    read at 1 Hz through an MCP3208 behind hal::AdcPort, converted, checked and
//    voted by hal::TemperatureAcquisition exactly as on the DPU. QEMU's MPS2
//    board has no ADC, so EmulatedBoomAdc stands in for the chip behind the
//    same port: it returns the counts the divider would give for a boom
//    temperature profile, with faults injected at fixed seconds:
//      seconds 4–6:  THT00057 open (outvoted: T2 stays valid from 29 and 87),
//      seconds 9–10: THT00032 and THT00060 open (no quorum: T3 withheld, the
//                    thermal stage is skipped with status 8 + 64).
//  - Time for settle waits and staleness is SysTick's (SysTickClock).
// Fixed-point builds (Cortex-M3, no FPU) keep simulated_temperatures.cpp: the
// HAL's conversion is floating point (Steinhart–Hart needs a logarithm).
#include <cstdint>

#include "ascorr_hal/acquisition.hpp"
#include "board.hpp"
#include "temperature_source.hpp"

namespace ascorr::app {
namespace {

constexpr std::uint32_t kCyclesPerSecond = 22U;
constexpr std::uint32_t kPeriod = board::kCoreClockHz / kCyclesPerSecond;  // SysTick reload + 1, as main.cpp
constexpr std::uint32_t kCountsPerUs = board::kCoreClockHz / 1000000U;

// Microseconds on SysTick. now_us: the cycle's start plus the time elapsed in
// it, never decreasing. wait_us: counts SysTick decrements across reloads; it
// reads the counter far more often than once per period, so no reload is
// missed, and it gives up after a fixed number of reads (a stopped timer must
// not hang the loop).
class SysTickClock final : public hal::Clock {
public:
    void start_cycle(std::uint32_t cycle) noexcept {
        base_us_ = static_cast<std::uint64_t>(cycle) * 1000000U / kCyclesPerSecond;
    }
    std::uint64_t now_us() noexcept override {
        const std::uint32_t elapsed = (kPeriod - 1U - board::systick_value()) / kCountsPerUs;
        const std::uint64_t t = base_us_ + elapsed;
        last_us_ = t > last_us_ ? t : last_us_;
        return last_us_;
    }
    void wait_us(std::uint32_t us) noexcept override {
        const std::uint64_t need = static_cast<std::uint64_t>(us) * kCountsPerUs;
        std::uint64_t done = 0U;
        std::uint32_t prev = board::systick_value();
        for (std::uint64_t reads = 0U; done < need && reads < need + 1000000U; ++reads) {
            const std::uint32_t now = board::systick_value();
            done += prev >= now ? prev - now : prev + (kPeriod - now);
            prev = now;
        }
    }

private:
    std::uint64_t base_us_ = 0U;
    std::uint64_t last_us_ = 0U;
};

constexpr hal::SteinhartHart<float> k10K3A1{1.129241e-3F, 2.341077e-4F, 8.775468e-8F};

constexpr hal::ChannelConfig<float> boom_channel(const char (&name)[9], hal::Role role, std::uint8_t adc) {
    hal::ChannelConfig<float> c{};
    for (std::uint8_t i = 0; i < 9; ++i) {
        c.name[i] = name[i];
    }
    c.role = role;
    c.adc_channel = adc;
    c.divider = {true, 10000.0F, 4096U};  // thermistor to ground, 10 kΩ to the ADC reference
    c.sh = k10K3A1;
    c.r_open = 2.0e6F;
    c.r_short = 100.0F;
    c.t_min = -60.0F;
    c.t_max = 80.0F;
    c.max_rate = 0.5F;
    c.stuck_frames = 0U;  // the emulated ADC has no noise: a stuck check would fire on a steady reading
    c.max_spread = 8U;
    return c;
}

constexpr hal::AcquisitionConfig<float> make_config() {
    hal::AcquisitionConfig<float> a{};
    a.channel[0] = boom_channel("THT00029", hal::Role::kT029, 0);
    a.channel[1] = boom_channel("THT00057", hal::Role::kT029, 1);
    a.channel[2] = boom_channel("THT00087", hal::Role::kT029, 2);
    a.channel[3] = boom_channel("THT00032", hal::Role::kT032, 3);
    a.channel[4] = boom_channel("THT00060", hal::Role::kT032, 4);
    a.channel[5] = boom_channel("THT00090", hal::Role::kT032, 5);
    a.channels = 6;
    a.sampler = {2000U, 9U, 0U};  // 2 ms settle, median of 9
    a.stale_us = 3000000U;        // a reading older than 3 s (three missed polls) is withheld
    a.vote_tolerance = 1.0F;
    a.quorum = 2U;
    return a;
}

const hal::AcquisitionConfig<float> kConfig = make_config();

// The boom's temperature in the current second, per channel (°C).
float boom_celsius(std::uint8_t channel, std::uint32_t second) noexcept {
    const std::uint32_t s = second % 16U;
    const float ramp = 0.75F * static_cast<float>(s < 8U ? s : 16U - s);
    const float spread = 0.05F * static_cast<float>(channel % 3U);  // triplet members read almost the same
    return channel < 3U ? -6.5F + 0.5F * ramp + spread : -20.0F + 0.25F * ramp + spread;
}

bool injected_open(std::uint8_t channel, std::uint32_t second) noexcept {
    const std::uint32_t s = second % 16U;
    return (channel == 1U && s >= 4U && s <= 6U) || ((channel == 3U || channel == 4U) && (s == 9U || s == 10U));
}

class EmulatedBoomAdc final : public hal::AdcPort {
public:
    void set_second(std::uint32_t second) noexcept { second_ = second; }
    bool convert(std::uint8_t channel, std::uint16_t& counts) noexcept override {
        if (channel >= 6U) {
            return false;
        }
        if (injected_open(channel, second_)) {
            counts = 4095U;  // open thermistor to ground: the input sits at the reference
            return true;
        }
        const hal::ChannelConfig<float>& c = kConfig.channel[channel];
        counts =
            hal::counts_from_resistance(c.divider, hal::resistance_from_celsius(c.sh, boom_celsius(channel, second_)));
        return true;
    }

private:
    std::uint32_t second_ = 0U;
};

// T_CHU from each head's housekeeping, °C (head D: none).
float chu_celsius(std::uint8_t head, std::uint32_t second) noexcept {
    const std::uint32_t s = second % 16U;
    const float ramp = 0.75F * static_cast<float>(s < 8U ? s : 16U - s);
    return 10.0F + 2.5F * static_cast<float>(head) + ramp;
}

SysTickClock g_clock;
EmulatedBoomAdc g_adc;
hal::AdcFrameSource<float> g_source(g_adc, g_clock, kConfig);
hal::TemperatureAcquisition<float> g_acquisition(kConfig);
hal::HeadAcquisition<float> g_heads[kMaxHeads + 1];  // the last entry: all invalid

}  // namespace

void temperatures_update(std::uint32_t cycle) noexcept {
    const std::uint32_t second = cycle / kCyclesPerSecond;
    g_clock.start_cycle(cycle);
    if (cycle % kCyclesPerSecond == 0U) {  // 1 Hz acquisition
        g_adc.set_second(second);
        (void)g_acquisition.poll(g_source);
    }
    const std::uint64_t now = g_clock.now_us();
    for (std::uint8_t h = 0; h < kMaxHeads; ++h) {  // fixed trip count
        hal::HeadAcquisition<float> a = g_acquisition.head(h, now);
        const bool has_camera = h < 3U;
        a.temperatures.t_chu = {chu_celsius(h, second), has_camera};
        a.faults_chu = has_camera ? hal::FaultBits{0U} : a.faults_chu;
        g_heads[h] = a;
    }
}

const HeadTemperatures<Scalar>& temperatures_of(std::uint8_t head) noexcept {
    return g_heads[head < kMaxHeads ? head : kMaxHeads].temperatures;
}

StatusBits temperatures_merge_status(std::uint8_t head, StatusBits core) noexcept {
    return hal::merge_status(core, g_heads[head < kMaxHeads ? head : kMaxHeads]);
}

}  // namespace ascorr::app
