// The libgpiod backend at the libgpiod API boundary, against the scripted
// double (gpiod_double.cpp, linked instead of libgpiodcxx): line requests,
// the MCP3208 bit stream as the chip sees it, faults on the bus; then the
// whole path from ADC counts to a corrected attitude.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <gpiod.hpp>
#include <string>
#include <system_error>

#include "ascorr_hal/acquisition.hpp"
#include "ascorr_hal_linux/gpiod_backend.hpp"
#include "ascorr_host/formats/model_csv.hpp"
#include "gpiod_double.hpp"
#include "hal_support.hpp"
#include "test_support.hpp"

namespace ascorr::test {
namespace {

namespace fault = hal::fault;
using gpiod_double::Call;

hal::HalConfig board() {
    hal::HalConfig c;
    c.acquisition = swarm_config();
    c.gpio = {"gpiochip0", 8, 11, 10, 9, 5};
    return c;
}

TEST(HalGpiod, RequestsTheFourLinesAsTheWiringSaysAndReleasesThem) {
    gpiod_double::reset({});
    {
        hal::GpiodPins pins(board().gpio);
        const auto& calls = gpiod_double::calls();
        ASSERT_GE(calls.size(), 1U);
        EXPECT_EQ(calls[0].kind, Call::kOpen);
        EXPECT_EQ(calls[0].consumer, "gpiochip0");
        struct Expect {
            unsigned offset;
            int type;
            int initial;
        };
        const Expect want[4] = {{8, gpiod::line_request::DIRECTION_OUTPUT, 1},   // CS idle high
                                {11, gpiod::line_request::DIRECTION_OUTPUT, 0},  // CLK idle low
                                {10, gpiod::line_request::DIRECTION_OUTPUT, 0},  // MOSI
                                {9, gpiod::line_request::DIRECTION_INPUT, 0}};   // MISO
        int found = 0;
        for (const Call& c : calls) {
            if (c.kind != Call::kRequest) {
                continue;
            }
            ASSERT_LT(found, 4);
            EXPECT_EQ(c.offset, want[found].offset);
            EXPECT_EQ(c.request_type, want[found].type);
            if (want[found].type == gpiod::line_request::DIRECTION_OUTPUT) {
                EXPECT_EQ(c.value, want[found].initial) << c.offset;
            }
            EXPECT_EQ(c.consumer, "ascorr");
            ++found;
        }
        EXPECT_EQ(found, 4);
        EXPECT_EQ(gpiod_double::level(8), 1);
        EXPECT_EQ(gpiod_double::level(11), 0);
    }
    for (unsigned o : {8U, 11U, 10U, 9U}) {
        EXPECT_FALSE(gpiod_double::requested(o)) << o;
    }
}

TEST(HalGpiod, MissingChipOrLineIsAnErrorNamingIt) {
    gpiod_double::reset({});
    hal::GpioWiring w = board().gpio;
    w.chip = "gpiochip7";
    const auto refusal = [&w] { hal::GpiodPins pins(w); };
    const std::string no_chip = thrown_by<std::system_error>(refusal, "no exception");
    EXPECT_NE(no_chip.find("gpiochip7"), std::string::npos) << no_chip;
    gpiod_double::reset({});
    w = board().gpio;
    w.miso = 40;  // the scripted chip has 32 lines
    const std::string no_line = thrown_by<std::exception>(refusal, "no exception");
    EXPECT_NE(no_line.find("gpiochip0: line 40 (MISO)"), std::string::npos) << no_line;
    gpiod_double::reset({});
    {
        hal::GpiodPins first(board().gpio);  // a second user of the same lines
        try {
            hal::GpiodPins second(board().gpio);
            FAIL() << "no exception";
        } catch (const std::system_error& e) {
            EXPECT_NE(std::string(e.what()).find("gpiochip0: line 8 (CS)"), std::string::npos) << e.what();
        }
    }
}

TEST(HalGpiod, ConversionBitStreamAsTheChipSeesIt) {
    gpiod_double::Script s;
    s.counts = [](unsigned ch, unsigned) { return static_cast<std::uint16_t>(0xA5C ^ (ch * 0x111U)); };
    gpiod_double::reset(s);
    hal::ManualClock clock(0);
    hal::GpiodPins pins(board().gpio);
    hal::Mcp3208 adc(pins, clock, 5U);
    for (std::uint8_t ch = 0; ch < 8; ++ch) {
        std::uint16_t counts = 0;
        ASSERT_TRUE(adc.convert(ch, counts));
        EXPECT_EQ(counts, 0xA5C ^ (ch * 0x111U)) << int(ch);
    }
    const auto& conv = gpiod_double::conversions();
    ASSERT_EQ(conv.size(), 8U);
    for (unsigned ch = 0; ch < 8; ++ch) {
        EXPECT_TRUE(conv[ch].single_ended);
        EXPECT_EQ(conv[ch].channel, ch);
        EXPECT_EQ(conv[ch].rising_clocks, 19U);
        EXPECT_EQ(conv[ch].miso_reads_clk_low, 0U);
    }
    EXPECT_TRUE(gpiod_double::protocol_errors().empty()) << gpiod_double::protocol_errors().front();
    // Idle state after the conversions: deselected, clock low.
    EXPECT_EQ(gpiod_double::level(8), 1);
    EXPECT_EQ(gpiod_double::level(11), 0);
    // 19 clocks of two 5 µs halves per conversion, on the injected clock.
    EXPECT_EQ(clock.now_us(), 8U * 19U * 10U);
    // MISO read 13 times per conversion (null bit + 12), never written.
    int reads = 0;
    for (const Call& c : gpiod_double::calls()) {
        reads += c.kind == Call::kGet && c.offset == 9U ? 1 : 0;
        EXPECT_FALSE(c.kind == Call::kSet && c.offset == 9U);
    }
    EXPECT_EQ(reads, 8 * 13);
}

TEST(HalGpiod, SampleSetSourceSettlesAndTakesTheMedianPerChannel) {
    gpiod_double::Script s;
    // Conversion 0 on each channel is the discarded settling one (far off);
    // then 9 samples with one glitch.
    s.counts = [](unsigned ch, unsigned i) {
        if (i == 0) {
            return std::uint16_t{5};
        }
        if (i == 4) {
            return std::uint16_t{4000};
        }
        return static_cast<std::uint16_t>(1000U + 100U * ch + (i % 2U));
    };
    gpiod_double::reset(s);
    const hal::HalConfig cfg = board();
    hal::ManualClock clock(1000000U);
    hal::GpiodSampleSetSource src(cfg, clock);
    hal::SampleSet<double> f{};
    ASSERT_TRUE(src.acquire(f));
    EXPECT_EQ(f.t_us, 1000000U);
    for (unsigned ch = 0; ch < 8; ++ch) {
        EXPECT_EQ(f.channel[ch].kind, hal::SampleKind::kCounts);
        EXPECT_EQ(f.channel[ch].faults, 0U);
        EXPECT_EQ(f.channel[ch].counts, 1000U + 100U * ch + 1U) << ch;  // median of 1000,1001,… and 4000
        EXPECT_LE(f.channel[ch].spread, 1U);
    }
    EXPECT_EQ(gpiod_double::conversions().size(), 8U * 10U);
    // Settle 2 ms per channel plus 10 conversions × 19 clocks × 10 µs.
    EXPECT_EQ(clock.now_us() - 1000000U, 8U * (2000U + 10U * 190U));
    EXPECT_TRUE(gpiod_double::protocol_errors().empty());
}

TEST(HalGpiod, AbsentAdcIsABusFaultNotZeroCounts) {
    gpiod_double::Script s;
    s.device_present = false;  // DOUT pulled up: the null bit reads 1
    gpiod_double::reset(s);
    hal::ManualClock clock(0);
    hal::GpiodSampleSetSource src(board(), clock);
    hal::SampleSet<double> f{};
    ASSERT_TRUE(src.acquire(f));
    hal::TemperatureAcquisition<double> acq(board().acquisition);
    acq.update(f);
    for (std::uint8_t ch = 0; ch < 8; ++ch) {
        EXPECT_EQ(f.channel[ch].faults, fault::kBus);
        EXPECT_EQ(acq.channel(ch, 0U).faults, fault::kBus);
    }
    EXPECT_FALSE(acq.head(0, 0U).temperatures.t_chu.valid);
}

TEST(HalGpiod, LineIoErrorIsABusFaultAndTheBusIsReleased) {
    gpiod_double::Script s;
    s.failing_outputs = {10U};  // MOSI cannot be driven
    gpiod_double::reset(s);
    hal::ManualClock clock(0);
    hal::GpiodPins pins(board().gpio);
    hal::Mcp3208 adc(pins, clock, 0U);
    std::uint16_t counts = 0;
    EXPECT_FALSE(adc.convert(3, counts));
    EXPECT_EQ(gpiod_double::level(8), 1);  // CS deselected even so
    EXPECT_EQ(gpiod_double::level(11), 0);
}

// ---- the whole path: counts → acquisition → voting → HeadTemperatures → core ----

struct PathResult {
    CorrectedSolution<double> out;
    CorrectedSolution<double> reference;  // the same solution with the exact temperatures
};

// Serves counts for the record's temperatures through the board's dividers,
// with an optional channel forced to a fixed count (a fault on the wire).
PathResult run_path(const host::SolutionRecord& rec, const ThermalModel<double>& model, int faulty_channel = -1,
                    std::uint16_t faulty_counts = 0, int second_faulty = -1) {
    const hal::HalConfig cfg = board();
    double truth[8];
    for (int i = 0; i < 3; ++i) {
        truth[i] = rec.temperature[1] + 0.05 * (i - 1);      // THT00029/57/87
        truth[3 + i] = rec.temperature[2] + 0.05 * (i - 1);  // THT00032/60/90
    }
    truth[6] = rec.temperature[0];
    truth[7] = rec.temperature[0];
    gpiod_double::Script s;
    s.counts = [&](unsigned ch, unsigned) {
        if (static_cast<int>(ch) == faulty_channel || static_cast<int>(ch) == second_faulty) {
            return faulty_counts;
        }
        return counts_at(cfg.acquisition.channel[ch], truth[ch]);
    };
    gpiod_double::reset(s);
    hal::ManualClock clock(10000000U);
    hal::GpiodSampleSetSource src(cfg, clock);
    hal::TemperatureAcquisition<double> acq(cfg.acquisition);
    EXPECT_TRUE(acq.poll(src));
    const hal::HeadAcquisition<double> h = acq.head(rec.head, clock.now_us());

    SolutionInput<double> in{rec.q_chu_icrf, rec.head, h.temperatures, {{0.0, 0.0, 0.0}, 1.0, false}};
    const CorrectionConfig<double> ccfg{false, &model};
    PathResult r{correct_solution(in, ccfg), {}};
    r.out.status = hal::merge_status(r.out.status, h);
    in.temperatures = {{rec.temperature[0], true}, {rec.temperature[1], true}, {rec.temperature[2], true}};
    r.reference = correct_solution(in, ccfg);
    return r;
}

TEST(HalPath, CountsToCorrectedAttitudeMatchesExactTemperatures) {
    std::string storage;
    const auto rows = read_records(data_path("solutions.csv"), storage);
    const ThermalModel<double> model = host::to_core<double>(host::read_model_file(data_path("model_table2.csv")));
    double worst = 0.0;
    int used = 0;
    for (const auto& rec : rows) {
        if (rec.head > 1 || !(rec.temperature_present[0] && rec.temperature_present[1] && rec.temperature_present[2])) {
            continue;  // the board carries CHU_A and CHU_B
        }
        const PathResult r = run_path(rec, model);
        EXPECT_EQ(r.out.status, status::kThermalApplied) << rec.line;
        EXPECT_EQ(r.reference.status, status::kThermalApplied);
        worst = std::max(worst, angle_arcsec(r.out.q_chu_icrf, r.reference.q_chu_icrf));
        ++used;
    }
    ASSERT_GT(used, 0);
    std::printf("[measured] counts -> corrected attitude vs exact temperatures: max %.4f arcsec over %d solutions\n",
                worst, used);
    EXPECT_LT(worst, 0.1);
}

TEST(HalPath, OneOpenTripletMemberIsOutvotedAndTheCorrectionStillApplies) {
    std::string storage;
    const auto rows = read_records(data_path("solutions.csv"), storage);
    const ThermalModel<double> model = host::to_core<double>(host::read_model_file(data_path("model_table2.csv")));
    const host::SolutionRecord& rec = rows.front();
    ASSERT_EQ(rec.head, 0U);
    const PathResult r = run_path(rec, model, 1, 4095U);  // THT00057 open
    EXPECT_EQ(r.out.status, status::kThermalApplied);
    EXPECT_LT(angle_arcsec(r.out.q_chu_icrf, r.reference.q_chu_icrf), 0.1);
}

TEST(HalPath, EveryFaultThatRemovesATemperatureWithholdsTheCorrection) {
    std::string storage;
    const auto rows = read_records(data_path("solutions.csv"), storage);
    const ThermalModel<double> model = host::to_core<double>(host::read_model_file(data_path("model_table2.csv")));
    const host::SolutionRecord& rec = rows.front();
    struct Case {
        const char* what;
        int ch;
        int ch2;
        std::uint16_t counts;
    };
    const Case cases[] = {{"CHU_A open", 6, -1, 4095U},
                          {"CHU_A shorted", 6, -1, 0U},
                          {"two of THT00029/57/87 open", 0, 2, 4095U},
                          {"two of THT00032/60/90 shorted", 3, 4, 0U},
                          {"CHU_A at 95 degC (out of range)", 6, -1, counts_at(board().acquisition.channel[6], 95.0)}};
    for (const Case& c : cases) {
        const PathResult r = run_path(rec, model, c.ch, c.counts, c.ch2);
        EXPECT_EQ(r.out.status, status::kNoTemperature | status::kTemperatureInvalid) << c.what;
        EXPECT_LT(angle_arcsec(r.out.q_chu_icrf, rec.q_chu_icrf), 1e-6) << c.what;  // attitude untouched
    }
}

}  // namespace
}  // namespace ascorr::test
