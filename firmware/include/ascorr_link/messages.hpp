// ascorr_link/messages.hpp: the messages of the host–DPU link.
//
// Payload layouts are little-endian; a "word" is one scalar of the target's
// type in its 32-bit wire form (wire.hpp), so host and target exchange
// exactly the values the core computes with. The host converts with the same
// ScalarTraits as its own core in that type, which is why a replayed solution
// can be compared bit for bit with the host core. The self-calibration
// messages are in calib_messages.hpp, the combined attitude's in
// combine_messages.hpp (both included here).
// Every decode_* checks the exact payload length and every enumerated field,
// and returns false rather than accept a frame it cannot fully account for.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <initializer_list>

#include "ascorr/core/correct.hpp"
#include "ascorr/core/fixed_point.hpp"
#include "ascorr/core/sun_term.hpp"
#include "ascorr/nav/velocity_service.hpp"
#include "ascorr/pipeline/temperature_lag.hpp"
#include "calib_messages.hpp"
#include "combine_messages.hpp"
#include "frame.hpp"
#include "wire.hpp"

namespace ascorr::link {

enum class MessageType : std::uint8_t {
    kHello = 1,                 // target → host: boot id, protocol, scalar kind
    kModelUpload = 2,           // host → target: one head's thermal model
    kVelocityUpdate = 3,        // host → target: observer velocity (v/c) and 1/s
    kTemperatureUpdate = 4,     // host → target: one head's temperatures with validity
    kSolutionIn = 5,            // host → target: a raw attitude solution
    kSolutionOut = 6,           // target → host: the corrected solution, status, cost
    kAck = 7,                   // target → host: a request without data reply was applied (or why not)
    kHelloRequest = 8,          // host → target: answer with kHello
    kNak = 9,                   // target → host: a frame arrived broken; resend
    kStateUpdate = 10,          // host → target: a spacecraft state for the velocity service (v2)
    kCalibStart = 11,           // host → target: run the estimator on the solutions, its configuration (v3)
    kCalibCommand = 12,         // host → target: freeze, resume or reset the estimator (v3)
    kCalibModelLoad = 13,       // host → target: one head of a model for the estimator, staged or loaded (v3)
    kCalibReportRequest = 14,   // host → target: answer with kCalibReport (v3)
    kCalibReport = 15,          // target → host: the estimator's state (v3)
    kCalibModelRequest = 16,    // host → target: answer with kCalibModel for a head (v4)
    kCalibModel = 17,           // target → host: one head of the estimator's active model (v4)
    kServiceConfig = 18,        // host → target: the velocity service's horizon (v4)
    kMountingLoad = 19,         // host → target: one head's mounting and noise, staged or built (v5)
    kCombineRequest = 20,       // host → target: combine the solutions since the last request (v5)
    kCombined = 21,             // target → host: the combined attitude of the bench (v5)
    kSunTermUpload = 22,        // host → target: one head's Sun term (docs/contract.md, "The Sun term on the link")
    kCalibSunTermRequest = 23,  // host → target: answer with kCalibSunTerm for a head
    kCalibSunTerm = 24,         // target → host: one head's Sun term of the active model version
    kSunLearnerReportRequest = 25,  // host → target: answer with kSunLearnerReport
    kSunLearnerReport = 26,         // target → host: the Sun term learner's state
    kStackReportRequest = 27,       // host → target: answer with kStackReport
    kStackReport = 28,              // target → host: the image's stack high-water mark
};

enum class AckResult : std::uint8_t {
    kOk = 0,
    kUnknownType = 1,  // a message type the target does not take
    kBadPayload = 2,   // wrong length or an out-of-range field
};

// A head's coefficients on the link: alpha, beta, gamma × the terms of
// kModelTermTable (core/model_terms.hpp), in its order, each a word of its
// term's format.
inline constexpr std::size_t kCoefficientsPerHead = std::size_t{kModelAxes} * kModelTerms;

struct Hello {
    std::uint32_t boot_id;  // changes at every target start: the host re-uploads state when it does
    std::uint8_t protocol;
    std::uint8_t scalar_kind;
};

// lag_s: the head's lag τ in seconds (docs/contract.md, "The bench's lag";
// pipeline/head_lags.hpp), 0 for none. On the wire an IEEE binary64 after
// the words, sent only when the head lags (absent: 0, the bytes a target
// before it takes); a τ outside [kMinLagTauS, kMaxLagTauS] is a bad payload.
template <typename T>
struct ModelUpload {
    std::uint8_t head;
    HeadThermalModel<T> model;
    double lag_s = 0.0;
};

// One head's Sun term (core/sun_term.hpp): S[a][c], rad per unit of ŝ_chu's
// component c, for the axes alpha, beta, gamma, as 9 words after the head.
// All 0: the head has no term. A word that is not finite, or an axis whose
// |S| row sum passes the core's domain (kMaxThermalAngleRad, with room for
// the words' rounding to T), is a bad payload: the Q30 kernel's range needs it.
template <typename T>
struct SunTermUpload {
    std::uint8_t head;
    T coefficient[kModelAxes][kSunComponents];
};

template <typename T>
struct SolutionIn {
    std::uint32_t id;
    std::uint8_t head;
    Quaternion<T> q_chu_icrf;
    TtTime t;                  // the solution's time tag (v2)
    std::uint8_t from_states;  // 1: velocity from the target's service at t; 0: the last VELOCITY_UPDATE
    std::uint8_t calib;        // kCalibClean | kCalibNoTime, or 0 (v4; used while the estimator runs)
};

// SolutionIn::calib. kCalibClean: the solution passes its source's
// selection (flags 1, 2, 4 clear, confidence ≤ 5: what the camera head says
// of itself), so it may feed the estimator. kCalibNoTime: its time tag is not
// one the on-board clock holds (t is then 0): it belongs to no epoch and is
// corrected without a model (status 256) while the estimator runs.
inline constexpr std::uint8_t kCalibClean = 1U;
inline constexpr std::uint8_t kCalibNoTime = 2U;

// A spacecraft state (velocity_service.hpp): TT µs, ITRF (0) or GCRS (1),
// position km, velocity km/s, as IEEE binary64 on the wire (the service's
// double part computes with them; the answers stay bit-comparable).
struct StateUpdate {
    TtTime t;
    std::uint8_t reference_frame;  // StateFrame: 0 itrf, 1 gcrs
    Vector3<double> r_km;
    Vector3<double> v_kms;
};

template <typename T>
struct SolutionOut {
    std::uint32_t id;
    std::uint8_t head;
    StatusBits status;
    Quaternion<T> q_chu_icrf;
    std::uint32_t instructions;   // cost of correct_solution on the target
    std::uint32_t model_version;  // the estimator's model used (v4); kNoModelVersion: none, or not running
};

inline constexpr std::uint32_t kNoModelVersion = 0xFFFFFFFFU;

struct Ack {
    std::uint16_t seq;  // the request's sequence number
    AckResult result;
};

// The velocity service's configuration the host may set (kServiceConfig):
// the propagation horizon, (0, kMaxHorizonUs] (velocity_service.hpp).
// Applying it restarts the service (its states are dropped: send it before
// the states).
struct ServiceConfig {
    std::int64_t horizon_us;
};

// The image's stack (answer to kStackReportRequest, no payload): the most
// bytes it has used since boot and its size (firmware/app/stack_watch.hpp);
// 0 and 0 where the server does not measure it (a host's in-process one).
struct StackReport {
    std::uint32_t high_water;
    std::uint32_t size;
};

// ---- messages (encode returns the payload size; buffers of kMaxPayload suffice)
inline std::size_t encode(const Hello& m, std::uint8_t* out) noexcept {
    Writer w(out);
    w.u32(m.boot_id);
    w.u8(m.protocol);
    w.u8(m.scalar_kind);
    return w.size();
}
inline bool decode(const std::uint8_t* p, std::size_t n, Hello& m) noexcept {
    Reader r(p, n);
    return r.u32(m.boot_id) && r.u8(m.protocol) && r.u8(m.scalar_kind) && r.done();
}

template <typename T>
std::size_t encode(const ModelUpload<T>& m, std::uint8_t* out) noexcept {
    Writer w(out);
    w.u8(m.head);
    w.u8(m.model.present ? 1U : 0U);
    for (const AxisPolynomial<T>* a : {&m.model.alpha, &m.model.beta, &m.model.gamma}) {
        for_each_term(*a, [&w](auto, const auto& c) { w.word(c); });
    }
    if (m.lag_s != 0.0) {
        w.f64(m.lag_s);
    }
    return w.size();
}
template <typename T>
bool decode(const std::uint8_t* p, std::size_t n, ModelUpload<T>& m) noexcept {
    Reader r(p, n);
    std::uint8_t present = 0;
    if (!(r.u8(m.head) && r.u8(present)) || m.head >= kMaxHeads || present > 1U) {
        return false;
    }
    m.model.present = present == 1U;
    bool ok = true;
    for (AxisPolynomial<T>* a : {&m.model.alpha, &m.model.beta, &m.model.gamma}) {
        for_each_term(*a, [&](auto, auto& c) { ok = ok && r.word(c); });
    }
    m.lag_s = 0.0;
    if (!ok || r.done()) {
        return ok;
    }
    return r.f64(m.lag_s) && r.done() && m.lag_s >= pipeline::kMinLagTauS && m.lag_s <= pipeline::kMaxLagTauS;
}

template <typename T>
std::size_t encode(const SunTermUpload<T>& m, std::uint8_t* out) noexcept {
    Writer w(out);
    w.u8(m.head);
    for (const auto& axis : m.coefficient) {
        for (const T& c : axis) {
            w.word(c);
        }
    }
    return w.size();
}
// Whether an axis' |S| row sum is within the core's domain; the bound has
// room for three words each rounded to T from a sum at the domain's edge
// (a relative 2⁻²⁰ ≫ float's 3·2⁻²⁴ and Q30's 1.5 LSB at 1°).
template <typename T>
bool sun_row_in_domain(const T (&row)[kSunComponents]) noexcept {
    double sum = 0.0;
    for (const T& c : row) {
        const double x = ScalarTraits<T>::to_double(c);
        if (!std::isfinite(x)) {
            return false;
        }
        sum += std::fabs(x);
    }
    return sum <= kMaxThermalAngleRad * (1.0 + 0x1p-20);
}
template <typename T>
bool decode(const std::uint8_t* p, std::size_t n, SunTermUpload<T>& m) noexcept {
    Reader r(p, n);
    bool ok = r.u8(m.head) && m.head < kMaxHeads;
    for (auto& axis : m.coefficient) {
        for (T& c : axis) {
            ok = ok && r.word(c);
        }
        ok = ok && sun_row_in_domain(axis);
    }
    return ok && r.done();
}

template <typename T>
std::size_t encode(const ObserverVelocity<T>& m, std::uint8_t* out) noexcept {
    Writer w(out);
    w.u8(m.valid ? 1U : 0U);
    w.word(m.beta_icrf.x);
    w.word(m.beta_icrf.y);
    w.word(m.beta_icrf.z);
    w.word(m.inv_sun_distance_au);
    return w.size();
}
template <typename T>
bool decode(const std::uint8_t* p, std::size_t n, ObserverVelocity<T>& m) noexcept {
    Reader r(p, n);
    std::uint8_t valid = 0;
    const bool ok = r.u8(valid) && r.word(m.beta_icrf.x) && r.word(m.beta_icrf.y) && r.word(m.beta_icrf.z) &&
                    r.word(m.inv_sun_distance_au) && r.done() && valid <= 1U;
    m.valid = valid == 1U;
    return ok;
}

template <typename T>
struct TemperatureUpdate {
    std::uint8_t head;
    HeadTemperatures<T> temperatures;
};

template <typename T>
std::size_t encode(const TemperatureUpdate<T>& m, std::uint8_t* out) noexcept {
    Writer w(out);
    w.u8(m.head);
    const auto& t = m.temperatures;
    w.u8(static_cast<std::uint8_t>((t.t_chu.valid ? 1U : 0U) | (t.t_029.valid ? 2U : 0U) | (t.t_032.valid ? 4U : 0U)));
    w.word(t.t_chu.value);
    w.word(t.t_029.value);
    w.word(t.t_032.value);
    return w.size();
}
template <typename T>
bool decode(const std::uint8_t* p, std::size_t n, TemperatureUpdate<T>& m) noexcept {
    Reader r(p, n);
    std::uint8_t mask = 0;
    auto& t = m.temperatures;
    if (!(r.u8(m.head) && r.u8(mask) && r.word(t.t_chu.value) && r.word(t.t_029.value) && r.word(t.t_032.value) &&
          r.done()) ||
        m.head >= kMaxHeads || mask > 7U) {
        return false;
    }
    t.t_chu.valid = (mask & 1U) != 0U;
    t.t_029.valid = (mask & 2U) != 0U;
    t.t_032.valid = (mask & 4U) != 0U;
    return true;
}

template <typename T>
std::size_t encode(const SolutionIn<T>& m, std::uint8_t* out) noexcept {
    Writer w(out);
    w.u32(m.id);
    w.u8(m.head);
    w.u64(static_cast<std::uint64_t>(m.t.us));
    w.u8(m.from_states);
    w.u8(m.calib);
    w.word(m.q_chu_icrf.w);
    w.word(m.q_chu_icrf.x);
    w.word(m.q_chu_icrf.y);
    w.word(m.q_chu_icrf.z);
    return w.size();
}
// The head is not range-checked here: the core rejects a bad head with
// status kRejected, which is the answer the host must see.
template <typename T>
bool decode(const std::uint8_t* p, std::size_t n, SolutionIn<T>& m) noexcept {
    Reader r(p, n);
    return r.u32(m.id) && r.u8(m.head) && r.i64(m.t.us) && r.u8(m.from_states) && m.from_states <= 1U &&
           r.u8(m.calib) && (m.calib & ~(kCalibClean | kCalibNoTime)) == 0U &&
           ((m.calib & kCalibNoTime) == 0U || (m.t.us == 0 && m.from_states == 0U)) && r.word(m.q_chu_icrf.w) &&
           r.word(m.q_chu_icrf.x) && r.word(m.q_chu_icrf.y) && r.word(m.q_chu_icrf.z) && r.done();
}

inline std::size_t encode(const StateUpdate& m, std::uint8_t* out) noexcept {
    Writer w(out);
    w.u64(static_cast<std::uint64_t>(m.t.us));
    w.u8(m.reference_frame);
    for (const double x : {m.r_km.x, m.r_km.y, m.r_km.z, m.v_kms.x, m.v_kms.y, m.v_kms.z}) {
        w.f64(x);
    }
    return w.size();
}
// Non-finite or implausible values decode: the service refuses them (and counts).
inline bool decode(const std::uint8_t* p, std::size_t n, StateUpdate& m) noexcept {
    Reader r(p, n);
    return r.i64(m.t.us) && r.u8(m.reference_frame) && m.reference_frame <= 1U && r.f64(m.r_km.x) && r.f64(m.r_km.y) &&
           r.f64(m.r_km.z) && r.f64(m.v_kms.x) && r.f64(m.v_kms.y) && r.f64(m.v_kms.z) && r.done();
}

template <typename T>
std::size_t encode(const SolutionOut<T>& m, std::uint8_t* out) noexcept {
    Writer w(out);
    w.u32(m.id);
    w.u8(m.head);
    w.u16(m.status);
    w.word(m.q_chu_icrf.w);
    w.word(m.q_chu_icrf.x);
    w.word(m.q_chu_icrf.y);
    w.word(m.q_chu_icrf.z);
    w.u32(m.instructions);
    w.u32(m.model_version);
    return w.size();
}
template <typename T>
bool decode(const std::uint8_t* p, std::size_t n, SolutionOut<T>& m) noexcept {
    Reader r(p, n);
    return r.u32(m.id) && r.u8(m.head) && r.u16(m.status) && r.word(m.q_chu_icrf.w) && r.word(m.q_chu_icrf.x) &&
           r.word(m.q_chu_icrf.y) && r.word(m.q_chu_icrf.z) && r.u32(m.instructions) && r.u32(m.model_version) &&
           r.done();
}

inline std::size_t encode(const StackReport& m, std::uint8_t* out) noexcept {
    Writer w(out);
    w.u32(m.high_water);
    w.u32(m.size);
    return w.size();
}
inline bool decode(const std::uint8_t* p, std::size_t n, StackReport& m) noexcept {
    Reader r(p, n);
    return r.u32(m.high_water) && r.u32(m.size) && r.done();
}

inline std::size_t encode(const Ack& m, std::uint8_t* out) noexcept {
    Writer w(out);
    w.u16(m.seq);
    w.u8(static_cast<std::uint8_t>(m.result));
    return w.size();
}
inline bool decode(const std::uint8_t* p, std::size_t n, Ack& m) noexcept {
    Reader r(p, n);
    std::uint8_t result = 0;
    const bool ok = r.u16(m.seq) && r.u8(result) && r.done() && result <= 2U;
    m.result = static_cast<AckResult>(result);
    return ok;
}

inline std::size_t encode(const ServiceConfig& m, std::uint8_t* out) noexcept {
    Writer w(out);
    w.u64(static_cast<std::uint64_t>(m.horizon_us));
    return w.size();
}
inline bool decode(const std::uint8_t* p, std::size_t n, ServiceConfig& m) noexcept {
    Reader r(p, n);
    return r.i64(m.horizon_us) && r.done() && m.horizon_us > 0 && m.horizon_us <= kMaxHorizonUs;
}

}  // namespace ascorr::link
