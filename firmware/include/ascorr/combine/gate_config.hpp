// ascorr/combine/gate_config.hpp: the combination's consistency gate, as
// configured (combiner.hpp's step 3 applies it): its sigmas and floor, their
// range, the defaults by what is known of the rows and the mountings, and
// the fixed-point format's limit on its tables, checked without building
// them (the link server's test before a build).
#pragma once

#include <cstdint>

#include "../core/heads.hpp"
#include "matrix3.hpp"
#include "mountings.hpp"
#include "subset_tables.hpp"

namespace ascorr::combine {

// The consistency gate (combiner.hpp, step 3). Accepted: gate_sigmas in [3, 100],
// gate_floor_arcsec in [1, 3600]; anything else makes the combiner invalid
// (MountingsProblem::kGateConfig).
struct CombinerConfig {
    double gate_sigmas = 6.0;
    double gate_floor_arcsec = 10.0;
};

// The gate's default follows what is known of the rows and the mountings
// (the contract's "The consistency gate"). On the ground, with the
// aberration and the thermal stage applied, the heads disagree by their noise
// and what the thermal model leaves (about 0.5″, method.md §3.3), and the
// mountings are the ground's (estimated by align, or stated with their
// noise): a floor of 2″ keeps that far inside the gate (k·f = 12″, and the
// covariance adds to it) and catches a head 40″ off across its boresight
// (20″ where the other heads' weak axes allow). Rows without both stages
// disagree also by the differential aberration (up to 2·20.5″·sin(angle/2)
// between two boresights, ~29″ at 90°) and the bench's uncorrected
// deformation: 10″. On board (flight_gate) the mountings are the pre-flight
// ones in flash, which nothing aligns in flight: 10″ too.
inline constexpr double kGateFloorCorrectedArcsec = 2.0;
inline constexpr double kGateFloorUncorrectedArcsec = 10.0;

constexpr CombinerConfig default_gate(bool both_stages_applied) noexcept {
    return {6.0, both_stages_applied ? kGateFloorCorrectedArcsec : kGateFloorUncorrectedArcsec};
}
constexpr CombinerConfig flight_gate() noexcept {
    return default_gate(false);
}

inline constexpr double kMinGateSigmas = 3.0;
inline constexpr double kMaxGateSigmas = 100.0;
inline constexpr double kMinGateFloorArcsec = 1.0;
inline constexpr double kMaxGateFloorArcsec = 3600.0;

constexpr bool gate_config_valid(const CombinerConfig& c) noexcept {
    return c.gate_sigmas >= kMinGateSigmas && c.gate_sigmas <= kMaxGateSigmas &&
           c.gate_floor_arcsec >= kMinGateFloorArcsec && c.gate_floor_arcsec <= kMaxGateFloorArcsec;
}

// The largest gate factor (per radian of half-angle) the tables accept in
// every scalar, so that host and DPU refuse the same mountings: the Q30 gate
// format's range (kernels.hpp, QGate: 2²⁹, with a factor 2 of margin). With
// the default gate the factors are below 7e3 times the leave-one-out
// amplification (≤ 50 for near-orthogonal heads).
inline constexpr double kMaxGateFactor = 0x1p28;

// U of subset_gate within kMaxGateFactor in every entry (build_gate's test).
inline bool gate_factors_fit(const Matrix3& u) noexcept {
    for (const auto& row : u.m) {
        for (double x : row) {
            if (!(x <= kMaxGateFactor && x >= -kMaxGateFactor)) {
                return false;
            }
        }
    }
    return true;
}

// Every gate of every head set of two or more mounted heads within the
// fixed-point format, without building the tables (the link server's test
// before it builds: a few hundred bytes of stack, not the combiner's tables).
// kNone, or kGateOutOfRange with *head and *subset; for mountings that
// check_mountings() accepts and a gate_config_valid() cfg.
inline MountingsProblem check_gates(const Mountings& m, const CombinerConfig& cfg, std::uint8_t* head,
                                    HeadMask* subset) noexcept {
    const HeadMask mounted = mounted_heads(m);
    for (unsigned sub = 1; sub < kSubsetCount; ++sub) {
        const auto s = static_cast<HeadMask>(sub);
        if ((sub & ~unsigned{mounted}) != 0U || head_count(s) < 2) {
            continue;
        }
        for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
            Matrix3 u{};
            if ((s & head_bit(h)) != 0U &&
                !(subset_gate(m, s, h, cfg.gate_sigmas, cfg.gate_floor_arcsec, &u) && gate_factors_fit(u))) {
                *head = h;
                *subset = s;
                return MountingsProblem::kGateOutOfRange;
            }
        }
    }
    return MountingsProblem::kNone;
}

}  // namespace ascorr::combine
