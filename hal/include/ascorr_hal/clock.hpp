// ascorr_hal/clock.hpp: the time source of the HAL, injectable.
//
// Conventions:
//  - Time is a monotonic count of microseconds (std::uint64_t), with an
//    arbitrary origin; only differences matter.
//  - Every settle time, staleness and rate check uses this interface, never a
//    wall clock, so tests drive time deterministically (ManualClock).
//  - Freestanding: the firmware provides its own implementation (a timer).
#pragma once

#include <cstdint>
#include "interface.hpp"

namespace ascorr::hal {

class Clock : private Interface {
public:
    virtual ~Clock() = default;
    virtual std::uint64_t now_us() noexcept = 0;
    // Waits at least us microseconds (busy wait or sleep, as the platform does).
    virtual void wait_us(std::uint32_t us) noexcept = 0;
};

// A clock that only moves when told to: wait_us() advances it exactly.
class ManualClock final : public Clock {
public:
    explicit ManualClock(std::uint64_t start_us = 0) noexcept : now_(start_us) {}
    std::uint64_t now_us() noexcept override { return now_; }
    void wait_us(std::uint32_t us) noexcept override { now_ += us; }
    void advance_us(std::uint64_t us) noexcept { now_ += us; }
    std::uint64_t waited_total_us() const noexcept { return now_; }

private:
    std::uint64_t now_;
};

}  // namespace ascorr::hal
