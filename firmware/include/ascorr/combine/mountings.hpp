// ascorr/combine/mountings.hpp: the heads' mountings on the bench and their noise,
// and what makes them unusable.
//
// Conventions (the contract's "Combined attitude"; quaternion.hpp):
//  - q_chu_crf maps components in the common reference frame of the bench
//    (CRF) into the head's: v_chu = R(q_chu_crf) v_crf, so that
//    R(q_chu_icrf) = R(q_chu_crf) R(q_crf_icrf).
//  - sigma_cross_arcsec is the head's 1σ noise per axis across its boresight
//    (CHU x and y), sigma_about_arcsec about it (CHU z), in arcsec.
//  - A head's information in CRF axes (1/arcsec²), with M = R(q_chu_crf):
//      W = Mᵀ diag(1/σc², 1/σc², 1/σa²) M,
//    since a small rotation δ_chu in CHU axes is δ_crf = Mᵀ δ_chu in CRF axes.
// Double: the host reads the mountings file into this, the DPU has it in flash;
// the combiner (combiner.hpp) converts what it needs once, at construction.
#pragma once

#include <cmath>
#include <cstdint>

#include "../core/heads.hpp"
#include "../core/quaternion.hpp"
#include "../core/scalar_traits.hpp"
#include "matrix3.hpp"

