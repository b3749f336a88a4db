#include "ascorr_host/analysis/fit.hpp"

#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include <map>
#include <sstream>
#include <vector>
#include "ascorr_host/formats/atomic_file.hpp"
#include "ascorr_host/formats/csv.hpp"

#include "ascorr/calib/frame.hpp"
#include "ascorr/calib/head_rotation.hpp"
#include "ascorr/combine/mountings.hpp"
#include "ascorr/core/correct.hpp"
#include "ascorr/nav/orbit_propagation.hpp"
#include "ascorr_host/analysis/epochs.hpp"
#include "ascorr_host/correct/earth_velocity.hpp"
#include "ascorr_host/correct/lagged_temperatures.hpp"
#include "ascorr_host/correct/solution_input.hpp"
#include "ascorr_text/c_format.hpp"
#include "ascorr_text/input_name.hpp"

namespace ascorr::host {

namespace {

struct Row {
    Eigen::Quaterniond q;        // aberration-corrected, ICRF into head
    std::array<double, 3> temp;  // T1, T2, T3
    double t;                    // the row's own (an epoch's heads agree to the millisecond)
};

// Sums over one orbit's epochs, per head. q: the rotations a = q_head_f ⊗ r⁻¹
// relative to a provisional reference r (4-vectors, w ≥ 0); e: filled at the
// end, the small angles relative to the final reference, derived exactly from
// q (rebase_on_earliest_epoch), so that the result does not depend on which
// epoch came first; x, x2: the regressors and their squares.
// By head index.
struct OrbitSums {
    OrbitSums() {
        q.fill(Eigen::Vector4d::Zero());
        e.fill(Eigen::Vector3d::Zero());
        x.fill(Eigen::Vector3d::Zero());
        x2.fill(Eigen::Vector3d::Zero());
    }
    std::size_t count = 0;
    std::array<Eigen::Vector4d, kMaxHeads> q;
    std::array<Eigen::Vector3d, kMaxHeads> e;
    std::array<Eigen::Vector3d, kMaxHeads> x;
    std::array<Eigen::Vector3d, kMaxHeads> x2;
};

std::string time_text(double t) {
    char buf[64];
    text::c_snprintf(buf, sizeof buf, "%.3f", t);
    return buf;
}

}  // namespace

namespace {
FitReport fit_pass(const FitOptions& opt, const RowSource& rows, std::optional<double> earliest_period, HeadMask heads,
                   const LaggedTemperatures* lag, const std::vector<LagReading>* lag_search,
                   Handed handed = Handed::kForget);

// The heads a reading assumes: the given ones, else the analysis's with the
// heads seen with rows so far.
HeadMask fit_heads(const FitOptions& opt, HeadMask with_rows) {
    return opt.heads ? *opt.heads : analysis_heads(with_rows, frame_set(opt.frame_heads));
}

// A lag --lag's parser would refuse (an option set by a library caller).
void refuse_bad_lags(const FitOptions& opt) {
    const std::string bad = bad_lag_text(opt.lag_s);
    if (!bad.empty()) {
        throw FitRefused(bad);
    }
}

// NaN, zero or negative thresholds would silently accept or refuse everything.
void refuse_bad_fit_options(const FitOptions& opt) {
    refuse_bad_lags(opt);
    if (opt.from && !std::isfinite(*opt.from)) {
        throw FitRefused("--from " + number_text(*opt.from) + ": not a finite time");
    }
    if (opt.to && !std::isfinite(*opt.to)) {
        throw FitRefused("--to " + number_text(*opt.to) + ": not a finite time");
    }
    if (!(opt.min_span_days > 0.0 && std::isfinite(opt.min_span_days))) {
        throw FitRefused("--min-days " + number_text(opt.min_span_days) + ": must be a positive number of days");
    }
    if (!(opt.max_condition > 0.0) || std::isnan(opt.max_condition)) {
        throw FitRefused("--max-condition " + number_text(opt.max_condition) + ": must be positive");
    }
    if (opt.frame_heads[0] >= kMaxHeads || opt.frame_heads[1] >= kMaxHeads ||
        opt.frame_heads[0] == opt.frame_heads[1]) {
        throw FitRefused(std::string("--frame-heads ") + head_name(opt.frame_heads[0]) + head_name(opt.frame_heads[1]) +
                         ": two different heads of " + kHeadChoices.text + " are needed");
    }
    (void)common_rotation_rule(opt);  // a rule without what it weighs with, before any row is read
    if (opt.heads) {
        const std::string given = "--heads " + head_letters(*opt.heads);
        if (head_count(*opt.heads) < 2U || (*opt.heads & ~kAllHeads) != 0U) {
            throw FitRefused(given + ": two or more heads of " + kHeadChoices.text + " are needed");
        }
        if ((frame_set(opt.frame_heads) & ~*opt.heads) != 0U) {
            throw FitRefused(given + ": frame F's heads " + head_letters(frame_set(opt.frame_heads)) +
                             " are not among them (--frame-heads)");
        }
    }
}
}  // namespace

FitReport fit_model(const FitOptions& opt, OutputSet& outputs) {
    refuse_output_over_input({{"--in", opt.in}}, {{"--out", opt.out}}, true);
    refuse_corrected_file(opt.in);  // fit applies the aberration itself: never twice
    FitReport r = fit_model(
        opt, [&](const std::function<void(const SolutionRecord&)>& fn) { for_each_solution(opt.in, fn, "fit"); });
    outputs["--out"].write(format_model(r.model));
    return r;
}

FitReport fit_model(const FitOptions& opt) {
    OutputSet outputs({{"--out", opt.out}}, {{"--in", opt.in}});
    FitReport r = fit_model(opt, outputs);
    outputs.commit();
    return r;
}

namespace {

// --lag auto: the fit without a lag, whose pass chooses one (select_lags);
// then, when it took one, the fit with it, as --lag with those lags. A lagged
// model the data refuse (its terms, its condition) leaves the unlagged one.
FitReport fit_choosing_lag(const FitOptions& opt, const RowSource& rows) {
    std::vector<LagReading> readings = opt.holdout > 0.0 ? lag_readings(rows) : std::vector<LagReading>{};
    FitReport r = fit_pass(opt, rows, std::nullopt, fit_heads(opt, 0U), nullptr, &readings);
    if (!pipeline::any_lagged(r.lag.lag_s)) {
        return r;
    }
    const LaggedTemperatures lag(r.lag.lag_s, std::move(readings));
    try {
        FitReport lagged = fit_pass(opt, rows, std::nullopt, fit_heads(opt, 0U), &lag, nullptr);
        lagged.lag = r.lag;
        lagged.model.lag_s = r.lag.lag_s;
        lagged.model.lag_s = head_lags(lagged.model);  // a head not fitted has none
        return lagged;
    } catch (const FitRefused& e) {
        // The fit without a lag again, now with its Sun term (the first pass
        // left it to the lagged fit).
        LagSelection chosen = r.lag;
        chosen.lag_s = {};
        chosen.verdict += std::string("; but the fit with them is refused (") + e.what() + "): no lag";
        FitReport plain = fit_pass(opt, rows, std::nullopt, fit_heads(opt, 0U), nullptr, nullptr);
        plain.lag = chosen;
        return plain;
    }
}

}  // namespace

FitReport fit_model(const FitOptions& opt, const RowSource& rows) {
    refuse_bad_fit_options(opt);
    if (opt.from && opt.to && !(*opt.from < *opt.to)) {
        throw FitRefused("the modelling period is empty: --from " + time_text(*opt.from) + " is not before --to " +
                         time_text(*opt.to));
    }
    if (opt.orbit_period_s && !(*opt.orbit_period_s >= 600.0 && *opt.orbit_period_s <= kSecondsPerDay)) {
        throw FitRefused("--orbit-period must be in [600, 86400] s");
    }
    if (!(opt.holdout >= 0.0 && opt.holdout <= 0.5)) {
        throw FitRefused("--holdout must be in [0, 0.5] (a fraction of the modelling period), got " +
                         number_text(opt.holdout));
    }
    if (!(opt.min_temperature_range_c >= 0.0 && std::isfinite(opt.min_temperature_range_c))) {
        throw FitRefused("--min-temperature-range must be a finite number of degC >= 0, got " +
                         number_text(opt.min_temperature_range_c));
    }
    if (opt.lag_s && pipeline::any_lagged(*opt.lag_s)) {
        const LaggedTemperatures lag(*opt.lag_s, lag_readings(rows));
        FitReport r = fit_pass(opt, rows, std::nullopt, fit_heads(opt, 0U), &lag, nullptr);
        r.model.lag_s = *opt.lag_s;
        r.model.lag_s = head_lags(r.model);  // a head not fitted has none
        return r;
    }
    if (opt.lag_s || !opt.selection_report) {
        return fit_pass(opt, rows, std::nullopt, fit_heads(opt, 0U), nullptr, nullptr);
    }
    return fit_choosing_lag(opt, rows);
}

std::optional<std::array<double, kMaxHeads>> parse_lags(std::string_view text) {
    if (text == "auto") {
        return std::nullopt;
    }
    std::array<double, kMaxHeads> lag{};
    const auto value = [&](std::string_view v, std::string_view item) {
        const std::optional<double> x = parse_double(v);
        if (!x || !lag_acceptable(*x)) {
            throw FitRefused("--lag " + std::string(text) + ": '" + std::string(item) + "': the lag must be " +
                             lag_range_text());
        }
        return *x;
    };
    if (text.find(':') == std::string_view::npos) {
        lag.fill(value(text, text));
        return lag;
    }
    HeadMask named = 0U;
    for (std::size_t start = 0; start <= text.size();) {
        const std::size_t end = std::min(text.find(',', start), text.size());
        const std::string_view item = text.substr(start, end - start);
        const std::uint8_t h = item.size() > 2 && item[1] == ':' ? head_index(item[0]) : kMaxHeads;
        if (h >= kMaxHeads || (named & head_bit(h)) != 0U) {
            throw FitRefused("--lag " + std::string(text) + ": '" + std::string(item) +
                             "': expected TAU (every head) "
                             "or X:TAU,... (X a head, " +
                             kHeadChoices.text + ", once each)");
        }
        named |= head_bit(h);
        lag[h] = value(item.substr(2), item);
        start = end + 1;
    }
    return lag;
}

namespace {

constexpr double kPlaceholderPeriodS = 5400.0;

// What one reading of the rows gathers (fit_pass reads them once, or twice
// when the rows are out of time order).
struct Pass {
    FitReport r;
    HeadMask with_rows = 0U;                                             // heads with rows in the modelling period
    std::array<double, kMaxHeads> first_row{};                           // per head in with_rows: its rows' first t
    std::array<double, kMaxHeads> last_row{};                            //   and last t in the period
    std::optional<double> period;                                        // bins the epochs into orbits
    bool period_given = false;                                           // --orbit-period, or the second reading
    std::array<std::optional<Eigen::Quaterniond>, kMaxHeads> reference;  // provisional r, then N_i
    std::array<Eigen::Quaterniond, kMaxHeads> earliest_a;                // the earliest epoch's a
    bool any_epoch = false;
    double earliest_epoch = 0.0;
    // The earliest selected row: its speed gives the orbit period.
    bool any_row = false;
    double earliest_row = 0.0;
    double earliest_row_period = 0.0;
    double earliest_row_speed = 0.0;
    std::size_t earliest_row_line = 0;
    std::map<long long, OrbitSums> orbits;
    std::vector<FitEpoch> fit_epochs;                     // for the selection report's IBA RMS
    const std::vector<LagReading>* lag_search = nullptr;  // --lag auto: every row, by lag_order
};

Quaternion<double> to_core_q(const Eigen::Quaterniond& q) {
    return {q.w(), q.x(), q.y(), q.z()};
}
Eigen::Quaterniond to_eigen_q(const Quaternion<double>& q) {
    return {q.w, q.x, q.y, q.z};
}

// Frame F (eqs. 1–3) of its two heads at one epoch (calib/frame.hpp).
Quaternion<double> q_f_icrf_at(const Epoch<Row>& e, const std::array<std::uint8_t, 2>& frame) {
    return calib::q_f_icrf(to_core_q(e.head[frame[0]]->q), to_core_q(e.head[frame[1]]->q));
}

// Head h's rotation in F relative to its provisional reference (the first
// one seen), and its regressors, into the orbit's sums (calib/head_rotation.hpp).
void add_head(Pass& p, OrbitSums& o, const Epoch<Row>& e, const Quaternion<double>& q_f_icrf, std::size_t h) {
    const Quaternion<double> q_head_f = calib::q_head_f(to_core_q(e.head[h]->q), q_f_icrf);
    if (!p.reference[h]) {
        p.reference[h] = to_eigen_q(q_head_f);
    }
    const Quaternion<double> d = calib::relative_to(q_head_f, to_core_q(*p.reference[h]));
    o.q[h] += Eigen::Vector4d(d.w, d.x, d.y, d.z);
    if (!p.any_epoch || e.t < p.earliest_epoch) {
        p.earliest_a[h] = to_eigen_q(d);
    }
    const auto& t = e.head[h]->temp;
    o.x[h] += Eigen::Vector3d(t[0], t[1] - t[0], t[2] - t[0]);
    o.x2[h] += Eigen::Vector3d(t[0] * t[0], (t[1] - t[0]) * (t[1] - t[0]), (t[2] - t[0]) * (t[2] - t[0]));
}

FitEpoch fit_epoch_of(const Epoch<Row>& e, HeadMask heads) {
    FitEpoch fe{};
    fe.t = e.t;
    const HeadList list = heads_of(heads);
    for (std::size_t i = 0; i < list.count; ++i) {
        const std::size_t h = list.head[i];
        const Eigen::Quaterniond& q = e.head[h]->q;
        fe.q_chu_icrf[h] = {q.w(), q.x(), q.y(), q.z()};
        fe.temp[h] = e.head[h]->temp;
        fe.t_head[h] = e.head[h]->t;
    }
    return fe;
}

// The epoch count, the earliest epoch and the period's first and last epochs.
void note_epoch_time(Pass& p, double t) {
    ++p.r.epochs;
    if (!p.any_epoch || t < p.earliest_epoch) {
        p.earliest_epoch = t;
    }
    if (!p.any_epoch || t < p.r.t_first) {
        p.r.t_first = t;
    }
    if (!p.any_epoch || t > p.r.t_last) {
        p.r.t_last = t;
    }
    p.any_epoch = true;
}

// One epoch into its orbit's sums. F needs its two heads; the same epochs
// serve all heads, so an epoch without all the fit's heads is left out.
void add_epoch(Pass& p, const Epoch<Row>& e, const FitOptions& opt) {
    const HeadList list = heads_of(p.r.heads);
    for (std::size_t i = 0; i < list.count; ++i) {
        if (!e.head[list.head[i]]) {
            return;
        }
    }
    const Quaternion<double> q_f_icrf = q_f_icrf_at(e, opt.frame_heads);
    const auto bin = static_cast<long long>(std::floor(e.t / *p.period));
    OrbitSums& o = p.orbits[bin];
    ++o.count;
    for (std::size_t i = 0; i < list.count; ++i) {
        add_head(p, o, e, q_f_icrf, list.head[i]);
    }
    if (opt.selection_report) {
        p.fit_epochs.push_back(fit_epoch_of(e, p.r.heads));
    }
    note_epoch_time(p, e.t);
}

bool in_modelling_period(const FitOptions& opt, const SolutionRecord& rec) {
    return !((opt.from && rec.t < *opt.from) || (opt.to && rec.t > *opt.to) || rec.head >= kMaxHeads);
}

// The selection (fit_selection), then the aberration correction into c;
// kRejected where the core does not correct the row.
Drop select_and_correct(const SolutionRecord& rec, EarthVelocity& earth, CorrectedSolution<double>& c) {
    const CorrectionConfig<double> ab_only{true, nullptr};
    Drop d = fit_selection(rec);
    if (d == Drop::kNone) {
        c = correct_solution(to_core_input<double>(rec, &earth), ab_only);
        if ((c.status & status::kAberrationApplied) == 0U) {
            d = Drop::kRejected;
        }
    }
    return d;
}

// Only the earliest selected row's speed gives the orbit period, so it is
// judged after all rows are read (a later row read first must not decide).
// Until then an implausible speed gets a placeholder period, so that no orbit
// index overflows.
void note_selected_row(Pass& p, const SolutionRecord& rec) {
    if (!p.period_given && (!p.any_row || rec.t < p.earliest_row)) {
        const double v = std::sqrt(squared_norm(rec.v_sc_kms));
        const bool plausible = v > 1.0 && v < 12.0;
        p.earliest_row = rec.t;
        p.earliest_row_speed = v;
        p.earliest_row_line = rec.line;
        p.earliest_row_period = plausible ? 2.0 * kPi * kEarthGmKm3S2 / (v * v * v) : 0.0;
        if (!p.period) {
            p.period = plausible ? p.earliest_row_period : kPlaceholderPeriodS;
        }
    }
    p.any_row = true;
}

// One row: counted, selected and corrected, then handed to the epochs.
void add_row(Pass& p, const FitOptions& opt, EarthVelocity& earth, EpochAssembler<Row>& epochs,
             const SolutionRecord& rec) {
    if (!in_modelling_period(opt, rec)) {
        return;
    }
    if (!has_head(p.with_rows, rec.head) || rec.t < p.first_row[rec.head]) {
        p.first_row[rec.head] = rec.t;
    }
    if (!has_head(p.with_rows, rec.head) || rec.t > p.last_row[rec.head]) {
        p.last_row[rec.head] = rec.t;
    }
    p.with_rows |= head_bit(rec.head);
    if (!has_head(p.r.heads, rec.head)) {
        // A head this pass does not fit: left out (--heads), or fit_pass reads the rows again with it.
        p.r.rows_other_heads += opt.heads ? 1U : 0U;
        return;
    }
    ++p.r.rows;
    CorrectedSolution<double> c{};
    const Drop d = select_and_correct(rec, earth, c);
    ++p.r.dropped[static_cast<std::size_t>(d)];
    if (d != Drop::kNone) {
        return;
    }
    note_selected_row(p, rec);
    Row row;
    row.q = Eigen::Quaterniond(c.q_chu_icrf.w, c.q_chu_icrf.x, c.q_chu_icrf.y, c.q_chu_icrf.z);
    row.temp = rec.temperature;
    row.t = rec.t;
    epochs.add(rec.t, rec.head, rec.line, row);
}

// Re-base on the earliest epoch: with b = earliest a, each epoch's small
// angle is 2·vec(a ⊗ b⁻¹), bilinear in a, so an orbit's sum is exactly
// 2·vec(Σa ⊗ b⁻¹) (Σa as an unnormalised quaternion). Small angle: error ~ θ³/24.
void rebase_on_earliest_epoch(Pass& p) {
    const HeadList list = heads_of(p.r.heads);
    for (std::size_t i = 0; i < list.count && p.r.epochs != 0; ++i) {
        const std::size_t h = list.head[i];
        const Quaternion<double> b_inv = conjugate(to_core_q(p.earliest_a[h]));
        for (auto& kv : p.orbits) {
            const Eigen::Vector4d& s = kv.second.q[h];
            const Vector3<double> e =
                calib::small_angle(calib::hamilton_product(Quaternion<double>{s(0), s(1), s(2), s(3)}, b_inv));
            kv.second.e[h] = Eigen::Vector3d(e.x, e.y, e.z) * kRadToArcsec;
        }
        p.reference[h] = (p.earliest_a[h] * *p.reference[h]).normalized();
    }
}

// Why a refused period may be a head's doing: a fitted head without rows in
// the period, or whose rows span less than half the longest span of the
// fitted heads' rows (a head that failed for good; an epoch needs every
// fitted head). Names them and, when two or more heads are left, the
// --heads and --frame-heads that fit those; empty when no head is to blame.
std::string heads_hint(const FitOptions& opt, const Pass& p) {
    const FitReport& r = p.r;
    const HeadMask present = r.heads & p.with_rows;
    const HeadList listed = heads_of(present);
    double longest = 0.0;
    for (std::size_t i = 0; i < listed.count; ++i) {
        longest = std::max(longest, p.last_row[listed.head[i]] - p.first_row[listed.head[i]]);
    }
    HeadMask brief = 0U;
    std::string why;
    for (std::size_t i = 0; i < listed.count; ++i) {
        const std::uint8_t h = listed.head[i];
        if (p.last_row[h] - p.first_row[h] < 0.5 * longest) {
            brief |= head_bit(h);
            why += std::string(why.empty() ? "" : ", ") + head_name(h) +
                   "'s rows span only t = " + time_text(p.first_row[h]) + " .. " + time_text(p.last_row[h]);
        }
    }
    const HeadMask without_rows = r.heads & ~p.with_rows;
    if (without_rows != 0U) {
        why = head_words(without_rows) + (head_count(without_rows) == 1U ? " has" : " have") + " no rows there" +
              (why.empty() ? "" : ", ") + why;
    }
    if (present == 0U || why.empty()) {
        return {};
    }
    const HeadMask keep = present & ~brief;
    const HeadList kept = heads_of(keep);
    if (kept.count < 2U) {
        return "; " + why + ": a fit needs two heads with rows";
    }
    std::string example = "--heads " + head_letters(keep);
    if ((frame_set(opt.frame_heads) & ~keep) != 0U) {
        example += std::string(" --frame-heads ") + head_name(kept.head[0]) + head_name(kept.head[kept.count - 1U]);
    }
    return "; " + why + ": --heads and --frame-heads name the heads to fit (e.g. " + example + ")";
}

void refuse_short_period(const FitOptions& opt, const Pass& p, const std::string& period_text) {
    const FitReport& r = p.r;
    if (r.epochs == 0) {
        throw FitRefused(text::input_name(opt.in) + ": no epoch in the modelling period has solutions of " +
                         head_words(r.heads) + " that pass the selection" + heads_hint(opt, p));
    }
    const double span_days = (r.t_last - r.t_first) / kSecondsPerDay;
    if (span_days < opt.min_span_days) {
        char buf[200];
        text::c_snprintf(buf, sizeof buf,
                         "modelling period too short: the selected data span %.1f days (%s); at least %.1f days (one "
                         "thermal period; --min-days) are needed",
                         span_days, period_text.c_str(), opt.min_span_days);
        throw FitRefused(text::input_name(opt.in) + ": " + buf + heads_hint(opt, p));
    }
}

// Orbits with at least half the typical number of epochs: a short one
// (a gap, the ends of the period) is dominated by its part of the orbit.
std::size_t min_epochs_per_orbit(const std::map<long long, OrbitSums>& orbits) {
    std::vector<std::size_t> counts;
    counts.reserve(orbits.size());
    for (const auto& kv : orbits) {
        counts.push_back(kv.second.count);
    }
    std::nth_element(counts.begin(), counts.begin() + static_cast<long>(counts.size() / 2), counts.end());
    return std::max<std::size_t>(2, counts[counts.size() / 2] / 2);
}

// The averages of the orbits with at least min_count epochs.
std::vector<OrbitAverage> orbit_averages(const std::map<long long, OrbitSums>& orbits, std::size_t min_count,
                                         double period, HeadMask heads) {
    const HeadList list = heads_of(heads);
    std::vector<OrbitAverage> averages;
    for (const auto& kv : orbits) {
        if (kv.second.count < min_count) {
            continue;
        }
        OrbitAverage& a = averages.emplace_back();
        const double w = 1.0 / static_cast<double>(kv.second.count);
        a.t_mid = (static_cast<double>(kv.first) + 0.5) * period;
        for (std::size_t i = 0; i < list.count; ++i) {
            const std::size_t h = list.head[i];
            a.e[h] = kv.second.e[h] * w;
            a.x[h] = kv.second.x[h] * w;
            a.x2[h] = kv.second.x2[h] * w;
        }
    }
    return averages;
}

// The rule `combined`'s weights A_h (combine/mountings.hpp, motion_weight)
// for the heads fitted, from the mountings, which must have them all, with
// their sigmas.
void fill_motion(const FitOptions& opt, HeadMask heads, CommonRotation& rule) {
    const MountingsFile& m = *opt.mountings;
    const std::string name = text::input_name(opt.mountings_name);
    if (!m.sigmas) {
        throw FitRefused(name +
                         ": the mountings give no sigma_cross,sigma_about; the common rotation's rule 'combined' "
                         "weights the heads as the combination does, by their noise (ascorr align estimates it)");
    }
    const HeadList list = heads_of(heads);
    for (std::size_t i = 0; i < list.count; ++i) {
        const std::uint8_t h = list.head[i];
        if (!m.mountings.head[h].present) {
            throw FitRefused(name + ": head " + head_name(h) +
                             ", fitted, is not in the mountings; the common rotation's rule 'combined' needs every "
                             "head fitted (or --common-rotation smallest, or --heads without it)");
        }
        const combine::Matrix3 a = combine::motion_weight(m.mountings.head[h]);
        for (Eigen::Index r = 0; r < 3; ++r) {
            for (Eigen::Index c = 0; c < 3; ++c) {
                rule.motion[h](r, c) = a.m[r][c];
            }
        }
    }
}

// --sun-term auto: the Sun term fitted inside the orbit after the model
// written, taken when the held-out part supports it (fit_sun.hpp).
void choose_sun_term(const FitOptions& opt, Pass& p) {
    FitReport& r = p.r;
    SunSearchInput in;
    in.epochs = &p.fit_epochs;
    in.model = &r.model;
    in.heads = r.heads;
    in.frame_heads = r.frame_heads;
    in.period = *p.period;
    in.t_split = r.selection.t_split;
    in.rule = r.common_rotation;
    // Scored with the written terms fitted before the held-out part, or, when
    // the data there refuse them (quadratic terms on a smaller range), the
    // linear ones: the same polynomial on both sides of the comparison.
    const std::vector<ModelScore>& before = r.selection.models;
    const std::size_t written = r.terms == Terms::kQuadratic ? 1 : 0;
    if (opt.holdout <= 0.0) {
        in.no_split = "nothing held out (--holdout 0)";
    } else if (before.size() > written && before[written].fit.refused.empty()) {
        in.model_before_split = &before[written].fit.model;
    } else if (!before.empty() && before[0].fit.refused.empty()) {
        in.model_before_split = &before[0].fit.model;
    } else {
        in.no_split = "the polynomial cannot be fitted before the held-out part";
    }
    r.sun = select_sun_term(in);
    if (r.sun.taken) {
        r.model.sun = sun_coefficients_of(r.sun.fit, r.heads);
    }
}

// The fit of the orbit averages against the heads' orientations N_i in F,
// refused as solve_terms says; then the model-selection report.
void solve(const FitOptions& opt, Pass& p, const std::vector<OrbitAverage>& averages, const std::string& period_text) {
    FitReport& r = p.r;
    HeadOrientations n_ref;
    n_ref.fill(Eigen::Matrix3d::Identity());
    const HeadList list = heads_of(r.heads);
    for (std::size_t i = 0; i < list.count; ++i) {
        n_ref[list.head[i]] = p.reference[list.head[i]]->toRotationMatrix();
    }
    r.terms = opt.terms;
    r.common_rotation = common_rotation_rule(opt);
    if (r.common_rotation.rule == CommonRotationRule::kCombined) {
        fill_motion(opt, r.heads, r.common_rotation);
    }
    if (r.common_rotation.rule == CommonRotationRule::kRigid &&
        (r.heads & head_bit(r.common_rotation.rigid_head)) == 0U) {
        throw FitRefused("--common-rotation " + common_rotation_name(r.common_rotation) + ": head " +
                         head_name(r.common_rotation.rigid_head) + " is not among the heads fitted (" +
                         head_letters(r.heads) + ")");
    }
    r.fit = solve_terms(averages, n_ref, r.heads, opt.terms, opt.max_condition, opt.min_temperature_range_c,
                        r.common_rotation);
    if (!r.fit.refused.empty()) {
        if (opt.terms == Terms::kQuadratic) {
            throw FitRefused(text::input_name(opt.in) +
                             ": quadratic terms not supported by the data in the modelling period (" + period_text +
                             "): " + r.fit.refused + "; use --terms linear");
        }
        throw FitRefused(text::input_name(opt.in) + ": " + r.fit.refused +
                         ": T_CHU, T029 - T_CHU and T032 - T_CHU do not vary independently in the modelling period (" +
                         period_text + ")");
    }
    std::sort(p.fit_epochs.begin(), p.fit_epochs.end(), [](const FitEpoch& a, const FitEpoch& b) { return a.t < b.t; });
    if (opt.selection_report) {
        r.selection = select_terms(averages, p.fit_epochs, n_ref, r.heads, r.t_first, r.t_last, opt.holdout,
                                   opt.max_condition, opt.min_temperature_range_c, r.common_rotation);
    }
    if (p.lag_search != nullptr) {
        LagSearchInput in;
        in.orbits = &averages;
        in.period = *p.period;
        in.epochs = &p.fit_epochs;
        in.readings = p.lag_search;
        in.n_ref = n_ref;
        in.heads = r.heads;
        in.t_split = r.selection.t_split;
        in.max_condition = opt.max_condition;
        in.min_range_c = opt.min_temperature_range_c;
        in.rule = r.common_rotation;
        r.lag = select_lags(in);
    }
    r.singular_values = r.fit.singular_values;
    r.condition = r.fit.condition;
    r.head = r.fit.head;
    r.model = r.fit.model;
    if (r.common_rotation.rule != CommonRotationRule::kSmallest) {
        r.model.common_rotation = r.common_rotation;  // a file without the column: smallest
    }
    if (opt.sun_term == SunTermChoice::kAuto && opt.selection_report &&
        (p.lag_search == nullptr || !pipeline::any_lagged(r.lag.lag_s))) {  // else the lagged pass decides
        choose_sun_term(opt, p);
    }
}

// Row order must not matter. The reference N_i is the earliest
// epoch's (re-based exactly at the end), and the orbit period, when not
// given, comes from the earliest selected row: if that is not the first one
// read, the file is read again with that period (unordered files only).
// (earliest_period: that second reading.) Likewise the heads, unless
// --heads names them: a reading assumes them (A, B, C and F's first); when
// the period holds rows of others, the rows are read again with those too.
// And a row that came back to an epoch already handed on (a second row of
// its head there, unless the file is out of time order): again, keeping the
// epochs handed on (EpochAssembler::late).
FitReport fit_pass(const FitOptions& opt, const RowSource& rows, std::optional<double> earliest_period, HeadMask heads,
                   const LaggedTemperatures* lag, const std::vector<LagReading>* lag_search, Handed handed) {
    EarthVelocity earth;
    Pass p;
    p.lag_search = lag_search;
    p.r.heads = heads;
    p.r.frame_heads = opt.frame_heads;
    p.period_given = opt.orbit_period_s.has_value() || earliest_period.has_value();
    p.period = earliest_period ? earliest_period : opt.orbit_period_s;
    EpochAssembler<Row> epochs(
        opt.in, [&](const Epoch<Row>& e) { add_epoch(p, e, opt); }, heads, handed);
    SolutionRecord lagged;
    rows([&](const SolutionRecord& rec) {
        if (lag == nullptr) {
            add_row(p, opt, earth, epochs, rec);
            return;
        }
        lagged = rec;
        lag->apply(lagged);  // the terms take the head's lagged temperatures
        add_row(p, opt, earth, epochs, lagged);
    });
    epochs.finish();
    if (!opt.heads && (p.with_rows & ~heads) != 0U) {
        return fit_pass(opt, rows, earliest_period, fit_heads(opt, p.with_rows), lag, lag_search, handed);
    }
    if (epochs.late() && handed == Handed::kForget) {
        return fit_pass(opt, rows, earliest_period, heads, lag, lag_search, Handed::kRemember);
    }
    if (!p.period_given && p.any_row && !(p.earliest_row_speed > 1.0 && p.earliest_row_speed < 12.0)) {
        throw text::InputError(opt.in, p.earliest_row_line, 1,
                               "spacecraft speed " + number_text(p.earliest_row_speed) +
                                   " km/s is not that of an Earth orbit: give --orbit-period");
    }
    if (!p.period_given && p.period && *p.period != p.earliest_row_period) {
        // Rows out of time order: again, with the earliest row's period.
        return fit_pass(opt, rows, p.earliest_row_period, heads, lag, lag_search, handed);
    }
    p.r.orbit_period_s = p.period.value_or(0.0);
    rebase_on_earliest_epoch(p);

    const std::string period_text = "t = " + time_text(p.r.t_first) + " .. " + time_text(p.r.t_last);
    refuse_short_period(opt, p, period_text);
    const std::vector<OrbitAverage> averages =
        orbit_averages(p.orbits, min_epochs_per_orbit(p.orbits), *p.period, p.r.heads);
    p.r.orbits_used = averages.size();
    p.r.orbits_left_out = p.orbits.size() - averages.size();
    if (averages.size() < opt.min_orbits) {
        throw FitRefused(text::input_name(opt.in) + ": too few orbits in the modelling period (" + period_text +
                         "): " + std::to_string(averages.size()) + " with enough data, at least " +
                         std::to_string(opt.min_orbits) + " are needed (--min-orbits)" + heads_hint(opt, p));
    }
    solve(opt, p, averages, period_text);
    return p.r;
}

// The rule's sentence of the report; the smallest correction's is the
// report's as it always was.
std::string describe_rule(const CommonRotation& c) {
    switch (c.rule) {
        case CommonRotationRule::kCombined:
            return "(9 directions), the one that moves the combined attitude of the heads fitted least over the "
                   "period\n(--common-rotation combined, weights of the mountings) is written.\n";
        case CommonRotationRule::kRigid:
            return std::string("(9 directions), the one whose correction of head ") + head_name(c.rigid_head) +
                   " is smallest (taken as rigid to the bench:\n--common-rotation " + common_rotation_name(c) +
                   ") is written.\n";
        case CommonRotationRule::kSmallest:
            break;
    }
    return "(9 directions), the one with the smallest corrections over the period is written.\n";
}

// The heads whose temperatures the terms took through a lag (--lag), or nothing.
std::string describe_lag(const ModelFile& m) {
    if (!has_lag(m)) {
        return {};
    }
    std::string out = "each head's temperatures taken through the bench's lag (--lag, the model's lag_s):";
    for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
        if (m.present[h]) {
            out += std::string(" ") + head_name(h) + " " + number_text(m.lag_s[h]) + " s";
        }
    }
    return out + "\n";
}

}  // namespace

