#include "ascorr_host/correct/lagged_temperatures.hpp"

#include <algorithm>
#include <iterator>
#include <limits>
#include <tuple>
#include <utility>

#include "ascorr/nav/tt_time.hpp"

namespace ascorr::host {

bool lag_order(const LagReading& a, const LagReading& b) noexcept {
    const auto key = [](const LagReading& r) {
        return std::make_tuple(r.head, r.t_us, r.present[0], r.present[0] ? r.temperature[0] : 0.0, r.present[1],
                               r.present[1] ? r.temperature[1] : 0.0, r.present[2],
                               r.present[2] ? r.temperature[2] : 0.0);
    };
    return key(a) < key(b);
}

bool lag_reading_of(const SolutionRecord& rec, LagReading& out) noexcept {
    TtTime t{};
    if (rec.head >= kMaxHeads || !tt_from_seconds(rec.t, t)) {
        return false;
    }
    out = {t.us, rec.head, rec.temperature, rec.temperature_present};
    return true;
}

LaggedTemperatures::LaggedTemperatures(const std::array<double, kMaxHeads>& lag_s, std::vector<LagReading> readings)
    : lag_s_(lag_s) {
    readings.erase(std::remove_if(readings.begin(), readings.end(), [&](const LagReading& r) { return !lags(r.head); }),
                   readings.end());
    std::sort(readings.begin(), readings.end(), lag_order);
    for (auto first = readings.begin(); first != readings.end();) {
        const std::uint8_t head = first->head;
        const auto last = std::find_if(first, readings.end(), [&](const LagReading& r) { return r.head != head; });
        std::vector<Entry>& s = series_[head];
        walk_lag(lag_s_[head], &*first, &*first + (last - first),
                 [&](std::int64_t t_us, const std::array<double, 3>& lagged, const std::array<bool, 3>& valid) {
                     s.push_back({t_us, lagged, valid});
                 });
        first = last;
    }
}

std::vector<LagReading> lag_readings(const RowSource& rows, HeadMask heads) {
    std::vector<LagReading> readings;
    rows([&](const SolutionRecord& rec) {
        LagReading r;
        if (lag_reading_of(rec, r) && has_head(heads, r.head)) {
            readings.push_back(r);
        }
    });
    std::sort(readings.begin(), readings.end(), lag_order);
    return readings;
}

std::optional<LaggedTemperatures> lagged_temperatures(const std::array<double, kMaxHeads>& lag_s,
                                                      const RowSource& rows) {
    HeadMask lagged = 0U;
    for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
        lagged |= lag_s[h] != 0.0 ? head_bit(h) : HeadMask{0};
    }
    if (lagged == 0U) {
        return std::nullopt;
    }
    return LaggedTemperatures(lag_s, lag_readings(rows, lagged));
}

RowSource lagged_rows(const RowSource& rows, const LaggedTemperatures& lag) {
    return [&rows, &lag](const std::function<void(const SolutionRecord&)>& fn) {
        rows([&](const SolutionRecord& rec) {
            SolutionRecord lagged = rec;
            lag.apply(lagged);
            fn(lagged);
        });
    };
}

namespace {

// Head h's spans: where its lag changes from one version to the next.
std::vector<std::pair<std::int64_t, double>> lag_changes(const std::vector<LagSchedule::Version>& versions,
                                                         std::uint8_t h) {
    std::vector<std::pair<std::int64_t, double>> out;
    double before = 0.0;
    for (const LagSchedule::Version& v : versions) {
        if (v.lag_s[h] != before) {
            out.emplace_back(v.from_us, v.lag_s[h]);
            before = v.lag_s[h];
        }
    }
    return out;
}

}  // namespace

LagSchedule::LagSchedule(const std::vector<Version>& versions, std::vector<LagReading> readings) {
    std::sort(readings.begin(), readings.end(), lag_order);  // by head, then time
    const auto before = [](const LagReading& r, const std::pair<std::uint8_t, std::int64_t>& k) {
        return r.head < k.first || (r.head == k.first && r.t_us < k.second);
    };
    const auto at = [&](std::uint8_t h, std::int64_t t_us) {
        return std::lower_bound(readings.begin(), readings.end(), std::make_pair(h, t_us), before);
    };
    for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
        const std::vector<std::pair<std::int64_t, double>> changes = lag_changes(versions, h);
        for (std::size_t i = 0; i < changes.size(); ++i) {
            Span span{changes[i].first, std::nullopt};
            if (changes[i].second != 0.0) {
                std::array<double, kMaxHeads> lag_s{};
                lag_s[h] = changes[i].second;
                const auto last = i + 1 < changes.size() ? at(h, changes[i + 1].first)
                                                         : at(h, std::numeric_limits<std::int64_t>::max());
                span.table.emplace(lag_s, std::vector<LagReading>(at(h, changes[i].first), last));
                lagged_ |= head_bit(h);
            }
            spans_[h].push_back(std::move(span));
        }
    }
}

void LagSchedule::apply(SolutionRecord& rec) const {
    if (!has_head(lagged_, rec.head)) {
        return;
    }
    TtTime t{};
    if (!tt_from_seconds(rec.t, t)) {
        rec.temperature_present = {};  // no time: no lagged temperature, and no unlagged one
        return;
    }
    const std::vector<Span>& spans = spans_[rec.head];
    const auto it =
        std::upper_bound(spans.begin(), spans.end(), t.us, [](std::int64_t x, const Span& s) { return x < s.from_us; });
    if (it != spans.begin() && std::prev(it)->table) {  // before the first change: no lag
        std::prev(it)->table->apply(rec);
    }
}

void LaggedTemperatures::apply(SolutionRecord& rec) const {
    if (!lags(rec.head)) {
        return;
    }
    LagReading r;
    const std::vector<Entry>& s = series_[rec.head];
    const auto it = lag_reading_of(rec, r) ? std::lower_bound(s.begin(), s.end(), r.t_us,
                                                              [](const Entry& e, std::int64_t t) { return e.t_us < t; })
                                           : s.end();
    const bool found = it != s.end() && it->t_us == r.t_us;
    for (std::size_t k = 0; k < 3; ++k) {
        if (!found) {
            rec.temperature_present[k] = false;  // a row not in the table: no unlagged temperature
        } else if (lagged_reading_usable(rec.temperature_present[k], rec.temperature[k], it->valid[k])) {
            rec.temperature[k] = it->lagged[k];
        }
    }
}

}  // namespace ascorr::host
