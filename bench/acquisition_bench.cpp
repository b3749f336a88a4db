// bench/acquisition_bench.cpp: instructions per thermistor acquisition on a
// target, fixed point against float, under QEMU -icount (systick_counter.hpp).
//
// One acquisition is one 1 Hz sample set of eight channels (the boom's six plus
// CHU_A and CHU_B, firmware/app/boom_channels.hpp, make_config(8)): for each
// channel a selecting conversion and nine samples from the emulated ADC, the
// median, then counts → °C, the checks; then the vote of each head's three
// temperatures (head(), as the 22 Hz loop calls it for four heads). The
// settle waits go to a clock that does not wait (they are time, not work).
// kRuns acquisitions cycle over the 16-s profile, with its injected open
// circuits. Figures per acquisition:
//   acquire  poll(): sampling + conversion + checks of eight channels
//   update   conversion + checks alone, on the sample sets poll() read
//   heads    four head() calls (three votes each)
// for the fixed-point path and, as the baseline in the same run, the float
// path (on the Cortex-M3, which has no FPU, the float path runs in libgcc's
// soft float: the cost the fixed-point path avoids).
// Output: one line per figure, "acquisition <path> <part> <instructions>".
#include <cstdint>
#include <cstdio>

#include "boom_channels.hpp"
#include "systick_counter.hpp"

namespace {

using namespace ascorr;
namespace boom = ascorr::app::boom;

constexpr std::uint32_t kRuns = 64;

// A clock that moves only when told to; waits cost nothing.
class BenchClock final : public hal::Clock {
public:
    std::uint64_t now_us() noexcept override { return now_; }
    void wait_us(std::uint32_t /*us*/) noexcept override {}
    void set(std::uint64_t t) noexcept { now_ = t; }

private:
    std::uint64_t now_ = 0U;
};

volatile std::uint32_t g_sink;

template <typename T>
struct Bench {
    hal::AcquisitionConfig<T> config;
    BenchClock clock;
    boom::EmulatedBoomAdc adc;
    hal::SampleSet<T> sets[kRuns];
};

template <typename T>
void run(const char* name, Bench<T>& b, std::uint32_t ipc) {
    hal::AdcSampleSetSource<T> src(b.adc, b.clock, b.config);
    hal::TemperatureAcquisition<T> acq(b.config);
    // Empty loop of the same shape: its cost is subtracted.
    const std::uint32_t c0 = bench::counts([&] {
        for (std::uint32_t i = 0; i < kRuns; ++i) {
            b.clock.set(std::uint64_t{i} * 1000000U);
            b.adc.set_second(i);
            g_sink = i;
        }
    });
    const std::uint32_t c_acquire = bench::counts([&] {
        for (std::uint32_t i = 0; i < kRuns; ++i) {
            b.clock.set(std::uint64_t{i} * 1000000U);
            b.adc.set_second(i);
            g_sink = src.acquire(b.sets[i]) ? 1U : 0U;
            acq.update(b.sets[i]);
        }
    });
    hal::TemperatureAcquisition<T> acq2(b.config);
    const std::uint32_t c_update = bench::counts([&] {
        for (std::uint32_t i = 0; i < kRuns; ++i) {
            b.clock.set(std::uint64_t{i} * 1000000U);
            b.adc.set_second(i);
            acq2.update(b.sets[i]);
            g_sink = i;
        }
    });
    std::uint32_t valid = 0U;
    const std::uint32_t c_heads = bench::counts([&] {
        for (std::uint32_t i = 0; i < kRuns; ++i) {
            b.clock.set(std::uint64_t{i} * 1000000U);
            b.adc.set_second(i);
            for (std::uint8_t h = 0; h < ascorr::kMaxHeads; ++h) {
                valid += acq.head(h, std::uint64_t{kRuns - 1U} * 1000000U).temperatures.t_032.valid ? 1U : 0U;
            }
            g_sink = valid;
        }
    });
    const auto per = [&](std::uint32_t c) { return ((c - c0) * ipc + kRuns / 2U) / kRuns; };
    std::printf("acquisition %s acquire %u\n", name, static_cast<unsigned>(per(c_acquire)));
    std::printf("acquisition %s update %u\n", name, static_cast<unsigned>(per(c_update)));
    std::printf("acquisition %s heads %u\n", name, static_cast<unsigned>(per(c_heads)));
}

constexpr hal::AcquisitionConfig<float> kFloat8 = boom::make_config(hal::kMaxChannels);
constexpr hal::AcquisitionConfig<QCelsius> kFixed8 = boom::fixed_config(kFloat8);

Bench<float> g_float{};
Bench<QCelsius> g_fixed{};

}  // namespace

int main() {
    const std::uint32_t ipc = bench::instructions_per_count();
    std::printf("acquisition calibration %u instructions per SysTick count\n", static_cast<unsigned>(ipc));
    g_fixed.config = kFixed8;
    g_float.config = kFloat8;
    run<QCelsius>("fixed", g_fixed, ipc);
    run<float>("float", g_float, ipc);
    return 0;
}
