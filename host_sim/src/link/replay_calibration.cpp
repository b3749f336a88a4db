// `ascorr replay --self-calibrate`: the target's model versions, models and estimator report against the host's.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <optional>
#include <ostream>
#include <string>

#include "ascorr_text/c_format.hpp"
#include "replay_parts.hpp"

namespace ascorr::host::detail {

namespace {

// Whether two doubles are the same value: bit for bit, or both NaN (the
// targets' and the host's default NaNs differ in sign).
bool same_double(double a, double b) {
    return (std::isnan(a) && std::isnan(b)) || std::memcmp(&a, &b, sizeof a) == 0;
}

// A field that differs, named with the target's and the host's values;
// empty when the same (doubles: same_double).
std::string count_difference(const char* name, std::uint64_t target, std::uint64_t host) {
    return target == host ? std::string()
                          : std::string(name) + ": target " + std::to_string(target) + ", host " + std::to_string(host);
}
std::string double_difference(const char* name, double target, double host) {
    return same_double(target, host)
               ? std::string()
               : std::string(name) + ": target " + number_text(target) + ", host " + number_text(host);
}

// The first of the fields' differences; empty: none.
template <std::size_t N>
std::string first_of(const std::string (&fields)[N]) {
    for (const std::string& f : fields) {
        if (!f.empty()) {
            return f;
        }
    }
    return {};
}

// The first field in which a (the target's) and b (the host's) differ, with
// both values; empty when they are the same (doubles: same_double).
std::string first_report_difference(const calib::EstimatorReport& a, const calib::EstimatorReport& b) {
    const std::string fields[] = {
        count_difference("orbits used", a.orbits_used, b.orbits_used),
        count_difference("orbits short", a.orbits_short, b.orbits_short),
        count_difference("orbits held back", a.orbits_held, b.orbits_held),
        count_difference("orbits late", a.orbits_late, b.orbits_late),
        count_difference("changes", a.changes, b.changes),
        double_difference("condition", a.condition, b.condition),
        double_difference("residual RMS", a.residual_rms_arcsec, b.residual_rms_arcsec),
        double_difference("candidate RMS", a.candidate_rms_arcsec, b.candidate_rms_arcsec),
        count_difference("has a model", a.has_active, b.has_active),
        count_difference("active version", a.active_version, b.active_version),
        count_difference("active CRC-32C", a.active_crc, b.active_crc),
        count_difference("last refusal", static_cast<unsigned>(a.last_refusal), static_cast<unsigned>(b.last_refusal)),
        count_difference("frozen", a.frozen, b.frozen)};
    if (std::string f = first_of(fields); !f.empty()) {
        return f;
    }
    for (std::size_t i = 1; i < calib::kRefusalKinds; ++i) {
        if (a.refusals[i] != b.refusals[i]) {
            return std::string("refusals '") + calib::refusal_name(static_cast<calib::Refusal>(i)) + "': target " +
                   std::to_string(a.refusals[i]) + ", host " + std::to_string(b.refusals[i]);
        }
    }
    return {};
}

// The same for the Sun learner's report (b: the host's learner); its
// candidate's coefficients by their CRC (what the message carries). Not its
// takes settled late: they count how the target spread the solve over its
// idle time, where the host solves at once (the same bits: SunLearner::settle).
std::string first_sun_report_difference(const link::SunLearnerReport& a, const calib::SunLearnReport& b) {
    if (a.learning != 1U) {
        return "the target's learner does not learn (CALIB_START's sun term not taken)";
    }
    const calib::SunLearnReport& r = a.report;
    const std::string fields[] = {
        count_difference("orbits", r.orbits, b.orbits),
        count_difference("cycles", r.cycles, b.cycles),
        count_difference("cycles without the Sun", r.without_sun, b.without_sun),
        count_difference("cycles not finite", r.not_finite, b.not_finite),
        count_difference("cycles thinned", r.thinned, b.thinned),
        double_difference("score with the polynomial alone", r.score[0], b.score[0]),
        double_difference("score with the candidate", r.score[1], b.score[1]),
        double_difference("gain", r.gain, b.gain),
        double_difference("RMS inside the orbit", r.rms_arcsec, b.rms_arcsec),
        double_difference("orbits held", r.orbits_held, b.orbits_held),
        double_difference("orbits to decide", r.orbits_to_decide, b.orbits_to_decide),
        count_difference("deciding", r.deciding ? 1U : 0U, b.deciding ? 1U : 0U),
        count_difference("taken", r.taken ? 1U : 0U, b.taken ? 1U : 0U),
        count_difference("candidate solved", r.candidate.solved ? 1U : 0U, b.candidate.solved ? 1U : 0U),
        count_difference("candidate heads", r.candidate.heads, b.candidate.heads),
        count_difference("candidate rank", static_cast<std::uint64_t>(r.candidate.rank),
                         static_cast<std::uint64_t>(b.candidate.rank)),
        count_difference("candidate orbits", r.candidate.orbits, b.candidate.orbits),
        count_difference("candidate epochs", r.candidate.epochs, b.candidate.epochs),
        count_difference("candidate CRC-32C", a.candidate_crc, calib::sun_fit_crc(b.candidate))};
    return first_of(fields);
}

// The target's model `version`, head by head (CALIB_MODEL, and with
// learn_sun CALIB_SUN_TERM), as a history entry active from t (the first
// solution corrected with it).
template <typename T>
ActiveModel target_model(LinkClient<T>& client, double t, bool learn_sun) {
    ActiveModel a{t, 0, 0, 0, ModelFile{}};
    for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
        const link::CalibModel m = client.calib_model(h);
        a.t_us = m.active_from_us;
        a.version = m.version;
        a.crc = m.crc;
        a.model.present[h] = m.present == 1U;
        for (std::size_t x = 0; x < kModelAxes; ++x) {
            for (std::size_t i = 0; i < kLinearModelTerms; ++i) {
                a.model.coefficients[h][x][i] = m.c[x][i];
            }
        }
        const link::CalibSunTerm s = learn_sun ? client.calib_sun_term(h) : link::CalibSunTerm{};
        if (learn_sun && s.version != m.version) {
            throw LinkError("the target's Sun term is of model version " + std::to_string(s.version) +
                            ", its model of version " + std::to_string(m.version));
        }
        for (std::size_t x = 0; x < kModelAxes; ++x) {
            for (std::size_t k = 0; k < kSunComponents; ++k) {
                a.model.sun[h][x][k] = s.sun[x][k];
            }
        }
    }
    return a;
}

// The first of head h's Sun term coefficients that differs between a (the
// target's) and b (the host's) model, with both values; empty: none.
std::string first_sun_difference(const ModelFile& a, const ModelFile& b, std::size_t h) {
    for (std::size_t x = 0; x < kModelAxes; ++x) {
        for (std::size_t k = 0; k < kSunComponents; ++k) {
            if (!same_double(a.sun[h][x][k], b.sun[h][x][k])) {
                return std::string("head ") + head_name(static_cast<std::uint8_t>(h)) + " " + kAxisNames[x] + " " +
                       kSunColumns[k] + ": target " + number_text(a.sun[h][x][k]) + ", host " +
                       number_text(b.sun[h][x][k]);
            }
        }
    }
    return {};
}

// What differs first between a (the target's) and b (the host's) model of
// one version: the epoch, a head's presence, a coefficient, its Sun term
// or the CRC; empty when they are the same model, active from the same epoch.
std::string first_model_difference(const ActiveModel& a, const ActiveModel& b) {
    if (a.t_us != b.t_us) {
        return "active from TT " + std::to_string(a.t_us) + " us on the target, " + std::to_string(b.t_us) +
               " us on the host";
    }
    for (std::size_t h = 0; h < kMaxHeads; ++h) {
        const std::string head(1, head_name(static_cast<std::uint8_t>(h)));
        if (a.model.present[h] != b.model.present[h]) {
            return "head " + head + (a.model.present[h] ? " present" : " absent") + " on the target only";
        }
        for (std::size_t x = 0; x < kModelAxes; ++x) {
            for (std::size_t i = 0; i < kModelTerms; ++i) {
                if (!same_double(a.model.coefficients[h][x][i], b.model.coefficients[h][x][i])) {
                    return "head " + head + " " + kAxisNames[x] + " c" + std::to_string(i) + ": target " +
                           number_text(a.model.coefficients[h][x][i]) + ", host " +
                           number_text(b.model.coefficients[h][x][i]);
                }
            }
        }
        if (std::string d = first_sun_difference(a.model, b.model, h); !d.empty()) {
            return d;
        }
    }
    if (a.crc == b.crc) {
        return {};
    }
    char buf[64];
    text::c_snprintf(buf, sizeof buf, "CRC-32C %08x on the target, %08x on the host", a.crc, b.crc);
    return buf;
}

}  // namespace

