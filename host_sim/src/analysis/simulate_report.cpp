// `ascorr simulate`'s text beside the solutions: the summary, the noise floor, the heater events, the truth history.
#include <cmath>
#include <cstdio>
#include <sstream>
#include <string>
#include <vector>

#include "ascorr_host/formats/model_csv.hpp"
#include "ascorr_host/formats/solutions_csv.hpp"
#include "ascorr_text/c_format.hpp"
#include "simulate_parts.hpp"

namespace ascorr::host {

std::string heaters_csv(const std::vector<HeaterEvent>& events) {
    std::string s = "start,end,heater\n";
    char line[96];
    for (const HeaterEvent& e : events) {
        text::c_snprintf(line, sizeof line, "%.3f,%.3f,%s\n", e.start, e.end,
                         e.operational ? "operational" : "survival");
        s += line;
    }
    return s;
}

std::string floor_json(const std::array<Rms, kMaxPairs>& floor, const PairList& pairs) {
    std::ostringstream s;
    s.precision(6);
    s << std::fixed << "{\"floor\": {";
    for (std::size_t p = 0; p < pairs.count; ++p) {
        // A pair without clean epochs has no RMS: null (JSON has no NaN either).
        const auto value = [n = floor[p].n](double x) {
            std::ostringstream v;
            v.precision(6);
            v << std::fixed << x;
            return n != 0 && std::isfinite(x) ? v.str() : std::string("null");
        };
        s << (p ? ", " : "") << '"' << pairs.pair[p].name << "\": {\"rms\": " << value(floor[p].rms)
          << ", \"rms_200s\": " << value(floor[p].rms_smoothed) << ", \"n\": " << floor[p].n << '}';
    }
    s << "}}\n";
    return s.str();
}

std::string describe(const SimulateSummary& s) {
    std::ostringstream o;
    const HeadList heads = heads_of(s.heads);
    o << s.epochs << " epochs, " << s.rows << " rows; blinded (Sun/Moon) rows ";
    for (std::size_t i = 0; i < heads.count; ++i) {
        o << (i ? "/" : "") << head_name(heads.head[i]);
    }
    o << ':';
    for (std::size_t i = 0; i < heads.count; ++i) {
        o << (i ? '/' : ' ') << s.outage_rows[heads.head[i]];
    }
    o << "; flagged " << s.flagged_rows << ", without temperatures " << s.rows_without_temperature
      << ", without velocity " << s.rows_without_velocity << "\nnoise floor (IBA RMS, arcsec):";
    char buf[96];
    for (std::size_t p = 0; p < s.pairs.count; ++p) {
        text::c_snprintf(buf, sizeof buf, "  %s %.3f (200 s: %.3f)", s.pairs.pair[p].name, s.floor[p].rms,
                         s.floor[p].rms_smoothed);
        o << buf;
    }
    o << "\ntruth model: " << s.truth_path << " (history: " << s.truth_history_path << ")\nfloor: " << s.floor_path
      << " (per day: " << s.floor_daily_path << ")\nheater events (" << s.heaters.size() << "): " << s.heaters_path
      << "\nmountings (true noise): " << s.mountings_path << "\ntrue CRF attitude: " << s.attitude_path;
    if (!s.noise_iba_path.empty()) {
        o << "\nnoise-only IBAs: " << s.noise_iba_path;
    }
    if (s.gap_epochs != 0) {
        o << "\nepochs without rows (--gap): " << s.gap_epochs;
    }
    return o.str();
}

namespace detail {

// The truths as a model history (docs/contract.md, "Self-calibration"):
// version v's rows are its model file's rows after t and v.
std::string truth_history_csv(const std::vector<Truth>& truths) {
    bool quadratic = false;
    for (const Truth& t : truths) {
        quadratic = quadratic || t.file.quadratic;
    }
    std::string s = "t,version," + model_header(quadratic ? kModelTerms : kLinearModelTerms);
    for (std::size_t v = 0; v < truths.size(); ++v) {
        ModelFile m = truths[v].file;
        m.quadratic = quadratic;
        const std::string rows = format_model(m);
        char prefix[64];
        text::c_snprintf(prefix, sizeof prefix, "%.3f,%zu,", truths[v].t_from, v);
        for (std::size_t at = rows.find('\n') + 1; at < rows.size();) {
            const std::size_t end = rows.find('\n', at) + 1;
            s += prefix;
            s.append(rows, at, end - at);
            at = end;
        }
    }
    return s;
}

}  // namespace detail

}  // namespace ascorr::host
