// ascorr/calib/orbit_spread_scores.hpp: the score by which the self-calibration's
// side learners (lag_search.hpp, sun_learner.hpp) choose between candidate
// corrections: the inter-boresight angles' spread inside each orbit, with
// forgetting (issue 40; docs/ground.md, "The lag learnt in self-calibration").
//
// Per candidate k and fed cycle, the IBAs A-B, A-C and B-C of the frame heads
// corrected as k corrects them (arcsec; frame.hpp's angle_arcsec). A
// candidate's score is the IBAs' spread inside each orbit, Σ (x − x̄)² about
// the orbit's own mean (nothing an orbit mean holds counts: that is the
// estimator's), summed over the pairs and over the orbits with a forgetting
// e^(−Δt/memory) per orbit closed, memory the estimator's time constant but
// at least kSideLearnerMemoryDays. Every candidate is scored on the same
// epochs, so the trackers' noise adds the same to each; what differs is the
// thermal residual inside the orbit. An orbit is scored when it has at least
// the estimator's min_epochs_per_orbit cycles; the IBAs within an orbit are
// summed about its first cycle's IBAs of candidate 0, so that the sums hold
// arcseconds, not 90°.
// Time: cycles in time order; a cycle of another orbit than the open one
// closes it (begin()). Double; no allocation, no loop but over the
// candidates and pairs.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>

#include "estimator_types.hpp"
#include "frame.hpp"
#include "portable_math.hpp"

namespace ascorr::calib {

// The side learners' memory: at least this, whatever the estimator's
// forgetting. What they learn is the bench's (a lag, how the Sun heats it),
// which does not drift in days as the coefficients may, and their margins need
// the noise of a month of orbits: with a memory of the estimator's 1 day
// (`--time-constant 1`) a static bench took a lag by chance and changed it
// about 20 times in 60 days.
inline constexpr double kSideLearnerMemoryDays = 30.0;

// The side learners' memory for the estimator's configuration (days).
inline double side_learner_memory_days(const EstimatorConfig& cfg) noexcept {
    return cfg.time_constant_days > kSideLearnerMemoryDays ? cfg.time_constant_days : kSideLearnerMemoryDays;
}

// An accepted orbit period (EstimatorConfig's), or the default one.
inline std::int64_t side_learner_period_us(const EstimatorConfig& cfg) noexcept {
    return cfg.orbit_period_us > 0 ? cfg.orbit_period_us : EstimatorConfig{}.orbit_period_us;
}

template <std::size_t K>
class OrbitSpreadScores {
public:
    static constexpr std::size_t kPairs = iba_pairs(kFrameHeads);

    // cfg as the estimator accepted it (configuration_acceptable).
    explicit OrbitSpreadScores(const EstimatorConfig& cfg) noexcept
        : period_us_(side_learner_period_us(cfg)),
          memory_us_(side_learner_memory_days(cfg) * 86400e6),
          min_orbits_(cfg.min_orbits),
          orbits_to_decide_(orbits_of_a_memory(cfg, period_us_)),  // period_us_ is declared before
          min_epochs_(cfg.min_epochs_per_orbit) {}

    // A cycle at t_us: a cycle of a later orbit closes the open one first.
    // true: an orbit was scored then (the caller's rule may reconsider).
    bool begin(std::int64_t t_us) noexcept {
        const std::int64_t bin = orbit_bin(t_us, period_us_);
        bool scored = false;
        if (open_ && bin != bin_) {
            scored = close_orbit();
        }
        if (!open_) {
            open_ = true;
            bin_ = bin;
        }
        return scored;
    }

    // Whether a cycle at t_us closes the open orbit (begin() would), and
    // that orbit's bin: for a learner whose own sums close with it.
    bool closes(std::int64_t t_us) const noexcept { return open_ && orbit_bin(t_us, period_us_) != bin_; }
    bool open() const noexcept { return open_; }
    std::int64_t open_bin() const noexcept { return bin_; }

    // The cycle's IBAs of every candidate (begin() came first).
    void add(const double (&iba)[K][kPairs]) noexcept {
        if (n_ == 0U) {
            for (std::size_t p = 0; p < kPairs; ++p) {
                ref_[p] = iba[0][p];
            }
        }
        for (std::size_t k = 0; k < K; ++k) {
            for (std::size_t p = 0; p < kPairs; ++p) {
                const double x = iba[k][p] - ref_[p];
                s1_[k][p] += x;
                s2_[k][p] += x * x;
            }
        }
        ++n_;
    }

    // Closes the open orbit (the end of the data); true: it was scored.
    bool finish() noexcept { return open_ && close_orbit(); }

