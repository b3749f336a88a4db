// firmware/app/flight_bench.hpp: the simulated bench of the flight loop, which
// deforms with temperature, and the on-board estimator's place in the loop.
//
// Conventions: the bench's truth is a thermal model in the contract's form
// (arcsec, ascorr/core/thermal.hpp) that is not the one in flash: Table 2 with head
// B's slopes 40 % larger and head C's mount 3″ further in α (a bench that has
// settled since the ground fit). Each head's raw solution at second s of the
// 16-s temperature profile is the truth's thermal rotation at that second's
// true temperatures (boom_channels.hpp, boom_temperatures.hpp) undone from the
// head's undeformed attitude (flight_data.hpp): q_raw = q_th⁻¹ ⊗ q_0, so that
// the correction with the truth would give q_0 back. Computed in double at
// compile time and stored in the core's scalar: no work in the loop. Head D
// has no model and does not deform.
//
// Accelerated time: the estimator sees one orbit (EstimatorConfig's default
// period, 5640 s) per kCalibCyclesPerOrbit cycles, so the 352 cycles of a test
// run are 44 orbits (2.9 days) and its default 30-day forgetting, 30 orbits
// before a first model and 30-orbit window apply as in flight.
#pragma once

#include <cstdint>

#include "app_scalar.hpp"
#include "ascorr/calib/estimator.hpp"
#include "ascorr/combine/mountings.hpp"
#include "ascorr/core/constants.hpp"
#include "ascorr/core/model_coefficients.hpp"
#include "ascorr/core/table2.hpp"
#include "ascorr/core/thermal.hpp"
#include "boom_channels.hpp"
#include "boom_temperatures.hpp"
#include "flight_data.hpp"
#include "loop_rate.hpp"

namespace ascorr::app {

inline constexpr std::uint32_t kCalibCyclesPerOrbit = 8U;
// The estimator is fed every kCalibFeedEvery-th cycle (11 Hz): orbit means of
// a signal whose shortest period is the orbit lose nothing measurable (the
// ground fit works at 300-s epochs), and the per-cycle cost halves.
inline constexpr std::uint32_t kCalibFeedEvery = 2U;
inline constexpr calib::EstimatorConfig kCalibConfig{};
inline constexpr std::int64_t kCalibCycleUs =
    kCalibConfig.orbit_period_us / static_cast<std::int64_t>(kCalibCyclesPerOrbit);

// The estimator's time of cycle `cycle` (accelerated), µs.
constexpr std::int64_t calib_time_us(std::uint32_t cycle) noexcept {
    return static_cast<std::int64_t>(cycle) * kCalibCycleUs;
}

constexpr ModelCoefficients make_bench_truth() {
    ModelCoefficients m = kTable2;
    for (std::size_t a = 0; a < kModelAxes; ++a) {
        for (std::size_t t = 1; t < kLinearModelTerms; ++t) {
            m.coefficient[1][a][t] *= 1.4;
        }
    }
    m.coefficient[2][0][0] += 3.0;
    return m;
}
inline constexpr ModelCoefficients kBenchTruth = make_bench_truth();

struct BenchAttitudes {
    Quaternion<Scalar> q[boom::kProfileSeconds][kMaxHeads];
};

// The star tracker's noise: a fixed pseudo-random rotation per head and
// second of the profile, up to kNoiseArcsec about each axis (a 64-bit LCG,
// Knuth's MMIX constants), so that the models' residuals are at a noise level
// and the adoption gate compares real differences, not roundings.
inline constexpr double kNoiseArcsec = 0.5;
constexpr Quaternion<double> measurement_noise(std::uint32_t sec, std::uint8_t h) {
    std::uint64_t x = 0x9E3779B97F4A7C15ULL ^ (static_cast<std::uint64_t>(sec) * 4U + h);
    double a[3] = {};
    for (double& v : a) {
        x = x * 6364136223846793005ULL + 1442695040888963407ULL;
        const double u = static_cast<double>(x >> 11U) * 0x1p-53;  // [0, 1)
        v = (2.0 * u - 1.0) * kNoiseArcsec * kArcsecToRad * 0.5;   // half-angle
    }
    return {1.0 - 0.5 * (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]), a[0], a[1], a[2]};
}

constexpr BenchAttitudes make_bench_attitudes() {
    constexpr ThermalModel<double> truth = thermal_model<double>(kBenchTruth, kArcsecToRad);
    BenchAttitudes b{};
    for (std::uint32_t sec = 0; sec < boom::kProfileSeconds; ++sec) {
        for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
            const HeadThermalModel<double>& m = truth.head[h];
            const double t1 = chu_celsius(h, sec);
            const double t2 = boom::profile_celsius(0U, sec);
            const double t3 = boom::profile_celsius(3U, sec);
            const Quaternion<double> q =
                m.present ? to_quaternion(conjugate(thermal_rotation(thermal_angle(m.alpha, t1, t2, t3),
                                                                     thermal_angle(m.beta, t1, t2, t3),
                                                                     thermal_angle(m.gamma, t1, t2, t3)))) *
                                kHeadAttitude[h]
                          : kHeadAttitude[h];
            const Quaternion<double> n = measurement_noise(sec, h);
            const Quaternion<double> qn = n * q;
            b.q[sec][h] = {s(qn.w), s(qn.x), s(qn.y), s(qn.z)};
        }
    }
    return b;
}

inline constexpr BenchAttitudes kBenchAttitudes = make_bench_attitudes();

// The bench's mountings, in flash: its common reference frame (CRF) is head
// A's undeformed frame, so q_chu_crf = q_chu_icrf ⊗ q_crf_icrf* of the heads'
// undeformed attitudes (flight_data.hpp), and the µASC's nominal noise, 1.3″
// across and 9″ about the boresight (docs/contract.md, "Combined attitude").
constexpr combine::Mountings make_bench_mountings() {
    combine::Mountings m{};
    const Quaternion<double> q_crf_icrf = kHeadAttitude[0];
    for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
        m.head[h] = {true, kHeadAttitude[h] * conjugate(q_crf_icrf), 1.3, 9.0};
    }
    return m;
}
inline constexpr combine::Mountings kBenchMountings = make_bench_mountings();

// Head h's raw solution in cycle `cycle` of a loop at kRateHz.
constexpr const Quaternion<Scalar>& bench_attitude(std::uint32_t cycle, std::uint8_t h) noexcept {
    return kBenchAttitudes.q[(cycle / kRateHz) % boom::kProfileSeconds][h < kMaxHeads ? h : 0U];
}

}  // namespace ascorr::app