// A solution's model version on the target against the host's (`want`); a
// version the target uses for the first time is fetched (CALIB_MODEL) and
// compared with the host's model of that version.
template <typename T>
void check_model_version(LinkClient<T>& client, const std::string& file, const SolutionRecord& rec, std::uint32_t got,
                         const std::optional<std::uint32_t>& want, ReplaySummary& sum,
                         std::vector<ActiveModel>& target_history, std::ostream& log, const SelfCalibration& host_sc) {
    const bool same = want ? got == *want : got == link::kNoModelVersion;
    if (!same && ++sum.version_mismatches <= kMaxCalibMessages) {
        log << file << ":" << rec.line << ": the target corrected with model version "
            << (got == link::kNoModelVersion ? std::string("none") : std::to_string(got)) << ", the host with "
            << (want ? std::to_string(*want) : std::string("none")) << "\n";
    }
    if (got == link::kNoModelVersion || (!target_history.empty() && target_history.back().version == got)) {
        return;
    }
    target_history.push_back(target_model(client, rec.t, host_sc.sun_learnt.has_value()));
    ActiveModel& mine = target_history.back();
    mine.model.lag_s = client.lag_s();  // CALIB_START's: CALIB_MODEL carries no lag
    mine.model.lag_s = head_lags(mine.model);
    const auto host = std::find_if(host_sc.history.begin(), host_sc.history.end(),
                                   [&](const ActiveModel& a) { return a.version == mine.version; });
    if (host != host_sc.history.end()) {
        mine.learnt = host->learnt;  // the link does not say; the comparison below checks the coefficients
    }
    const std::string difference =
        host == host_sc.history.end() ? "the host has no such version" : first_model_difference(mine, *host);
    if (!difference.empty()) {
        if (++sum.history_mismatches <= kMaxCalibMessages) {
            char buf[200];
            text::c_snprintf(buf, sizeof buf, "model version %u (crc32c %08x) differs from the host's: ", mine.version,
                             mine.crc);
            log << "ascorr replay: the target's " << buf << difference << "\n";
        }
    }
}

