// HAL core (freestanding part): conversion accuracy against tabulated curves,
// the sampler's robust average, every fault class, voting, and what the
// correction core makes of each fault.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

#include "ascorr/ascorr.hpp"
#include "ascorr_hal/acquisition.hpp"
#include "ascorr_hal/sampler.hpp"
#include "ascorr_host/formats/model_csv.hpp"
#include "hal_support.hpp"

namespace ascorr::test {
namespace {

using hal::ChannelReading;
using hal::ChannelSample;
using hal::FaultBits;
using hal::SampleKind;
using hal::SampleSet;
namespace fault = hal::fault;

// ---- conversion accuracy ----------------------------------------------------

// Amphenol Thermometrics "Sensor Temperature Resistance Curves, Reference
// Guide" Rev. C (November 2014), Material Type 1 (DK, NK parts): Rt/R25 at
// −40 … 100 °C, four significant figures, as tabulated by the manufacturer.
struct TableRow {
    double celsius;
    double ratio;
};
constexpr TableRow kType1[] = {{-40, 33.36}, {-35, 24.11}, {-30, 17.61},  {-25, 12.99},  {-20, 9.681},  {-15, 7.281},
                               {-10, 5.525}, {-5, 4.229},  {0, 3.264},    {5, 2.539},    {10, 1.990},   {15, 1.571},
                               {20, 1.249},  {25, 1.0000}, {30, 0.8056},  {35, 0.6530},  {40, 0.5325},  {45, 0.4367},
                               {50, 0.3601}, {55, 0.2985}, {60, 0.2487},  {65, 0.2082},  {70, 0.1751},  {75, 0.1480},
                               {80, 0.1256}, {85, 0.1070}, {90, 0.09155}, {95, 0.07864}, {100, 0.06781}};

// Steinhart–Hart coefficients through three table points (Cramer's rule).
hal::SteinhartHart<double> fit_three(const TableRow& p, const TableRow& q, const TableRow& r, double r25) {
    const TableRow* rows[3] = {&p, &q, &r};
    double m[3][3];
    double y[3];
    for (int i = 0; i < 3; ++i) {
        const double l = std::log(rows[i]->ratio * r25);
        m[i][0] = 1.0;
        m[i][1] = l;
        m[i][2] = l * l * l;
        y[i] = 1.0 / (rows[i]->celsius + 273.15);
    }
    const auto det = [](double a[3][3]) {
        return a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
               a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
    };
    const double d = det(m);
    double out[3];
    for (int k = 0; k < 3; ++k) {
        double mk[3][3];
        for (int i = 0; i < 3; ++i) {
            for (int j = 0; j < 3; ++j) {
                mk[i][j] = j == k ? y[i] : m[i][j];
            }
        }
        out[k] = det(mk) / d;
    }
    return {out[0], out[1], out[2]};
}

TEST(HalConversion, SteinhartHartMatchesManufacturerTable) {
    // Fit on −30, 25 and 80 °C; check every tabulated point from −40 to 100 °C.
    const hal::SteinhartHart<double> sh = fit_three(kType1[2], kType1[13], kType1[24], 10000.0);
    double worst = 0.0;
    double worst_operating = 0.0;  // −30 … 60 °C, where the boom thermistors live
    for (const TableRow& row : kType1) {
        const double t = hal::celsius_from_resistance(sh, row.ratio * 10000.0);
        const double e = std::fabs(t - row.celsius);
        worst = std::max(worst, e);
        if (row.celsius >= -30.0 && row.celsius <= 60.0) {
            worst_operating = std::max(worst_operating, e);
        }
    }
    std::printf("[measured] Steinhart-Hart vs Amphenol Type 1 table: max %.4f degC (-40..100), %.4f degC (-30..60)\n",
                worst, worst_operating);
    EXPECT_LT(worst, 0.05);
    EXPECT_LT(worst_operating, 0.02);
}

TEST(HalConversion, TenK3A1CoefficientsMatchCampbellTable) {
    // Campbell Scientific 109SS manual, Table C-1 (10K3MCD1 thermistor): ohm at °C.
    const TableRow rows[] = {{-40, 336103.2}, {-30, 176804.8}, {-20, 97006.9}, {-10, 55303.9}, {0, 32650.9}};
    for (const TableRow& r : rows) {
        EXPECT_NEAR(hal::celsius_from_resistance(k10K3A1, r.ratio), r.celsius, 0.01) << r.celsius;
    }
    // 25 °C is the thermistor's nominal 10 kΩ.
    EXPECT_NEAR(hal::celsius_from_resistance(k10K3A1, 10000.0), 25.0, 0.01);
}

TEST(HalConversion, InverseSteinhartHartRoundTrips) {
    for (double t = -80.0; t <= 150.0; t += 0.37) {
        const double r = hal::resistance_from_celsius(k10K3A1, t);
        EXPECT_NEAR(hal::celsius_from_resistance(k10K3A1, r), t, 1e-9);
    }
}

// The 12-bit quantisation through the divider, in double and float, and its
// effect on the thermal model of Table 2 (Herceg et al. 2017).
TEST(HalConversion, QuantisationErrorAndItsEffectInArcsec) {
    const hal::ChannelConfig<double> c = channel("X", hal::Role::kT029, 0);
    const hal::Divider<float> df{true, 10000.0F, 4096U};
    const hal::SteinhartHart<float> shf{static_cast<float>(k10K3A1.a), static_cast<float>(k10K3A1.b),
                                        static_cast<float>(k10K3A1.c)};
    double worst = 0.0;
    double worst_float = 0.0;
    for (double t = -30.0; t <= 60.0; t += 0.01) {
        const std::uint16_t n = counts_at(c, t);
        const double back = hal::celsius_from_resistance(c.sh, hal::resistance_from_counts(c.divider, n));
        worst = std::max(worst, std::fabs(back - t));
        const float backf = hal::celsius_from_resistance(shf, hal::resistance_from_counts(df, n));
        worst_float = std::max(worst_float, std::fabs(static_cast<double>(backf) - back));
    }
    // Half an LSB. The 10 kΩ divider is least sensitive at the cold end:
    // at −30 °C (Rt ≈ 177 kΩ, x ≈ 0.95) one count is ≈ 0.075 °C.
    EXPECT_LT(worst, 0.04);
    EXPECT_LT(worst_float, 1e-3);

    // Worst-case angle error per head: each temperature off by e, signs adverse.
    const host::ModelFile m = host::read_model_file(std::string(ASCORR_TEST_DATA) + "/model_table2.csv");
    double worst_arcsec = 0.0;
    const double e = worst + worst_float;
    for (std::size_t h = 0; h < kMaxHeads; ++h) {
        if (!m.present[h]) {
            continue;
        }
        for (int axis = 0; axis < 3; ++axis) {
            const auto& k = m.coefficients[h][static_cast<std::size_t>(axis)];
            const double s = (std::fabs(k[1] - k[2] - k[3]) + std::fabs(k[2]) + std::fabs(k[3])) * e;
            worst_arcsec = std::max(worst_arcsec, s);
        }
    }
    std::printf(
        "[measured] 12-bit quantisation -30..60 degC: %.4f degC (float adds %.1e); Table-2 effect <= %.3f arcsec\n",
        worst, worst_float, worst_arcsec);
    EXPECT_LT(worst_arcsec, 0.25);
}

TEST(HalConversion, RailsAreOpenOrShortNotDivisionByZero) {
    const hal::Divider<double> low{true, 10000.0, 4096U};
    const hal::Divider<double> high{false, 10000.0, 4096U};
    EXPECT_EQ(hal::resistance_from_counts(low, 0U), 0.0);
    EXPECT_TRUE(std::isinf(hal::resistance_from_counts(low, 4096U)));
    EXPECT_TRUE(std::isinf(hal::resistance_from_counts(high, 0U)));
    EXPECT_EQ(hal::resistance_from_counts(high, 4096U), 0.0);
    EXPECT_NEAR(hal::resistance_from_counts(low, 2048U), 10000.0, 1e-9);
    EXPECT_NEAR(hal::resistance_from_counts(high, 2048U), 10000.0, 1e-9);
    EXPECT_TRUE(std::isnan(hal::celsius_from_resistance(k10K3A1, 0.0)));
    EXPECT_TRUE(std::isnan(hal::celsius_from_resistance(k10K3A1, std::numeric_limits<double>::infinity())));
}

// ---- sampler ------------------------------------------------------------------

class ScriptedAdc final : public hal::AdcPort {
public:
    std::uint16_t values[32] = {};
    int n = 0;
    int fail_at = -1;
    int calls = 0;
    std::uint8_t last_channel = 0xFF;
    bool convert(std::uint8_t ch, std::uint16_t& counts) noexcept override {
        last_channel = ch;
        const int i = calls++;
        if (i == fail_at) {
            return false;
        }
        counts = values[i % n];
        return true;
    }
};

TEST(HalSampler, SettlesDiscardsFirstAndTakesTheMedian) {
    ScriptedAdc adc;
    // First conversion (discarded) is wildly off: the input had not settled.
    const std::uint16_t v[10] = {100, 2000, 2001, 1999, 2000, 3900, 2002, 2000, 1998, 2001};
    std::copy(v, v + 10, adc.values);
    adc.n = 10;
    hal::ManualClock clock(0);
    const hal::RobustSample r = hal::sample_channel(adc, clock, {2000U, 9U, 100U}, 5U);
    EXPECT_EQ(adc.calls, 10);
    EXPECT_EQ(adc.last_channel, 5U);
    EXPECT_EQ(clock.now_us(), 2000U + 8U * 100U);  // settle once, 8 gaps
    EXPECT_EQ(r.counts, 2000U);                    // one glitch (3900) does not move the median
    EXPECT_LE(r.spread, 3U);                       // nor the inner-half spread
    EXPECT_EQ(r.faults, 0U);
}

TEST(HalSampler, AFailedConversionIsABusFault) {
    ScriptedAdc adc;
    adc.values[0] = 2000;
    adc.n = 1;
    adc.fail_at = 4;
    hal::ManualClock clock(0);
    EXPECT_EQ(hal::sample_channel(adc, clock, {0U, 9U, 0U}, 0U).faults, fault::kBus);
}

// ---- fault classes --------------------------------------------------------------

struct Rig {
    hal::AcquisitionConfig<double> cfg = swarm_config();
    hal::TemperatureAcquisition<double> acq{cfg};
    SampleSet<double> f{};
    std::uint64_t t = 1000000000U;

