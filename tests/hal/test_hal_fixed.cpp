// The fixed-point thermistor path (hal/include/ascorr_hal/fixed_thermistor.hpp)
// against the floating one: the table on every ADC code (against the float
// conversion and against an independent double evaluation of
// Steinhart–Hart), open/short on every code, and the same count streams
// (recorded and simulated, every fault class injected) through both paths:
// the same fault bits, the same validity, the voted temperatures within the
// conversion bound.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "ascorr_hal/acquisition.hpp"
#include "ascorr_hal/fixed_thermistor.hpp"
#include "ascorr_hal_linux/config_file.hpp"
#include "ascorr_hal_linux/replay_source.hpp"
#include "ascorr_hal_linux/simulated_source.hpp"
#include "hal_support.hpp"
#include "test_support.hpp"

namespace ascorr::test {
namespace {

namespace fault = hal::fault;

const std::string kExamples = ASCORR_HAL_EXAMPLES;
constexpr double kConversionBoundC = 0.005;  // the fixed path adds at most this to the float conversion

double to_c(QCelsius x) {
    return static_cast<double>(x.raw) / 1048576.0;
}

// Both paths of one floating configuration: its float acquisition and the
// fixed-point one derived from it (one table per channel).
struct Paths {
    explicit Paths(const hal::AcquisitionConfig<double>& d) : f(to_float(d)) {
        const hal::CountsTable* ptr[hal::kMaxChannels] = {};
        for (std::uint8_t i = 0; i < hal::kMaxChannels; ++i) {
            tables[i] = hal::make_counts_table(f.channel[i]);
            ptr[i] = &tables[i];
        }
        q = hal::fixed_acquisition(f, ptr);
        float_acq = std::make_unique<hal::TemperatureAcquisition<float>>(f);
        fixed_acq = std::make_unique<hal::TemperatureAcquisition<QCelsius>>(q);
    }
    hal::AcquisitionConfig<float> f;
    hal::CountsTable tables[hal::kMaxChannels]{};
    hal::AcquisitionConfig<QCelsius> q{};
    std::unique_ptr<hal::TemperatureAcquisition<float>> float_acq;
    std::unique_ptr<hal::TemperatureAcquisition<QCelsius>> fixed_acq;
};

template <typename T>
hal::SampleSet<T> convert_sample_set(const hal::SampleSet<double>& in) {
    hal::SampleSet<T> out{};
    out.t_us = in.t_us;
    for (std::uint8_t i = 0; i < hal::kMaxChannels; ++i) {
        const hal::ChannelSample<double>& s = in.channel[i];
        T c{};
        if constexpr (std::is_same_v<T, QCelsius>) {
            c = hal::celsius_sample(s.celsius);
        } else {
            c = static_cast<T>(s.celsius);
        }
        out.channel[i] = {s.kind, s.counts, s.spread, c, s.faults};
    }
    return out;
}

// What a run of sample sets through both paths showed.
struct Comparison {
    int sample_sets = 0;
    int mismatches = 0;
    hal::FaultBits seen = 0;  // every fault bit of a channel or a voted value, on either path
    double worst_voted_c = 0.0;
    int voted_compared = 0;
};

void compare_sample_set(Paths& p, const hal::SampleSet<double>& samples, Comparison& cmp, const std::string& what) {
    p.float_acq->update(convert_sample_set<float>(samples));
    p.fixed_acq->update(convert_sample_set<QCelsius>(samples));
    ++cmp.sample_sets;
    const std::uint64_t now = samples.t_us;
    for (std::uint8_t i = 0; i < p.f.channels; ++i) {
        const hal::ChannelReading<float> a = p.float_acq->channel(i, now);
        const hal::ChannelReading<QCelsius> b = p.fixed_acq->channel(i, now);
        cmp.seen |= a.faults;
        if (a.faults != b.faults) {
            ++cmp.mismatches;
            ADD_FAILURE() << what << " t_us " << now << " channel " << p.f.channel[i].name << ": float faults "
                          << a.faults << " (" << a.celsius << " °C, counts " << a.counts << "), fixed " << b.faults
                          << " (" << to_c(b.celsius) << " °C)";
        }
    }
    for (std::uint8_t r = 1; r < hal::kRoleCount; ++r) {
        const auto role = static_cast<hal::Role>(r);
        hal::ChannelReading<float> ma[hal::kMaxVoters];
        hal::ChannelReading<QCelsius> mb[hal::kMaxVoters];
        const hal::VotedTemperature<float> a = p.float_acq->role(role, now, ma);
        const hal::VotedTemperature<QCelsius> b = p.fixed_acq->role(role, now, mb);
        cmp.seen |= a.faults;
        bool same = a.faults == b.faults && a.valid() == b.valid() && a.agreeing == b.agreeing;
        for (std::uint8_t k = 0; k < a.members; ++k) {
            cmp.seen |= ma[k].faults;
            same = same && ma[k].faults == mb[k].faults;
        }
        if (a.valid() && b.valid()) {
            const double d = std::fabs(static_cast<double>(a.celsius) - to_c(b.celsius));
            cmp.worst_voted_c = std::max(cmp.worst_voted_c, d);
            ++cmp.voted_compared;
            same = same && d <= kConversionBoundC;
        }
        if (!same) {
            ++cmp.mismatches;
            ADD_FAILURE() << what << " t_us " << now << " role " << hal::kRoleNames[r] << ": float " << a.faults << " "
                          << a.celsius << " °C, fixed " << b.faults << " " << to_c(b.celsius) << " °C";
        }
    }
    for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
        const hal::HeadAcquisition<float> a = p.float_acq->head(h, now);
        const hal::HeadAcquisition<QCelsius> b = p.fixed_acq->head(h, now);
        if (a.status_bits() != b.status_bits() || a.temperatures.t_029.valid != b.temperatures.t_029.valid ||
            a.temperatures.t_032.valid != b.temperatures.t_032.valid ||
            a.temperatures.t_chu.valid != b.temperatures.t_chu.valid) {
            ++cmp.mismatches;
            ADD_FAILURE() << what << " t_us " << now << " head " << int{h} << ": status " << a.status_bits() << " vs "
                          << b.status_bits();
        }
    }
}

// The Swarm boom channel of the firmware and of board.cfg.
hal::ChannelConfig<float> boom_channel() {
    return to_float(swarm_config()).channel[0];
}

double double_sh(const hal::ChannelConfig<float>& c, std::uint16_t code) {
    const double x = static_cast<double>(code) / c.divider.levels;
    const auto rf = static_cast<double>(c.divider.r_fixed);
    const double r = c.divider.thermistor_low ? rf * x / (1.0 - x) : rf * (1.0 - x) / x;
    const double l = std::log(r);
    return 1.0 / (static_cast<double>(c.sh.a) + static_cast<double>(c.sh.b) * l +
                  static_cast<double>(c.sh.c) * l * l * l) -
           273.15;
}

struct CodeSweep {
    int codes_in_range = 0;     // codes whose float temperature is within [t_min, t_max]
    double worst_vs_float = 0;  // °C
    double worst_vs_double = 0;
    double worst_float_vs_double = 0;  // the float conversion's own error
    int fault_mismatches = 0;          // codes where open/short differ (every code 0 … 0xFFFF)
};

// Every code through the float conversion and the table.
CodeSweep sweep(const hal::ChannelConfig<float>& fc, const hal::CountsTable& table) {
    const hal::ChannelConfig<QCelsius> qc = hal::fixed_channel(fc, &table);
    CodeSweep s;
    for (std::uint32_t code = 0; code <= 0xFFFFU; ++code) {
        const auto c16 = static_cast<std::uint16_t>(code);
        hal::ChannelReading<float> a{NAN, NAN, 0U, 0U, 0U};
        hal::ChannelReading<QCelsius> b{hal::TemperatureMath<QCelsius>::none(), {}, 0U, 0U, 0U};
        const bool ta = hal::TemperatureMath<float>::convert_counts(fc, c16, 0U, a);
        const bool tb = hal::TemperatureMath<QCelsius>::convert_counts(qc, c16, 0U, b);
        if (ta != tb || a.faults != b.faults) {
            ++s.fault_mismatches;
            continue;
        }
        if (!ta || !(a.celsius >= fc.t_min && a.celsius <= fc.t_max)) {
            continue;
        }
        ++s.codes_in_range;
        s.worst_vs_float = std::max(s.worst_vs_float, std::fabs(to_c(b.celsius) - static_cast<double>(a.celsius)));
        s.worst_vs_double = std::max(s.worst_vs_double, std::fabs(to_c(b.celsius) - double_sh(fc, c16)));
        s.worst_float_vs_double =
            std::max(s.worst_float_vs_double, std::fabs(static_cast<double>(a.celsius) - double_sh(fc, c16)));
    }
    return s;
}

TEST(HalFixed, TableOnEveryCodeWithinTheBoundOfTheFloatConversion) {
    const hal::ChannelConfig<float> low = boom_channel();
    hal::ChannelConfig<float> high = low;  // the other divider orientation
    high.divider.thermistor_low = false;
    for (const hal::ChannelConfig<float>& fc : {low, high}) {
        const hal::CountsTable table = hal::make_counts_table(fc);
        ASSERT_TRUE(table.ok);
        const CodeSweep s = sweep(fc, table);
        std::printf(
            "divider %s: %u breakpoints, table error %.5f °C (built), codes in [t_min, t_max] %d, "
            "|fixed - float| <= %.5f °C, |fixed - double| <= %.5f °C, |float - double| <= %.6f °C\n",
            fc.divider.thermistor_low ? "low" : "high", static_cast<unsigned>(table.n),
            table.worst_error_raw / 1048576.0, s.codes_in_range, s.worst_vs_float, s.worst_vs_double,
            s.worst_float_vs_double);
        EXPECT_EQ(s.fault_mismatches, 0);   // open and short on the same codes, all 65536
        EXPECT_GT(s.codes_in_range, 3000);  // the whole valid range was swept
        EXPECT_LE(s.worst_vs_float, kConversionBoundC);
        EXPECT_LE(s.worst_vs_double, hal::kTableBudgetC + 1e-6);
        EXPECT_LE(table.worst_error_raw, static_cast<std::int32_t>(hal::kTableBudgetC * 1048576.0));
    }
}

// Mutation check: a table built from slightly different coefficients (B
// off by 0.05 %) is caught by the same sweep, so the bound is not vacuous.
TEST(HalFixed, SweepCatchesAWrongTable) {
    const hal::ChannelConfig<float> fc = boom_channel();
    hal::ChannelConfig<float> wrong = fc;
    wrong.sh.b *= 1.0005F;
    hal::CountsTable table = hal::make_counts_table(wrong);
    ASSERT_TRUE(table.ok);
    // Force the mismatch past table_matches() (which would refuse it).
    table.curve.b = static_cast<double>(fc.sh.b);
    const CodeSweep s = sweep(fc, table);
    EXPECT_GT(s.worst_vs_float, kConversionBoundC);
}

TEST(HalFixed, TableIsChosenToItsChannel) {
    const hal::ChannelConfig<float> fc = boom_channel();
    hal::ChannelConfig<float> other = fc;
    other.t_max = 70.0F;
    const hal::CountsTable table = hal::make_counts_table(other);
    const hal::ChannelConfig<QCelsius> q = hal::fixed_channel(fc, &table);
    EXPECT_EQ(q.table, nullptr);  // not built from this channel: refused
    hal::ChannelReading<QCelsius> r{hal::TemperatureMath<QCelsius>::none(), {}, 0U, 0U, 0U};
    hal::ChannelCheck<QCelsius> check;
    const hal::ChannelSample<QCelsius> s{hal::SampleKind::kCounts, 2000U, 0U, {}, 0U};
    r = check.update(q, s, 1000U);
    EXPECT_EQ(r.faults, fault::kConversion);  // every reading, as a non-finite float conversion
}

// Bad coefficients: the float conversion is not finite, the table is refused;
// both flag kConversion.
TEST(HalFixed, BadCoefficientsAreConversionFaultsOnBothPaths) {
    hal::ChannelConfig<float> fc = boom_channel();
    fc.sh = {0.0F, 0.0F, 0.0F};
    const hal::CountsTable table = hal::make_counts_table(fc);
    EXPECT_FALSE(table.ok);
    const hal::ChannelConfig<QCelsius> q = hal::fixed_channel(fc, &table);
    hal::ChannelCheck<float> a;
    hal::ChannelCheck<QCelsius> b;
    const hal::ChannelReading<float> ra = a.update(fc, {hal::SampleKind::kCounts, 2000U, 0U, 0.0F, 0U}, 1000U);
    const hal::ChannelReading<QCelsius> rb = b.update(q, {hal::SampleKind::kCounts, 2000U, 0U, {}, 0U}, 1000U);
    EXPECT_EQ(ra.faults, fault::kConversion);
    EXPECT_EQ(rb.faults, fault::kConversion);
}

// A replayed temperature that is not a number: kConversion on both paths;
// a finite one beyond the limits: kOutOfRange on both.
TEST(HalFixed, ReplayedTemperaturesBeyondTheDomainOnBothPaths) {
    const hal::ChannelConfig<float> fc = boom_channel();
    const hal::CountsTable table = hal::make_counts_table(fc);
    const hal::ChannelConfig<QCelsius> q = hal::fixed_channel(fc, &table);
    const double values[] = {NAN, 500.0, -100.0, 12.5};
    const hal::FaultBits want[] = {fault::kConversion, fault::kOutOfRange, fault::kOutOfRange, 0U};
    for (std::size_t i = 0; i < 4; ++i) {
        hal::ChannelCheck<float> a;
        hal::ChannelCheck<QCelsius> b;
        const hal::ChannelReading<float> ra =
            a.update(fc, {hal::SampleKind::kCelsius, 0U, 0U, static_cast<float>(values[i]), 0U}, 1000U);
        const hal::ChannelReading<QCelsius> rb =
            b.update(q, {hal::SampleKind::kCelsius, 0U, 0U, hal::celsius_sample(values[i]), 0U}, 1000U);
        EXPECT_EQ(ra.faults, want[i]) << values[i];
        EXPECT_EQ(rb.faults, want[i]) << values[i];
    }
}

// The recorded example (counts and converted temperatures, an open member, a
// short and a gap) through both paths.
TEST(HalFixed, RecordedStreamsGiveTheSameFaultsAndVotes) {
    const hal::AcquisitionConfig<double> cfg = hal::read_config(kExamples + "/board.cfg").acquisition;
    Paths p(cfg);
    const std::unique_ptr<hal::ReplaySource> src = hal::ReplaySource::from_file(kExamples + "/replay.csv", cfg);
    Comparison cmp;
    hal::SampleSet<double> f{};
    while (src->acquire(f)) {
        compare_sample_set(p, f, cmp, "replay.csv");
    }
    std::printf("replay.csv: %d sample sets, %d voted values compared, worst |fixed - float| %.5f °C\n",
                cmp.sample_sets, cmp.voted_compared, cmp.worst_voted_c);
    EXPECT_EQ(cmp.mismatches, 0);
    EXPECT_GT(cmp.voted_compared, 0);
    EXPECT_NE(cmp.seen & fault::kOpen, 0U);
}

// A simulated mission stretch through the simulated MCP3208 (counts), with
// every fault class the acquisition knows injected, through both paths.
TEST(HalFixed, SimulatedStreamsWithEveryFaultClassGiveTheSameFaultsAndVotes) {
    const hal::AcquisitionConfig<double> cfg = hal::read_config(kExamples + "/board.cfg").acquisition;
    std::vector<hal::HistoryRow> history;
    for (int k = 0; k < 600; ++k) {
        const double t = 1000.0 + k;
        const double w = 0.01 * k;
        // Out of range (t_max 80 °C) on the CHU for 30 s; otherwise slow drifts
        // with steps of about 0.02–0.1 °C per second.
        const double chu = (k >= 400 && k < 430) ? 85.0 : 3.2 + 6.0 * std::sin(w);
        history.push_back({t, -1, chu, -9.5 + 4.0 * std::sin(0.7 * w), -19.8 + 2.5 * std::cos(0.5 * w)});
    }
    // From the start: CHU_B without samples (no data, then stale).
    const char* specs[] = {"CHU_B:drop:0:1030",
                           "THT00057:open:1050:1080",
                           "THT00087:short:1100:1130",
                           "THT00060:bus:1150:1170",
                           "THT00029:stuck:1200:1270",
                           "THT00090:offset:1280:1300:3",  // outvoted (3 °C off, tolerance 1 °C)
                           "THT00032:offset:1320:1321:8",  // a spike: rate
                           "THT00029:noise:1340:1360:200",
                           "CHU_A:drop:1480:1500",     // stale
                           "THT00032:open:1520:1540",  // with the next: T_032 without quorum
                           "THT00060:open:1520:1540"};
    std::vector<hal::InjectedFault> faults;
    for (const char* s : specs) {
        faults.push_back(hal::parse_fault(s, cfg));
    }
    hal::SimulatedSource src(cfg, hal::history_epochs("history", history), faults);
    Paths p(cfg);
    Comparison cmp;
    hal::SampleSet<double> f{};
    while (src.acquire(f)) {
        compare_sample_set(p, f, cmp, "simulated");
    }
    // The worked examples' temperatures as a history, without faults.
    hal::SimulatedSource examples(cfg, hal::read_history(data_path("solutions.csv")), {});
    Paths p2(cfg);
    while (examples.acquire(f)) {
        compare_sample_set(p2, f, cmp, "solutions.csv");
    }
    std::printf(
        "simulated + solutions.csv: %d sample sets, %d voted values compared, worst |fixed - float| %.5f °C, "
        "fault bits seen %#x\n",
        cmp.sample_sets, cmp.voted_compared, cmp.worst_voted_c, static_cast<unsigned>(cmp.seen));
    EXPECT_EQ(cmp.mismatches, 0);
    EXPECT_GT(cmp.voted_compared, 1000);
    // Every fault class occurred (kConversion: BadCoefficientsAreConversionFaultsOnBothPaths).
    const hal::FaultBits all = fault::kNoData | fault::kBus | fault::kOpen | fault::kShort | fault::kOutOfRange |
                               fault::kRate | fault::kStuck | fault::kStale | fault::kNoisy | fault::kOutvoted |
                               fault::kNoQuorum;
    EXPECT_EQ(cmp.seen & all, all) << "seen " << cmp.seen;
}

// The rate check in integers: the allowed change grows with the gap without
// overflow, even after years.
TEST(HalFixed, RateCheckAtLongGaps) {
    using M = hal::TemperatureMath<QCelsius>;
    const QCelsius rate = hal::celsius_sample(0.5);
    const QCelsius a = hal::celsius_sample(-60.0);
    const QCelsius b = hal::celsius_sample(80.0);
    EXPECT_FALSE(M::within_rate(rate, a, 0U, b, 279000000U));  // 140 °C in 279 s: too fast
    EXPECT_TRUE(M::within_rate(rate, a, 0U, b, 280000000U));   // exactly 0.5 °C/s
    EXPECT_TRUE(M::within_rate(rate, a, 0U, b, std::uint64_t{1} << 62));
    EXPECT_TRUE(M::within_rate(hal::celsius_sample(2047.0), a, 0U, b, ~std::uint64_t{0}));  // product overflows
}

}  // namespace
}  // namespace ascorr::test
