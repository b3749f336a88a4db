// One `ascorr replay` session over an open transport: the inputs read, the host's side started, the outputs written.
#include <array>
#include <chrono>
#include <cmath>
#include <functional>
#include <memory>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "ascorr/pipeline/common_rotation_weights.hpp"
#include "ascorr_host/correct/solution_input.hpp"
#include "ascorr_host/formats/corrected_csv.hpp"
#include "ascorr_host/formats/csv.hpp"
#include "ascorr_host/formats/model_csv.hpp"
#include "replay_parts.hpp"

namespace ascorr::host::detail {

namespace {

// The rows as the target's lag stage gives them to its terms: each lagged
// head's temperatures through pipeline::HeadLags<T> in the order the rows
// are sent (time_order; a row with no time has none), written back in double
// (exactly: each is a value of T), so that the host's self-calibration learns
// from what the target's estimator learns from, bit for bit. A reading the
// stage leaves as it came (not usable) stays the row's own.
template <typename T>
std::vector<SolutionRecord> lagged_as_sent(const std::vector<SolutionRecord>& rows,
                                           const std::array<double, kMaxHeads>& lag_s) {
    pipeline::HeadLags<T> lags;
    (void)lags.configure_all(lag_s);  // checked: the model's reader, --lag's parser
    std::vector<SolutionRecord> out = rows;
    for (const std::size_t k : time_order(rows)) {
        SolutionRecord& r = out[k];
        HeadTemperatures<T> temps = to_core_input<T>(r, nullptr).temperatures;
        TtTime tt{};
        if (tt_from_seconds(r.t, tt)) {
            lags.apply(r.head, tt.us, temps);
        } else {
            lags.without_time(r.head, temps);
        }
        const TemperatureReading<T>* const reading[3] = {&temps.t_chu, &temps.t_029, &temps.t_032};
        for (std::size_t c = 0; c < 3; ++c) {
            const double v = ScalarTraits<T>::to_double(reading[c]->value);
            if (reading[c]->valid && v != ScalarTraits<T>::to_double(ScalarTraits<T>::celsius(r.temperature[c]))) {
                r.temperature[c] = v;  // lagged
            }
            r.temperature_present[c] = reading[c]->valid;
        }
    }
    return out;
}

// --model read and checked for the target's scalar (refused before the
// target sees it, as by `correct`); none without --model.
template <typename T>
std::optional<ModelFile> read_replay_model(const ReplayOptions& opt) {
    if (opt.model.empty()) {
        return std::nullopt;
    }
    ModelFile mf = read_model_file(opt.model);
    check_model_for_scalar(mf, scalar_kind_of<T>(), opt.model);
    if (opt.self_calibrate) {
        refuse_sun_term(
            mf, opt.model,
            opt.sun_auto ? kSunTermNotLearnt : "the target's estimator does not learn it (its models have none)");
        refuse_other_lag(mf, opt.model, run_lags(opt.lag_s, mf));
        refuse_quadratic_initial_model(mf, opt.model);
    }
    const SunTermModel<T> sun = sun_term_of<T>(mf);
    bool has_term_in_scalar[kMaxHeads] = {};
    for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
        has_term_in_scalar[h] = has_sun_term(sun, h);
    }
    refuse_sun_term_for_link(mf, opt.model, has_term_in_scalar);
    return mf;
}

std::optional<StatesFile> read_replay_states(const ReplayOptions& opt, std::ostream& log) {
    if (opt.states.empty()) {
        return std::nullopt;
    }
    Diagnostics diag(log);
    std::optional<StatesFile> states =
        read_states_file(opt.states, opt.states_gcrs ? StateFrame::kGcrs : StateFrame::kItrf, diag);
    diag.summarize();
    return states;
}

// --self-calibrate: the host's run of the estimator over the file, and the
// target's started alike; otherwise the model uploaded and used on both.
// rule: the estimator's rule for the rotation common to all heads (the
// mountings of --combined, already loaded on the target; none: its frame).
template <typename T>
void start_host(const ReplayOptions& opt, const std::vector<SolutionRecord>& rows, const std::optional<ModelFile>& mf,
                const ThermalModel<T>& model_t, LinkClient<T>& client, HostSide<T>& host, ReplaySummary& sum,
                const calib::CommonRotationWeights& rule) {
    if (!opt.self_calibrate) {
        // The model's lags, on both sides (the target's lag stage, in its
        // scalar), and the reference's in double over the whole file, as
        // `ascorr correct` lags (lagged_temperatures.hpp).
        const std::array<double, kMaxHeads> lag_s = mf ? head_lags(*mf) : std::array<double, kMaxHeads>{};
        client.upload_model(model_t, lag_s);
        host.pipeline.use_model(&model_t);
        // The Sun term, folded into the thermal stage on both sides (the
        // flight form); the reference applies the contract's form in double.
        if (mf && has_sun_term(*mf)) {
            host.sun = sun_term_of<T>(*mf);
            host.sun_d = sun_term_of<double>(*mf);
            client.upload_sun_term(*host.sun);
            host.pipeline.use_sun_term(&*host.sun);
        }
        (void)host.lags.configure_all(lag_s);  // the model's reader checked each τ
        host.pipeline.use_lags(&host.lags);
        host.lagged_d = lagged_temperatures(lag_s, rows_in(rows));
        return;
    }
    calib::EstimatorConfig ecfg;
    ecfg.time_constant_days = opt.time_constant_days;
    ecfg.common_rotation = rule;
    // The lags: CALIB_START's on the target, the host's pipeline alike, the
    // host's estimator over the rows lagged as the target lags them, and the
    // reference's as `correct` lags (in double).
    const std::array<double, kMaxHeads> lag_s = run_lags(opt.lag_s, mf);
    const std::vector<SolutionRecord> lagged = pipeline::any_lagged(lag_s) ? lagged_as_sent<T>(rows, lag_s) : rows;
    host.sc = self_calibrate<T>(opt.in, rows_in(lagged), mf, ecfg, opt.orbit_period_s, kSelfCalibrationMemoryBytes,
                                kMaxHeads, lag_s, false, opt.sun_auto, calib::kSunLearnOnBoardIntervalUs);
    host.schedule_d.emplace(host.sc->history);
    for (const ActiveModel& a : host.sc->history) {  // --sun-term auto: each version's term, as the target holds it
        if (has_sun_term(a.model)) {
            host.version_sun.emplace(a.version, sun_term_of<T>(a.model));
        }
    }
    (void)host.lags.configure_all(lag_s);
    host.pipeline.use_lags(&host.lags);
    host.lagged_d = lagged_temperatures(lag_s, rows_in(rows));
    std::optional<ModelCoefficients> initial;
    if (mf) {
        initial = coefficients_of(*mf);
    }
    const std::int64_t period_us = std::llround(host.sc->orbit_period_s * 1e6);
    client.start_calibration(period_us, opt.time_constant_days, initial ? &*initial : nullptr, rule.heads != 0U, lag_s,
                             opt.sun_auto);
    calib::EstimatorConfig host_cfg{};  // as the target's CALIB_START makes it
    host_cfg.orbit_period_us = period_us;
    host_cfg.time_constant_days = opt.time_constant_days;
    host_cfg.common_rotation = rule;
    host.estimator.emplace(host_cfg, initial ? &*initial : nullptr);
    host.pipeline.use_estimator(&*host.estimator);
    sum.self_calibrate = true;
}

// The rows, in file order.
std::vector<SolutionRecord> read_rows(SolutionsReader& reader) {
    SolutionRecord record;
    std::vector<SolutionRecord> rows;
    while (reader.next(record)) {
        rows.push_back(record);
    }
    return rows;
}

// --mountings/--combined: the mountings read and checked, loaded on the
// target and the combination started on both sides; the estimator's rule
// for the rotation common to all heads (none without --combined).
template <typename T>
calib::CommonRotationWeights start_combination(const ReplayOptions& opt, LinkClient<T>& client, HostSide<T>& host,
                                               std::optional<EpochCombination<T>>& combination, std::ostream& log) {
    calib::CommonRotationWeights rule{};
    if (!opt.combined.empty()) {
        const MountingsFile m = read_mountings_file(opt.mountings);
        // The target combines as the flight loop does (its gate, pre-flight
        // mountings), unless --gate-sigmas/--gate-floor say otherwise.
        const combine::CombinerConfig gate = gate_config(opt.gate, combine::flight_gate());
        refuse_unusable_mountings(m, opt.mountings, std::vector<combine::CombinerConfig>{gate});
        combination.emplace(m, gate, client, host.pipeline, opt.in, log);
        rule = pipeline::common_rotation_weights(m.mountings);
    }
    return rule;
}

// The corrected file's rows, in file order (text: the input's).
std::string corrected_rows(const ReplayOptions& opt, const std::string& text, const RowWriter& writer,
                           const std::vector<WrittenRow>& written_rows) {
    std::string buf;
    SolutionRecord record;
    SolutionsReader again(opt.in, text);
    for (std::size_t k = 0; again.next(record); ++k) {
        writer.row(again, written_rows[k].q, written_rows[k].status, buf);
    }
    return buf;
}

// The link's figures: corrupted frames, retries, restarts, the target's
// instructions per solution and the faults injected (none: injector null).
void count_link(ReplaySummary& sum, const LinkStats& st, const ReplayedRows& replayed, const FaultInjector* injector) {
    sum.crc_errors = st.naks + st.broken_answers;
    sum.retries = st.retries;
    sum.restarts = st.restarts;
    sum.instructions_per_solution =
        replayed.costed == 0 ? 0.0 : replayed.instructions / static_cast<double>(replayed.costed);
    if (injector != nullptr) {
        sum.injected = injector->to_target().total() + injector->to_host().total();
    }
}

// The target's stack at the end of the run (STACK_REPORT), into the summary
// and the log: its deepest use since boot, against its size. A firmware
// from before the message is said so; its run's outputs stand.
template <typename T>
void report_stack(LinkClient<T>& client, ReplaySummary& sum, std::ostream& log) {
    const std::optional<link::StackReport> report = client.stack_report();
    if (!report) {
        log << "ascorr replay: the target does not report its stack (firmware before STACK_REPORT)\n";
        return;
    }
    const link::StackReport& st = *report;
    sum.target_stack_bytes = st.high_water;
    sum.target_stack_size = st.size;
    if (st.size == 0U) {
        log << "ascorr replay: the target does not measure its stack\n";
        return;
    }
    log << "ascorr replay: the target's stack: at most " << st.high_water << " of " << st.size
        << " bytes used since its boot\n";
}

}  // namespace

