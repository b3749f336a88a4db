// ascorr/calib/sun_learner.hpp: the thermal model's Sun term (core/sun_term.hpp),
// learnt by the self-calibration as it runs (issue 40; docs/ground.md, "The
// Sun term learnt in self-calibration").
//
// Why a learner beside the estimator: the estimator learns from orbit means,
// which average the Sun's direction in the orbital plane away; the term lives
// inside the orbit. So, as `fit` does on the ground (sun_moments.hpp), the
// learner sums, at fed cycles with an active model (heads A, B and C
// selected; on board one per 120 s, below), the heads' rotations in F and
// the Sun's direction in each head's frame, about each orbit's own mean,
// with a forgetting e^(−Δt/memory) per orbit closed (memory:
// orbit_spread_scores.hpp's, the estimator's time constant but at least 30
// days), and solves them after every orbit closed (step(), in idle time;
// put to use from the next cycle taken, settle(), so that the ground, the
// link and the flight loop agree whatever their idle time): the candidate,
// under the estimator's weights for
// the common rotation when it has them (`--mountings`' combined attitude),
// otherwise the smallest coefficients (not the estimator's own gauge, frame F
// of A and C: the term's common part then moves F a little). Heads A, B and C
// only: a further head learnt by the estimator gets no term.
//
// Taken (taken(), report().taken): each cycle is corrected by the polynomial
// alone and by the polynomial and the candidate solved before its orbit
// began, and both are scored by their IBAs' spread inside the orbit
// (orbit_spread_scores.hpp): the candidate is scored on orbits it has not
// seen, as `fit` scores on held-out data (the cycle that closes an orbit is
// scored with the candidate before that orbit's solve, which runs after it:
// step()). Once the scores hold a memory's
// orbits, the term is taken when its score is below the polynomial's by more
// than kSunLearnMargin (fit's margin, in the mean square), and left again when
// the polynomial's is below its by as much. While taken, the term is the
// latest candidate (within the core's domain: sun_fit_within_domain; a
// candidate beyond it is not used).
//
// Thinned on board: given an interval (the DPU's: kSunLearnOnBoardIntervalUs,
// 120 s), the learner takes a cycle only when its interval floor(t /
// interval) is not that of the last cycle it looked at; the others are
// skipped and counted (report().thinned). A cycle refused (no Sun, not
// finite) takes its interval too, so that the bound holds whatever the
// input. Why: a take
// costs the DPU as much as 110 to 155 of the estimator's cycles
// (docs/figures.md, "The side learners"). It biases nothing: the moments are
// sums over the epochs taken, with no state between them (the lag search
// cannot be thinned so: its lags must step as the pipeline's). A time that
// jumps forward and back costs at most one extra take, never a learner
// stopped until the clock comes back. Without an interval (0, the ground's
// `correct --self-calibrate`, as the contract says) every fed cycle is
// taken.
//
// Arithmetic: double (the attitudes as the caller corrected them: the
// pipeline's kept solutions, or the lag search's at its lag; the Sun from
// nav/sun_direction.hpp at the cycle's TT). A cycle outside the Sun
// ephemeris' span (2000–2051), or whose attitudes give no finite rotation, is
// not taken (counted: report()).
// Cost per cycle taken (take): a Sun direction, three Sun-term rotations, six
// boresights and IBAs, the moments' 2·9² products; and, where idle time
// left a solve unfinished, its rest (settle: up to a whole solve, counted in
// report().late). Per orbit closed (step):
// the normal equations (27 × 27) and their Jacobi eigen-decomposition
// (symmetric_eigen.hpp, at most 30 sweeps), a bounded step per call (the
// normal equations, 8 lines of the change to the last solve's basis, one row
// of a sweep, or the result), in the learner's own 12 KiB workspace
// (SunMoments::Solve, kept from solve to solve: each begins in the last
// one's eigenvectors, every 64th from the identity), not on the stack. Measured on the
// targets by bench/target_bench.cpp (docs/figures.md, "The side
// learners").
// No allocation, every loop bounded.
#pragma once

#include <cstddef>
#include <cstdint>

#include "../core/correct.hpp"
#include "../core/quaternion.hpp"
#include "../core/status.hpp"
#include "../core/sun_term.hpp"
#include "../nav/sun_direction.hpp"
#include "estimator_types.hpp"
#include "orbit_spread_scores.hpp"
#include "portable_math.hpp"
#include "sun_moments.hpp"

