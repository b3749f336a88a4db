// `ascorr simulate`'s options: their refusals, and the truth models --truth and --truth-change name.
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

#include "ascorr_host/formats/csv.hpp"
#include "ascorr_host/formats/embedded_model.hpp"
#include "ascorr_host/formats/solutions_csv.hpp"
#include "ascorr_text/c_format.hpp"
#include "simulate_parts.hpp"

namespace ascorr::host {

namespace {

// "OPTION FROM:TO: ..." for a window outside [0, days] or empty.
void refuse_window(const char* option, const char* form, const DayWindow& w, double days) {
    if (!(w.from_day >= 0.0 && w.from_day < w.to_day && w.to_day <= days)) {
        char what[256];
        text::c_snprintf(what, sizeof what, "%s %g:%g: expected %s with 0 <= FROM_DAY < TO_DAY <= %g (--days)", option,
                         w.from_day, w.to_day, form, days);
        throw std::invalid_argument(what);
    }
}

void refuse_bad_head(const char* option, std::size_t head, HeadMask heads) {
    if (head >= kMaxHeads || !has_head(heads, static_cast<std::uint8_t>(head))) {
        throw std::invalid_argument(std::string(option) + ": HEAD must be " + head_words(heads, " or ") +
                                    " (the heads simulated, --heads), got " +
                                    head_name(static_cast<std::uint8_t>(head)));
    }
}

void refuse_bad_truth_changes(const SimulateOptions& opt) {
    double previous = 0.0;
    for (const TruthChange& c : opt.truth_changes) {
        if (!(c.day > previous && c.day < opt.days) || c.model.empty()) {
            char what[256];
            text::c_snprintf(what, sizeof what,
                             "--truth-change %g:%s: expected DAY:MODEL, a model file from DAY in (0, %g) (--days), "
                             "DAY increasing from one change to the next (the previous: %g)",
                             c.day, c.model.c_str(), opt.days, previous);
            throw std::invalid_argument(what);
        }
        previous = c.day;
    }
}

void refuse_bad_thermistor_faults(const SimulateOptions& opt) {
    constexpr const char* kOption = "--thermistor-fault";
    for (const ThermistorFault& f : opt.thermistor_faults) {
        refuse_bad_head(kOption, f.head, opt.heads);
        if (f.channel > 2) {
            throw std::invalid_argument(std::string(kOption) + ": CHANNEL must be t_chu, t_029 or t_032");
        }
        refuse_window(kOption, "HEAD:CHANNEL:stuck|drift:FROM_DAY:TO_DAY[:RATE]", f.window, opt.days);
        const bool drift = f.kind == ThermistorFaultKind::kDrift;
        if (!(std::fabs(f.rate_c_per_day) <= 100.0) || (!drift && f.rate_c_per_day != 0.0)) {
            char what[160];
            text::c_snprintf(what, sizeof what,
                             "%s: RATE %g: expected a drift's RATE in [-100, 100] degC/day; a stuck channel has none",
                             kOption, f.rate_c_per_day);
            throw std::invalid_argument(what);
        }
    }
}

// --bench-lag and --orbit-term out of their ranges (BenchDynamics).
void refuse_bad_bench(const BenchDynamics& b) {
    if (!(b.lag_s >= 0.0 && b.lag_s <= kMaxBenchLagS)) {
        throw std::invalid_argument("--bench-lag must be in [0, " + number_text(kMaxBenchLagS) +
                                    "] s (0: no lag), got " + number_text(b.lag_s));
    }
    if (!(b.orbit_arcsec >= 0.0 && b.orbit_arcsec <= kMaxOrbitTermArcsec)) {
        throw std::invalid_argument("--orbit-term must be in [0, " + number_text(kMaxOrbitTermArcsec) +
                                    "] arcsec (0: none), got " + number_text(b.orbit_arcsec));
    }
}

void refuse_bad_event_options(const SimulateOptions& opt) {
    if ((opt.heads & ~kAllHeads) != 0U || head_count(opt.heads) < 2) {
        throw std::invalid_argument("--heads " + head_letters(opt.heads) + ": expected two or more of the heads " +
                                    kHeadLetters + ", in that order");
    }
    refuse_bad_truth_changes(opt);
    for (const DayWindow& g : opt.gaps) {
        refuse_window("--gap", "FROM_DAY:TO_DAY", g, opt.days);
    }
    refuse_bad_thermistor_faults(opt);
    refuse_bad_bench(opt.bench);
    for (const HeadBias& b : opt.head_biases) {
        refuse_bad_head("--head-bias", b.head, opt.heads);
        refuse_window("--head-bias", "HEAD:FROM_DAY:TO_DAY:ARCSEC", b.window, opt.days);
        if (!(std::fabs(b.arcsec) <= 3600.0)) {
            char what[120];
            text::c_snprintf(what, sizeof what, "--head-bias: ARCSEC %g: expected a rotation in [-3600, 3600] arcsec",
                             b.arcsec);
            throw std::invalid_argument(what);
        }
    }
}

}  // namespace

void refuse_bad_events(const SimulateOptions& opt) {
    refuse_bad_event_options(opt);
}

namespace detail {

namespace {

std::string truth_name(const std::string& path) {
    return path.empty() ? std::string("truth model (Table 2)") : path;
}

// A model file (empty path: Table 2); heads A, B and C must all have
// coefficients. A head beyond C (index h ≥ 3) simulated that the file has
// none for takes head h − 3's with the opposite sign (D: −A's): a deformation
// of its own, not a rotation common to the heads.
ModelFile truth_model(const std::string& path, HeadMask heads) {
    ModelFile truth_file = path.empty() ? table2_model() : read_model_file(path);
    refuse_lagged_model(truth_file, path, "a truth model takes no lag: --bench-lag lags the simulated bench");
    refuse_sun_term(truth_file, path, "a truth model takes none: --orbit-term gives the simulated bench one");
    for (std::size_t h = 0; h < kOwnHeads; ++h) {
        if (!truth_file.present[h]) {
            throw std::invalid_argument((path.empty() ? std::string("truth model") : path) +
                                        ": no coefficients for CHU " + head_name(static_cast<std::uint8_t>(h)));
        }
    }
    for (std::size_t h = kOwnHeads; h < kMaxHeads; ++h) {
        if (!truth_file.present[h] && has_head(heads, static_cast<std::uint8_t>(h))) {
            truth_file.present[h] = true;
            for (std::size_t ax = 0; ax < kModelAxes; ++ax) {
                for (std::size_t c = 0; c < kModelTerms; ++c) {
                    truth_file.coefficients[h][ax][c] = -truth_file.coefficients[h - kOwnHeads][ax][c];
                }
            }
        }
    }
    return truth_file;
}

}  // namespace

// --truth (from the first epoch), then each --truth-change.
std::vector<Truth> truth_models(const SimulateOptions& opt) {
    std::vector<Truth> truths;
    const auto add = [&truths, &opt](const std::string& path, double t_from) {
        ModelFile file = truth_model(path, opt.heads);
        ThermalModel<double> model = to_core<double>(file);
        truths.push_back({std::move(file), model, truth_name(path), t_from});
    };
    add(opt.truth, std::round(opt.start_t * 1000.0) / 1000.0);
    for (const TruthChange& c : opt.truth_changes) {
        add(c.model, std::round((opt.start_t + c.day * kSecondsPerDay) * 1000.0) / 1000.0);
    }
    return truths;
}

void refuse_bad_options(const SimulateOptions& opt) {
    if (!(opt.days > 0.0 && opt.days <= 36600.0)) {
        throw std::invalid_argument("--days must be in (0, 36600], got " + number_text(opt.days));
    }
    if (!(opt.step_s >= 1.0 && opt.step_s <= 600.0)) {
        throw std::invalid_argument("--step must be in [1, 600] s (the orbit must be resolved), got " +
                                    number_text(opt.step_s));
    }
    if (!in_ephemeris_span(opt.start_t) || !in_ephemeris_span(opt.start_t + opt.days * kSecondsPerDay)) {
        throw std::invalid_argument("--start " + number_text(opt.start_t) +
                                    ": the mission must lie within the Earth ephemeris (1900-2100; s since J2000 TT)");
    }
    refuse_bad_event_options(opt);
}

}  // namespace detail

}  // namespace ascorr::host
