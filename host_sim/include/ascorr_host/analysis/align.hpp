// ascorr_host/analysis/align.hpp: the heads' mountings and noise from the data (`ascorr align`).
//
// Conventions (docs/contract.md, "Combined attitude"):
//  - a mounting is q_chu_crf, R(q_chu_icrf) = R(q_chu_crf)·R(q_crf_icrf); head
//    i's estimate of the common reference frame (CRF) at an epoch is
//    q_crf_icrf_i = q_chu_crf_i* ⊗ q_chu_icrf_i;
//  - small rotations are rotation vectors in CRF axes, arcsec: θ from b to a
//    with a = exp(θ) ⊗ b (rotation_arcsec below);
//  - head i's noise in CRF axes is C_i = σc²·(I − b bᵀ) + σa²·b bᵀ, b its
//    boresight in CRF (the third row of R(q_chu_crf)); its information is
//    W_i = C_i⁻¹ = M_iᵀ diag(1/σc², 1/σc², 1/σa²) M_i, M_i = R(q_chu_crf).
//
// The model of the data: θ_i(t) = ψ(t) + δ_i + e_i(t), where ψ is the CRF's
// attitude (unknown, one per epoch), δ_i a constant error of head i's given
// mounting and e_i white noise of covariance C_i. Relative attitudes of the
// heads (θ_i − θ_ref at one epoch) are free of ψ: everything here is formed
// from them, so the estimates do not depend on the attitude itself.
//
// 1. Noise (estimate_noise): at an epoch with heads S = {s0, s1, …}, the
//    differences d = (θ_s1 − θ_s0, θ_s2 − θ_s0, …) have covariance
//    D·blockdiag(C_s)·Dᵀ, linear in the variance components σc², σa² of each
//    head. Their scatter is taken about the mean of each window of
//    `noise_window_s` (piecewise-constant mean: the heads' slowly varying
//    thermal disagreement does not enter; one degree of freedom per window
//    and head set is spent on it), summed per head set. The components are
//    then estimated by restricted maximum likelihood, iterated as Fisher
//    scoring (the variance-component estimation GROOPS uses per arc; Koch,
//    "Parameter Estimation and Hypothesis Testing in Linear Models", 1999,
//    estimation of variance and covariance components),
//    starting from the unweighted (MINQUE with unit weights) solution; their
//    covariance is the inverse Fisher information at the solution. With two
//    heads the four components are not all identifiable (three numbers per
//    epoch for orthogonal boresights): the heads are then assumed to share
//    one σc (NoiseModel::kEqualCross), and the report says so.
// 2. Mountings (solve_alignment): least squares for the δ_i with ψ(t)
//    eliminated epoch by epoch, weighted by W_i: per head set S with n epochs
//    the normal equations gain n·(blockdiag W_i − [W_i]·(ΣW)⁻¹·[W_j]ᵀ) and
//    the right side W_i·(Σ_t θ_i − (ΣW)⁻¹ Σ_j W_j Σ_t θ_j). The data fix the δ
//    up to a rotation common to all heads; the datum keeps the CRF of the
//    given mountings: Σ_i W_i·δ_i = 0 (the information-weighted mean of the
//    rotations is zero, so the combination of all heads is unchanged). The
//    covariance of the δ is that of the constrained solution (the bordered
//    normal matrix's inverse), formal: for white noise.
// Both need only sums per head set (and per open window): a mission-length
// file streams through in bounded memory. The new mounting of head i is
// q_chu_crf_i ⊗ exp(δ_i) (then θ_i loses δ_i).
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>

#include "ascorr/core/heads.hpp"
#include "ascorr/core/quaternion.hpp"
#include "ascorr_host/analysis/combine.hpp"
#include "ascorr_host/analysis/iba.hpp"
#include "ascorr_host/formats/mountings_csv.hpp"

