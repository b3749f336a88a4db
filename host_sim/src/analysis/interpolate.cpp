#include "ascorr_host/analysis/interpolate.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <deque>
#include <limits>
#include <numeric>

#include "ascorr/combine/combined_status.hpp"
#include "ascorr/core/heads.hpp"
#include "ascorr/core/rotation_vector.hpp"
#include "ascorr/core/vector3.hpp"
#include "ascorr/pipeline/epoch_key.hpp"
#include "ascorr_host/analysis/iba.hpp"
#include "ascorr_host/formats/csv.hpp"
#include "ascorr_text/c_format.hpp"
#include "ascorr_text/input_error.hpp"

namespace ascorr::host {

namespace {

namespace cs = combine::combined_status;

AttitudeRow no_attitude(double t) {
    AttitudeRow r;
    r.t = t;
    r.status = static_cast<unsigned>(cs::kNoHead);
    return r;
}

// Whether the later time t1 is more than s seconds after t0. The times are
// decimals read into doubles, each within half an ulp of its text, and their
// difference is exact (Sterbenz), so a distance of exactly s computes as up
// to one ulp(max |t|) ≤ max |t|·2⁻⁵² more (456148800.1 − 456148800.0 =
// 0.10000002384): that much, and s's own rounding, is not "more than s".
bool farther_than(double t1, double t0, double s) noexcept {
    return (t1 - t0) - s > std::max(std::abs(t1), std::abs(t0)) * 0x1p-51;
}

// The mean rate from a to b (arcsec/s, a's CRF axes).
Vector3<double> mean_rate(const AttitudeRow& a, const AttitudeRow& b) noexcept {
    const Vector3<double> th = rotation_vector_arcsec(b.q_crf_icrf, a.q_crf_icrf);
    const double dt = b.t - a.t;
    return {th.x / dt, th.y / dt, th.z / dt};
}

}  // namespace

std::string describe(const InterpolateSummary& s) {
    char buf[400];
    text::c_snprintf(buf, sizeof buf,
                     "%zu rows: %zu interpolated, %zu at an epoch, %zu outside the file and %zu across a gap "
                     "(status 8); from %zu epochs, %zu with an attitude; largest interpolation error bound %.3g "
                     "arcsec",
                     s.rows, s.interpolated, s.exact, s.outside, s.gap, s.epochs, s.usable, s.max_error_bound_arcsec);
    std::string out = buf;
    if (s.without_rate_change > 0) {
        out += "; " + std::to_string(s.without_rate_change) +
               " rows between two epochs without a neighbour to measure the rate's change: bound 0";
    }
    return out;
}

struct Interpolator::Impl {
    Impl(std::vector<double> times, double gap, bool cov)
        : at(std::move(times)), max_gap(gap), covariance(cov), order(at.size()), out(at.size()) {
        std::iota(order.begin(), order.end(), std::size_t{0});
        std::stable_sort(order.begin(), order.end(), [this](std::size_t i, std::size_t j) { return at[i] < at[j]; });
        sum.rows = at.size();
    }

    void add(const AttitudeRow& row) {
        ++sum.epochs;
        if (!row.has_q) {
            return;
        }
        ++sum.usable;
        window.push_back(row);
        // An interval waits for the epoch after it (its rate change needs
        // that neighbour): four epochs held, the middle two interpolated.
        if (window.size() == 4) {
            interval(&window[0], window[1], window[2], &window[3]);
            window.pop_front();
        } else if (window.size() == 3) {
            interval(nullptr, window[0], window[1], &window[2]);
        }
    }

    const std::vector<AttitudeRow>& finish() {
        const std::size_t n = window.size();
        if (n == 2) {
            interval(nullptr, window[0], window[1], nullptr);
        } else if (n >= 3) {
            interval(&window[n - 3], window[n - 2], window[n - 1], nullptr);
        }
        if (n >= 1) {
            exact_last(window[n - 1]);
        }
        // Beyond the last usable epoch, or none at all (every time is finite: the constructor's precondition).
        outside_before(std::numeric_limits<double>::infinity());
        return out;
    }

