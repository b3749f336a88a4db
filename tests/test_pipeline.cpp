// The epoch pipeline (ascorr/pipeline/epoch_pipeline.hpp) on its own: which
// model each epoch takes, which epochs feed the estimator on which schedule,
// what the combination stage is given and what it says of a crowded epoch.
// The callers (flight loop, link server, self-calibration, replay) are
// checked bit for bit against each other elsewhere; here each rule alone,
// with a Calls double that records what the pipeline asked of it.
#include <gtest/gtest.h>

#include <cstdint>
#include <utility>
#include <vector>

#include "ascorr/core/constants.hpp"
#include "ascorr/core/table2.hpp"
#include "ascorr/pipeline/epoch_pipeline.hpp"

namespace ascorr::test {
namespace {

// Records the pipeline's calls (F Prime's test doubles), and answers as the library does.
struct Recorded {
    std::vector<std::int64_t> model_epochs;               // model_for_epoch's t_us
    std::vector<std::int64_t> feeds;                      // feed's t_us
    std::vector<unsigned> further;                        // feed's further heads (mask)
    std::vector<std::pair<std::int64_t, unsigned>> late;  // feed_head's t_us and head
    int steps = 0;
    std::vector<int> combined_n;  // combine's n
};
Recorded g_calls;

struct RecordingCalls : pipeline::InlineCalls<double> {
    template <std::size_t N>
    static const ThermalModel<double>* model_for_epoch(calib::Estimator<double, N>& e, std::int64_t t_us) noexcept {
        g_calls.model_epochs.push_back(t_us);
        return e.model_for_cycle(t_us);
    }
    template <std::size_t N>
    static bool feed(calib::Estimator<double, N>& e, std::int64_t t_us, const ThermalModel<double>* model,
                     const CorrectedSolution<double>* corrected, const HeadTemperatures<double>* const* temperatures,
                     std::uint8_t further) noexcept {
        g_calls.feeds.push_back(t_us);
        g_calls.further.push_back(further);
        return calib::feed_estimator(e, t_us, model, corrected, temperatures, further);
    }
    template <std::size_t N>
    static bool feed_head(calib::Estimator<double, N>& e, std::uint8_t h, std::int64_t t_us,
                          const ThermalModel<double>* model, const CorrectedSolution<double>& corrected,
                          const HeadTemperatures<double>& temperatures) noexcept {
        g_calls.late.emplace_back(t_us, h);
        return calib::feed_estimator_head(e, h, t_us, model, corrected, temperatures);
    }
    template <std::size_t N>
    static bool step(calib::Estimator<double, N>& e) noexcept {
        ++g_calls.steps;
        return e.step();
    }
    static combine::CombinedAttitude<double> combine(const combine::Combiner<double>& c,
                                                     const combine::HeadAttitude<double>* heads,
                                                     std::uint8_t n) noexcept {
        g_calls.combined_n.push_back(n);
        return c.combine(heads, n);
    }
};

// A solution of head h that the core corrects with both stages.
SolutionInput<double> solution(std::uint8_t h) {
    SolutionInput<double> in{};
    in.q_chu_icrf = {0.5, 0.5, 0.5, 0.5};
    in.head = h;
    in.temperatures = {{{20.0}, true}, {{21.0}, true}, {{22.0}, true}};
    in.velocity = {{7.5 / kSpeedOfLightKmS, 0.0, 0.0}, 1.0, true};
    return in;
}

auto given(const SolutionInput<double>& in) {
    return [v = in.velocity] { return pipeline::given_velocity(v); };
}

TEST(Pipeline, AnEpochTakesTheModelOnceAndFeedsWhenItsCalibratedHeadsAreIn) {
    g_calls = {};
    calib::Estimator<double> estimator(calib::EstimatorConfig{}, &kTable2);
    pipeline::EpochPipeline<double, RecordingCalls> pipe;
    pipe.use_estimator(&estimator);
    for (std::int64_t t = 0; t < 3; ++t) {
        const ThermalModel<double>* model = pipe.begin(t * 1000000);
        EXPECT_NE(model, nullptr);  // Table 2 is version 0
        for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
            EXPECT_EQ(pipe.begin(t * 1000000), model);  // the same epoch: no second model stage
            const CorrectedSolution<double> c = pipe.solution(solution(h), given(solution(h)), true);
            if (h < calib::kCalibHeads) {
                EXPECT_EQ(c.status, status::kAberrationApplied | status::kThermalApplied);
            }
        }
    }
    EXPECT_EQ(g_calls.model_epochs, (std::vector<std::int64_t>{0, 1000000, 2000000}));
    EXPECT_EQ(g_calls.feeds, (std::vector<std::int64_t>{0, 1000000, 2000000}));
    EXPECT_EQ(pipe.feeds(), 3U);
}

TEST(Pipeline, TheScheduleFeedsEveryNthEpochAndIdleSteps) {
    g_calls = {};
    calib::Estimator<double> estimator(calib::EstimatorConfig{}, &kTable2);
    pipeline::EpochPipeline<double, RecordingCalls> pipe(pipeline::FeedSchedule{2U, 0});
    pipe.use_estimator(&estimator);
    for (std::int64_t t = 0; t < 5; ++t) {
        (void)pipe.begin(t);
        for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
            (void)pipe.solution(solution(h), given(solution(h)), true);
        }
        pipeline::NoMeter m;
        (void)pipe.idle(m);
    }
    EXPECT_EQ(g_calls.feeds, (std::vector<std::int64_t>{0, 2, 4}));  // epochs 0, 2, 4
    EXPECT_EQ(g_calls.steps, 5);                                     // one per idle(), none after a feed
}

