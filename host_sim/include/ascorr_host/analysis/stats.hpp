// ascorr_host/analysis/stats.hpp: IBA statistics of a recorded file (`ascorr stats`).
//
// Per pair of the heads the file holds (iba.hpp: analysis_heads, pairs_of;
// A–B, A–C, B–C for three heads) and stage (original, aberration-corrected,
// aberration- and thermal-corrected), the IBA RMS about the mean over the
// clean epochs of docs/contract.md: both rows with flags == 0, confidence <= 5,
// all three temperatures and the velocity present (and accepted by the core),
// rows matched by t to the millisecond. The same epochs serve every stage.
#pragma once

#include <array>
#include <cstddef>
#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

#include "ascorr/core/sun_term.hpp"
#include "ascorr/core/thermal.hpp"
#include "ascorr_host/analysis/epochs.hpp"
#include "ascorr_host/analysis/iba.hpp"
#include "ascorr_host/correct/lagged_temperatures.hpp"
#include "ascorr_host/formats/solutions_csv.hpp"

namespace ascorr::host {

inline constexpr std::size_t kStages = 3;
inline constexpr const char* kStageNames[kStages] = {"original", "aberration", "thermal"};

struct StatsOptions {
    std::string in;
    std::string model;  // empty: no thermal stage
    std::optional<double> from;
    std::optional<double> to;
    bool keep_series = false;                    // keep the IBA time series (for plots)
    std::string period_options = "--from/--to";  // the options that set from and to, for messages
    // The rows are already corrected (a corrected file): no stage is applied;
    // the "original" stage is the rows as they are, the others are null.
    bool corrected_input = false;
    // Log a line per pair without clean epochs (plot says it once, itself).
    bool log_empty_pairs = true;
    // simulate's OUT.noise-iba.csv (empty: none): the systematic residual per
    // pair and stage, the RMS about the mean of IBA − noise-only IBA over the
    // clean epochs the file has too.
    std::string noise_iba;
};

struct PairSeries {
    std::vector<double> t;
    std::array<std::vector<double>, kStages> iba;  // arcsec, by stage
};

struct StatsResult {
    bool thermal = false;
    bool corrected_input = false;  // StatsOptions::corrected_input: only the "original" stage
    HeadMask heads = kPaperHeads;  // analysis_heads of the heads with rows in the file
    PairList pairs = kPaperPairs;  // pairs_of(heads): the arrays below are indexed by position in it
    std::array<std::array<Rms, kStages>, kMaxPairs> rms{};
    std::array<std::size_t, kMaxPairs> n{};
    std::array<PairSeries, kMaxPairs> series;  // sorted by t; filled when keep_series
    std::size_t rows = 0;                      // rows in [from, to]
    std::size_t clean_rows = 0;
    // For a pair without clean epochs (n == 0), why, in words: no rows in the
    // file or in [from, to], a head without rows or without clean rows (and
    // what kept them out), or the two heads' clean rows never at one epoch.
    std::array<std::string, kMaxPairs> no_epochs_reason;
    bool systematic = false;  // StatsOptions::noise_iba given
    std::array<std::array<Rms, kStages>, kMaxPairs> systematic_rms{};
    std::array<std::size_t, kMaxPairs> systematic_n{};  // epochs with a noise-only IBA
};

// docs/contract.md's clean solution (before the core has seen it).
bool is_clean(const SolutionRecord& rec) noexcept;

// Throws InputError for a malformed input; log gets one line per rejected row
// and one per pair without clean epochs ("FILE: pair A-C: no clean epochs: REASON").
// A corrected file (a `status` column) is never corrected again: with a model it
// is refused; without one it is shown as it is (corrected_input).
StatsResult compute_stats(const StatsOptions& opt, std::ostream& log);
// The same on rows from elsewhere (opt.in names them in messages; opt.model is
// not read: model, nullptr for no thermal stage; lag, a lagged model's table
// over the same rows (lagged_temperatures.hpp), nullptr for none; sun, the
// model's Sun term, nullptr for none).
StatsResult compute_stats(const StatsOptions& opt, const RowSource& rows, const ThermalModel<double>* model,
                          std::ostream& log, const LaggedTemperatures* lag = nullptr,
                          const SunTermModel<double>* sun = nullptr);

// Whether pair p has an RMS at stage st: two clean epochs at least (the RMS
// of one epoch about itself is 0, not a measurement) and, for the thermal
// stage, a model; for the aberration and thermal stages, a raw input (a
// corrected file is shown as it is, under "original"). Otherwise the table
// says "-", the JSON null, Python None.
inline constexpr std::size_t kMinEpochsForRms = 2;
bool rms_defined(const StatsResult& r, std::size_t p, std::size_t st) noexcept;
// The same for the systematic residual: rms_defined, a noise-only IBA file,
// and two of its epochs in the pair at least.
bool systematic_defined(const StatsResult& r, std::size_t p, std::size_t st) noexcept;

std::string stats_table(const StatsResult& r);
std::string stats_json(const StatsResult& r);

}  // namespace ascorr::host