namespace ascorr::combine {

// Head sets are core/heads.hpp's HeadMask.
inline constexpr unsigned kSubsetCount = 1U << kMaxHeads;  // masks 0 … 2^kMaxHeads − 1 (0: no head)

struct HeadMounting {
    bool present;                  // the head is in the mountings
    Quaternion<double> q_chu_crf;  // v_chu = R(q_chu_crf) v_crf; unit
    double sigma_cross_arcsec;     // 1σ per axis across the boresight
    double sigma_about_arcsec;     // 1σ about the boresight
};

struct Mountings {
    HeadMounting head[kMaxHeads];  // by head index (heads.hpp)
};

// The accepted range of a σ (arcsec). Below 1e-3″ (a thousandth of the best
// star tracker's noise) or above 1000″ (a quarter of a degree) a value is a
// unit or transcription error, and the information matrices would span more
// than the 1e12 the tables are built to (matrix3.hpp's inverse_spd).
inline constexpr double kMinSigmaArcsec = 1e-3;
inline constexpr double kMaxSigmaArcsec = 1e3;

// A mounting quaternion must be unit to this tolerance in ‖q‖² (the core's
// tolerance for a solution's quaternion, scalar_traits.hpp); the combiner
// then normalises it exactly.
inline constexpr double kMountingNormTolerance = ScalarTraits<double>::unit_norm_tolerance;

// The largest sum of absolute gains in one row over the heads of a subset
// (subset_tables.hpp): the combined estimate is then at most this many times
// the largest head difference, and the gains fit the fixed-point gain format
// (kernels.hpp, QGain: ±64). Near-orthogonal heads have ≤ 1.5; two heads
// 20° apart with σa/σc = 7, about 10; more means a head set that determines
// some axis only through near-cancelling heads (and amplifies their noise
// as much).
inline constexpr double kMaxGainRowSum = 60.0;

// Why mountings are unusable; kNone: usable. The first problem found is
// reported, heads in index order (per-head checks before the head set's).
enum class MountingsProblem : std::uint8_t {
    kNone,
    kNoHead,                 // no head present
    kQuaternionNotFinite,    // a component is NaN or infinite
    kQuaternionZero,         // all four components zero (an empty row)
    kQuaternionNotUnit,      // |‖q‖² − 1| > kMountingNormTolerance
    kSigmaCrossNotFinite,    // NaN or infinite
    kSigmaCrossNotPositive,  // zero or negative
    kSigmaCrossOutOfRange,   // outside [kMinSigmaArcsec, kMaxSigmaArcsec]
    kSigmaAboutNotFinite,
    kSigmaAboutNotPositive,
    kSigmaAboutOutOfRange,
    kIllConditioned,  // a subset's information is singular or its gains exceed kMaxGainRowSum
    kGateConfig,      // CombinerConfig outside its documented range (combiner.hpp)
    kGateOutOfRange,  // a gate factor beyond the fixed-point gate format (combiner.hpp)
};

// What each problem means, for messages ("mountings: head B: <text>").
constexpr const char* problem_text(MountingsProblem p) noexcept {
    switch (p) {
        case MountingsProblem::kNone:
            return "usable";
        case MountingsProblem::kNoHead:
            return "no head in the mountings";
        case MountingsProblem::kQuaternionNotFinite:
            return "quaternion not finite";
        case MountingsProblem::kQuaternionZero:
            return "quaternion is zero";
        case MountingsProblem::kQuaternionNotUnit:
            return "quaternion not unit (|qw²+qx²+qy²+qz² - 1| > 1e-6)";
        case MountingsProblem::kSigmaCrossNotFinite:
            return "sigma_cross not finite";
        case MountingsProblem::kSigmaCrossNotPositive:
            return "sigma_cross not positive";
        case MountingsProblem::kSigmaCrossOutOfRange:
            return "sigma_cross outside [0.001, 1000] arcsec";
        case MountingsProblem::kSigmaAboutNotFinite:
            return "sigma_about not finite";
        case MountingsProblem::kSigmaAboutNotPositive:
            return "sigma_about not positive";
        case MountingsProblem::kSigmaAboutOutOfRange:
            return "sigma_about outside [0.001, 1000] arcsec";
        case MountingsProblem::kIllConditioned:
            return "head set ill-conditioned (gains beyond 60: heads nearly aligned with weak axes)";
        case MountingsProblem::kGateConfig:
            return "consistency gate outside its range (sigmas 3..100, floor 1..3600 arcsec)";
        case MountingsProblem::kGateOutOfRange:
            return "consistency gate factor beyond the fixed-point format";
    }
    return "unknown problem";
}

namespace detail {

// A σ's problem, with the three problems of one σ in the order of the enum.
constexpr MountingsProblem sigma_problem(double s, MountingsProblem not_finite) noexcept {
    const auto base = static_cast<std::uint8_t>(not_finite);
    if (!(s - s == 0.0)) {  // NaN or ±inf (constexpr: no std::isfinite)
        return not_finite;
    }
    if (!(s > 0.0)) {
        return static_cast<MountingsProblem>(base + 1);
    }
    if (s < kMinSigmaArcsec || s > kMaxSigmaArcsec) {
        return static_cast<MountingsProblem>(base + 2);
    }
    return MountingsProblem::kNone;
}

constexpr MountingsProblem head_problem(const HeadMounting& h) noexcept {
    const Quaternion<double>& q = h.q_chu_crf;
    const double n2 = q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z;
    if (!(n2 - n2 == 0.0)) {
        return MountingsProblem::kQuaternionNotFinite;
    }
    if (q.w == 0.0 && q.x == 0.0 && q.y == 0.0 && q.z == 0.0) {
        return MountingsProblem::kQuaternionZero;
    }
    if (!(n2 - 1.0 <= kMountingNormTolerance && 1.0 - n2 <= kMountingNormTolerance)) {
        return MountingsProblem::kQuaternionNotUnit;
    }
    const MountingsProblem c = sigma_problem(h.sigma_cross_arcsec, MountingsProblem::kSigmaCrossNotFinite);
    if (c != MountingsProblem::kNone) {
        return c;
    }
    return sigma_problem(h.sigma_about_arcsec, MountingsProblem::kSigmaAboutNotFinite);
}

}  // namespace detail

// q_chu_crf scaled to unit norm (the tolerance above leaves a scale of up to
// 5e-7, which is no rotation); for a mounting that passed head_problem().
inline Quaternion<double> unit_mounting(const HeadMounting& h) noexcept {
    const Quaternion<double>& q = h.q_chu_crf;
    const double s = 1.0 / std::sqrt(q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z);
    return {q.w * s, q.x * s, q.y * s, q.z * s};
}

// W = Mᵀ diag(1/σc², 1/σc², 1/σa²) M (1/arcsec², CRF axes), above.
inline Matrix3 information(const HeadMounting& h) noexcept {
    const Matrix3 m = rotation_matrix(unit_mounting(h));
    const double ic = 1.0 / (h.sigma_cross_arcsec * h.sigma_cross_arcsec);
    const double ia = 1.0 / (h.sigma_about_arcsec * h.sigma_about_arcsec);
    return transpose(m) * diagonal(ic, ic, ia) * m;
}

// How a small rotation δ of the head (CHU axes) moves the combined attitude
// of a head set S, up to the set's common factor P_S⁻¹ (subset_tables.hpp):
// P_S⁻¹·W·Mᵀ·δ = P_S⁻¹·Mᵀ diag(1/σc², 1/σc², 1/σa²)·δ, so the weight is
// Mᵀ diag(1/σc², 1/σc², 1/σa²) (1/arcsec², CHU axes → CRF axes). The rule for
// the rotation common to all heads (calib/common_rotation.hpp) weighs each
// head's correction by it; the common factor cancels there.
inline Matrix3 motion_weight(const HeadMounting& h) noexcept {
    const Matrix3 m = rotation_matrix(unit_mounting(h));
    const double ic = 1.0 / (h.sigma_cross_arcsec * h.sigma_cross_arcsec);
    const double ia = 1.0 / (h.sigma_about_arcsec * h.sigma_about_arcsec);
    return transpose(m) * diagonal(ic, ic, ia);
}

// C = W⁻¹ = Mᵀ diag(σc², σc², σa²) M (arcsec², CRF axes).
inline Matrix3 covariance(const HeadMounting& h) noexcept {
    const Matrix3 m = rotation_matrix(unit_mounting(h));
    const double c = h.sigma_cross_arcsec * h.sigma_cross_arcsec;
    const double a = h.sigma_about_arcsec * h.sigma_about_arcsec;
    return transpose(m) * diagonal(c, c, a) * m;
}

// The heads present, as a mask.
constexpr HeadMask mounted_heads(const Mountings& m) noexcept {
    HeadMask mask = 0;
    for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
        if (m.head[h].present) {
            mask = static_cast<HeadMask>(mask | head_bit(h));
        }
    }
    return mask;
}

}  // namespace ascorr::combine