// The target's learner: its report, its candidate's coefficients by their
// CRC, against the host's as of the last epoch (the target's data do not
// end). Its takes settled late are said, not compared: the target spreads
// its solve over cycles, the host solves at once. A target that cannot
// report its learner (a firmware before SUN_LEARNER_REPORT) does not match:
// what it learnt is unknown. Returns the target's report, if any.
template <typename T>
std::optional<calib::SunLearnReport> compare_sun_learner(LinkClient<T>& client, const calib::SunLearnReport& host,
                                                         ReplaySummary& sum, std::ostream& log) {
    const std::optional<link::SunLearnerReport> sun = client.sun_learner_report();
    if (!sun) {
        sum.report_matches = false;
        log << "ascorr replay: the target does not report its Sun learner (firmware before SUN_LEARNER_REPORT): "
               "what it learnt cannot be compared\n";
        return std::nullopt;
    }
    const std::string difference = first_sun_report_difference(*sun, host);
    if (!difference.empty()) {
        sum.report_matches = false;
        log << "ascorr replay: the target's Sun learner report differs from the host's: " << difference << "\n";
    }
    if (sun->report.late > 0U) {
        log << "ascorr replay: the target's Sun learner finished " << sun->report.late
            << " solves in a cycle (idle time had not; at most " << sun->report.late_steps << " steps in one)\n";
    }
    return sun->report;
}

// The end of a self-calibrating replay: the host's models the target never
// used, and the final report.
template <typename T>
void finish_self_calibration(LinkClient<T>& client, ReplaySummary& sum, const std::vector<ActiveModel>& target_history,
                             std::ostream& log, const SelfCalibration& host_sc) {
    sum.models = target_history.size();
    for (const ActiveModel& a : host_sc.history) {
        const bool seen = std::any_of(target_history.begin(), target_history.end(),
                                      [&](const ActiveModel& b) { return b.version == a.version; });
        if (!seen && ++sum.history_mismatches <= kMaxCalibMessages) {
            log << "ascorr replay: the host's model version " << a.version << " was never used by the target\n";
        }
    }
    const calib::EstimatorReport r = client.calib_report();
    const std::string difference = first_report_difference(r, host_sc.report);
    sum.report_matches = difference.empty();
    if (!sum.report_matches) {
        log << "ascorr replay: the target's estimator report differs from the host's: " << difference << "\n";
    }
    SelfCalibration on_target = host_sc;
    on_target.history = target_history;
    on_target.report = r;
    if (host_sc.sun_learnt_at_last_epoch) {
        on_target.sun_learnt = compare_sun_learner(client, *host_sc.sun_learnt_at_last_epoch, sum, log);
    }
    log << "ascorr replay: on the target, " << describe(on_target) << "\n";
}

template void check_model_version(LinkClient<float>&, const std::string&, const SolutionRecord&, std::uint32_t,
                                  const std::optional<std::uint32_t>&, ReplaySummary&, std::vector<ActiveModel>&,
                                  std::ostream&, const SelfCalibration&);
template void check_model_version(LinkClient<Q30>&, const std::string&, const SolutionRecord&, std::uint32_t,
                                  const std::optional<std::uint32_t>&, ReplaySummary&, std::vector<ActiveModel>&,
                                  std::ostream&, const SelfCalibration&);
template void finish_self_calibration(LinkClient<float>&, ReplaySummary&, const std::vector<ActiveModel>&,
                                      std::ostream&, const SelfCalibration&);
template void finish_self_calibration(LinkClient<Q30>&, ReplaySummary&, const std::vector<ActiveModel>&, std::ostream&,
                                      const SelfCalibration&);

}  // namespace ascorr::host::detail