namespace ascorr::host {

// The window of the noise's slowly varying mean (s); 0: one mean over the
// period, else within [kMinNoiseWindowS, kMaxNoiseWindowS] (a window's index
// of any epoch time, |t| < 9e15 s, then fits an int64).
inline constexpr double kDefaultNoiseWindowS = 600.0;
inline constexpr double kMinNoiseWindowS = 0.01;
inline constexpr double kMaxNoiseWindowS = 1e10;
constexpr bool noise_window_valid(double s) noexcept {
    return s == 0.0 || (s >= kMinNoiseWindowS && s <= kMaxNoiseWindowS);
}
// Fewest epochs with two or more usable heads that align accepts.
inline constexpr std::size_t kMinAlignEpochs = 100;

// core/rotation_vector.hpp's rotation_vector_arcsec and exp_arcsec in Eigen's
// vectors: θ (arcsec, the left frame's axes) with a = exp(θ) ⊗ b (either sign
// of a and b), and exp(θ), the unit quaternion of the rotation vector θ.
Eigen::Vector3d rotation_arcsec(const Quaternion<double>& a, const Quaternion<double>& b) noexcept;
Quaternion<double> rotation_quaternion(const Eigen::Vector3d& theta_arcsec) noexcept;

// A head's boresight in CRF (third row of R(q_chu_crf)) and its information
// W = M_iᵀ diag(1/σc², 1/σc², 1/σa²) M_i (1/arcsec²): the combination's own
// (combine::information, mountings.hpp) in Eigen's type.
Eigen::Vector3d boresight_crf(const Quaternion<double>& q_chu_crf) noexcept;
Eigen::Matrix3d information_crf(const Quaternion<double>& q_chu_crf, double sigma_cross_arcsec,
                                double sigma_about_arcsec) noexcept;

// Every set of heads: indexed by its HeadMask bits.
inline constexpr std::size_t kHeadSets = std::size_t{1} << kMaxHeads;

// The sums of one pass over the data.
class AlignSums {
public:
    explicit AlignSums(double noise_window_s = kDefaultNoiseWindowS);

    // One epoch: head h's CRF attitude q_crf_icrf, or nothing when the head has
    // no usable row. Epochs with fewer than two heads count and add nothing.
    void add(double t, const std::array<std::optional<Quaternion<double>>, kMaxHeads>& q_crf_icrf);
    // Closes the windows still open (before estimate_noise).
    void finish();

    struct SetSums {
        std::size_t n = 0;        // epochs with exactly these heads
        Eigen::VectorXd sum;      // Σ d, d = (θ_s1 − θ_s0, …), arcsec
        Eigen::MatrixXd scatter;  // Σ over windows of Σ (d − window mean)(…)ᵀ
        double dof = 0.0;         // Σ over windows of (n_window − 1)
    };
    const SetSums& set(HeadMask s) const noexcept { return total_[s]; }
    // Epochs with two or more heads in which head h is (per head), and in all.
    std::size_t head_epochs(std::uint8_t h) const noexcept { return head_epochs_[h]; }
    std::size_t joint_epochs() const noexcept { return joint_; }
    std::size_t single_epochs() const noexcept { return single_; }
    HeadMask heads() const noexcept { return heads_; }  // heads of the joint epochs
    double noise_window_s() const noexcept { return window_s_; }

private:
    struct Window {
        std::array<std::size_t, kHeadSets> n{};
        std::array<Eigen::VectorXd, kHeadSets> sum;
        std::array<Eigen::MatrixXd, kHeadSets> sum_sq;
    };
    void close(Window& w);

