#include "ascorr_host/correct/self_calibration.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "ascorr/core/correct.hpp"
#include "ascorr/core/fixed_point.hpp"
#include "ascorr/nav/orbit_propagation.hpp"
#include "ascorr/nav/tt_time.hpp"
#include "ascorr_host/correct/earth_velocity.hpp"
#include "ascorr_host/correct/selection.hpp"
#include "ascorr_host/correct/solution_input.hpp"
#include "ascorr_host/formats/csv.hpp"
#include "ascorr_host/formats/input_error.hpp"

namespace ascorr::host {

namespace {

// A selected row as the estimator needs it; q and the temperatures in T, kept
// as doubles (exact for float and Q30) until the cycle is formed. Only the
// selected rows are kept: the others matter only through their t (below).
struct SelectedRow {
    double t;
    std::size_t line;
    std::uint8_t head;
    double q[4];
    double temp[3];
};

ModelFile model_file_of(const ModelCoefficients& c) {
    ModelFile m;
    for (std::size_t h = 0; h < kMaxHeads; ++h) {
        m.present[h] = c.present[h];
        for (std::size_t a = 0; a < kModelAxes; ++a) {
            for (std::size_t i = 0; i < kModelTerms; ++i) {
                m.coefficients[h][a][i] = c.coefficient[h][a][i];
            }
        }
    }
    return m;
}

// The distinct times of the selected rows, in order, and for each the first t
// of any row after it (+inf: none): a model adopted in the idle time after a
// cycle becomes active at that t. Unselected rows change nothing else: the
// estimator's idle work only follows a cycle, and a swap it leaves pending is
// taken at the next t, which is never later than the next selected one.
struct CycleTimes {
    std::vector<double> t;
    std::vector<double> next;

