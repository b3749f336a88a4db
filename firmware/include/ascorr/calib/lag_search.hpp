// ascorr/calib/lag_search.hpp: the bench's lag, measured by the
// self-calibration as it runs (issue 40; docs/ground.md, "The lag learnt in
// self-calibration").
//
// Why: the estimator learns from orbit means, and an orbit mean does not show
// a lag of the orbit's order (L's orbit mean is T's, but for the
// temperature's drift over the orbit times τ); inside the orbit a lagging
// bench leaves the largest residual of all (docs/ground.md, "The bench inside
// the orbit"). For the same reason the coefficients do not depend on the lag:
// one estimator serves every candidate, and the search only scores them.
//
// What it scores: at each fed cycle with an active model (heads A, B and C
// selected, feed.hpp), the three heads' attitudes corrected with that model
// at each candidate's temperatures (no lag, and every τ of kLagGridS, one τ
// for every head: the bench's), and their IBAs A-B, A-C and B-C (the angle
// between the boresights, as `stats`). A candidate's score is the IBAs'
// spread inside each orbit, Σ (x − x̄)² about the orbit's own mean (so that
// nothing an orbit mean holds counts: that is the estimator's), summed over
// the pairs and over the orbits with a forgetting e^(−Δt/memory) per orbit
// closed, memory the estimator's time constant but at least
// kLagSearchMemoryDays. Every candidate is scored on the same epochs, so the
// star trackers' noise adds the same to each; what differs is the thermal
// residual inside the orbit.
//
// Taken (report().tau_s, next_taken): at each orbit closed once the scores
// hold a memory's orbits (their forgotten count, so that a long gap in the
// data waits for as many again; and at least min_orbits scored), the
// candidate with the lowest score (ties: the shorter lag, no lag first)
// replaces the one taken (at first: no lag) when its score is below the
// taken one's by more than kLagSearchMargin of it between a lag and none,
// kLagSwitchMargin between two lags; so a lag is taken only when the data
// show it, and then kept until another (or none) is clearly better. The
// answer is a grid point, a third of an octave apart: a τ off by half a step
// (13 %) leaves about 13 % of the lag's residual.
//
// Arithmetic: q_ab (the attitude without the thermal stage) as the
// estimator's feed forms it (selected_solution), the thermal stage in T as
// the core's (thermal_stage), each candidate's lag a
// pipeline::TemperatureLag<T> stepped at the fed cycles only (a reading
// between two of them is not seen: on the host every epoch with A, B and C
// selected is one, on board every second cycle, 11 Hz, against τ ≥ 300 s);
// the corrected attitudes, the IBAs and the sums in double. The IBAs within
// an orbit are summed about the orbit's first no-lag IBA, so that the sums
// hold arcseconds, not 90°.
// Time: cycles in time order (the host sorts the rows; on board the clock).
// A cycle of another orbit than the open one closes it; one earlier than the
// last scored orbit forgets nothing, and a lag's channel refuses its time
// (TemperatureLag: kTimeNotIncreasing) and keeps its state.
// Cost per fed cycle: 3·kLagGridPoints lag steps, 3·kLagCandidates thermal
// stages, quaternion products and boresights, 3·kLagCandidates IBAs (an atan2
// and a square root each). Bounded: no allocation, no loop but over the
// candidates, heads and pairs. A cycle whose model cannot correct a head at
// some candidate's temperatures (no coefficients for it, an angle beyond the
// core's limits) scores no candidate.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>

#include "../core/correct.hpp"
#include "../core/quaternion.hpp"
#include "../core/thermal.hpp"
#include "../pipeline/temperature_lag.hpp"
#include "estimator_types.hpp"
#include "feed.hpp"
#include "frame.hpp"
#include "portable_math.hpp"

