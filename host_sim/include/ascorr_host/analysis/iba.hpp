// ascorr_host/analysis/iba.hpp: inter-boresight angles and their statistics.
//
// Conventions (docs/contract.md, "Statistics"):
//  - pairs in the paper's order: 0 = A–B, 1 = A–C, 2 = B–C;
//  - the IBA of a pair is the angle between the two boresights (the third rows
//    of R(q_chu_icrf)) at the same epoch, in arcsec;
//  - RMS is about the mean; the smoothed RMS is that of the running mean over
//    a centred window (200 s by default) of the same samples, which removes
//    the short-term star-tracker noise and keeps the thermal signal.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "ascorr/core/quaternion.hpp"
#include "ascorr/core/vector3.hpp"

namespace ascorr::host {

inline constexpr std::size_t kPairs = 3;
inline constexpr std::array<std::array<std::uint8_t, 2>, kPairs> kPairHeads{{{0, 1}, {0, 2}, {1, 2}}};
inline constexpr const char* kPairNames[kPairs] = {"A-B", "A-C", "B-C"};
inline constexpr double kSmoothingWindowS = 200.0;

// Angle between two unit vectors in arcsec, precise for any angle.
double angle_arcsec(const Vector3<double>& a, const Vector3<double>& b) noexcept;

// Epoch key: t rounded to the millisecond, as rows are matched. Only for
// |t| < kMaxEpochTimeS (the key is a 64-bit count of milliseconds); a row
// beyond it (1e300 s: far outside any ephemeris) belongs to no epoch.
inline constexpr double kMaxEpochTimeS = 9.0e15;
std::int64_t epoch_key(double t) noexcept;

struct Rms {
    double rms = 0.0;           // about the mean, arcsec
    double rms_smoothed = 0.0;  // of the running mean over the window
    std::size_t n = 0;
};

// RMS of v about its mean, and after a running mean of width window_s
// (samples with |t_j − t_i| ≤ window_s/2). t must be non-decreasing.
Rms rms_about_mean(const std::vector<double>& t, const std::vector<double>& v, double window_s = kSmoothingWindowS);

}  // namespace ascorr::host