    // The times in [a.t, b.t) (b.t itself belongs to the next interval, or to exact_last).
    void interval(const AttitudeRow* before, const AttitudeRow& a, const AttitudeRow& b, const AttitudeRow* after) {
        outside_before(a.t);  // only before the first usable epoch: later ones are taken by an interval
        if (next == order.size() || at[order[next]] >= b.t) {
            return;
        }
        const double alpha = rate_change(before, a, b, after);
        for (; next < order.size() && at[order[next]] < b.t; ++next) {
            set(order[next], between(a, b, at[order[next]], alpha));
        }
    }

    // The times before t, not yet taken, have no attitude (status 8).
    void outside_before(double t) {
        for (; next < order.size() && at[order[next]] < t; ++next) {
            set(order[next], no_attitude(at[order[next]]));
            ++sum.outside;
        }
    }

    void exact_last(const AttitudeRow& last) {
        outside_before(last.t);  // one usable epoch: none before it
        for (; next < order.size() && at[order[next]] == last.t; ++next) {
            set(order[next], last);
            ++sum.exact;
        }
    }

    // α (arcsec/s²): the largest change of the mean rate from a neighbouring
    // interval to [a, b], per the mean of their spans; -1 without one.
    double rate_change(const AttitudeRow* before, const AttitudeRow& a, const AttitudeRow& b,
                       const AttitudeRow* after) const noexcept {
        const Vector3<double> w = mean_rate(a, b);
        double alpha = -1.0;
        const auto change = [&](const Vector3<double>& w2, double span) {
            const Vector3<double> d{w2.x - w.x, w2.y - w.y, w2.z - w.z};
            alpha = std::max(alpha, std::sqrt(squared_norm(d)) / span);
        };
        if (before != nullptr && !farther_than(a.t, before->t, 2.0 * max_gap)) {
            change(mean_rate(*before, a), 0.5 * (b.t - before->t));
        }
        if (after != nullptr && !farther_than(after->t, b.t, 2.0 * max_gap)) {
            change(mean_rate(b, *after), 0.5 * (after->t - a.t));
        }
        return alpha;
    }

    AttitudeRow between(const AttitudeRow& a, const AttitudeRow& b, double t, double alpha) {
        if (t == a.t) {
            ++sum.exact;
            return a;
        }
        if (farther_than(t, a.t, max_gap) || farther_than(b.t, t, max_gap)) {
            ++sum.gap;
            return no_attitude(t);
        }
        ++sum.interpolated;
        sum.without_rate_change += alpha < 0.0 ? 1U : 0U;
        const double u = (t - a.t) / (b.t - a.t);
        const Vector3<double> th = rotation_vector_arcsec(b.q_crf_icrf, a.q_crf_icrf);
        AttitudeRow r;
        r.t = t;
        r.has_q = true;
        r.q_crf_icrf = canonical(exp_arcsec({u * th.x, u * th.y, u * th.z}) * a.q_crf_icrf);
        r.heads = a.heads | b.heads;
        r.status = static_cast<unsigned>(head_count(r.heads) >= 2 ? cs::kTwoOrMoreHeads : cs::kOneHead) |
                   ((a.status | b.status) & static_cast<unsigned>(cs::kHeadLeftOut));
        const double e = std::max(alpha, 0.0) * (t - a.t) * (b.t - t) / 2.0;
        sum.max_error_bound_arcsec = std::max(sum.max_error_bound_arcsec, e);
        const double wa = 1.0 - u;  // linear in the covariances (see the header)
        const double wb = u;
        for (std::size_t k = 0; k < 3; ++k) {
            r.sigma_arcsec[k] = std::sqrt(wa * a.sigma_arcsec[k] * a.sigma_arcsec[k] +
                                          wb * b.sigma_arcsec[k] * b.sigma_arcsec[k] + e * e);
            r.cov_arcsec2[k] = wa * a.cov_arcsec2[k] + wb * b.cov_arcsec2[k];
        }
        r.has_cov = covariance;
        return r;
    }

    void set(std::size_t i, AttitudeRow r) {
        r.t = at[i];
        r.line = 0;
        out[i] = r;
    }