namespace ascorr::calib {

// Candidates: index 0 no lag, index k ≥ 1 the lag kLagGridS[k − 1].
inline constexpr std::size_t kLagCandidates = pipeline::kLagGridPoints + 1U;
inline constexpr double lag_candidate_tau_s(std::size_t k) noexcept {
    return k == 0U || k > pipeline::kLagGridPoints ? 0.0 : pipeline::kLagGridS[k - 1U];
}

// A lag is taken when its score is below no lag's by more than this fraction:
// as `fit --lag auto`'s margin (0.15 % of the RMS, 0.3 % of the mean square).
// The spread inside the orbit is mostly the trackers' noise, (2.1″)² per pair
// and epoch; the lagging benches of docs/ground.md lower it by 0.6 to 2 %.
inline constexpr double kLagSearchMargin = 0.003;
// A lag taken gives way to another when that one's score is below it by more
// than this fraction: near the best τ the grid's neighbours score within
// 0.01 % of each other (the 300-day bench lagging by 1800 s: 1512, 1905 and
// 2400 s within 0.012 %), so they do not take turns; a lag taken early, on few
// orbits and a young model, is left once the data say so (there 6048 s,
// 0.11 % above 1905 s).
inline constexpr double kLagSwitchMargin = 0.0005;
// The search's memory: at least this, whatever the estimator's forgetting.
// The lag is the bench's, which does not drift in days as its coefficients
// may, and the margins above need the noise of a month of orbits: with a
// memory of the estimator's 1 day (`--time-constant 1`) a static bench took a
// lag by chance and changed it about 20 times in 60 days. (With that
// estimator the models themselves swing by tenths of an arcsecond from day to
// day, and a lag can still offset some of it: 200-day static benches took
// lags with it, their residuals 0.5–0.75″ with the lag or without.)
inline constexpr double kLagSearchMemoryDays = 30.0;

struct LagSearchReport {
    std::uint32_t orbits = 0;           // orbits scored (each with ≥ min_epochs_per_orbit cycles)
    std::uint64_t cycles = 0;           // cycles scored
    std::size_t best = 0;               // the candidate with the lowest score now (0: no lag)
    double best_tau_s = 0.0;            // its τ (0: no lag)
    double gain = 0.0;                  // 1 − best's score / no lag's (0 before any orbit)
    double rms_arcsec = 0.0;            // no lag's spread inside the orbit, RMS per pair and cycle
    double tau_s = 0.0;                 // the lag taken: the bench's, 0 none
    bool deciding = false;              // the scores hold a memory's orbits: the rule applies
    double orbits_held = 0.0;           // their forgotten count of orbits
    double orbits_to_decide = 0.0;      // ... that the rule needs (a memory's)
    double score[kLagCandidates] = {};  // forgotten sums of squares (arcsec²)
};

template <typename T>
class LagSearch {
public:
    static constexpr std::size_t kPairs = iba_pairs(kFrameHeads);

    // The estimator's orbits (period, forgetting, min_orbits, min epochs);
    // cfg as the estimator accepted it (configuration_acceptable).
    explicit LagSearch(const EstimatorConfig& cfg) noexcept
        : period_us_(cfg.orbit_period_us > 0 ? cfg.orbit_period_us : EstimatorConfig{}.orbit_period_us),
          memory_us_(memory_days(cfg) * 86400e6),
          min_orbits_(cfg.min_orbits),
          orbits_to_decide_(orbits_of_a_memory(cfg, period_us_)),  // period_us_ is declared before
          min_epochs_(cfg.min_epochs_per_orbit) {
        for (std::size_t k = 0; k < pipeline::kLagGridPoints; ++k) {
            for (pipeline::TemperatureLag<T>& lag : lag_[k]) {
                (void)lag.configure(pipeline::kLagGridS[k]);  // within [kMinLagTauS, kMaxLagTauS]
            }
        }
    }

    // One fed cycle at t_us (TT µs): the frame heads' corrected solutions
    // (corrected[h], with `model` at temperatures[h], as the pipeline kept
    // them for the feed). false: not scored (a head not selected, or a
    // candidate that cannot correct it). A cycle of a later orbit closes the
    // open one first.
    bool take(std::int64_t t_us, const ThermalModel<T>& model, const CorrectedSolution<T>* corrected,
              const HeadTemperatures<T>* const* temperatures) noexcept {
        const std::int64_t bin = orbit_bin(t_us, period_us_);
        if (open_ && bin != bin_) {
            close_orbit();
        }
        if (!open_) {
            open_ = true;
            bin_ = bin;
        }
        Quaternion<double> q_ab[kFrameHeads];
        for (std::uint8_t h = 0; h < kFrameHeads; ++h) {  // every head selected before any lag steps
            Quaternion<T> q{};
            if (!selected_solution(h, &model, corrected[h], *temperatures[h], q)) {
                return false;
            }
            q_ab[h] = to_double(q);
        }
        for (pipeline::TemperatureLag<T>(&lags)[kFrameHeads] : lag_) {
            for (std::uint8_t h = 0; h < kFrameHeads; ++h) {
                (void)lags[h].step(t_us, *temperatures[h]);
            }
        }
        double iba[kLagCandidates][kPairs];
        for (std::size_t k = 0; k < kLagCandidates; ++k) {
            if (!ibas(k, model, q_ab, temperatures, iba[k])) {
                return false;
            }
        }
        add(iba);
        return true;
    }

