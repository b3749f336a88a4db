// bench/host_bench.cpp: the host figures of toolchain/run-target-bench.
//
//   ascorr_host_bench DIR RUNS
// reads DIR/vectors.bin (tests/target_vectors.cpp), takes its first 32 fully
// correctable random inputs (as bench/target_bench.cpp does) and corrects
// RUNS solutions in each extern "C" function ascorr_bench_<scalar>_<stage>
// (double, float, fixed core; the baseline of bench/baseline.hpp), and RUNS
// copies in ascorr_bench_overhead. Run under valgrind --tool=callgrind, the
// inclusive instruction count of each function minus the overhead's, over
// RUNS, is the host's instructions per solution. The combined attitude
// (ascorr/combine/) is measured the same way per epoch of three heads
// (bench/combination_fixture.hpp) in ascorr_bench_<scalar>_combination,
// against ascorr_bench_combination_overhead (copies). It also prints the
// baseline's largest difference from the double core over all 2000+ inputs:
// "baseline_max_error_arcsec x".
#include <Eigen/Geometry>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "ascorr/ascorr.hpp"
#include "baseline.hpp"
#include "combination_fixture.hpp"
#include "target/vector_convert.hpp"

namespace {

using namespace ascorr;
using namespace ascorr::target;

constexpr std::size_t kInputs = 32;
std::uint32_t g_runs = 0;
std::vector<VectorRecord> g_records;
ModelRecord g_model_records[kModels];

template <typename T>
struct Fixture {
    SolutionInput<T> in[kInputs];
    ThermalModel<T> model[kModels];
};

template <typename T>
Fixture<T> make_fixture() {
    Fixture<T> fx{};
    for (std::size_t m = 0; m < kModels; ++m) {
        fx.model[m] = to_core_model<T>(g_model_records[m]);
    }
    for (std::size_t i = 0; i < kInputs; ++i) {
        fx.in[i] = to_core_input<T>(g_records[i]);  // fully valid records (selected below)
    }
    return fx;
}

// The whole result is kept (in memory, as the compiler must assume it is
// read): with only the status kept, the compiler drops every computation the
// status does not depend on, e.g. all of the aberration stage in Q30.
template <typename T>
inline void keep(const T& value) {
    __asm__ volatile("" : : "m"(value) : "memory");
}

template <typename T>
__attribute__((noinline)) void run_core(const Fixture<T>& fx, const CorrectionConfig<T>& cfg) {
    for (std::uint32_t i = 0; i < g_runs; ++i) {
        const CorrectedSolution<T> r = correct_solution(fx.in[i % kInputs], cfg);
        keep(r);
    }
}

bench::BaselineInput g_baseline_in[kInputs];
bench::BaselineModel g_baseline_model[kModels];

bench::BaselineInput baseline_input(const VectorRecord& r) {
    return {{r.q[0], r.q[1], r.q[2], r.q[3]},
            r.head,
            {r.temperature[0], r.temperature[1], r.temperature[2]},
            r.temperature_valid == 7U,
            {r.beta[0], r.beta[1], r.beta[2]},
            r.inv_sun_distance_au,
            r.velocity_valid != 0U};
}

__attribute__((noinline)) void run_baseline(const bench::BaselineModel* model, bool ab) {
    volatile double sink = 0.0;
    for (std::uint32_t i = 0; i < g_runs; ++i) {
        sink = bench::baseline_correct(g_baseline_in[i % kInputs], model, ab).q[0];
    }
    (void)sink;
}

Fixture<double> g_double;
Fixture<float> g_float;
Fixture<Q30> g_fixed;

// The combination: kInputs epochs of three heads per scalar, the combiner
// built once from the fixture's mountings.
template <typename T>
struct CombinationFixture {
    combine::HeadAttitude<T> epoch[kInputs][bench::kCombinationHeads];
};

template <typename T>
CombinationFixture<T> make_combination_fixture() {
    using Tr = ScalarTraits<T>;
    CombinationFixture<T> fx{};
    const combine::Mountings m = bench::combination_mountings();
    std::uint32_t state = 1U;
    for (std::size_t i = 0; i < kInputs; ++i) {
        const double* q = g_records[i].q;
        Quaternion<double> heads[bench::kCombinationHeads];
        bench::combination_epoch(m, {q[0], q[1], q[2], q[3]}, &state, heads);
        for (std::uint8_t h = 0; h < bench::kCombinationHeads; ++h) {
            fx.epoch[i][h] = {{Tr::from_double(heads[h].w), Tr::from_double(heads[h].x), Tr::from_double(heads[h].y),
                               Tr::from_double(heads[h].z)},
                              h,
                              true};
        }
    }
    return fx;
}

template <typename T>
__attribute__((noinline)) void run_combination(const combine::Combiner<T>& c, const CombinationFixture<T>& fx) {
    for (std::uint32_t i = 0; i < g_runs; ++i) {
        const combine::CombinedAttitude<T> r = c.combine(fx.epoch[i % kInputs], bench::kCombinationHeads);
        keep(r);
    }
}

template <typename T>
void run_stages(const Fixture<T>& fx, int stage) {
    const CorrectionConfig<T> cfg[] = {
        {true, &fx.model[0]}, {true, nullptr}, {false, &fx.model[0]}, {true, &fx.model[1]}, {false, &fx.model[1]}};
    run_core(fx, cfg[stage]);
}

void run_baseline_stage(int stage) {
    const bench::BaselineModel* m[] = {&g_baseline_model[0], nullptr, &g_baseline_model[0], &g_baseline_model[1],
                                       &g_baseline_model[1]};
    const bool ab[] = {true, true, false, true, false};
    run_baseline(m[stage], ab[stage]);
}

}  // namespace

