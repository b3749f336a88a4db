// OUT.floor-daily.csv (ascorr_host/analysis/simulate.hpp): the floor's per-day sums,
// and the floor of a window of days from them.
#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <string>
#include <system_error>

#include "ascorr_host/analysis/simulate.hpp"
#include "ascorr_text/c_format.hpp"
#include "ascorr_text/input_error.hpp"

namespace ascorr::host {

namespace {

constexpr const char* kFloorDailyHeader = "day,t_start,pair,n,sum,sum_sq";

// The fields of one line, split at commas, with the 1-based column of each.
struct Fields {
    std::string text[6];
    std::size_t column[6] = {};
    std::size_t count = 0;
};

Fields split(const std::string& line) {
    Fields f;
    std::size_t start = 0;
    while (f.count < 6) {
        const std::size_t comma = line.find(',', start);
        f.column[f.count] = start + 1;
        f.text[f.count++] = line.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
        if (comma == std::string::npos) {
            return f;
        }
        start = comma + 1;
    }
    f.count = 7;  // more than six
    return f;
}

// The whole field as a finite long double (std::from_chars: whatever the C
// locale's decimal point), else InputError.
long double number(const std::string& path, std::size_t line, const Fields& f, std::size_t i) {
    const std::string& s = f.text[i];
    long double x = 0.0L;
    const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), x);
    if (s.empty() || ptr != s.data() + s.size() || ec != std::errc() || !std::isfinite(x)) {
        throw text::InputError(path, line, f.column[i], "'" + s + "' is not a finite number");
    }
    return x;
}

// The position of the line's pair in `pairs`, pairs.count for another pair of
// heads.hpp's heads; InputError for a name that is no pair of them.
std::size_t pair_position(const std::string& path, std::size_t line, const Fields& f, const PairList& pairs) {
    constexpr PairList kAllPairs = pairs_of(kAllHeads);
    bool known = false;
    for (std::size_t p = 0; p < kAllPairs.count; ++p) {
        known = known || f.text[2] == kAllPairs.pair[p].name;
    }
    if (!known) {
        throw text::InputError(path, line, f.column[2],
                               "pair '" + f.text[2] + "' is not two heads of " + kHeadLetters + " (as A-B)");
    }
    std::size_t position = pairs.count;
    for (std::size_t p = 0; p < pairs.count; ++p) {
        position = f.text[2] == pairs.pair[p].name ? p : position;
    }
    return position;
}

}  // namespace

std::string floor_daily_csv(const DailyFloor& days, double start_t, const PairList& pairs) {
    std::string s = std::string(kFloorDailyHeader) + '\n';
    char line[192];
    for (std::size_t d = 0; d < days.size(); ++d) {
        for (std::size_t p = 0; p < pairs.count; ++p) {
            const FloorSums& f = days[d][p];
            text::c_snprintf(line, sizeof line, "%zu,%.3f,%s,%zu,%.21Lg,%.21Lg\n", d,
                             start_t + static_cast<double>(d) * 86400.0, pairs.pair[p].name, f.n, f.sum, f.sum_sq);
            s += line;
        }
    }
    return s;
}

std::array<WindowFloor, kMaxPairs> floor_of_days(const std::string& path, long long from_day, long long to_day,
                                                 const PairList& pairs) {
    std::ifstream in(path);
    if (!in) {
        throw text::InputError(path, 0, 0, "cannot open the daily floor file");
    }
    std::string line;
    std::size_t number_of_line = 1;
    if (!std::getline(in, line) || line != kFloorDailyHeader) {
        throw text::InputError(path, 1, 1, std::string("expected the header ") + kFloorDailyHeader);
    }
    std::array<FloorSums, kMaxPairs> total{};
    while (std::getline(in, line)) {
        ++number_of_line;
        const Fields f = split(line);
        if (f.count != 6) {
            throw text::InputError(path, number_of_line, 1,
                                   "expected 6 fields (" + std::string(kFloorDailyHeader) + ")");
        }
        const std::size_t pair = pair_position(path, number_of_line, f, pairs);
        const long double day = number(path, number_of_line, f, 0);
        const long double n = number(path, number_of_line, f, 3);
        if (day < 0 || day != std::floor(day) || n < 0 || n != std::floor(n)) {
            throw text::InputError(path, number_of_line, f.column[day < 0 || day != std::floor(day) ? 0 : 3],
                                   "day and n must be non-negative integers");
        }
        if (pair < pairs.count && day >= static_cast<long double>(from_day) && day < static_cast<long double>(to_day)) {
            total[pair].n += static_cast<std::size_t>(n);
            total[pair].sum += number(path, number_of_line, f, 4);
            total[pair].sum_sq += number(path, number_of_line, f, 5);
        }
    }
    std::array<WindowFloor, kMaxPairs> out{};
    for (std::size_t p = 0; p < pairs.count; ++p) {
        const FloorSums& t = total[p];
        out[p].n = t.n;
        if (t.n == 0) {
            out[p].rms = std::numeric_limits<double>::quiet_NaN();
            continue;
        }
        const long double mean = t.sum / static_cast<long double>(t.n);
        const long double var = t.sum_sq / static_cast<long double>(t.n) - mean * mean;
        out[p].rms = static_cast<double>(std::sqrt(std::max(var, 0.0L)));
    }
    return out;
}

}  // namespace ascorr::host
