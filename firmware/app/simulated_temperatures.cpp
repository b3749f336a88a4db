// firmware/app/simulated_temperatures.cpp: a simulated temperature producer
// for temperature_source.hpp, for the fixed-point build (Cortex-M3, no FPU),
// where the HAL's floating-point conversion is not used (hal_temperatures.cpp
// is the producer of the float build).
//
// Each head's three readings follow a stepped profile of 16 points (one point
// per simulated second of 22 cycles), in °C around the worked examples'
// values; the profile is converted to the core's format at compile time, so
// the loop does no arithmetic on it. Every 16th second head C's T_029 reading
// is withheld (valid = false), as a faulty thermistor would be.
#include <cstdint>

#include "temperature_source.hpp"

namespace ascorr::app {
namespace {

constexpr std::uint32_t kCyclesPerStep = 22U;
constexpr std::uint32_t kSteps = 16U;

constexpr Celsius<Scalar> c(double t) {
    return ScalarTraits<Scalar>::celsius(t);
}

// T_CHU, T_029, T_032 of head A at step s; other heads are offset.
constexpr double kChuBase = 10.0;
constexpr double kStep = 0.75;

struct Profile {
    Celsius<Scalar> t[kMaxHeads][kSteps][3];
};

constexpr Profile make_profile() {
    Profile p{};
    for (std::uint32_t h = 0; h < kMaxHeads; ++h) {
        for (std::uint32_t s = 0; s < kSteps; ++s) {
            const double ramp = kStep * static_cast<double>(s < kSteps / 2 ? s : kSteps - s);
            const double offset = 2.5 * static_cast<double>(h);
            p.t[h][s][0] = c(kChuBase + offset + ramp);
            p.t[h][s][1] = c(-6.5 + 0.5 * ramp);
            p.t[h][s][2] = c(-20.0 + 0.25 * ramp);
        }
    }
    return p;
}

constexpr Profile kProfile = make_profile();

HeadTemperatures<Scalar> g_table[kMaxHeads + 1];  // the last entry: all invalid

}  // namespace

void temperatures_update(std::uint32_t cycle) noexcept {
    const std::uint32_t second = cycle / kCyclesPerStep;
    const std::uint32_t s = second % kSteps;
    for (std::uint32_t h = 0; h < kMaxHeads; ++h) {  // fixed trip count
        g_table[h].t_chu = {kProfile.t[h][s][0], true};
        g_table[h].t_029 = {kProfile.t[h][s][1], !(h == 2U && s == kSteps - 1U)};
        g_table[h].t_032 = {kProfile.t[h][s][2], true};
    }
}

const HeadTemperatures<Scalar>& temperatures_of(std::uint8_t head) noexcept {
    return g_table[head < kMaxHeads ? head : kMaxHeads];
}

// The simulation withholds readings without a reason: nothing to add.
StatusBits temperatures_merge_status(std::uint8_t /*head*/, StatusBits core) noexcept {
    return core;
}

}  // namespace ascorr::app
