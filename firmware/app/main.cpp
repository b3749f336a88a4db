// firmware/app/main.cpp: the flight correction loop.
//
// Conventions: SysTick raises an exception at kRateHz = 22 Hz; each cycle the
// loop refreshes the temperatures (temperature_source.hpp), then corrects one
// raw solution per camera head with the core in the build's scalar
// (app_scalar.hpp) and the model and velocity in static storage
// (flight_data.hpp), and keeps the corrected solutions for telemetry. Every
// loop has a fixed trip count; the only wait is for the next tick. The work
// of a cycle is measured in SysTick counts (core clocks; under QEMU's -icount
// shift=0, 40 instructions each) and an overrun (work longer than a period) is
// counted. ASCORR_APP_CYCLES > 0 ends the run after that many cycles with a
// report and exit status 0 (no overrun) or 1; 0 runs forever (flight).
#include <cstdint>
#include <cstring>

#include "app_scalar.hpp"
#include "board.hpp"
#include "core_entry.hpp"
#include "flight_data.hpp"
#include "report.hpp"
#include "temperature_source.hpp"

#ifndef ASCORR_APP_CYCLES
#define ASCORR_APP_CYCLES 0
#endif

namespace ascorr::app {
namespace {

constexpr std::uint32_t kRateHz = 22U;
constexpr std::uint32_t kPeriod = board::kCoreClockHz / kRateHz;  // 1136363 < 2^24
constexpr std::uint32_t kCycles = ASCORR_APP_CYCLES;

volatile std::uint32_t g_ticks = 0U;

ObserverVelocity<Scalar> g_velocity = kInitialVelocity;  // refreshed by the ephemeris owner
CorrectedSolution<Scalar> g_corrected[kMaxHeads];        // latest corrected solution per head

struct Statistics {
    std::uint32_t cycles;
    std::uint32_t overruns;
    std::uint32_t worst_busy;            // SysTick counts
    std::uint32_t applied[kMaxHeads];    // cycles with both corrections applied
    StatusBits status_union[kMaxHeads];  // every status bit seen per head
};
Statistics g_stats{};

[[maybe_unused]] std::uint32_t bits_of(Q30 x) {
    return static_cast<std::uint32_t>(x.raw);
}
[[maybe_unused]] std::uint32_t bits_of(float x) {
    std::uint32_t u = 0U;
    std::memcpy(&u, &x, sizeof u);
    return u;
}

void correct_all_heads() noexcept {
    const CorrectionConfig<Scalar> cfg{true, &kThermalModel};
    for (std::uint8_t h = 0; h < kMaxHeads; ++h) {  // fixed trip count
        const SolutionInput<Scalar> in{kRawAttitude[h], h, temperatures_of(h), g_velocity};
        g_corrected[h] = correct(in, cfg);
        g_corrected[h].status = temperatures_merge_status(h, g_corrected[h].status);
        const StatusBits st = g_corrected[h].status;
        g_stats.status_union[h] = static_cast<StatusBits>(g_stats.status_union[h] | st);
        if (st == (status::kAberrationApplied | status::kThermalApplied)) {
            ++g_stats.applied[h];
        }
    }
}

void print_report() noexcept {
    using namespace report;
    text(ASCORR_APP_SCALAR_NAME " core, ");
    u32(g_stats.cycles);
    text(" cycles at 22 Hz, overruns ");
    u32(g_stats.overruns);
    text(", worst cycle ");
    u32(g_stats.worst_busy);
    text(" SysTick counts of ");
    u32(kPeriod);
    text("\n");
    for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
        const Quaternion<Scalar>& q = g_corrected[h].q_chu_icrf;
        text("head ");
        u32(h);
        text(": applied ");
        u32(g_stats.applied[h]);
        text(" status seen ");
        u32(g_stats.status_union[h]);
        text(" last q ");
        hex32(bits_of(q.w));
        text(" ");
        hex32(bits_of(q.x));
        text(" ");
        hex32(bits_of(q.y));
        text(" ");
        hex32(bits_of(q.z));
        text("\n");
    }
}

}  // namespace
}  // namespace ascorr::app

extern "C" void arm_systick_isr() {
    ascorr::app::g_ticks = ascorr::app::g_ticks + 1U;
}

int main() {
    using namespace ascorr::app;
    board::systick_start(kPeriod, true);
    std::uint32_t seen = g_ticks;
    for (std::uint32_t cycle = 0U; kCycles == 0U || cycle < kCycles; ++cycle) {
        while (g_ticks == seen) {  // until the next 22 Hz tick
            board::wait_for_interrupt();
        }
        seen = g_ticks;
        temperatures_update(cycle);
        correct_all_heads();
        const std::uint32_t busy = kPeriod - 1U - board::systick_value();
        if (g_ticks != seen) {
            ++g_stats.overruns;
        } else if (busy > g_stats.worst_busy) {
            g_stats.worst_busy = busy;
        }
        ++g_stats.cycles;
    }
    print_report();
    return g_stats.overruns == 0U ? 0 : 1;
}
