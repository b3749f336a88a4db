// firmware/app/cycle_log.hpp: what the flight loop reports of its solutions
// and of the estimator's models (flight_cycle.hpp runs the cycle), the same
// text on the DPU and the host (report.hpp: integers and hex only).
//
// CorrectionLog: per head, the cycles with both corrections applied, every
// status bit seen, the last corrected solution, and a CRC-32C (crc32c.hpp)
// over every cycle's corrected solution (the four components' bit patterns,
// then the status; little-endian); and every head's solution at each
// kSampleEvery-th cycle (the first kMaxSamples of them). Printed with
// report.hpp (integers and hex only), the same text on the DPU and the host.
// ModelHistory: the models the estimator made active, in turn.
#pragma once

#include <cstdint>
#include <cstring>

#include "app_scalar.hpp"
#include "ascorr/calib/estimator.hpp"
#include "ascorr/calib/sun_learner.hpp"
#include "ascorr/core/correct.hpp"
#include "ascorr/core/status.hpp"
#include "ascorr_link/crc32c.hpp"
#include "report.hpp"

namespace ascorr::app {

inline std::uint32_t bits_of(Q30 x) noexcept {
    return static_cast<std::uint32_t>(x.raw);
}
inline std::uint32_t bits_of(float x) noexcept {
    std::uint32_t u = 0U;
    std::memcpy(&u, &x, sizeof u);
    return u;
}

class CorrectionLog {
public:
    static constexpr std::uint32_t kSampleEvery = 16U;
    static constexpr std::uint32_t kMaxSamples = 32U;
    // Records: one per head, then the cycle's combined attitude (kCombined).
    static constexpr std::uint8_t kCombined = kMaxHeads;
    static constexpr std::uint8_t kRecords = kMaxHeads + 1U;

    // Head `head`'s corrected solution of cycle `cycle` (cycles in order from 0).
    void add(std::uint32_t cycle, std::uint8_t head, const CorrectedSolution<Scalar>& c) noexcept {
        if (head < kMaxHeads) {
            add_record(cycle, head, c, c.status == (status::kAberrationApplied | status::kThermalApplied));
        }
    }

    // The cycle's combined attitude, as a record whose status is the
    // combined status with the heads used in bits 8..8+kMaxHeads−1, and
    // "applied" when two or more heads were averaged.
    void add_combined(std::uint32_t cycle, const combine::CombinedAttitude<Scalar>& a) noexcept {
        const auto st = static_cast<StatusBits>(a.status | (static_cast<unsigned>(a.used) << 8U));
        add_record(cycle, kCombined, {a.q_crf_icrf, st}, (a.status & combine::combined_status::kTwoOrMoreHeads) != 0U);
    }

    struct Head {
        std::uint32_t applied;    // cycles with both corrections applied (combined: two or more heads)
        StatusBits status_union;  // every status bit seen
        std::uint32_t solutions;  // cycles recorded
        std::uint32_t crc;        // CRC-32C over every cycle's solution and status
        CorrectedSolution<Scalar> last;
    };
    const Head& head(std::uint8_t h) const noexcept { return heads_[h < kRecords ? h : 0U]; }
    std::uint32_t samples_taken() const noexcept { return samples_taken_; }
    // Record h's solution of cycle i·kSampleEvery, i < samples_taken().
    const CorrectedSolution<Scalar>& sample(std::uint32_t i, std::uint8_t h) const noexcept {
        return samples_[i < kMaxSamples ? i : 0U][h < kRecords ? h : 0U];
    }

    // Per record: "head H: applied N status seen S last q W X Y Z"
    // ("combined: ..." for the combined attitude).
    void print_heads() const noexcept {
        using namespace report;
        for (std::uint8_t h = 0; h < kRecords; ++h) {
            const Head& r = heads_[h];
            name(h);
            text(": applied ");
            u32(r.applied);
            text(" status seen ");
            u32(r.status_union);
            text(" last q ");
            quaternion(r.last.q_chu_icrf);
            text("\n");
        }
    }

    // "sample cycle C head H status S q W X Y Z" per sample and record, then
    // "solutions head H cycles N crc32c X" per record ("combined" for head H
    // of the combined attitude).
    void print_solutions() const noexcept {
        using namespace report;
        for (std::uint32_t i = 0; i < samples_taken_; ++i) {
            for (std::uint8_t h = 0; h < kRecords; ++h) {
                text("sample cycle ");
                u32(i * kSampleEvery);
                text(" ");
                name(h);
                text(" status ");
                u32(samples_[i][h].status);
                text(" q ");
                quaternion(samples_[i][h].q_chu_icrf);
                text("\n");
            }
        }
        for (std::uint8_t h = 0; h < kRecords; ++h) {
            text("solutions ");
            name(h);
            text(" cycles ");
            u32(heads_[h].solutions);
            text(" crc32c ");
            hex32(heads_[h].crc);
            text("\n");
        }
    }

private:
    static void name(std::uint8_t h) noexcept {
        if (h == kCombined) {
            report::text("combined");
            return;
        }
        report::text("head ");
        report::u32(h);
    }

