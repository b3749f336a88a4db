#include "ascorr_host/correct/self_calibration.hpp"

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <sstream>
#include <stdexcept>
#include <type_traits>

#include "ascorr/core/correct.hpp"
#include "ascorr/core/fixed_point.hpp"
#include "ascorr/nav/orbit_propagation.hpp"
#include "ascorr/nav/tt_time.hpp"
#include "ascorr/pipeline/epoch_pipeline.hpp"
#include "ascorr_host/correct/earth_velocity.hpp"
#include "ascorr_host/correct/selection.hpp"
#include "ascorr_host/correct/solution_input.hpp"
#include "ascorr_host/formats/csv.hpp"
#include "ascorr_text/c_format.hpp"
#include "ascorr_text/input_error.hpp"

namespace ascorr::host {

namespace {

// The side learners a run has (self_calibrate's learn_lag, learn_sun).
struct SideLearning {
    bool lag = false;
    bool sun = false;
    std::int64_t sun_interval_us = 0;  // the learner's (SunLearner: 0, every cycle)
};

// The model file's Sun term of a learnt one, for the heads m has.
// One row as the run needs it: its epoch, and for a clean row of A, B or C
// whose aberration stage applies, its input to the core.
template <typename T>
struct CalibRow {
    std::int64_t t_us;
    double t;
    std::size_t line;
    bool fed;
    double speed_kms;  // fed rows: |v_sc|, for the orbit period
    SolutionInput<T> in;
};

// The orbit period, when not given, from the speeds of the first
// kOrbitPeriodRows fed rows in time order (docs/contract.md,
// Self-calibration): their median's circular orbit (vis-viva), so that no
// single row decides; a set in which fewer than three quarters lie within
// kPeriodSpeedTolerance of the median is refused (an eccentric orbit or
// corrupted velocities: give --orbit-period).
constexpr double kPeriodSpeedTolerance = 0.01;

// The estimator over rows taken in time order (t_us, then line), one at a
// time, as the link server takes them. Until the orbit period is known (given,
// or kOrbitPeriodRows fed rows seen), rows are held and replayed when the
// estimator starts: the fed rows whole, and of the epochs between two fed rows
// only the first and the last (the others change nothing: no model becomes
// pending without a fed epoch, and the run's pipeline feeds every epoch, so
// the epochs' count does not matter), so the rows held are bounded.
template <typename T, std::size_t N>
class Run {
public:
    Run(const std::string& file, const std::optional<ModelFile>& initial, const calib::EstimatorConfig& cfg,
        std::optional<double> orbit_period_s, SideLearning learn)
        : file_(file), cfg_(cfg), learn_(learn) {
        if (initial) {
            initial_ = coefficients_of(*initial);
        }
        if (orbit_period_s) {
            start(*orbit_period_s);
        }
    }

    void take(const CalibRow<T>& r) {
        if (est_) {
            process(r);
        } else {
            hold(r);
        }
    }

    SelfCalibration finish(std::size_t untimed) {
        if (!est_) {
            // Fewer than kOrbitPeriodRows fed rows: their period; none: nothing is
            // learnt, the period is not used.
            start(fed_held_ > 0 ? period_from_speeds()
                                : static_cast<double>(calib::EstimatorConfig{}.orbit_period_us) / 1e6);
        }
        out_.report = est_->report();
        out_.regauges = est_->regauges();
        out_.untimed = untimed;
        if (search_) {
            search_->finish();
            out_.lag_search = search_->report();
        }
        if (sun_) {
            out_.sun_learnt_at_last_epoch = sun_->report();
            sun_->finish();
            out_.sun_learnt = sun_->report();
        }
        return out_;
    }

private:
    void process(const CalibRow<T>& r) {
        (void)epoch(r.t_us, r.t);
        if (r.fed) {
            const std::uint32_t feeds = pipeline_.feeds();
            (void)pipeline_.solution(
                r.in, [&r] { return pipeline::given_velocity(r.in.velocity); }, true);
            out_.cycles += pipeline_.feeds() - feeds;
            if (pipeline_.feeds() != feeds && pipeline_.model() != nullptr) {
                learn_beside(r.t_us);
            }
        }
    }

    void hold(const CalibRow<T>& r) {
        const std::size_t n = held_.size();
        if (!r.fed && n >= 2 && !held_[n - 1].fed && !held_[n - 2].fed) {
            if (r.t_us != held_[n - 1].t_us) {
                held_[n - 1] = r;  // the last epoch between two fed rows so far
            }
            return;
        }
        held_.push_back(r);
        if (r.fed && ++fed_held_ == kOrbitPeriodRows) {
            start(period_from_speeds());
        }
    }

