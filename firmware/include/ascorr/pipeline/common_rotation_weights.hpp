// ascorr/pipeline/common_rotation_weights.hpp: the on-board estimator's rule
// for the rotation common to all heads, from the mountings the combination
// uses (calib/estimator_types.hpp's CommonRotationWeights;
// calib/common_rotation.hpp, "The rule"; docs/contract.md, "The common
// rotation").
//
// One conversion for the flight loop, the link server and the host: each head
// present in the mountings with finite sigmas weighs
// A_h = M_hᵀ·diag(1/σc², 1/σc², 1/σa²) (combine/mountings.hpp, motion_weight),
// how its correction moves the combined attitude up to the common factor. A
// head without sigmas weighs nothing; mountings without any: no rule.
// Double, construction time only; no allocation.
#pragma once

#include <cmath>

#include "../calib/estimator_types.hpp"
#include "../combine/mountings.hpp"

namespace ascorr::pipeline {

inline calib::CommonRotationWeights common_rotation_weights(const combine::Mountings& m) noexcept {
    calib::CommonRotationWeights w{};
    for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
        const combine::HeadMounting& hm = m.head[h];
        if (!hm.present || !std::isfinite(hm.sigma_cross_arcsec) || !std::isfinite(hm.sigma_about_arcsec) ||
            !(hm.sigma_cross_arcsec > 0.0) || !(hm.sigma_about_arcsec > 0.0)) {
            continue;
        }
        const combine::Matrix3 a = combine::motion_weight(hm);
        for (int r = 0; r < 3; ++r) {
            for (int c = 0; c < 3; ++c) {
                w.a[h].m[r][c] = a.m[r][c];
            }
        }
        w.heads = static_cast<std::uint8_t>(w.heads | (1U << h));
    }
    return w;
}

}  // namespace ascorr::pipeline
