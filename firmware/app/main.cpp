// firmware/app/main.cpp: the flight correction loop.
//
// Conventions: SysTick raises an exception at kRateHz = 22 Hz; each cycle the
// loop refreshes the temperatures (temperature_source.hpp), takes the GNSS
// states that arrived (gnss_feed.hpp) into the velocity service
// (velocity_service.hpp: frame conversion and propagation in double, bounded
// per cycle), then corrects one raw solution per camera head with the core in
// the build's scalar (app_scalar.hpp), the model in flash (flight_data.hpp)
// and the observer velocity the service gives for that solution's own time
// (velocity_entry.hpp), and keeps the corrected solutions for telemetry. Every
// loop has a fixed trip count; the only wait is for the next tick. The work
// of a cycle is measured in SysTick counts (core clocks; under QEMU's -icount
// shift=0, 40 instructions each). Overruns are counted honestly: a cycle whose
// work outlasts its period is one, and every further tick that passes before
// the next cycle starts is one more (a period without its cycle). The wait for
// the tick masks interrupts between its check and WFI (board.hpp,
// sleep_until_changed), so a tick can never slip in between and cost a whole
// period unseen. ASCORR_APP_CYCLES > 0 ends the run after that many cycles with a
// report and exit status 0 (no overrun) or 1; 0 runs forever (flight).
#include <cstdint>
#include <cstring>

#include "app_scalar.hpp"
#include "board.hpp"
#include "core_entry.hpp"
#include "flight_data.hpp"
#include "gnss_feed.hpp"
#include "report.hpp"
#include "temperature_source.hpp"
#include "velocity_entry.hpp"

#ifndef ASCORR_APP_CYCLES
#define ASCORR_APP_CYCLES 0
#endif