namespace ascorr::calib {

// The learner's margin on the scores (mean squares): fit's on the RMS, doubled.
inline constexpr double kSunLearnMargin = 2.0 * kSunSelectionMargin;
// The DPU's interval for the learner (µs; above). The missions that measured
// the term have an epoch every 120 to 240 s, and 47 epochs in a 94-min orbit
// hold its variation inside the orbit.
inline constexpr std::int64_t kSunLearnOnBoardIntervalUs = 120'000'000;

// Which cycles the learner takes (above): with an interval (µs, > 0; any
// other value: none), due() unless the cycle's interval is the last one
// marked (then counted as thinned), mark() once a cycle was looked at;
// without an interval, every one.
class SunLearnThinning {
public:
    explicit SunLearnThinning(std::int64_t interval_us = 0) noexcept
        : interval_us_(interval_us > 0 ? interval_us : 0) {}
    bool due(std::int64_t t_us) noexcept {
        if (interval_us_ != 0 && any_ && orbit_bin(t_us, interval_us_) == interval_) {
            ++thinned_;
            return false;
        }
        return true;
    }
    void mark(std::int64_t t_us) noexcept {
        any_ = true;
        interval_ = interval_us_ != 0 ? orbit_bin(t_us, interval_us_) : 0;
    }
    std::uint64_t thinned() const noexcept { return thinned_; }

private:
    std::int64_t interval_us_;   // 0: every cycle
    bool any_ = false;           // a cycle marked (interval_)
    std::int64_t interval_ = 0;  // the interval of the last one
    std::uint64_t thinned_ = 0U;
};

struct SunLearnReport {
    std::uint32_t orbits = 0;       // orbits scored
    std::uint64_t cycles = 0;       // cycles scored
    double score[2] = {};           // forgotten sums of squares: the polynomial alone, with the candidate (arcsec²)
    double gain = 0.0;              // 1 − score[1]/score[0] (0 before any orbit)
    double rms_arcsec = 0.0;        // the polynomial's spread inside the orbit, RMS per pair and cycle
    bool deciding = false;          // the scores hold a memory's orbits: the rule applies
    double orbits_held = 0.0;       // their forgotten count of orbits
    double orbits_to_decide = 0.0;  // ... that the rule needs
    bool taken = false;             // the term is taken
    SunTermFit candidate;           // the latest solution (its rank, orbits, epochs)
    std::uint64_t without_sun = 0;  // cycles not taken: t outside the Sun ephemeris' span
    std::uint64_t not_finite = 0;   // cycles not taken: an attitude that is not finite
    std::uint64_t thinned = 0;      // cycles not taken: their interval had one (thinned)
    std::uint64_t late = 0;         // cycles looked at (not thinned) with a solve idle time had not finished (settle)
    int late_steps = 0;             // ... the most steps one of them ran
};

class SunLearner {
public:
    static constexpr std::size_t kPairs = OrbitSpreadScores<2>::kPairs;

    // cfg as the estimator accepted it (configuration_acceptable); its
    // common_rotation weights (none: the smallest coefficients) are the rule.
    // interval_us: take one cycle per interval (the DPU's,
    // kSunLearnOnBoardIntervalUs); 0, every one (the ground's).
    explicit SunLearner(const EstimatorConfig& cfg, std::int64_t interval_us = 0) noexcept
        : scores_(cfg),
          moments_(kFrameHeadIndices, kFrameHeads, 0U, 2U),
          weights_(cfg.common_rotation),
          thinning_(interval_us) {
        if (weights_.heads != 0U) {
            rule_.weight = weights_.a;
        }
    }
    SunLearner(const SunLearner&) = delete;  // rule_ points into weights_
    SunLearner& operator=(const SunLearner&) = delete;

