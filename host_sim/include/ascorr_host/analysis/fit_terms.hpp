// ascorr_host/analysis/fit_terms.hpp: the least-squares step of `ascorr fit` for the
// linear or the quadratic model, and the model-selection report.
//
// Regressors, per head h (the data contract, docs/contract.md): x1 = T1 = T_CHU of h, x2 = T2 − T1,
// x3 = T3 − T1 (T2 = T029, T3 = T032), in °C. The terms per axis are those of
// ascorr/core/model_terms.hpp: the linear model's [1, x1, x2, x3], the
// quadratic one's also [x1², x2², x3²].
//
// Centring and scaling. The design is built from u_j = (x_j − m_j)/s_j, m_j and
// s_j the mean and standard deviation of x_j over the orbit averages the fit
// uses (per head), and u_j² (the orbit average of it, from the orbit averages
// of x_j and x_j²). Raw x and x² are nearly collinear (x = 10 ± 3 °C gives
// corr(x, x²) ≈ 0.99); u and u² are not. The columns are then scaled to unit
// norm, so the condition number measures how independent the regressors are,
// not their units. The solution is expanded back into the contract's form
// before it is written:
//     a + b·u + q·u²  =  (a − b·m/s + q·m²/s²) + (b/s − 2·q·m/s²)·x + (q/s²)·x²,
// so the model file's coefficients refer to temperatures in °C (not centred),
// and c0 to 0 °C and the mean orientation over the modelling period.
//
// Orbit averages of a quadratic model: the average of c·x² over an orbit is
// c·avg(x²), not c·avg(x)², so the orbit sums carry x² too; the averaged
// model is then exact (up to the small-angle error of e, ~θ³/24).
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <string>
#include <vector>

#include "ascorr/core/correct.hpp"
#include "ascorr/core/quaternion.hpp"
#include "ascorr_host/analysis/iba.hpp"
#include "ascorr_host/formats/model_csv.hpp"