// Per-head selection with four heads: the cycle feeds as soon as A, B and C
// are in, whatever D does (D not clean: the epoch still counts for A, B, C);
// D kept before them goes with the cycle, D after them is fed alone into the
// same cycle (feed_head), and only once.
TEST(Pipeline, AFourthHeadNeverHoldsBackTheFrameHeadsAndIsFedWhenItIsClean) {
    g_calls = {};
    calib::Estimator<double, 4> estimator(calib::EstimatorConfig{}, &kTable2);
    pipeline::EpochPipeline<double, RecordingCalls, 4> pipe;
    pipe.use_estimator(&estimator);
    const auto in = [&](std::uint8_t h, bool clean) { (void)pipe.solution(solution(h), given(solution(h)), clean); };
    (void)pipe.begin(0);  // D not clean: A, B, C feed alone
    in(3, false);
    in(0, true);
    in(1, true);
    in(2, true);
    (void)pipe.begin(1);  // D first: in the cycle
    in(3, true);
    in(0, true);
    in(1, true);
    in(2, true);
    (void)pipe.begin(2);  // D last: alone, once
    in(0, true);
    in(1, true);
    in(2, true);
    in(3, true);
    in(3, true);
    (void)pipe.begin(3);  // B not clean: no cycle, D not fed
    in(0, true);
    in(1, false);
    in(2, true);
    in(3, true);
    EXPECT_EQ(g_calls.feeds, (std::vector<std::int64_t>{0, 1, 2}));
    EXPECT_EQ(g_calls.further, (std::vector<unsigned>{0U, 8U, 0U}));
    EXPECT_EQ(g_calls.late, (std::vector<std::pair<std::int64_t, unsigned>>{{2, 3U}}));
    EXPECT_EQ(pipe.feeds(), 3U);
}

