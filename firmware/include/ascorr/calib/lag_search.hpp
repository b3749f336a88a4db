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
// between the boresights, as `stats`), scored by their spread inside the
// orbit with forgetting (orbit_spread_scores.hpp).
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
// the corrected attitudes, the IBAs and the sums in double.
// Time: cycles in time order (the host sorts the rows; on board the clock).
// A cycle of another orbit than the open one closes it
// (orbit_spread_scores.hpp); one earlier than the last scored orbit forgets
// nothing, and a lag's channel refuses its time
// (TemperatureLag: kTimeNotIncreasing) and keeps its state.
// Cost per fed cycle: 3·kLagGridPoints lag steps, 3·kLagCandidates thermal
// stages, quaternion products and boresights, 3·kLagCandidates IBAs (a square
// root and portable_math.hpp's atan2_upper each). Bounded: no allocation, no
// loop but over the candidates, heads and pairs. A cycle whose model cannot
// correct a head at some candidate's temperatures (no coefficients for it, an
// angle beyond the core's limits) scores no candidate.
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
#include "orbit_spread_scores.hpp"

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
// The search's memory: orbit_spread_scores.hpp's side_learner_memory_days.
// (With the estimator's `--time-constant 1` its models themselves swing by
// tenths of an arcsecond from day to day, and a lag can still offset some of
// it: 200-day static benches took lags with it, their residuals 0.5–0.75″
// with the lag or without.)

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
    static constexpr std::size_t kPairs = OrbitSpreadScores<kLagCandidates>::kPairs;

    // The estimator's orbits (period, forgetting, min_orbits, min epochs);
    // cfg as the estimator accepted it (configuration_acceptable).
    explicit LagSearch(const EstimatorConfig& cfg) noexcept : scores_(cfg) {
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
        if (scores_.begin(t_us)) {
            reconsider();
        }
        Quaternion<double> q_ab[kFrameHeads];
        for (std::uint8_t h = 0; h < kFrameHeads; ++h) {  // every head selected before any lag steps
            Quaternion<T> q{};
            if (!selected_solution(h, &model, corrected[h], *temperatures[h], q)) {
                return false;
            }
            q_ab[h] = in_double(q);
        }
        for (pipeline::TemperatureLag<T>(&lags)[kFrameHeads] : lag_) {
            for (std::uint8_t h = 0; h < kFrameHeads; ++h) {
                (void)lags[h].step(t_us, *temperatures[h]);
            }
        }
        double iba[kLagCandidates][kPairs];
        Quaternion<double> q[kFrameHeads];
        for (std::size_t k = 0; k < kLagCandidates; ++k) {
            if (!corrected_at(k, model, q_ab, temperatures, q)) {
                return false;
            }
            frame_ibas(q, iba[k]);
            if (k == taken_) {
                for (std::size_t h = 0; h < kFrameHeads; ++h) {
                    q_taken_[h] = q[h];
                }
            }
        }
        scores_.add(iba);
        return true;
    }

    // Closes the open orbit (the end of the data).
    void finish() noexcept {
        if (scores_.finish()) {
            reconsider();
        }
    }

    LagSearchReport report() const noexcept {
        LagSearchReport r;
        r.orbits = scores_.orbits();
        r.cycles = scores_.cycles();
        const double(&score)[kLagCandidates] = scores_.score();
        for (std::size_t k = 0; k < kLagCandidates; ++k) {
            r.score[k] = score[k];
        }
        r.best = best_of(score);
        r.best_tau_s = lag_candidate_tau_s(r.best);
        if (score[0] > 0.0) {
            r.gain = (score[0] - score[r.best]) / score[0];
        }
        if (scores_.weight() > 0.0) {
            r.rms_arcsec = std::sqrt(score[0] / scores_.weight());
        }
        r.tau_s = lag_candidate_tau_s(taken_);
        r.deciding = scores_.deciding();
        r.orbits_held = scores_.orbits_held();
        r.orbits_to_decide = scores_.orbits_to_decide();
        return r;
    }

    // The bench's lag as taken so far (s; 0: none).
    double tau_s() const noexcept { return lag_candidate_tau_s(taken_); }

    // The frame heads' attitudes of the last scored cycle as the lag taken
    // (when the cycle began) corrected them (double).
    const Quaternion<double> (&taken_attitudes() const noexcept)[kFrameHeads] { return q_taken_; }

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

    // The frame heads corrected at candidate k's temperatures; false when a
    // head cannot be corrected at them.
    bool corrected_at(std::size_t k, const ThermalModel<T>& model, const Quaternion<double>* q_ab,
                      const HeadTemperatures<T>* const* temperatures,
                      Quaternion<double> (&out)[kFrameHeads]) const noexcept {
        for (std::uint8_t h = 0; h < kFrameHeads; ++h) {
            const HeadTemperatures<T> tp = k == 0U ? *temperatures[h] : lagged(lag_[k - 1U][h]);
            const ThermalStage<T> th = thermal_stage(model, h, tp);
            if (th.skip != 0U) {
                return false;
            }
            out[h] = corrected(q_ab[h], th.q_th);
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

    // The candidate taken, once the scores hold a memory's orbits (above).
    void reconsider() noexcept {
        if (scores_.deciding()) {
            taken_ = next_taken(scores_.score(), taken_);
        }
    }

    OrbitSpreadScores<kLagCandidates> scores_;
    pipeline::TemperatureLag<T> lag_[kGrid][kFrameHeads]{};
    std::size_t taken_ = 0U;
    Quaternion<double> q_taken_[kFrameHeads]{};
};

}  // namespace ascorr::calib