// One function per figure, for callgrind's inclusive counts.
#define ASCORR_BENCH_STAGES(scalar, call)                                                   \
    extern "C" __attribute__((noinline)) void ascorr_bench_##scalar##_both() {              \
        call(0);                                                                            \
    }                                                                                       \
    extern "C" __attribute__((noinline)) void ascorr_bench_##scalar##_aberration() {        \
        call(1);                                                                            \
    }                                                                                       \
    extern "C" __attribute__((noinline)) void ascorr_bench_##scalar##_thermal() {           \
        call(2);                                                                            \
    }                                                                                       \
    extern "C" __attribute__((noinline)) void ascorr_bench_##scalar##_both_quadratic() {    \
        call(3);                                                                            \
    }                                                                                       \
    extern "C" __attribute__((noinline)) void ascorr_bench_##scalar##_thermal_quadratic() { \
        call(4);                                                                            \
    }

#define ASCORR_CALL_DOUBLE(s) run_stages(g_double, s)
#define ASCORR_CALL_FLOAT(s) run_stages(g_float, s)
#define ASCORR_CALL_FIXED(s) run_stages(g_fixed, s)
#define ASCORR_CALL_BASELINE(s) run_baseline_stage(s)
ASCORR_BENCH_STAGES(double, ASCORR_CALL_DOUBLE)
ASCORR_BENCH_STAGES(float, ASCORR_CALL_FLOAT)
ASCORR_BENCH_STAGES(fixed, ASCORR_CALL_FIXED)
ASCORR_BENCH_STAGES(baseline, ASCORR_CALL_BASELINE)

const combine::Combiner<double> g_combiner_double{bench::combination_mountings()};
const combine::Combiner<float> g_combiner_float{bench::combination_mountings()};
const combine::Combiner<Q30> g_combiner_fixed{bench::combination_mountings()};
CombinationFixture<double> g_combination_double;
CombinationFixture<float> g_combination_float;
CombinationFixture<Q30> g_combination_fixed;

extern "C" __attribute__((noinline)) void ascorr_bench_double_combination() {
    run_combination(g_combiner_double, g_combination_double);
}
extern "C" __attribute__((noinline)) void ascorr_bench_float_combination() {
    run_combination(g_combiner_float, g_combination_float);
}
extern "C" __attribute__((noinline)) void ascorr_bench_fixed_combination() {
    run_combination(g_combiner_fixed, g_combination_fixed);
}
extern "C" __attribute__((noinline)) void ascorr_bench_combination_overhead() {
    for (std::uint32_t i = 0; i < g_runs; ++i) {
        const combine::CombinedAttitude<Q30> r{
            g_combination_fixed.epoch[i % kInputs][0].q_chu_icrf, 0U, 0U, 0U, 0U, 0U};
        keep(r);
    }
}

extern "C" __attribute__((noinline)) void ascorr_bench_overhead() {
    for (std::uint32_t i = 0; i < g_runs; ++i) {
        const CorrectedSolution<Q30> r{g_fixed.in[i % kInputs].q_chu_icrf, 0U};
        keep(r);
    }
}