    // A circular orbit's period at the median speed of the fed rows held
    // (vis-viva); the estimator's limits (10 min to a day) are speeds of 3.3
    // to 16 km/s: beyond 12 km/s nothing is bound to the Earth.
    double period_from_speeds() const {
        std::vector<const CalibRow<T>*> fed;
        for (const CalibRow<T>& r : held_) {
            if (r.fed) {
                fed.push_back(&r);
            }
        }
        const auto by_speed = [](const CalibRow<T>* a, const CalibRow<T>* b) {  // ties by line: one median row
            return a->speed_kms < b->speed_kms || (a->speed_kms == b->speed_kms && a->line < b->line);
        };
        const auto mid = fed.begin() + static_cast<std::ptrdiff_t>((fed.size() - 1) / 2);
        std::nth_element(fed.begin(), mid, fed.end(), by_speed);
        const CalibRow<T>& median = **mid;
        const double v = median.speed_kms;
        const std::size_t near = static_cast<std::size_t>(std::count_if(fed.begin(), fed.end(), [v](const auto* r) {
            return std::fabs(r->speed_kms - v) <= kPeriodSpeedTolerance * v;
        }));
        if (4 * near < 3 * fed.size()) {
            throw text::InputError(file_, median.line, 1,
                                   "the spacecraft speeds of the first " + std::to_string(fed.size()) +
                                       " rows the self-calibration learns from disagree: " + std::to_string(near) +
                                       " are within " + number_text(kPeriodSpeedTolerance * 100.0) +
                                       " % of their median " + number_text(v) +
                                       " km/s (three quarters must be): the orbit period cannot be derived; give "
                                       "--orbit-period");
        }
        const double period_s = 2.0 * kPi * kEarthGmKm3S2 / (v * v * v);
        if (!(v < 12.0 && period_s * 1e6 <= static_cast<double>(calib::kMaxOrbitPeriodUs))) {
            throw text::InputError(
                file_, median.line, 1,
                "spacecraft speed " + number_text(v) +
                    " km/s is not that of an Earth orbit of 10 min to a day: the orbit period for the "
                    "self-calibration cannot be derived; give --orbit-period");
        }
        return period_s;
    }

    void start(double period_s) {
        if (!orbit_period_acceptable(period_s)) {
            throw std::invalid_argument("orbit period " + number_text(period_s) + " s is outside the estimator's " +
                                        orbit_period_range() + " s");
        }
        out_.orbit_period_s = period_s;
        cfg_.orbit_period_us = static_cast<std::int64_t>(std::llround(period_s * 1e6));
        est_.emplace(cfg_, initial_ ? &*initial_ : nullptr);
        pipeline_.use_estimator(&*est_);
        if (learn_.lag) {
            search_.emplace(cfg_);
        }
        if (learn_.sun) {
            sun_.emplace(cfg_, learn_.sun_interval_us);
        }
        for (const CalibRow<T>& r : held_) {
            process(r);
        }
        held_.clear();
        held_.shrink_to_fit();
    }

    // The epoch's model (a new epoch when t_us changes), and the history.
    const ThermalModel<T>* epoch(std::int64_t t_us, double t) {
        const ThermalModel<T>* model = pipeline_.begin(t_us);
        if (model != nullptr && (!had_ || pipeline_.version() != version_)) {
            out_.history.push_back({t, t_us, pipeline_.version(), est_->active_crc(),
                                    model_file_of(*est_->active_coefficients()), est_->active_learnt()});
            ModelFile& m = out_.history.back().model;
            if (search_) {  // a version takes the lag the search has taken by then
                m.lag_s.fill(search_->tau_s());
                m.lag_s = head_lags(m);
            }
            if (sun_) {  // ... and the Sun term the learner has taken
                sun_->version_term(heads_where(m.present), m.sun);
            }
            had_ = true;
            version_ = pipeline_.version();
        }
        return model;
    }

    // The fed cycle's frame heads into the lag search, with the epoch's
    // model, and into the Sun term's learner, as corrected at the lag taken.
    void learn_beside(std::int64_t t_us) {
        const CorrectedSolution<T>* kept = pipeline_.kept_solutions();
        if (search_) {
            const HeadTemperatures<T>* tp[calib::kFrameHeads];
            for (std::size_t h = 0; h < calib::kFrameHeads; ++h) {
                tp[h] = &pipeline_.kept_temperatures()[h];
            }
            if (search_->take(t_us, *pipeline_.model(), kept, tp) && sun_) {
                learn_sun(t_us, search_->taken_attitudes());
            }
            return;
        }
        if (sun_) {
            (void)sun_->take_kept(t_us, kept);
            sun_idle();
        }
    }

    void learn_sun(std::int64_t t_us, const Quaternion<double> (&q)[calib::kFrameHeads]) {
        (void)sun_->take(t_us, q);
        sun_idle();
    }
    // After the learner's take: its per-orbit work, as idle time (in use
    // from the next cycle it takes: SunLearner::settle).
    void sun_idle() { (void)sun_->step_all(); }

