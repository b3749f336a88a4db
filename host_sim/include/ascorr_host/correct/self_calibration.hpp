// ascorr_host/correct/self_calibration.hpp: the on-board estimator (calib/estimator.hpp)
// run over a recorded file, as `ascorr correct --self-calibrate` and the
// Python module do it (docs/contract.md, "Self-calibration").
//
// The rows are read once (twice when they are not in time order), in any
// order; only the selected ones are kept. The estimator is fed in time order
// (t, then line), one cycle per distinct t: at each, the model for the cycle
// is taken first (a model adopted after an earlier cycle becomes active here),
// then the cycle's selected solutions of A, B and C (the ground fit's
// selection, fit_selection(), and the aberration stage in the scalar T) are
// accumulated, then the idle-time work runs to its end. The result is the
// schedule of active models: each row is corrected with the model active at
// its t. Before the first one, rows get a model with no head present, so the
// core sets 256 (no model coefficients) and skips the thermal stage. A row
// whose t the on-board clock cannot hold (nav/tt_time.hpp: |t| > 1e11 s) is
// no cycle and no time at which a model becomes active; it is only counted.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "ascorr/calib/estimator.hpp"
#include "ascorr_host/formats/model_csv.hpp"
#include "ascorr_host/formats/solutions_csv.hpp"

namespace ascorr::host {

struct ActiveModel {
    double t;               // active from this time on (the first cycle using it)
    std::uint32_t version;  // 0: the model given at start
    std::uint32_t crc;      // calib::model_crc
    ModelFile model;
};

struct SelfCalibration {
    std::vector<ActiveModel> history;  // in time order
    calib::EstimatorReport report;     // at the end of the file
    double orbit_period_s = 0.0;
    std::size_t cycles = 0;  // selected epochs with A, B and C
    // Rows whose t the on-board clock cannot hold (tt_from_seconds: |t| >
    // 1e11 s): neither learnt from nor a time at which a model becomes active.
    std::size_t rows_unclocked = 0;
};

// kind: "double", "float" or "fixed" is chosen by T. initial: --model.
// orbit_period_s: when not given, from the earliest selected row's speed
// (as `ascorr fit`). Throws InputError for a file whose rows cannot be read.
template <typename T>
SelfCalibration self_calibrate(const std::string& file, const RowSource& rows, const std::optional<ModelFile>& initial,
                               const calib::EstimatorConfig& cfg, std::optional<double> orbit_period_s);

// The model history file (docs/contract.md): header
// t,version,chu,axis,c0,c1,c2,c3,crc32c and one row per head and axis of each model.
std::string format_model_history(const std::vector<ActiveModel>& history);

// One line per model and the estimator's state, for the terminal.
std::string describe(const SelfCalibration& s);

}  // namespace ascorr::host
