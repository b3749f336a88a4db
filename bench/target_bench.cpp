// bench/target_bench.cpp: instructions per corrected solution on a target,
// under QEMU with -icount shift=0 (toolchain/qemu-run).
//
// SysTick runs from the core clock (25 MHz) without interrupt; with icount
// every instruction is 1 ns of virtual time, so a SysTick count is 40
// instructions. The ratio is measured, not assumed: a loop of known length
// (2 instructions per iteration) calibrates it. For each scalar and stage the
// core (the out-of-line entry of firmware/app/core_entry_*.cpp, called through
// a pointer) corrects kRuns solutions cycling over kInputs prepared inputs;
// the same loop calling a function that only copies its input is subtracted,
// so the figure is the call of the core and nothing else. Inputs are the first
// kInputs random records of vectors.bin (tests/target_vectors.cpp) that the
// core corrects fully (status 3), with the Table 2 model (linear, as flown) and
// with the random model with quadratic terms (stages *_quadratic), and with
// both stages off ("neither": validation and renormalisation alone).
// The baseline (bench/baseline.hpp, double, Eigen) is measured the same way.
// The Earth ephemeris series (ascorr/nav/earth_series.hpp, double: software floating
// point on both targets, the M4F's FPU being single precision) is measured per
// evaluation at kSeriesRuns epochs spread over its span, against a function
// that only writes its output; the series is the out-of-line entry of
// firmware/app/earth_series_entry.cpp ("bench double earth_series <instructions>").
// The combined attitude (ascorr/combine/, the out-of-line entry of
// firmware/app/combine_entry_*.cpp) is measured per epoch of three usable,
// consistent heads (bench/combination_fixture.hpp: near-orthogonal heads,
// the contract's noise, the true attitudes those of the selected records),
// against a function that only copies the first head's quaternion
// ("bench <scalar> combination <instructions>").
// The lag stage of a lagged head (pipeline/head_lags.hpp, the out-of-line
// entry of firmware/app/lag_entry_*.cpp) is measured per solution: heads A,
// B and C in turn at 22 Hz on millisecond time tags (each head's Δt 45 or
// 46 ms: α from its series, every channel in step: the usual path), τ = 900 s,
// the selected records' temperatures, against a function that only copies a
// reading ("bench <scalar> lag <instructions>": what a lagged head adds to
// its solution's correction).
// The thermal model's Sun term of a head (core/sun_term.hpp, folded into the
// core's thermal stage: the out-of-line entry of firmware/app/sun_entry_*.cpp)
// is measured per solution: the selected records, Table 2, every head with
// coefficients of ±2″ per axis, the Sun's direction given (the loop would
// form it at the velocity service's rate), against the core without it
// ("bench <scalar> sun <instructions>": what a head with a Sun term adds to
// its solution's correction).
// The self-calibration's lag search (calib/lag_search.hpp, the out-of-line
// entry of firmware/app/lag_search_entry_*.cpp) per fed cycle at 11 Hz
// (the loop's feed every 2nd cycle), the selected records as heads A, B and
// C corrected with Table 2, against a function that only reads a status
// ("bench <scalar> lag_search <instructions>"; lag_search_ram, its sizeof).
// The self-calibration's Sun-term learner (calib/sun_learner.hpp, double:
// software floating point on both targets; the out-of-line entry of
// firmware/app/sun_learner_entry.cpp) on the default 5640 s orbit in 2026,
// the combination fixture's three heads on a bench turning once per orbit:
// per cycle taken, the mean take over three orbits (the cycles that close an
// orbit included) against a function that only reads an attitude; per orbit
// closed, its solve's steps each timed alone, as idle time runs them between
// cycles ("bench double sun_learner_<figure> <n>": take, steps, solve (their
// sum), worst_step, ram, sizeof(SunLearner), interval_us, the DPU's
// kSunLearnOnBoardIntervalUs, and orbit_s). Its cycles are an interval
// apart (each taken: one per interval), at the 11 Hz feed's phase in it.
// Output: one line per figure, "bench <scalar> <stage> <instructions>".
#include <cmath>
#include <cstdint>
#include <cstdio>

#include "ascorr/core/fixed_point.hpp"
#include "baseline.hpp"
#include "board.hpp"
#include "combination_fixture.hpp"
#include "combine_entry.hpp"
#include "core_entry.hpp"
#include "earth_series_entry.hpp"
#include "lag_entry.hpp"
#include "lag_search_entry.hpp"
#include "sun_entry.hpp"
#include "sun_learner_entry.hpp"
#include "systick_counter.hpp"
#include "vector_convert.hpp"