    const std::string& file_;
    calib::EstimatorConfig cfg_;
    SideLearning learn_;
    std::optional<calib::LagSearch<T>> search_;  // learn_.lag: the bench's lag (calib/lag_search.hpp)
    std::optional<calib::SunLearner> sun_;       // learn_.sun: the Sun term (calib/sun_learner.hpp)
    std::optional<ModelCoefficients> initial_;
    std::optional<calib::Estimator<T, N>> est_;
    pipeline::EpochPipeline<T, pipeline::InlineCalls<T>, N> pipeline_;
    std::vector<CalibRow<T>> held_;  // rows before the orbit period is known (hold)
    std::size_t fed_held_ = 0;
    bool had_ = false;
    std::uint32_t version_ = 0;
    SelfCalibration out_;
};

// The clock's order: TT µs, then the line (rows and their keys).
template <typename A, typename B>
bool before(const A& a, const B& b) {
    return a.t_us < b.t_us || (a.t_us == b.t_us && a.line < b.line);
}

// Rows sorted into the clock's order within a memory budget. Each row is a
// 24-byte key, and a fed row also its input (CalibRow); a run is sorted in
// memory. When a run fills the budget it is written, sorted, to an anonymous
// temporary file (std::tmpfile: gone when closed, at exit and on a signal),
// and each() merges the runs, each read through a small buffer: the memory
// stays within about the budget whatever the number of rows (the disk holds
// them). One run (the usual case) never touches the disk.
template <typename T>
class SortedRuns {
public:
    explicit SortedRuns(std::size_t budget_bytes) : budget_(std::max<std::size_t>(budget_bytes, 4096)) {}
    SortedRuns(const SortedRuns&) = delete;
    SortedRuns& operator=(const SortedRuns&) = delete;
    ~SortedRuns() {
        if (file_ != nullptr) {
            (void)std::fclose(file_);
        }
    }

    void add(const CalibRow<T>& r) {
        // (Line numbers fit 32 bits: a file of 4 × 10⁹ lines is beyond any recording.)
        keys_.push_back(
            {r.t_us, r.t, static_cast<std::uint32_t>(r.line), r.fed ? static_cast<std::uint32_t>(fed_.size()) : kNone});
        if (r.fed) {
            fed_.push_back(r);
        }
        if (bytes() >= budget_) {
            spill();
        }
    }

    // Calls fn for every row in the clock's order.
    template <typename Fn>
    void each(Fn&& fn) {
        if (file_ == nullptr) {
            sort_run();
            for (const Key& k : keys_) {
                fn(row_of(k));
            }
            return;
        }
        if (!keys_.empty()) {
            spill();
        }
        merge(fn);
    }

    std::size_t count() const noexcept { return spilled_.empty() ? 1U : spilled_.size(); }

private:
    struct Key {
        std::int64_t t_us;
        double t;
        std::uint32_t line;
        std::uint32_t fed;  // index in fed_ (in a run file: 1 when the row's input follows), or kNone
    };
    static constexpr std::uint32_t kNone = 0xFFFFFFFFU;
    static_assert(std::is_trivially_copyable_v<CalibRow<T>>, "rows are written to the run file as bytes");

    // A spilled run: its bytes [begin, end) in the file, read through a buffer.
    struct RunReader {
        std::int64_t at;
        std::int64_t end;
        std::vector<char> buf;
        std::size_t pos = 0;
        std::size_t len = 0;
        Key key{};
        CalibRow<T> row{};
    };

    // What the run holds, as allocated (a vector grows beyond its size).
    std::size_t bytes() const noexcept {
        return keys_.capacity() * sizeof(Key) + fed_.capacity() * sizeof(CalibRow<T>);
    }

    void sort_run() {
        std::sort(keys_.begin(), keys_.end(), [](const Key& a, const Key& b) { return before(a, b); });
    }

    CalibRow<T> row_of(const Key& k) const {
        if (k.fed != kNone) {
            return fed_[k.fed];
        }
        CalibRow<T> r{};
        r.t_us = k.t_us;
        r.t = k.t;
        r.line = k.line;
        return r;
    }

    void spill() {
        sort_run();
        if (file_ == nullptr) {
            file_ = std::tmpfile();
            if (file_ == nullptr) {
                throw std::runtime_error(std::string("self-calibration: cannot open a temporary file for the rows "
                                                     "out of time order: ") +
                                         std::strerror(errno));
            }
        }
        const std::int64_t begin = written_;
        for (const Key& k : keys_) {
            Key out = k;
            out.fed = k.fed == kNone ? kNone : 1U;
            put(&out, sizeof out);
            if (k.fed != kNone) {
                put(&fed_[k.fed], sizeof(CalibRow<T>));
            }
        }
        if (std::fflush(file_) != 0) {
            fail("write");
        }
        spilled_.emplace_back(begin, written_);
        keys_.clear();
        keys_.shrink_to_fit();
        fed_.clear();
        fed_.shrink_to_fit();
    }

