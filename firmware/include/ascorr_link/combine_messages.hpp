// ascorr_link/combine_messages.hpp: the combined attitude's messages of the
// link (protocol v5): their payloads and codecs. The combination is
// ascorr/combine/combiner.hpp, a stage of the epoch pipeline
// (ascorr/pipeline/epoch_pipeline.hpp); the server's handling, server.hpp.
// Every decode checks the exact payload length and every enumerated or
// bounded field, and returns false rather than accept what it cannot account
// for.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>

#include "ascorr/combine/combined_status.hpp"
#include "ascorr/combine/combiner.hpp"
#include "ascorr/combine/mountings.hpp"
#include "ascorr/core/heads.hpp"
#include "wire.hpp"

namespace ascorr::link {

// One head's mounting and noise (the mountings file's row, IEEE binary64),
// staged on the target. build = 1: the staged mountings, with this head,
// become the combiner's (its tables built in double on the target, as on the
// host), with the consistency gate `gate`, refused with kBadPayload and
// nothing changed when they are not usable (combine::check_mountings). The
// gate (two more binary64, k and the floor) is sent only in a build frame and
// only when it is not CombinerConfig{}'s: a target before it takes the
// 51-byte message as it was.
struct MountingLoad {
    std::uint8_t head;
    std::uint8_t present;  // 0 or 1
    std::uint8_t build;    // 0 or 1
    Quaternion<double> q_chu_crf;
    double sigma_cross_arcsec;
    double sigma_about_arcsec;
    combine::CombinerConfig gate;  // with build 1
};

// Answer to kCombineRequest (empty payload): the solutions the target
// corrected since the previous request, combined (epoch_pipeline.hpp's
// close()); without mountings built, status 8 and the identity.
template <typename T>
struct Combined {
    combine::CombinedStatus status;
    HeadMask used;
    HeadMask left_out;
    HeadMask inconsistent;
    Quaternion<T> q_crf_icrf;
    std::uint32_t instructions;  // cost of the combination on the target
};

// ---- codecs (encode returns the payload size; buffers of kMaxPayload suffice)
inline std::size_t encode(const MountingLoad& m, std::uint8_t* out) noexcept {
    Writer w(out);
    w.u8(m.head);
    w.u8(m.present);
    w.u8(m.build);
    for (const double x :
         {m.q_chu_crf.w, m.q_chu_crf.x, m.q_chu_crf.y, m.q_chu_crf.z, m.sigma_cross_arcsec, m.sigma_about_arcsec}) {
        w.f64(x);
    }
    const combine::CombinerConfig usual{};
    if (m.build == 1U &&
        (m.gate.gate_sigmas != usual.gate_sigmas || m.gate.gate_floor_arcsec != usual.gate_floor_arcsec)) {
        w.f64(m.gate.gate_sigmas);
        w.f64(m.gate.gate_floor_arcsec);
    }
    return w.size();
}
// Refused: a head beyond the last, a flag other than 0 or 1, a value that is
// not finite (what the combiner checks of the set, at build), a gate outside
// its range or in a frame that builds nothing.
inline bool decode(const std::uint8_t* p, std::size_t n, MountingLoad& m) noexcept {
    Reader r(p, n);
    if (!(r.u8(m.head) && r.u8(m.present) && r.u8(m.build)) || m.head >= kMaxHeads || m.present > 1U || m.build > 1U) {
        return false;
    }
    double* const fields[] = {&m.q_chu_crf.w, &m.q_chu_crf.x,        &m.q_chu_crf.y,
                              &m.q_chu_crf.z, &m.sigma_cross_arcsec, &m.sigma_about_arcsec};
    for (double* x : fields) {
        if (!r.f64(*x) || !std::isfinite(*x)) {
            return false;
        }
    }
    m.gate = combine::CombinerConfig{};
    if (r.done()) {
        return true;
    }
    return m.build == 1U && r.f64(m.gate.gate_sigmas) && r.f64(m.gate.gate_floor_arcsec) && r.done() &&
           combine::gate_config_valid(m.gate);
}

template <typename T>
std::size_t encode(const Combined<T>& m, std::uint8_t* out) noexcept {
    Writer w(out);
    w.u8(m.status);
    w.u8(m.used);
    w.u8(m.left_out);
    w.u8(m.inconsistent);
    w.word(m.q_crf_icrf.w);
    w.word(m.q_crf_icrf.x);
    w.word(m.q_crf_icrf.y);
    w.word(m.q_crf_icrf.z);
    w.u32(m.instructions);
    return w.size();
}
// Refused: a status that breaks the rule of combined_status.hpp, a head mask
// beyond the heads.
template <typename T>
bool decode(const std::uint8_t* p, std::size_t n, Combined<T>& m) noexcept {
    Reader r(p, n);
    constexpr unsigned kAllHeads = (1U << kMaxHeads) - 1U;
    return r.u8(m.status) && r.u8(m.used) && r.u8(m.left_out) && r.u8(m.inconsistent) && r.word(m.q_crf_icrf.w) &&
           r.word(m.q_crf_icrf.x) && r.word(m.q_crf_icrf.y) && r.word(m.q_crf_icrf.z) && r.u32(m.instructions) &&
           r.done() && combine::combined_status::status_consistent(m.status) && (m.used & ~kAllHeads) == 0U &&
           (m.left_out & ~kAllHeads) == 0U && (m.inconsistent & ~kAllHeads) == 0U;
}

}  // namespace ascorr::link
