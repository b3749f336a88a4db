// ascorr_hal/acquisition.hpp: sample sets in, HeadTemperatures with validity out.
//
// Conventions:
//  - TemperatureAcquisition<T> owns one ChannelCheck per configured channel.
//    update(samples) runs the checks (channel_check.hpp); head(h, now_us) votes
//    each role (voting.hpp) as seen at now_us and returns the core's
//    HeadTemperatures<T> with valid = false for every withheld value, plus
//    the fault bits of T1, T2, T3.
//  - status_bits() maps the faults to the core's status bits: a withheld
//    value gives kNoTemperature, with kStale if it (or the triplet members
//    it lacks) is stale and kTemperatureInvalid for any other fault, or for
//    valid members that disagree (kNoQuorum alone). merge_status() adds
//    them to a CorrectedSolution only where the core itself skipped the
//    thermal stage for missing temperatures, so the bits never claim a skip
//    that did not happen.
//  - Freestanding: fixed-size state, bounded loops, no heap, no exceptions.
//    Typical firmware loop (1 Hz acquisition, corrections at any rate):
//        AdcSampleSetSource<float> src(mcp3208, clock, config);
//        TemperatureAcquisition<float> acq(config);
//        every second:     acq.poll(src);
//        every solution:   HeadAcquisition<float> h = acq.head(head, clock.now_us());
//                          in.temperatures = h.temperatures;
//                          out = correct_solution(in, cfg);
//                          out.status = merge_status(out.status, h);
#pragma once

#include <cstdint>

#include "ascorr/core/correct.hpp"
#include "ascorr/core/status.hpp"
#include "ascorr/core/thermal.hpp"
#include "channel_check.hpp"
#include "channel_config.hpp"
#include "faults.hpp"
#include "sample_set.hpp"
#include "voting.hpp"

namespace ascorr::hal {

template <typename T>
struct HeadAcquisition {
    // valid = false where withheld; in the core's scalar whose Celsius<> is T
    // (float, double; Q30 for the fixed-point path's QCelsius)
    HeadTemperatures<typename TemperatureMath<T>::CoreScalar> temperatures;
    FaultBits faults_chu;
    FaultBits faults_029;
    FaultBits faults_032;

    // kStale when a value is withheld because it (or the members it was
    // voted from) is stale; kTemperatureInvalid for any other reason,
    // including a triplet whose valid members disagree (kNoQuorum alone).
    StatusBits status_bits() const noexcept {
        const FaultBits f[3] = {faults_chu, faults_029, faults_032};
        StatusBits s = 0U;
        for (const FaultBits x : f) {
            if (x == 0U) {
                continue;
            }
            s |= status::kNoTemperature;
            const FaultBits reasons = static_cast<FaultBits>(x & static_cast<FaultBits>(~fault::kNoQuorum));
            if ((reasons & fault::kStale) != 0U) {
                s |= status::kStale;
            }
            if (reasons == 0U || (reasons & static_cast<FaultBits>(~fault::kStale)) != 0U) {
                s |= status::kTemperatureInvalid;
            }
        }
        return s;
    }
};

// The core's status plus the acquisition's reasons, where the core reported
// missing temperatures (kNoTemperature): never on a thermal stage that ran.
template <typename T>
constexpr StatusBits merge_status(StatusBits core, const HeadAcquisition<T>& h) noexcept {
    return (core & status::kNoTemperature) != 0U ? static_cast<StatusBits>(core | h.status_bits()) : core;
}

template <typename T>
class TemperatureAcquisition {
public:
    explicit TemperatureAcquisition(const AcquisitionConfig<T>& config) noexcept : config_(config) {}

    const AcquisitionConfig<T>& config() const noexcept { return config_; }

    void update(const SampleSet<T>& samples) noexcept {
        for (std::uint8_t i = 0; i < config_.channels && i < kMaxChannels; ++i) {
            check_[i].update(config_.channel[i], samples.channel[i], samples.t_us);
        }
    }

    // Acquires one sample set from src and processes it; false if src had none.
    bool poll(SampleSetSource<T>& src) noexcept {
        if (!src.acquire(samples_)) {
            return false;
        }
        update(samples_);
        return true;
    }

    // Channel i's latest reading as seen at now_us (not voted).
    ChannelReading<T> channel(std::uint8_t i, std::uint64_t now_us) const noexcept {
        return check_[i].at(now_us, config_.stale_us);
    }

    // The voted value of a role at now_us; members (if given, kMaxVoters
    // entries) receive the member readings with kOutvoted where it applies,
    // and member_index their channel indices.
    VotedTemperature<T> role(Role r, std::uint64_t now_us, ChannelReading<T>* members = nullptr,
                             std::uint8_t* member_index = nullptr) const noexcept {
        ChannelReading<T> m[kMaxVoters];
        std::uint8_t idx[kMaxVoters] = {};
        std::uint8_t n = 0;
        for (std::uint8_t i = 0; i < config_.channels && i < kMaxChannels && n < kMaxVoters; ++i) {
            if (config_.channel[i].role == r) {
                idx[n] = i;
                m[n++] = channel(i, now_us);
            }
        }
        const VotedTemperature<T> v = vote(m, n, config_.vote_tolerance, config_.quorum);
        for (std::uint8_t k = 0; k < n; ++k) {
            if (members != nullptr) {
                members[k] = m[k];
            }
            if (member_index != nullptr) {
                member_index[k] = idx[k];
            }
        }
        return v;
    }

    HeadAcquisition<T> head(std::uint8_t h, std::uint64_t now_us) const noexcept {
        const VotedTemperature<T> t1 = role(h < kMaxHeads ? chu_role(h) : Role::kMonitor, now_us);
        const VotedTemperature<T> t2 = role(Role::kT029, now_us);
        const VotedTemperature<T> t3 = role(Role::kT032, now_us);
        FaultBits f1 = h < kMaxHeads ? t1.faults : fault::kNoData;
        if (f1 == 0U && t1.members == 0U) {
            f1 = fault::kNoData;
        }
        HeadAcquisition<T> out{};
        out.temperatures.t_chu = {f1 == 0U ? t1.celsius : T{}, f1 == 0U};
        out.temperatures.t_029 = {t2.valid() ? t2.celsius : T{}, t2.valid()};
        out.temperatures.t_032 = {t3.valid() ? t3.celsius : T{}, t3.valid()};
        out.faults_chu = f1;
        out.faults_029 = t2.faults;
        out.faults_032 = t3.faults;
        return out;
    }

private:
    AcquisitionConfig<T> config_;
    ChannelCheck<T> check_[kMaxChannels];
    SampleSet<T> samples_{};
};

}  // namespace ascorr::hal