namespace {

using namespace ascorr;
using namespace ascorr::target;
namespace board = ascorr::app::board;
using ascorr::bench::counts;
using ascorr::bench::instructions_per_count;

constexpr std::uint32_t kInputs = 32;
constexpr std::uint32_t kRuns = 2048;  // per figure; the longest block (baseline) stays below 2^24 counts

VectorRecord g_records[kInputs];
volatile std::uint16_t g_sink_status;  // results are stored, so that calls cannot be dropped
volatile double g_sink_q;
ModelRecord g_model_records[kModels];

template <typename T>
struct Fixture {
    SolutionInput<T> in[kInputs];
    ThermalModel<T> model[kModels];  // 0: Table 2 (linear), 1: random with quadratic terms
};

template <typename T>
using CoreFn = CorrectedSolution<T> (*)(const SolutionInput<T>&, const CorrectionConfig<T>&) noexcept;

template <typename T>
__attribute__((noinline)) CorrectedSolution<T> copy_only(const SolutionInput<T>& in,
                                                         const CorrectionConfig<T>& /*cfg*/) noexcept {
    return {in.q_chu_icrf, 0U};
}

template <typename T>
__attribute__((noinline)) CorrectedSolution<T> core(const SolutionInput<T>& in,
                                                    const CorrectionConfig<T>& cfg) noexcept {
    return app::correct(in, cfg);
}

template <typename T>
std::uint32_t run(volatile CoreFn<T> fn, const Fixture<T>& fx, const CorrectionConfig<T>& cfg) {
    return counts([&] {
        for (std::uint32_t i = 0; i < kRuns; ++i) {
            g_sink_status = fn(fx.in[i % kInputs], cfg).status;
        }
    });
}

void report(const char* scalar, const char* stage, std::uint32_t c, std::uint32_t c0, std::uint32_t ipc) {
    const std::uint32_t per = ((c - c0) * ipc + kRuns / 2U) / kRuns;
    std::printf("bench %s %s %u\n", scalar, stage, static_cast<unsigned>(per));
}

template <typename T>
void bench_scalar(const char* name, Fixture<T>& fx, std::uint32_t ipc) {
    // The selected records are fully valid (temperatures, velocity, head < 3).
    for (std::uint32_t m = 0; m < kModels; ++m) {
        fx.model[m] = to_core_model<T>(g_model_records[m]);
    }
    for (std::uint32_t i = 0; i < kInputs; ++i) {
        fx.in[i] = to_core_input<T>(g_records[i]);
    }
    const CorrectionConfig<T> both{true, &fx.model[0]};
    const CorrectionConfig<T> aberration{true, nullptr};
    const CorrectionConfig<T> thermal{false, &fx.model[0]};
    const CorrectionConfig<T> both_quadratic{true, &fx.model[1]};
    const CorrectionConfig<T> thermal_quadratic{false, &fx.model[1]};
    const CorrectionConfig<T> neither{false, nullptr};
    const std::uint32_t c0 = run<T>(&copy_only<T>, fx, both);
    report(name, "both", run<T>(&core<T>, fx, both), c0, ipc);
    report(name, "aberration", run<T>(&core<T>, fx, aberration), c0, ipc);
    report(name, "thermal", run<T>(&core<T>, fx, thermal), c0, ipc);
    report(name, "both_quadratic", run<T>(&core<T>, fx, both_quadratic), c0, ipc);
    report(name, "thermal_quadratic", run<T>(&core<T>, fx, thermal_quadratic), c0, ipc);
    report(name, "neither", run<T>(&core<T>, fx, neither), c0, ipc);
}

using BaselineFn = bench::BaselineOutput (*)(const bench::BaselineInput&, const bench::BaselineModel*, bool);

__attribute__((noinline)) bench::BaselineOutput baseline_copy(const bench::BaselineInput& in,
                                                              const bench::BaselineModel* /*model*/, bool /*ab*/) {
    return {{in.q[0], in.q[1], in.q[2], in.q[3]}};
}

__attribute__((noinline)) bench::BaselineOutput baseline(const bench::BaselineInput& in,
                                                         const bench::BaselineModel* model, bool ab) {
    return bench::baseline_correct(in, model, ab);
}

bench::BaselineInput g_baseline_in[kInputs];
bench::BaselineModel g_baseline_model[kModels];

std::uint32_t run_baseline(volatile BaselineFn fn, const bench::BaselineModel* model, bool ab) {
    return counts([&] {
        for (std::uint32_t i = 0; i < kRuns; ++i) {
            g_sink_q = fn(g_baseline_in[i % kInputs], model, ab).q[0];
        }
    });
}

void bench_baseline(std::uint32_t ipc) {
    for (std::uint32_t m = 0; m < kModels; ++m) {
        for (std::uint32_t h = 0; h < kMaxHeads; ++h) {
            g_baseline_model[m].present[h] = g_model_records[m].present[h] != 0U;
            for (std::uint32_t a = 0; a < 3; ++a) {
                for (std::uint32_t c = 0; c < 7; ++c) {
                    g_baseline_model[m].coefficient[h][a][c] = g_model_records[m].coefficient[h][a][c];
                }
            }
        }
    }
    for (std::uint32_t i = 0; i < kInputs; ++i) {
        const VectorRecord& r = g_records[i];
        g_baseline_in[i] = {{r.q[0], r.q[1], r.q[2], r.q[3]},
                            r.head,
                            {r.temperature[0], r.temperature[1], r.temperature[2]},
                            true,
                            {r.beta[0], r.beta[1], r.beta[2]},
                            r.inv_sun_distance_au,
                            true};
    }
    const std::uint32_t c0 = run_baseline(&baseline_copy, &g_baseline_model[0], true);
    report("baseline", "both", run_baseline(&baseline, &g_baseline_model[0], true), c0, ipc);
    report("baseline", "aberration", run_baseline(&baseline, nullptr, true), c0, ipc);
    report("baseline", "thermal", run_baseline(&baseline, &g_baseline_model[0], false), c0, ipc);
    report("baseline", "both_quadratic", run_baseline(&baseline, &g_baseline_model[1], true), c0, ipc);
    report("baseline", "thermal_quadratic", run_baseline(&baseline, &g_baseline_model[1], false), c0, ipc);
}

// Earth series: one evaluation per call, at epochs spread evenly over the span.
constexpr std::uint32_t kSeriesRuns = 256;  // ~60k instructions each: the block stays below 2^24 counts
double g_series_t[kSeriesRuns];
volatile double g_sink_series;

using SeriesFn = bool (*)(double, EarthBarycentric&) noexcept;

__attribute__((noinline)) bool series_copy(double t, EarthBarycentric& out) noexcept {
    out.v_earth_icrf_kms.x = t;
    return true;
}

std::uint32_t run_series(volatile SeriesFn fn) {
    return counts([&] {
        for (std::uint32_t i = 0; i < kSeriesRuns; ++i) {
            EarthBarycentric out{};
            g_sink_status = static_cast<std::uint16_t>(fn(g_series_t[i], out));
            g_sink_series = out.v_earth_icrf_kms.x;
        }
    });
}

void bench_series(std::uint32_t ipc) {
    const double step = (kEarthSeriesLastTt - kEarthSeriesFirstTt) / kSeriesRuns;
    for (std::uint32_t i = 0; i < kSeriesRuns; ++i) {
        g_series_t[i] = kEarthSeriesFirstTt + (static_cast<double>(i) + 0.5) * step;
    }
    const std::uint32_t c0 = run_series(&series_copy);
    const std::uint32_t c = run_series(&app::earth_series_entry);
    const std::uint32_t per = ((c - c0) * ipc + kSeriesRuns / 2U) / kSeriesRuns;
    std::printf("bench double earth_series %u\n", static_cast<unsigned>(per));
}

// The combination: one epoch of three heads per call.
template <typename T>
using CombineFn = combine::CombinedAttitude<T> (*)(const combine::Combiner<T>&, const combine::HeadAttitude<T>*,
                                                   std::uint8_t) noexcept;

template <typename T>
__attribute__((noinline)) combine::CombinedAttitude<T> combine_copy(const combine::Combiner<T>& /*c*/,
                                                                    const combine::HeadAttitude<T>* heads,
                                                                    std::uint8_t /*n*/) noexcept {
    return {heads[0].q_chu_icrf, 0U, 0U, 0U, 0U, 0U};
}

template <typename T>
__attribute__((noinline)) combine::CombinedAttitude<T> combine_call(const combine::Combiner<T>& c,
                                                                    const combine::HeadAttitude<T>* heads,
                                                                    std::uint8_t n) noexcept {
    return app::combine_epoch(c, heads, n);
}

template <typename T>
struct CombinationFixture {
    combine::HeadAttitude<T> epoch[kInputs][bench::kCombinationHeads];
};

template <typename T>
std::uint32_t run_combination(volatile CombineFn<T> fn, const combine::Combiner<T>& c,
                              const CombinationFixture<T>& fx) {
    return counts([&] {
        for (std::uint32_t i = 0; i < kRuns; ++i) {
            g_sink_status = fn(c, fx.epoch[i % kInputs], bench::kCombinationHeads).status;
        }
    });
}

// The double combination of the benchmark's mountings, on the target (its
// tables built in software double at start, as the flight loop's).
const combine::Combiner<double> g_combiner_double{bench::combination_mountings()};

// The largest angle (arcsec) between c's combination of each fixture epoch
// and the double combination of the same inputs widened to double.
template <typename T>
double largest_combination_error(const combine::Combiner<T>& c, const CombinationFixture<T>& fx) {
    using Tr = ScalarTraits<T>;
    const auto widen = [](const Quaternion<T>& q) {
        return Quaternion<double>{Tr::to_double(q.w), Tr::to_double(q.x), Tr::to_double(q.y), Tr::to_double(q.z)};
    };
    double worst = 0.0;
    for (std::uint32_t i = 0; i < kInputs; ++i) {
        combine::HeadAttitude<double> wide[bench::kCombinationHeads];
        for (std::uint8_t h = 0; h < bench::kCombinationHeads; ++h) {
            wide[h] = {widen(fx.epoch[i][h].q_chu_icrf), h, true};
        }
        const Quaternion<double> a = widen(c.combine(fx.epoch[i], bench::kCombinationHeads).q_crf_icrf);
        const Quaternion<double> b = g_combiner_double.combine(wide, bench::kCombinationHeads).q_crf_icrf;
        const Quaternion<double> d = conjugate(a) * b;
        const double angle = 2.0 * std::atan2(std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z), std::fabs(d.w));
        worst = std::fmax(worst, angle * kRadToArcsec);
    }
    return worst;
}

