// firmware/app/flight_cycle.hpp: what one cycle of the flight loop computes,
// and what the loop reports of its solutions; one definition for the DPU
// (main.cpp) and for the host's prediction of its output
// (tests/target/flight_expectation.cpp).
//
// Conventions: the loop runs at kRateHz. Each cycle takes the GNSS states that
// arrived (gnss_feed.hpp) into the velocity service (velocity_service.hpp:
// frame conversion and propagation in double, bounded per cycle), then runs
// the cycle as one epoch of the epoch pipeline (pipeline/epoch_pipeline.hpp),
// with the image's out-of-line entries (EntryCalls): the on-board
// estimator's active model (calib_entry.hpp; a new one starts between
// cycles), then one raw solution per camera head (the simulated deforming
// bench, flight_bench.hpp) with the velocity the service gives for that
// solution's own time (velocity_entry.hpp), the core in the build's scalar
// (app_scalar.hpp, core_entry.hpp), the temperatures of
// temperature_source.hpp and their status bits; every kCalibFeedEvery-th
// cycle heads A, B and C (and D when it passes the selection) feed the
// estimator (FlightEstimator, calib_entry.hpp); then the cycle's heads are
// combined into the bench's attitude (combine_entry.hpp, the mountings
// kBenchMountings of flight_bench.hpp); after the solutions one bounded step
// of the estimator's per-orbit update runs (idle()). Times are TT µs
// (integers: no time in the scalar). Every loop has a fixed trip count.
//
// The Sun term (calib/sun_learner.hpp, sun_learner_entry.hpp): at each cycle
// that fed the estimator, the learner takes the frame heads as the
// polynomial corrected them (one per kSunLearnOnBoardIntervalUs; in the
// accelerated time of a test run every fed cycle is further apart); each
// model version takes the term the learner has taken when it becomes active
// (pipeline/version_sun_term.hpp), applied after the feed in the contract's
// form (the pipeline's with_version_term; sun_entry.hpp's core form, which
// Calls must have for the stage, serves a fixed model's term). None until
// the learner takes a term: it decides after its memory's orbits, at least
// 30 days, beyond a test run's 44. The learner's per-orbit solve runs in the
// period's idle time after the cycle (learn_in_idle), a step while the Meter
// says there is room; what is left runs at its next take (settle), so the
// host, which runs it all at once, learns the same bits.
//
// The cost of each part is measured by the caller's Meter (main.cpp: SysTick
// counts; the host: NoMeter), which sees the work but never changes it:
//   std::uint32_t now() noexcept;                    a time stamp
//   void add(Part part, std::uint32_t start) noexcept;  the part just done since `start`
//   bool idle_room() noexcept;                       the period has room for an idle step
//
// The loop's record of its solutions and models: cycle_log.hpp.
#pragma once

#include <cstdint>

#include "app_scalar.hpp"
#include "ascorr/calib/estimator.hpp"
#include "ascorr/core/correct.hpp"
#include "ascorr/core/status.hpp"
#include "ascorr/nav/velocity_service.hpp"
#include "ascorr/pipeline/common_rotation_weights.hpp"
#include "ascorr/pipeline/epoch_pipeline.hpp"
#include "ascorr/pipeline/version_sun_term.hpp"
#include "calib_entry.hpp"
#include "combine_entry.hpp"
#include "core_entry.hpp"
#include "cycle_log.hpp"
#include "flight_bench.hpp"
#include "flight_data.hpp"
#include "gnss_feed.hpp"
#include "loop_rate.hpp"
#include "recorded_orbit.hpp"
#include "sun_entry.hpp"
#include "sun_learner_entry.hpp"
#include "temperature_source.hpp"
#include "velocity_entry.hpp"

