// firmware/app/hal_temperatures.cpp: the flight loop's temperatures through
// the HAL (hal/): thermistor acquisition, fault checks and triplet voting.
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
//  - Time for settle waits and staleness is SysTick's (SysTickClock).
#include <cstdint>

#include "ascorr_hal/acquisition.hpp"
#include "board.hpp"
#include "boom_channels.hpp"
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

// T_CHU from each head's housekeeping (°C, a stepped profile of 16 seconds;
// head D: none), in the core's format at compile time.
struct ChuProfile {
    Celsius<Scalar> t[kMaxHeads][boom::kProfileSeconds];
};

constexpr ChuProfile make_chu_profile() {
    ChuProfile p{};
    for (std::uint32_t h = 0; h < kMaxHeads; ++h) {
        for (std::uint32_t s = 0; s < boom::kProfileSeconds; ++s) {
            p.t[h][s] = ScalarTraits<Scalar>::celsius(10.0 + 2.5 * static_cast<double>(h) + boom::ramp(s));
        }
    }
    return p;
}

constexpr ChuProfile kChuProfile = make_chu_profile();

using HalScalar = boom::HalScalar;
constexpr hal::AcquisitionConfig<HalScalar> kConfig = boom::Config<HalScalar>::of(boom::kFloatConfig);

SysTickClock g_clock;
boom::EmulatedBoomAdc g_adc;
hal::AdcSampleSetSource<HalScalar> g_source(g_adc, g_clock, kConfig);
hal::TemperatureAcquisition<HalScalar> g_acquisition(kConfig);
hal::HeadAcquisition<HalScalar> g_heads[kMaxHeads + 1];  // the last entry: all invalid

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
        hal::HeadAcquisition<HalScalar> a = g_acquisition.head(h, now);
        const bool has_camera = h < 3U;
        a.temperatures.t_chu = {kChuProfile.t[h][second % boom::kProfileSeconds], has_camera};
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