template <typename T>
void bench_combination(const char* name, const combine::Combiner<T>& c, CombinationFixture<T>& fx, std::uint32_t ipc) {
    using Tr = ScalarTraits<T>;
    const combine::Mountings m = bench::combination_mountings();
    std::uint32_t state = 1U;
    for (std::uint32_t i = 0; i < kInputs; ++i) {
        const double* q = g_records[i].q;
        Quaternion<double> heads[bench::kCombinationHeads];
        bench::combination_epoch(m, {q[0], q[1], q[2], q[3]}, &state, heads);
        for (std::uint8_t h = 0; h < bench::kCombinationHeads; ++h) {
            fx.epoch[i][h] = {{Tr::from_double(heads[h].w), Tr::from_double(heads[h].x), Tr::from_double(heads[h].y),
                               Tr::from_double(heads[h].z)},
                              h,
                              true};
        }
        if (c.combine(fx.epoch[i], bench::kCombinationHeads).status != combine::combined_status::kTwoOrMoreHeads) {
            std::printf("bench: %s combination epoch %u not combined from three heads\n", name,
                        static_cast<unsigned>(i));
        }
    }
    const std::uint32_t c0 = run_combination<T>(&combine_copy<T>, c, fx);
    report(name, "combination", run_combination<T>(&combine_call<T>, c, fx), c0, ipc);
    // The largest error against the double combination of the same inputs
    // (the float decision: 0.06″ worst; Q30: 0.01″), in nano-arcsec.
    const double e = largest_combination_error(c, fx) * 1e9 + 0.5;  // clamped: never a wrapped small figure
    std::printf("bench %s combination_error_nanoarcsec %u\n", name,
                static_cast<unsigned>(e < 4294967295.0 ? e : 4294967295.0));
}

