// The firmware loop's use of the HAL, on the host: float scalar, an ADC
// behind the AdcPort interface, acquisition at 1 Hz, a correction for every
// solution at 22 Hz on a ManualClock, faults and a stalled acquisition in the
// middle; with global operator new counted to prove the loop never allocates.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <new>

#include "alloc_counter.hpp"
#include "ascorr/ascorr.hpp"
#include "ascorr_hal/acquisition.hpp"
#include "hal_support.hpp"

namespace ascorr::test {
namespace {

// An MCP3208 as the firmware sees it through AdcPort: counts from the
// temperatures of the boom, with faults switched by the test.
class BoomAdc final : public hal::AdcPort {
public:
    explicit BoomAdc(const hal::AcquisitionConfig<float>& c) : cfg_(c) {}
    float celsius[8] = {-9.5F, -9.45F, -9.55F, -19.8F, -19.75F, -19.85F, 3.2F, 15.8F};
    bool open[8] = {};
    unsigned dither = 0;
    bool convert(std::uint8_t ch, std::uint16_t& counts) noexcept override {
        const hal::ChannelConfig<float>& c = cfg_.channel[ch];
        if (open[ch]) {
            counts = 4095U;
            return true;
        }
        const std::uint16_t n = hal::counts_from_resistance(c.divider, hal::resistance_from_celsius(c.sh, celsius[ch]));
        counts = static_cast<std::uint16_t>(n + (dither++ % 2U));  // one LSB of noise
        return true;
    }

private:
    const hal::AcquisitionConfig<float>& cfg_;
};

hal::AcquisitionConfig<float> float_config() {
    hal::AcquisitionConfig<float> f = to_float(swarm_config());
    for (std::uint8_t i = 0; i < hal::kMaxChannels; ++i) {
        if (i < f.channels) {
            f.channel[i].stuck_frames = 30U;
        } else {
            f.channel[i] = {};  // only the configured channels
        }
    }
    f.vote_tolerance = 1.0F;
    f.quorum = 2U;
    return f;
}

TEST(HalFirmwareLoop, OneHertzAcquisitionFeedsEverySolutionWithoutAllocating) {
    const hal::AcquisitionConfig<float> cfg = float_config();
    BoomAdc adc(cfg);
    hal::ManualClock clock(0);
    hal::AdcSampleSetSource<float> source(adc, clock, cfg);
    hal::TemperatureAcquisition<float> acq(cfg);

    ThermalModel<float> model{};
    model.head[0].present = true;
    model.head[0].gamma.c1 = 1e-5F;  // any model: the test is about validity
    const CorrectionConfig<float> ccfg{false, &model};
    SolutionInput<float> in{{1.0F, 0.0F, 0.0F, 0.0F}, 0U, {}, {{0.0F, 0.0F, 0.0F}, 1.0F, false}};

    // Per second of the run: how many of its 22 solutions had the thermal
    // correction applied, and the status of the last one.
    constexpr int kSeconds = 60;
    int applied[kSeconds] = {};
    StatusBits last_status[kSeconds] = {};

    arm_allocation_counter();
    for (int s = 0; s < kSeconds; ++s) {
        // Scenario: THT00029 and THT00087 open from 20 s to 25 s (no quorum);
        // the acquisition task stalls from 40 s to 50 s (stale after 5 s).
        adc.open[0] = adc.open[2] = s >= 20 && s < 25;
        const std::uint64_t second = static_cast<std::uint64_t>(s) * 1000000U;
        if (clock.now_us() < second) {
            clock.advance_us(second - clock.now_us());
        }
        if (s < 40 || s >= 50) {
            acq.poll(source);  // the 1 Hz task
        }
        for (int k = 0; k < 22; ++k) {  // the solution task
            const std::uint64_t t = second + 100000U + static_cast<std::uint64_t>(k) * 40000U;
            if (clock.now_us() < t) {
                clock.advance_us(t - clock.now_us());
            }
            const hal::HeadAcquisition<float> h = acq.head(0U, clock.now_us());
            in.temperatures = h.temperatures;
            CorrectedSolution<float> out = correct_solution(in, ccfg);
            out.status = hal::merge_status(out.status, h);
            applied[s] += (out.status & status::kThermalApplied) != 0U ? 1 : 0;
            last_status[s] = out.status;
        }
    }
    EXPECT_EQ(disarm_allocation_counter(), 0);

    for (int s = 0; s < kSeconds; ++s) {
        if (s >= 20 && s < 25) {
            EXPECT_EQ(applied[s], 0) << s;
            EXPECT_EQ(last_status[s], status::kNoTemperature | status::kTemperatureInvalid) << s;
        } else if (s >= 44 && s < 50) {  // last sample set at 39.0 s: stale from 44.0 s on
            EXPECT_EQ(applied[s], 0) << s;
            EXPECT_EQ(last_status[s], status::kNoTemperature | status::kStale) << s;
        } else {
            EXPECT_EQ(applied[s], 22) << s;
            EXPECT_EQ(last_status[s], status::kThermalApplied) << s;
        }
    }
}

}  // namespace
}  // namespace ascorr::test