TEST(Pipeline, ASolutionThatIsNotCleanOrRepeatedDoesNotFeed) {
    g_calls = {};
    calib::Estimator<double> estimator(calib::EstimatorConfig{}, &kTable2);
    pipeline::EpochPipeline<double, RecordingCalls> pipe;
    pipe.use_estimator(&estimator);
    (void)pipe.begin(0);
    (void)pipe.solution(solution(0), given(solution(0)), true);
    (void)pipe.solution(solution(0), given(solution(0)), true);   // A again: not a second A
    (void)pipe.solution(solution(1), given(solution(1)), false);  // B not clean
    (void)pipe.solution(solution(2), given(solution(2)), true);
    EXPECT_TRUE(g_calls.feeds.empty());
    SolutionInput<double> b = solution(1);
    b.temperatures.t_029.valid = false;  // usable only with three temperatures
    (void)pipe.solution(b, given(b), true);
    EXPECT_TRUE(g_calls.feeds.empty());
    (void)pipe.solution(solution(1), given(solution(1)), true);
    EXPECT_EQ(g_calls.feeds.size(), 1U);
}

TEST(Pipeline, UntimedSolutionsHaveNoModelWhileCalibrating) {
    calib::Estimator<double> estimator(calib::EstimatorConfig{}, &kTable2);
    pipeline::EpochPipeline<double> pipe;
    pipe.use_estimator(&estimator);
    const CorrectedSolution<double> c = pipe.untimed_solution(solution(0), given(solution(0)));
    EXPECT_EQ(c.status, status::kAberrationApplied | status::kNoModelForHead);
    const ThermalModel<double> table2 = thermal_model<double>(kTable2, kArcsecToRad);
    pipe.use_model(&table2);
    EXPECT_EQ(pipe.untimed_solution(solution(0), given(solution(0))).status,
              status::kAberrationApplied | status::kThermalApplied);
}

// With a Sun term folded in, a solution without a time stays out of the
// epochs only when its own head has a term (it has no Sun direction: 128);
// a head without one keeps its epoch (and its combination), as with no term
// at all; while calibrating no untimed solution has one. The pipeline whose
// Calls has no flight form (TakesSunTerm) compiles without the stage.
TEST(Pipeline, AnUntimedSolutionLeavesTheEpochsOnlyWhenItsHeadHasASunTerm) {
    const ThermalModel<double> table2 = thermal_model<double>(kTable2, kArcsecToRad);
    SunTermModel<double> sun{};
    sun.present[0] = true;
    sun.coefficient[0][1][2] = 1e-5;
    keep_present_where_terms(sun);
    pipeline::EpochPipeline<double> pipe;
    pipe.use_model(&table2);
    EXPECT_TRUE(pipe.in_epoch(0, false));
    pipe.use_sun_term(&sun);
    EXPECT_FALSE(pipe.in_epoch(0, false));
    EXPECT_TRUE(pipe.in_epoch(1, false));
    EXPECT_TRUE(pipe.in_epoch(0, true));
    EXPECT_TRUE(pipe.in_epoch(kMaxHeads, false));  // no such head: no term; the core rejects it
    const CorrectedSolution<double> c = pipe.untimed_solution(solution(0), given(solution(0)));
    EXPECT_EQ(c.status, status::kAberrationApplied | status::kThermalOutOfRange);
    pipe.use_sun_term(nullptr);
    EXPECT_TRUE(pipe.in_epoch(0, false));
    calib::Estimator<double> estimator(calib::EstimatorConfig{}, &kTable2);
    pipe.use_sun_term(&sun);
    pipe.use_estimator(&estimator);
    EXPECT_FALSE(pipe.in_epoch(1, false));
    static_assert(pipeline::TakesSunTerm<pipeline::InlineCalls<double>, double>::value);
    static_assert(!pipeline::TakesSunTerm<pipeline::NoMeter, double>::value);
}