    void add_record(std::uint32_t cycle, std::uint8_t head, const CorrectedSolution<Scalar>& c, bool applied) noexcept {
        Head& r = heads_[head];
        const std::uint32_t words[5] = {bits_of(c.q_chu_icrf.w), bits_of(c.q_chu_icrf.x), bits_of(c.q_chu_icrf.y),
                                        bits_of(c.q_chu_icrf.z), c.status};
        std::uint8_t bytes[sizeof words];
        for (std::uint32_t i = 0; i < 20U; ++i) {  // little-endian, whatever the machine
            bytes[i] = static_cast<std::uint8_t>(words[i / 4U] >> (8U * (i % 4U)));
        }
        r.crc = link::crc32c(bytes, 18U, r.crc);  // the status: its 16 bits
        r.solutions = cycle + 1U;
        r.last = c;
        r.status_union = static_cast<StatusBits>(r.status_union | c.status);
        if (applied) {
            ++r.applied;
        }
        if (cycle % kSampleEvery == 0U && cycle / kSampleEvery < kMaxSamples) {
            samples_[cycle / kSampleEvery][head] = c;
            samples_taken_ = cycle / kSampleEvery + 1U;
        }
    }

    static void quaternion(const Quaternion<Scalar>& q) noexcept {
        report::hex32(bits_of(q.w));
        report::text(" ");
        report::hex32(bits_of(q.x));
        report::text(" ");
        report::hex32(bits_of(q.y));
        report::text(" ");
        report::hex32(bits_of(q.z));
    }
    Head heads_[kRecords]{};
    CorrectedSolution<Scalar> samples_[kMaxSamples][kRecords]{};
    std::uint32_t samples_taken_ = 0U;
};

// "sun learner: cycles C orbits O thinned T candidate orbits K rank R taken X
// crc32c Z": the learner's state as the loop reports it, the line its host
// prediction checks (tests/target/flight_expectation.cpp).
inline void print_sun_learner_state(const calib::SunLearnReport& r) noexcept {
    using namespace report;
    text("sun learner: cycles ");
    u32(static_cast<std::uint32_t>(r.cycles));
    text(" orbits ");
    u32(r.orbits);
    text(" thinned ");
    u32(static_cast<std::uint32_t>(r.thinned));
    text(" candidate orbits ");
    u32(r.candidate.orbits);
    text(" rank ");
    u32(static_cast<std::uint32_t>(r.candidate.rank));
    text(" taken ");
    u32(r.taken ? 1U : 0U);
    text(" crc32c ");
    hex32(calib::sun_fit_crc(r.candidate));
    text("\n");
}

// The models the estimator made active, in turn (the first kMaxModels): the
// cycle from which each was used, its version and CRC-32C (model_identity.hpp)
// and its coefficients (arcsec; printed as the bits of each double).
class ModelHistory {
public:
    static constexpr std::uint32_t kMaxModels = 4U;
    struct Entry {
        std::uint32_t cycle;
        std::uint32_t version;
        std::uint32_t crc;
        ModelCoefficients model;
    };

    void add(std::uint32_t cycle, const calib::EstimatorReport& r, const ModelCoefficients& m) noexcept {
        if (size_ < kMaxModels) {
            entries_[size_] = {cycle, r.active_version, r.active_crc, m};
            ++size_;
        }
    }
    std::uint32_t size() const noexcept { return size_; }
    const Entry& entry(std::uint32_t i) const noexcept { return entries_[i < kMaxModels ? i : 0U]; }

    // Per model: "model version V from cycle C crc32c X", then per head and
    // axis "model version V head H axis A c HHHHHHHHLLLLLLLL ..." (c0..c3).
    void print() const noexcept {
        using namespace report;
        for (std::uint32_t i = 0; i < size_; ++i) {
            const Entry& e = entries_[i];
            text("model version ");
            u32(e.version);
            text(" from cycle ");
            u32(e.cycle);
            text(" crc32c ");
            hex32(e.crc);
            text("\n");
            for (std::uint32_t h = 0; h < kMaxHeads; ++h) {
                for (std::uint32_t a = 0; a < kModelAxes; ++a) {
                    text("model version ");
                    u32(e.version);
                    text(" head ");
                    u32(h);
                    text(" axis ");
                    u32(a);
                    text(" c");
                    for (std::uint32_t t = 0; t < kLinearModelTerms; ++t) {
                        std::uint64_t b = 0U;
                        std::memcpy(&b, &e.model.coefficient[h][a][t], sizeof b);
                        text(" ");
                        hex32(static_cast<std::uint32_t>(b >> 32U));
                        hex32(static_cast<std::uint32_t>(b));
                    }
                    text("\n");
                }
            }
        }
    }

private:
    Entry entries_[kMaxModels]{};
    std::uint32_t size_ = 0U;
};

}  // namespace ascorr::app
