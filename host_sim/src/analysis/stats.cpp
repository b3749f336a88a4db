#include "ascorr_host/analysis/stats.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <optional>
#include <ostream>
#include <sstream>
#include <string>
#include <utility>

#include "ascorr/core/correct.hpp"
#include "ascorr_host/analysis/epochs.hpp"
#include "ascorr_host/analysis/simulate.hpp"
#include "ascorr_host/correct/correct_row.hpp"
#include "ascorr_host/correct/earth_velocity.hpp"
#include "ascorr_host/correct/lagged_temperatures.hpp"
#include "ascorr_host/correct/selection.hpp"
#include "ascorr_host/correct/solution_input.hpp"
#include "ascorr_host/formats/atomic_file.hpp"
#include "ascorr_host/formats/diagnostics.hpp"
#include "ascorr_host/formats/model_csv.hpp"
#include "ascorr_text/c_format.hpp"
#include "ascorr_text/input_name.hpp"

namespace ascorr::host {

bool is_clean(const SolutionRecord& rec) noexcept {
    return rec.flags == 0 && confidence_clean(rec) && rec.temperature_present[0] && rec.temperature_present[1] &&
           rec.temperature_present[2] && rec.velocity_components == 3;
}

namespace {

struct Row {
    bool clean = false;
    std::array<Vector3<double>, kStages> z{};  // boresight per stage
};

// What kept each head's rows out of the clean epochs, for the reasons.
struct HeadTally {
    std::size_t rows = 0;  // in [from, to]
    std::size_t clean = 0;
    std::size_t flagged = 0;
    std::size_t low_confidence = 0;  // confidence above 5 or missing (confidence_clean)
    std::size_t no_temperatures = 0;
    std::size_t no_velocity = 0;
    std::size_t not_corrected = 0;
};

std::string head_without_clean_rows(char name, const HeadTally& h) {
    std::string s = std::string("none of CHU ") + name + "'s " + std::to_string(h.rows) + " rows is clean (";
    const std::pair<std::size_t, const char*> parts[] = {{h.flagged, "flags set"},
                                                         {h.low_confidence, "confidence above 5 or missing"},
                                                         {h.no_temperatures, "temperatures missing"},
                                                         {h.no_velocity, "velocity missing"},
                                                         {h.not_corrected, "not corrected by the core"}};
    const char* sep = "";
    for (const auto& [n, what] : parts) {
        if (n != 0) {
            s += sep + std::to_string(n) + " " + what;
            sep = ", ";
        }
    }
    return s + ")";
}

// Why pair p has no clean epoch; the tests are in the order a reader would check.
std::string why_no_epochs(const HeadPair& pair, const StatsOptions& opt, std::size_t rows_seen,
                          std::size_t rows_in_period, const std::array<HeadTally, kMaxHeads>& heads,
                          std::size_t both_present) {
    const bool period = opt.from.has_value() || opt.to.has_value();
    const auto t = [](double x) {
        char buf[40];
        text::c_snprintf(buf, sizeof buf, "%.17g", x);
        return std::string(buf);
    };
    const std::string in_period = period ? " in [" + (opt.from ? t(*opt.from) : std::string("-inf")) + ", " +
                                               (opt.to ? t(*opt.to) : std::string("inf")) + "] s (" +
                                               opt.period_options + ")"
                                         : std::string();
    if (rows_seen == 0) {
        return "the file has no data rows";
    }
    if (rows_in_period == 0) {
        return "no rows" + in_period + " (the file has " + std::to_string(rows_seen) + ")";
    }
    const std::uint8_t pair_heads[2] = {pair.first, pair.second};
    for (const std::uint8_t h : pair_heads) {
        if (heads[h].rows == 0) {
            return std::string("CHU ") + head_name(h) + " has no rows" + in_period;
        }
    }
    for (const std::uint8_t h : pair_heads) {
        if (heads[h].clean == 0) {
            return head_without_clean_rows(head_name(h), heads[h]);
        }
    }
    const char a = head_name(pair.first);
    const char b = head_name(pair.second);
    if (both_present == 0) {
        return std::string("CHU ") + a + " and CHU " + b + " never have a row at the same epoch (t to the millisecond)";
    }
    return "at the " + std::to_string(both_present) + " epochs with rows of both CHU " + a + " and CHU " + b +
           ", one of the two is never clean";
}

// The epoch's IBA of every pair of kAllPairs with both heads clean.
template <typename Row>
void add_epoch(const Epoch<Row>& e, const PairList& all_pairs, std::array<std::size_t, kMaxPairs>& both_present,
               std::array<PairSeries, kMaxPairs>& series) {
    for (std::size_t p = 0; p < all_pairs.count; ++p) {
        const auto& a = e.head[all_pairs.pair[p].first];
        const auto& b = e.head[all_pairs.pair[p].second];
        both_present[p] += a && b ? 1U : 0U;
        if (a && b && a->clean && b->clean) {
            series[p].t.push_back(e.t);
            for (std::size_t s = 0; s < kStages; ++s) {
                series[p].iba[s].push_back(angle_arcsec(a->z[s], b->z[s]));
            }
        }
    }
}

// The row in its head's tally (before the correction's verdict).
void tally_row(const SolutionRecord& rec, HeadTally& tally) {
    ++tally.rows;
    tally.flagged += rec.flags != 0 ? 1U : 0U;
    tally.low_confidence += !confidence_clean(rec) ? 1U : 0U;  // as is_clean
    tally.no_temperatures +=
        !(rec.temperature_present[0] && rec.temperature_present[1] && rec.temperature_present[2]) ? 1U : 0U;
    tally.no_velocity += rec.velocity_components != 3 ? 1U : 0U;
}

// The index of `pair` in `list` (which holds it).
template <typename Pair>
std::size_t index_of_pair(const PairList& list, const Pair& pair) {
    std::size_t all = 0;
    while (list.pair[all].first != pair.first || list.pair[all].second != pair.second) {
        ++all;
    }
    return all;
}

// Incomplete epochs arrive last and unordered: sort by time for smoothing.
void sort_by_time(PairSeries& s) {
    std::vector<std::size_t> idx(s.t.size());
    std::iota(idx.begin(), idx.end(), std::size_t{0});
    std::sort(idx.begin(), idx.end(), [&](std::size_t i, std::size_t j) { return s.t[i] < s.t[j]; });
    const auto permute = [&](std::vector<double>& v) {
        std::vector<double> o(v.size());
        for (std::size_t i = 0; i < idx.size(); ++i) {
            o[i] = v[idx[i]];
        }
        v.swap(o);
    };
    permute(s.t);
    for (auto& v : s.iba) {
        permute(v);
    }
}

// Whether the core applied the stages asked for: aberration (c1) and, with
// a model, the thermal one (c2).
bool corrected(StatusBits c1, StatusBits c2, bool with_model) {
    const bool thermal_ok = !with_model || (c2 & status::kThermalApplied) != 0U;
    return (c1 & status::kAberrationApplied) != 0U && thermal_ok;
}

// Whether t is within --from/--to.
bool within_time_range(const StatsOptions& opt, double t) {
    return !((opt.from && t < *opt.from) || (opt.to && t > *opt.to));
}

template <typename Name>
void log_empty_pair(const StatsOptions& opt, const Name& name, const std::string& reason, std::ostream& log) {
    if (opt.log_empty_pairs) {
        log << opt.in << ": pair " << name << ": no clean epochs: " << reason << '\n';
    }
}

// The core's input of rec with its lagged head's temperatures (the thermal
// stage's; the others take the row as it is); `in` without a lag (nullptr).
SolutionInput<double> lagged_input(const SolutionRecord& rec, const LaggedTemperatures* lag,
                                   const SolutionInput<double>& in) {
    if (lag == nullptr || !lag->lags(rec.head)) {
        return in;
    }
    SolutionRecord lagged = rec;
    lag->apply(lagged);
    SolutionInput<double> out = in;
    out.temperatures = to_core_input<double>(lagged, nullptr).temperatures;
    return out;
}

}  // namespace

StatsResult compute_stats(const StatsOptions& opt, std::ostream& log) {
    refuse_output_over_input({{"--in", opt.in}, {"--model", opt.model}, {"--noise-iba", opt.noise_iba}}, {}, true);
    refuse_bad_time_range(opt.from, opt.to);
    StatsOptions o = opt;
    o.corrected_input = is_corrected_file(opt.in);
    if (o.corrected_input) {
        if (!opt.model.empty()) {
            refuse_corrected_file(opt.in);  // the thermal stage would be applied a second time
        }
        log << opt.in
            << ": a corrected file (status column): shown as it is, under \"original\"; no stage is "
               "applied again\n";
    }
    std::optional<ThermalModel<double>> model;
    const RowSource rows = [&](const std::function<void(const SolutionRecord&)>& fn) {
        for_each_solution(opt.in, fn, "stats");
    };
    std::optional<LaggedTemperatures> lag;
    std::optional<SunTermModel<double>> sun;
    if (!opt.model.empty()) {
        const ModelFile m = read_model_file(opt.model);
        model = to_core<double>(m);
        lag = lagged_temperatures(head_lags(m), rows);  // as `correct` lags them
        sun = sun_term_if_any(&m);
    }
    return compute_stats(o, rows, model ? &*model : nullptr, log, lag ? &*lag : nullptr, sun ? &*sun : nullptr);
}

namespace {

// Per stage, the RMS about the mean of the pair's IBA minus its noise-only
// IBA (noise, keyed by t in ms) over the epochs both have; n those epochs.
void systematic(const PairSeries& s, const NoiseIbaSeries& noise, std::array<Rms, kStages>& out, std::size_t& n) {
    PairSeries d;
    for (std::size_t k = 0; k < s.t.size(); ++k) {
        const double* noise_iba = noise_iba_at(noise, std::llround(s.t[k] * 1000.0));
        if (noise_iba == nullptr) {
            continue;
        }
        d.t.push_back(s.t[k]);
        for (std::size_t st = 0; st < kStages; ++st) {
            d.iba[st].push_back(s.iba[st][k] - *noise_iba);
        }
    }
    n = d.t.size();
    for (std::size_t st = 0; st < kStages; ++st) {
        out[st] = rms_about_mean(d.t, d.iba[st]);
    }
}

// Pair p's RMS per stage and, with its noise-only IBAs, its systematic
// residual; its series dropped unless kept.
void summarize_pair(const StatsOptions& opt, const NoiseIbaSeries* noise, std::size_t p, StatsResult& r) {
    PairSeries& s = r.series[p];
    for (std::size_t st = 0; st < kStages; ++st) {
        r.rms[p][st] = rms_about_mean(s.t, s.iba[st]);
    }
    if (noise != nullptr) {
        systematic(s, *noise, r.systematic_rms[p], r.systematic_n[p]);
    }
    if (!opt.keep_series) {
        s = PairSeries{};
    }
}

}  // namespace

namespace {

// One reading of the rows: each head's tally and each pair's series (every
// pair of kMaxHeads, by position in kAllPairs).
struct StatsPass {
    std::size_t rows_seen = 0;
    std::size_t rows = 0;  // in [from, to]
    std::size_t clean_rows = 0;
    HeadMask with_rows = 0U;
    std::array<HeadTally, kMaxHeads> heads{};
    std::array<std::size_t, kMaxPairs> both_present{};
    std::array<PairSeries, kMaxPairs> series;
    bool late = false;  // a row came back to an epoch already handed on (EpochAssembler::late)
};

constexpr PairList kAllPairs = pairs_of(kAllHeads);

// c, the thermal stage's output, with the model's Sun term (sun, nullptr:
// none) applied as `correct` applies it (correct_row.hpp); where the Sun's
// direction is unknown, ab (the aberration stage's) with status 128.
CorrectedSolution<double> with_sun(const CorrectedSolution<double>& c, const CorrectedSolution<double>& ab,
                                   const SunTermModel<double>* sun, const SolutionRecord& rec) {
    const RowSunTerm s = row_sun_term(sun, c.status, rec.head, rec.t);
    if (s.unknown) {
        return {ab.q_chu_icrf, static_cast<StatusBits>(ab.status | status::kThermalOutOfRange)};
    }
    if (!s.apply) {
        return c;
    }
    return {with_sun_term(c.q_chu_icrf, sun_term_rotation(*sun, rec.head, c.q_chu_icrf, s.s_icrf)), c.status};
}

// The pass over the rows: epochs complete with the heads seen so far (none
// given), or with `heads`, keeping those handed on.
StatsPass read_pass(const StatsOptions& opt, const RowSource& rows, const ThermalModel<double>* model,
                    const LaggedTemperatures* lag, const SunTermModel<double>* sun, std::optional<HeadMask> heads,
                    std::ostream& log) {
    const CorrectionConfig<double> ab_only{true, nullptr};
    const CorrectionConfig<double> both{true, model};
    EarthVelocity earth;
    Diagnostics diag(log);
    StatsPass r;
    const auto sink = [&](const Epoch<Row>& e) { add_epoch(e, kAllPairs, r.both_present, r.series); };
    EpochAssembler<Row> epochs =
        heads ? EpochAssembler<Row>(opt.in, sink, *heads, Handed::kRemember) : EpochAssembler<Row>(opt.in, sink);
    rows([&](const SolutionRecord& rec) {
        ++r.rows_seen;
        r.with_rows |= rec.head < kMaxHeads ? head_bit(rec.head) : HeadMask{0};
        if (!within_time_range(opt, rec.t)) {
            return;
        }
        ++r.rows;
        if (rec.head >= kMaxHeads) {
            return;  // not in any pair (an unknown head: left to `correct` to report)
        }
        HeadTally& tally = r.heads[rec.head];
        tally_row(rec, tally);
        Row row;
        row.clean = is_clean(rec);
        const SolutionInput<double> in = to_core_input<double>(rec, &earth);
        const CorrectedSolution<double> c1 = correct_solution(in, ab_only);
        const CorrectedSolution<double> c2 = with_sun(correct_solution(lagged_input(rec, lag, in), both), c1, sun, rec);
        if (row.clean && !corrected(c1.status, c2.status, model != nullptr)) {
            diag.report("not corrected", text::input_name(opt.in) + ":" + std::to_string(rec.line) +
                                             ": clean row the core did not correct (status " +
                                             std::to_string(c2.status) + "): left out of the statistics");
            row.clean = false;
            ++tally.not_corrected;
        }
        r.clean_rows += row.clean ? 1U : 0U;
        tally.clean += row.clean ? 1U : 0U;
        row.z[0] = boresight(rec.q_chu_icrf);
        row.z[1] = opt.corrected_input ? row.z[0] : boresight(c1.q_chu_icrf);
        row.z[2] = opt.corrected_input ? row.z[0] : boresight(c2.q_chu_icrf);
        epochs.add(rec.t, rec.head, rec.line, row);
    });
    epochs.finish();
    diag.summarize();
    r.late = epochs.late();
    return r;
}

}  // namespace

StatsResult compute_stats(const StatsOptions& opt, const RowSource& rows, const ThermalModel<double>* model,
                          std::ostream& log, const LaggedTemperatures* lag, const SunTermModel<double>* sun) {
    StatsResult r;
    r.thermal = model != nullptr && !opt.corrected_input;
    r.corrected_input = opt.corrected_input;
    // By position in kAllPairs; read before the rows, so that a bad file fails at once.
    r.systematic = !opt.noise_iba.empty();
    std::array<NoiseIbaSeries, kMaxPairs> noise;
    if (r.systematic) {
        noise = read_noise_iba(opt.noise_iba, kAllPairs);
    }
    // Rows out of time order that came back to an epoch already handed on:
    // read again with the file's heads known, so that no row order loses an
    // epoch or hides a second row of a head in one (the first reading's
    // diagnostics are dropped, the second's are the same).
    std::ostringstream first_log;
    StatsPass pass = read_pass(opt, rows, model, lag, sun, std::nullopt, first_log);
    if (pass.late) {
        pass = read_pass(opt, rows, model, lag, sun, pass.with_rows, log);
    } else {
        log << first_log.str();
    }
    const std::size_t rows_seen = pass.rows_seen;
    const std::array<HeadTally, kMaxHeads>& heads = pass.heads;
    const std::array<std::size_t, kMaxPairs>& both_present = pass.both_present;
    std::array<PairSeries, kMaxPairs>& series = pass.series;
    const HeadMask with_rows = pass.with_rows;
    r.rows = pass.rows;
    r.clean_rows = pass.clean_rows;

    r.heads = analysis_heads(with_rows);
    r.pairs = pairs_of(r.heads);
    for (std::size_t p = 0; p < r.pairs.count; ++p) {
        const std::size_t all = index_of_pair(kAllPairs, r.pairs.pair[p]);
        PairSeries& s = r.series[p];
        s = std::move(series[all]);
        sort_by_time(s);
        r.n[p] = s.t.size();
        if (r.n[p] == 0) {
            r.no_epochs_reason[p] = why_no_epochs(r.pairs.pair[p], opt, rows_seen, r.rows, heads, both_present[all]);
            log_empty_pair(opt, r.pairs.pair[p].name, r.no_epochs_reason[p], log);
        }
        summarize_pair(opt, r.systematic ? &noise[all] : nullptr, p, r);
    }
    return r;
}

bool rms_defined(const StatsResult& r, std::size_t p, std::size_t st) noexcept {
    return r.n[p] >= kMinEpochsForRms && (st != 2 || r.thermal) && (st == 0 || !r.corrected_input);
}

// Whether pair p has a systematic residual at stage st (rms_defined over the
// epochs with a noise-only IBA).
bool systematic_defined(const StatsResult& r, std::size_t p, std::size_t st) noexcept {
    return r.systematic && r.systematic_n[p] >= kMinEpochsForRms && rms_defined(r, p, st);
}

namespace {

// A row of the table: the pair, its epochs and a cell per stage.
std::string table_row(const char* pair, std::size_t n, const std::string (&cells)[kStages]) {
    char buf[200];
    text::c_snprintf(buf, sizeof buf, "%-5s %9zu  %-18s %-18s %-18s\n", pair, n, cells[0].c_str(), cells[1].c_str(),
                     cells[2].c_str());
    return buf;
}

std::string systematic_table(const StatsResult& r) {
    std::ostringstream o;
    o << "systematic IBA residual (IBA minus the noise-only IBA), RMS about the mean, arcsec\n";
    for (std::size_t p = 0; p < r.pairs.count; ++p) {
        std::string cells[kStages];
        for (std::size_t s = 0; s < kStages; ++s) {
            char c[64];
            text::c_snprintf(c, sizeof c, "%6.3f", r.systematic_rms[p][s].rms);
            cells[s] = systematic_defined(r, p, s) ? std::string(c) : std::string("-");
        }
        o << table_row(r.pairs.pair[p].name, r.systematic_n[p], cells);
    }
    return o.str();
}

// The JSON object of the pairs, {"A-B": {"original": x, "aberration": x,
// "thermal": x, "n": N}, ...}: rms[p][st] where defined(r, p, st), else null.
void json_pairs(std::ostream& o, const StatsResult& r, const std::array<std::array<Rms, kStages>, kMaxPairs>& rms,
                const std::array<std::size_t, kMaxPairs>& n,
                bool (*defined)(const StatsResult&, std::size_t, std::size_t) noexcept) {
    o << '{';
    for (std::size_t p = 0; p < r.pairs.count; ++p) {
        o << (p ? ", " : "") << '"' << r.pairs.pair[p].name << "\": {";
        for (std::size_t st = 0; st < kStages; ++st) {
            char c[32];
            text::c_snprintf(c, sizeof c, "%.6f", rms[p][st].rms);
            o << (st ? ", " : "") << '"' << kStageNames[st] << "\": " << (defined(r, p, st) ? c : "null");
        }
        o << ", \"n\": " << n[p] << '}';
    }
    o << '}';
}

}  // namespace

std::string stats_table(const StatsResult& r) {
    std::ostringstream o;
    o << "IBA RMS about the mean, arcsec, over clean epochs (after 200 s smoothing in brackets)\n";
    char buf[200];
    text::c_snprintf(buf, sizeof buf, "%-5s %9s  %-18s %-18s %-18s\n", "pair", "epochs", "original", "aberration",
                     "thermal");
    o << buf;
    for (std::size_t p = 0; p < r.pairs.count; ++p) {
        std::string cells[kStages];
        for (std::size_t s = 0; s < kStages; ++s) {
            if (!rms_defined(r, p, s)) {
                cells[s] = "-";
            } else {
                char c[64];
                text::c_snprintf(c, sizeof c, "%6.2f (%5.2f)", r.rms[p][s].rms, r.rms[p][s].rms_smoothed);
                cells[s] = c;
            }
        }
        o << table_row(r.pairs.pair[p].name, r.n[p], cells);
    }
    if (r.systematic) {
        o << systematic_table(r);
    }
    return o.str();
}

std::string stats_json(const StatsResult& r) {
    std::ostringstream o;
    o << "{\"pairs\": ";
    json_pairs(o, r, r.rms, r.n, &rms_defined);
    if (r.systematic) {
        o << ", \"systematic\": ";
        json_pairs(o, r, r.systematic_rms, r.systematic_n, &systematic_defined);
    }
    o << "}\n";
    return o.str();
}

}  // namespace ascorr::host
