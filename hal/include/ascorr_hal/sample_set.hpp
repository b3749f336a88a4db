// ascorr_hal/sample_set.hpp: one acquisition of every channel, and the interface
// of the backends that produce it.
//
// Conventions:
//  - A SampleSet holds, per configured channel (index as in AcquisitionConfig),
//    either raw counts (an ADC: the robust average and its spread) or a
//    temperature (a replay of converted values), or nothing (kNone), plus the
//    device-level faults (kBus). t_us is its time on the HAL clock.
//  - SampleSetSource is the one interface every backend implements (F Prime
//    style: real and test-double implementations chosen at build time):
//      AdcSampleSetSource (here, freestanding: any AdcPort, e.g. Mcp3208 over the
//      DPU's pins or over libgpiod), ReplaySource and SimulatedSource (host).
//  - acquire() never throws and never allocates; false means no sample set
//    (the end of a replay).
//  - Names: a sample set is not a frame. In ascorr "frame" means a reference
//    frame (q_chu_icrf, StateFrame) or, in ascorr_link/frame.hpp, a framed
//    link-protocol message. Two older interfaces keep the word for a sample
//    set, unchanged because they are the command line and the board
//    configuration file: `ascorr thermistors --frames N` acquires N sample
//    sets, and a channel's stuck_frames counts sample sets.
#pragma once

#include <cstdint>
#include "interface.hpp"

#include "channel_config.hpp"
#include "clock.hpp"
#include "faults.hpp"
#include "mcp3208.hpp"
#include "sampler.hpp"

namespace ascorr::hal {

enum class SampleKind : std::uint8_t { kNone = 0, kCounts, kCelsius };

template <typename T>
struct ChannelSample {
    SampleKind kind;
    std::uint16_t counts;  // kCounts: median of the samples
    std::uint16_t spread;  // kCounts: inner-half range of the samples
    T celsius;             // kCelsius
    FaultBits faults;      // device-level faults (kBus)
};

template <typename T>
struct SampleSet {
    std::uint64_t t_us;
    ChannelSample<T> channel[kMaxChannels];
};

template <typename T>
class SampleSetSource : private Interface {
public:
    virtual ~SampleSetSource() = default;
    virtual bool acquire(SampleSet<T>& samples) noexcept = 0;
};

// Reads every configured channel through an ADC with the sampler's settle
// time, sample count and robust average. Time of the sample set: its start.
template <typename T>
class AdcSampleSetSource final : public SampleSetSource<T> {
public:
    AdcSampleSetSource(AdcPort& adc, Clock& clock, const AcquisitionConfig<T>& config) noexcept
        : adc_(adc), clock_(clock), config_(config) {}

    bool acquire(SampleSet<T>& samples) noexcept override {
        samples.t_us = clock_.now_us();
        for (std::uint8_t i = 0; i < kMaxChannels; ++i) {
            ChannelSample<T>& s = samples.channel[i];
            s = {SampleKind::kNone, 0U, 0U, T{}, 0U};
            if (i >= config_.channels) {
                continue;
            }
            const RobustSample r = sample_channel(adc_, clock_, config_.sampler, config_.channel[i].adc_channel);
            s.kind = SampleKind::kCounts;
            s.counts = r.counts;
            s.spread = r.spread;
            s.faults = r.faults;
        }
        return true;
    }

private:
    AdcPort& adc_;
    Clock& clock_;
    const AcquisitionConfig<T>& config_;
};

}  // namespace ascorr::hal
