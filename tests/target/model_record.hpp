// tests/target/model_record.hpp: a host model file as the record that
// target_vectors writes for the Cortex-M accuracy images (vector_format.hpp):
// coefficients in radians (per °C, per °C²), one presence flag per head. Host
// side only (it reads host::ModelFile); the images convert the record back
// with vector_convert.hpp. Used by target_vectors.cpp and by test_facts.cpp,
// which checks that this path and the host's give the same bits.
#pragma once

#include <cstddef>

#include "ascorr/core/constants.hpp"
#include "ascorr/core/heads.hpp"
#include "ascorr_host/formats/model_csv.hpp"
#include "target/vector_format.hpp"

namespace ascorr::target {

inline ModelRecord model_record(const host::ModelFile& m) {
    ModelRecord r{};
    for (std::size_t h = 0; h < kMaxHeads; ++h) {
        r.present[h] = m.present[h] ? 1U : 0U;
        for (std::size_t a = 0; a < 3; ++a) {
            for (std::size_t i = 0; i < 7; ++i) {
                r.coefficient[h][a][i] = m.coefficients[h][a][i] * kArcsecToRad;
            }
        }
    }
    return r;
}

}  // namespace ascorr::target