// The lag stage: one solution per call, in the entry's order of arguments
// (lag_entry.hpp).
template <typename T>
using LagFn = void (*)(pipeline::HeadLags<T>&, HeadTemperatures<T>&, std::int64_t, std::uint8_t) noexcept;

template <typename T>
__attribute__((noinline)) void lag_copy(pipeline::HeadLags<T>& /*lags*/, HeadTemperatures<T>& temps,
                                        std::int64_t /*t_us*/, std::uint8_t /*head*/) noexcept {
    temps.t_032 = temps.t_chu;
}

template <typename T>
__attribute__((noinline)) void lag_call(pipeline::HeadLags<T>& lags, HeadTemperatures<T>& temps, std::int64_t t_us,
                                        std::uint8_t head) noexcept {
    app::lag(lags, head, t_us, temps);
}

// kRuns solutions from the epoch after `epoch` on (22 Hz, millisecond tags).
template <typename T>
std::uint32_t run_lag(volatile LagFn<T> fn, pipeline::HeadLags<T>& lags, const Fixture<T>& fx, std::uint32_t& epoch) {
    return counts([&] {
        for (std::uint32_t i = 0; i < kRuns; ++i) {
            const std::uint32_t e = epoch + i / 3U;
            const std::int64_t t_us = std::int64_t{e} * 1000 / 22 * 1000;
            HeadTemperatures<T> temps = fx.in[i % kInputs].temperatures;
            fn(lags, temps, t_us, static_cast<std::uint8_t>(i % 3U));
            g_sink_status = static_cast<std::uint16_t>(temps.t_chu.valid ? 1U : 0U);
        }
        epoch += kRuns / 3U + 1U;
    });
}

