#include "ascorr_host/correct/self_calibration.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <stdexcept>

#include "ascorr/calib/feed.hpp"
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

// A row's place in time order; `input`: its index among the clean rows of
// A, B and C kept for the estimator, or kNotFed.
struct RowKey {
    std::int64_t t_us;
    std::size_t line;
    std::uint32_t input;
    double t;
};
constexpr std::uint32_t kNotFed = 0xFFFFFFFFU;

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

}  // namespace

template <typename T>
SelfCalibration self_calibrate(const std::string& file, const RowSource& rows, const std::optional<ModelFile>& initial,
                               const calib::EstimatorConfig& cfg_in, std::optional<double> orbit_period_s) {
    EarthVelocity earth;
    const CorrectionConfig<T> ab_only{true, nullptr};
    std::vector<RowKey> keys;
    std::vector<SolutionInput<T>> inputs;  // the clean rows of A, B and C whose aberration stage applies
    double earliest = 0.0;
    double earliest_speed = 0.0;
    std::size_t earliest_line = 0;
    SelfCalibration out;
    rows([&](const SolutionRecord& rec) {
        TtTime t{};
        if (!tt_from_seconds(rec.t, t)) {
            ++out.untimed;  // no epoch: corrected without a model (256)
            return;
        }
        RowKey k{t.us, rec.line, kNotFed, rec.t};
        if (rec.head < calib::kCalibHeads && calibration_clean(rec)) {
            const SolutionInput<T> in = to_core_input<T>(rec, &earth);
            if ((correct_solution(in, ab_only).status & status::kAberrationApplied) != 0U) {
                if (inputs.empty() || rec.t < earliest) {
                    earliest = rec.t;
                    earliest_speed = std::sqrt(squared_norm(rec.v_sc_kms));
                    earliest_line = rec.line;
                }
                k.input = static_cast<std::uint32_t>(inputs.size());
                inputs.push_back(in);
            }
        }
        keys.push_back(k);
    });
    std::sort(keys.begin(), keys.end(), [](const RowKey& a, const RowKey& b) {
        return a.t_us < b.t_us || (a.t_us == b.t_us && a.line < b.line);
    });

    if (orbit_period_s) {
        out.orbit_period_s = *orbit_period_s;
    } else if (!inputs.empty()) {
        // A circular orbit's period at that speed (vis-viva); the estimator's
        // limits (10 min to a day) are speeds of 3.3 to 16 km/s: beyond 12
        // km/s nothing is bound to the Earth.
        const double v = earliest_speed;
        const double period_s = 2.0 * kPi * kEarthGmKm3S2 / (v * v * v);
        if (!(v < 12.0 && period_s * 1e6 <= static_cast<double>(calib::kMaxOrbitPeriodUs))) {
            throw InputError(file, earliest_line, 1,
                             "spacecraft speed " + number_text(earliest_speed) +
                                 " km/s is not that of an Earth orbit of 10 min to a day: the orbit period for the "
                                 "self-calibration cannot be derived");
        }
        out.orbit_period_s = period_s;
    } else {
        out.orbit_period_s = 5640.0;  // no selected row: nothing is learnt, the period is not used
    }
    calib::EstimatorConfig cfg = cfg_in;
    if (!(out.orbit_period_s * 1e6 >= static_cast<double>(calib::kMinOrbitPeriodUs) &&
          out.orbit_period_s * 1e6 <= static_cast<double>(calib::kMaxOrbitPeriodUs))) {
        throw std::invalid_argument("orbit period " + number_text(out.orbit_period_s) +
                                    " s is outside the estimator's 600 s to 1 day");
    }
    cfg.orbit_period_us = static_cast<std::int64_t>(std::llround(out.orbit_period_s * 1e6));

    std::optional<ModelCoefficients> init_c;
    if (initial) {
        init_c = coefficients_of(*initial);
    }
    calib::Estimator<T> est(cfg, init_c ? &*init_c : nullptr);
    calib::EpochFeed<T> feed;
    const ThermalModel<T> no_model{};
    bool had = false;
    std::uint32_t version = 0;
    for (std::size_t i = 0; i < keys.size(); ++i) {
        const RowKey& k = keys[i];
        const ThermalModel<T>* model = feed.model_at(est, k.t_us);
        if (model != nullptr && (!had || feed.version() != version)) {
            out.history.push_back(
                {k.t, k.t_us, feed.version(), est.active_crc(), model_file_of(*est.active_coefficients())});
            had = true;
            version = feed.version();
        }
        if (k.input != kNotFed) {
            const SolutionInput<T>& in = inputs[k.input];
            const CorrectedSolution<T> c = correct_solution(in, CorrectionConfig<T>{true, model ? model : &no_model});
            if (feed.take(est, in.head, c, in.temperatures, true)) {
                ++out.cycles;
            }
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

template <typename T>
ModelSchedule<T>::ModelSchedule(const std::vector<ActiveModel>& history) : model_(1) {
    for (const ActiveModel& a : history) {
        from_us_.push_back(a.t_us);
        version_.push_back(a.version);
        model_.push_back(to_core<T>(a.model));
    }
}

template <typename T>
std::size_t ModelSchedule<T>::index_at(double t) const noexcept {
    TtTime tt{};
    if (!tt_from_seconds(t, tt)) {
        return 0;  // no epoch
    }
    return static_cast<std::size_t>(std::upper_bound(from_us_.begin(), from_us_.end(), tt.us) - from_us_.begin());
}

template <typename T>
const ThermalModel<T>& ModelSchedule<T>::at(double t) const noexcept {
    return model_[index_at(t)];
}

template <typename T>
std::optional<std::uint32_t> ModelSchedule<T>::version_at(double t) const noexcept {
    const std::size_t k = index_at(t);
    return k == 0 ? std::nullopt : std::optional<std::uint32_t>(version_[k - 1]);
}

template class ModelSchedule<double>;
template class ModelSchedule<float>;
template class ModelSchedule<Q30>;

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
    if (s.untimed > 0) {
        o << "; " << s.untimed
          << " row(s) with a time the on-board clock cannot hold (|t| > 1e11 s) left out of the estimation: no "
             "model for them (256)";
    }
    o << "; refusals:";
    for (std::size_t k = 1; k < calib::kRefusalKinds; ++k) {
        o << (k > 1 ? "," : "") << ' ' << calib::refusal_name(static_cast<calib::Refusal>(k)) << ' ' << r.refusals[k];
    }
    return o.str();
}

}  // namespace ascorr::host