namespace ascorr::host {

enum class Terms { kLinear, kQuadratic };
const char* terms_name(Terms t) noexcept;
inline constexpr int terms_per_axis(Terms t) noexcept {
    return t == Terms::kLinear ? kLinearModelTerms : kModelTerms;
}

inline constexpr double kDefaultHoldout = 0.25;             // last quarter of the period held out
inline constexpr double kDefaultMinTemperatureRange = 2.0;  // °C, of each regressor, for quadratic terms
// The quadratic model is preferred when its held-out IBA RMS (mean over the
// pairs) is lower than the linear model's by more than this fraction; below
// it, the quadratic terms fit noise.
inline constexpr double kSelectionMargin = 0.01;

inline constexpr const char* kRegressorNames[kRegressors] = {"T_CHU", "T029 - T_CHU", "T032 - T_CHU"};

// The rule that fixes the 9 unobservable directions, a rotation common to all
// heads and linear in T029 and T032 (calib/common_rotation.hpp, "The rule";
// its names: model_csv.hpp's CommonRotationId), with what `combined` needs.
struct CommonRotation : CommonRotationId {
    // kCombined: A_h by head index, how head h's correction (head axes) moves
    // the combined attitude (CRF axes), up to a factor common to all heads
    // (combine/mountings.hpp, motion_weight; fit.cpp, from the mountings).
    std::array<Eigen::Matrix3d, kMaxHeads> motion{};
};

struct HeadFit {
    std::array<double, 3> residual_rms{};  // orbit averages, arcsec, alpha/beta/gamma
    std::array<double, 3> signal_rms{};    // orbit-averaged angle about its mean
};

// One orbit's averages, per head (by head index; the fit's heads are filled).
struct OrbitAverage {
    double t_mid = 0.0;                           // s since J2000 TT
    std::array<Eigen::Vector3d, kMaxHeads> e{};   // rotation relative to F, head axes, arcsec
    std::array<Eigen::Vector3d, kMaxHeads> x{};   // (x1, x2, x3), °C
    std::array<Eigen::Vector3d, kMaxHeads> x2{};  // (x1², x2², x3²), °C²
};

struct Centring {
    std::array<std::array<double, 3>, kMaxHeads> mean{};   // [head][regressor], °C
    std::array<std::array<double, 3>, kMaxHeads> scale{};  // standard deviation, °C
    std::array<std::array<double, 3>, kMaxHeads> range{};  // max − min over the orbit averages, °C
};

struct TermsFit {
    Terms terms = Terms::kLinear;
    HeadMask heads = kPaperHeads;  // the heads fitted, jointly
    std::string refused;           // non-empty: the data do not support this model (why); no model
    int unknowns = 0;
    int rank = 0;                         // observable directions: unknowns − 9 (the gauge)
    std::vector<double> singular_values;  // of the centred, unit-norm-column design, descending
    double condition = 0.0;               // largest / smallest observable singular value
    Centring centring;
    std::array<HeadFit, kMaxHeads> head{};  // by head index
    ModelFile model;
};

// Joint least squares over the orbits (fit.hpp explains the model and the
// gauge). heads: the heads fitted (two or more); n_ref: their orientations N_i
// in F (by head index). Each orbit contributes 3 equations per head, in
// heads.hpp's order. Refuses (TermsFit::refused)
// a quadratic model when a regressor of a head spans less than min_range_c
// over the orbit averages, and any model whose condition number exceeds
// max_condition, naming the head and term of the weakest direction.
using HeadOrientations = std::array<Eigen::Matrix3d, kMaxHeads>;  // N_i by head index
// The 9 unobservable directions are fixed by `rule` over the same orbits; a
// rule that the orbits do not fix uniquely (T029 and T032 never vary apart) is
// refused.
TermsFit solve_terms(const std::vector<OrbitAverage>& orbits, const HeadOrientations& n_ref, HeadMask heads,
                     Terms terms, double max_condition, double min_range_c, const CommonRotation& rule = {});

// One epoch with all the fit's heads selected: the aberration-corrected
// attitudes and each head's (T1, T2, T3), by head index.
struct FitEpoch {
    double t = 0.0;
    std::array<Quaternion<double>, kMaxHeads> q_chu_icrf{};
    std::array<std::array<double, 3>, kMaxHeads> temp{};
    std::array<double, kMaxHeads> t_head{};  // each head's row's own t (within the epoch's millisecond)
};

// Head h of epoch e as the core's input to its thermal stage alone (no velocity).
SolutionInput<double> thermal_input(const FitEpoch& e, std::size_t h);

// IBA RMS per pair of `heads` (pairs_of, by position) of the epochs with t in
// [from, to), thermally corrected by m (the core, double; its Sun term too,
// core/sun_term.hpp, where the Sun's direction is known). Epochs the core
// does not correct are left out. epochs must be sorted by t.
// kWhereTheSunIsKnown: also without a Sun term, only the epochs where the Sun's
// direction is known (nav/sun_direction.hpp), so that a model with one and a
// model without it are scored on the same epochs.
inline constexpr bool kWhereTheSunIsKnown = true;
std::array<Rms, kMaxPairs> corrected_iba_rms(const std::vector<FitEpoch>& epochs, HeadMask heads, double from,
                                             double to, const ModelFile& m, bool where_the_sun_is_known = false);

// The mean over `pairs` of their RMS; NaN when a pair has no epoch.
double mean_pair_rms(const std::array<Rms, kMaxPairs>& r, const PairList& pairs);

struct ModelScore {
    TermsFit fit;                      // fitted on the part of the period before t_split
    std::array<Rms, kMaxPairs> in{};   // IBA RMS, t < t_split, by position in Selection::pairs
    std::array<Rms, kMaxPairs> out{};  // IBA RMS, t ≥ t_split (held out)
};

struct Selection {
    PairList pairs = kPaperPairs;  // of the fit's heads
    double holdout = 0.0;          // fraction of the period held out (its end)
    double t_split = 0.0;
    std::size_t orbits_fitted = 0;
    std::vector<ModelScore> models;  // linear first, then quadratic
    bool decided = false;            // false without a held-out part
    Terms preferred = Terms::kLinear;
    std::string verdict;  // one sentence: which model the data support, and why
};

// The verdict on two held-out IBA RMS (means over the pairs, both > 0): the
// quadratic model when it is lower by more than the margin; otherwise the
// linear, saying by how much the quadratic terms lower or raise the RMS.
std::string selection_verdict(double linear_rms, double quadratic_rms);

// Fits both models on the orbits before t_split and scores them on the
// epochs before and after it. holdout 0: fits and scores on the whole period,
// no verdict.
Selection select_terms(const std::vector<OrbitAverage>& orbits, const std::vector<FitEpoch>& epochs,
                       const HeadOrientations& n_ref, HeadMask heads, double t_first, double t_last, double holdout,
                       double max_condition, double min_range_c, const CommonRotation& rule = {});

std::string describe_centring(const TermsFit& f);
std::string describe_selection(const Selection& s);

}  // namespace ascorr::host