namespace ascorr::app {

// A head's solution time in cycle `cycle`: the tick's time minus a per-head
// exposure offset (heads 5 ms apart), TT µs.
inline constexpr std::int64_t kHeadOffsetUs = 5000;
constexpr TtTime solution_time(std::uint32_t cycle, std::uint8_t head) noexcept {
    const std::int64_t tick = kLoopStartTtUs + static_cast<std::int64_t>(cycle) * 1000000LL / kRateHz;
    return {tick - static_cast<std::int64_t>(kMaxHeads - head) * kHeadOffsetUs};
}

// The velocity service: at most 4 RK4 steps per call of advance() (one per
// 10 s of flight is the steady state), the default 6 h horizon.
inline constexpr VelocityServiceConfig kServiceConfig{kDefaultHorizonUs, kDefaultTtMinusUt1Us, 4U};

// One GNSS state per kStateIntervalUs is enough: 10 s of propagation adds
// ≤ 0.5 m/s (velocity_service.hpp), and each state costs a frame conversion
// and a node in software double. The others are skipped and counted (a state
// going back in time still reaches the service, which refuses and counts it).
inline constexpr std::int64_t kStateIntervalUs = 10 * kMicrosecondsPerSecond;

enum class Part : std::uint8_t {
    kState,       // push_state: checks + ITRF → GCRS (double)
    kNode,        // an advance() call that built a node (force, RK4 steps, Earth series; double)
    kQuery,       // velocity_at(): the per-solution query (scalar)
    kCorrect,     // the core
    kCalibCycle,  // the estimator's per-cycle part: the cycle's model, the feed (calib_entry.hpp)
    kCalibStep,   // one step() of the estimator's per-orbit update, in idle time
    kCombine,     // the combined attitude of the cycle's heads (combine_entry.hpp)
    kSunTake,     // the Sun learner's take of a fed cycle (its settle included)
    kSunStep,     // one step of the Sun learner's per-orbit solve, in idle time
};

struct NoMeter {
    std::uint32_t now() noexcept { return 0U; }
    void add(Part /*part*/, std::uint32_t /*start*/) noexcept {}
    bool idle_room() noexcept { return true; }  // the host: every step at once
};

// The pipeline's calls: the image's out-of-line entries (core_entry.hpp,
// calib_entry.hpp, each measured alone) and the temperatures' status bits.
struct EntryCalls {
    static const ThermalModel<Scalar>* model_for_epoch(FlightEstimator<Scalar>& e, std::int64_t t_us) noexcept {
        return calib_model(e, t_us);
    }
    static CorrectedSolution<Scalar> correct(const SolutionInput<Scalar>& in,
                                             const CorrectionConfig<Scalar>& cfg) noexcept {
        return app::correct(in, cfg);
    }
    static CorrectedSolution<Scalar> correct(const SolutionInput<Scalar>& in, const CorrectionConfig<Scalar>& cfg,
                                             const SunTermInput<Scalar>& sun) noexcept {
        return app::correct(in, cfg, sun);
    }
    static bool feed(FlightEstimator<Scalar>& e, std::int64_t t_us, const ThermalModel<Scalar>* model,
                     const CorrectedSolution<Scalar>* corrected, const HeadTemperatures<Scalar>* const* temperatures,
                     std::uint8_t further) noexcept {
        return calib_feed(e, t_us, model, corrected, temperatures, further);
    }
    static bool feed_head(FlightEstimator<Scalar>& e, std::uint8_t h, std::int64_t t_us,
                          const ThermalModel<Scalar>* model, const CorrectedSolution<Scalar>& corrected,
                          const HeadTemperatures<Scalar>& temperatures) noexcept {
        return calib_feed_head(e, h, t_us, model, corrected, temperatures);
    }
    static bool step(FlightEstimator<Scalar>& e) noexcept { return calib_step(e); }
    static StatusBits status(std::uint8_t head, StatusBits s) noexcept { return temperatures_merge_status(head, s); }
    static combine::CombinedAttitude<Scalar> combine(const combine::Combiner<Scalar>& c,
                                                     const combine::HeadAttitude<Scalar>* heads,
                                                     std::uint8_t n) noexcept {
        return combine_epoch(c, heads, n);
    }
};

// The pipeline's stages as the loop's parts.
constexpr Part part_of(pipeline::Stage stage) noexcept {
    switch (stage) {
        case pipeline::Stage::kVelocity:
            return Part::kQuery;
        case pipeline::Stage::kLag:  // part of the solution's correction
        case pipeline::Stage::kCorrect:
            return Part::kCorrect;
        case pipeline::Stage::kStep:
            return Part::kCalibStep;
        case pipeline::Stage::kCombine:
            return Part::kCombine;
        case pipeline::Stage::kModel:
        case pipeline::Stage::kFeed:
            break;
    }
    return Part::kCalibCycle;
}

template <typename Meter>
struct StageMeter {
    Meter& meter;
    std::uint32_t now() noexcept { return meter.now(); }
    void add(pipeline::Stage stage, std::uint32_t start) noexcept { meter.add(part_of(stage), start); }
};

// The estimator's configuration: kCalibConfig with the rule for the rotation
// common to all heads, the combined attitude of the mountings in flash moving
// least (docs/contract.md, "The common rotation"), fixed at construction.
inline calib::EstimatorConfig calib_config() noexcept {
    calib::EstimatorConfig c = kCalibConfig;
    c.common_rotation = pipeline::common_rotation_weights(kBenchMountings);
    return c;
}

class FlightCycle {
public:
    FlightCycle() noexcept {
        pipeline_.use_estimator(&estimator_);
        pipeline_.use_combiner(&combiner_);
    }
    FlightCycle(const FlightCycle&) = delete;
    FlightCycle& operator=(const FlightCycle&) = delete;