int main(int argc, char** argv) {
    if (argc != 3) {
        std::fputs("usage: ascorr_host_bench DIR RUNS\n", stderr);
        return 2;
    }
    g_runs = static_cast<std::uint32_t>(std::stoul(argv[2]));
    std::ifstream f(std::string(argv[1]) + "/vectors.bin", std::ios::binary);
    VectorHeader header{};
    f.read(reinterpret_cast<char*>(&header), sizeof header);
    if (!f || header.magic != kVectorMagic) {
        std::fputs("ascorr_host_bench: cannot read vectors.bin\n", stderr);
        return 1;
    }
    std::vector<VectorRecord> all(header.count);
    f.read(reinterpret_cast<char*>(all.data()), static_cast<std::streamsize>(all.size() * sizeof(VectorRecord)));
    for (const VectorRecord& r : all) {
        const double n2 = r.q[0] * r.q[0] + r.q[1] * r.q[1] + r.q[2] * r.q[2] + r.q[3] * r.q[3];
        const bool good = r.model == 1U && r.temperature_valid == 7U && r.velocity_valid != 0U && r.head < 3U &&
                          std::fabs(n2 - 1.0) < 1e-9 && std::fabs(r.temperature[1]) < 200.0 &&
                          std::fabs(r.temperature[2]) < 200.0 && std::fabs(r.beta[0]) < 1e-3 &&
                          std::fabs(r.beta[1]) < 1e-3;
        if (good && g_records.size() < kInputs) {
            g_records.push_back(r);
        }
    }
    if (g_records.size() != kInputs) {
        std::fputs("ascorr_host_bench: not enough inputs\n", stderr);
        return 1;
    }
    for (std::size_t m = 0; m < kModels; ++m) {
        g_model_records[m] = header.model[m];
        for (std::size_t h = 0; h < kMaxHeads; ++h) {
            g_baseline_model[m].present[h] = header.model[m].present[h] != 0U;
            for (std::size_t a = 0; a < 3; ++a) {
                for (std::size_t c = 0; c < 7; ++c) {
                    g_baseline_model[m].coefficient[h][a][c] = header.model[m].coefficient[h][a][c];
                }
            }
        }
    }
    for (std::size_t i = 0; i < kInputs; ++i) {
        g_baseline_in[i] = baseline_input(g_records[i]);
    }
    g_double = make_fixture<double>();
    g_float = make_fixture<float>();
    g_fixed = make_fixture<Q30>();
    g_combination_double = make_combination_fixture<double>();
    g_combination_float = make_combination_fixture<float>();
    g_combination_fixed = make_combination_fixture<Q30>();
    ascorr_bench_combination_overhead();
    ascorr_bench_double_combination();
    ascorr_bench_float_combination();
    ascorr_bench_fixed_combination();

    ascorr_bench_overhead();
    ascorr_bench_double_both();
    ascorr_bench_double_aberration();
    ascorr_bench_double_thermal();
    ascorr_bench_double_both_quadratic();
    ascorr_bench_double_thermal_quadratic();
    ascorr_bench_float_both();
    ascorr_bench_float_aberration();
    ascorr_bench_float_thermal();
    ascorr_bench_float_both_quadratic();
    ascorr_bench_float_thermal_quadratic();
    ascorr_bench_fixed_both();
    ascorr_bench_fixed_aberration();
    ascorr_bench_fixed_thermal();
    ascorr_bench_fixed_both_quadratic();
    ascorr_bench_fixed_thermal_quadratic();
    ascorr_bench_baseline_both();
    ascorr_bench_baseline_aberration();
    ascorr_bench_baseline_thermal();
    ascorr_bench_baseline_both_quadratic();
    ascorr_bench_baseline_thermal_quadratic();

    // The baseline against the double core, every input and configuration it
    // corrects alike (same rules for missing inputs; no domain checks).
    double worst = 0.0;
    const ThermalModel<double>* models[kModels] = {&g_double.model[0], &g_double.model[1]};
    for (const VectorRecord& r : all) {
        const double n2 = r.q[0] * r.q[0] + r.q[1] * r.q[1] + r.q[2] * r.q[2] + r.q[3] * r.q[3];
        if (!(std::fabs(n2 - 1.0) < 1e-9) || r.head >= 3U || !(std::fabs(r.temperature[1]) < 200.0) ||
            !(std::fabs(r.temperature[2]) < 200.0) || !(std::fabs(r.beta[0]) < 1e-3) ||
            !(std::fabs(r.beta[1]) < 1e-3)) {
            continue;
        }
        SolutionInput<double> in{};
        in.q_chu_icrf = {r.q[0], r.q[1], r.q[2], r.q[3]};
        in.head = static_cast<std::uint8_t>(r.head);
        const bool tv = r.temperature_valid == 7U;
        in.temperatures = {{r.temperature[0], tv}, {r.temperature[1], tv}, {r.temperature[2], tv}};
        in.velocity = {{r.beta[0], r.beta[1], r.beta[2]}, r.inv_sun_distance_au, r.velocity_valid != 0U};
        const auto ref = correct_solution(in, CorrectionConfig<double>{true, models[r.model]});
        const bench::BaselineModel* bm = &g_baseline_model[r.model];
        const auto got = bench::baseline_correct(baseline_input(r), bm, true);
        const Eigen::Quaterniond d =
            Eigen::Quaterniond(ref.q_chu_icrf.w, ref.q_chu_icrf.x, ref.q_chu_icrf.y, ref.q_chu_icrf.z).conjugate() *
            Eigen::Quaterniond(got.q[0], got.q[1], got.q[2], got.q[3]);
        worst = std::max(worst, 2.0 * std::asin(std::min(1.0, d.vec().norm())) * kRadToArcsec);
    }
    std::printf("baseline_max_error_arcsec %.3g\n", worst);
    return 0;
}
