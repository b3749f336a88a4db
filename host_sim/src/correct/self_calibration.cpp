#include "ascorr_host/correct/self_calibration.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "ascorr/core/correct.hpp"
#include "ascorr/core/fixed_point.hpp"
#include "ascorr/nav/orbit_propagation.hpp"
#include "ascorr_host/correct/earth_velocity.hpp"
#include "ascorr_host/correct/selection.hpp"
#include "ascorr_host/correct/solution_input.hpp"
#include "ascorr_host/formats/input_error.hpp"

namespace ascorr::host {

namespace {

// One row as the estimator needs it; q and the temperatures in T, kept as
// doubles (exact for float and Q30) until the cycle is formed.
struct CalibRow {
    double t;
    std::size_t line;
    std::uint8_t head;
    bool selected;
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

std::int64_t to_us(double t) {
    return static_cast<std::int64_t>(std::llround(t * 1e6));
}

}  // namespace

template <typename T>
SelfCalibration self_calibrate(const std::string& file, const RowSource& rows, const std::optional<ModelFile>& initial,
                               const calib::EstimatorConfig& cfg_in, std::optional<double> orbit_period_s) {
    using Tr = ScalarTraits<T>;
    EarthVelocity earth;
    const CorrectionConfig<T> ab_only{true, nullptr};
    std::vector<CalibRow> all;
    double earliest = 0.0;
    double earliest_speed = 0.0;
    std::size_t earliest_line = 0;
    bool any_selected = false;
    rows([&](const SolutionRecord& rec) {
        CalibRow r{rec.t, rec.line, rec.head, false, {}, {}};
        // The clean epochs of docs/contract.md's Statistics: the fit's selection,
        // and no flag bit at all, and a confidence that is a number <= 5.
        const bool clean = fit_selection(rec) == Drop::kNone && rec.flags == 0 && rec.confidence <= 5.0;
        if (rec.head < calib::kCalibHeads && clean) {
            const SolutionInput<T> in = to_core_input<T>(rec, &earth);
            const CorrectedSolution<T> c = correct_solution(in, ab_only);
            if ((c.status & status::kAberrationApplied) != 0U) {
                r.selected = true;
                r.q[0] = Tr::to_double(c.q_chu_icrf.w);
                r.q[1] = Tr::to_double(c.q_chu_icrf.x);
                r.q[2] = Tr::to_double(c.q_chu_icrf.y);
                r.q[3] = Tr::to_double(c.q_chu_icrf.z);
                r.temp[0] = Tr::to_double(in.temperatures.t_chu.value);
                r.temp[1] = Tr::to_double(in.temperatures.t_029.value);
                r.temp[2] = Tr::to_double(in.temperatures.t_032.value);
                if (!any_selected || rec.t < earliest) {
                    earliest = rec.t;
                    earliest_speed = std::sqrt(squared_norm(rec.v_sc_kms));
                    earliest_line = rec.line;
                }
                any_selected = true;
            }
        }
        all.push_back(r);
    });
    std::sort(all.begin(), all.end(),
              [](const CalibRow& a, const CalibRow& b) { return a.t < b.t || (a.t == b.t && a.line < b.line); });

    SelfCalibration out;
    if (orbit_period_s) {
        out.orbit_period_s = *orbit_period_s;
    } else if (any_selected) {
        if (!(earliest_speed > 1.0 && earliest_speed < 12.0)) {
            throw InputError(file, earliest_line, 1,
                             "spacecraft speed " + std::to_string(earliest_speed) +
                                 " km/s is not that of an Earth orbit: the orbit period for the self-calibration "
                                 "cannot be derived");
        }
        out.orbit_period_s = 2.0 * kPi * kEarthGmKm3S2 / (earliest_speed * earliest_speed * earliest_speed);
    } else {
        out.orbit_period_s = 5640.0;  // no selected row: nothing is learnt, the period is not used
    }
    calib::EstimatorConfig cfg = cfg_in;
    cfg.orbit_period_us = to_us(out.orbit_period_s);

    std::optional<ModelCoefficients> init_c;
    if (initial) {
        init_c = coefficients_of(*initial);
    }
    calib::Estimator<T> est(cfg, init_c ? &*init_c : nullptr);
    bool had = false;
    std::uint32_t version = 0;
    for (std::size_t i = 0; i < all.size();) {
        std::size_t j = i;
        while (j < all.size() && all[j].t == all[i].t) {
            ++j;
        }
        const double t = all[i].t;
        const std::int64_t t_us = to_us(t);
        (void)est.model_for_cycle(t_us);
        const calib::EstimatorReport rep = est.report();
        if (rep.has_active && (!had || rep.active_version != version)) {
            out.history.push_back({t, rep.active_version, rep.active_crc, model_file_of(*est.active_coefficients())});
            had = true;
            version = rep.active_version;
        }
        const CalibRow* head[calib::kCalibHeads] = {nullptr, nullptr, nullptr};
        for (std::size_t k = i; k < j; ++k) {
            if (all[k].selected && head[all[k].head] == nullptr) {
                head[all[k].head] = &all[k];
            }
        }
        if (head[0] != nullptr && head[1] != nullptr && head[2] != nullptr) {
            calib::CalibCycle<T> c{};
            c.t_us = t_us;
            for (std::size_t h = 0; h < calib::kCalibHeads; ++h) {
                const CalibRow& r = *head[h];
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
        i = j;
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
    o << "; refusals:";
    for (std::size_t k = 1; k < calib::kRefusalKinds; ++k) {
        o << (k > 1 ? "," : "") << ' ' << calib::refusal_name(static_cast<calib::Refusal>(k)) << ' ' << r.refusals[k];
    }
    return o.str();
}

}  // namespace ascorr::host