TEST(Pipeline, TheServiceBitsJoinOnlyWhenTheServiceWasAsked) {
    const ThermalModel<double> table2 = thermal_model<double>(kTable2, kArcsecToRad);
    pipeline::EpochPipeline<double> pipe;
    pipe.use_model(&table2);
    (void)pipe.begin(0);
    ServiceVelocity<double> stale{};
    stale.velocity.valid = false;
    stale.status = status::kNoVelocity | status::kStale;
    const CorrectedSolution<double> asked = pipe.solution(
        solution(0), [&] { return pipeline::from_service(stale); }, true);
    EXPECT_EQ(asked.status, status::kThermalApplied | status::kNoVelocity | status::kStale);
    pipeline::VelocityAnswer<double> not_asked{stale.velocity, status::kStale, false};
    EXPECT_EQ(pipe.solution(
                      solution(0), [&] { return not_asked; }, true)
                  .status,
              status::kThermalApplied | status::kNoVelocity);
}

combine::Mountings mountings() {
    combine::Mountings m{};
    const Quaternion<double> q[kMaxHeads] = {
        {1.0, 0.0, 0.0, 0.0}, {0.5, 0.5, 0.5, 0.5}, {0.5, -0.5, -0.5, -0.5}, {0.0, 1.0, 0.0, 0.0}};
    for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
        m.head[h] = {true, q[h], 1.3, 9.0};
    }
    return m;
}

// Head h's raw attitude on a bench whose CRF is the identity: q_chu_crf itself.
SolutionInput<double> mounted(std::uint8_t h) {
    SolutionInput<double> in = solution(h);
    in.q_chu_icrf = mountings().head[h].q_chu_crf;
    return in;
}

TEST(Pipeline, TheCombinationTakesTheSolutionsSinceTheLastCloseAndSaysWhenSomeDidNotFit) {
    g_calls = {};
    const combine::Combiner<double> combiner(mountings());
    ASSERT_TRUE(combiner.valid());
    pipeline::EpochPipeline<double, RecordingCalls> pipe;
    pipe.use_model(nullptr);  // no thermal stage, and no aberration below: the raw attitudes, which agree
    EXPECT_EQ(pipe.close().status, combine::combined_status::kNoHead);  // no combiner: nothing to combine
    pipe.use_combiner(&combiner);
    (void)pipe.begin(0);
    for (std::uint8_t h = 0; h < 3; ++h) {
        (void)pipe.solution(mounted(h), given(mounted(h)), true, false);
    }
    const combine::CombinedAttitude<double> a = pipe.close();
    EXPECT_EQ(g_calls.combined_n, (std::vector<int>{3}));
    EXPECT_EQ(a.status, combine::combined_status::kTwoOrMoreHeads);
    EXPECT_EQ(a.used, 0x7U);
    EXPECT_NEAR(a.q_crf_icrf.w, 1.0, 1e-12);
    (void)pipe.solution(mounted(1), given(mounted(1)), false, false);  // not clean: given, left out
    const combine::CombinedAttitude<double> b = pipe.close();
    EXPECT_EQ(g_calls.combined_n.back(), 1);
    EXPECT_EQ(b.status, combine::combined_status::kNoHead | combine::combined_status::kHeadLeftOut);
    (void)pipe.solution(mounted(0), given(mounted(0)), true);  // with aberration asked and no velocity: 4, left out
    SolutionInput<double> without = mounted(0);
    without.velocity.valid = false;
    (void)pipe.solution(without, given(without), true);
    EXPECT_EQ(pipe.close().used, 0x1U);        // the first A only (the second: a repeated head)
    for (int i = 0; i < 3 * kMaxHeads; ++i) {  // more than the slots: the rest is left out, bit 4
        const auto h = static_cast<std::uint8_t>(i % kMaxHeads);
        (void)pipe.solution(mounted(h), given(mounted(h)), true, false);
    }
    const combine::CombinedAttitude<double> c = pipe.close();
    EXPECT_EQ(g_calls.combined_n.back(), 2 * kMaxHeads);
    EXPECT_NE(c.status & combine::combined_status::kHeadLeftOut, 0U);
    EXPECT_EQ(pipe.close().status, combine::combined_status::kNoHead);  // nothing since: no head
}

}  // namespace
}  // namespace ascorr::test