namespace ascorr::app {
namespace {

constexpr std::uint32_t kRateHz = 22U;
constexpr std::uint32_t kPeriod = board::kCoreClockHz / kRateHz;  // 1136363 < 2^24
constexpr std::uint32_t kCycles = ASCORR_APP_CYCLES;

volatile std::uint32_t g_ticks = 0U;

// The velocity service: at most 4 RK4 steps per call of advance() (one per
// 10 s of flight is the steady state), the default 6 h horizon.
constexpr VelocityServiceConfig kServiceConfig{kDefaultHorizonUs, kDefaultTtMinusUt1Us, 4U};
VelocityService<Scalar> g_service{kServiceConfig};
GnssFeed g_gnss;
CorrectedSolution<Scalar> g_corrected[kMaxHeads];  // latest corrected solution per head

// A head's solution time in cycle `cycle`: the tick's time minus a per-head
// exposure offset (heads 5 ms apart), TT µs. Integer: no time in the scalar.
constexpr std::int64_t kHeadOffsetUs = 5000;
TtTime solution_time(std::uint32_t cycle, std::uint8_t head) noexcept {
    const std::int64_t tick = kLoopStartTtUs + static_cast<std::int64_t>(cycle) * 1000000LL / kRateHz;
    return {tick - static_cast<std::int64_t>(kMaxHeads - head) * kHeadOffsetUs};
}

// SysTick counts spent in each part (40 instructions each under QEMU).
struct Cost {
    std::uint32_t calls;
    std::uint32_t total;
    std::uint32_t worst;
    void add(std::uint32_t c) noexcept {
        ++calls;
        total += c;
        worst = c > worst ? c : worst;
    }
};
struct VelocityCosts {
    Cost states;   // push_state: checks + ITRF → GCRS (double)
    Cost advance;  // advance() calls that built a node (force, RK4 steps, Earth series; double)
    Cost query;    // velocity_at(): the per-solution query (scalar)
    Cost correct;  // the core, for comparison
    std::uint32_t refused;
};
VelocityCosts g_costs{};

// Each part of the service measured once before the loop (SysTick counts),
// for the steady-state figure: the 16 s run is dominated by its start.
struct Calibration {
    std::uint32_t earth_series;  // one evaluation of the Earth series
    std::uint32_t rk4_step;      // one propagation step (4 force evaluations)
    std::uint32_t node;          // a node from a fresh state, Earth grid loaded
};
Calibration g_cal{};
volatile double g_sink;

std::uint32_t now_counts() noexcept {
    return board::systick_value();
}
std::uint32_t since(std::uint32_t start) noexcept {  // SysTick counts down; no wrap within a cycle
    return start - board::systick_value();
}

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

// The GNSS states due by the cycle's first solution: at most two per cycle
// (the receiver's rate is 1 Hz; a late one is taken next cycle).
// One GNSS state per kStateIntervalUs is enough: 10 s of propagation adds
// ≤ 0.5 m/s (velocity_service.hpp), and each state costs a frame conversion
// and a node in software double. The others are skipped and counted (a state
// going back in time still reaches the service, which refuses and counts it).
constexpr std::int64_t kStateIntervalUs = 10 * kMicrosecondsPerSecond;
std::uint32_t g_states_skipped = 0U;

void take_states(std::uint32_t cycle) noexcept {
    GnssState s{};
    for (int i = 0; i < 2 && g_gnss.poll(solution_time(cycle, 0U), s); ++i) {
        if (g_service.has_state() && g_service.state_time() < s.t &&
            s.t.us - g_service.state_time().us < kStateIntervalUs) {
            ++g_states_skipped;
            continue;
        }
        const std::uint32_t start = now_counts();
        if (g_service.push_state(s.t, s.r_itrf_km, s.v_itrf_kms, StateFrame::kItrf) != StateVerdict::kAccepted) {
            ++g_costs.refused;
        }
        g_costs.states.add(since(start));
    }
}

void calibrate() noexcept {
    const RecordedState& r0 = kRecordedOrbit[0];
    EarthBarycentric e{};
    std::uint32_t start = now_counts();
    earth_series(static_cast<double>(r0.t_tt_us) * 1e-6, e);
    g_cal.earth_series = since(start);
    g_sink = e.v_earth_icrf_kms.x;
    const Vector3<double> pole{0.0, 0.0, 1.0};
    const OrbitState y{{6838.0, 0.0, 0.0}, {0.0, 0.35, 7.6}};
    const Vector3<double> a = gravity_j2(y.r_km, pole);
    start = now_counts();
    const OrbitState y1 = rk4_step(y, a, pole, kPropagationStepS);
    g_cal.rk4_step = since(start);
    g_sink = y1.v_kms.z;
    VelocityService<Scalar> svc{kServiceConfig};
    const TtTime t0{r0.t_tt_us};
    svc.push_state(t0, {r0.r_itrf_km[0], r0.r_itrf_km[1], r0.r_itrf_km[2]},
                   {r0.v_itrf_kms[0], r0.v_itrf_kms[1], r0.v_itrf_kms[2]}, StateFrame::kItrf);
    svc.advance(t0, OnBoardEarth{});  // loads the Earth grid
    svc.push_state({t0.us + 1}, {r0.r_itrf_km[0], r0.r_itrf_km[1], r0.r_itrf_km[2]},
                   {r0.v_itrf_kms[0], r0.v_itrf_kms[1], r0.v_itrf_kms[2]}, StateFrame::kItrf);
    start = now_counts();
    svc.advance({t0.us + 1}, OnBoardEarth{});
    g_cal.node = since(start);
    g_sink = static_cast<double>(svc.nodes_built());
}

void correct_all_heads(std::uint32_t cycle) noexcept {
    const CorrectionConfig<Scalar> cfg{true, &kThermalModel};
    for (std::uint8_t h = 0; h < kMaxHeads; ++h) {  // fixed trip count
        const TtTime t = solution_time(cycle, h);
        std::uint32_t start = now_counts();
        const std::uint32_t nodes_before = g_service.nodes_built();
        g_service.advance(t, OnBoardEarth{});  // a no-op while t is in the current node
        if (g_service.nodes_built() != nodes_before) {
            g_costs.advance.add(since(start));
        }
        start = now_counts();
        const ServiceVelocity<Scalar> v = velocity_query(g_service, t);
        g_costs.query.add(since(start));
        const SolutionInput<Scalar> in{kRawAttitude[h], h, temperatures_of(h), v.velocity};
        start = now_counts();
        g_corrected[h] = correct(in, cfg);
        g_costs.correct.add(since(start));
        g_corrected[h].status = with_service_status(g_corrected[h].status, v.status, cfg.aberration);
        g_corrected[h].status = temperatures_merge_status(h, g_corrected[h].status);
        const StatusBits st = g_corrected[h].status;
        g_stats.status_union[h] = static_cast<StatusBits>(g_stats.status_union[h] | st);
        if (st == (status::kAberrationApplied | status::kThermalApplied)) {
            ++g_stats.applied[h];
        }
    }
}

void cost(const char* name, const Cost& c) noexcept {
    using namespace report;
    text(name);
    text(" calls ");
    u32(c.calls);
    text(" instructions total ");
    u32(c.total * 40U);
    text(" worst ");
    u32(c.worst * 40U);
    text(" mean ");
    u32(c.calls == 0U ? 0U : (c.total * 40U + c.calls / 2U) / c.calls);
    text("\n");
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
    text("velocity service: states accepted ");
    u32(g_service.counts().accepted);
    text(" refused ");
    u32(g_costs.refused);
    text(", velocity nodes ");
    u32(g_service.nodes_built());
    text(", RK4 steps ");
    u32(g_service.steps_taken());
    text(" (SysTick counts x 40 = instructions under QEMU -icount)\n");
    cost("  state update", g_costs.states);
    cost("  propagation (node)", g_costs.advance);
    cost("  query", g_costs.query);
    cost("  correction", g_costs.correct);
    const std::uint32_t service = g_costs.states.total + g_costs.advance.total + g_costs.query.total;
    text("this run, per cycle: velocity service ");
    u32(g_stats.cycles == 0U ? 0U : service * 40U / g_stats.cycles);
    text(" instructions, correction of the heads ");
    u32(g_stats.cycles == 0U ? 0U : g_costs.correct.total * 40U / g_stats.cycles);
    text(" (states skipped ");
    u32(g_states_skipped);
    text(")\n");
    text("parts: Earth series ");
    u32(g_cal.earth_series * 40U);
    text(", RK4 step ");
    u32(g_cal.rk4_step * 40U);
    text(", node from a fresh state ");
    u32(g_cal.node * 40U);
    text(", state update ");
    u32(g_costs.states.calls == 0U ? 0U : g_costs.states.total * 40U / g_costs.states.calls);
    text(", query ");
    const std::uint32_t query = g_costs.query.calls == 0U ? 0U : (g_costs.query.total * 40U) / g_costs.query.calls;
    u32(query);
    text(" instructions\n");
    // Steady state, three heads: a state and a node per 10 s (220 cycles), the
    // Earth series per minute (1320 cycles), three queries per cycle.
    const std::uint32_t per_state = g_costs.states.worst;  // an accepted state (a refused one costs less)
    const std::uint32_t amortised =
        ((per_state + g_cal.node) * 40U + 110U) / 220U + (g_cal.earth_series * 40U + 660U) / 1320U + 3U * query;
    const std::uint32_t correction3 =
        g_costs.correct.calls == 0U ? 0U : 3U * ((g_costs.correct.total * 40U) / g_costs.correct.calls);
    text("steady state, three heads, per cycle: velocity service ");
    u32(amortised);
    text(" instructions, correction ");
    u32(correction3);
    text(amortised <= correction3 ? " (service within the correction's cost)\n"
                                  : " (service above the correction's cost)\n");
}

}  // namespace
}  // namespace ascorr::app

extern "C" void arm_systick_isr() {
    ascorr::app::g_ticks = ascorr::app::g_ticks + 1U;
}

int main() {
    using namespace ascorr::app;
    board::systick_start(kPeriod, true);
    calibrate();
    std::uint32_t seen = g_ticks;
    for (std::uint32_t cycle = 0U; kCycles == 0U || cycle < kCycles; ++cycle) {
        board::sleep_until_changed(g_ticks, seen);  // the next 22 Hz tick (race-free: board.hpp)
        const std::uint32_t start = g_ticks;
        // Ticks that passed while the previous cycle overran: each is a period
        // without its cycle, counted as an overrun (below, the overrunning
        // cycle itself is counted once).
        if (start - seen > 1U) {
            g_stats.overruns += start - seen - 1U;
        }
        seen = start;
        temperatures_update(cycle);
        take_states(cycle);
        correct_all_heads(cycle);
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
