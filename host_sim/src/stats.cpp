#include "ascorr_host/stats.hpp"

#include <algorithm>
#include <cstdio>
#include <numeric>
#include <ostream>
#include <sstream>

#include "ascorr/correct.hpp"
#include "ascorr_host/atomic_file.hpp"
#include "ascorr_host/diagnostics.hpp"
#include "ascorr_host/earth_velocity.hpp"
#include "ascorr_host/epochs.hpp"
#include "ascorr_host/model_csv.hpp"
#include "ascorr_host/solution_input.hpp"

namespace ascorr::host {

bool is_clean(const SolutionRecord& rec) noexcept {
    return rec.flags == 0 && rec.confidence <= 5.0 && rec.temperature_present[0] && rec.temperature_present[1] &&
           rec.temperature_present[2] && rec.velocity_components == 3;
}

namespace {

struct Row {
    bool clean = false;
    std::array<Vector3<double>, kStages> z{};  // boresight per stage
};

}  // namespace

StatsResult compute_stats(const StatsOptions& opt, std::ostream& log) {
    refuse_output_over_input({{"--in", opt.in}, {"--model", opt.model}}, {}, true);
    refuse_bad_time_range(opt.from, opt.to);
    std::optional<ThermalModel<double>> model;
    if (!opt.model.empty()) {
        model = to_core<double>(read_model_file(opt.model));
    }
    return compute_stats(
        opt, [&](const std::function<void(const SolutionRecord&)>& fn) { for_each_solution(opt.in, fn, "stats"); },
        model ? &*model : nullptr, log);
}

StatsResult compute_stats(const StatsOptions& opt, const RowSource& rows, const ThermalModel<double>* model,
                          std::ostream& log) {
    const CorrectionConfig<double> ab_only{true, nullptr};
    const CorrectionConfig<double> both{true, model};
    StatsResult r;
    r.thermal = model != nullptr;
    EarthVelocity earth;
    Diagnostics diag(log);

    EpochAssembler<Row> epochs(opt.in, [&](const Epoch<Row>& e) {
        for (std::size_t p = 0; p < kPairs; ++p) {
            const auto& a = e.head[kPairHeads[p][0]];
            const auto& b = e.head[kPairHeads[p][1]];
            if (a && b && a->clean && b->clean) {
                r.series[p].t.push_back(e.t);
                for (std::size_t s = 0; s < kStages; ++s) {
                    r.series[p].iba[s].push_back(angle_arcsec(a->z[s], b->z[s]));
                }
            }
        }
    });
    rows([&](const SolutionRecord& rec) {
        if ((opt.from && rec.t < *opt.from) || (opt.to && rec.t > *opt.to)) {
            return;
        }
        ++r.rows;
        if (rec.head > 2) {
            return;  // not in any pair (head D, or unknown: left to `correct` to report)
        }
        Row row;
        row.clean = is_clean(rec);
        const SolutionInput<double> in = to_core_input<double>(rec, &earth);
        const CorrectedSolution<double> c1 = correct_solution(in, ab_only);
        const CorrectedSolution<double> c2 = correct_solution(in, both);
        const bool thermal_ok = !model || (c2.status & status::kThermalApplied) != 0U;
        if (row.clean && ((c1.status & status::kAberrationApplied) == 0U || !thermal_ok)) {
            diag.report("not corrected", opt.in + ":" + std::to_string(rec.line) +
                                             ": clean row the core did not correct (status " +
                                             std::to_string(c2.status) + "): left out of the statistics");
            row.clean = false;
        }
        r.clean_rows += row.clean ? 1U : 0U;
        row.z[0] = boresight(rec.q_chu_icrf);
        row.z[1] = boresight(c1.q_chu_icrf);
        row.z[2] = boresight(c2.q_chu_icrf);
        epochs.add(rec.t, rec.head, rec.line, row);
    });
    epochs.finish();
    diag.summarize();

    for (std::size_t p = 0; p < kPairs; ++p) {
        PairSeries& s = r.series[p];
        // Incomplete epochs arrive last and unordered: sort by time for smoothing.
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
        r.n[p] = s.t.size();
        for (std::size_t st = 0; st < kStages; ++st) {
            r.rms[p][st] = rms_about_mean(s.t, s.iba[st]);
        }
        if (!opt.keep_series) {
            s = PairSeries{};
        }
    }
    return r;
}

std::string stats_table(const StatsResult& r) {
    std::ostringstream o;
    o << "IBA RMS about the mean, arcsec, over clean epochs (after 200 s smoothing in brackets)\n";
    char buf[200];
    std::snprintf(buf, sizeof buf, "%-5s %9s  %-18s %-18s %-18s\n", "pair", "epochs", "original", "aberration",
                  "thermal");
    o << buf;
    for (std::size_t p = 0; p < kPairs; ++p) {
        std::string cells[kStages];
        for (std::size_t s = 0; s < kStages; ++s) {
            if (r.n[p] == 0 || (s == 2 && !r.thermal)) {
                cells[s] = "-";
            } else {
                char c[64];
                std::snprintf(c, sizeof c, "%6.2f (%5.2f)", r.rms[p][s].rms, r.rms[p][s].rms_smoothed);
                cells[s] = c;
            }
        }
        std::snprintf(buf, sizeof buf, "%-5s %9zu  %-18s %-18s %-18s\n", kPairNames[p], r.n[p], cells[0].c_str(),
                      cells[1].c_str(), cells[2].c_str());
        o << buf;
    }
    return o.str();
}

std::string stats_json(const StatsResult& r) {
    std::ostringstream o;
    const auto num = [](double x) {
        char c[32];
        std::snprintf(c, sizeof c, "%.6f", x);
        return std::string(c);
    };
    o << "{\"pairs\": {";
    for (std::size_t p = 0; p < kPairs; ++p) {
        const bool any = r.n[p] > 0;
        o << (p ? ", " : "") << '"' << kPairNames[p] << "\": {";
        o << "\"original\": " << (any ? num(r.rms[p][0].rms) : "null");
        o << ", \"aberration\": " << (any ? num(r.rms[p][1].rms) : "null");
        o << ", \"thermal\": " << (any && r.thermal ? num(r.rms[p][2].rms) : "null");
        o << ", \"n\": " << r.n[p] << '}';
    }
    o << "}}\n";
    return o.str();
}

}  // namespace ascorr::host
