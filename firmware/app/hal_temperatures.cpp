// firmware/app/hal_temperatures.cpp: the flight loop's temperatures
// (temperature_source.hpp) through the HAL's acquisition on the boom
// thermistors (boom_temperatures.hpp), timed by SysTick.
//
// Time for settle waits and staleness is SysTick's (SysTickClock).
#include <cstdint>

#include "board.hpp"
#include "boom_temperatures.hpp"
#include "loop_rate.hpp"
#include "temperature_source.hpp"

namespace ascorr::app {
namespace {

constexpr std::uint32_t kPeriod = board::kCoreClockHz / kRateHz;  // SysTick reload + 1, as main.cpp
constexpr std::uint32_t kCountsPerUs = board::kCoreClockHz / 1000000U;

// Microseconds on SysTick. now_us: the cycle's start plus the time elapsed in
// it, never decreasing. wait_us: counts SysTick decrements across reloads; it
// reads the counter far more often than once per period, so no reload is
// missed, and it gives up after a fixed number of reads (a stopped timer must
// not hang the loop).
class SysTickClock final : public hal::Clock {
public:
    void start_cycle(std::uint32_t cycle) noexcept {
        base_us_ = static_cast<std::uint64_t>(cycle) * 1000000U / kRateHz;
    }
    std::uint64_t now_us() noexcept override {
        const std::uint32_t elapsed = (kPeriod - 1U - board::systick_value()) / kCountsPerUs;
        const std::uint64_t t = base_us_ + elapsed;
        last_us_ = t > last_us_ ? t : last_us_;
        return last_us_;
    }
    void wait_us(std::uint32_t us) noexcept override {
        const std::uint64_t need = static_cast<std::uint64_t>(us) * kCountsPerUs;
        std::uint64_t done = 0U;
        std::uint32_t prev = board::systick_value();
        for (std::uint64_t reads = 0U; done < need && reads < need + 1000000U; ++reads) {
            const std::uint32_t now = board::systick_value();
            done += prev >= now ? prev - now : prev + (kPeriod - now);
            prev = now;
        }
    }

private:
    std::uint64_t base_us_ = 0U;
    std::uint64_t last_us_ = 0U;
};

SysTickClock g_clock;
BoomTemperatures g_temperatures{g_clock};

}  // namespace

void temperatures_update(std::uint32_t cycle) noexcept {
    g_clock.start_cycle(cycle);
    g_temperatures.update(cycle, kRateHz);
}

const HeadTemperatures<Scalar>& temperatures_of(std::uint8_t head) noexcept {
    return g_temperatures.of(head);
}

StatusBits temperatures_merge_status(std::uint8_t head, StatusBits core) noexcept {
    return g_temperatures.merge_status(head, core);
}

}  // namespace ascorr::app
