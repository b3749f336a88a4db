#include "ascorr_host/correct/correct_file.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <future>
#include <limits>
#include <optional>
#include <ostream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "ascorr/core/correct.hpp"
#include "ascorr/core/fixed_point.hpp"
#include "ascorr_host/correct/correct_row.hpp"
#include "ascorr_host/correct/lagged_temperatures.hpp"
#include "ascorr_host/correct/self_calibration.hpp"
#include "ascorr_host/correct/solution_input.hpp"
#include "ascorr_host/correct/states_velocity.hpp"
#include "ascorr_host/correct/workers.hpp"
#include "ascorr_host/formats/atomic_file.hpp"
#include "ascorr_host/formats/corrected_csv.hpp"
#include "ascorr_host/formats/csv.hpp"
#include "ascorr_host/formats/diagnostics.hpp"
#include "ascorr_host/formats/model_csv.hpp"
#include "ascorr_host/formats/solutions_csv.hpp"
#include "ascorr_host/formats/states_csv.hpp"
#include "ascorr_text/c_format.hpp"
#include "ascorr_text/input_error.hpp"
#include "ascorr_text/input_name.hpp"

namespace ascorr::host {

namespace {

std::string where(const std::string& file, const SolutionRecord& rec) {
    return text::input_name(file) + ":" + std::to_string(rec.line) + ": ";
}

// Explains, once per affected row, the status bits that mean "bad input".
template <typename T, typename Sink>
void explain(const SolutionRecord& rec, const RowCorrection<T>& row, StatusBits st, const std::string& file,
             Sink& diag) {
    const SolutionInput<T>& in = row.in;
    if ((st & status::kRejected) != 0U) {
        std::string why;
        switch (check_solution(in)) {
            case Rejection::kHeadOutOfRange:
                why =
                    "chu '" + std::string(rec.chu) + "' is not a camera head (" + std::string(kHeadChoices.text) + ")";
                break;
            case Rejection::kQuaternionNotFinite:
                why = "quaternion is not finite";
                break;
            case Rejection::kQuaternionNotUnit: {
                const auto& q = rec.q_chu_icrf;
                char buf[96];
                text::c_snprintf(buf, sizeof buf, "quaternion is not unit (|q|^2 = %.9g, tolerance %.1g)",
                                 q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z,
                                 ScalarTraits<T>::to_double(ScalarTraits<T>::unit_norm_tolerance));
                why = buf;
                break;
            }
            case Rejection::kNone:
                break;
        }
        diag.report("rejected", where(file, rec) + why + ": row kept, quaternion unchanged (status 16)");
        return;
    }
    if ((st & status::kVelocityInvalid) != 0U) {
        // (A row without vx,vy,vz reaches here only with a velocity from the
        // states that the core found out of its domain.)
        if (rec.velocity_components != 3 && rec.velocity_components != 0) {
            diag.report("velocity incomplete", where(file, rec) + velocity_problem(rec) + ": aberration skipped");
        } else if (rec.velocity_components == 3 && !in_ephemeris_span(rec.t)) {
            diag.report("outside the ephemeris", where(file, rec) + velocity_problem(rec) + ": aberration skipped");
        } else if (!beta_in_domain(in.velocity.beta_icrf)) {
            const auto b = in.velocity.beta_icrf;
            const double speed = std::sqrt(ScalarTraits<T>::to_double(squared_norm(b))) * kSpeedOfLightKmS;
            char buf[128];
            text::c_snprintf(buf, sizeof buf, "observer speed %.6g km/s is not below %.0f km/s: aberration skipped",
                             speed, kMaxObserverSpeedKmS);
            diag.report("velocity invalid", where(file, rec) + buf);
        } else {
            char buf[160];
            text::c_snprintf(buf, sizeof buf, "Sun distance 1/%.6g au is outside [%g, %g] au: aberration skipped",
                             ScalarTraits<T>::to_double(in.velocity.inv_sun_distance_au), kMinSunDistanceAu,
                             kMaxSunDistanceAu);
            diag.report("velocity invalid", where(file, rec) + buf);
        }
    }
    if ((st & status::kTemperatureInvalid) != 0U) {
        diag.report("temperature invalid",
                    where(file, rec) + "temperature outside +-" + number_text(kMaxAbsTemperatureC) +
                        " C (t_chu=" + number_text(rec.temperature[0]) + ", t_029=" + number_text(rec.temperature[1]) +
                        ", t_032=" + number_text(rec.temperature[2]) + "): thermal skipped");
    }
    if (row.sun_unknown) {
        diag.report("thermal out of range", where(file, rec) + kSunUnknownText);
    } else if ((st & status::kThermalOutOfRange) != 0U) {
        diag.report("thermal out of range",
                    where(file, rec) + "model angle beyond 1 degree for these temperatures: thermal skipped");
    }
    if ((st & status::kNoModelForHead) != 0U) {
        diag.report("no model for head", where(file, rec) + "the model has no coefficients for chu '" +
                                             std::string(rec.chu) + "': thermal skipped");
    }
}

// Diagnostics of one chunk, replayed in file order after the workers join.
class DeferredDiagnostics {
public:
    void report(const std::string& kind, const std::string& message) { items_.emplace_back(kind, message); }
    void replay(Diagnostics& d) const {
        for (const auto& [kind, message] : items_) {
            d.report(kind, message);
        }
    }

private:
    std::vector<std::pair<std::string, std::string>> items_;
};

struct ChunkResult {
    std::string out;
    CorrectSummary summary;
    DeferredDiagnostics diag;
    std::optional<text::InputError> error;  // the first malformed row, when not skipping
    std::size_t empty_lines = 0;
    std::vector<CorrectedRow> rows;  // for the sink (correct --combined), in file order
};

template <typename T>
struct Job {
    const CorrectOptions& opt;
    const CorrectionConfig<T>& cfg;
    const SolutionsReader& header;
    const RowWriter& writer;
    const StatesFile* states;  // nullptr: no --states
    VelocityServiceConfig service;
    const StatesVelocityTable<T>* table;  // the rows' velocities from the states, in time order
    const ModelSchedule<T>* schedule;     // --self-calibrate; nullptr: cfg's model for every row
    const LaggedTemperatures* lag;        // the model's lagged heads; nullptr: none
    const LagSchedule* learnt_lag;        // --lag auto: the lag the self-calibration took; nullptr: none
    const SunTermModel<T>* sun;           // the model's Sun term; nullptr: none
    bool keep_rows;                       // a sink takes the corrected rows
};

// The configuration of one row: with a schedule, the model active at its t.
template <typename T>
CorrectionConfig<T> config_at(const Job<T>& job, double t) {
    if (job.schedule == nullptr) {
        return job.cfg;
    }
    const ThermalModel<T>* m = &job.schedule->at(t);
    return {job.cfg.aberration, job.cfg.thermal != nullptr ? m : nullptr};
}

// The Sun term of one row: with a schedule, that of the model active at its t.
template <typename T>
const SunTermModel<T>* sun_at(const Job<T>& job, double t) {
    return job.schedule != nullptr ? job.schedule->sun_at(t) : job.sun;
}

// With --states, a row without its own velocity gets the service's
// (correct_row); the status bits the service adds (4, 4|512, 4|32) are
// explained here.
template <typename Sink>
void explain_service(StatusBits service, const SolutionRecord& rec, const std::string& file, Sink& diag) {
    if (service == status::kNoVelocity) {
        diag.report("no state yet",
                    where(file, rec) + "no accepted state at or before t: aberration skipped (status 4)");
    } else if ((service & status::kStale) != 0U) {
        diag.report("state too old", where(file, rec) +
                                         "the latest state is older than --max-propagation: aberration skipped "
                                         "(status 4+512)");
    } else if ((service & status::kVelocityInvalid) != 0U) {
        diag.report("velocity from states invalid",
                    where(file, rec) +
                        "the propagated state left a plausible orbit, or t is outside the Earth series' span "
                        "(2000-2050): aberration skipped (status 4+32)");
    }
}

enum class RowRead { kRow, kSkipped, kEnd };

// The next row into rec: kEnd at the end or at a malformed row (res.error
// set), kSkipped for a malformed row under --skip-bad (counted, reported).
RowRead read_row(SolutionsReader& reader, SolutionRecord& rec, const CorrectOptions& opt, ChunkResult& res) {
    try {
        return reader.next(rec) ? RowRead::kRow : RowRead::kEnd;
    } catch (const text::InputError& e) {
        if (!opt.skip_bad) {
            res.error = e;
            return RowRead::kEnd;
        }
        ++res.summary.malformed;
        res.diag.report("malformed", std::string(e.what()) + " (row skipped: --skip-bad)");
        return RowRead::kSkipped;
    }
}

template <typename Summary>
void count_status_bits(StatusBits st, Summary& summary) {
    for (std::size_t b = 0; b < summary.status_bit.size(); ++b) {
        summary.status_bit[b] += (static_cast<unsigned>(st) >> b) & 1U;
    }
}

// rec as the thermal stage's terms take it: with a lagged model, its head's
// lagged temperatures, in `lagged` (the messages and the written row keep the
// row's own readings); otherwise rec itself.
template <typename T>
const SolutionRecord& as_terms_take(const Job<T>& job, const CorrectionConfig<T>& cfg, const SolutionRecord& rec,
                                    SolutionRecord& lagged) {
    if ((job.lag == nullptr && job.learnt_lag == nullptr) || cfg.thermal == nullptr) {
        return rec;
    }
    lagged = rec;
    if (job.lag != nullptr) {
        job.lag->apply(lagged);
    } else {
        job.learnt_lag->apply(lagged);
    }
    return lagged;
}

template <typename T>
void correct_chunk(const Job<T>& job, std::string_view body, std::size_t lines_before, ChunkResult& res) {
    const CorrectOptions& opt = job.opt;
    SolutionsReader reader(job.header, body, lines_before);
    EarthVelocity earth;
    std::optional<StatesVelocity<T>> states;
    if (job.states != nullptr) {
        states.emplace(*job.states, job.service, job.table);
    }
    SolutionRecord rec;
    SolutionRecord lagged;  // rec as a lagged model's terms take it
    res.out.reserve(body.size() + body.size() / 8);
    for (RowRead got = read_row(reader, rec, opt, res); got != RowRead::kEnd; got = read_row(reader, rec, opt, res)) {
        if (got == RowRead::kSkipped) {
            continue;
        }
        const CorrectionConfig<T> cfg = config_at(job, rec.t);
        const RowCorrection<T> row = correct_row(as_terms_take(job, cfg, rec, lagged), &earth, cfg,
                                                 states ? &*states : nullptr, sun_at(job, rec.t));
        const StatusBits st = row.status;
        if (row.from_states) {
            explain_service(row.service, rec, opt.in, res.diag);
        }
        // A states row whose 32 comes from the service is explained by
        // explain_service(); a 32 from the core itself (speed, Sun distance) by explain().
        const bool service_invalid = row.from_states && (row.service & status::kVelocityInvalid) != 0U;
        explain(rec, row, service_invalid ? static_cast<StatusBits>(st & ~status::kVelocityInvalid) : st, opt.in,
                res.diag);
        if ((st & status::kRejected) != 0U) {
            job.writer.row(reader, std::nullopt, st, res.out);  // the input text, unchanged
        } else {
            job.writer.row(reader, row.q_chu_icrf, st, res.out);
        }
        if (job.keep_rows) {
            res.rows.push_back({rec.t, rec.line, rec.head,
                                (st & status::kRejected) != 0U ? rec.q_chu_icrf : as_written(row.q_chu_icrf), rec.flags,
                                rec.confidence, true, st});
        }
        ++res.summary.rows;
        count_status_bits(st, res.summary);
    }
    res.empty_lines = reader.empty_lines();
    if (states) {
        res.summary.service_cost = states->cost();
    }
}

// Splits a block of whole lines into n pieces of about equal size, at line ends.
std::vector<std::string_view> split_at_lines(std::string_view block, std::size_t n) {
    std::vector<std::string_view> parts;
    std::size_t start = 0;
    for (std::size_t i = 1; i <= n && start < block.size(); ++i) {
        std::size_t end = i == n ? block.size() : std::max(start, block.size() * i / n);
        if (end < block.size()) {
            const std::size_t nl = block.find('\n', end);
            end = nl == std::string_view::npos ? block.size() : nl + 1;
        }
        parts.push_back(block.substr(start, end - start));
        start = end;
    }
    return parts;
}

// What collect(rec, out) gathers from every row of the file that parses, in
// parallel parts of each block; each part's out is passed to finish(out)
// before the parts are joined in file order. Rows that do not parse are left
// to the correction, which reports them.
template <typename Item, typename Collect, typename Finish>
std::vector<Item> scan_rows(const std::string& path, const SolutionsReader& header, std::size_t workers,
                            const Collect& collect, const Finish& finish) {
    BlockReader blocks(path);
    std::string_view block;
    std::vector<Item> out;
    for (bool first = true; blocks.next(block); first = false) {
        if (first) {  // the header line is not data
            const std::size_t nl = block.find('\n');
            block = nl == std::string_view::npos ? std::string_view() : block.substr(nl + 1);
        }
        const std::vector<std::string_view> parts = split_at_lines(block, workers);
        std::vector<std::vector<Item>> items(parts.size());
        const auto scan = [&](std::size_t i) {
            SolutionsReader reader(header, parts[i], 0);
            SolutionRecord rec;
            for (;;) {
                try {
                    if (!reader.next(rec)) {
                        break;
                    }
                } catch (const text::InputError&) {
                    continue;
                }
                collect(rec, items[i]);
            }
            finish(items[i]);
        };
        run_workers(parts.size(), scan);
        for (const auto& part : items) {
            out.insert(out.end(), part.begin(), part.end());
        }
    }
    return out;
}

// The TtTime (µs) of every row that will ask the states for its velocity (no
// vx,vy,vz; a usable t), read ahead of the correction so that the service
// answers in time order (StatesVelocityTable), whatever the rows' order.
std::vector<std::int64_t> service_times(const std::string& path, const SolutionsReader& header, std::size_t workers) {
    return scan_rows<std::int64_t>(
        path, header, workers,
        [](const SolutionRecord& rec, std::vector<std::int64_t>& times) {
            TtTime t{};
            if (rec.velocity_components == 0 && tt_from_seconds(rec.t, t)) {
                times.push_back(t.us);
            }
        },
        [](std::vector<std::int64_t>& times) {
            std::sort(times.begin(), times.end());  // the heads of an epoch: one time
            times.erase(std::unique(times.begin(), times.end()), times.end());
        });
}

// The readings of the rows of the heads the run lags (run_lags), read ahead of
// the correction and of the self-calibration: each head's lag runs over its
// rows in time order. None without a thermal stage, or when no head lags.
std::optional<LaggedTemperatures> lagged_temperatures(const std::string& path, const SolutionsReader& header,
                                                      std::size_t workers, const std::array<double, kMaxHeads>& lag_s,
                                                      bool thermal) {
    if (!thermal || !pipeline::any_lagged(lag_s)) {
        return std::nullopt;
    }
    std::vector<LagReading> readings = scan_rows<LagReading>(
        path, header, workers,
        [&](const SolutionRecord& rec, std::vector<LagReading>& out) {
            LagReading r;
            if (rec.head < kMaxHeads && lag_s[rec.head] != 0.0 && lag_reading_of(rec, r)) {
                out.push_back(r);
            }
        },
        [](std::vector<LagReading>&) {});
    return LaggedTemperatures(lag_s, std::move(readings));
}

// --self-calibrate's run (self_calibration.hpp): the models the rows are
// corrected with, the history file's text and the terminal's account.
template <typename T>
struct SelfCalibrated {
    ModelSchedule<T> schedule;
    std::string history;
    std::string account;
    std::optional<LagSchedule> learnt_lag;  // --lag auto, when a model of the history lags
};

template <typename T>
SelfCalibrated<T> self_calibrated(const CorrectOptions& opt, const std::optional<ModelFile>& model_file,
                                  const LaggedTemperatures* lag) {
    calib::EstimatorConfig ecfg;
    ecfg.time_constant_days = opt.time_constant_days;
    ecfg.common_rotation = opt.common_rotation;
    ecfg.regauge_arcsec = opt.regauge_arcsec;
    const RowSource rows = [&](const std::function<void(const SolutionRecord&)>& fn) {
        for_each_solution(opt.in, fn, "correct");
    };
    const SelfCalibration sc =
        self_calibrate<T>(opt.in, lag != nullptr ? lagged_rows(rows, *lag) : rows, model_file, ecfg, opt.orbit_period_s,
                          kSelfCalibrationMemoryBytes, kMaxHeads,
                          lag != nullptr ? lag->lag_s() : std::array<double, kMaxHeads>{}, opt.lag_auto, opt.sun_auto);
    return {ModelSchedule<T>(sc.history), format_model_history(sc.history, opt.common_rotation.heads != 0U),
            describe(sc), opt.lag_auto ? learnt_lags(sc.history, rows) : std::nullopt};
}

// The lags a --lag auto run took (nullptr: none, or no such run).
template <typename T>
const LagSchedule* learnt_lag_of(const std::optional<SelfCalibrated<T>>& sc) noexcept {
    return sc && sc->learnt_lag ? &*sc->learnt_lag : nullptr;
}

void refuse_self_calibration_options(const CorrectOptions& opt) {
    if (!opt.thermal) {
        throw std::runtime_error("--self-calibrate estimates the thermal model: it cannot go with --no-thermal");
    }
    if (!opt.aberration) {
        throw std::runtime_error(
            "--self-calibrate learns from aberration-corrected solutions: it cannot go with --no-aberration");
    }
    if (opt.skip_bad) {
        throw std::runtime_error("--self-calibrate reads every row in time order: it cannot go with --skip-bad");
    }
    if (!calib::time_constant_acceptable(opt.time_constant_days)) {
        throw std::runtime_error("--time-constant must be in " + time_constant_range() + " days, got " +
                                 number_text(opt.time_constant_days));
    }
    if (opt.orbit_period_s && !orbit_period_acceptable(*opt.orbit_period_s)) {
        throw std::runtime_error("--orbit-period must be in " + orbit_period_range() + " s, got " +
                                 number_text(*opt.orbit_period_s));
    }
    if (!opt.states.empty()) {
        // The estimator's pass reads the rows' own velocities only: rows whose
        // velocity would come from the states would never be learnt from.
        throw std::runtime_error(
            "--self-calibrate learns from rows with their own vx,vy,vz: it cannot go with --states");
    }
    if (!opt.model_history.empty()) {
        refuse_same_output({"--out", opt.out}, {"--model-history", opt.model_history});
    }
}

// --model read and checked for the scalar (none without --model or with
// --no-thermal); the file kept in model_file for the self-calibration.
template <typename T>
std::optional<ThermalModel<T>> read_model(const CorrectOptions& opt, std::optional<ModelFile>& model_file) {
    if (!opt.thermal || opt.model.empty()) {
        return std::nullopt;
    }
    model_file = read_model_file(opt.model);
    check_model_for_scalar(*model_file, scalar_kind_of<T>(), opt.model);
    if (opt.self_calibrate) {
        refuse_quadratic_initial_model(*model_file, opt.model);
        if (opt.lag_auto) {
            refuse_lag_to_learn(*model_file, opt.model, "--lag auto");
        }
        refuse_other_lag(*model_file, opt.model, run_lags(opt.lag_s, model_file));
        refuse_sun_term(*model_file, opt.model, kSunTermNotLearnt);
    }
    return to_core<T>(*model_file);
}

// --states read (none without it), after --max-propagation's check.
std::optional<StatesFile> read_states(const CorrectOptions& opt, Diagnostics& diag) {
    if (opt.states.empty()) {
        return std::nullopt;
    }
    if (!max_propagation_acceptable(opt.max_propagation_s)) {
        throw std::runtime_error(std::string("--max-propagation ") + kMaxPropagationRule);
    }
    return read_states_file(opt.states, opt.states_gcrs ? StateFrame::kGcrs : StateFrame::kItrf, diag, opt.skip_bad);
}

// One chunk's results into the run's, in file order: its messages, its
// error (thrown), its counts and its rows for the sink.
void merge_chunk(const ChunkResult& r, Diagnostics& diag, CorrectSummary& sum, std::size_t& empty_lines,
                 CorrectedRowSink* sink) {
    r.diag.replay(diag);
    if (r.error) {
        throw *r.error;
    }
    sum.rows += r.summary.rows;
    sum.malformed += r.summary.malformed;
    sum.service_cost += r.summary.service_cost;
    for (std::size_t b = 0; b < sum.status_bit.size(); ++b) {
        sum.status_bit[b] += r.summary.status_bit[b];
    }
    empty_lines += r.empty_lines;
    for (const CorrectedRow& row : r.rows) {
        sink->add(row);
    }
}

// The lines before each of a block's parts, the first's being lines_before.
std::vector<std::size_t> lines_before_parts(const std::vector<std::string_view>& parts, std::size_t lines_before) {
    std::vector<std::size_t> first_line(parts.size(), lines_before);
    for (std::size_t i = 1; i < parts.size(); ++i) {
        first_line[i] = first_line[i - 1] + count_line_ends(parts[i - 1]);
    }
    return first_line;
}

void count_states(const std::optional<StatesFile>& states, CorrectSummary& sum) {
    if (states) {
        sum.states_given = true;
        sum.states_accepted = states->accepted.size();
        sum.states_refused = states->refused();
        sum.states_malformed = states->malformed;
    }
}

// The end of the rows: the empty lines and the messages' summary; a file
// whose every row --skip-bad dropped is refused.
void report_rows(const CorrectOptions& opt, const CorrectSummary& sum, std::size_t empty_lines, Diagnostics& diag,
                 std::ostream& log) {
    if (empty_lines != 0) {
        log << opt.in << ": " << empty_lines << " empty line(s) ignored\n";
    }
    diag.summarize();
    if (sum.rows == 0 && sum.malformed != 0) {  // --skip-bad dropped everything: not a success
        throw text::InputError(opt.in, 1, 1,
                               "every one of the " + std::to_string(sum.malformed) +
                                   " data rows is malformed (--skip-bad dropped them all): nothing written");
    }
}

// The write in flight, if any, finished (its error thrown here).
void wait_for(std::future<void>& writing) {
    if (writing.valid()) {
        writing.get();
    }
}

// The velocities the states give the rows without their own (--states,
// with the aberration stage), by the on-board service.
template <typename T>
std::optional<StatesVelocityTable<T>> velocity_table(const CorrectOptions& opt, const std::optional<StatesFile>& states,
                                                     const SolutionsReader& header, std::size_t workers) {
    std::optional<StatesVelocityTable<T>> table;
    if (states && opt.aberration) {
        table.emplace(*states, service_config(opt.max_propagation_s), service_times(opt.in, header, workers), workers);
    }
    return table;
}

// What the options cannot do together: the self-calibration's
// (refuse_self_calibration_options), and --lag without it.
void refuse_run_options(const CorrectOptions& opt) {
    if (const std::string bad = bad_lag_text(opt.lag_s); !bad.empty()) {
        throw std::runtime_error(bad);
    }
    if (opt.self_calibrate) {
        refuse_self_calibration_options(opt);
    } else if (opt.lag_s || opt.lag_auto) {
        throw std::runtime_error(std::string("--lag ") + kLagNeedsSelfCalibration);
    }
    if (opt.lag_s && opt.lag_auto) {
        throw std::runtime_error("--lag auto learns the lag and --lag TAU gives it: give one");
    }
    if (opt.sun_auto && !opt.self_calibrate) {
        throw std::runtime_error(std::string("--sun-term ") + kSunTermNeedsSelfCalibration);
    }
}

template <typename T>
CorrectSummary run(const CorrectOptions& opt, OutputSet& outputs, std::ostream& log, CorrectedRowSink* sink) {
    refuse_output_over_input({{"--in", opt.in}, {"--model", opt.model}, {"--states", opt.states}},
                             {{"--out", opt.out}, {"--model-history", opt.model_history}});
    refuse_run_options(opt);  // before the model: a --lag out of range is named as such, not as another τ
    std::optional<ModelFile> model_file;
    std::optional<ThermalModel<T>> model = read_model<T>(opt, model_file);

    BlockReader blocks(opt.in);
    std::string_view block;
    if (!blocks.next(block)) {
        throw text::InputError(opt.in, 1, 1, "empty file: expected a header line");
    }
    const SolutionsReader header(opt.in, block.substr(0, block.find('\n')));
    refuse_corrected_input(header);
    const RowWriter writer(header);
    Diagnostics diag(log);
    const std::optional<StatesFile> states = read_states(opt, diag);
    const std::size_t workers = worker_count();
    const std::optional<StatesVelocityTable<T>> table = velocity_table<T>(opt, states, header, workers);
    // (Without --model or --self-calibrate no head lags: --lag needs the latter.)
    const std::optional<LaggedTemperatures> lag =
        lagged_temperatures(opt.in, header, workers, run_lags(opt.lag_s, model_file), opt.thermal);
    std::optional<SelfCalibrated<T>> sc;
    if (opt.self_calibrate) {
        sc.emplace(self_calibrated<T>(opt, model_file, lag ? &*lag : nullptr));
        model = ThermalModel<T>{};  // marks the thermal stage on; the schedule gives the model
    }
    const CorrectionConfig<T> cfg{opt.aberration, model ? &*model : nullptr};
    // The model's Sun term in T, once (refused with --self-calibrate: read_model).
    const std::optional<SunTermModel<T>> sun = sun_term_if_any<T>(model_file);
    const Job<T> job{opt,
                     cfg,
                     header,
                     writer,
                     states ? &*states : nullptr,
                     service_config(opt.max_propagation_s),
                     table ? &*table : nullptr,
                     sc ? &sc->schedule : nullptr,
                     lag ? &*lag : nullptr,
                     learnt_lag_of(sc),
                     sun ? &*sun : nullptr,
                     sink != nullptr};

    AtomicFile& out = outputs["--out"];
    out.write(writer.header_line());
    CorrectSummary sum;
    if (table) {
        sum.service_cost = table->cost();
    }
    count_states(states, sum);
    std::size_t empty_lines = 0;
    std::future<void> writing;  // declared after `out`: destroyed (joined) before it
    bool first = true;
    do {
        std::size_t lines_before = blocks.lines_before();
        if (first) {  // the header line is not data
            const std::size_t nl = block.find('\n');
            block = nl == std::string_view::npos ? std::string_view() : block.substr(nl + 1);
            lines_before += 1;
            first = false;
        }
        const std::vector<std::string_view> parts = split_at_lines(block, workers);
        const std::vector<std::size_t> first_line = lines_before_parts(parts, lines_before);
        std::vector<ChunkResult> results(parts.size());
        run_workers(parts.size(), [&](std::size_t i) { correct_chunk(job, parts[i], first_line[i], results[i]); });
        for (const ChunkResult& r : results) {  // in file order
            merge_chunk(r, diag, sum, empty_lines, sink);
        }
        // Write this block while the workers correct the next one; one block
        // in flight, its errors surface at the next block or at the end.
        wait_for(writing);
        writing = std::async(std::launch::async, [&out, done = std::move(results)] {
            for (const ChunkResult& r : done) {
                out.write(r.out);
            }
        });
    } while (blocks.next(block));
    wait_for(writing);
    report_rows(opt, sum, empty_lines, diag, log);
    if (outputs.has("--model-history")) {
        outputs["--model-history"].write(sc->history);
    }
    if (sink != nullptr) {
        sink->finish();  // into its own output of the set
    }
    sum.self_calibration = sc ? sc->account : std::string();
    return sum;
}

}  // namespace

void check_model_for_scalar(const ModelFile& m, ScalarKind scalar, const std::string& path) {
    if (scalar == ScalarKind::kFixed) {
        check_fixed_point_range(m, path);
    } else if (scalar == ScalarKind::kFloat) {
        check_float_range(m, path);
    }
}

std::vector<NamedPath> correct_inputs(const CorrectOptions& opt) {
    return {{"--in", opt.in}, {"--model", opt.model}, {"--states", opt.states}};
}

std::vector<NamedPath> correct_outputs(const CorrectOptions& opt) {
    std::vector<NamedPath> outputs = {{"--out", opt.out}};
    if (opt.self_calibrate && !opt.model_history.empty()) {
        outputs.push_back({"--model-history", opt.model_history});
    }
    return outputs;
}

CorrectSummary correct_file(const CorrectOptions& opt, OutputSet& outputs, std::ostream& log, CorrectedRowSink* sink) {
    switch (opt.scalar) {
        case ScalarKind::kDouble:
            return run<double>(opt, outputs, log, sink);
        case ScalarKind::kFloat:
            return run<float>(opt, outputs, log, sink);
        case ScalarKind::kFixed:
            return run<Q30>(opt, outputs, log, sink);
    }
    throw std::logic_error("correct_file: unknown scalar type");
}

CorrectSummary correct_file(const CorrectOptions& opt, std::ostream& log) {
    OutputSet outputs(correct_outputs(opt), correct_inputs(opt));
    const CorrectSummary s = correct_file(opt, outputs, log);
    outputs.commit();
    return s;
}

std::string describe(const CorrectSummary& s) {
    std::ostringstream o;
    o << s.rows << " rows written";
    for (std::size_t b = 0; b < static_cast<std::size_t>(status::kStatusBitCount); ++b) {
        if (s.status_bit[b] != 0) {
            o << ", " << s.status_bit[b] << " " << status::kStatusBitNames[b];
        }
    }
    if (s.malformed != 0) {
        o << ", " << s.malformed << " malformed rows skipped";
    }
    if (s.states_given) {
        o << "; states: " << s.states_accepted << " accepted, " << s.states_refused << " refused";
        if (s.states_malformed != 0) {
            o << ", " << s.states_malformed << " malformed skipped";
        }
    }
    return o.str();
}

}  // namespace ascorr::host
