// tests/target/vector_format.hpp: the files exchanged between the host and a
// target image under QEMU (semihosting file I/O), for the accuracy tests.
//
// Conventions: plain little-endian structs of doubles and 32-bit integers,
// identical in layout on x86-64 and ARM EABI (8-byte aligned doubles; checked
// by the static_asserts). vectors.bin = VectorHeader, then `count` VectorRecord;
// the target writes results.bin = `count` ResultRecord, one per input, with the
// corrected quaternion (converted to double) and status for each of the three
// configurations: aberration only, thermal only, both. Inputs are doubles in
// the core's units (rad, °C, v/c); the target converts them to its scalar the
// way a DPU would be given them (ScalarTraits<T>::from_double, celsius,
// coefficient), which is the input rounding the double reference does not have.
#pragma once

#include <cstdint>

#include "ascorr/core/heads.hpp"
#include "ascorr/core/model_terms.hpp"

namespace ascorr::target {

inline constexpr std::uint32_t kVectorMagic = 0x41534331U;  // "ASC1"
inline constexpr std::uint32_t kModels = 2;                 // 0: Table 2, 1: random with quadratic terms

struct ModelRecord {
    std::uint32_t present[kMaxHeads];
    double coefficient[kMaxHeads][kModelAxes][kModelTerms];  // [head][alpha, beta, gamma][term], rad
};

struct VectorHeader {
    std::uint32_t magic;
    std::uint32_t count;
    ModelRecord model[kModels];
};

struct VectorRecord {
    double q[4];  // w, x, y, z
    double temperature[3];
    double beta[3];
    double inv_sun_distance_au;
    std::uint32_t head;
    std::uint32_t temperature_valid;  // bit i: temperature[i]
    std::uint32_t velocity_valid;
    std::uint32_t model;  // index into VectorHeader::model
};

inline constexpr int kConfigs = 3;  // aberration only, thermal only, both

struct ResultRecord {
    double q[kConfigs][4];
    std::uint32_t status[kConfigs];
    std::uint32_t pad;
};

static_assert(sizeof(ModelRecord) == kMaxHeads * (4 + 3 * 7 * 8) + (kMaxHeads % 2) * 4, "layout");
static_assert(sizeof(VectorRecord) == 11 * 8 + 16, "layout");
static_assert(sizeof(ResultRecord) == 12 * 8 + 16, "layout");

}  // namespace ascorr::target
