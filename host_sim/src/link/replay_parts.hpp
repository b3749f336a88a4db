// The parts of `ascorr replay` (ascorr_host/link/replay.hpp) its sources share;
// private to the link library: replay.cpp (options, targets, QEMU),
// replay_run.cpp (one session), row_replay.cpp (the rows),
// epoch_combination.cpp (--combined), replay_calibration.cpp
// (--self-calibrate's comparisons) and replay_summary.cpp.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <map>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "ascorr/core/fixed_point.hpp"
#include "ascorr/pipeline/epoch_key.hpp"
#include "ascorr_host/analysis/combine.hpp"
#include "ascorr_host/correct/lagged_temperatures.hpp"
#include "ascorr_host/correct/self_calibration.hpp"
#include "ascorr_host/correct/states_velocity.hpp"
#include "ascorr_host/formats/atomic_file.hpp"
#include "ascorr_host/formats/mountings_csv.hpp"
#include "ascorr_host/formats/solutions_csv.hpp"
#include "ascorr_host/formats/states_csv.hpp"
#include "ascorr_host/link/link_client.hpp"
#include "ascorr_host/link/link_transport.hpp"
#include "ascorr_host/link/replay.hpp"
#include "ascorr_link/server.hpp"

namespace ascorr::host::detail {

// A quaternion of the target's scalar in double.
template <typename T>
Quaternion<double> widen(const Quaternion<T>& q) {
    const auto d = [](const T& x) { return ScalarTraits<T>::to_double(x); };
    return {d(q.w), d(q.x), d(q.y), d(q.z)};
}

// The order the rows go to the target in (row_replay.cpp): the on-board
// clock's (TT µs; rows within one microsecond in file order); rows whose t
// the clock cannot hold last.
std::vector<std::size_t> time_order(const std::vector<SolutionRecord>& rows);

constexpr std::size_t kMaxCalibMessages = 20;  // per kind, as the diagnostics of `ascorr correct`

// The session over an open transport, in the target's scalar T (float or
// Q30): the inputs read, the rows replayed, the outputs written (replay_run.cpp).
template <typename T>
ReplaySummary run(const ReplayOptions& opt, Transport& raw, OutputSet& outputs, std::ostream& log);

// --self-calibrate (replay_calibration.cpp): each solution's model version
// and each new model against the host's; at the end, the report.
template <typename T>
void check_model_version(LinkClient<T>& client, const std::string& file, const SolutionRecord& rec, std::uint32_t got,
                         const std::optional<std::uint32_t>& want, ReplaySummary& sum,
                         std::vector<ActiveModel>& target_history, std::ostream& log, const SelfCalibration& host_sc);
template <typename T>
void finish_self_calibration(LinkClient<T>& client, ReplaySummary& sum, const std::vector<ActiveModel>& target_history,
                             std::ostream& log, const SelfCalibration& host_sc);

// --mountings/--combined: each epoch (rows whose t agree to the
// millisecond, pipeline/epoch_key.hpp; in time order they come together) is
// combined on the target (COMBINE_REQUEST after its last solution) and on the
// host by the same pipeline stage in the same scalar, and the two compared
// bit for bit; the target's is the combined file's row, with the formal σ of
// the host's tables (the same mountings, the head set only). A row in no
// epoch is combined alone and dropped on both sides. (epoch_combination.cpp)
template <typename T>
class EpochCombination {
public:
    EpochCombination(const MountingsFile& m, const combine::CombinerConfig& gate, LinkClient<T>& client,
                     link::LinkPipeline<T>& host, std::string file, std::ostream& log);

    // Before a row at t is sent: the open epoch ends when t is of another.
    void before(double t);
    // After a row at t is sent: a row in no epoch is combined alone, dropped.
    void after(double t);
    void finish(ReplaySummary& sum);
    const std::string& text() const noexcept { return text_; }

private:
    void close(bool write);

    LinkClient<T>& client_;
    link::LinkPipeline<T>& host_;
    combine::Combiner<T> combiner_;
    std::string file_;
    std::ostream& log_;
    pipeline::ConsecutiveEpochs grouper_;  // consecutive rows with one key
    double t_ = 0.0;                       // the epoch's first (earliest) row's
    std::size_t epochs_ = 0;
    std::size_t mismatches_ = 0;
    double instructions_ = 0.0;
    std::size_t costed_ = 0;
    std::string text_;
};

// The host's side of a replay: the target's pipeline on the host, with
// --self-calibrate the host's run of the estimator over the file.
template <typename T>
struct HostSide {
    pipeline::HeadLags<T> lags;                  // the model's, as the target's lag stage
    std::optional<LaggedTemperatures> lagged_d;  // the reference's: `correct`'s lag, in double
    std::optional<SunTermModel<T>> sun;          // the model's Sun term, as the target holds it
    std::optional<SunTermModel<double>> sun_d;   // the reference's
    std::optional<SelfCalibration> sc;
    std::optional<ModelSchedule<double>> schedule_d;  // the host's models in double, for the reference
    // --sun-term auto: each model version's Sun term in T (the host's run's
    // history), which the host's pipeline applies as the target its own;
    // sun_version: the version whose term the pipeline has.
    std::map<std::uint32_t, SunTermModel<T>> version_sun;
    std::optional<std::uint32_t> sun_version;
    std::optional<link::LinkEstimator<T>> estimator;  // the link's
    link::LinkPipeline<T> pipeline;
    std::vector<ActiveModel> target_history;
};

struct WrittenRow {
    std::optional<Quaternion<double>> q;  // none: rejected, the input text unchanged
    StatusBits status;
};

// What replay_rows returns: each row's answer, in file order, and the
// target's instructions over the solutions with both stages applied.
struct ReplayedRows {
    std::vector<WrittenRow> rows;
    double instructions = 0.0;
    std::size_t costed = 0;
};

// The rows through the target and the host, in the on-board clock's time
// order (row_replay.cpp); start: the clock --realtime paces the rows from.
template <typename T>
ReplayedRows replay_rows(const ReplayOptions& opt, const std::vector<SolutionRecord>& rows, LinkClient<T>& client,
                         const std::optional<StatesFile>& states, const VelocityServiceConfig& service,
                         HostSide<T>& host, const ThermalModel<double>& model_d, EpochCombination<T>* combination,
                         ReplaySummary& sum, std::chrono::steady_clock::time_point start, std::ostream& log);

}  // namespace ascorr::host::detail