template <typename T>
void bench_lag(const char* name, const Fixture<T>& fx, std::uint32_t ipc) {
    static pipeline::HeadLags<T> lags;
    for (std::uint8_t h = 0; h < 3; ++h) {
        (void)lags.configure(h, 900.0);
    }
    std::uint32_t epoch = 0U;
    (void)run_lag<T>(&lag_call<T>, lags, fx, epoch);  // warm-up: every channel started and in step
    const std::uint32_t c0 = run_lag<T>(&lag_copy<T>, lags, fx, epoch);
    report(name, "lag", run_lag<T>(&lag_call<T>, lags, fx, epoch), c0, ipc);
}

// The Sun term: one solution per call, the core with it against the core.
template <typename T>
using SunFn = CorrectedSolution<T> (*)(const SolutionInput<T>&, const CorrectionConfig<T>&,
                                       const SunTermInput<T>&) noexcept;

template <typename T>
__attribute__((noinline)) CorrectedSolution<T> sun_without(const SolutionInput<T>& in, const CorrectionConfig<T>& cfg,
                                                           const SunTermInput<T>& /*sun*/) noexcept {
    return app::correct(in, cfg);
}

template <typename T>
__attribute__((noinline)) CorrectedSolution<T> sun_with(const SolutionInput<T>& in, const CorrectionConfig<T>& cfg,
                                                        const SunTermInput<T>& sun) noexcept {
    return app::correct(in, cfg, sun);
}

template <typename T>
std::uint32_t run_sun(volatile SunFn<T> fn, const Fixture<T>& fx, const SunTermInput<T>& sun) {
    const CorrectionConfig<T> both{true, &fx.model[0]};
    return counts([&] {
        for (std::uint32_t i = 0; i < kRuns; ++i) {
            g_sink_status = fn(fx.in[i % kInputs], both, sun).status;
        }
    });
}

template <typename T>
void bench_sun(const char* name, const Fixture<T>& fx, std::uint32_t ipc) {
    using S = ScalarTraits<T>;
    static SunTermModel<T> m{};
    for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
        m.present[h] = true;
        for (std::uint8_t a = 0; a < kModelAxes; ++a) {
            for (std::uint8_t c = 0; c < kSunComponents; ++c) {
                const double arcsec = ((h * 9 + a * 3 + c) % 5 - 2.0) * 0.8 + 0.3;  // within ±2″, none 0
                m.coefficient[h][a][c] = S::from_double(arcsec * kArcsecToRad);
            }
        }
    }
    const SunTermInput<T> sun{&m, {S::from_double(0.6), S::from_double(-0.64), S::from_double(0.48)}, true};  // unit
    const std::uint32_t c0 = run_sun<T>(&sun_without<T>, fx, sun);
    report(name, "sun", run_sun<T>(&sun_with<T>, fx, sun), c0, ipc);
}