    std::vector<double> at;
    double max_gap;
    bool covariance;
    std::vector<std::size_t> order;  // indices of `at` in time order
    std::vector<AttitudeRow> out;
    std::size_t next = 0;  // of order: the first time without its row
    std::deque<AttitudeRow> window;
    InterpolateSummary sum;
};

Interpolator::Interpolator(std::vector<double> at, double max_gap_s, bool covariance)
    : impl_(std::make_unique<Impl>(std::move(at), max_gap_s, covariance)) {}
Interpolator::~Interpolator() = default;
void Interpolator::add(const AttitudeRow& row) {
    impl_->add(row);
}
const std::vector<AttitudeRow>& Interpolator::finish() {
    return impl_->finish();
}
const InterpolateSummary& Interpolator::summary() const noexcept {
    return impl_->sum;
}

std::vector<NamedPath> interpolate_inputs(const InterpolateOptions& opt) {
    return {{"--in", opt.in}, {"--at", opt.at}};
}

std::vector<NamedPath> interpolate_outputs(const InterpolateOptions& opt) {
    return {{"--out", opt.out}};
}

namespace {

// The time in field `col` of a data line of `path` (read_times).
double time_of_line(std::string_view line, std::size_t n, std::size_t col, const std::string& path,
                    std::vector<std::string_view>& fields, std::vector<std::size_t>& starts) {
    if (const std::size_t bad = split_fields(line, fields, starts); bad != kSplitOk) {
        throw text::InputError(path, n, bad + 1, why_split_failed(line, bad));
    }
    if (col >= fields.size()) {
        throw text::InputError(
            path, n, line.size() + 1,
            "expected at least " + std::to_string(col + 1) + " fields, found " + std::to_string(fields.size()));
    }
    const auto t = parse_double(fields[col]);
    if (!t || !(std::abs(*t) < pipeline::kMaxEpochTimeS)) {
        throw text::InputError(path, n, starts[col] + 1,
                               "column 't': " + (t ? "t = " + number_text(*t) + " s is no time of an epoch"
                                                   : why_not_a_number(fields[col])));
    }
    return *t;
}

}  // namespace

std::vector<double> read_times(const std::string& path) {
    BlockReader blocks(path);
    std::string_view block;
    std::vector<double> times;
    std::vector<std::string_view> fields;
    std::vector<std::size_t> starts;
    int col = -1;
    while (blocks.next(block)) {
        LineReader lines(block, blocks.lines_before());
        for (std::string_view line; lines.next(line);) {
            if (!line.empty() && line.back() == '\r') {
                line.remove_suffix(1);
            }
            if (col < 0) {  // the header
                col = Header(line, path).index("t");
                if (col < 0) {
                    throw text::InputError(path, lines.line_number(), 1, "expected a header with a column 't'");
                }
            } else if (!line.empty()) {
                times.push_back(
                    time_of_line(line, lines.line_number(), static_cast<std::size_t>(col), path, fields, starts));
            }
        }
    }
    if (col < 0) {
        throw text::InputError(path, 1, 1, "empty file: expected a header with a column 't'");
    }
    return times;
}

InterpolateSummary interpolate_file(const InterpolateOptions& opt, OutputSet& outputs) {
    refuse_output_over_input(interpolate_inputs(opt), interpolate_outputs(opt));
    const std::vector<double> times = read_times(opt.at);
    AttitudeReader reader(opt.in);
    if (!reader.combined()) {
        throw text::InputError(opt.in, 1, 1,
                               "expected a combined file (" + std::string(kCombinedHeader) + "), not an attitude file");
    }
    const CombinedColumns cols = reader.columns();
    Interpolator interp(times, opt.max_gap_s, cols.covariance);
    AttitudeRow row;
    double last_t = 0.0;
    std::size_t last_line = 0;
    while (reader.next(row)) {
        if (last_line != 0 && !(row.t > last_t)) {
            throw text::InputError(opt.in, row.line, 1,
                                   "the combined file's rows must be in time order (line " + std::to_string(last_line) +
                                       " is at or after this one)");
        }
        last_t = row.t;
        last_line = row.line;
        interp.add(row);
    }
    const std::vector<AttitudeRow>& rows = interp.finish();
    std::string buf = combined_header(cols) + "\n";
    AtomicFile& out = outputs["--out"];
    for (const AttitudeRow& r : rows) {
        append_combined_row(buf, r, cols);
        if (buf.size() > (1U << 20)) {
            out.write(buf);
            buf.clear();
        }
    }
    out.write(buf);
    return interp.summary();
}

}  // namespace ascorr::host