    // Every channel at its temperature as counts: one sample set at t
    // (commit() hands it to the acquisition).
    void fill(const std::array<double, 8>& temps, std::uint64_t dt_us = 1000000U) {
        t += dt_us;
        f.t_us = t;
        for (std::uint8_t i = 0; i < 8; ++i) {
            f.channel[i] = {SampleKind::kCounts, counts_at(cfg.channel[i], temps[i]), 1U, 0.0, 0U};
        }
    }
    void commit() { acq.update(f); }
    ChannelReading<double> ch(std::uint8_t i) const { return acq.channel(i, t); }
};

constexpr std::array<double, 8> kNominal = {-9.5, -9.45, -9.55, -19.8, -19.75, -19.85, 3.2, 15.8};

// The core never applies a thermal correction with the acquisition's result,
// and reports why.
void expect_thermal_withheld(const hal::HeadAcquisition<double>& h, StatusBits must) {
    ThermalModel<double> model{};
    model.head[0].present = true;
    model.head[0].gamma.c1 = 1e-5;
    SolutionInput<double> in{{0.5, 0.5, 0.5, 0.5}, 0U, h.temperatures, {{0.0, 0.0, 0.0}, 1.0, false}};
    const CorrectionConfig<double> cfg{false, &model};
    const CorrectedSolution<double> out = correct_solution(in, cfg);
    const StatusBits st = hal::merge_status(out.status, h);
    EXPECT_EQ(st & status::kThermalApplied, 0U);
    EXPECT_NE(st & status::kNoTemperature, 0U);
    EXPECT_EQ(st & must, must) << st;
    EXPECT_EQ(out.q_chu_icrf.w, 0.5);
    EXPECT_EQ(out.q_chu_icrf.x, 0.5);
}

TEST(HalFaults, NominalFramesAreValidAndTheCoreAppliesThem) {
    Rig r;
    r.fill(kNominal);
    r.commit();
    for (std::uint8_t i = 0; i < 8; ++i) {
        EXPECT_EQ(r.ch(i).faults, 0U) << int(i);
        EXPECT_NEAR(r.ch(i).celsius, kNominal[i], 0.03) << int(i);
    }
    const hal::HeadAcquisition<double> h = r.acq.head(0, r.t);
    EXPECT_TRUE(h.temperatures.t_chu.valid && h.temperatures.t_029.valid && h.temperatures.t_032.valid);
    EXPECT_EQ(h.status_bits(), 0U);
    EXPECT_NEAR(h.temperatures.t_029.value, -9.5, 0.03);  // the median of the triplet
    EXPECT_NEAR(h.temperatures.t_032.value, -19.8, 0.03);
}

TEST(HalFaults, NoData) {
    Rig r;
    r.fill(kNominal);
    r.f.channel[6].kind = SampleKind::kNone;  // CHU_A never sampled
    r.commit();
    EXPECT_EQ(r.ch(6).faults, fault::kNoData);
    const hal::HeadAcquisition<double> h = r.acq.head(0, r.t);
    EXPECT_FALSE(h.temperatures.t_chu.valid);
    EXPECT_EQ(h.faults_chu, fault::kNoData);
    expect_thermal_withheld(h, status::kTemperatureInvalid);
}

TEST(HalFaults, BusOpenShortNoisyEachFlagged) {
    Rig r;
    r.fill(kNominal);
    r.f.channel[0].faults = fault::kBus;
    r.f.channel[1].counts = 4095U;  // thermistor open (low side)
    r.f.channel[3].counts = 0U;     // shorted
    r.f.channel[6].spread = 40U;    // noisy
    r.commit();
    EXPECT_EQ(r.ch(0).faults, fault::kBus);
    EXPECT_EQ(r.ch(1).faults, fault::kOpen);
    EXPECT_EQ(r.ch(3).faults, fault::kShort);
    EXPECT_EQ(r.ch(6).faults, fault::kNoisy);
    EXPECT_TRUE(std::isnan(r.ch(1).celsius));
    // Two of the T029 triplet lost: no quorum; T032 still has two agreeing.
    const hal::HeadAcquisition<double> h = r.acq.head(0, r.t);
    EXPECT_FALSE(h.temperatures.t_029.valid);
    EXPECT_EQ(h.faults_029, fault::kNoQuorum | fault::kBus | fault::kOpen);
    EXPECT_TRUE(h.temperatures.t_032.valid);
    EXPECT_NEAR(h.temperatures.t_032.value, -19.8, 0.03);  // mean of the two survivors
    expect_thermal_withheld(h, status::kTemperatureInvalid);
}

TEST(HalFaults, OpenAndShortOnAHighSideDivider) {
    Rig r;
    r.cfg.channel[7].divider.thermistor_low = false;
    hal::TemperatureAcquisition<double> acq(r.cfg);
    r.fill(kNominal);
    r.f.channel[7].counts = 0U;
    acq.update(r.f);
    EXPECT_EQ(acq.channel(7, r.t).faults, fault::kOpen);
    r.fill(kNominal);
    r.f.channel[7].counts = 4095U;
    acq.update(r.f);
    EXPECT_EQ(acq.channel(7, r.t).faults, fault::kShort);
}

TEST(HalFaults, OutOfRange) {
    Rig r;
    std::array<double, 8> t = kNominal;
    t[6] = 95.0;  // above t_max = 80, still a plausible resistance
    r.fill(t);
    r.commit();
    EXPECT_EQ(r.ch(6).faults, fault::kOutOfRange);
    expect_thermal_withheld(r.acq.head(0, r.t), status::kTemperatureInvalid);
}

TEST(HalFaults, ConversionWithBadCoefficients) {
    Rig r;
    r.fill(kNominal);
    hal::AcquisitionConfig<double> bad = r.cfg;
    bad.channel[6].sh = {0.0, 0.0, 0.0};  // 1/T = 0
    hal::TemperatureAcquisition<double> acq(bad);
    acq.update(r.f);
    EXPECT_EQ(acq.channel(6, r.t).faults, fault::kConversion);
}

TEST(HalFaults, RateSpikeCostsOneReadingAndAStepIsAcceptedAfterOne) {
    Rig r;
    std::array<double, 8> t = kNominal;
    r.fill(t);
    r.commit();
    t[6] = 13.2;  // +10 °C in 1 s, max_rate 0.5 °C/s
    r.fill(t);
    r.commit();
    EXPECT_EQ(r.ch(6).faults, fault::kRate);
    expect_thermal_withheld(r.acq.head(0, r.t), status::kTemperatureInvalid);
    t[6] = 3.3;  // back: it was a spike
    r.fill(t);
    r.commit();
    EXPECT_EQ(r.ch(6).faults, 0U);
    t[6] = 8.3;  // a real step (e.g. after a heater switched) ...
    r.fill(t);
    r.commit();
    EXPECT_EQ(r.ch(6).faults, fault::kRate);
    t[6] = 8.4;  // ... confirmed by the next reading
    r.fill(t);
    r.commit();
    EXPECT_EQ(r.ch(6).faults, 0U);
    EXPECT_NEAR(r.ch(6).celsius, 8.4, 0.03);
}

TEST(HalFaults, StuckAfterIdenticalFramesAndRecovers) {
    Rig r;
    for (int k = 0; k < 4; ++k) {
        r.fill(kNominal);
        r.f.channel[6].spread = 0U;
        r.commit();
        EXPECT_EQ(r.ch(6).faults, 0U) << k;
    }
    r.fill(kNominal);
    r.f.channel[6].spread = 0U;
    r.commit();
    EXPECT_EQ(r.ch(6).faults, fault::kStuck);  // 5th identical, noise-free sample set
    expect_thermal_withheld(r.acq.head(0, r.t), status::kTemperatureInvalid);
    r.fill(kNominal);
    r.f.channel[6].spread = 1U;  // the ADC shows noise again
    r.commit();
    EXPECT_EQ(r.ch(6).faults, 0U);
    // A quiet but live channel (identical median, spread 1) is never stuck.
    for (int k = 0; k < 10; ++k) {
        r.fill(kNominal);
        r.commit();
    }
    EXPECT_EQ(r.ch(6).faults, 0U);
}

TEST(HalFaults, StaleWhenOldOrWhenTimeDoesNotAdvance) {
    Rig r;
    r.fill(kNominal);
    r.commit();
    const std::uint64_t t0 = r.t;
    EXPECT_EQ(r.acq.channel(6, t0 + 5000000U).faults, 0U);             // 5 s: still fresh
    EXPECT_EQ(r.acq.channel(6, t0 + 5000001U).faults, fault::kStale);  // older than stale_s
    const hal::HeadAcquisition<double> h = r.acq.head(0, t0 + 6000000U);
    EXPECT_EQ(h.faults_chu, fault::kStale);
    EXPECT_EQ(h.status_bits(), status::kNoTemperature | status::kStale);
    expect_thermal_withheld(h, status::kStale);
    // Samples stop (kNone) but the last reading is kept until it is stale.
    r.fill(kNominal);
    for (auto& s : r.f.channel) {
        s.kind = SampleKind::kNone;
    }
    r.commit();
    EXPECT_EQ(r.ch(6).faults, 0U);
    EXPECT_EQ(r.ch(6).t_us, t0);
    // A sample set whose time does not advance (replayed twice, frozen clock).
    r.fill(kNominal, 0U);
    r.commit();
    r.fill(kNominal, 0U);
    r.commit();
    EXPECT_EQ(r.ch(6).faults, fault::kStale);
}

// ---- voting ---------------------------------------------------------------------

ChannelReading<double> reading(double c, FaultBits f = 0U) {
    return {c, 1.0, 1U, f, 100U};
}

TEST(HalVoting, MedianOfThreeFlagsTheDisagreeingMember) {
    ChannelReading<double> m[3] = {reading(-9.5), reading(-3.0), reading(-9.6)};
    const hal::VotedTemperature<double> v = hal::vote(m, 3, 1.0, 2);
    EXPECT_TRUE(v.valid());
    EXPECT_EQ(v.celsius, -9.5);
    EXPECT_EQ(v.agreeing, 2U);
    EXPECT_EQ(m[1].faults, fault::kOutvoted);
    EXPECT_EQ(m[0].faults, 0U);
    EXPECT_EQ(m[2].faults, 0U);
}

TEST(HalVoting, ThreeAllDisagreeingHaveNoQuorum) {
    ChannelReading<double> m[3] = {reading(-9.5), reading(-3.0), reading(5.0)};
    const hal::VotedTemperature<double> v = hal::vote(m, 3, 1.0, 2);
    EXPECT_FALSE(v.valid());
    EXPECT_EQ(v.faults, fault::kNoQuorum);
    EXPECT_TRUE(std::isnan(v.celsius));
    EXPECT_EQ(m[0].faults, fault::kOutvoted);
    EXPECT_EQ(m[2].faults, fault::kOutvoted);
}

TEST(HalVoting, TwoValidAgreeingGiveTheirMeanAndDisagreeingGiveNothing) {
    ChannelReading<double> a[3] = {reading(-9.5), reading(0.0, fault::kOpen), reading(-9.7)};
    hal::VotedTemperature<double> v = hal::vote(a, 3, 1.0, 2);
    EXPECT_TRUE(v.valid());
    EXPECT_NEAR(v.celsius, -9.6, 1e-12);
    ChannelReading<double> b[3] = {reading(-9.5), reading(0.0, fault::kOpen), reading(-7.0)};
    v = hal::vote(b, 3, 1.0, 2);
    EXPECT_FALSE(v.valid());
    EXPECT_EQ(v.faults, fault::kNoQuorum | fault::kOpen);
}

TEST(HalVoting, OneSurvivorNeedsQuorumOne) {
    ChannelReading<double> m[3] = {reading(-9.5), reading(0.0, fault::kShort), reading(0.0, fault::kStale)};
    EXPECT_FALSE(hal::vote(m, 3, 1.0, 2).valid());
    EXPECT_EQ(hal::vote(m, 3, 1.0, 2).faults, fault::kNoQuorum | fault::kShort | fault::kStale);
    const hal::VotedTemperature<double> v = hal::vote(m, 3, 1.0, 1);
    EXPECT_TRUE(v.valid());
    EXPECT_EQ(v.celsius, -9.5);
}

TEST(HalVoting, ASingleChannelIsItsOwnValue) {
    ChannelReading<double> ok[1] = {reading(3.2)};
    EXPECT_EQ(hal::vote(ok, 1, 1.0, 2).celsius, 3.2);
    ChannelReading<double> bad[1] = {reading(0.0, fault::kOpen)};
    EXPECT_EQ(hal::vote(bad, 1, 1.0, 2).faults, fault::kOpen);
    EXPECT_EQ(hal::vote(bad, 0, 1.0, 2).faults, fault::kNoData);
}

TEST(HalVoting, AcquisitionFlagsTheOutvotedMemberAndKeepsTheMedian) {
    Rig r;
    std::array<double, 8> t = kNominal;
    t[2] = -4.0;  // THT00087 reads 5.5 °C warm (first sample set: no rate anchor yet)
    r.fill(t);
    r.commit();
    ChannelReading<double> members[3];
    std::uint8_t index[3];
    const hal::VotedTemperature<double> v = r.acq.role(hal::Role::kT029, r.t, members, index);
    EXPECT_TRUE(v.valid());
    EXPECT_NEAR(v.celsius, -9.45, 0.03);  // median of −9.5, −9.45, −4.0
    EXPECT_EQ(index[2], 2U);
    EXPECT_EQ(members[2].faults, fault::kOutvoted);
    EXPECT_EQ(members[0].faults, 0U);
}

TEST(HalStatus, MergeOnlyWhereTheCoreSkippedForTemperatures) {
    hal::HeadAcquisition<double> h{};
    h.faults_029 = fault::kOpen;
    h.faults_032 = fault::kStale;
    EXPECT_EQ(h.status_bits(), status::kNoTemperature | status::kTemperatureInvalid | status::kStale);
    EXPECT_EQ(hal::merge_status(status::kThermalApplied, h), status::kThermalApplied);
    EXPECT_EQ(hal::merge_status(status::kNoTemperature, h),
              status::kNoTemperature | status::kTemperatureInvalid | status::kStale);
}

}  // namespace
}  // namespace ascorr::test
