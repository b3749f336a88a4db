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
// The cost of each part is measured by the caller's Meter (main.cpp: SysTick
// counts; the host: NoMeter), which sees the work but never changes it:
//   std::uint32_t now() noexcept;                    a time stamp
//   void add(Part part, std::uint32_t start) noexcept;  the part just done since `start`
//
// CorrectionLog: per head, the cycles with both corrections applied, every
// status bit seen, the last corrected solution, and a CRC-32C (crc32c.hpp)
// over every cycle's corrected solution (the four components' bit patterns,
// then the status; little-endian); and every head's solution at each
// kSampleEvery-th cycle (the first kMaxSamples of them). Printed with
// report.hpp (integers and hex only), the same text on the DPU and the host.
#pragma once

#include <cstdint>
#include <cstring>

#include "app_scalar.hpp"
#include "ascorr/calib/estimator.hpp"
#include "ascorr/core/correct.hpp"
#include "ascorr/core/status.hpp"
#include "ascorr/nav/velocity_service.hpp"
#include "ascorr/pipeline/common_rotation_weights.hpp"
#include "ascorr/pipeline/epoch_pipeline.hpp"
#include "ascorr_link/crc32c.hpp"
#include "calib_entry.hpp"
#include "combine_entry.hpp"
#include "core_entry.hpp"
#include "flight_bench.hpp"
#include "flight_data.hpp"
#include "gnss_feed.hpp"
#include "loop_rate.hpp"
#include "recorded_orbit.hpp"
#include "report.hpp"
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
};

struct NoMeter {
    std::uint32_t now() noexcept { return 0U; }
    void add(Part /*part*/, std::uint32_t /*start*/) noexcept {}
};

inline std::uint32_t bits_of(Q30 x) noexcept {
    return static_cast<std::uint32_t>(x.raw);
}
inline std::uint32_t bits_of(float x) noexcept {
    std::uint32_t u = 0U;
    std::memcpy(&u, &x, sizeof u);
    return u;
}

class CorrectionLog {
public:
    static constexpr std::uint32_t kSampleEvery = 16U;
    static constexpr std::uint32_t kMaxSamples = 32U;
    // Records: one per head, then the cycle's combined attitude (kCombined).
    static constexpr std::uint8_t kCombined = kMaxHeads;
    static constexpr std::uint8_t kRecords = kMaxHeads + 1U;

    // Head `head`'s corrected solution of cycle `cycle` (cycles in order from 0).
    void add(std::uint32_t cycle, std::uint8_t head, const CorrectedSolution<Scalar>& c) noexcept {
        if (head < kMaxHeads) {
            add_record(cycle, head, c, c.status == (status::kAberrationApplied | status::kThermalApplied));
        }
    }

    // The cycle's combined attitude, as a record whose status is the
    // combined status with the heads used in bits 8..8+kMaxHeads−1, and
    // "applied" when two or more heads were averaged.
    void add_combined(std::uint32_t cycle, const combine::CombinedAttitude<Scalar>& a) noexcept {
        const auto st = static_cast<StatusBits>(a.status | (static_cast<unsigned>(a.used) << 8U));
        add_record(cycle, kCombined, {a.q_crf_icrf, st}, (a.status & combine::combined_status::kTwoOrMoreHeads) != 0U);
    }

    struct Head {
        std::uint32_t applied;    // cycles with both corrections applied (combined: two or more heads)
        StatusBits status_union;  // every status bit seen
        std::uint32_t solutions;  // cycles recorded
        std::uint32_t crc;        // CRC-32C over every cycle's solution and status
        CorrectedSolution<Scalar> last;
    };
    const Head& head(std::uint8_t h) const noexcept { return heads_[h < kRecords ? h : 0U]; }
    std::uint32_t samples_taken() const noexcept { return samples_taken_; }
    // Record h's solution of cycle i·kSampleEvery, i < samples_taken().
    const CorrectedSolution<Scalar>& sample(std::uint32_t i, std::uint8_t h) const noexcept {
        return samples_[i < kMaxSamples ? i : 0U][h < kRecords ? h : 0U];
    }

    // Per record: "head H: applied N status seen S last q W X Y Z"
    // ("combined: ..." for the combined attitude).
    void print_heads() const noexcept {
        using namespace report;
        for (std::uint8_t h = 0; h < kRecords; ++h) {
            const Head& r = heads_[h];
            name(h);
            text(": applied ");
            u32(r.applied);
            text(" status seen ");
            u32(r.status_union);
            text(" last q ");
            quaternion(r.last.q_chu_icrf);
            text("\n");
        }
    }