    void put(const void* p, std::size_t n) {
        if (std::fwrite(p, 1, n, file_) != n) {
            fail("write");
        }
        written_ += static_cast<std::int64_t>(n);
    }

    [[noreturn]] static void fail(const char* what) {
        throw std::runtime_error(std::string("self-calibration: cannot ") + what +
                                 " the temporary file of the rows out of time order: " + std::strerror(errno));
    }

    void get(RunReader& r, void* p, std::size_t n) const {
        char* out = static_cast<char*>(p);
        while (n > 0) {
            if (r.pos == r.len) {
                const auto want = static_cast<std::size_t>(
                    std::min<std::int64_t>(static_cast<std::int64_t>(r.buf.size()), r.end - r.at));
                const ssize_t got = ::pread(fileno(file_), r.buf.data(), want, static_cast<off_t>(r.at));
                if (got <= 0) {
                    fail("read");
                }
                r.at += got;
                r.len = static_cast<std::size_t>(got);
                r.pos = 0;
            }
            const std::size_t k = std::min(n, r.len - r.pos);
            std::memcpy(out, r.buf.data() + r.pos, k);
            r.pos += k;
            out += k;
            n -= k;
        }
    }

    // The next row of run r; false at its end.
    bool next(RunReader& r) const {
        if (r.at == r.end && r.pos == r.len) {
            return false;
        }
        get(r, &r.key, sizeof r.key);
        if (r.key.fed != kNone) {
            get(r, &r.row, sizeof r.row);
        } else {
            r.row = CalibRow<T>{};
            r.row.t_us = r.key.t_us;
            r.row.t = r.key.t;
            r.row.line = r.key.line;
        }
        return true;
    }

    template <typename Fn>
    void merge(Fn&& fn) {
        // The read buffers share the budget (at least 4 KiB each).
        const std::size_t each_bytes = std::max<std::size_t>(4096, budget_ / spilled_.size());
        std::vector<RunReader> readers;
        readers.reserve(spilled_.size());
        for (const auto& [begin, end] : spilled_) {
            readers.push_back({begin, end, std::vector<char>(each_bytes)});
        }
        const auto later = [&readers](std::size_t a, std::size_t b) { return before(readers[b].key, readers[a].key); };
        std::vector<std::size_t> heap;
        for (std::size_t i = 0; i < readers.size(); ++i) {
            if (next(readers[i])) {
                heap.push_back(i);
            }
        }
        std::make_heap(heap.begin(), heap.end(), later);
        while (!heap.empty()) {
            std::pop_heap(heap.begin(), heap.end(), later);
            RunReader& r = readers[heap.back()];
            fn(static_cast<const CalibRow<T>&>(r.row));
            if (next(r)) {
                std::push_heap(heap.begin(), heap.end(), later);
            } else {
                heap.pop_back();
            }
        }
    }

    std::size_t budget_;
    std::vector<Key> keys_;
    std::vector<CalibRow<T>> fed_;
    std::FILE* file_ = nullptr;
    std::int64_t written_ = 0;
    std::vector<std::pair<std::int64_t, std::int64_t>> spilled_;
};

}  // namespace

void refuse_other_lag(const ModelFile& m, const std::string& name, const std::array<double, kMaxHeads>& lag_s) {
    for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
        if (m.present[h] && m.lag_s[h] != 0.0 && m.lag_s[h] != lag_s[h]) {
            throw std::runtime_error(
                name + ": head " + std::string(1, head_name(h)) + " lags by " + number_text(m.lag_s[h]) +
                " s, but the self-calibration " +
                (lag_s[h] == 0.0 ? std::string("lags it by none") : "lags it by " + number_text(lag_s[h]) + " s") +
                ": its coefficients belong to its lag; give --lag with its lag for that head, or leave --lag out");
        }
    }
}

void refuse_lag_to_learn(const ModelFile& m, const std::string& name, const std::string& option) {
    if (has_lag(m)) {
        throw std::runtime_error(name + ": the model's lag_s gives the bench's lag, and " + option +
                                 " learns it from none: leave " + option +
                                 " out to learn with the model's lag, or start from a model without lag_s");
    }
}

void refuse_quadratic_initial_model(const ModelFile& m, const std::string& name) {
    for (std::size_t h = 0; h < kMaxHeads; ++h) {
        for (std::size_t a = 0; a < kModelAxes; ++a) {
            for (std::size_t i = kLinearModelTerms; i < kModelTerms; ++i) {
                if (m.present[h] && m.coefficients[h][a][i] != 0.0) {
                    const std::string linear =
                        std::string(kCoefficientNames[0]) + ".." + kCoefficientNames[kLinearModelTerms - 1];
                    throw std::runtime_error(
                        name + ": head " + std::string(1, head_name(static_cast<std::uint8_t>(h))) + " " +
                        kAxisNames[a] + " has a quadratic term (" + kCoefficientNames[i] +
                        "): self-calibration starts from a linear model (the on-board estimator's models are " +
                        linear + ", and the link's CALIB_MODEL_LOAD carries " + linear +
                        "); give the model without its quadratic terms");
                }
            }
        }
    }
}