    // Whether the scores hold enough orbits for a rule: a memory's orbits in
    // a row, counted with the forgetting, and at least min_orbits scored (a
    // relative 1e-9 below the count of N in a row, which rounds otherwise).
    bool deciding() const noexcept {
        return orbits_ >= min_orbits_ && orbits_held_ >= orbits_to_decide_ * (1.0 - 1e-9);
    }

    const double (&score() const noexcept)[K] { return score_; }
    double weight() const noexcept { return weight_; }  // forgotten cycles × pairs
    std::uint32_t orbits() const noexcept { return orbits_; }
    std::uint64_t cycles() const noexcept { return cycles_; }
    double orbits_held() const noexcept { return orbits_held_; }
    double orbits_to_decide() const noexcept { return orbits_to_decide_; }
    std::int64_t period_us() const noexcept { return period_us_; }
    double memory_us() const noexcept { return memory_us_; }

private:
    // The forgotten count of orbits the scores must hold before a rule
    // applies: that of a memory's orbits scored in a row, N = ⌈memory /
    // period⌉ (about 461 of 95 min in 30 days), (1 − λᴺ)/(1 − λ) with λ an
    // orbit's forgetting. Before, the scores weigh the orbits of the first,
    // young models, whose wrong coefficients some candidate offsets by chance
    // (on the static 300-day bench of docs/ground.md, a lag of 6048 s at orbit
    // 30, left again 9 versions later), or after a long gap a day of new
    // orbits (a static bench without head B for 120 days took 378 s a day
    // after it).
    static double orbits_of_a_memory(const EstimatorConfig& cfg, std::int64_t period_us) noexcept {
        const double x = static_cast<double>(period_us) / (side_learner_memory_days(cfg) * 86400e6);  // ≤ 1
        const double n = std::ceil(1.0 / x);
        return -expm1_nonpositive(-n * x) / -expm1_nonpositive(-x);
    }

    // The open orbit's spreads into the scores (when it has enough cycles),
    // the older orbits forgotten over the time since the last scored one.
    bool close_orbit() noexcept {
        const bool scored = n_ >= min_epochs_ && n_ > 0U;
        if (scored) {
            const double lambda = scored_ ? exp_nonpositive(-static_cast<double>(bin_ - last_bin_) *
                                                            static_cast<double>(period_us_) / memory_us_)
                                          : 0.0;
            const double n = static_cast<double>(n_);
            for (std::size_t k = 0; k < K; ++k) {
                double spread = 0.0;
                for (std::size_t p = 0; p < kPairs; ++p) {
                    spread += s2_[k][p] - s1_[k][p] * s1_[k][p] / n;
                }
                score_[k] = lambda * score_[k] + spread;
            }
            weight_ = lambda * weight_ + n * static_cast<double>(kPairs);
            orbits_held_ = lambda * orbits_held_ + 1.0;
            scored_ = true;
            last_bin_ = bin_;
            ++orbits_;
            cycles_ += n_;
        }
        for (std::size_t k = 0; k < K; ++k) {
            for (std::size_t p = 0; p < kPairs; ++p) {
                s1_[k][p] = 0.0;
                s2_[k][p] = 0.0;
            }
        }
        n_ = 0U;
        open_ = false;
        return scored;
    }

    std::int64_t period_us_;
    double memory_us_;  // the forgetting's time constant (side_learner_memory_days)
    std::uint32_t min_orbits_;
    double orbits_to_decide_;  // orbits_of_a_memory
    std::uint32_t min_epochs_;
    bool open_ = false;
    std::int64_t bin_ = 0;     // the open orbit
    std::uint32_t n_ = 0U;     // its cycles
    double ref_[kPairs] = {};  // its first IBAs of candidate 0
    double s1_[K][kPairs] = {};
    double s2_[K][kPairs] = {};
    bool scored_ = false;
    std::int64_t last_bin_ = 0;  // the last orbit scored
    double score_[K] = {};
    double weight_ = 0.0;
    std::uint32_t orbits_ = 0U;
    std::uint64_t cycles_ = 0U;
    double orbits_held_ = 0.0;  // the forgotten count of orbits scored
};

// The IBAs A-B, A-C, B-C of the frame heads' attitudes (arcsec).
inline void frame_ibas(const Quaternion<double> (&q)[kFrameHeads],
                       double (&out)[OrbitSpreadScores<1>::kPairs]) noexcept {
    Vector3<double> b[kFrameHeads];
    for (std::size_t h = 0; h < kFrameHeads; ++h) {
        b[h] = boresight_of(q[h]);
    }
    std::size_t p = 0;
    for (std::size_t i = 0; i < kFrameHeads; ++i) {
        for (std::size_t j = i + 1U; j < kFrameHeads; ++j) {
            out[p++] = angle_arcsec(b[i], b[j]);
        }
    }
}

}  // namespace ascorr::calib
