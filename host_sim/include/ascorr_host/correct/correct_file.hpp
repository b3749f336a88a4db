// ascorr_host/correct/correct_file.hpp: the `ascorr correct` job.
//
// Reads a solutions file, corrects every row with the core in the chosen
// scalar type, and writes the corrected file (docs/contract.md): every input row in
// input order, all its fields verbatim except qw,qx,qy,qz, plus `status`.
// Output is all or nothing (atomic_file.hpp's OutputSet). A malformed row stops the run with
// file:line:column, unless skip_bad, which reports and drops it. With
// states, rows without their own velocity get the on-board service's.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

#include "ascorr/calib/estimator_types.hpp"
#include "ascorr/core/quaternion.hpp"
#include "ascorr/core/status.hpp"
#include "ascorr_host/correct/scalar_kind.hpp"
#include "ascorr_host/correct/states_velocity.hpp"
#include "ascorr_host/formats/atomic_file.hpp"
#include "ascorr_host/formats/solutions_csv.hpp"

namespace ascorr::host {

struct CorrectOptions {
    std::string in;
    std::string out;
    std::string model;  // empty: no thermal stage
    bool aberration = true;
    bool thermal = true;
    ScalarKind scalar = ScalarKind::kDouble;
    bool skip_bad = false;
    // --states: the velocity of rows without vx,vy,vz from spacecraft states,
    // by the on-board service (states_velocity.hpp); empty: none.
    std::string states;
    bool states_gcrs = false;            // --states-frame gcrs (default itrf)
    double max_propagation_s = 21600.0;  // --max-propagation (the service's default horizon)
    // --self-calibrate: the thermal model is the on-board estimator's, learnt
    // from the rows themselves (self_calibration.hpp), starting from `model`
    // (version 0) or from none; model_history: where its models go (empty: not written).
    bool self_calibrate = false;
    std::string model_history;
    double time_constant_days = 30.0;      // --time-constant
    std::optional<double> orbit_period_s;  // --orbit-period; nullopt: from the rows' speeds
    // --lag (self-calibration only): the bench's lag per head the estimator
    // learns with (fit's parse_lags; a lagged `model` must have the same);
    // nullopt: the model's lag_s, or none.
    std::optional<std::array<double, kMaxHeads>> lag_s;
    // --lag auto (self-calibration only, lag_s none, a --model without lag_s):
    // the bench's lag learnt as the estimator runs (calib/lag_search.hpp).
    bool lag_auto = false;
    // --sun-term auto (self-calibration only, the scalar double, a --model
    // without a Sun term): the Sun term learnt as the estimator runs
    // (calib/sun_learner.hpp).
    bool sun_auto = false;
    // The estimator's rule for the rotation common to all heads (with
    // --mountings: pipeline/common_rotation_weights.hpp; none: its own frame).
    calib::CommonRotationWeights common_rotation{};
    // The rule's re-gauge of the active model (calib::EstimatorConfig; no
    // command-line option: the flight's default; +inf turns it off).
    double regauge_arcsec = calib::EstimatorConfig{}.regauge_arcsec;
};

struct CorrectSummary {
    std::size_t rows = 0;                      // rows written
    std::size_t malformed = 0;                 // rows dropped (skip_bad only)
    std::array<std::size_t, 16> status_bit{};  // rows with each status bit set
    ServiceCost service_cost;                  // the velocity service's work (--states)
    bool states_given = false;                 // --states: the three counts below
    std::size_t states_accepted = 0;
    std::size_t states_refused = 0;    // by the velocity service's checks
    std::size_t states_malformed = 0;  // skipped (skip_bad only)
    std::string self_calibration;      // --self-calibrate: the estimator's account
};

// A corrected row as a later stage takes it (correct --combined): q as the
// corrected file writes it (15 decimals), the row's status and cleanness.
struct CorrectedRow {
    double t = 0.0;
    std::size_t line = 0;
    std::uint8_t head = kUnknownHead;
    Quaternion<double> q_chu_icrf{};
    long long flags = 0;
    double confidence = 0.0;  // NaN when not a number
    bool corrected = false;   // status is the row's (false: a raw row, taken as it is)
    StatusBits status = 0;

    // A solution's row, corrected with `status`, or raw (nullopt: status 0).
    static CorrectedRow of(const SolutionRecord& rec, std::optional<StatusBits> status) noexcept {
        return {rec.t,     rec.line,       rec.head,           rec.q_chu_icrf,
                rec.flags, rec.confidence, status.has_value(), status.value_or(StatusBits{0})};
    }
};

// Takes every corrected row in file order; finish() after the last, which
// writes what the sink makes into its output of the run's OutputSet (the
// caller commits the set: the outputs of one run appear together).
class CorrectedRowSink {
public:
    virtual ~CorrectedRowSink() = default;
    virtual void add(const CorrectedRow& row) = 0;
    virtual void finish() = 0;
};

// The command's files (atomic_file.hpp's OutputSet): its inputs, and its
// outputs by option: "--out", and "--model-history" with self_calibrate.
struct ModelFile;  // formats/model_csv.hpp

// A model refused for a scalar as by `correct --scalar`: beyond the
// fixed-point formats (check_fixed_point_range, fixed) or beyond the float
// core's bound (check_float_range, float); nothing for double. One rule for
// correct, replay and Python.
void check_model_for_scalar(const ModelFile& m, ScalarKind scalar, const std::string& path);

std::vector<NamedPath> correct_inputs(const CorrectOptions& opt);
std::vector<NamedPath> correct_outputs(const CorrectOptions& opt);

// Writes into outputs (opened from correct_outputs, committed by the caller).
// Throws InputError or std::runtime_error; the caller's outputs are then not
// committed: nothing is written. sink: the corrected rows also go there
// (correct --combined), its finish() called after the last.
CorrectSummary correct_file(const CorrectOptions& opt, OutputSet& outputs, std::ostream& log,
                            CorrectedRowSink* sink = nullptr);
// The same with its own OutputSet, committed at the end.
CorrectSummary correct_file(const CorrectOptions& opt, std::ostream& log);

// A one-paragraph account of a summary, for the terminal.
std::string describe(const CorrectSummary& s);

}  // namespace ascorr::host
