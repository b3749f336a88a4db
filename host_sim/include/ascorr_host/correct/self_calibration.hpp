// ascorr_host/correct/self_calibration.hpp: the on-board estimator (calib/estimator.hpp)
// run over a recorded file, as `ascorr correct --self-calibrate` and the
// Python module do it (docs/contract.md, "Self-calibration").
//
// The rows are read once, in any order; they are taken in time order (TT µs
// of the on-board clock, then line) one at a time, as the link server takes
// them (ascorr_link/server.hpp), through the same epoch pipeline (pipeline/epoch_pipeline.hpp): each
// epoch (a distinct time tag) takes the model the estimator holds active at
// its first row (a model adopted after an earlier epoch becomes active
// there); the epoch's clean rows of A, B and C (calibration_clean(),
// selection.hpp) are corrected with that model in the scalar T and the first
// usable one of each head feeds the estimator (calib/feed.hpp: the thermal
// stage taken off again), whose per-orbit work then runs to its end. The
// result is the schedule of active models: each row is corrected with the
// model active at its time tag. Before the first one, and for a row whose t
// the on-board clock cannot hold (NaN, |t| > 1e11 s: no epoch), rows get a
// model with no head present, so the core sets 256 (no model coefficients)
// and skips the thermal stage.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "ascorr/calib/estimator.hpp"
#include "ascorr/calib/lag_search.hpp"
#include "ascorr/calib/sun_learner.hpp"
#include "ascorr_host/correct/lagged_temperatures.hpp"
#include "ascorr_host/formats/model_csv.hpp"
#include "ascorr_host/formats/solutions_csv.hpp"