// The Sun learner takes one cycle per interval, the first fed in it: the
// cycles of its bench are an interval apart, each at the 11 Hz feed's phase
// in it (a Δt that varies by up to 91 ms, as on board).
std::int64_t learner_cycle_us(std::int64_t k) {
    return k * calib::kSunLearnOnBoardIntervalUs + (k * 45'454) % 90'909;
}

// The lag search: one fed cycle per take at 11 Hz (the loop's feed every
// 2nd cycle), the frame heads corrected with Table 2 (each record's input
// as head A, B and C in turn).
constexpr std::uint32_t kLagSearchCycles = 64;
constexpr std::int64_t kLagSearchCycleUs = 1'000'000 / 11;

template <typename T>
struct LagSearchFixture {
    CorrectedSolution<T> corrected[kInputs][calib::kFrameHeads];
    HeadTemperatures<T> temperatures[kInputs][calib::kFrameHeads];
};

template <typename T>
using LagSearchFn = bool (*)(calib::LagSearch<T>&, std::int64_t, const ThermalModel<T>&, const CorrectedSolution<T>*,
                             const HeadTemperatures<T>* const*) noexcept;

template <typename T>
__attribute__((noinline)) bool lag_search_copy(calib::LagSearch<T>& /*search*/, std::int64_t t_us,
                                               const ThermalModel<T>& /*model*/, const CorrectedSolution<T>* corrected,
                                               const HeadTemperatures<T>* const* /*temperatures*/) noexcept {
    g_sink_status = corrected[0].status;
    return t_us > 0;
}

template <typename T>
__attribute__((noinline)) bool lag_search_call(calib::LagSearch<T>& search, std::int64_t t_us,
                                               const ThermalModel<T>& model, const CorrectedSolution<T>* corrected,
                                               const HeadTemperatures<T>* const* temperatures) noexcept {
    return app::lag_search_take(search, t_us, model, corrected, temperatures);
}

// kLagSearchCycles takes from cycle *cycle on; the takes that scored.
template <typename T>
std::uint32_t run_lag_search(volatile LagSearchFn<T> fn, calib::LagSearch<T>& search, const ThermalModel<T>& model,
                             const LagSearchFixture<T>& fx, std::int64_t& cycle, std::uint32_t& scored) {
    return counts([&] {
        for (std::uint32_t i = 0; i < kLagSearchCycles; ++i, ++cycle) {
            const std::uint32_t k = i % kInputs;
            const HeadTemperatures<T>* tp[calib::kFrameHeads] = {&fx.temperatures[k][0], &fx.temperatures[k][1],
                                                                 &fx.temperatures[k][2]};
            const std::int64_t t_us = 820'800'000'000'000 + cycle * kLagSearchCycleUs;
            scored += fn(search, t_us, model, fx.corrected[k], tp) ? 1U : 0U;
        }
    });
}

template <typename T>
void bench_lag_search(const char* name, const Fixture<T>& fx, LagSearchFixture<T>& lf, std::uint32_t ipc) {
    static calib::LagSearch<T> search{calib::EstimatorConfig{}};
    const CorrectionConfig<T> both{true, &fx.model[0]};
    for (std::uint32_t k = 0; k < kInputs; ++k) {
        for (std::uint8_t h = 0; h < calib::kFrameHeads; ++h) {
            SolutionInput<T> in = fx.in[k];
            in.head = h;
            lf.corrected[k][h] = app::correct(in, both);
            lf.temperatures[k][h] = in.temperatures;
        }
    }
    std::int64_t cycle = 0;
    std::uint32_t scored = 0U;
    (void)run_lag_search<T>(&lag_search_call<T>, search, fx.model[0], lf, cycle, scored);  // warm-up: lags started
    scored = 0U;
    const std::uint32_t c = run_lag_search<T>(&lag_search_call<T>, search, fx.model[0], lf, cycle, scored);
    std::uint32_t none = 0U;
    const std::uint32_t c0 = run_lag_search<T>(&lag_search_copy<T>, search, fx.model[0], lf, cycle, none);
    std::printf("bench %s lag_search %u\n", name,
                static_cast<unsigned>(((c - c0) * ipc + kLagSearchCycles / 2U) / kLagSearchCycles));
    std::printf("bench %s lag_search_ram %u\n", name, static_cast<unsigned>(sizeof(calib::LagSearch<T>)));
    if (scored != kLagSearchCycles) {
        std::printf("bench: %s lag search scored %u of %u cycles\n", name, static_cast<unsigned>(scored),
                    static_cast<unsigned>(kLagSearchCycles));
    }
}

// The Sun term's learner: one fed cycle per take, one idle step per step.
constexpr std::int64_t kLearnerOrbitUs = calib::EstimatorConfig{}.orbit_period_us;
constexpr std::uint32_t kLearnerCycles = kLearnerOrbitUs / calib::kSunLearnOnBoardIntervalUs;  // an orbit
// The first orbit's solve starts from the identity, the others warm (the
// one before's basis: sun_moments.hpp), as on board between its cold ones.
constexpr std::uint32_t kLearnerOrbits = 8;                          // the first closed by the second's first take
Quaternion<double> g_learner_q[kLearnerCycles][calib::kFrameHeads];  // the orbit's: its own noise

using TakeFn = bool (*)(calib::SunLearner&, std::int64_t, const Quaternion<double> (&)[calib::kFrameHeads]) noexcept;
using StepFn = bool (*)(calib::SunLearner&) noexcept;

__attribute__((noinline)) bool take_copy(calib::SunLearner& /*learner*/, std::int64_t t_us,
                                         const Quaternion<double> (&q)[calib::kFrameHeads]) noexcept {
    g_sink_q = q[0].w;
    return t_us > 0;
}

__attribute__((noinline)) bool step_none(calib::SunLearner& /*learner*/) noexcept {
    return false;
}

calib::SunLearner g_learner{calib::EstimatorConfig{}, calib::kSunLearnOnBoardIntervalUs};

// SysTick counts of fn over the orbit's cycles [first, end).
std::uint32_t run_takes(volatile TakeFn fn, std::int64_t t0_us, std::uint32_t first, std::uint32_t end) {
    return counts([&] {
        for (std::uint32_t i = first; i < end; ++i) {
            g_sink_status = fn(g_learner, t0_us + learner_cycle_us(i), g_learner_q[i]) ? 1U : 0U;
        }
    });
}
// ... less the same loop over take_copy's (the loop's and the inputs' cost).
std::uint32_t run_takes_net(std::int64_t t0_us, std::uint32_t first, std::uint32_t end) {
    const std::uint32_t c = run_takes(&app::sun_learner_take, t0_us, first, end);
    return c - run_takes(&take_copy, t0_us, first, end);
}

// SysTick counts of one call of fn (a step).
std::uint32_t run_step(volatile StepFn fn, bool& more) {
    return counts([&] { more = fn(g_learner); });
}

struct SolveCost {
    std::uint32_t steps = 0;
    std::uint32_t total = 0;  // SysTick counts
    std::uint32_t worst = 0;
};

SolveCost run_solve() {
    SolveCost c;
    bool more = false;
    const std::uint32_t c0 = run_step(&step_none, more);
    for (int i = 0; i < calib::SunLearner::kMaxSolveSteps; ++i) {
        const std::uint32_t n = run_step(&app::sun_learner_step, more) - c0;
        if (!more) {
            break;
        }
        ++c.steps;
        c.total += n;
        c.worst = n > c.worst ? n : c.worst;
    }
    return c;
}

// One orbit's frame heads: the bench turning once about a fixed axis, each
// head with its own noise (state: the noise generator's, continued from
// orbit to orbit, so that the sums change as a mission's do).
void learner_orbit(const combine::Mountings& m, std::uint32_t& state) {
    const double* q0 = g_records[0].q;
    for (std::uint32_t i = 0; i < kLearnerCycles; ++i) {
        const double phase =
            2.0 * kPi * static_cast<double>(learner_cycle_us(i)) / static_cast<double>(kLearnerOrbitUs);
        const Quaternion<double> q_crf_icrf =
            bench::axis_angle(0.0, 0.6, 0.8, phase) * Quaternion<double>{q0[0], q0[1], q0[2], q0[3]};
        Quaternion<double> heads[bench::kCombinationHeads];
        bench::combination_epoch(m, q_crf_icrf, &state, heads);
        for (std::uint8_t h = 0; h < calib::kFrameHeads; ++h) {
            g_learner_q[i][h] = heads[h];
        }
    }
}

void bench_sun_learner(std::uint32_t ipc) {
    const combine::Mountings m = bench::combination_mountings();
    std::uint32_t state = 7U;
    const std::int64_t start_us = 820'000'000'000'000;  // TT µs since J2000: 2026
    const std::int64_t t0_us = start_us - start_us % kLearnerOrbitUs;
    std::uint64_t takes = 0;
    SolveCost cold;
    std::uint64_t warm = 0;  // SysTick counts of the warm solves
    std::uint32_t warm_steps = 0;
    std::uint32_t worst = 0;
    // Each orbit's first take closes the one before; its solve runs in
    // idle time before the next take (which would otherwise settle it).
    for (std::uint32_t o = 0; o < kLearnerOrbits; ++o) {
        learner_orbit(m, state);
        const std::int64_t t_us = t0_us + std::int64_t{o} * kLearnerOrbitUs;
        const std::uint32_t first = run_takes_net(t_us, 0U, 1U);
        if (o > 0U) {
            const SolveCost c = run_solve();  // the orbit closed by this one's first take
            worst = c.worst > worst ? c.worst : worst;
            cold = o == 1U ? c : cold;
            warm += o > 1U ? c.total : 0U;
            warm_steps += o > 1U ? c.steps : 0U;
        }
        const std::uint32_t rest = run_takes_net(t_us, 1U, kLearnerCycles);
        takes += o > 0U ? first + rest : 0U;
    }
    const std::uint64_t n = std::uint64_t{kLearnerCycles} * (kLearnerOrbits - 1U);
    constexpr std::uint32_t kWarm = kLearnerOrbits - 2U;
    const std::uint64_t warm_solve = (warm * ipc + kWarm / 2U) / kWarm;
    const std::uint64_t warm_mean_steps = (warm_steps + kWarm / 2U) / kWarm;
    // Per orbit on board: of kWarmSolves solves, one from the identity.
    constexpr std::uint64_t kRun = calib::SunMoments<calib::kFrameHeads>::kWarmSolves;
    const std::uint64_t per_orbit = (std::uint64_t{cold.total} * ipc + (kRun - 1U) * warm_solve + kRun / 2U) / kRun;
    const std::uint64_t steps = (cold.steps + (kRun - 1U) * warm_mean_steps + kRun / 2U) / kRun;
    std::printf("bench double sun_learner_take %u\n", static_cast<unsigned>((takes * ipc + n / 2U) / n));
    std::printf("bench double sun_learner_steps %u\n", static_cast<unsigned>(steps));
    std::printf("bench double sun_learner_solve %u\n", static_cast<unsigned>(per_orbit));
    std::printf("bench double sun_learner_cold_solve %u\n", static_cast<unsigned>(cold.total * ipc));
    std::printf("bench double sun_learner_cold_steps %u\n", static_cast<unsigned>(cold.steps));
    std::printf("bench double sun_learner_warm_solve %u\n", static_cast<unsigned>(warm_solve));
    std::printf("bench double sun_learner_warm_steps %u\n", static_cast<unsigned>(warm_mean_steps));
    std::printf("bench double sun_learner_warm_solves %u\n", static_cast<unsigned>(kRun));
    std::printf("bench double sun_learner_worst_step %u\n", static_cast<unsigned>(worst * ipc));
    std::printf("bench double sun_learner_ram %u\n", static_cast<unsigned>(sizeof(calib::SunLearner)));
    std::printf("bench double sun_learner_interval_us %u\n", static_cast<unsigned>(calib::kSunLearnOnBoardIntervalUs));
    std::printf("bench double sun_learner_orbit_s %u\n", static_cast<unsigned>(kLearnerOrbitUs / 1'000'000));
    const calib::SunLearnReport r = g_learner.report();
    if (!r.candidate.solved || r.thinned != 0U || r.without_sun != 0U || r.not_finite != 0U || r.late != 0U) {
        std::puts(
            "bench: the Sun learner's bench did not take every cycle, solved no candidate or left a take a solve");
    }
}

Fixture<Q30> g_fixed;
LagSearchFixture<Q30> g_lag_search_fixed;
combine::Combiner<Q30> g_combiner_fixed{bench::combination_mountings()};
CombinationFixture<Q30> g_combination_fixed;
#if !defined(ASCORR_TARGET_FIXED)
Fixture<float> g_float;
LagSearchFixture<float> g_lag_search_float;
combine::Combiner<float> g_combiner_float{bench::combination_mountings()};
CombinationFixture<float> g_combination_float;
#endif

}  // namespace

