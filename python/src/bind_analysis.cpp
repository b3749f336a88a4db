// python/src/bind_analysis.cpp: iba(), stats() and fit(): the host's
// analyses (ascorr_host/analysis/) over the rows of arrays, as `ascorr stats`
// and `ascorr fit` run them over a file's.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "ascorr/core/correct.hpp"
#include "ascorr_host/analysis/epochs.hpp"
#include "ascorr_host/analysis/fit.hpp"
#include "ascorr_host/analysis/iba.hpp"
#include "ascorr_host/analysis/stats.hpp"
#include "ascorr_host/formats/diagnostics.hpp"
#include "bind.hpp"
#include "docstrings.hpp"

namespace ascorr::python {

using host::SolutionRecord;
using namespace pybind11::literals;

namespace {

// The heads the rows have.
HeadMask heads_of(const Rows& r) {
    HeadMask heads = 0U;
    SolutionRecord rec;
    for (py::ssize_t i = 0; i < r.n; ++i) {
        record_of(r, i, rec);
        heads |= rec.head < kMaxHeads ? head_bit(rec.head) : HeadMask{0};
    }
    return heads;
}

py::dict iba(const py::object& t, const py::object& chu, const py::object& q) {
    const Rows r = rows_of(t, chu, q, py::none(), py::none());
    // Every pair of kMaxHeads while reading; those of the rows' heads at the end (as stats()).
    constexpr host::PairList kAllPairs = host::pairs_of(host::kAllHeads);
    // The rows' heads first, so that the epochs group alike in any row order
    // (an epoch is complete with every head the rows have), and the epochs
    // handed on kept: a second row of a head in one is refused wherever it
    // comes (the arrays are in memory anyway).
    const HeadMask with_rows = heads_of(r);
    std::array<std::vector<double>, host::kMaxPairs> pt;
    std::array<std::vector<double>, host::kMaxPairs> pv;
    // A row whose quaternion the core rejects (not finite, not unit: status 16
    // in correct()) takes no part in any IBA, as in stats(); it still counts
    // for the one-row-per-head-and-epoch rule.
    struct Boresight {
        Vector3<double> z;
        bool accepted;
    };
    SolutionRecord rec;
    const auto pairs_of_epoch = [&](const host::Epoch<Boresight>& e) {
        for (std::size_t p = 0; p < kAllPairs.count; ++p) {
            const auto& a = e.head[kAllPairs.pair[p].first];
            const auto& b = e.head[kAllPairs.pair[p].second];
            if (a && b && a->accepted && b->accepted) {
                pt[p].push_back(e.t);
                pv[p].push_back(host::angle_arcsec(a->z, b->z));
            }
        }
    };
    host::EpochAssembler<Boresight> epochs(kArrayRows, pairs_of_epoch, with_rows, host::Handed::kRemember);
    std::ostringstream log;
    host::Diagnostics diag(log);
    for (py::ssize_t i = 0; i < r.n; ++i) {
        record_of(r, i, rec);
        if (rec.head < kMaxHeads) {
            SolutionInput<double> in{};
            in.q_chu_icrf = rec.q_chu_icrf;
            in.head = rec.head;
            const Rejection why = check_solution(in);
            if (why != Rejection::kNone) {
                diag.report("rejected", std::string(kArrayRows) + ":" + std::to_string(rec.line) + ": quaternion " +
                                            (why == Rejection::kQuaternionNotFinite ? "not finite" : "not unit") +
                                            ": left out of the IBA (status 16 in correct())");
            }
            epochs.add(rec.t, rec.head, rec.line, Boresight{boresight(rec.q_chu_icrf), why == Rejection::kNone});
        }
    }
    epochs.finish();
    diag.summarize();
    if (!log.str().empty() && PyErr_WarnEx(PyExc_UserWarning, log.str().c_str(), 1) != 0) {
        throw py::error_already_set();
    }
    py::dict out;
    for (std::size_t p = 0; p < kAllPairs.count; ++p) {
        const host::HeadPair& pair = kAllPairs.pair[p];
        const HeadMask heads = host::analysis_heads(with_rows);
        if (!has_head(heads, pair.first) || !has_head(heads, pair.second)) {
            continue;
        }
        std::vector<std::size_t> idx(pt[p].size());
        std::iota(idx.begin(), idx.end(), std::size_t{0});
        std::sort(idx.begin(), idx.end(), [&](std::size_t i, std::size_t j) { return pt[p][i] < pt[p][j]; });
        py::array_t<double> ta(static_cast<py::ssize_t>(idx.size()));
        py::array_t<double> va(static_cast<py::ssize_t>(idx.size()));
        for (std::size_t i = 0; i < idx.size(); ++i) {
            ta.mutable_data()[i] = pt[p][idx[i]];
            va.mutable_data()[i] = pv[p][idx[i]];
        }
        out[pair.name] = py::make_tuple(ta, va);
    }
    return out;
}

// Pair p's systematic residual per stage as `stats --json`'s "systematic":
// None where that has null.
py::dict systematic_of(const host::StatsResult& s, std::size_t p) {
    py::dict d;
    for (std::size_t st = 0; st < host::kStages; ++st) {
        d[host::kStageNames[st]] = host::systematic_defined(s, p, st)
                                       ? py::object(py::float_(s.systematic_rms[p][st].rms))
                                       : py::object(py::none());
    }
    d["n"] = s.systematic_n[p];
    return d;
}

py::dict stats(const py::object& t, const py::object& chu, const py::object& q, const py::object& temps,
               const py::object& v, const py::object& flags, const py::object& confidence, const py::object& model,
               const py::object& t_from, const py::object& t_to, const py::object& noise_iba) {
    const host::ModelFile* m = model_arg(model);
    host::StatsOptions opt;
    opt.in = kArrayRows;
    if (!noise_iba.is_none()) {
        opt.noise_iba = path_arg(noise_iba, "noise_iba");  // simulate's file, read as `stats --noise-iba` reads it
    }
    opt.from = time_arg(t_from, "t_from");
    opt.to = time_arg(t_to, "t_to");
    opt.period_options = "t_from/t_to";
    host::refuse_bad_time_range(opt.from, opt.to, "t_from", "t_to");  // as `ascorr stats`: an empty period is refused
    const Rows r = rows_of(t, chu, q, temps, v, flags, confidence);
    std::optional<ThermalModel<double>> core_model;
    std::optional<host::LaggedTemperatures> lag;
    std::optional<SunTermModel<double>> sun;
    if (m != nullptr) {
        core_model = host::to_core<double>(*m);
        lag = host::lagged_temperatures(host::head_lags(*m), source_of(r));  // as `ascorr stats --model`
        sun = host::sun_term_if_any(m);
    }
    std::ostringstream log;
    const host::StatsResult s = host::compute_stats(opt, source_of(r), core_model ? &*core_model : nullptr, log,
                                                    lag ? &*lag : nullptr, sun ? &*sun : nullptr);
    py::dict pairs;
    py::dict systematic;
    for (std::size_t p = 0; p < s.pairs.count; ++p) {
        if (s.systematic) {
            systematic[s.pairs.pair[p].name] = systematic_of(s, p);
        }
        py::dict d;
        for (std::size_t st = 0; st < host::kStages; ++st) {
            const bool have = host::rms_defined(s, p, st);
            d[host::kStageNames[st]] = have ? py::object(py::float_(s.rms[p][st].rms)) : py::object(py::none());
            d[(std::string(host::kStageNames[st]) + "_smoothed").c_str()] =
                have ? py::object(py::float_(s.rms[p][st].rms_smoothed)) : py::object(py::none());
        }
        d["n"] = s.n[p];
        pairs[s.pairs.pair[p].name] = d;
    }
    py::dict out;
    out["pairs"] = pairs;
    if (s.systematic) {
        out["systematic"] = systematic;
    }
    out["rows"] = s.rows;
    out["clean_rows"] = s.clean_rows;
    out["table"] = host::stats_table(s);
    out["messages"] = log.str();
    return out;
}

// The value after "--terms ", "--holdout ", "--heads " or "--frame-heads "
// at text[i], as a keyword's: "='linear'", "=0", "='ABD'", "='auto'"; empty (and i
// unchanged) when none follows.
std::string keyword_value(const std::string& name, const std::string& text, std::size_t& i) {
    if (i >= text.size() || text[i] != ' ') {
        return {};
    }
    if (name == "heads" || name == "frame_heads") {
        std::size_t v = i + 1;
        while (v < text.size() && text[v] >= 'A' && text[v] <= 'Z') {
            ++v;
        }
        if (v == i + 1) {
            return {};
        }
        const std::string value = text.substr(i + 1, v - i - 1);
        i = v;
        return "='" + value + "'";
    }
    if (name != "terms" && name != "holdout" && name != "lag" && name != "sun_term") {
        return {};
    }
    std::size_t v = i + 1;
    while (v < text.size() &&
           ((text[v] >= 'a' && text[v] <= 'z') || (text[v] >= '0' && text[v] <= '9') || text[v] == '.')) {
        ++v;
    }
    const std::string value = text.substr(i + 1, v - i - 1);
    if ((name == "terms" && (value == "linear" || value == "quadratic")) || (name == "lag" && value == "auto") ||
        (name == "sun_term" && (value == "auto" || value == "none"))) {
        i = v;
        return "='" + value + "'";
    }
    if (name == "holdout" && !value.empty() && value[0] >= '0' && value[0] <= '9') {
        i = v;
        return "=" + value;
    }
    return {};
}

// The host's fit names its settings as the command line's options; from
// Python they are fit()'s keywords: "--min-temperature-range" is
// "min_temperature_range", "--from" "t_from", "--terms linear" "terms='linear'".
std::string as_keywords(const std::string& text) {
    std::string out;
    for (std::size_t i = 0; i < text.size();) {
        if (text.compare(i, 2, "--") != 0 || i + 2 >= text.size() || text[i + 2] < 'a' || text[i + 2] > 'z') {
            out += text[i++];
            continue;
        }
        std::size_t e = i + 2;
        while (e < text.size() && ((text[e] >= 'a' && text[e] <= 'z') || text[e] == '-')) {
            ++e;
        }
        std::string name = text.substr(i + 2, e - i - 2);
        i = e;
        if (name == "from" || name == "to") {
            name = "t_" + name;
        }
        std::replace(name.begin(), name.end(), '-', '_');
        out += name + keyword_value(name, text, i);
    }
    return out;
}

}  // namespace

std::optional<std::array<double, kMaxHeads>> lags_arg(const py::handle& lag) {
    if (py::isinstance<py::str>(lag)) {
        std::optional<std::array<double, kMaxHeads>> out;
        try {
            out = host::parse_lags(lag.cast<std::string>());
        } catch (const host::FitRefused& e) {
            bad_argument("lag", as_keywords(e.what()));
        }
        return out;
    }
    const double x = real_arg(lag, "lag");
    if (!host::lag_acceptable(x)) {
        bad_argument(
            "lag", "expected 'auto', 'X:TAU,...' or a lag in s, " + host::lag_range_text() + ", got " + number_text(x));
    }
    std::array<double, kMaxHeads> out{};
    out.fill(x);
    return out;
}

namespace {

py::tuple fit(const py::object& t, const py::object& chu, const py::object& q, const py::object& temps,
              const py::object& v, const py::object& flags, const py::object& confidence, const py::object& t_from,
              const py::object& t_to, const py::object& min_days, const py::object& min_orbits,
              const py::object& max_condition, const py::object& orbit_period, const py::object& terms,
              const py::object& holdout, const py::object& min_temperature_range, const py::object& frame_heads,
              const py::object& heads, const py::object& mountings, const py::object& common_rotation,
              const py::object& lag, const py::object& sun_term) {
    host::FitOptions opt;
    opt.in = kArrayRows;
    opt.from = time_arg(t_from, "t_from");
    opt.to = time_arg(t_to, "t_to");
    opt.min_span_days = real_arg(min_days, "min_days");
    opt.min_orbits = count_arg(min_orbits, "min_orbits");
    opt.max_condition = real_arg(max_condition, "max_condition");
    if (!orbit_period.is_none()) {
        opt.orbit_period_s = real_arg(orbit_period, "orbit_period");
    }
    opt.terms = choice_arg(terms, "terms", {"linear", "quadratic"}) == "linear" ? host::Terms::kLinear
                                                                                : host::Terms::kQuadratic;
    opt.holdout = real_arg(holdout, "holdout");
    opt.min_temperature_range_c = real_arg(min_temperature_range, "min_temperature_range");
    const host::HeadList frame = host::heads_of(heads_arg(frame_heads, "frame_heads", 2U, 2U));
    opt.frame_heads = {frame.head[0], frame.head[1]};
    if (!heads.is_none()) {
        opt.heads = heads_arg(heads, "heads", 2U, kMaxHeads);
    }
    if (!mountings.is_none()) {
        opt.mountings = mountings_arg(mountings);
        opt.mountings_name = "argument 'mountings'";
    }
    if (!common_rotation.is_none()) {
        const std::string name = py::isinstance<py::str>(common_rotation) ? common_rotation.cast<std::string>() : "";
        const std::optional<host::CommonRotationId> id = host::common_rotation_named(name);
        if (!id) {
            bad_argument("common_rotation",
                         "expected " + host::common_rotation_choices() + ", got " + value_text(common_rotation));
        }
        opt.common_rotation.emplace();
        static_cast<host::CommonRotationId&>(*opt.common_rotation) = *id;
    }
    opt.lag_s = lags_arg(lag);
    opt.sun_term = choice_arg(sun_term, "sun_term", {"auto", "none"}) == "auto" ? host::SunTermChoice::kAuto
                                                                                : host::SunTermChoice::kNone;
    const Rows r = rows_of(t, chu, q, temps, v, flags, confidence);
    const host::FitReport rep = [&] {
        try {
            return host::fit_model(opt, source_of(r));
        } catch (const host::FitRefused& e) {
            throw host::FitRefused(as_keywords(e.what()));
        }
    }();
    py::dict d;
    d["t_first"] = rep.t_first;
    d["t_last"] = rep.t_last;
    d["orbit_period_s"] = rep.orbit_period_s;
    d["rows"] = rep.rows;
    d["rows_other_heads"] = rep.rows_other_heads;
    py::dict dropped;
    for (std::size_t k = 0; k < host::kDropKinds; ++k) {
        dropped[host::drop_name(static_cast<host::Drop>(k))] = rep.dropped[k];
    }
    d["dropped"] = dropped;
    d["epochs"] = rep.epochs;
    d["orbits_used"] = rep.orbits_used;
    d["orbits_left_out"] = rep.orbits_left_out;
    d["singular_values"] = rep.singular_values;
    d["condition"] = rep.condition;
    // A row per head fitted (d["heads"], in heads.hpp's order), a column per axis.
    const host::HeadList fitted = host::heads_of(rep.heads);
    const auto n_heads = static_cast<py::ssize_t>(fitted.count);
    py::array_t<double> res({n_heads, py::ssize_t{3}});
    py::array_t<double> sig({n_heads, py::ssize_t{3}});
    for (std::size_t i = 0; i < fitted.count; ++i) {
        for (std::size_t a = 0; a < 3; ++a) {
            res.mutable_data()[3 * i + a] = rep.head[fitted.head[i]].residual_rms[a];
            sig.mutable_data()[3 * i + a] = rep.head[fitted.head[i]].signal_rms[a];
        }
    }
    d["heads"] = host::head_letters(rep.heads);
    d["residual_rms"] = res;
    d["signal_rms"] = sig;
    d["terms"] = host::terms_name(rep.terms);
    d["common_rotation"] = host::common_rotation_name(rep.common_rotation);
    d["lag"] = rep.lag.verdict;
    d["sun"] = rep.sun.verdict;
    d["text"] = as_keywords(host::describe(rep));
    return py::make_tuple(py::cast(rep.model), d);
}

}  // namespace

void bind_analysis(py::module_& mod) {
    mod.def("iba", &iba, "t"_a, "chu"_a, "q"_a, docstring(docs::kIba));
    mod.def("stats", &stats, "t"_a, "chu"_a, "q"_a, "temps"_a, "v"_a, "flags"_a = py::none(),
            "confidence"_a = py::none(), "model"_a = py::none(), "t_from"_a = py::none(), "t_to"_a = py::none(),
            "noise_iba"_a = py::none(), docstring(docs::kStats));
    mod.def("fit", &fit, "t"_a, "chu"_a, "q"_a, "temps"_a, "v"_a, "flags"_a = py::none(), "confidence"_a = py::none(),
            "t_from"_a = py::none(), "t_to"_a = py::none(), "min_days"_a = host::kDefaultMinSpanDays,
            "min_orbits"_a = host::kDefaultMinOrbits, "max_condition"_a = host::kDefaultMaxCondition,
            "orbit_period"_a = py::none(), "terms"_a = "linear", "holdout"_a = host::kDefaultHoldout,
            "min_temperature_range"_a = host::kDefaultMinTemperatureRange,
            "frame_heads"_a = host::frame_heads_text(host::kDefaultFrameHeads), "heads"_a = py::none(),
            "mountings"_a = py::none(), "common_rotation"_a = py::none(), "lag"_a = "auto", "sun_term"_a = "auto",
            docstring(docs::kFit));
}

}  // namespace ascorr::python