template <typename T>
ReplaySummary run(const ReplayOptions& opt, Transport& raw, OutputSet& outputs, std::ostream& log) {
    const std::string text = read_text_file(opt.in);
    SolutionsReader reader(opt.in, text);
    refuse_corrected_input(reader);
    // The thermal model: --model's, or with --self-calibrate the estimator's
    // (--model, if given, is its version 0).
    const std::optional<ModelFile> mf = read_replay_model<T>(opt);
    const ThermalModel<T> model_t = mf ? to_core<T>(*mf) : ThermalModel<T>{};
    const ThermalModel<double> model_d = mf ? to_core<double>(*mf) : ThermalModel<double>{};

    std::unique_ptr<FaultInjector> injector;
    Transport* transport = &raw;
    if (opt.inject_errors > 0.0) {
        injector = std::make_unique<FaultInjector>(raw, opt.inject_errors, opt.seed);
        transport = injector.get();
    }
    LinkClient<T> client(*transport, opt.timeout_ms, opt.max_attempts);
    const link::Hello hello = client.connect();
    log << "ascorr replay: target " << opt.target << " (boot id " << hello.boot_id << ", scalar kind "
        << static_cast<int>(hello.scalar_kind) << ")\n";
    const std::optional<StatesFile> states = read_replay_states(opt, log);
    // The target's velocity service, mirrored in its scalar and in double.
    const VelocityServiceConfig service =
        opt.max_propagation_s ? service_config(*opt.max_propagation_s) : default_velocity_service_config();
    if (opt.max_propagation_s) {
        client.set_service_horizon(service.horizon_us);
    }

    const RowWriter writer(reader);
    AtomicFile& out = outputs["--out"];
    out.write(writer.header_line());
    const auto start = std::chrono::steady_clock::now();
    // The rows go to the target in time order, as a DPU takes them (its
    // velocity service is causal: a row earlier than a state it already has
    // would get none), so that any row order gives `ascorr correct`'s answers;
    // they are written in file order.
    const std::vector<SolutionRecord> rows = read_rows(reader);
    ReplaySummary sum;
    HostSide<T> host;
    // The mountings first: the target's estimator takes its rule's weights
    // from those staged when CALIB_START comes (correct --self-calibrate
    // --combined's rule).
    std::optional<EpochCombination<T>> combination;
    const calib::CommonRotationWeights rule = start_combination(opt, client, host, combination, log);
    start_host(opt, rows, mf, model_t, client, host, sum, rule);
    const ReplayedRows replayed = replay_rows(opt, rows, client, states, service, host, model_d,
                                              combination ? &*combination : nullptr, sum, start, log);
    out.write(corrected_rows(opt, text, writer, replayed.rows));
    if (opt.self_calibrate) {
        finish_self_calibration(client, sum, host.target_history, log, *host.sc);
        if (outputs.has("--model-history")) {
            outputs["--model-history"].write(format_model_history(host.target_history, rule.heads != 0U));
        }
    }
    if (combination) {
        combination->finish(sum);
        outputs["--combined"].write(combination->text());
    }
    report_stack(client, sum, log);
    count_link(sum, client.stats(), replayed, injector.get());
    return sum;
}

template ReplaySummary run<float>(const ReplayOptions&, Transport&, OutputSet&, std::ostream&);
template ReplaySummary run<Q30>(const ReplayOptions&, Transport&, OutputSet&, std::ostream&);

}  // namespace ascorr::host::detail