namespace {

// self_calibrate() with an estimator of N heads.
template <typename T, std::size_t N>
SelfCalibration self_calibrate_heads(const std::string& file, const RowSource& rows,
                                     const std::optional<ModelFile>& initial, const calib::EstimatorConfig& cfg,
                                     std::optional<double> orbit_period_s, std::size_t memory_budget_bytes,
                                     SideLearning learn) {
    EarthVelocity earth;
    // A row as the run takes it; false: its t is one the on-board clock cannot hold (no epoch).
    const auto calib_row = [&earth](const SolutionRecord& rec, CalibRow<T>& r) {
        TtTime t{};
        if (!tt_from_seconds(rec.t, t)) {
            return false;
        }
        r.t_us = t.us;
        r.t = rec.t;
        r.line = rec.line;
        r.fed = false;
        if (rec.head < N && calibration_clean(rec)) {
            r.in = to_core_input<T>(rec, &earth);
            r.fed =
                (correct_solution(r.in, CorrectionConfig<T>{true, nullptr}).status & status::kAberrationApplied) != 0U;
            r.speed_kms = std::sqrt(squared_norm(rec.v_sc_kms));
        }
        return true;
    };

    // Rows in time order (the usual file) are taken as they are read; at the
    // first row out of order the run stops, and the rows are read again and
    // sorted (the epoch of each, the input of those fed) within the memory
    // budget (SortedRuns).
    {
        Run<T, N> run(file, initial, cfg, orbit_period_s, learn);
        std::size_t untimed = 0;
        bool ordered = true;
        CalibRow<T> r{};
        CalibRow<T> last{};
        bool any = false;
        rows([&](const SolutionRecord& rec) {
            if (!ordered) {
                return;
            }
            if (!calib_row(rec, r)) {
                ++untimed;
                return;
            }
            if (any && before(r, last)) {
                ordered = false;
                return;
            }
            run.take(r);
            last = r;
            any = true;
        });
        if (ordered) {
            return run.finish(untimed);
        }
    }
    // Out of order: the rows are sorted by the clock's order in runs that fit
    // the memory budget; when there are more, each run is written sorted to an
    // anonymous temporary file and the runs are merged (SortedRuns).
    SortedRuns<T> runs(memory_budget_bytes);
    std::size_t untimed = 0;
    rows([&](const SolutionRecord& rec) {
        CalibRow<T> r{};
        if (!calib_row(rec, r)) {
            ++untimed;
            return;
        }
        runs.add(r);
    });
    Run<T, N> run(file, initial, cfg, orbit_period_s, learn);
    runs.each([&run](const CalibRow<T>& r) { run.take(r); });
    SelfCalibration out = run.finish(untimed);
    out.runs = runs.count();
    return out;
}

// The heads the estimator learns: A, B, C (kMinCalibHeads), and up to the
// last head that has a row passing the selection (at most kMaxHeads and max_heads).
std::size_t heads_to_learn(const RowSource& rows, std::size_t max_heads) {
    std::size_t n = calib::kMinCalibHeads;
    rows([&n, max_heads](const SolutionRecord& rec) {
        if (rec.head < kMaxHeads && rec.head < max_heads && rec.head >= n && calibration_clean(rec)) {
            n = rec.head + 1U;
        }
    });
    return n;
}

// self_calibrate_heads() with N the smallest from N0 up that is at least heads.
template <typename T, std::size_t N0 = calib::kMinCalibHeads>
SelfCalibration self_calibrate_dispatch(std::size_t heads, const std::string& file, const RowSource& rows,
                                        const std::optional<ModelFile>& initial, const calib::EstimatorConfig& cfg,
                                        std::optional<double> orbit_period_s, std::size_t memory_budget_bytes,
                                        SideLearning learn) {
    if constexpr (N0 < kMaxHeads) {
        if (heads > N0) {
            return self_calibrate_dispatch<T, N0 + 1U>(heads, file, rows, initial, cfg, orbit_period_s,
                                                       memory_budget_bytes, learn);
        }
    }
    return self_calibrate_heads<T, N0>(file, rows, initial, cfg, orbit_period_s, memory_budget_bytes, learn);
}

}  // namespace

