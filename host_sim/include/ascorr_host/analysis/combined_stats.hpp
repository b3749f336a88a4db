// ascorr_host/analysis/combined_stats.hpp: a combined file's report (`ascorr stats --combined`).
//
// Per head set (the `heads` column; "-" for epochs without a usable head):
//  - the number of epochs;
//  - with a truth attitude file (`simulate`'s OUT.attitude.csv, matched by t
//    to the millisecond): the error of q_crf_icrf per CRF axis, the rotation
//    vector θ of q_est ⊗ q_true* (R_est = R(θ) R_true), in arcsec: its RMS and
//    mean, beside the RMS of the file's formal σ;
//  - the step at head-set changes against the truth: for each head set S
//    other than the full one (the set of most heads, then most epochs), the
//    RMS over days of the difference of the daily mean errors of S and of the
//    full set (days with epochs of both; day = whole days since the first
//    epoch). A constant offset common to every set is no step.
// The step without a truth, by combining the full set's epochs again with
// each subset, is combine's (CombineSummary::steps, combine.hpp).
// Both files are read in blocks; the truth must be in time order (the
// combined file is, by construction), otherwise InputError names the row.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "ascorr/core/heads.hpp"
#include "ascorr/core/quaternion.hpp"

namespace ascorr::host {

struct CombinedStatsOptions {
    std::string combined;
    std::string truth;  // empty: no error, no step
};

struct HeadSetReport {
    HeadMask heads = 0;  // mask (bit h: head h); 0: no usable head
    std::size_t epochs = 0;
    std::size_t with_truth = 0;  // epochs with a truth row
    std::array<double, 3> error_rms{};
    std::array<double, 3> error_mean{};
    std::array<double, 3> sigma_rms{};  // of the formal σ, over the epochs with a truth row
    std::size_t step_days = 0;          // days with epochs of this set and of the full one
    std::array<double, 3> step{};       // RMS over those days of the daily mean difference
};

struct CombinedStats {
    std::size_t epochs = 0;
    std::array<std::size_t, 4> status_bit{};  // epochs with status 1, 2, 4, 8
    bool truth = false;
    HeadMask full = 0;                // the full head set
    std::vector<HeadSetReport> sets;  // most heads first, then heads.hpp's order; "-" last
    std::size_t epochs_without_truth = 0;
};

CombinedStats combined_stats(const CombinedStatsOptions& opt);
std::string combined_stats_table(const CombinedStats& s);
// {"epochs": N, "status": {"1": n, "2": n, "4": n, "8": n}, "full": "ABC",
//  "head_sets": {"ABC": {"epochs": n, "with_truth": n, "error_rms": [x, y, z],
//  "error_mean": [...], "sigma_rms": [...], "step": [...], "step_days": n}, ...}};
// arrays null where not measured.
std::string combined_stats_json(const CombinedStats& s);

// The letters of a head mask, "-" for none.
std::string head_set_name(HeadMask heads);

}  // namespace ascorr::host