    // One cycle: the temperatures (temperature_source.hpp), the states, the
    // heads, and (record: a bounded test run, whose report prints it) their
    // solutions into the record; a flight run (record false) does no
    // test-only work.
    template <typename Meter>
    void run(std::uint32_t cycle, Meter& meter, bool record) noexcept;

    // The GNSS states due by the cycle's first solution: at most two per cycle
    // (the receiver's rate is 1 Hz; a late one is taken next cycle).
    template <typename Meter>
    void take_states(std::uint32_t cycle, Meter& meter) noexcept {
        GnssState s{};
        for (int i = 0; i < 2 && gnss_.poll(solution_time(cycle, 0U), s); ++i) {
            if (service_.has_state() && service_.state_time() < s.t &&
                s.t.us - service_.state_time().us < kStateIntervalUs) {
                ++states_skipped_;
                continue;
            }
            const std::uint32_t start = meter.now();
            if (service_.push_state(s.t, s.r_itrf_km, s.v_itrf_kms, StateFrame::kItrf) != StateVerdict::kAccepted) {
                ++states_refused_;
            }
            meter.add(Part::kState, start);
        }
    }

    // One corrected solution per head, in head order (fixed trip count),
    // through the epoch pipeline (the cycle is the epoch): the cycle's model,
    // then per head the service's velocity at the head's own time, the core,
    // the status, and the estimator's feed on the schedule's cycles.
    template <typename Meter>
    void correct_heads(std::uint32_t cycle, Meter& meter) noexcept {
        StageMeter<Meter> stages{meter};
        const ThermalModel<Scalar>* model = pipeline_.begin(calib_time_us(cycle), stages);
        version_sun_.follow(sun_learner_, estimator_.active_coefficients(), pipeline_);
        const std::uint32_t feeds = pipeline_.feeds();
        for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
            const TtTime t = solution_time(cycle, h);
            const std::uint32_t start = meter.now();
            const std::uint32_t nodes_before = service_.nodes_built();
            service_.advance(t, OnBoardEarth{});  // a no-op while t is in the current node
            if (service_.nodes_built() != nodes_before) {
                meter.add(Part::kNode, start);
            }
            const SolutionInput<Scalar> in{bench_attitude(cycle, h), h, temperatures_of(h), {}};
            corrected_[h] = pipeline_.solution(
                in, [&] { return pipeline::from_service(velocity_query(service_, t)); }, true, true, stages);
        }
        combined_ = pipeline_.close(stages);
        if (pipeline::learner_takes_feed(pipeline_, feeds, estimator_)) {
            take_sun(cycle, meter);
        }
        if (model != model_) {  // a model became active (double-buffered: a new one is at the other address)
            model_ = model;
            if (model != nullptr) {
                history_.add(cycle, estimator_.report(), *estimator_.active_coefficients());
            }
        }
    }

