// The bench's lag on board (issue 40): the lag stage (pipeline/head_lags.hpp)
// in double, float and Q30 against the host's lag of the same rows
// (lagged_temperatures.hpp, itself tested against a long-double filter in
// test_bench_lag.cpp), what it cannot lag, MODEL_UPLOAD's τ on the link, and
// `replay` of a lagged model on the loopback target against `ascorr correct`
// (the QEMU boards: test_replay_qemu.cpp). The mission is simulate's, its
// bench lagging by 900 s; the model is its truth with that lag.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <map>
#include <memory>
#include <random>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "ascorr/core/fixed_point.hpp"
#include "ascorr/nav/tt_time.hpp"
#include "ascorr/pipeline/head_lags.hpp"
#include "ascorr_host/correct/lagged_temperatures.hpp"
#include "ascorr_host/formats/model_csv.hpp"
#include "ascorr_host/link/link_client.hpp"
#include "ascorr_host/link/link_transport.hpp"
#include "ascorr_host/link/replay.hpp"
#include "ascorr_link/server.hpp"
#include "cli_run.hpp"
#include "corrected_files.hpp"
#include "lagged_models.hpp"
#include "restarting_target.hpp"
#include "test_support.hpp"

namespace ascorr::test {
namespace {

namespace fs = std::filesystem;

constexpr double kTauS = 900.0;

// The mission (0.3 days, an epoch a minute, bench lag 900 s) and two
// models made from its truth: m.csv as is, m_lag.csv with lag_s 900.
const fs::path& mission() {
    static const fs::path dir = [] {
        const fs::path d = scratch_dir("lag-on-board");
        EXPECT_EQ(run_in("simulate --days 0.3 --bench-lag 900 --out s.csv > /dev/null", d).exit_code, 0);
        write_truth_models(d, "900");
        return d;
    }();
    return dir;
}

std::vector<host::SolutionRecord> rows_of(const fs::path& file) {
    const std::string text = host::read_text_file(file.string());
    host::SolutionsReader reader(file.string(), text);
    std::vector<host::SolutionRecord> rows;
    for (host::SolutionRecord r; reader.next(r);) {
        rows.push_back(r);
    }
    return rows;
}

template <typename T>
HeadTemperatures<T> temperatures_of(const host::SolutionRecord& r) {
    const auto c = [](double x) { return ScalarTraits<T>::celsius(x); };
    return {{c(r.temperature[0]), r.temperature_present[0]},
            {c(r.temperature[1]), r.temperature_present[1]},
            {c(r.temperature[2]), r.temperature_present[2]}};
}

// The largest |lag stage in T − the host's double lag| over the rows' usable
// readings (°C); checks that validity agrees everywhere.
template <typename T>
double worst_against_host(const std::vector<host::SolutionRecord>& rows, const host::LaggedTemperatures& table,
                          std::size_t* moved = nullptr) {
    pipeline::HeadLags<T> lags;
    for (std::uint8_t h = 0; h < 3; ++h) {
        EXPECT_TRUE(lags.configure(h, kTauS));
    }
    double worst = 0.0;
    for (const host::SolutionRecord& rec : rows) {
        host::SolutionRecord want = rec;
        table.apply(want);
        TtTime t{};
        EXPECT_TRUE(tt_from_seconds(rec.t, t));
        HeadTemperatures<T> got = temperatures_of<T>(rec);
        lags.apply(rec.head, t.us, got);
        const TemperatureReading<T>* g[3] = {&got.t_chu, &got.t_029, &got.t_032};
        for (std::size_t k = 0; k < 3; ++k) {
            EXPECT_EQ(g[k]->valid, want.temperature_present[k]) << rec.line;
            if (!want.temperature_present[k]) {
                continue;
            }
            const double v = ScalarTraits<T>::to_double(g[k]->value);
            worst = std::max(worst, std::fabs(v - want.temperature[k]));
            if (moved != nullptr && std::fabs(want.temperature[k] - rec.temperature[k]) > 0.01) {
                ++*moved;
            }
        }
    }
    return worst;
}

// On board the rows come in time order, one at a time; the host's table is
// built over the whole file. Double takes the same steps: the same bits.
// Float and Q30 round as their formats do (test_temperature_lag.cpp: 3e-5 °C
// at 22 Hz) plus the readings' own rounding (Q30: 2⁻²¹ °C).
TEST(LagStage, EachScalarFollowsTheHostsLagOfTheSameRows) {
    const std::vector<host::SolutionRecord> rows = rows_of(mission() / "s.csv");
    const std::array<double, kMaxHeads> lag_s{kTauS, kTauS, kTauS, 0.0};
    const std::optional<host::LaggedTemperatures> table = host::lagged_temperatures(lag_s, host::rows_in(rows));
    ASSERT_TRUE(table.has_value());
    std::size_t moved = 0;
    EXPECT_EQ(worst_against_host<double>(rows, *table, &moved), 0.0);
    EXPECT_GT(moved, rows.size());  // the lag moves most readings by more than 0.01 °C
    EXPECT_LT(worst_against_host<float>(rows, *table), 1e-4);
    EXPECT_LT(worst_against_host<Q30>(rows, *table), 1e-4);
}

TEST(LagStage, WhatItCannotLagHasNoTemperatures) {
    pipeline::HeadLags<double> lags;
    EXPECT_FALSE(lags.configure(kMaxHeads, kTauS));
    EXPECT_FALSE(lags.configure(0, 0.5));
    EXPECT_FALSE(lags.lags(0));
    ASSERT_TRUE(lags.configure(0, 600.0));
    EXPECT_TRUE(lags.lags(0));
    EXPECT_FALSE(lags.lags(1));
    const HeadTemperatures<double> first{{20.0, true}, {21.0, true}, {22.0, true}};
    HeadTemperatures<double> x = first;
    lags.apply(0, 1'000'000, x);  // the first reading: L = T
    EXPECT_EQ(x.t_chu.value, 20.0);
    EXPECT_TRUE(x.t_chu.valid);
    // 60 s on: T1 lags its step of 1 °C; a NaN and a withheld reading stay
    // as they came, so the core says why it cannot use them.
    x = {{21.0, true}, {std::nan(""), true}, {30.0, false}};
    lags.apply(0, 61'000'000, x);
    const double l1 = 20.0 + (1.0 - std::exp(-0.1));
    EXPECT_NEAR(x.t_chu.value, l1, 1e-13);
    EXPECT_TRUE(std::isnan(x.t_029.value));
    EXPECT_TRUE(x.t_029.valid);
    EXPECT_EQ(x.t_032.value, 30.0);
    EXPECT_FALSE(x.t_032.valid);
    // The same time again: the state at that time, whatever the reading.
    x = {{25.0, true}, {21.0, true}, {22.0, true}};
    lags.apply(0, 61'000'000, x);
    EXPECT_NEAR(x.t_chu.value, l1, 1e-13);
    // Earlier than the head's last time, or no time: no lagged temperatures.
    x = first;
    lags.apply(0, 30'000'000, x);
    EXPECT_FALSE(x.t_chu.valid || x.t_029.valid || x.t_032.valid);
    x = first;
    lags.without_time(0, x);
    EXPECT_FALSE(x.t_chu.valid || x.t_029.valid || x.t_032.valid);
    // A head without a lag keeps its readings, timed or not.
    x = first;
    lags.apply(1, 30'000'000, x);
    lags.without_time(1, x);
    EXPECT_TRUE(x.t_chu.valid && x.t_029.valid && x.t_032.valid);
    EXPECT_EQ(x.t_chu.value, 20.0);
    // τ 0: the head lags no more.
    ASSERT_TRUE(lags.configure(0, 0.0));
    x = first;
    lags.apply(0, 30'000'000, x);
    EXPECT_TRUE(x.t_chu.valid);
    EXPECT_EQ(x.t_chu.value, 20.0);
}

TEST(LagStage, EveryHeadsLagAtOnce) {
    pipeline::HeadLags<double> lags;
    std::array<double, kMaxHeads> tau{};
    EXPECT_FALSE(pipeline::any_lagged(tau));
    EXPECT_TRUE(lags.configure_all(tau));
    EXPECT_FALSE(lags.any());
    tau[1] = 900.0;
    tau[kMaxHeads - 1] = 1800.0;
    EXPECT_TRUE(pipeline::any_lagged(tau));
    EXPECT_TRUE(lags.configure_all(tau));
    for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
        EXPECT_EQ(lags.lags(h), tau[h] != 0.0) << int{h};
    }
    // One refused τ: false, that head as it was, the others configured.
    std::array<double, kMaxHeads> bad{};
    bad[0] = 600.0;
    bad[1] = 0.5;
    EXPECT_FALSE(lags.configure_all(bad));
    EXPECT_TRUE(lags.lags(0));
    EXPECT_TRUE(lags.lags(1));
    EXPECT_FALSE(lags.lags(kMaxHeads - 1));
}

// MODEL_UPLOAD: τ after the words, only when the head lags.
TEST(LagLink, ModelUploadCarriesTheLagOnlyWhenTheHeadLags) {
    const ThermalModel<float> model = host::to_core<float>(host::read_model_file((mission() / "m.csv").string()));
    std::uint8_t p[link::kMaxPayload];
    const std::size_t plain = link::encode(link::ModelUpload<float>{1, model.head[1], 0.0}, p);
    link::ModelUpload<float> back{};
    ASSERT_TRUE(link::decode(p, plain, back));
    EXPECT_EQ(back.lag_s, 0.0);
    const std::size_t lagged = link::encode(link::ModelUpload<float>{1, model.head[1], 1234.5}, p);
    EXPECT_EQ(lagged, plain + 8);
    back.lag_s = 0.0;
    ASSERT_TRUE(link::decode(p, lagged, back));
    EXPECT_EQ(back.lag_s, 1234.5);
    EXPECT_EQ(std::memcmp(&back.model, &model.head[1], sizeof back.model), 0);
    // A τ out of range (0 included: a head without a lag sends none), or cut short.
    for (double bad : {0.0, 0.5, 86400.5, -900.0, std::nan("")}) {
        std::memcpy(p + plain, &bad, sizeof bad);  // little-endian, as the wire
        EXPECT_FALSE(link::decode(p, lagged, back)) << bad;
    }
    EXPECT_FALSE(link::decode(p, plain + 4, back));
}

// On the link: a lagged head's solution without a time has no lagged
// temperatures (status 8), another head's keeps its thermal stage; a restart
// while a head lags is an error, since the lag's state is lost with it.
TEST(LagLink, AnUntimedSolutionOfALaggedHeadHasNoTemperaturesAndARestartIsAnError) {
    const ThermalModel<float> model = host::to_core<float>(host::read_model_file((mission() / "m.csv").string()));
    RestartingTarget target(300);
    host::LoopbackTransport t(
        [&](const std::uint8_t* p, std::size_t n, const host::LoopbackTransport::Reply& r) { target.serve(p, n, r); });
    host::LinkClient<float> client(t, 1, 20);
    client.connect();
    client.upload_model(model, {kTauS, 0.0, 0.0, 0.0});
    client.set_velocity({{1e-4F, -2e-5F, 3e-5F}, 1.0F, true});
    const Quaternion<float> q{0.5F, 0.5F, 0.5F, 0.5F};
    for (std::uint8_t h = 0; h < 2; ++h) {
        client.set_temperatures(h, {{10.0F, true}, {-5.0F, true}, {-20.0F, true}});
        const link::SolutionOut<float> timed = client.correct(h, h, q, TtTime{5'000'000'000'000});
        EXPECT_EQ(timed.status, status::kAberrationApplied | status::kThermalApplied) << int{h};
        const link::SolutionOut<float> untimed =
            client.correct(10U + h, h, q, TtTime{0}, false, false, link::kCalibNoTime);
        EXPECT_EQ(untimed.status & status::kNoTemperature, h == 0 ? status::kNoTemperature : 0U) << int{h};
    }
    std::uint32_t id = 100;
    const auto run_on = [&] {
        for (int i = 0; i < 400; ++i, ++id) {
            client.set_temperatures(0, {{10.0F + static_cast<float>(i % 7), true}, {-5.0F, true}, {-20.0F, true}});
            (void)client.correct(id, 0, q, TtTime{5'000'000'000'000 + std::int64_t{id} * 1'000'000});
        }
    };
    try {
        run_on();
        ADD_FAILURE() << "a restart while head A lags was not refused";
    } catch (const host::LinkError& e) {
        EXPECT_TRUE(has(e.what(), "head A lags: the lag's state of its temperatures is lost")) << e.what();
    }
}

// CALIB_START: the lags after common_rotation, only when a head lags.
TEST(LagLink, CalibStartCarriesTheLagsOnlyWhenAHeadLags) {
    std::uint8_t p[link::kMaxPayload];
    link::CalibStart m{5'700'000'000, 30.0, 1U, 0U};
    EXPECT_EQ(link::encode(m, p), 17U);
    m.common_rotation = 1U;
    EXPECT_EQ(link::encode(m, p), 18U);
    m.common_rotation = 0U;
    m.lag_s[0] = 900.0;
    m.lag_s[2] = 1800.5;
    const std::size_t n = link::encode(m, p);
    ASSERT_EQ(n, 18U + 4U * 8U);
    link::CalibStart back{};
    ASSERT_TRUE(link::decode(p, n, back));
    EXPECT_EQ(back.common_rotation, 0U);
    EXPECT_EQ(back.lag_s[0], 900.0);
    EXPECT_EQ(back.lag_s[1], 0.0);
    EXPECT_EQ(back.lag_s[2], 1800.5);
    EXPECT_EQ(back.lag_s[3], 0.0);
    ASSERT_TRUE(link::decode(p, 17U, back));  // as a host before it: no lag
    EXPECT_FALSE(pipeline::any_lagged(back.lag_s));
    // A τ out of range (NaN included), or a frame cut short.
    for (double bad : {0.5, 86400.5, -900.0, std::nan("")}) {
        std::uint8_t q[link::kMaxPayload];
        std::memcpy(q, p, n);
        std::memcpy(q + 18 + 8, &bad, sizeof bad);  // head B's, little-endian as the wire
        EXPECT_FALSE(link::decode(q, n, back)) << bad;
    }
    EXPECT_FALSE(link::decode(p, n - 8U, back));
    EXPECT_FALSE(link::decode(p, 19U, back));
}

// A restart before any timed solution of a lagged head loses no lag state:
// the model and its lags are restored. While the estimator runs, its lags
// are CALIB_START's (here none: the model's lag ends), and a MODEL_UPLOAD's
// lag is refused.
TEST(LagLink, ARestartBeforeTheLagHasStateIsRestoredAndTheEstimatorTakesCalibStartsLags) {
    const ThermalModel<float> model = host::to_core<float>(host::read_model_file((mission() / "m.csv").string()));
    RestartingTarget target(2);  // during the model's upload
    host::LoopbackTransport t(
        [&](const std::uint8_t* p, std::size_t n, const host::LoopbackTransport::Reply& r) { target.serve(p, n, r); });
    host::LinkClient<float> client(t, 1, 20);
    client.connect();
    client.upload_model(model, {kTauS, 0.0, 0.0, 0.0});
    EXPECT_EQ(client.stats().restarts, 1U);
    client.set_velocity({{1e-4F, -2e-5F, 3e-5F}, 1.0F, true});
    client.set_temperatures(0, {{10.0F, true}, {-5.0F, true}, {-20.0F, true}});
    const Quaternion<float> q{0.5F, 0.5F, 0.5F, 0.5F};
    EXPECT_EQ(client.correct(0, 0, q, TtTime{5'000'000'000'000}).status,
              status::kAberrationApplied | status::kThermalApplied);
    client.start_calibration(5'700'000'000, 30.0, nullptr);
    EXPECT_THROW(client.upload_model(model, {0.0, kTauS, 0.0, 0.0}), host::LinkError);
}

// Head A's answers over a step of its temperatures, the estimator started
// from the mission's model with `calib_lags` (CALIB_START's), after
// `before` (a MODEL_UPLOAD's lags, or none) and, while it runs, a
// MODEL_UPLOAD without a lag when `upload_while` (the target keeps
// CALIB_START's lags: the same answers).
std::vector<Quaternion<float>> answers_while_calibrating(const std::optional<std::array<double, kMaxHeads>>& before,
                                                         const std::array<double, kMaxHeads>& calib_lags,
                                                         bool upload_while) {
    const host::ModelFile mf = host::read_model_file((mission() / "m.csv").string());
    const ThermalModel<float> model = host::to_core<float>(mf);
    const ModelCoefficients initial = host::coefficients_of(mf);
    RestartingTarget target(1'000'000);  // no restart
    host::LoopbackTransport t(
        [&](const std::uint8_t* p, std::size_t n, const host::LoopbackTransport::Reply& r) { target.serve(p, n, r); });
    host::LinkClient<float> client(t, 1, 20);
    client.connect();
    if (before) {
        client.upload_model(model, *before);
    }
    client.start_calibration(5'700'000'000, 30.0, &initial, false, calib_lags);
    if (upload_while) {
        client.upload_model(model);
        // A lag now is refused before the target sees it, and changes nothing.
        EXPECT_THROW(client.upload_model(model, {0.0, kTauS, 0.0, 0.0}), host::LinkError);
        EXPECT_EQ(client.lag_s(), calib_lags);
    }
    client.set_velocity({{1e-4F, -2e-5F, 3e-5F}, 1.0F, true});
    const Quaternion<float> q{0.5F, 0.5F, 0.5F, 0.5F};
    std::vector<Quaternion<float>> out;
    for (std::uint32_t i = 0; i < 40; ++i) {
        const float step = i < 10 ? 0.0F : 8.0F;  // the lag follows it over τ
        client.set_temperatures(0, {{10.0F + step, true}, {-5.0F + step, true}, {-20.0F, true}});
        const link::SolutionOut<float> a =
            client.correct(i, 0, q, TtTime{5'000'000'000'000 + std::int64_t{i} * 60'000'000});
        EXPECT_NE(a.status & status::kThermalApplied, 0U) << i;
        out.push_back(a.q_chu_icrf);
    }
    return out;
}

bool same_answers(const std::vector<Quaternion<float>>& a, const std::vector<Quaternion<float>>& b) {
    return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof a[0]) == 0;
}

// While the estimator runs its lags are CALIB_START's: a MODEL_UPLOAD
// without one changes none, one with τ is refused; CALIB_START without lags
// ends a MODEL_UPLOAD's. Mutation: the lag changes the answers.
TEST(LagLink, WhileTheEstimatorRunsItsLagsAreCalibStarts) {
    const std::array<double, kMaxHeads> lagged{kTauS, 0.0, 0.0, 0.0};
    const auto with = answers_while_calibrating(std::nullopt, lagged, false);
    EXPECT_TRUE(same_answers(answers_while_calibrating(std::nullopt, lagged, true), with));
    const auto without = answers_while_calibrating(std::nullopt, {}, false);
    EXPECT_FALSE(same_answers(with, without)) << "the lag changes no answer: the test would be vacuous";
    EXPECT_TRUE(same_answers(answers_while_calibrating(lagged, {}, false), without));
    // A CALIB_START with every τ 0 on the wire (50 bytes) is no lag.
    std::uint8_t p[link::kMaxPayload];
    link::CalibStart m{5'700'000'000, 30.0, 0U, 0U};
    m.lag_s[3] = 900.0;
    const std::size_t n = link::encode(m, p);
    std::memset(p + n - 8, 0, 8);
    link::CalibStart back{};
    ASSERT_TRUE(link::decode(p, n, back));
    EXPECT_FALSE(pipeline::any_lagged(back.lag_s));
}

// `replay` of a lagged model: the target lags in its scalar, row by row in
// time order, bit for bit as the host's pipeline, and its file agrees with
// `ascorr correct`'s (which lags in double over the whole file) within the
// float bound of the replay tests (0.05"); in any row order. Mutation: the
// same model without its lag is arcseconds away, so the lag is applied.
TEST(ReplayLag, LoopbackTargetAnswersAsCorrectDoesInAnyRowOrder) {
    const fs::path& dir = mission();
    (void)expect_replay_as_correct(dir, "m_lag.csv", "lagged");  // c.csv and c0.csv measured 1.1" apart
    host::ReplayOptions o;
    o.target = "loopback-float";
    o.model = (dir / "m_lag.csv").string();
    std::ostringstream log;
    // The rows shuffled: the target still takes them in time order.
    std::vector<std::string> lines = lines_of_file(dir / "s.csv");
    std::mt19937 rng(5);
    std::shuffle(lines.begin() + 1, lines.end(), rng);
    write_lines(dir / "shuffled.csv", lines);
    o.in = (dir / "shuffled.csv").string();
    o.out = (dir / "r_shuffled.csv").string();
    const host::ReplaySummary shuffled = host::replay(o, log);
    EXPECT_EQ(shuffled.mismatches, 0U);
    EXPECT_EQ(largest_difference(dir / "r_shuffled.csv", dir / "r.csv"), 0.0);
}

}  // namespace
}  // namespace ascorr::test
