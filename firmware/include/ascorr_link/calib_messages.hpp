// ascorr_link/calib_messages.hpp: the self-calibration messages of the link
// (protocol v3, CALIB_MODEL v4): their payloads and codecs. The estimator is
// ascorr/calib/estimator.hpp; the server's handling, server.hpp.
// Every decode checks the exact payload length and every enumerated or
// bounded field, and returns false rather than accept what it cannot account
// for.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>

#include "ascorr/calib/estimator.hpp"
#include "ascorr/calib/sun_learner.hpp"
#include "ascorr/core/constants.hpp"
#include "ascorr/core/heads.hpp"
#include "ascorr/core/sun_term.hpp"
#include "ascorr/pipeline/head_lags.hpp"
#include "wire.hpp"

namespace ascorr::link {

// Starts (or restarts from nothing) the estimator: from then on each
// solution is corrected with its active model and heads A, B and C at the
// same time tag feed it (server.hpp). initial = 1: the staged model
// (kCalibModelLoad without `load`) is version 0; 0: no model.
struct CalibStart {
    std::int64_t orbit_period_us;  // within the estimator's limits (calib::kMinOrbitPeriodUs ...)
    double time_constant_days;     // within calib::kMinTimeConstantDays, calib::kMaxTimeConstantDays
    std::uint8_t initial;          // 0 or 1
    // 1: the rule 'combined' for the rotation common to all heads, with the
    // weights of the mountings staged by MOUNTING_LOAD (their heads with
    // sigmas; pipeline/common_rotation_weights.hpp); 0: the estimator's own
    // frame. Absent from the payload when 0 (as a host before it sent it).
    std::uint8_t common_rotation = 0;
    // The bench's lag of each head the estimator learns with (s; 0 none,
    // otherwise in [pipeline::kMinLagTauS, kMaxLagTauS]): the lag stage
    // lags those heads' solutions (pipeline/head_lags.hpp), and the
    // estimator learns from the lagged temperatures. On the wire 4 IEEE
    // binary64 after common_rotation (then always sent), only when a head
    // lags: absent, none (the 17 or 18 bytes a target before it takes).
    double lag_s[kMaxHeads] = {};
    // 1: the Sun term is learnt beside the estimator (calib/sun_learner.hpp,
    // one cycle per kSunLearnOnBoardIntervalUs) and each model version takes
    // the term taken when it becomes active (server.hpp); 0: none. On the
    // wire a u8 after the lags (then always sent, 0 when none lags), only
    // when 1: absent, 0 (the message as a target before it takes it).
    std::uint8_t sun_term = 0;
};

enum class CalibCommand : std::uint8_t {
    kFreeze = 1,
    kResume = 2,
    kReset = 3,
};

// One head's linear model in arcsec, arcsec/°C (the model file's c0..c3 per
// axis α, β, γ; the estimator's models are linear). load = 1: the staged
// model, with this head, becomes the estimator's (load_model: active from
// the next epoch, version + 1); 0: staged only.
struct CalibModelLoad {
    std::uint8_t head;
    std::uint8_t present;  // 0 or 1
    std::uint8_t load;     // 0 or 1
    double c[kModelAxes][kLinearModelTerms];
};

// One head of the estimator's active model (answer to kCalibModelRequest,
// whose payload is the head u8): version and CRC-32C as in the report, the
// time tag of the first epoch it was active in, and the coefficients as in
// kCalibModelLoad. No active model: present 0, version kNoModelVersion, all
// else 0.
struct CalibModel {
    std::uint8_t head;
    std::uint8_t present;  // 0 or 1
    std::uint32_t version;
    std::uint32_t crc;
    std::int64_t active_from_us;
    double c[kModelAxes][kLinearModelTerms];
};

// One head's Sun term of the estimator's active model version (answer to
// kCalibSunTermRequest, whose payload is the head u8): the version (as in
// CalibModel; none: kNoModelVersion) and its term for the head in arcsec
// (the model file's sun_x, sun_y, sun_z per axis α, β, γ), the one the
// version took when it became active (CalibStart::sun_term; none: 0). Its
// own message: with CALIB_MODEL's coefficients it would not fit a frame.
struct CalibSunTerm {
    std::uint8_t head;
    std::uint32_t version;
    double sun[kModelAxes][kSunComponents];
};

// The Sun term learner's state (answer to kSunLearnerReportRequest, no
// payload): whether it learns (CalibStart::sun_term), its report
// (calib/sun_learner.hpp; the candidate's coefficients, 27 doubles, do not
// fit a frame: report.candidate.sun stays 0 on decode, and candidate_crc,
// calib::sun_fit_crc of them, identifies them). Not learning: a report of
// zeros. 118 bytes.
struct SunLearnerReport {
    std::uint8_t learning;
    calib::SunLearnReport report;
    std::uint32_t candidate_crc;
};

// The largest coefficient a model may have (arcsec or arcsec/°C): the Q30
// coefficient format's range, 2⁻⁵ rad (ScalarTraits<Q30>::max_coefficient).
inline constexpr double kMaxLoadCoefficient = 0x1p-5 * kRadToArcsec;

// ---- codecs (encode returns the payload size; buffers of kMaxPayload suffice)
inline std::size_t encode(const CalibStart& m, std::uint8_t* out) noexcept {
    Writer w(out);
    w.u64(static_cast<std::uint64_t>(m.orbit_period_us));
    w.f64(m.time_constant_days);
    w.u8(m.initial);
    // Each optional field is sent when it or a later one is not 0: absent,
    // a target before it takes the message as it was.
    const bool learns_sun = m.sun_term != 0U;
    const bool lags = pipeline::any_lagged(m.lag_s) || learns_sun;
    if (m.common_rotation != 0U || lags) {
        w.u8(m.common_rotation);
    }
    for (std::size_t h = 0; lags && h < kMaxHeads; ++h) {
        w.f64(m.lag_s[h]);
    }
    if (learns_sun) {
        w.u8(m.sun_term);
    }
    return w.size();
}
// CALIB_START's optional tail: common_rotation, the lags, sun_term (above).
// Refused: a τ neither 0 nor in the lag's range (NaN included).
inline bool decode_calib_start_tail(Reader& r, CalibStart& m) noexcept {
    if (r.done()) {
        return true;
    }
    if (!r.u8(m.common_rotation)) {
        return false;
    }
    if (r.done()) {
        return true;
    }
    bool ok = true;
    for (double& tau : m.lag_s) {
        ok = ok && r.f64(tau) && (tau == 0.0 || (tau >= pipeline::kMinLagTauS && tau <= pipeline::kMaxLagTauS));
    }
    if (ok && !r.done()) {
        ok = r.u8(m.sun_term);
    }
    return ok && r.done();
}
inline bool decode(const std::uint8_t* p, std::size_t n, CalibStart& m) noexcept {
    Reader r(p, n);
    m.common_rotation = 0U;
    m.sun_term = 0U;
    for (double& tau : m.lag_s) {
        tau = 0.0;
    }
    return r.i64(m.orbit_period_us) && r.f64(m.time_constant_days) && r.u8(m.initial) &&
           decode_calib_start_tail(r, m) && calib::configuration_acceptable(m.orbit_period_us, m.time_constant_days) &&
           m.initial <= 1U && m.common_rotation <= 1U && m.sun_term <= 1U;
}

inline std::size_t encode(CalibCommand m, std::uint8_t* out) noexcept {
    out[0] = static_cast<std::uint8_t>(m);
    return 1;
}
inline bool decode(const std::uint8_t* p, std::size_t n, CalibCommand& m) noexcept {
    if (n != 1U || p[0] < 1U || p[0] > 3U) {
        return false;
    }
    m = static_cast<CalibCommand>(p[0]);
    return true;
}

inline std::size_t encode(const CalibModelLoad& m, std::uint8_t* out) noexcept {
    Writer w(out);
    w.u8(m.head);
    w.u8(m.present);
    w.u8(m.load);
    put_linear(w, m.c);
    return w.size();
}
// Refused: a head beyond D, a flag other than 0 or 1, a coefficient not
// finite or beyond kMaxLoadCoefficient.
inline bool decode(const std::uint8_t* p, std::size_t n, CalibModelLoad& m) noexcept {
    Reader r(p, n);
    if (!(r.u8(m.head) && r.u8(m.present) && r.u8(m.load)) || m.head >= kMaxHeads || m.present > 1U || m.load > 1U) {
        return false;
    }
    return get_linear(r, m.c, [](double x) { return std::fabs(x) < kMaxLoadCoefficient; }) &&  // false for NaN
           r.done();
}

inline std::size_t encode(const calib::EstimatorReport& m, std::uint8_t* out) noexcept {
    Writer w(out);
    w.u32(m.orbits_used);
    w.u32(m.orbits_short);
    w.u32(m.orbits_held);
    w.u32(m.orbits_late);
    w.u32(m.changes);
    w.f64(m.condition);
    w.f64(m.residual_rms_arcsec);
    w.f64(m.candidate_rms_arcsec);
    w.u8(m.has_active ? 1U : 0U);
    w.u32(m.active_version);
    w.u32(m.active_crc);
    w.u8(static_cast<std::uint8_t>(m.last_refusal));
    for (std::size_t i = 1; i < calib::kRefusalKinds; ++i) {
        w.u32(m.refusals[i]);
    }
    w.u8(m.frozen ? 1U : 0U);
    return w.size();
}
inline bool decode(const std::uint8_t* p, std::size_t n, calib::EstimatorReport& m) noexcept {
    Reader r(p, n);
    std::uint8_t has = 0;
    std::uint8_t refusal = 0;
    std::uint8_t frozen = 0;
    bool ok = r.u32(m.orbits_used) && r.u32(m.orbits_short) && r.u32(m.orbits_held) && r.u32(m.orbits_late) &&
              r.u32(m.changes) && r.f64(m.condition) && r.f64(m.residual_rms_arcsec) && r.f64(m.candidate_rms_arcsec) &&
              r.u8(has) && r.u32(m.active_version) && r.u32(m.active_crc) && r.u8(refusal);
    m.refusals[0] = 0U;
    for (std::size_t i = 1; ok && i < calib::kRefusalKinds; ++i) {
        ok = r.u32(m.refusals[i]);
    }
    ok = ok && r.u8(frozen) && r.done() && has <= 1U && frozen <= 1U && refusal < calib::kRefusalKinds;
    m.has_active = has == 1U;
    m.frozen = frozen == 1U;
    m.last_refusal = static_cast<calib::Refusal>(refusal < calib::kRefusalKinds ? refusal : 0U);
    return ok;
}

inline std::size_t encode(const CalibModel& m, std::uint8_t* out) noexcept {
    Writer w(out);
    w.u8(m.head);
    w.u8(m.present);
    w.u32(m.version);
    w.u32(m.crc);
    w.u64(static_cast<std::uint64_t>(m.active_from_us));
    put_linear(w, m.c);
    return w.size();
}
// The host reads what the target holds: any finite or non-finite value
// decodes (a comparison, not a use, follows).
inline bool decode(const std::uint8_t* p, std::size_t n, CalibModel& m) noexcept {
    Reader r(p, n);
    return r.u8(m.head) && r.u8(m.present) && r.u32(m.version) && r.u32(m.crc) && r.i64(m.active_from_us) &&
           m.head < kMaxHeads && m.present <= 1U && get_linear(r, m.c, [](double) { return true; }) && r.done();
}

inline std::size_t encode(const CalibSunTerm& m, std::uint8_t* out) noexcept {
    Writer w(out);
    w.u8(m.head);
    w.u32(m.version);
    for (const auto& axis : m.sun) {
        for (const double c : axis) {
            w.f64(c);
        }
    }
    return w.size();
}
// As CalibModel's: any value decodes (the host compares it).
inline bool decode(const std::uint8_t* p, std::size_t n, CalibSunTerm& m) noexcept {
    Reader r(p, n);
    bool ok = r.u8(m.head) && r.u32(m.version) && m.head < kMaxHeads;
    for (auto& axis : m.sun) {
        for (double& c : axis) {
            ok = ok && r.f64(c);
        }
    }
    return ok && r.done();
}

// learning, then the report's counts, flags and doubles, then the candidate
// (its CRC for its coefficients).
inline std::size_t encode(const SunLearnerReport& m, std::uint8_t* out) noexcept {
    const calib::SunLearnReport& r = m.report;
    Writer w(out);
    w.u8(m.learning);
    w.u8(r.deciding ? 1U : 0U);
    w.u8(r.taken ? 1U : 0U);
    w.u32(r.orbits);
    w.u64(r.cycles);
    w.u64(r.without_sun);
    w.u64(r.not_finite);
    w.u64(r.thinned);
    w.u64(r.late);
    w.u32(static_cast<std::uint32_t>(r.late_steps));
    for (const double d : {r.score[0], r.score[1], r.gain, r.rms_arcsec, r.orbits_held, r.orbits_to_decide}) {
        w.f64(d);
    }
    w.u8(r.candidate.solved ? 1U : 0U);
    w.u8(r.candidate.heads);
    w.u8(static_cast<std::uint8_t>(r.candidate.rank));
    w.u32(r.candidate.orbits);
    w.u64(r.candidate.epochs);
    w.u32(m.candidate_crc);
    return w.size();
}
// As CalibModel's: any value decodes (the host compares it); flags are 0 or
// 1, a rank at most the fit's unknowns.
inline bool decode(const std::uint8_t* p, std::size_t n, SunLearnerReport& m) noexcept {
    calib::SunLearnReport& r = m.report;
    r = calib::SunLearnReport{};
    Reader rd(p, n);
    std::uint8_t flags[4] = {};
    std::uint8_t rank = 0U;
    std::uint32_t late_steps = 0U;
    bool ok = rd.u8(m.learning) && rd.u8(flags[0]) && rd.u8(flags[1]) && rd.u32(r.orbits) && rd.u64(r.cycles) &&
              rd.u64(r.without_sun) && rd.u64(r.not_finite) && rd.u64(r.thinned) && rd.u64(r.late) &&
              rd.u32(late_steps);
    for (double* d : {&r.score[0], &r.score[1], &r.gain, &r.rms_arcsec, &r.orbits_held, &r.orbits_to_decide}) {
        ok = ok && rd.f64(*d);
    }
    ok = ok && rd.u8(flags[2]) && rd.u8(r.candidate.heads) && rd.u8(rank) && rd.u32(r.candidate.orbits) &&
         rd.u64(r.candidate.epochs) && rd.u32(m.candidate_crc) && rd.done();
    r.deciding = flags[0] == 1U;
    r.taken = flags[1] == 1U;
    r.candidate.solved = flags[2] == 1U;
    r.candidate.rank = rank;
    r.late_steps = static_cast<int>(late_steps & 0x7FFFFFFFU);
    return ok && m.learning <= 1U && flags[0] <= 1U && flags[1] <= 1U && flags[2] <= 1U &&
           rank <= calib::SunMoments<calib::kFrameHeads>::kUnknowns && late_steps <= 0x7FFFFFFFU;
}

}  // namespace ascorr::link