    // One fed cycle at t_us (TT µs since J2000): q[h] the frame heads'
    // attitudes corrected by the active polynomial. false: not taken (t
    // outside the Sun ephemeris' span, or attitudes that give no finite
    // rotation; counted), or thinned (its interval had a cycle: counted,
    // and nothing else done). First the solve under way is settled (settle());
    // then a cycle of another orbit than the open one closes it (its solve
    // then waits for step()).
    bool take(std::int64_t t_us, const Quaternion<double> (&q)[kFrameHeads]) noexcept {
        if (!thinning_.due(t_us)) {
            return false;
        }
        thinning_.mark(t_us);
        (void)settle();
        if (scores_.closes(t_us)) {
            close_orbit(scores_.open_bin());
        }
        if (scores_.begin(t_us)) {
            reconsider();
        }
        Vector3<double> s_icrf{};
        if (!nav::sun_direction_icrf(static_cast<double>(t_us) * 1e-6, s_icrf)) {
            ++without_sun_;
            return false;
        }
        Quaternion<double> by_head[kMaxHeads]{};
        for (std::size_t h = 0; h < kFrameHeads; ++h) {
            by_head[h] = q[h];
        }
        if (!moments_.add(by_head, s_icrf)) {
            ++not_finite_;
            return false;
        }
        double iba[2][kPairs];
        frame_ibas(q, iba[0]);
        Quaternion<double> with_term[kFrameHeads];
        for (std::uint8_t h = 0; h < kFrameHeads; ++h) {
            with_term[h] = with_sun_term(q[h], sun_term_rotation(candidate_model_, h, q[h], s_icrf));
        }
        frame_ibas(with_term, iba[1]);
        scores_.add(iba);
        return true;
    }

    // A fed cycle's frame heads as the epoch pipeline kept them
    // (kept_solutions(), in T) into take(), in double, when the polynomial
    // corrected every one (otherwise they are not its residual: false, and
    // nothing counted). What the link server and the ground's run without a
    // lag search take.
    template <typename T>
    bool take_kept(std::int64_t t_us, const CorrectedSolution<T>* kept) noexcept {
        Quaternion<double> q[kFrameHeads];
        return frame_heads_of(kept, q) && take(t_us, q);
    }
    // take_kept's conversion (for a caller whose take() is out of line): the
    // kept frame heads in double; false when the polynomial did not correct
    // every one.
    template <typename T>
    static bool frame_heads_of(const CorrectedSolution<T>* kept, Quaternion<double> (&q)[kFrameHeads]) noexcept {
        for (std::size_t h = 0; h < kFrameHeads; ++h) {
            if ((kept[h].status & status::kThermalApplied) == 0U) {
                return false;
            }
            q[h] = in_double(kept[h].q_chu_icrf);
        }
        return true;
    }

    // The most step() calls one solve takes (sun_moments.hpp's solve_step).
    static constexpr int kMaxSolveSteps = SunMoments<kFrameHeads>::kMaxSolveSteps;

    // The per-orbit work, in idle time after a cycle (take) closed an orbit:
    // the candidate solved again from the sums, one bounded step of the
    // solve per call (sun_moments.hpp's solve_step: the normal equations,
    // 8 lines of the change to the last solve's basis, one row of a Jacobi
    // sweep, or the result), at most kMaxSolveSteps per
    // solve, with the sums as they were when it began. Its candidate is put
    // to use by the next settle() (the next cycle taken), not here, so that
    // when idle time ran the steps changes nothing. false: nothing pending.
    bool step() noexcept {
        if (!solving_) {
            if (!solve_pending_) {
                return false;
            }
            solve_pending_ = false;
            solving_ = true;
        }
        const SunSolveStep s = moments_.solve_step(solve_, rule_);
        if (s == SunSolveStep::kRunning) {
            return true;
        }
        solving_ = false;
        solved_ = s == SunSolveStep::kSolved && sun_fit_within_domain(solve_.fit);
        return true;
    }

    // The solve under way (or pending) run to its end and its candidate put
    // to use: what take() does first, before its cycle can close another
    // orbit, so that the candidate a cycle is scored with and a model takes
    // is the solve of the orbits closed before the last cycle taken,
    // whatever idle time did (the ground's run, the link's and the flight
    // loop's alike). Where idle time had not finished it, the rest runs
    // here (counted: report().late, late_steps). Returns the steps it ran.
    // Out of line: take()'s frame stays a cycle's, the solve's frames are
    // a step's.
    [[gnu::noinline]] int settle() noexcept {
        int n = 0;
        while (n < 2 * kMaxSolveSteps && step()) {
            ++n;
        }
        if (solved_) {
            candidate_ = solve_.fit;
            candidate_model_ = sun_term_model(solve_.fit);
            solved_ = false;
        }
        if (n > 0) {
            ++late_;
            late_steps_ = n > late_steps_ ? n : late_steps_;
        }
        return n;
    }