template <typename T>
SelfCalibration self_calibrate(const std::string& file, const RowSource& rows, const std::optional<ModelFile>& initial,
                               const calib::EstimatorConfig& cfg, std::optional<double> orbit_period_s,
                               std::size_t memory_budget_bytes, std::size_t max_heads,
                               const std::array<double, kMaxHeads>& lag_s, bool learn_lag, bool learn_sun,
                               std::int64_t sun_interval_us) {
    if (learn_lag && pipeline::any_lagged(lag_s)) {
        throw std::invalid_argument("self_calibrate: a lag is learnt from none, not from a given one");
    }
    if (initial) {
        refuse_quadratic_initial_model(*initial, "the initial model");  // the callers name it first
        refuse_other_lag(*initial, "the initial model", lag_s);
        refuse_sun_term(*initial, "the initial model", kSunTermNotLearnt);
    }
    SelfCalibration out =
        self_calibrate_dispatch<T>(heads_to_learn(rows, max_heads), file, rows, initial, cfg, orbit_period_s,
                                   memory_budget_bytes, {learn_lag, learn_sun, sun_interval_us});
    if (!learn_lag) {
        for (ActiveModel& a : out.history) {  // every model the run makes takes the run's lag
            a.model.lag_s = lag_s;
            a.model.lag_s = head_lags(a.model);
        }
    }
    return out;
}

template SelfCalibration self_calibrate<double>(const std::string&, const RowSource&, const std::optional<ModelFile>&,
                                                const calib::EstimatorConfig&, std::optional<double>, std::size_t,
                                                std::size_t, const std::array<double, kMaxHeads>&, bool, bool,
                                                std::int64_t);
template SelfCalibration self_calibrate<float>(const std::string&, const RowSource&, const std::optional<ModelFile>&,
                                               const calib::EstimatorConfig&, std::optional<double>, std::size_t,
                                               std::size_t, const std::array<double, kMaxHeads>&, bool, bool,
                                               std::int64_t);
template SelfCalibration self_calibrate<Q30>(const std::string&, const RowSource&, const std::optional<ModelFile>&,
                                             const calib::EstimatorConfig&, std::optional<double>, std::size_t,
                                             std::size_t, const std::array<double, kMaxHeads>&, bool, bool,
                                             std::int64_t);

std::optional<LagSchedule> learnt_lags(const std::vector<ActiveModel>& history, const RowSource& rows) {
    std::vector<LagSchedule::Version> versions;
    HeadMask lagged = 0U;  // the heads some model lags: the only readings needed
    for (const ActiveModel& a : history) {
        versions.push_back({a.t_us, head_lags(a.model)});
        for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
            lagged |= versions.back().lag_s[h] != 0.0 ? head_bit(h) : HeadMask{0};
        }
    }
    if (lagged == 0U) {
        return std::nullopt;
    }
    return LagSchedule(versions, lag_readings(rows, lagged));
}

template <typename T>
ModelSchedule<T>::ModelSchedule(const std::vector<ActiveModel>& history) : model_(1) {
    for (const ActiveModel& a : history) {
        from_us_.push_back(a.t_us);
        version_.push_back(a.version);
        model_.push_back(to_core<T>(a.model));
        sun_.push_back(sun_term_if_any<T>(&a.model));
    }
}

template <typename T>
std::size_t ModelSchedule<T>::index_at(double t) const noexcept {
    TtTime tt{};
    if (!tt_from_seconds(t, tt)) {
        return 0;  // no epoch
    }
    return static_cast<std::size_t>(std::upper_bound(from_us_.begin(), from_us_.end(), tt.us) - from_us_.begin());
}

template <typename T>
const ThermalModel<T>& ModelSchedule<T>::at(double t) const noexcept {
    return model_[index_at(t)];
}

template <typename T>
const SunTermModel<T>* ModelSchedule<T>::sun_at(double t) const noexcept {
    const std::size_t k = index_at(t);
    return k == 0 || !sun_[k - 1] ? nullptr : &*sun_[k - 1];
}

template <typename T>
std::optional<std::uint32_t> ModelSchedule<T>::version_at(double t) const noexcept {
    const std::size_t k = index_at(t);
    return k == 0 ? std::nullopt : std::optional<std::uint32_t>(version_[k - 1]);
}

template class ModelSchedule<double>;
template class ModelSchedule<float>;
template class ModelSchedule<Q30>;

const char* head_origin(std::uint32_t version, std::size_t h, std::uint8_t learnt) {
    if (version == 0U) {
        return "given";
    }
    return calib::learns_head(h, learnt) ? "learnt" : "kept";
}