    // Closes the open orbit (the end of the data).
    void finish() noexcept {
        if (open_) {
            close_orbit();
        }
    }

    LagSearchReport report() const noexcept {
        LagSearchReport r;
        r.orbits = orbits_;
        r.cycles = cycles_;
        for (std::size_t k = 0; k < kLagCandidates; ++k) {
            r.score[k] = score_[k];
        }
        r.best = best_of(score_);
        r.best_tau_s = lag_candidate_tau_s(r.best);
        if (score_[0] > 0.0) {
            r.gain = (score_[0] - score_[r.best]) / score_[0];
        }
        if (weight_ > 0.0) {
            r.rms_arcsec = std::sqrt(score_[0] / weight_);
        }
        r.tau_s = lag_candidate_tau_s(taken_);
        r.deciding = deciding();
        r.orbits_held = orbits_held_;
        r.orbits_to_decide = orbits_to_decide_;
        return r;
    }

    // The bench's lag as taken so far (s; 0: none).
    double tau_s() const noexcept { return lag_candidate_tau_s(taken_); }

    // The rule (above): the candidate taken after `taken`, given the scores.
    static constexpr std::size_t next_taken(const double (&score)[kLagCandidates], std::size_t taken) noexcept {
        const std::size_t best = best_of(score);
        const double margin = best != 0U && taken != 0U ? kLagSwitchMargin : kLagSearchMargin;
        return best != taken && score[best] < (1.0 - margin) * score[taken] ? best : taken;
    }

private:
    static constexpr std::size_t kGrid = pipeline::kLagGridPoints;

    // The candidate with the lowest score (ties: the first, no lag before any).
    static constexpr std::size_t best_of(const double (&score)[kLagCandidates]) noexcept {
        std::size_t best = 0;
        for (std::size_t k = 1; k < kLagCandidates; ++k) {
            best = score[k] < score[best] ? k : best;
        }
        return best;
    }

    static double memory_days(const EstimatorConfig& cfg) noexcept {
        return cfg.time_constant_days > kLagSearchMemoryDays ? cfg.time_constant_days : kLagSearchMemoryDays;
    }

    // The forgotten count of orbits the scores must hold before the rule
    // applies: that of a memory's orbits scored in a row, N = ⌈memory /
    // period⌉ (about 461 of 95 min in 30 days), (1 − λᴺ)/(1 − λ) with λ an
    // orbit's forgetting. Before, the scores weigh the orbits of the first,
    // young models, whose wrong coefficients some lag offsets by chance (on
    // the static 300-day bench of docs/ground.md, 6048 s at orbit 30, left
    // again 9 versions later), or after a long gap a day of new orbits (a
    // static bench without head B for 120 days took 378 s a day after it).
    static double orbits_of_a_memory(const EstimatorConfig& cfg, std::int64_t period_us) noexcept {
        const double x = static_cast<double>(period_us) / (memory_days(cfg) * 86400e6);  // an orbit's, ≤ 1
        const double n = std::ceil(1.0 / x);
        return -expm1_nonpositive(-n * x) / -expm1_nonpositive(-x);
    }

    // Whether the scores hold enough orbits for the rule (above; a relative
    // 1e-9 below the count of N in a row, which rounds otherwise).
    bool deciding() const noexcept {
        return orbits_ >= min_orbits_ && orbits_held_ >= orbits_to_decide_ * (1.0 - 1e-9);
    }

    static Quaternion<double> to_double(const Quaternion<T>& q) noexcept {
        using S = ScalarTraits<T>;
        return {S::to_double(q.w), S::to_double(q.x), S::to_double(q.y), S::to_double(q.z)};
    }

