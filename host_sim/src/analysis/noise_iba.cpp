// OUT.noise-iba.csv (ascorr_host/analysis/simulate.hpp): the floor's IBAs,
// written a row at a time by `simulate --noise-iba`, read by `stats --noise-iba`.
#include <algorithm>
#include <cmath>
#include <string>
#include <string_view>
#include <vector>

#include "ascorr/pipeline/epoch_key.hpp"
#include "ascorr_host/analysis/simulate.hpp"
#include "ascorr_host/formats/csv.hpp"
#include "ascorr_text/c_format.hpp"
#include "ascorr_text/input_error.hpp"

namespace ascorr::host {

void append_noise_iba_row(std::string& buf, double t, const HeadPair& pair, double iba) {
    char line[96];
    const int n = text::c_snprintf(line, sizeof line, "%.3f,%s,%.6f\n", t, pair.name, iba);
    buf.append(line, static_cast<std::size_t>(n));
}

const double* noise_iba_at(const NoiseIbaSeries& s, long long t_ms) {
    const auto it = std::lower_bound(s.begin(), s.end(), t_ms,
                                     [](const std::pair<long long, double>& e, long long k) { return e.first < k; });
    return it != s.end() && it->first == t_ms ? &it->second : nullptr;
}

namespace {

struct NoiseRow {
    long long t_ms = 0;
    double iba = 0.0;
    std::size_t line = 0;
};

// One data line's fields into rows[position of its pair in `pairs`] (a pair
// of heads.hpp's heads not in `pairs` is skipped).
// f and at: the caller's, kept from line to line.
void read_row(std::string_view line, std::size_t n, const std::string& path, const PairList& pairs,
              std::vector<std::string_view>& f, std::vector<std::size_t>& at,
              std::array<std::vector<NoiseRow>, kMaxPairs>& rows) {
    if (const std::size_t bad = split_fields(line, f, at); bad != kSplitOk) {
        throw text::InputError(path, n, bad + 1, why_split_failed(line, bad));
    }
    if (f.size() != 3) {
        throw text::InputError(
            path, n, 1, "expected 3 fields (" + std::string(kNoiseIbaHeader) + "), found " + std::to_string(f.size()));
    }
    const auto t = parse_double(f[0]);
    if (!t || !(std::fabs(*t) < pipeline::kMaxEpochTimeS)) {
        throw text::InputError(
            path, n, at[0] + 1,
            "column 't': " + (t ? "t = " + number_text(*t) + " s is no time of an epoch" : why_not_a_number(f[0])));
    }
    constexpr PairList kAllPairs = pairs_of(kAllHeads);
    const auto named = [&f](const HeadPair& p) { return f[1] == p.name; };
    if (std::none_of(kAllPairs.pair.begin(), kAllPairs.pair.begin() + kAllPairs.count, named)) {
        throw text::InputError(path, n, at[1] + 1,
                               "pair '" + std::string(f[1]) + "' is not two heads of " + kHeadLetters + " (as A-B)");
    }
    const auto iba = parse_double(f[2]);
    if (!iba || !(*iba >= 0.0 && *iba <= 648000.0)) {
        throw text::InputError(path, n, at[2] + 1,
                               "column 'iba': " + (iba ? number_text(*iba) + " is no angle in [0, 648000] arcsec"
                                                       : why_not_a_number(f[2])));
    }
    const auto p = static_cast<std::size_t>(std::find_if(pairs.pair.begin(), pairs.pair.begin() + pairs.count, named) -
                                            pairs.pair.begin());
    if (p < pairs.count) {
        rows[p].push_back({std::llround(*t * 1000.0), *iba, n});
    }
}

// A pair's rows in increasing t; InputError at the later line of a t twice.
NoiseIbaSeries series_of(std::vector<NoiseRow>& r, const HeadPair& pair, const std::string& path) {
    std::stable_sort(r.begin(), r.end(), [](const NoiseRow& a, const NoiseRow& b) { return a.t_ms < b.t_ms; });
    NoiseIbaSeries out;
    out.reserve(r.size());
    for (std::size_t k = 0; k < r.size(); ++k) {
        if (k > 0 && r[k].t_ms == r[k - 1].t_ms) {
            const std::size_t first = std::min(r[k].line, r[k - 1].line);
            throw text::InputError(
                path, std::max(r[k].line, r[k - 1].line), 1,
                "pair " + pair_name(pair) + " twice at this t (also line " + std::to_string(first) + ")");
        }
        out.emplace_back(r[k].t_ms, r[k].iba);
    }
    return out;
}

}  // namespace

std::array<NoiseIbaSeries, kMaxPairs> read_noise_iba(const std::string& path, const PairList& pairs) {
    BlockReader blocks(path);
    std::string_view block;
    bool header = false;
    std::array<std::vector<NoiseRow>, kMaxPairs> rows;
    std::vector<std::string_view> fields;
    std::vector<std::size_t> starts;
    while (blocks.next(block)) {
        LineReader lines(block, blocks.lines_before());
        for (std::string_view line; lines.next(line);) {
            if (!header) {
                if (line.substr(0, 3) == "\xEF\xBB\xBF") {  // a UTF-8 byte-order mark, as every reader drops it
                    line.remove_prefix(3);
                }
                if (line != kNoiseIbaHeader) {
                    throw text::InputError(path, lines.line_number(), 1,
                                           std::string("expected the header ") + kNoiseIbaHeader);
                }
                header = true;
            } else if (!line.empty()) {
                read_row(line, lines.line_number(), path, pairs, fields, starts, rows);
            }
        }
    }
    if (!header) {
        throw text::InputError(path, 1, 1, std::string("empty file: expected the header ") + kNoiseIbaHeader);
    }
    std::array<NoiseIbaSeries, kMaxPairs> out;
    for (std::size_t p = 0; p < pairs.count; ++p) {
        out[p] = series_of(rows[p], pairs.pair[p], path);
    }
    return out;
}

}  // namespace ascorr::host
