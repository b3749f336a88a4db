// ascorr_host/analysis/interpolate.hpp: the combined attitude at given times
// (`ascorr interpolate`, Python interpolate(); docs/contract.md, "Attitude at
// given times").
//
// Between the usable epochs a and b (rows of the combined file with q) on
// either side of t, u = (t − t_a)/(t_b − t_a):
//   q(t) = Exp(u θ) ⊗ q_a,  θ = Log(q_b ⊗ q_a*)  (core/rotation_vector.hpp),
// the rotation at constant rate from a to b (spherical linear interpolation).
// Log takes q_b ⊗ q_a* with w ≥ 0, so the signs are made continuous first and
// the shorter way is taken; equal attitudes give θ = 0 exactly (no 0/0).
// The formal covariance per CRF axis pair:
//   C(t) = (1 − u) C_a + u C_b + e(t)² I,
// the epochs' own covariances linear in u (exact when their errors are the
// same, as a star tracker's slow errors are over seconds; with independent
// errors it would be (1 − u)² C_a + u² C_b, smaller: C(t) never falls below
// the smaller of C_a and C_b, and grows by e), e(t) the interpolation error
// bound: for an attitude
// whose angular acceleration is at most α, a constant-rate path departs from
// it by at most α (t − t_a)(t_b − t)/2 (the bound of linear interpolation,
// a function with |f''| ≤ α). α is taken from the data: the largest change of
// the mean rate between a and b and the interval before (after) it, per the
// mean of the two intervals' spans; a neighbour beyond the largest gap
// (2 · max_gap) is not used; with no neighbour, α = 0 (stated in the summary).
// The epochs' own noise enters α too (about 2σ/Δt² for spacing Δt, so e is
// about σ/4 at mid-interval): a bound rather than an estimate.
// heads: the union of a's and b's; status 1 or 2 by that union, with 4 when
// a's or b's has it. At t equal to a usable epoch's t: that epoch's row,
// unchanged.
// Status 8 (q, heads, sigmas empty) where t is before the first or after the
// last usable epoch, or an epoch on either side is further than max_gap.
//
// Memory: the times asked for (and one row each) are held; the combined file
// is read once, in blocks, with four usable epochs held.
#pragma once

#include <cstddef>
#include <memory>
#include <ostream>
#include <string>
#include <vector>

#include "ascorr_host/formats/atomic_file.hpp"
#include "ascorr_host/formats/combined_csv.hpp"

namespace ascorr::host {

inline constexpr double kDefaultMaxGapS = 10.0;
inline constexpr double kMinMaxGapS = 1e-3;
inline constexpr double kMaxMaxGapS = 1e6;

struct InterpolateSummary {
    std::size_t rows = 0;                 // rows written (the times asked for)
    std::size_t exact = 0;                // at an epoch's own t
    std::size_t interpolated = 0;         // between two usable epochs
    std::size_t outside = 0;              // status 8: before the first or after the last usable epoch
    std::size_t gap = 0;                  // status 8: an epoch on a side further than max_gap
    std::size_t epochs = 0;               // rows of the combined file read
    std::size_t usable = 0;               // of them with q
    std::size_t without_rate_change = 0;  // interpolated with α = 0 (no neighbour to measure it)
    double max_error_bound_arcsec = 0.0;  // the largest e(t) of the rows
};
std::string describe(const InterpolateSummary& s);

// The interpolation over a combined file's rows, streamed in time order.
class Interpolator {
public:
    // at: the times asked for, in the caller's order, each finite (|t| <
    // kMaxEpochTimeS, as read_times and Python's interpolate check); max_gap_s
    // in [kMinMaxGapS, kMaxMaxGapS]. covariance: the rows carry cov_xy..yz.
    Interpolator(std::vector<double> at, double max_gap_s, bool covariance);
    ~Interpolator();
    Interpolator(const Interpolator&) = delete;
    Interpolator& operator=(const Interpolator&) = delete;
    // The next row of the combined file; its t after the previous row's
    // (the caller checks and says where).
    void add(const AttitudeRow& row);
    // Every time asked for has its row, in the caller's order.
    const std::vector<AttitudeRow>& finish();
    const InterpolateSummary& summary() const noexcept;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

struct InterpolateOptions {
    std::string in;   // combined file
    std::string at;   // CSV with a column t
    std::string out;  // combined file at the times of `at`
    double max_gap_s = kDefaultMaxGapS;
};
std::vector<NamedPath> interpolate_inputs(const InterpolateOptions& opt);
std::vector<NamedPath> interpolate_outputs(const InterpolateOptions& opt);

// The column t of a CSV with a header (any other columns ignored), in its
// order; InputError (file:line:column) for a missing column, a field that is
// not a finite number of seconds with a millisecond key.
std::vector<double> read_times(const std::string& path);

// `ascorr interpolate` into outputs (opened from interpolate_outputs,
// committed by the caller). InputError for a malformed file: `in` not a
// combined file, or its rows not in time order (naming both lines).
InterpolateSummary interpolate_file(const InterpolateOptions& opt, OutputSet& outputs);

}  // namespace ascorr::host