    void add(double x) {
        if (t.empty() || t.back() != x) {
            t.push_back(x);
            next.push_back(std::numeric_limits<double>::infinity());
        }
    }
    // Row time x: the next t of the last cycle time before it.
    void see(double x) {
        const auto k = static_cast<std::size_t>(std::lower_bound(t.begin(), t.end(), x) - t.begin());
        if (k > 0 && x < next[k - 1]) {
            next[k - 1] = x;
        }
    }
};

}  // namespace

template <typename T>
SelfCalibration self_calibrate(const std::string& file, const RowSource& rows, const std::optional<ModelFile>& initial,
                               const calib::EstimatorConfig& cfg_in, std::optional<double> orbit_period_s) {
    using Tr = ScalarTraits<T>;
    EarthVelocity earth;
    const CorrectionConfig<T> ab_only{true, nullptr};
    std::vector<SelectedRow> selected;
    CycleTimes cycles;
    SelfCalibration out;
    bool any_row = false;
    bool in_order = true;  // rows in time order so far: the next times come with the one pass
    double first_t = 0.0;
    double last_t = 0.0;
    double earliest_t = 0.0;  // of the selected rows
    double earliest_speed = 0.0;
    std::size_t earliest_line = 0;
    rows([&](const SolutionRecord& rec) {
        TtTime tt{};
        if (!tt_from_seconds(rec.t, tt)) {
            ++out.rows_unclocked;  // a time the on-board clock cannot hold: no part in the estimation
            return;
        }
        in_order = in_order && (!any_row || rec.t >= last_t);
        if (in_order && !cycles.t.empty() && cycles.t.back() < rec.t && std::isinf(cycles.next.back())) {
            cycles.next.back() = rec.t;
        }
        first_t = any_row ? std::min(first_t, rec.t) : rec.t;
        last_t = rec.t;
        any_row = true;
        // The clean epochs of docs/contract.md's Statistics: the fit's selection,
        // and no flag bit at all, and a confidence that is a number <= 5.
        const bool clean = fit_selection(rec) == Drop::kNone && rec.flags == 0 && rec.confidence <= 5.0;
        if (rec.head >= calib::kCalibHeads || !clean) {
            return;
        }
        const SolutionInput<T> in = to_core_input<T>(rec, &earth);
        const CorrectedSolution<T> c = correct_solution(in, ab_only);
        if ((c.status & status::kAberrationApplied) == 0U) {
            return;
        }
        if (selected.empty() || rec.t < earliest_t) {
            earliest_t = rec.t;
            earliest_speed = std::sqrt(squared_norm(rec.v_sc_kms));
            earliest_line = rec.line;
        }
        selected.push_back({rec.t,
                            rec.line,
                            rec.head,
                            {Tr::to_double(c.q_chu_icrf.w), Tr::to_double(c.q_chu_icrf.x),
                             Tr::to_double(c.q_chu_icrf.y), Tr::to_double(c.q_chu_icrf.z)},
                            {Tr::to_double(in.temperatures.t_chu.value), Tr::to_double(in.temperatures.t_029.value),
                             Tr::to_double(in.temperatures.t_032.value)}});
        if (in_order) {
            cycles.add(rec.t);
        }
    });
    std::sort(selected.begin(), selected.end(),
              [](const SelectedRow& a, const SelectedRow& b) { return a.t < b.t || (a.t == b.t && a.line < b.line); });
    if (!in_order && !selected.empty()) {  // a second pass for the next times, over the t of every row
        cycles = CycleTimes{};
        for (const SelectedRow& r : selected) {
            cycles.add(r.t);
        }
        rows([&](const SolutionRecord& rec) {
            TtTime tt{};
            if (tt_from_seconds(rec.t, tt)) {
                cycles.see(rec.t);
            }
        });
    }

    if (orbit_period_s) {
        out.orbit_period_s = *orbit_period_s;
    } else if (!selected.empty()) {
        if (!(earliest_speed > 1.0 && earliest_speed < 12.0)) {
            throw InputError(file, earliest_line, 1,
                             "spacecraft speed " + number_text(earliest_speed) +
                                 " km/s is not that of an Earth orbit: the orbit period for the self-calibration "
                                 "cannot be derived");
        }
        out.orbit_period_s = 2.0 * kPi * kEarthGmKm3S2 / (earliest_speed * earliest_speed * earliest_speed);
    } else {
        out.orbit_period_s = 5640.0;  // no selected row: nothing is learnt, the period is not used
    }
    calib::EstimatorConfig cfg = cfg_in;
    TtTime period{};
    if (!tt_from_seconds(out.orbit_period_s, period) || period.us <= 0) {
        throw std::invalid_argument("orbit period " + number_text(out.orbit_period_s) + " s is not a positive time");
    }
    cfg.orbit_period_us = period.us;

    std::optional<ModelCoefficients> init_c;
    if (initial) {
        init_c = coefficients_of(*initial);
    }
    calib::Estimator<T> est(cfg, init_c ? &*init_c : nullptr);
    bool had = false;
    std::uint32_t version = 0;
    // t (a row's) on the on-board clock, which holds it.
    const auto clock_us = [](double t) {
        TtTime tt{};
        (void)tt_from_seconds(t, tt);
        return tt.us;
    };
    // The model for the cycle at t (a pending swap is taken here); a newly
    // active model joins the history.
    const auto take_model = [&](double t) {
        (void)est.model_for_cycle(clock_us(t));
        const calib::EstimatorReport rep = est.report();
        if (rep.has_active && (!had || rep.active_version != version)) {
            out.history.push_back({t, rep.active_version, rep.active_crc, model_file_of(*est.active_coefficients())});
            had = true;
            version = rep.active_version;
        }
    };
    if (any_row && (cycles.t.empty() || first_t < cycles.t.front())) {
        take_model(first_t);  // the first row: --model is active from it
    }
    for (std::size_t k = 0, i = 0; k < cycles.t.size(); ++k) {
        const double t = cycles.t[k];
        take_model(t);
        const SelectedRow* head[calib::kCalibHeads] = {nullptr, nullptr, nullptr};
        for (; i < selected.size() && selected[i].t == t; ++i) {
            if (head[selected[i].head] == nullptr) {
                head[selected[i].head] = &selected[i];
            }
        }
        if (head[0] != nullptr && head[1] != nullptr && head[2] != nullptr) {
            calib::CalibCycle<T> c{};
            c.t_us = clock_us(t);
            for (std::size_t h = 0; h < calib::kCalibHeads; ++h) {
                const SelectedRow& r = *head[h];
                c.q_chu_icrf[h] = {Tr::from_double(r.q[0]), Tr::from_double(r.q[1]), Tr::from_double(r.q[2]),
                                   Tr::from_double(r.q[3])};
                c.temperatures[h].t_chu = {Tr::celsius(r.temp[0]), true};
                c.temperatures[h].t_029 = {Tr::celsius(r.temp[1]), true};
                c.temperatures[h].t_032 = {Tr::celsius(r.temp[2]), true};
            }
            est.accumulate(c);
            ++out.cycles;
        }
        while (est.step()) {
        }
        const double next = cycles.next[k];
        if (!std::isinf(next) && (k + 1 == cycles.t.size() || next < cycles.t[k + 1])) {
            take_model(next);  // an unselected row's t before the next cycle
        }
    }
    out.report = est.report();
    return out;
}

template SelfCalibration self_calibrate<double>(const std::string&, const RowSource&, const std::optional<ModelFile>&,
                                                const calib::EstimatorConfig&, std::optional<double>);
template SelfCalibration self_calibrate<float>(const std::string&, const RowSource&, const std::optional<ModelFile>&,
                                               const calib::EstimatorConfig&, std::optional<double>);
template SelfCalibration self_calibrate<Q30>(const std::string&, const RowSource&, const std::optional<ModelFile>&,
                                             const calib::EstimatorConfig&, std::optional<double>);

std::string format_model_history(const std::vector<ActiveModel>& history) {
    std::string out = "t,version,chu,axis,c0,c1,c2,c3,crc32c\n";
    char buf[96];
    for (const ActiveModel& m : history) {
        for (std::size_t h = 0; h < kMaxHeads; ++h) {
            if (!m.model.present[h]) {
                continue;
            }
            for (std::size_t a = 0; a < kModelAxes; ++a) {
                std::snprintf(buf, sizeof buf, "%.3f,%u,%c,%s", m.t, m.version, head_name(static_cast<std::uint8_t>(h)),
                              kAxisNames[a]);
                out += buf;
                for (std::size_t i = 0; i < kLinearModelTerms; ++i) {
                    std::snprintf(buf, sizeof buf, ",%.16e", m.model.coefficients[h][a][i]);
                    out += buf;
                }
                std::snprintf(buf, sizeof buf, ",%08x\n", m.crc);
                out += buf;
            }
        }
    }
    return out;
}

std::string describe(const SelfCalibration& s) {
    std::ostringstream o;
    char buf[300];
    const calib::EstimatorReport& r = s.report;
    std::snprintf(buf, sizeof buf,
                  "self-calibration: orbit period %.1f s, %zu epochs with A, B and C selected; orbits used %u (short "
                  "%u, held back %u); %zu model(s) active in turn",
                  s.orbit_period_s, s.cycles, r.orbits_used, r.orbits_short, r.orbits_held, s.history.size());
    o << buf;
    if (r.has_active) {
        std::snprintf(buf, sizeof buf,
                      "; active version %u (crc32c %08x), residual RMS %.3f\" over the recent orbits, condition %.1f",
                      r.active_version, r.active_crc, r.residual_rms_arcsec, r.condition);
        o << buf;
    } else {
        o << "; no model adopted";
    }
    if (s.rows_unclocked != 0) {
        o << "; " << s.rows_unclocked << " row(s) with a time the on-board clock cannot hold (|t| > 1e11 s) left out";
    }
    o << "; refusals:";
    for (std::size_t k = 1; k < calib::kRefusalKinds; ++k) {
        o << (k > 1 ? "," : "") << ' ' << calib::refusal_name(static_cast<calib::Refusal>(k)) << ' ' << r.refusals[k];
    }
    return o.str();
}

}  // namespace ascorr::host