CommonRotation common_rotation_rule(const FitOptions& opt) {
    if (!opt.common_rotation) {
        CommonRotation c;
        c.rule = opt.mountings ? CommonRotationRule::kCombined : CommonRotationRule::kSmallest;
        return c;
    }
    if (opt.common_rotation->rule == CommonRotationRule::kCombined && !opt.mountings) {
        throw FitRefused(
            "--common-rotation combined needs the mountings (--mountings): the combination's weights say how each "
            "head's correction moves the bench");
    }
    return *opt.common_rotation;
}

std::string describe(const FitReport& r) {
    std::ostringstream o;
    char buf[400];
    text::c_snprintf(buf, sizeof buf, "modelling period t = %.3f .. %.3f (%.1f days), orbit period %.1f s\n", r.t_first,
                     r.t_last, (r.t_last - r.t_first) / kSecondsPerDay, r.orbit_period_s);
    o << buf;
    o << "rows in the period " << r.rows << ", selected " << r.dropped[0] << "; dropped:";
    for (std::size_t d = 1; d < kDropKinds; ++d) {
        o << (d > 1 ? "," : "") << ' ' << drop_name(static_cast<Drop>(d)) << ' ' << r.dropped[d];
    }
    if (r.rows_other_heads != 0U) {
        o << "; rows of other heads left out (--heads) " << r.rows_other_heads;
    }
    o << "\nepochs with " << head_words(r.heads) << " selected " << r.epochs << "; orbit averages used "
      << r.orbits_used << " (left out, too few epochs: " << r.orbits_left_out << ")\n";
    o << "fitted: the heads' rotations relative to the frame F of heads " << head_name(r.frame_heads[0]) << " and "
      << head_name(r.frame_heads[1])
      << " (eqs. 1-3), orbit-averaged,\n"
         "jointly against [1, T_CHU, T029 - T_CHU, T032 - T_CHU] of each head (--terms quadratic: and their "
         "squares),\n"
         "with F's own rotation in each orbit as a nuisance. Rotations common to all heads are not observable by "
         "the\n"
         "star trackers (they change no IBA): of the models that differ by one linear in T029 and T032\n";
    o << describe_rule(r.common_rotation);
    o << describe_lag(r.model);
    if (!r.lag.verdict.empty()) {
        o << "bench lag (--lag auto): " << r.lag.verdict << "\n";
    }
    if (!r.sun.verdict.empty()) {
        o << "Sun term (--sun-term auto): " << r.sun.verdict << "\n";
    }
    const auto rank = static_cast<std::size_t>(r.fit.rank);
    text::c_snprintf(buf, sizeof buf,
                     "terms %s; design %zu x %d (columns centred, scaled, unit norm): singular values %.3g .. %.3g (%d "
                     "observable), condition number %.1f; unobservable directions at %.1e\n",
                     terms_name(r.terms), 3 * heads_of(r.heads).count * r.orbits_used, r.fit.unknowns,
                     r.singular_values.front(), r.singular_values[rank - 1], r.fit.rank, r.condition,
                     r.singular_values[rank]);
    o << buf;
    o << describe_centring(r.fit);
    o << "CHU  residual RMS alpha/beta/gamma (arcsec)   signal RMS alpha/beta/gamma (arcsec), orbit averages\n";
    const HeadList list = heads_of(r.heads);
    for (std::size_t i = 0; i < list.count; ++i) {
        const std::size_t h = list.head[i];
        const HeadFit& f = r.head[h];
        text::c_snprintf(buf, sizeof buf, "%c    %6.3f %6.3f %6.3f                      %6.3f %6.3f %6.3f\n",
                         head_name(static_cast<std::uint8_t>(h)), f.residual_rms[0], f.residual_rms[1],
                         f.residual_rms[2], f.signal_rms[0], f.signal_rms[1], f.signal_rms[2]);
        o << buf;
    }
    if (!r.selection.models.empty()) {
        o << describe_selection(r.selection);
    }
    if (r.selection.decided && r.selection.preferred != r.terms) {
        o << "note: the model written has " << terms_name(r.terms) << " terms; the data support "
          << terms_name(r.selection.preferred) << " terms\n";
    }
    return o.str();
}

}  // namespace ascorr::host