    // Candidate k's IBAs of the cycle (arcsec); false when a head cannot be
    // corrected at its temperatures.
    bool ibas(std::size_t k, const ThermalModel<T>& model, const Quaternion<double>* q_ab,
              const HeadTemperatures<T>* const* temperatures, double* out) const noexcept {
        Vector3<double> b[kFrameHeads];
        for (std::uint8_t h = 0; h < kFrameHeads; ++h) {
            const HeadTemperatures<T> tp = k == 0U ? *temperatures[h] : lagged(lag_[k - 1U][h]);
            const ThermalStage<T> th = thermal_stage(model, h, tp);
            if (th.skip != 0U) {
                return false;
            }
            b[h] = boresight_of(corrected(q_ab[h], th.q_th));
        }
        std::size_t p = 0;
        for (std::size_t i = 0; i < kFrameHeads; ++i) {
            for (std::size_t j = i + 1U; j < kFrameHeads; ++j) {
                out[p++] = angle_arcsec(b[i], b[j]);  // frame.hpp
            }
        }
        return true;
    }

    static HeadTemperatures<T> lagged(const pipeline::TemperatureLag<T>& lag) noexcept {
        return {lag.lagged(0), lag.lagged(1), lag.lagged(2)};
    }

    // q_th ⊗ q_ab, as the core applies the thermal stage (correct.hpp), in double.
    static Quaternion<double> corrected(const Quaternion<double>& q_ab, const SmallRotation<T>& q_th) noexcept {
        using S = ScalarTraits<T>;
        const SmallRotation<double> r{S::to_double(q_th.dw),
                                      {S::to_double(q_th.v.x), S::to_double(q_th.v.y), S::to_double(q_th.v.z)}};
        return renormalized_sum(q_ab, increment(r) * q_ab);
    }

    void add(const double (&iba)[kLagCandidates][kPairs]) noexcept {
        if (n_ == 0U) {
            for (std::size_t p = 0; p < kPairs; ++p) {
                ref_[p] = iba[0][p];
            }
        }
        for (std::size_t k = 0; k < kLagCandidates; ++k) {
            for (std::size_t p = 0; p < kPairs; ++p) {
                const double x = iba[k][p] - ref_[p];
                s1_[k][p] += x;
                s2_[k][p] += x * x;
            }
        }
        ++n_;
    }

    // The open orbit's spreads into the scores (when it has enough cycles),
    // the older orbits forgotten over the time since the last scored one.
    void close_orbit() noexcept {
        if (n_ >= min_epochs_ && n_ > 0U) {
            const double lambda = scored_ ? exp_nonpositive(-static_cast<double>(bin_ - last_bin_) *
                                                            static_cast<double>(period_us_) / memory_us_)
                                          : 0.0;
            const double n = static_cast<double>(n_);
            for (std::size_t k = 0; k < kLagCandidates; ++k) {
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
            reconsider();
        }
        for (std::size_t k = 0; k < kLagCandidates; ++k) {
            for (std::size_t p = 0; p < kPairs; ++p) {
                s1_[k][p] = 0.0;
                s2_[k][p] = 0.0;
            }
        }
        n_ = 0U;
        open_ = false;
    }

    // The candidate taken, once the scores hold a memory's orbits (above).
    void reconsider() noexcept {
        if (deciding()) {
            taken_ = next_taken(score_, taken_);
        }
    }

    std::int64_t period_us_;
    double memory_us_;  // the forgetting's time constant (memory_days)
    std::uint32_t min_orbits_;
    double orbits_to_decide_;  // orbits_of_a_memory
    std::uint32_t min_epochs_;
    pipeline::TemperatureLag<T> lag_[kGrid][kFrameHeads]{};
    bool open_ = false;
    std::int64_t bin_ = 0;     // the open orbit
    std::uint32_t n_ = 0U;     // its cycles
    double ref_[kPairs] = {};  // its first no-lag IBAs
    double s1_[kLagCandidates][kPairs] = {};
    double s2_[kLagCandidates][kPairs] = {};
    bool scored_ = false;
    std::int64_t last_bin_ = 0;  // the last orbit scored
    double score_[kLagCandidates] = {};
    double weight_ = 0.0;  // forgotten cycles × pairs
    std::uint32_t orbits_ = 0U;
    std::uint64_t cycles_ = 0U;
    double orbits_held_ = 0.0;  // the forgotten count of orbits scored
    std::size_t taken_ = 0U;
};

}  // namespace ascorr::calib
