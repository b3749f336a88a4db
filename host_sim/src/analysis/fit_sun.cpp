#include "ascorr_host/analysis/fit_sun.hpp"

#include <cmath>
#include <limits>

#include "ascorr/core/correct.hpp"
#include "ascorr/nav/sun_direction.hpp"
#include "ascorr_host/formats/solutions_csv.hpp"
#include "ascorr_text/c_format.hpp"

namespace ascorr::host {

namespace {

// The fit's rule as the shared least squares take it (calib::SunRule); the
// combined rule's weights by head index into `weights`.
calib::SunRule sun_rule_of(const CommonRotation& rule, calib::Matrix3 (&weights)[kMaxHeads]) {
    calib::SunRule out;
    if (rule.rule == CommonRotationRule::kCombined) {
        for (std::size_t h = 0; h < kMaxHeads; ++h) {
            for (int r = 0; r < 3; ++r) {
                for (int c = 0; c < 3; ++c) {
                    weights[h].m[r][c] = rule.motion[h](r, c);
                }
            }
        }
        out.weight = weights;
    } else if (rule.rule == CommonRotationRule::kRigid) {
        out.rigid_head = rule.rigid_head;
    }
    return out;
}

// The model with the Sun term s (none: its polynomial alone).
ModelFile with_sun(const ModelFile& m, const SunCoefficients& s = {}) {
    ModelFile out = m;
    out.sun = s;
    return out;
}

// Why a fitted term is beyond what a model may hold (sun_axis_problem), or empty.
std::string outside_the_domain(const SunCoefficients& sun, HeadMask heads) {
    const HeadList list = heads_of(heads);
    for (std::size_t i = 0; i < list.count; ++i) {
        for (std::size_t a = 0; a < kModelAxes; ++a) {
            const std::string why = sun_axis_problem(sun[list.head[i]][a]);
            if (!why.empty()) {
                return std::string("head ") + head_name(static_cast<std::uint8_t>(list.head[i])) + " " + kAxisNames[a] +
                       ": " + why;
            }
        }
    }
    return {};
}

std::string verdict_of(const SunSelection& s) {
    const double gain = 1.0 - s.sun_rms / s.none_rms;
    char buf[400];
    text::c_snprintf(buf, sizeof buf,
                     "%s: fitted inside the orbit before the held-out part (rank %d), it %s the held-out IBA RMS "
                     "(mean over the pairs) from %.4f to %.4f arcsec (%+.2f %%), %s the %.2f %% margin",
                     s.taken ? "taken" : "none", s.fit.solved ? s.fit.rank : 0, gain >= 0.0 ? "lowers" : "raises",
                     s.none_rms, s.sun_rms, -100.0 * gain, s.taken ? "more than" : "not more than",
                     100.0 * kSunSelectionMargin);
    return buf;
}

}  // namespace

SunCoefficients sun_coefficients_of(const calib::SunTermFit& f, HeadMask heads) {
    SunCoefficients out{};
    calib::copy_sun_coefficients(f, heads, out);
    return out;
}

calib::SunTermFit fit_sun_term(const std::vector<FitEpoch>& epochs, double from, double to, const ModelFile& m,
                               HeadMask heads, const std::array<std::uint8_t, 2>& frame_heads, double period,
                               const CommonRotation& rule) {
    const ThermalModel<double> core = to_core<double>(m);
    const CorrectionConfig<double> thermal_only{false, &core};
    const HeadList list = heads_of(heads);
    std::uint8_t order[kMaxHeads] = {};
    for (std::size_t i = 0; i < list.count; ++i) {
        order[i] = static_cast<std::uint8_t>(list.head[i]);
    }
    calib::SunMoments<kMaxHeads> moments(order, list.count, frame_heads[0], frame_heads[1]);
    long long bin = 0;
    for (const FitEpoch& e : epochs) {
        if (!(e.t >= from && e.t < to)) {
            continue;
        }
        Quaternion<double> q[kMaxHeads]{};
        bool all = true;
        for (std::size_t i = 0; i < list.count; ++i) {
            const std::size_t h = list.head[i];
            const CorrectedSolution<double> c = correct_solution(thermal_input(e, h), thermal_only);
            all = all && (c.status & status::kThermalApplied) != 0U;
            q[h] = c.q_chu_icrf;
        }
        Vector3<double> s_icrf{};
        if (!all || !nav::sun_direction_icrf(e.t, s_icrf)) {
            continue;
        }
        const auto epoch_bin = static_cast<long long>(std::floor(e.t / period));
        if (moments.open_count() != 0U && epoch_bin != bin) {
            moments.close_orbit(1.0);  // every orbit kept
        }
        bin = epoch_bin;
        moments.add(q, s_icrf);
    }
    moments.close_orbit(1.0);
    calib::Matrix3 weights[kMaxHeads]{};
    calib::SunTermFit fit;
    (void)moments.solve(sun_rule_of(rule, weights), fit);
    return fit;
}

SunSelection select_sun_term(const SunSearchInput& in) {
    SunSelection s;
    const double inf = std::numeric_limits<double>::infinity();
    const PairList pairs = pairs_of(in.heads);
    if (in.model_before_split == nullptr) {
        s.verdict = "none: " + in.no_split;
        return s;
    }
    const ModelFile before = with_sun(*in.model_before_split);
    const calib::SunTermFit trial =
        fit_sun_term(*in.epochs, -inf, in.t_split, before, in.heads, in.frame_heads, in.period, in.rule);
    const auto held_out_rms = [&](const ModelFile& m) {
        return mean_pair_rms(corrected_iba_rms(*in.epochs, in.heads, in.t_split, inf, m, kWhereTheSunIsKnown), pairs);
    };
    s.none_rms = held_out_rms(before);
    s.sun_rms = held_out_rms(with_sun(before, sun_coefficients_of(trial, in.heads)));
    if (!(s.none_rms > 0.0 && s.sun_rms > 0.0)) {
        s.verdict = "none: a pair has no held-out epoch";
        return s;
    }
    s.decided = true;
    s.taken = 1.0 - s.sun_rms / s.none_rms > kSunSelectionMargin;
    s.fit = trial;
    s.verdict = verdict_of(s);
    if (s.taken) {
        s.fit = fit_sun_term(*in.epochs, -inf, inf, with_sun(*in.model), in.heads, in.frame_heads, in.period, in.rule);
        const std::string why = outside_the_domain(sun_coefficients_of(s.fit, in.heads), in.heads);
        if (!why.empty()) {
            s.taken = false;
            s.verdict += "; but the whole period's term is not taken: " + why;
        }
    }
    return s;
}

}  // namespace ascorr::host