    // step() until nothing is pending (at most kMaxSolveSteps per solve: the
    // one begun, and one pending): what idle time does after each cycle on
    // the ground (its candidate in use from the next cycle taken: settle()).
    // false: nothing was.
    bool step_all() noexcept {
        bool any = false;
        for (int i = 0; i < 2 * kMaxSolveSteps && step(); ++i) {
            any = true;
        }
        return any;
    }

    // Closes the open orbit (the end of the data), its solve included.
    void finish() noexcept {
        (void)settle();  // as take(): the solve before the last orbit's close in use first
        if (scores_.open()) {
            close_orbit(scores_.open_bin());
        }
        (void)step_all();
        (void)settle();
        if (scores_.finish()) {
            reconsider();
        }
    }

    // The term taken (arcsec by head), or nullptr: none.
    const SunTermFit* taken() const noexcept { return taken_ ? &candidate_ : nullptr; }

    // The term a model version takes as it becomes active (docs/contract.md,
    // "The Sun term learnt in self-calibration"): the term taken, for the
    // heads of `heads` (bit h: head h, those the version has), into out
    // (arcsec, indexable as SunTermFit::sun); 0 elsewhere and when none is.
    template <typename Out>
    void version_term(HeadMask heads, Out& out) const noexcept {
        for (auto& head : out) {
            for (auto& axis : head) {
                for (double& c : axis) {
                    c = 0.0;
                }
            }
        }
        if (taken_) {
            copy_sun_coefficients(candidate_, heads, out);
        }
    }

    SunLearnReport report() const noexcept {
        SunLearnReport r;
        r.orbits = scores_.orbits();
        r.cycles = scores_.cycles();
        r.score[0] = scores_.score()[0];
        r.score[1] = scores_.score()[1];
        if (r.score[0] > 0.0) {
            r.gain = (r.score[0] - r.score[1]) / r.score[0];
        }
        if (scores_.weight() > 0.0) {
            r.rms_arcsec = std::sqrt(r.score[0] / scores_.weight());
        }
        r.deciding = scores_.deciding();
        r.orbits_held = scores_.orbits_held();
        r.orbits_to_decide = scores_.orbits_to_decide();
        r.taken = taken_;
        r.candidate = candidate_;
        r.without_sun = without_sun_;
        r.not_finite = not_finite_;
        r.thinned = thinning_.thinned();
        r.late = late_;
        r.late_steps = late_steps_;
        return r;
    }

    // The rule (above): whether the term is taken after `taken`, given the
    // scores (the polynomial's, the candidate's).
    static constexpr bool next_taken(const double (&score)[2], bool taken) noexcept {
        return taken ? !(score[0] < (1.0 - kSunLearnMargin) * score[1]) : score[1] < (1.0 - kSunLearnMargin) * score[0];
    }

private:
    static constexpr std::uint8_t kFrameHeadIndices[kFrameHeads] = {0U, 1U, 2U};

    // The open orbit (bin: the scores' open one) into the moments (the older
    // ones forgotten over the time since the last closed), the candidate to
    // be solved again (step).
    void close_orbit(std::int64_t bin) noexcept {
        if (moments_.open_count() == 0U) {
            return;
        }
        const double keep = closed_any_
                                ? exp_nonpositive(-static_cast<double>(bin - last_closed_bin_) *
                                                  static_cast<double>(scores_.period_us()) / scores_.memory_us())
                                : 1.0;
        moments_.close_orbit(keep);
        closed_any_ = true;
        last_closed_bin_ = bin;
        solve_pending_ = true;
    }

    void reconsider() noexcept {
        if (scores_.deciding() && candidate_.solved) {
            taken_ = next_taken(scores_.score(), taken_);
        }
    }

    OrbitSpreadScores<2> scores_;
    SunMoments<kFrameHeads> moments_;
    CommonRotationWeights weights_;
    SunRule rule_{};
    bool closed_any_ = false;
    std::int64_t last_closed_bin_ = 0;
    SunTermFit candidate_{};
    SunTermModel<double> candidate_model_{};
    SunMoments<kFrameHeads>::Solve solve_{};  // the solve's workspace (step)
    bool solving_ = false;                    // a solve begun (solve_)
    bool solve_pending_ = false;
    bool solved_ = false;  // solve_.fit holds a candidate not yet in use (settle)
    std::uint64_t late_ = 0U;
    int late_steps_ = 0;
    bool taken_ = false;
    std::uint64_t without_sun_ = 0U;
    std::uint64_t not_finite_ = 0U;
    SunLearnThinning thinning_;
};

}  // namespace ascorr::calib