    // Idle time after the cycle's solutions: one bounded step of the
    // estimator's per-orbit update (at most one per cycle: the same on the DPU
    // and the host, whatever the time left).
    template <typename Meter>
    void idle(Meter& meter) noexcept {
        StageMeter<Meter> stages{meter};
        (void)pipeline_.idle(stages);
    }

    // The Sun learner's solve in the period's idle time after the cycle: a
    // step while the meter has room (at most two solves' steps: the one
    // under way and one pending).
    template <typename Meter>
    void learn_in_idle(Meter& meter) noexcept {
        for (int i = 0; i < 2 * calib::SunLearner::kMaxSolveSteps && meter.idle_room(); ++i) {
            const std::uint32_t start = meter.now();
            if (!sun_learner_step(sun_learner_)) {
                return;
            }
            meter.add(Part::kSunStep, start);
        }
    }

    // The cycle's combined attitude of the bench (kBenchMountings).
    const combine::CombinedAttitude<Scalar>& combined() const noexcept { return combined_; }
    const CorrectedSolution<Scalar>& corrected(std::uint8_t head) const noexcept {
        return corrected_[head < kMaxHeads ? head : 0U];
    }
    const VelocityService<Scalar>& service() const noexcept { return service_; }
    std::uint32_t states_skipped() const noexcept { return states_skipped_; }
    std::uint32_t states_refused() const noexcept { return states_refused_; }
    const CorrectionLog& record() const noexcept { return record_; }
    const FlightEstimator<Scalar>& estimator() const noexcept { return estimator_; }
    const ModelHistory& history() const noexcept { return history_; }
    const calib::SunLearner& sun_learner() const noexcept { return sun_learner_; }

private:
    // A fed cycle's frame heads into the Sun learner (as the link server's,
    // pipeline::learner_takes_feed).
    template <typename Meter>
    void take_sun(std::uint32_t cycle, Meter& meter) noexcept {
        Quaternion<double> q[calib::kFrameHeads];
        if (!calib::SunLearner::frame_heads_of(pipeline_.kept_solutions(), q)) {
            return;
        }
        const std::uint32_t start = meter.now();
        (void)sun_learner_take(sun_learner_, calib_time_us(cycle), q);
        meter.add(Part::kSunTake, start);
    }

    VelocityService<Scalar> service_{kServiceConfig};
    GnssFeed gnss_;
    CorrectedSolution<Scalar> corrected_[kMaxHeads]{};  // latest corrected solution per head
    std::uint32_t states_skipped_ = 0U;
    std::uint32_t states_refused_ = 0U;
    CorrectionLog record_;
    // The estimator, starting from the model in flash (version 0), fed every
    // kCalibFeedEvery-th cycle; its per-orbit update steps in idle time.
    FlightEstimator<Scalar> estimator_{calib_config(), &kTable2};
    pipeline::EpochPipeline<Scalar, EntryCalls, kMaxHeads> pipeline_{pipeline::FeedSchedule{kCalibFeedEvery, 0}};
    // The combination's tables, built once from the mountings in flash, with
    // the gate of pre-flight mountings (combine::flight_gate).
    combine::Combiner<Scalar> combiner_{kBenchMountings, combine::flight_gate()};
    combine::CombinedAttitude<Scalar> combined_{};
    const ThermalModel<Scalar>* model_ = nullptr;  // the last cycle's
    ModelHistory history_;
    // The Sun term's learner, under the estimator's rule for the common
    // rotation, and the term of the version the cycles use.
    calib::SunLearner sun_learner_{calib_config(), calib::kSunLearnOnBoardIntervalUs};
    pipeline::VersionSunTerm<Scalar> version_sun_{};
};

template <typename Meter>
void FlightCycle::run(std::uint32_t cycle, Meter& meter, bool record) noexcept {
    temperatures_update(cycle);
    take_states(cycle, meter);
    correct_heads(cycle, meter);
    idle(meter);
    for (std::uint8_t h = 0; record && h < kMaxHeads; ++h) {  // fixed trip count
        record_.add(cycle, h, corrected_[h]);
    }
    if (record) {
        record_.add_combined(cycle, combined_);
    }
}

}  // namespace ascorr::app