namespace ascorr::host {

struct ActiveModel {
    double t;               // active from this time on (the first cycle using it)
    std::int64_t t_us;      // t on the on-board clock (tt_from_seconds)
    std::uint32_t version;  // 0: the model given at start
    std::uint32_t crc;      // calib::model_crc
    ModelFile model;
    std::uint8_t learnt = calib::kFrameMask;  // the heads this model learnt (bit h; Estimator::active_learnt)
};

struct SelfCalibration {
    std::vector<ActiveModel> history;  // in time order
    calib::EstimatorReport report;     // at the end of the file
    calib::RegaugeCounts regauges;     // the rule's re-gauges (versions among history)
    double orbit_period_s = 0.0;
    std::size_t cycles = 0;   // epochs that fed the estimator (A, B and C usable)
    std::size_t untimed = 0;  // rows whose t the on-board clock cannot hold
    std::size_t runs = 0;     // rows out of time order: sorted runs (more than 1: merged from a temporary file)
    std::optional<calib::LagSearchReport> lag_search;  // learn_lag: the bench's lag, as the search took it
    std::optional<calib::SunLearnReport> sun_learnt;   // learn_sun: the Sun term, as the learner took it
    // learn_sun: the learner as of the last epoch, before the end of the data
    // closed its open orbit (SunLearner::finish): what a target, whose data
    // do not end, reports (`replay`, SUN_LEARNER_REPORT).
    std::optional<calib::SunLearnReport> sun_learnt_at_last_epoch;
};

// The fed rows (in time order) whose median speed gives the orbit period
// when it is not given: 33 epochs of A, B and C.
inline constexpr std::size_t kOrbitPeriodRows = 99;

// The memory self_calibrate() keeps rows out of time order in (the rest goes
// to a temporary file in sorted runs): 64 MiB.
inline constexpr std::size_t kSelfCalibrationMemoryBytes = std::size_t{64} << 20;

// Self-calibration starts from a linear model, on the host as on the target:
// the estimator's models are linear (c0..c3) and the link's CALIB_MODEL_LOAD
// carries c0..c3, so a model with a quadratic term would start the target
// from another model than the host, and the history would list a model other
// than the one that corrected. Throws std::runtime_error naming `name` (the
// model's file or argument), the head, axis and term. One rule for `correct
// --self-calibrate`, `replay --self-calibrate` and Python's self_calibrate()
// (self_calibrate() below checks it too).
void refuse_quadratic_initial_model(const ModelFile& m, const std::string& name);

// kind: "double", "float" or "fixed" is chosen by T. The estimator learns
// the file's heads: A, B, C, and D when a row of D passes the selection (a
// first reading of the rows), at most max_heads; A, B and C learn from the
// epochs they all pass, D from those of them it passes too
// (calib/estimator_types.hpp), so an estimator of more heads than the file
// has (the link's, kMaxHeads) takes the same decisions. initial: --model, linear
// (refuse_quadratic_initial_model).
// orbit_period_s (--orbit-period, orbit_period_acceptable): when not given,
// the circular orbit's at the median speed of the first kOrbitPeriodRows rows in time order
// that feed the estimator; refused (InputError naming a row and
// --orbit-period) when fewer than three quarters of them are within 1 % of
// that median, or it is no Earth orbit of 10 min to a day (docs/contract.md).
// Rows in time order are taken as read; once one is out of order, the rows
// are read again and sorted within memory_budget_bytes (beyond it, in sorted
// runs on a temporary file, merged). Throws InputError for a file whose rows
// cannot be read.
// lag_s: the bench's lag of each head (0 none), with which the caller has
// lagged the rows' temperatures (the estimator learns from the rows as a
// lagged model's terms take them: lagged_rows() over `correct`'s table, in
// double; `replay`, as its target in its scalar); every model of the history
// has it (the heads it has). A lagged initial model must have the same lag
// for each of its lagged heads (refuse_other_lag; an unlagged one may start
// a lagged run: its coefficients are those of the orbit means).
// learn_lag (`--lag auto`; lag_s none, and an unlagged initial model): the
// bench's lag is learnt as the run goes (calib/lag_search.hpp), from the
// rows' own temperatures, which the estimator learns from too (a lag does
// not change orbit means); each model of the history takes the lag the
// search had taken when it became active (lag_s, the same for every head),
// and lag_search reports the search at the end.
// learn_sun (`--sun-term auto`; an initial model without a Sun term,
// refuse_sun_term): the Sun term is learnt as the run goes
// (calib/sun_learner.hpp), from the frame heads' attitudes as the active model
// corrected them (with learn_lag, at the lag the search has taken); each model
// of the history takes the term the learner had taken when it became active
// (its sun, for the heads A, B and C it has), and sun_learnt reports the
// learner at the end. sun_interval_us: the learner takes one cycle per
// interval (SunLearner's thinning; `replay`: the target's,
// calib::kSunLearnOnBoardIntervalUs); 0, every one (`correct`).
template <typename T>
SelfCalibration self_calibrate(const std::string& file, const RowSource& rows, const std::optional<ModelFile>& initial,
                               const calib::EstimatorConfig& cfg, std::optional<double> orbit_period_s,
                               std::size_t memory_budget_bytes = kSelfCalibrationMemoryBytes,
                               std::size_t max_heads = kMaxHeads, const std::array<double, kMaxHeads>& lag_s = {},
                               bool learn_lag = false, bool learn_sun = false, std::int64_t sun_interval_us = 0);

// The lags of a learnt-lag history's models as they change (each model of
// it takes the lag its search had taken, self_calibrate's learn_lag), over
// the rows' readings (read once more); nullopt when no model lags.
std::optional<LagSchedule> learnt_lags(const std::vector<ActiveModel>& history, const RowSource& rows);

// A lagged head of m whose τ is not lag_s's: its coefficients belong to
// another lag. Throws std::runtime_error naming `name` and the head.
void refuse_other_lag(const ModelFile& m, const std::string& name, const std::array<double, kMaxHeads>& lag_s);
// A lagged model to start a run that learns the lag (`option`: how the caller
// spells it, `--lag auto` or `lag='auto'`). Throws std::runtime_error naming
// `name`.
void refuse_lag_to_learn(const ModelFile& m, const std::string& name, const std::string& option);

// The models of a history in turn, for correcting rows: at(t) is the model
// active at t's epoch (TT µs of the on-board clock), or one with no head
// present (256) before the first and for a t the clock cannot hold.
template <typename T>
class ModelSchedule {
public:
    explicit ModelSchedule(const std::vector<ActiveModel>& history);
    const ThermalModel<T>& at(double t) const noexcept;
    // The Sun term of the model active at t, in T (correct_row.hpp);
    // nullptr: none.
    const SunTermModel<T>* sun_at(double t) const noexcept;
    // The version active at t; nullopt: none.
    std::optional<std::uint32_t> version_at(double t) const noexcept;

private:
    std::size_t index_at(double t) const noexcept;  // 0: none, k: history[k − 1]
    std::vector<std::int64_t> from_us_;
    std::vector<std::uint32_t> version_;
    std::vector<ThermalModel<T>> model_;               // [0]: no head present
    std::vector<std::optional<SunTermModel<T>>> sun_;  // by version (model_[k + 1])
};

// How head h of a history's model `version` came to be: "given" (version 0,
// the model given at start), "learnt" (estimated: in the model's `learnt`
// mask, calib::learns_head) or "kept" (a head the model did not learn: the
// active model's coefficients, carried into the adopted model, Estimator::gate).
const char* head_origin(std::uint32_t version, std::size_t h, std::uint8_t learnt = calib::kFrameMask);

// The model history file (docs/contract.md): header
// t,version,chu,axis,c0,c1,c2,c3,crc32c,tt_us,origin (then common_rotation,
// lag_s and sun_x,sun_y,sun_z when they apply) and one row per head and
// axis of each model (origin: head_origin). t (3 decimals) says when; tt_us (t_us: TT µs of the
// on-board clock, an integer) says exactly which rows: those whose t rounds
// (tt_from_seconds) to at least it, up to the next version's.
// combined: the estimator applied the rule `combined` (its config's
// common_rotation weights); the column common_rotation is then added.
std::string format_model_history(const std::vector<ActiveModel>& history, bool combined = false);

// The orbit periods the estimator takes (calib::kMinOrbitPeriodUs ..
// kMaxOrbitPeriodUs), in s; false for NaN. And as messages write them:
// "[600, 86400]".
bool orbit_period_acceptable(double seconds);
std::string orbit_period_range();

// The forgetting time constants the estimator takes
// (calib::time_constant_acceptable) as messages write them: "[1, 10000]".
std::string time_constant_range();

// One line per model and the estimator's state, for the terminal.
// The lag search's outcome in a clause (--lag auto), and whether the last
// model of the history (its lag last_model_lag_s) took what it takes.
std::string describe(const calib::LagSearchReport& r, double last_model_lag_s);
// The Sun term's learner in a clause (--sun-term auto), and the first model
// of the history that took the term.
std::string describe(const calib::SunLearnReport& r, const std::vector<ActiveModel>& history);
std::string describe(const SelfCalibration& s);

}  // namespace ascorr::host