namespace {

// One row of the history: head h, axis a of model m (the columns above).
void append_history_row(std::string& out, const ActiveModel& m, std::size_t h, std::size_t a, bool combined,
                        bool lagged, bool sun) {
    char buf[96];
    text::c_snprintf(buf, sizeof buf, "%.3f,%u,%c,%s", m.t, m.version, head_name(static_cast<std::uint8_t>(h)),
                     kAxisNames[a]);
    out += buf;
    for (std::size_t i = 0; i < kLinearModelTerms; ++i) {
        text::c_snprintf(buf, sizeof buf, ",%.16e", m.model.coefficients[h][a][i]);
        out += buf;
    }
    text::c_snprintf(buf, sizeof buf, ",%08x,%lld,%s", m.crc, static_cast<long long>(m.t_us),
                     head_origin(m.version, h, m.learnt));
    out += buf;
    // A given model (version 0) is in the rule it was made by, which the history does not know.
    if (combined) {
        out += m.version == 0U ? ",given" : ",combined";
    }
    if (lagged) {
        text::c_snprintf(buf, sizeof buf, ",%.17g", m.model.lag_s[h]);  // as the model file writes it
        out += buf;
    }
    for (std::size_t c = 0; sun && c < kSunComponents; ++c) {
        text::c_snprintf(buf, sizeof buf, ",%.16e", m.model.sun[h][a][c]);  // as the model file writes them
        out += buf;
    }
    out += '\n';
}

}  // namespace

std::string format_model_history(const std::vector<ActiveModel>& history, bool combined) {
    const bool lagged =
        std::any_of(history.begin(), history.end(), [](const ActiveModel& m) { return has_lag(m.model); });
    const bool sun =
        std::any_of(history.begin(), history.end(), [](const ActiveModel& m) { return has_sun_term(m.model); });
    std::string out = "t,version,chu,axis," + coefficient_columns(0, kLinearModelTerms, ",") + ",crc32c,tt_us,origin" +
                      (combined ? ",common_rotation" : "") + (lagged ? ",lag_s" : "") +
                      (sun ? std::string(",") + kSunColumns[0] + "," + kSunColumns[1] + "," + kSunColumns[2] : "") +
                      "\n";
    for (const ActiveModel& m : history) {
        for (std::size_t h = 0; h < kMaxHeads; ++h) {
            for (std::size_t a = 0; a < kModelAxes && m.model.present[h]; ++a) {
                append_history_row(out, m, h, a, combined, lagged, sun);
            }
        }
    }
    return out;
}

bool orbit_period_acceptable(double seconds) {
    return seconds * 1e6 >= static_cast<double>(calib::kMinOrbitPeriodUs) &&
           seconds * 1e6 <= static_cast<double>(calib::kMaxOrbitPeriodUs);
}

std::string orbit_period_range() {
    return "[" + number_text(static_cast<double>(calib::kMinOrbitPeriodUs) / 1e6) + ", " +
           number_text(static_cast<double>(calib::kMaxOrbitPeriodUs) / 1e6) + "]";
}

std::string time_constant_range() {
    return "[" + number_text(calib::kMinTimeConstantDays) + ", " + number_text(calib::kMaxTimeConstantDays) + "]";
}

namespace {

std::string lag_text(double tau_s) {
    return tau_s != 0.0 ? number_text(tau_s) + " s" : std::string("no lag");
}

// The lag of a learnt-lag history's model: its heads' one τ (0: none).
double model_lag(const ActiveModel& a) {
    const std::array<double, kMaxHeads> lag = head_lags(a.model);
    return *std::max_element(lag.begin(), lag.end());
}

// What the models of a --lag auto history took, in a clause; `last` their last lag.
std::string lags_taken(const std::vector<ActiveModel>& history, double& last) {
    const ActiveModel* first = nullptr;
    std::size_t changes = 0;
    last = 0.0;
    for (const ActiveModel& a : history) {
        const double tau = model_lag(a);
        changes += tau != last ? 1U : 0U;
        last = tau;
        first = first == nullptr && tau != 0.0 ? &a : first;
    }
    if (first == nullptr) {
        return "no model took a lag";
    }
    char buf[160];
    text::c_snprintf(buf, sizeof buf, "the models took %s (each head they have) from version %u (t = %.3f)",
                     lag_text(model_lag(*first)).c_str(), first->version, first->t);
    std::string out = buf;
    if (changes > 1U) {
        out +=
            ", the lag changing " + std::to_string(changes - 1U) + " more time(s), the last model's " + lag_text(last);
    }
    return out;
}

}  // namespace

std::string describe(const calib::LagSearchReport& r, double last_model_lag_s) {
    if (r.orbits == 0U) {
        return "the search scored no orbit (no model active with A, B and C selected)";
    }
    char buf[400];
    text::c_snprintf(buf, sizeof buf,
                     "the search scored %u orbits: the IBAs' spread inside the orbit (%.3f\" RMS with no lag) is "
                     "lowest with %s, %.2f %% of the mean square below no lag's; ",
                     r.orbits, r.rms_arcsec, lag_text(r.best_tau_s).c_str(), 100.0 * r.gain);
    std::string out = buf;
    if (!r.deciding) {
        text::c_snprintf(buf, sizeof buf, "it decides once it holds %.0f orbits (it holds %.0f, forgotten)",
                         r.orbits_to_decide, r.orbits_held);
        return out + buf;
    }
    text::c_snprintf(buf, sizeof buf,
                     "it takes %s (a lag once %.1f %% below no lag's, kept until another is %.2f %% below it or no "
                     "lag %.1f %%)",
                     lag_text(r.tau_s).c_str(), 100.0 * calib::kLagSearchMargin, 100.0 * calib::kLagSwitchMargin,
                     100.0 * calib::kLagSearchMargin);
    return out + buf + (r.tau_s != last_model_lag_s ? "; no model since took it" : "");
}