int main() {
    std::FILE* f = std::fopen("vectors.bin", "rb");
    static VectorHeader header;
    if (f == nullptr || std::fread(&header, sizeof header, 1, f) != 1 || header.magic != kVectorMagic) {
        std::fputs("bench: cannot read vectors.bin\n", stderr);
        return 1;
    }
    std::uint32_t n = 0;
    for (std::uint32_t i = 0; i < header.count && n < kInputs; ++i) {
        VectorRecord r{};
        if (std::fread(&r, sizeof r, 1, f) != 1) {
            break;
        }
        // Random inputs that every configuration corrects fully (the bad
        // inputs of the set take shorter paths and are left out).
        const double n2 = r.q[0] * r.q[0] + r.q[1] * r.q[1] + r.q[2] * r.q[2] + r.q[3] * r.q[3];
        const bool good = r.model == 1U && r.temperature_valid == 7U && r.velocity_valid != 0U && r.head < 3U &&
                          n2 < 1.0 + 1e-9 && n2 > 1.0 - 1e-9 && r.temperature[1] < 200.0 && r.temperature[2] < 200.0 &&
                          r.beta[0] < 1e-3 && r.beta[1] < 1e-3 && r.beta[0] > -1e-3 && r.beta[1] > -1e-3;
        if (good) {
            g_records[n++] = r;
        }
    }
    std::fclose(f);
    if (n != kInputs) {
        std::fputs("bench: not enough inputs in vectors.bin\n", stderr);
        return 1;
    }
    for (std::uint32_t m = 0; m < kModels; ++m) {
        g_model_records[m] = header.model[m];
    }
    const std::uint32_t ipc = instructions_per_count();
    std::printf("bench calibration %u instructions per SysTick count\n", static_cast<unsigned>(ipc));
#if !defined(ASCORR_TARGET_FIXED)
    bench_scalar<float>("float", g_float, ipc);
    bench_lag<float>("float", g_float, ipc);
    bench_sun<float>("float", g_float, ipc);
    bench_lag_search<float>("float", g_float, g_lag_search_float, ipc);
    bench_combination<float>("float", g_combiner_float, g_combination_float, ipc);
#endif
    bench_scalar<Q30>("fixed", g_fixed, ipc);
    bench_lag<Q30>("fixed", g_fixed, ipc);
    bench_sun<Q30>("fixed", g_fixed, ipc);
    bench_lag_search<Q30>("fixed", g_fixed, g_lag_search_fixed, ipc);
    bench_combination<Q30>("fixed", g_combiner_fixed, g_combination_fixed, ipc);
    bench_baseline(ipc);
    bench_series(ipc);
    bench_sun_learner(ipc);
    return 0;
}