    double window_s_;
    std::optional<double> t0_;
    std::map<long long, Window> open_;  // at most two windows (the current and its predecessor)
    std::array<SetSums, kHeadSets> total_;
    std::array<std::size_t, kMaxHeads> head_epochs_{};
    std::size_t joint_ = 0;
    std::size_t single_ = 0;
    HeadMask heads_ = 0U;
};

enum class NoiseModel : std::uint8_t {
    kPerHead,     // σc and σa of every head
    kEqualCross,  // one σc shared by the heads (two heads: the rest is not identifiable)
};
const char* noise_model_text(NoiseModel m) noexcept;

struct HeadNoise {
    double sigma_cross_arcsec = 0.0;  // 1σ per axis across the boresight
    double sigma_about_arcsec = 0.0;  // 1σ about it
    double sd_cross_arcsec = 0.0;     // 1σ uncertainty of sigma_cross_arcsec (formal)
    double sd_about_arcsec = 0.0;
};

struct NoiseEstimate {
    HeadMask heads = 0U;
    std::array<HeadNoise, kMaxHeads> head{};
    NoiseModel model = NoiseModel::kPerHead;
    std::size_t iterations = 0;
    bool converged = false;
    double dof = 0.0;  // degrees of freedom of the scatter, all head sets
};

// REML estimate of each head's σc and σa (see the top) from the sums; heads:
// those estimated (each in some joint epoch), boresight_crf by head index.
// Throws std::invalid_argument when the data do not identify them even with
// one shared σc.
NoiseEstimate estimate_noise(const AlignSums& sums, HeadMask heads,
                             const std::array<Eigen::Vector3d, kMaxHeads>& boresight_crf);

struct Alignment {
    HeadMask heads = 0U;
    std::array<Eigen::Vector3d, kMaxHeads> delta_arcsec{};           // δ_i, CRF axes
    std::array<Eigen::Matrix3d, kMaxHeads> covariance{};             // of δ_i, arcsec²
    Eigen::Vector3d weighted_mean_arcsec = Eigen::Vector3d::Zero();  // (ΣW)⁻¹ Σ W_i (Δ_i + δ_i), zero up to rounding
};

// Least-squares δ_i under the datum Σ W_i (Δ_i + δ_i) = 0 (see the top),
// Δ_i the rotations the mountings were already turned by (align's earlier
// passes; zero: the datum Σ W_i δ_i = 0), so that the datum holds for the
// total rotation with the latest weights. Throws std::invalid_argument naming
// a head that shares no epoch with the others.
Alignment solve_alignment(const AlignSums& sums, HeadMask heads,
                          const std::array<Eigen::Matrix3d, kMaxHeads>& information,
                          const std::array<Eigen::Vector3d, kMaxHeads>& turned_arcsec);
// The same with every Δ_i zero.
Alignment solve_alignment(const AlignSums& sums, HeadMask heads,
                          const std::array<Eigen::Matrix3d, kMaxHeads>& information);

// ---- `ascorr align`: the passes over a file
//
// Which rows: those in [from, to] that the combination would average in
// (combine.hpp: clean, no stage skipped, the epoch's stages), of heads in the
// mountings; an epoch counts when two or more heads have such a row. Every
// head of the mountings must have clean epochs with another head. The
// estimate is iterated: each pass sums the data with the current mountings,
// estimates the noise and the δ_i, and turns the mountings by them.
//
// The gate: once a pass turned no head by more than kGateAfterUpdateArcsec,
// each epoch of every later pass goes through the combination's own
// consistency gate (combine/combiner.hpp, the gate of the epoch's stages,
// GateOptions) built from the current mountings and the noise of the pass
// before; a head it finds inconsistent is left out of the sums
// (LeftOut::kInconsistent). The first pass has no noise to gate with:
// outliers inflate its noise, and the gate of the next passes tightens as
// they go. The passes end after a gated pass whose largest δ is below
// kAlignToleranceArcsec (the first pass removes all but the second-order
// terms, about δ² ≈ 0.005" for 30") and whose gate left out the same rows as
// the pass before, at most kMaxAlignPasses.
//
// Refused (AlignRefused): noise the data do not determine (a head whose σ has
// a formal 1σ above kMaxNoiseRelativeSd of itself), and mountings the
// combination could not use: a σ outside the mountings file's range (noise-
// free or absurd data), tables a target cannot build (refuse_unusable_mountings).

inline constexpr double kAlignToleranceArcsec = 1e-3;
inline constexpr std::size_t kMaxAlignPasses = 10;
// The gate from the pass after one that turned no head by more than this.
inline constexpr double kGateAfterUpdateArcsec = 1.0;
inline constexpr double kMaxNoiseRelativeSd = 0.5;

struct AlignOptions {
    std::string in;         // corrected file (or solutions file: raw attitudes as they are)
    std::string mountings;  // mountings file; sigmas, if any, are reported, not used
    std::string out;        // M2
    std::optional<double> from;
    std::optional<double> to;
    double noise_window_s = kDefaultNoiseWindowS;
    std::size_t min_epochs = kMinAlignEpochs;
    GateOptions gate;  // the consistency gate of the passes after the first (combine.hpp)
};

struct HeadAlignment {
    std::size_t epochs = 0;                                        // clean epochs with another head
    Eigen::Vector3d rotation_arcsec = Eigen::Vector3d::Zero();     // M2's mounting = M's ⊗ exp(rotation), CRF axes
    Eigen::Vector3d rotation_sd_arcsec = Eigen::Vector3d::Zero();  // formal 1σ per axis
    HeadNoise noise;
    double given_sigma_cross_arcsec = 0.0;  // M's, NaN when it has none
    double given_sigma_about_arcsec = 0.0;
};

struct AlignReport {
    std::string in;
    std::string mountings;
    std::string out;
    std::optional<double> from;
    std::optional<double> to;
    HeadMask heads = 0U;  // of the mountings: every one aligned
    std::array<HeadAlignment, kMaxHeads> head{};
    NoiseEstimate noise;
    std::size_t rows = 0;                                    // all rows of the input
    std::size_t rows_in_period = 0;                          // with t in [from, to]
    std::array<std::size_t, kLeftOutKinds> rows_left_out{};  // in the period, by LeftOut (kUsed: used), last pass
    std::size_t epochs = 0;                                  // in the period
    // The rows were not in time order: kept in memory and sorted (a file in
    // time order streams, one epoch at a time).
    bool rows_sorted = false;
    std::size_t joint_epochs = 0;   // with two or more usable heads
    std::size_t single_epochs = 0;  // with one
    std::size_t passes = 0;
    double last_update_arcsec = 0.0;                                 // the largest δ of the last pass
    Eigen::Vector3d weighted_mean_arcsec = Eigen::Vector3d::Zero();  // (ΣW)⁻¹ Σ W_i rotation_i, W of M2
    double noise_window_s = kDefaultNoiseWindowS;
    MountingsFile aligned;  // M2: the new mountings with the estimated sigmas
};

// Rows from a file or from arrays (Python): calls its argument for every row,
// in order, each time it is called (align reads its input once per pass).
using CorrectedRowSource = std::function<void(const std::function<void(const CorrectedRow&)>&)>;

// Refusals of align (the command line exits 2): the input's InputError
// (file:line:column), and AlignRefused for an empty period, too few epochs,
// a head without clean epochs, noise or mountings the data do not determine.
class AlignRefused : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

// The estimate from rows (file: the input's name in messages); writes nothing.
AlignReport align_rows(const CorrectedRowSource& rows, const std::string& file, const MountingsFile& m,
                       const AlignOptions& opt);
// `ascorr align`: reads opt.in and opt.mountings, writes opt.out (atomically).
AlignReport align_file(const AlignOptions& opt);
// The same into outputs["--out"] (atomic_file.hpp's OutputSet, committed by the caller).
AlignReport align_file(const AlignOptions& opt, OutputSet& outputs);
// The rows of a corrected or solutions file as the combination takes them.
CorrectedRowSource rows_of_file(const std::string& path);
// The report on standard output (see docs/ground.md).
std::string describe(const AlignReport& r);

}  // namespace ascorr::host
