// The thermistor channel defaults exist once, in
// hal/include/ascorr_hal/channel_defaults.hpp. Every copy is derived from it
// or checked here against it: the board configuration's optional keys
// (config_file.cpp), the example hal/examples/board.cfg (text), the flight
// image's boom channels (firmware/app/boom_channels.hpp, float), and the HAL
// tests' Swarm layout (tests/hal/hal_support.hpp). A copy that drifts fails.
#include <gtest/gtest.h>

#include <cstdint>
#include <string>

#include "ascorr_hal/channel_defaults.hpp"
#include "ascorr_hal_linux/config_file.hpp"
#include "boom_channels.hpp"
#include "hal_support.hpp"

namespace ascorr::test {
namespace {

const std::string kExamples = ASCORR_HAL_EXAMPLES;

// The fields a channel takes from the defaults (all but name, role, input),
// with `stuck_frames` given separately: the copies that change it say why.
template <typename T>
std::string differences(const hal::ChannelConfig<T>& a, const hal::ChannelConfig<T>& d, std::uint16_t stuck) {
    std::string s;
    const auto note = [&](bool same, const char* field) { s += same ? "" : std::string(field) + " "; };
    note(a.divider.thermistor_low == d.divider.thermistor_low, "divider.thermistor_low");
    note(a.divider.r_fixed == d.divider.r_fixed, "divider.r_fixed");
    note(a.divider.levels == d.divider.levels, "divider.levels");
    note(a.sh.a == d.sh.a, "sh.a");
    note(a.sh.b == d.sh.b, "sh.b");
    note(a.sh.c == d.sh.c, "sh.c");
    note(a.r_open == d.r_open, "r_open");
    note(a.r_short == d.r_short, "r_short");
    note(a.t_min == d.t_min, "t_min");
    note(a.t_max == d.t_max, "t_max");
    note(a.max_rate == d.max_rate, "max_rate");
    note(a.stuck_frames == stuck, "stuck_frames");
    note(a.max_spread == d.max_spread, "max_spread");
    return s;
}

template <typename T>
std::string acquisition_differences(const hal::AcquisitionConfig<T>& a, const hal::AcquisitionConfig<T>& d,
                                    std::uint64_t stale_us) {
    std::string s;
    const auto note = [&](bool same, const char* field) { s += same ? "" : std::string(field) + " "; };
    note(a.sampler.settle_us == d.sampler.settle_us, "settle_us");
    note(a.sampler.samples == d.sampler.samples, "samples");
    note(a.sampler.gap_us == d.sampler.gap_us, "gap_us");
    note(a.stale_us == stale_us, "stale_us");
    note(a.vote_tolerance == d.vote_tolerance, "vote_tolerance");
    note(a.quorum == d.quorum, "quorum");
    return s;
}

TEST(HalDefaults, EveryCopyDerivesFromTheOneSource) {
    const hal::ChannelConfig<double> d = hal::default_channel<double>();
    const hal::AcquisitionConfig<double> da = hal::default_acquisition<double>();

    // The configuration file: a channel with only its required keys.
    const hal::HalConfig minimal =
        hal::parse_config("m.cfg", "channel name=T adc=0 role=t029 a=1.129241e-3 b=2.341077e-4 c=8.775468e-8\n");
    EXPECT_EQ(differences(minimal.acquisition.channel[0], d, d.stuck_frames), "");
    EXPECT_EQ(acquisition_differences(minimal.acquisition, da, da.stale_us), "");

    // The example file spells the curve and the acquisition out; it sets a
    // stuck check after 60 frames.
    const hal::HalConfig example = hal::read_config(kExamples + "/board.cfg");
    ASSERT_EQ(example.acquisition.channels, 8U);
    for (std::uint8_t i = 0; i < example.acquisition.channels; ++i) {
        EXPECT_EQ(differences(example.acquisition.channel[i], d, 60U), "") << example.acquisition.channel[i].name;
    }
    EXPECT_EQ(acquisition_differences(example.acquisition, da, da.stale_us), "");

    // The flight image (float): every boom channel, and the benchmark's eight;
    // its staleness limit is 3 s (three missed 1 Hz polls).
    const hal::ChannelConfig<float> df = hal::default_channel<float>();
    const hal::AcquisitionConfig<float> eight = app::boom::make_config(hal::kMaxChannels);
    for (std::uint8_t i = 0; i < hal::kMaxChannels; ++i) {
        EXPECT_EQ(differences(eight.channel[i], df, df.stuck_frames), "") << eight.channel[i].name;
    }
    EXPECT_EQ(acquisition_differences(app::boom::kFloatConfig, hal::default_acquisition<float>(), 3000000U), "");

    // The tests' Swarm layout, with a stuck check after 5 frames.
    const hal::AcquisitionConfig<double> swarm = swarm_config();
    for (std::uint8_t i = 0; i < swarm.channels; ++i) {
        EXPECT_EQ(differences(swarm.channel[i], d, 5U), "") << swarm.channel[i].name;
    }
    EXPECT_EQ(acquisition_differences(swarm, da, da.stale_us), "");

    // The one source is the 10K3A1 curve of the Campbell Scientific manual.
    EXPECT_EQ(d.sh.a, 1.129241e-3);
    EXPECT_EQ(d.sh.b, 2.341077e-4);
    EXPECT_EQ(d.sh.c, 8.775468e-8);
}

// Mutation check: the comparison sees a change of any field.
TEST(HalDefaults, TheComparisonSeesEveryField) {
    const hal::ChannelConfig<double> d = hal::default_channel<double>();
    int seen = 0;
    for (int field = 0; field < 13; ++field) {
        hal::ChannelConfig<double> m = d;
        switch (field) {
            case 0:
                m.divider.thermistor_low = !m.divider.thermistor_low;
                break;
            case 1:
                m.divider.r_fixed *= 1.0 + 1e-15;
                break;
            case 2:
                m.divider.levels = 1024U;
                break;
            case 3:
                m.sh.a *= 1.0 + 1e-15;
                break;
            case 4:
                m.sh.b *= 1.0 + 1e-15;
                break;
            case 5:
                m.sh.c *= 1.0 + 1e-15;
                break;
            case 6:
                m.r_open = 1.0e6;
                break;
            case 7:
                m.r_short = 99.0;
                break;
            case 8:
                m.t_min = -55.0;
                break;
            case 9:
                m.t_max = 85.0;
                break;
            case 10:
                m.max_rate = 1.0;
                break;
            case 11:
                m.stuck_frames = 7U;
                break;
            default:
                m.max_spread = 9U;
                break;
        }
        seen += differences(m, d, d.stuck_frames).empty() ? 0 : 1;
    }
    EXPECT_EQ(seen, 13);
    hal::AcquisitionConfig<double> a = hal::default_acquisition<double>();
    a.vote_tolerance = 0.5;
    EXPECT_NE(acquisition_differences(a, hal::default_acquisition<double>(), a.stale_us), "");
}

}  // namespace
}  // namespace ascorr::test
