// firmware/app/main.cpp: the flight correction loop.
//
// Conventions: SysTick raises an exception at kRateHz = 22 Hz; each cycle the
// loop refreshes the temperatures (temperature_source.hpp), takes the GNSS
// states that arrived (gnss_feed.hpp) into the velocity service
// (velocity_service.hpp: frame conversion and propagation in double, bounded
// per cycle), then corrects one raw solution per camera head with the core in
// the build's scalar (app_scalar.hpp), the on-board estimator's active model
// (starting from the one in flash, flight_data.hpp; flight_bench.hpp)
// and the observer velocity the service gives for that solution's own time
// (velocity_entry.hpp), and keeps the corrected solutions for telemetry (the
// cycle's computation: flight_cycle.hpp, shared with the host's prediction of
// this loop's output, tests/target/flight_expectation.cpp). Every
// loop has a fixed trip count; the only wait is for the next tick. The work
// of a cycle is measured in SysTick counts (core clocks; under QEMU's -icount
// shift=0, 40 instructions each). Overruns are counted honestly: a cycle whose
// work outlasts its period is one, and every further tick that passes before
// the next cycle starts is one more (a period without its cycle). The wait for
// the tick masks interrupts between its check and WFI (board.hpp,
// sleep_until_changed), so a tick can never slip in between and cost a whole
// period unseen. ASCORR_APP_CYCLES > 0 ends the run after that many cycles with a
// report (with the solutions' record: samples and CRC-32C per head,
// flight_cycle.hpp, and the stack's high-water mark, stack_watch.hpp) and exit
// status 0 (no overrun, the stack within its size) or 1; 0 runs forever
// (flight).
#include <cstdint>

#include "app_scalar.hpp"
#include "board.hpp"
#include "flight_cycle.hpp"
#include "report.hpp"
#include "stack_watch.hpp"

#ifndef ASCORR_APP_CYCLES
#define ASCORR_APP_CYCLES 0
#endif