namespace {

// The epochs the learner could not take, in a clause ("" when none).
std::string not_learnt_from(const calib::SunLearnReport& r) {
    std::string out;
    if (r.without_sun > 0U) {
        out += "; " + std::to_string(r.without_sun) +
               " epoch(s) outside the Sun ephemeris' span (2000-2051) not learnt from";
    }
    if (r.not_finite > 0U) {
        out +=
            "; " + std::to_string(r.not_finite) + " epoch(s) whose attitudes give no finite rotation not learnt from";
    }
    return out;
}

std::string describe_sun_learner(const calib::SunLearnReport& r, const std::vector<ActiveModel>& history) {
    if (r.orbits == 0U) {
        return "the learner scored no orbit (no model active with A, B and C selected and the Sun's direction known)";
    }
    char buf[400];
    text::c_snprintf(buf, sizeof buf,
                     "the learner scored %u orbits: the IBAs' spread inside the orbit (%.3f\" RMS with the polynomial "
                     "alone) is %.2f %% of the mean square %s with the term predicted from the orbits before "
                     "(rank %d of %u orbits); ",
                     r.orbits, r.rms_arcsec, 100.0 * std::fabs(r.gain), r.gain >= 0.0 ? "lower" : "higher",
                     r.candidate.rank, r.candidate.orbits);
    std::string out = buf;
    if (!r.deciding) {
        text::c_snprintf(buf, sizeof buf, "it decides once it holds %.0f orbits (it holds %.0f, forgotten)",
                         r.orbits_to_decide, r.orbits_held);
        return out + buf;
    }
    const auto first =
        std::find_if(history.begin(), history.end(), [](const ActiveModel& a) { return has_sun_term(a.model); });
    text::c_snprintf(buf, sizeof buf, "it %s the term (taken %.1f %% below, left %.1f %% above)",
                     r.taken ? "takes" : "does not take", 100.0 * calib::kSunLearnMargin,
                     100.0 * calib::kSunLearnMargin);
    out += buf;
    if (first == history.end()) {
        return out + "; no model took it";
    }
    text::c_snprintf(buf, sizeof buf, "; the models took it from version %u (t = %.3f)", first->version, first->t);
    return out + buf;
}

}  // namespace

std::string describe(const calib::SunLearnReport& r, const std::vector<ActiveModel>& history) {
    return describe_sun_learner(r, history) + not_learnt_from(r);
}

std::string describe(const SelfCalibration& s) {
    std::ostringstream o;
    char buf[300];
    const calib::EstimatorReport& r = s.report;
    text::c_snprintf(
        buf, sizeof buf,
        "self-calibration: orbit period %.1f s, %zu epochs with A, B and C selected; orbits used %u (short "
        "%u, held back %u); %zu model(s) active in turn",
        s.orbit_period_s, s.cycles, r.orbits_used, r.orbits_short, r.orbits_held, s.history.size());
    o << buf;
    if (r.has_active) {
        text::c_snprintf(
            buf, sizeof buf,
            "; active version %u (crc32c %08x), residual RMS %.3f\" over the recent orbits, condition %.1f",
            r.active_version, r.active_crc, r.residual_rms_arcsec, r.condition);
        o << buf;
    } else {
        o << "; no model adopted";
    }
    if (s.regauges.made + s.regauges.beyond_limits > 0U) {
        o << "; re-gauged by the rule " << s.regauges.made << " (beyond the core's limits, not made "
          << s.regauges.beyond_limits << ")";
    }
    if (s.untimed > 0) {
        o << "; " << s.untimed
          << " row(s) with a time the on-board clock cannot hold (|t| > 1e11 s) left out of the estimation: no "
             "model for them (256)";
    }
    o << "; refusals:";
    for (std::size_t k = 1; k < calib::kRefusalKinds; ++k) {
        o << (k > 1 ? "," : "") << ' ' << calib::refusal_name(static_cast<calib::Refusal>(k)) << ' ' << r.refusals[k];
    }
    if (s.lag_search) {
        double last = 0.0;
        o << "; bench lag (--lag auto): " << lags_taken(s.history, last) << "; " << describe(*s.lag_search, last);
    }
    if (s.sun_learnt) {
        o << "; Sun term (--sun-term auto): " << describe(*s.sun_learnt, s.history);
    }
    return o.str();
}

}  // namespace ascorr::host