    // "sample cycle C head H status S q W X Y Z" per sample and record, then
    // "solutions head H cycles N crc32c X" per record ("combined" for head H
    // of the combined attitude).
    void print_solutions() const noexcept {
        using namespace report;
        for (std::uint32_t i = 0; i < samples_taken_; ++i) {
            for (std::uint8_t h = 0; h < kRecords; ++h) {
                text("sample cycle ");
                u32(i * kSampleEvery);
                text(" ");
                name(h);
                text(" status ");
                u32(samples_[i][h].status);
                text(" q ");
                quaternion(samples_[i][h].q_chu_icrf);
                text("\n");
            }
        }
        for (std::uint8_t h = 0; h < kRecords; ++h) {
            text("solutions ");
            name(h);
            text(" cycles ");
            u32(heads_[h].solutions);
            text(" crc32c ");
            hex32(heads_[h].crc);
            text("\n");
        }
    }

private:
    static void name(std::uint8_t h) noexcept {
        if (h == kCombined) {
            report::text("combined");
            return;
        }
        report::text("head ");
        report::u32(h);
    }

    void add_record(std::uint32_t cycle, std::uint8_t head, const CorrectedSolution<Scalar>& c, bool applied) noexcept {
        Head& r = heads_[head];
        const std::uint32_t words[5] = {bits_of(c.q_chu_icrf.w), bits_of(c.q_chu_icrf.x), bits_of(c.q_chu_icrf.y),
                                        bits_of(c.q_chu_icrf.z), c.status};
        std::uint8_t bytes[sizeof words];
        for (std::uint32_t i = 0; i < 20U; ++i) {  // little-endian, whatever the machine
            bytes[i] = static_cast<std::uint8_t>(words[i / 4U] >> (8U * (i % 4U)));
        }
        r.crc = link::crc32c(bytes, 18U, r.crc);  // the status: its 16 bits
        r.solutions = cycle + 1U;
        r.last = c;
        r.status_union = static_cast<StatusBits>(r.status_union | c.status);
        if (applied) {
            ++r.applied;
        }
        if (cycle % kSampleEvery == 0U && cycle / kSampleEvery < kMaxSamples) {
            samples_[cycle / kSampleEvery][head] = c;
            samples_taken_ = cycle / kSampleEvery + 1U;
        }
    }

    static void quaternion(const Quaternion<Scalar>& q) noexcept {
        report::hex32(bits_of(q.w));
        report::text(" ");
        report::hex32(bits_of(q.x));
        report::text(" ");
        report::hex32(bits_of(q.y));
        report::text(" ");
        report::hex32(bits_of(q.z));
    }
    Head heads_[kRecords]{};
    CorrectedSolution<Scalar> samples_[kMaxSamples][kRecords]{};
    std::uint32_t samples_taken_ = 0U;
};

// The models the estimator made active, in turn (the first kMaxModels): the
// cycle from which each was used, its version and CRC-32C (model_identity.hpp)
// and its coefficients (arcsec; printed as the bits of each double).
class ModelHistory {
public:
    static constexpr std::uint32_t kMaxModels = 4U;
    struct Entry {
        std::uint32_t cycle;
        std::uint32_t version;
        std::uint32_t crc;
        ModelCoefficients model;
    };

    void add(std::uint32_t cycle, const calib::EstimatorReport& r, const ModelCoefficients& m) noexcept {
        if (size_ < kMaxModels) {
            entries_[size_] = {cycle, r.active_version, r.active_crc, m};
            ++size_;
        }
    }
    std::uint32_t size() const noexcept { return size_; }
    const Entry& entry(std::uint32_t i) const noexcept { return entries_[i < kMaxModels ? i : 0U]; }

    // Per model: "model version V from cycle C crc32c X", then per head and
    // axis "model version V head H axis A c HHHHHHHHLLLLLLLL ..." (c0..c3).
    void print() const noexcept {
        using namespace report;
        for (std::uint32_t i = 0; i < size_; ++i) {
            const Entry& e = entries_[i];
            text("model version ");
            u32(e.version);
            text(" from cycle ");
            u32(e.cycle);
            text(" crc32c ");
            hex32(e.crc);
            text("\n");
            for (std::uint32_t h = 0; h < kMaxHeads; ++h) {
                for (std::uint32_t a = 0; a < kModelAxes; ++a) {
                    text("model version ");
                    u32(e.version);
                    text(" head ");
                    u32(h);
                    text(" axis ");
                    u32(a);
                    text(" c");
                    for (std::uint32_t t = 0; t < kLinearModelTerms; ++t) {
                        std::uint64_t b = 0U;
                        std::memcpy(&b, &e.model.coefficient[h][a][t], sizeof b);
                        text(" ");
                        hex32(static_cast<std::uint32_t>(b >> 32U));
                        hex32(static_cast<std::uint32_t>(b));
                    }
                    text("\n");
                }
            }
        }
    }

private:
    Entry entries_[kMaxModels]{};
    std::uint32_t size_ = 0U;
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

private:
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