namespace ascorr::app {
namespace {

constexpr std::uint32_t kPeriod = board::kCoreClockHz / kRateHz;  // 1136363 < 2^24
constexpr std::uint32_t kCycles = ASCORR_APP_CYCLES;

volatile std::uint32_t g_ticks = 0U;
std::uint32_t g_cycle_tick = 0U;  // g_ticks when the current cycle began
// Idle steps (the Sun learner's solve) run while more than this is left of
// the period: an eighth, some 8 of its worst steps (docs/figures.md).
constexpr std::uint32_t kIdleReserve = kPeriod / 8U;

FlightCycle g_flight;  // the service, the GNSS feed, the solutions and their record (flight_cycle.hpp)

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
    Cost states;       // push_state: checks + ITRF → GCRS (double)
    Cost advance;      // advance() calls that built a node (force, RK4 steps, Earth series; double)
    Cost query;        // velocity_at(): the per-solution query (scalar)
    Cost correct;      // the core, for comparison
    Cost calib_cycle;  // the estimator's per-cycle part (two calls per cycle: the model, the feed)
    Cost calib_step;   // one step() of the estimator's per-orbit update (idle time)
    Cost combine;      // the cycle's combined attitude (combine_entry.hpp)
    Cost sun_take;     // the Sun learner's take of a fed cycle (its settle included)
    Cost sun_step;     // one step of the Sun learner's solve (idle time)
};
VelocityCosts g_costs{};

std::uint32_t now_counts() noexcept {
    return board::systick_value();
}
std::uint32_t since(std::uint32_t start) noexcept {  // SysTick counts down; no wrap within a cycle
    return start - board::systick_value();
}

// flight_cycle.hpp's Meter: SysTick counts per part.
struct SysTickMeter {
    std::uint32_t now() noexcept { return now_counts(); }
    void add(Part part, std::uint32_t start) noexcept {
        const std::uint32_t c = since(start);
        switch (part) {
            case Part::kState:
                g_costs.states.add(c);
                break;
            case Part::kNode:
                g_costs.advance.add(c);
                break;
            case Part::kQuery:
                g_costs.query.add(c);
                break;
            case Part::kCorrect:
                g_costs.correct.add(c);
                break;
            case Part::kCalibCycle:
                g_costs.calib_cycle.add(c);
                break;
            case Part::kCalibStep:
                g_costs.calib_step.add(c);
                break;
            case Part::kCombine:
                g_costs.combine.add(c);
                break;
            case Part::kSunTake:
                g_costs.sun_take.add(c);
                break;
            case Part::kSunStep:
                g_costs.sun_step.add(c);
                break;
        }
    }
    // Room for an idle step: the cycle's tick is the current one, and more
    // than kIdleReserve counts are left before the next (SysTick counts down).
    // SysTick first: read after a reload whose tick is already counted it
    // would claim the next period's time.
    bool idle_room() noexcept {
        const std::uint32_t left = board::systick_value();
        return g_ticks == g_cycle_tick && left > kIdleReserve;
    }
};
SysTickMeter g_meter;

// Each part of the service measured once before the loop (SysTick counts),
// for the steady-state figure: the 16 s run is dominated by its start.
struct Calibration {
    std::uint32_t earth_series;  // one evaluation of the Earth series
    std::uint32_t rk4_step;      // one propagation step (4 force evaluations)
    std::uint32_t node;          // a node from a fresh state, Earth grid loaded
};
Calibration g_cal{};
volatile double g_sink;

struct Statistics {
    std::uint32_t cycles;
    std::uint32_t overruns;
    std::uint32_t worst_busy;  // SysTick counts
};
Statistics g_stats{};

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

void cost(const char* name, const Cost& c) noexcept {
    using namespace report;
    text(name);
    text(" calls ");
    u32(c.calls);
    text(" instructions total ");
    u64(std::uint64_t{c.total} * 40U);  // a long run's idle steps pass 2^32
    text(" worst ");
    u32(c.worst * 40U);
    text(" mean ");
    u32(c.calls == 0U ? 0U : (c.total * 40U + c.calls / 2U) / c.calls);
    text("\n");
}

// The estimator: its state, its per-cycle cost (the mean of this run; the
// worst cycle: at most two calls, so the worst call twice bounds it) against
// the correction's own in this loop (four heads per cycle) and of three heads,
// its per-orbit update and its RAM.
void print_estimator(std::uint32_t correction3) noexcept {
    using namespace report;
    const calib::EstimatorReport r = g_flight.estimator().report();
    text("self-calibration: orbits used ");
    u32(r.orbits_used);
    text(" short ");
    u32(r.orbits_short);
    text(" held ");
    u32(r.orbits_held);
    text(" late ");
    u32(r.orbits_late);
    text(", refusals few orbits ");
    u32(r.refusals[static_cast<std::size_t>(calib::Refusal::kFewOrbits)]);
    text(" condition ");
    u32(r.refusals[static_cast<std::size_t>(calib::Refusal::kCondition)]);
    text(" angle ");
    u32(r.refusals[static_cast<std::size_t>(calib::Refusal::kAngleLimit)]);
    text(" no gain ");
    u32(r.refusals[static_cast<std::size_t>(calib::Refusal::kNoGain)]);
    text(", active version ");
    u32(r.active_version);
    text(" crc32c ");
    hex32(r.active_crc);
    text("\n");
    cost("  estimator per cycle (model, feed)", g_costs.calib_cycle);
    cost("  estimator per-orbit step (idle)", g_costs.calib_step);
    const std::uint32_t per_cycle =
        g_stats.cycles == 0U ? 0U : (g_costs.calib_cycle.total * 40U + g_stats.cycles / 2U) / g_stats.cycles;
    const std::uint32_t worst_cycle = 2U * g_costs.calib_cycle.worst * 40U;
    const std::uint32_t orbits = r.orbits_used + r.orbits_short + r.orbits_held;
    text("estimator: per cycle ");
    u32(per_cycle);
    text(" instructions (worst ");
    u32(worst_cycle);
    text("), per orbit ");
    u32(orbits == 0U ? 0U : (g_costs.calib_step.total * 40U + orbits / 2U) / orbits);
    text(" instructions in ");
    u32(orbits == 0U ? 0U : (g_costs.calib_step.calls + orbits / 2U) / orbits);
    text(" idle steps (worst step ");
    u32(g_costs.calib_step.worst * 40U);
    text("), RAM ");
    u32(static_cast<std::uint32_t>(sizeof(FlightEstimator<Scalar>)));
    const std::uint32_t correction =
        g_stats.cycles == 0U ? 0U : (g_costs.correct.total * 40U + g_stats.cycles / 2U) / g_stats.cycles;
    text(" bytes; correction per cycle ");
    u32(correction);
    text(" (three heads ");
    u32(correction3);
    text(per_cycle <= correction ? ") (estimator within the correction's cost)\n"
                                 : ") (estimator above the correction's cost)\n");
}

// "combination calls N ..." and the combination's cost per cycle of the
// bench's heads (instructions under QEMU -icount), with its tables' RAM.
void print_combination() noexcept {
    using namespace report;
    cost("  combination", g_costs.combine);
    text("combination: per cycle ");
    u32(g_costs.combine.calls == 0U ? 0U : (g_costs.combine.total * 40U) / g_costs.combine.calls);
    text(" instructions (worst ");
    u32(g_costs.combine.worst * 40U);
    text("), tables ");
    u32(static_cast<std::uint32_t>(sizeof(combine::Combiner<Scalar>)));
    text(" bytes\n");
}

// The Sun-term learner in the loop: what it took and solved (the line the
// host's prediction checks: "sun learner: ..."), then its costs and RAM.
void print_sun_learner() noexcept {
    using namespace report;
    const calib::SunLearnReport r = g_flight.sun_learner().report();
    print_sun_learner_state(r);
    cost("  sun learner take", g_costs.sun_take);
    cost("  sun learner idle step", g_costs.sun_step);
    text("sun learner: takes settled late ");
    u32(static_cast<std::uint32_t>(r.late));
    text(" (most steps ");
    u32(static_cast<std::uint32_t>(r.late_steps));
    text("), RAM ");
    u32(static_cast<std::uint32_t>(sizeof(calib::SunLearner)));
    text(" bytes\n");
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
    g_flight.record().print_heads();
    text("velocity service: states accepted ");
    u32(g_flight.service().counts().accepted);
    text(" refused ");
    u32(g_flight.states_refused());
    text(", velocity nodes ");
    u32(g_flight.service().nodes_built());
    text(", RK4 steps ");
    u32(g_flight.service().steps_taken());
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
    u32(g_flight.states_skipped());
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
    print_estimator(correction3);
    print_combination();
    print_sun_learner();
}

// "stack: high water N of S bytes" (stack_watch.hpp), measured after the
// run and its report; true when within the stack.
bool print_stack() noexcept {
    using namespace report;
    const std::uint32_t used = stack_watch::high_water();
    text("stack: high water ");
    u32(used);
    text(" of ");
    u32(stack_watch::size());
    text(" bytes\n");
    return used <= stack_watch::size();
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
        g_cycle_tick = start;
        g_flight.run(cycle, g_meter, kCycles != 0U);  // temperatures, states, heads (, record: a test run)
        const std::uint32_t busy = kPeriod - 1U - board::systick_value();
        g_flight.learn_in_idle(g_meter);  // the period's rest, less kIdleReserve: not in `busy`
        if (g_ticks != seen) {
            ++g_stats.overruns;
        } else if (busy > g_stats.worst_busy) {
            g_stats.worst_busy = busy;
        }
        ++g_stats.cycles;
    }
    print_report();
    g_flight.record().print_solutions();
    g_flight.history().print();
    const bool stack_within = print_stack();
    return g_stats.overruns == 0U && stack_within ? 0 : 1;
}
