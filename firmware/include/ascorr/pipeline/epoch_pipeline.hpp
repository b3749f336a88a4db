// ascorr/pipeline/epoch_pipeline.hpp: one epoch's solutions through every
// stage, in one order, for every caller.
//
// Conventions: an epoch is one time tag on the on-board clock (TT µs; the
// flight loop: one cycle). Its solutions, of any heads in any order, go
// through a fixed list of stages:
//   0. lag       (use_lags; each solution): a lagged head's temperatures as
//                its terms take them, stepped at the epoch's time
//                (head_lags.hpp); a solution with no time has none;
//   1. model     (begin(), at the epoch's first solution): the thermal model of
//                the whole epoch: a fixed one (use_model), or the one the
//                on-board estimator holds active (use_estimator; a new model
//                becomes active here, between epochs, never within one);
//                with the fixed model's Sun term (use_sun_term), the Sun's
//                direction at the epoch's time (nav/sun_direction.hpp, in
//                double, once per epoch, outside the meter as the velocity
//                service's advance is);
//   2. velocity  (the caller's source: given_velocity or from_service,
//                solution_stage.hpp);
//   3. correction and 4. status (correct_stage(), solution_stage.hpp, then
//                the caller's own bits: Calls::status); with the fixed
//                model's Sun term, the core's flight form
//                (correct_solution(in, cfg, sun), core/correct.hpp), the
//                term folded into its thermal stage; while calibrating, the
//                active version's Sun term (use_sun_term) is applied after
//                stage 5 took the solution, in the contract's form
//                (with_sun_term, core/sun_term.hpp), to what is returned
//                and combined: the feed and what learns beside it take the
//                polynomial's correction, as on the ground;
//   5. estimator feed: the first clean, usable solution of each of the
//                calibrated heads is kept; when A, B and C are there and the
//                epoch is one the schedule feeds (every feed_every-th), they
//                feed the estimator with the further heads kept so far
//                (calib::feed_estimator) and its per-orbit update runs
//                steps_after_feed bounded steps; a further head that comes
//                after them is fed alone into the same cycle
//                (calib::feed_estimator_head); idle() runs one more step;
//   6. combination (use_combiner; close()): the corrected solutions since the
//                last close() (the caller's epoch of the bench: a flight
//                cycle, the host's millisecond epoch) combined into the
//                attitude of the common reference frame (combine/combiner.hpp),
//                each head usable or not by combine/usable.hpp.
// The link server, the flight loop, the host's self-calibration run and
// replay's host side all drive this class, so they take the same decisions
// in the same order; `ascorr correct` (rows in any order, on many threads)
// calls the stages 2–4 alone (correct_stage).
//
// Calls: the out-of-line entries a flight image measures alone (the flight
// loop's core_entry.hpp, calib_entry.hpp); InlineCalls is the library's.
// Meter: sees each stage's work, never changes it (now(), add(Stage, start)).
// Bounded and allocation-free: no loop but over the calibrated heads and the
// steps_after_feed steps.
#pragma once

#include <cstdint>
#include <type_traits>
#include <utility>

#include "../calib/estimator.hpp"
#include "../calib/feed.hpp"
#include "../combine/combined_status.hpp"
#include "../combine/combiner.hpp"
#include "../combine/usable.hpp"
#include "../core/correct.hpp"
#include "../core/sun_term.hpp"
#include "../nav/sun_direction.hpp"
#include "../nav/tt_time.hpp"
#include "head_lags.hpp"
#include "solution_stage.hpp"

namespace ascorr::pipeline {

enum class Stage : std::uint8_t { kLag, kModel, kVelocity, kCorrect, kFeed, kStep, kCombine };

struct NoMeter {
    std::uint32_t now() noexcept { return 0U; }
    void add(Stage /*stage*/, std::uint32_t /*start*/) noexcept {}
};

template <typename T>
struct InlineCalls {
    template <std::size_t N>
    static const ThermalModel<T>* model_for_epoch(calib::Estimator<T, N>& e, std::int64_t t_us) noexcept {
        return e.model_for_cycle(t_us);
    }
    static CorrectedSolution<T> correct(const SolutionInput<T>& in, const CorrectionConfig<T>& cfg) noexcept {
        return correct_solution(in, cfg);
    }
    static CorrectedSolution<T> correct(const SolutionInput<T>& in, const CorrectionConfig<T>& cfg,
                                        const SunTermInput<T>& sun) noexcept {
        return correct_solution(in, cfg, sun);
    }
    template <std::size_t N>
    static bool feed(calib::Estimator<T, N>& e, std::int64_t t_us, const ThermalModel<T>* model,
                     const CorrectedSolution<T>* corrected, const HeadTemperatures<T>* const* temperatures,
                     std::uint8_t further) noexcept {
        return calib::feed_estimator(e, t_us, model, corrected, temperatures, further);
    }
    template <std::size_t N>
    static bool feed_head(calib::Estimator<T, N>& e, std::uint8_t h, std::int64_t t_us, const ThermalModel<T>* model,
                          const CorrectedSolution<T>& corrected, const HeadTemperatures<T>& temperatures) noexcept {
        return calib::feed_estimator_head(e, h, t_us, model, corrected, temperatures);
    }
    template <std::size_t N>
    static bool step(calib::Estimator<T, N>& e) noexcept {
        return e.step();
    }
    static combine::CombinedAttitude<T> combine(const combine::Combiner<T>& c, const combine::HeadAttitude<T>* heads,
                                                std::uint8_t n) noexcept {
        return c.combine(heads, n);
    }
    // The caller's own status bits for head `head` (none here).
    static StatusBits status(std::uint8_t /*head*/, StatusBits s) noexcept { return s; }
};

// Whether Calls has the core's flight form with a Sun term
// (Calls::correct(in, cfg, sun)): a pipeline whose Calls has none compiles
// without the term's stage (the link's and the flight loop's have it).
template <typename Calls, typename T, typename = void>
struct TakesSunTerm : std::false_type {};
template <typename Calls, typename T>
struct TakesSunTerm<Calls, T,
                    std::void_t<decltype(Calls::correct(std::declval<const SolutionInput<T>&>(),
                                                        std::declval<const CorrectionConfig<T>&>(),
                                                        std::declval<const SunTermInput<T>&>()))>> : std::true_type {};

// Which epochs feed the estimator, and how much of its per-orbit update runs
// right after a feed (the rest: idle()).
struct FeedSchedule {
    std::uint32_t feed_every = 1U;
    int steps_after_feed = calib::Estimator<double>::kPhases;
};

// N: the heads the estimator learns (estimator.hpp).
template <typename T, typename Calls = InlineCalls<T>, std::size_t N = calib::kCalibHeads>
class EpochPipeline {
public:
    explicit EpochPipeline(FeedSchedule schedule = {}) noexcept : schedule_(schedule) {}

    // The model stage's source: a fixed model for every epoch (nullptr: no
    // thermal stage) ...
    void use_model(const ThermalModel<T>* model) noexcept {
        estimator_ = nullptr;
        fixed_ = model;
        forget();
    }
    // ... or the estimator's active model (none yet: no head has
    // coefficients, status 256), which then learns from the epochs.
    void use_estimator(calib::Estimator<T, N>* e) noexcept {
        estimator_ = e;
        forget();
    }
    // Forgets the current epoch (a restarted estimator).
    void forget() noexcept {
        have_epoch_ = false;
        kept_ = 0U;
        epochs_ = 0U;
        model_ = nullptr;
    }

    bool calibrating() const noexcept { return estimator_ != nullptr; }

    // The Sun term (nullptr: none; the coefficients within the term's
    // domain, as the link's decode and the learner check): with the fixed
    // model, its term (keep_present_where_terms holds), folded into the
    // thermal stage of the heads that have one; while calibrating, the
    // active version's (the caller's, set at each new version: the term the
    // learner had taken, calib/sun_learner.hpp), applied after the feed in
    // the contract's form (stage 3 above). The Sun's direction is that of
    // the current epoch's time, if any.
    void use_sun_term(const SunTermModel<T>* sun) noexcept {
        static_assert(kTakesSunTerm, "Calls::correct(in, cfg, sun) evaluates the term");
        sun_ = sun;
        if (have_epoch_) {
            form_sun_direction();
        }
    }

    // Stage 0's lags (nullptr, or none of its heads lagging: no lag stage;
    // call again after configuring them).
    void use_lags(HeadLags<T>* lags) noexcept { lags_ = lags != nullptr && lags->any() ? lags : nullptr; }

    // Whether a solution of `head` goes through an epoch (begin(), then
    // solution()) or, with no time (`timed` false), untimed_solution(): a
    // solution with no time belongs to no epoch while calibrating, nor when
    // its head lags (it has no lagged temperatures), nor when its head has a
    // Sun term folded in (it has no Sun direction: 128); otherwise it takes
    // the fixed model in the epoch its caller gives it.
    bool in_epoch(std::uint8_t head, bool timed) const noexcept {
        return timed || (!calibrating() && (lags_ == nullptr || !lags_->lags(head)) && !sun_folded(head));
    }

    // Stage 6's combiner (nullptr: no combination); forgets the solutions
    // not combined yet.
    void use_combiner(const combine::Combiner<T>* c) noexcept {
        combiner_ = c;
        combined_n_ = 0U;
        overflow_ = false;
    }
    const combine::Combiner<T>* combiner() const noexcept { return combiner_; }

    // Stage 6: the solutions since the last close() combined (use_combiner
    // came first: without a combiner, no head, status 8). More solutions than
    // kCombineSlots in one epoch: the rest are left out (bit 4).
    template <typename Meter = NoMeter>
    combine::CombinedAttitude<T> close(Meter& meter) noexcept {
        combine::CombinedAttitude<T> r{};
        if (combiner_ == nullptr) {
            constexpr T one = constant<T>(1.0);
            constexpr T zero = constant<T>(0.0);
            r.q_crf_icrf = {one, zero, zero, zero};
            r.status = combine::combined_status::kNoHead;
            return r;
        }
        const std::uint32_t start = meter.now();
        r = Calls::combine(*combiner_, combined_, combined_n_);
        meter.add(Stage::kCombine, start);
        if (overflow_) {
            r.status = static_cast<combine::CombinedStatus>(r.status | combine::combined_status::kHeadLeftOut);
        }
        combined_n_ = 0U;
        overflow_ = false;
        return r;
    }
    combine::CombinedAttitude<T> close() noexcept {
        NoMeter m;
        return close(m);
    }

    // Stage 1: epoch t_us, unless it is the current one; its model.
    template <typename Meter = NoMeter>
    const ThermalModel<T>* begin(std::int64_t t_us, Meter& meter) noexcept {
        if (have_epoch_ && t_us == t_us_) {
            return model_;
        }
        if (have_epoch_) {
            ++epochs_;
        }
        have_epoch_ = true;
        t_us_ = t_us;
        kept_ = 0U;
        form_sun_direction();
        if (estimator_ == nullptr) {
            model_ = fixed_;
            return model_;
        }
        const std::uint32_t start = meter.now();
        model_ = Calls::model_for_epoch(*estimator_, t_us);
        version_ = estimator_->active_version();
        meter.add(Stage::kModel, start);
        return model_;
    }
    const ThermalModel<T>* begin(std::int64_t t_us) noexcept {
        NoMeter m;
        return begin(t_us, m);
    }

    // The current epoch's model (nullptr: none) and, calibrating, its version.
    const ThermalModel<T>* model() const noexcept { return model_; }
    std::uint32_t version() const noexcept { return version_; }
    // Epochs that fed the estimator so far (wraps at 2^32).
    std::uint32_t feeds() const noexcept { return feeds_; }
    // The current epoch's solutions and temperatures kept for the feed, by
    // head (the frame heads' are those fed once feeds() grew in this epoch):
    // for what learns beside the estimator (calib/lag_search.hpp).
    const CorrectedSolution<T>* kept_solutions() const noexcept { return solutions_; }
    const HeadTemperatures<T>* kept_temperatures() const noexcept { return temperatures_; }

    // Stages 0 and 2–5 for one solution of the current epoch (begin() came first).
    // `velocity` () → VelocityAnswer<T>; `clean`: the source's selection
    // (flags, confidence) lets it feed the estimator.
    template <typename Velocity, typename Meter = NoMeter>
    CorrectedSolution<T> solution(SolutionInput<T> in, Velocity&& velocity, bool clean, bool aberration,
                                  Meter& meter) noexcept {
        std::uint32_t start = 0U;
        if (lags_ != nullptr) {
            start = meter.now();
            lags_->apply(in.head, t_us_, in.temperatures);
            meter.add(Stage::kLag, start);
        }
        start = meter.now();
        const VelocityAnswer<T> v = velocity();
        meter.add(Stage::kVelocity, start);
        take_velocity(in, v);
        const CorrectionConfig<T> cfg = config(aberration);
        start = meter.now();
        CorrectedSolution<T> c = correct(in, cfg, sun_known_);
        meter.add(Stage::kCorrect, start);
        c.status = Calls::status(in.head, status_stage(c.status, v, cfg.aberration));
        if (estimator_ != nullptr && clean) {
            keep(in.head, c, in.temperatures, meter);
        }
        if constexpr (kTakesSunTerm) {
            if (sun_after()) {
                c = with_version_term(in, cfg, v, c);
            }
        }
        if (combiner_ != nullptr) {
            to_combine(in.head, c, clean);
        }
        return c;
    }
    template <typename Velocity>
    CorrectedSolution<T> solution(const SolutionInput<T>& in, Velocity&& velocity, bool clean,
                                  bool aberration = true) noexcept {
        NoMeter m;
        return solution(in, velocity, clean, aberration, m);
    }

    // A solution that belongs to no epoch (no time tag, in_epoch false):
    // corrected without a model when calibrating (status 256), without
    // temperatures when its head lags (status 8), never fed nor combined.
    template <typename Velocity>
    CorrectedSolution<T> untimed_solution(SolutionInput<T> in, Velocity&& velocity, bool aberration = true) noexcept {
        if (lags_ != nullptr) {
            lags_->without_time(in.head, in.temperatures);
        }
        const CorrectionConfig<T> cfg{aberration, estimator_ != nullptr ? &kNoModel : fixed_};
        CorrectedSolution<T> c = correct_stage(in, velocity(), cfg, CallsCorrect{this});
        c.status = Calls::status(in.head, c.status);
        return c;
    }

    // One step of the estimator's per-orbit update, in idle time.
    template <typename Meter = NoMeter>
    bool idle(Meter& meter) noexcept {
        const std::uint32_t start = meter.now();
        if (estimator_ == nullptr || !Calls::step(*estimator_)) {
            return false;
        }
        meter.add(Stage::kStep, start);
        return true;
    }

private:
    static constexpr bool kTakesSunTerm = TakesSunTerm<Calls, T>::value;

    // Whether the fixed model's Sun term is folded in (never without
    // kTakesSunTerm), and for head h, whether h has one.
    bool sun_folded() const noexcept { return kTakesSunTerm && sun_ != nullptr && estimator_ == nullptr; }
    bool sun_folded(std::uint8_t h) const noexcept { return sun_folded() && h < kMaxHeads && sun_->present[h]; }
    // Whether the active version's Sun term is applied after the feed.
    bool sun_after() const noexcept { return kTakesSunTerm && sun_ != nullptr && estimator_ != nullptr; }

    // The version's term on c (correct_stage_with_sun's contract form, the
    // host's): where the thermal stage applied and the head has a term, c
    // turned by it with ŝ the epoch's; where ŝ is unknown, the stage undone
    // (the aberration's result: the core again without a model) and 128.
    CorrectedSolution<T> with_version_term(const SolutionInput<T>& in, const CorrectionConfig<T>& cfg,
                                           const VelocityAnswer<T>& v, CorrectedSolution<T> c) const noexcept {
        if ((c.status & status::kThermalApplied) == 0U || in.head >= kMaxHeads || !sun_->present[in.head]) {
            return c;
        }
        if (!sun_known_) {
            c = Calls::correct(in, CorrectionConfig<T>{cfg.aberration, nullptr});
            c.status = Calls::status(
                in.head,
                status_stage(static_cast<StatusBits>(c.status | status::kThermalOutOfRange), v, cfg.aberration));
            return c;
        }
        c.q_chu_icrf = with_sun_term(c.q_chu_icrf, sun_term_rotation(*sun_, in.head, c.q_chu_icrf, sun_s_));
        return c;
    }

    // Stage 3: the core, or its flight form where the fixed model has a Sun
    // term; known: ŝ is the epoch's (a solution in no epoch has none: a head
    // with a term then gets 128, as the contract's form gives it).
    CorrectedSolution<T> correct(const SolutionInput<T>& in, const CorrectionConfig<T>& cfg,
                                 bool known) const noexcept {
        if constexpr (kTakesSunTerm) {
            if (sun_folded()) {
                return Calls::correct(in, cfg, SunTermInput<T>{sun_, sun_s_, known});
            }
        }
        return Calls::correct(in, cfg);
    }

    // Stage 1's Sun direction at t_us_, in T; none outside its span.
    void form_sun_direction() noexcept {
        if constexpr (kTakesSunTerm) {
            Vector3<double> s{};
            sun_known_ = sun_ != nullptr && nav::sun_direction_icrf(tt_seconds(TtTime{t_us_}), s);
            using S = ScalarTraits<T>;
            sun_s_ = {S::from_double(s.x), S::from_double(s.y), S::from_double(s.z)};
        }
    }

    struct CallsCorrect {
        const EpochPipeline* pipeline;
        CorrectedSolution<T> operator()(const SolutionInput<T>& in, const CorrectionConfig<T>& cfg) const noexcept {
            return pipeline->correct(in, cfg, false);
        }
    };

    // No coefficients for any head: the estimator has no model yet (256).
    static constexpr ThermalModel<T> kNoModel{};

    CorrectionConfig<T> config(bool aberration) const noexcept {
        if (estimator_ == nullptr) {
            return {aberration, fixed_};
        }
        return {aberration, model_ != nullptr ? model_ : &kNoModel};
    }

    // Stage 6's input: every solution, usable or not (the combiner accounts
    // for each one it is given).
    void to_combine(std::uint8_t head, const CorrectedSolution<T>& c, bool clean) noexcept {
        if (combined_n_ == kCombineSlots) {
            overflow_ = true;
            return;
        }
        combined_[combined_n_] = {c.q_chu_icrf, head, combine::usable_for_combination(c.status, clean)};
        ++combined_n_;
    }

    // Stage 5: the first clean, usable solution of each calibrated head; the
    // feed when A, B and C are there (with the further heads kept so far), on
    // the schedule's epochs; a further head that comes after it, alone.
    template <typename Meter>
    void keep(std::uint8_t h, const CorrectedSolution<T>& c, const HeadTemperatures<T>& tp, Meter& meter) noexcept {
        if (!have_epoch_ || h >= N || (kept_ & (1U << h)) != 0U || !calib::feeds_estimator(c, tp)) {
            return;
        }
        if ((kept_ & kFed) != 0U) {
            if constexpr (N > calib::kFrameHeads) {
                keep_late(h, c, tp, meter);
            }
            return;
        }
        solutions_[h] = c;
        temperatures_[h] = tp;
        kept_ = static_cast<std::uint8_t>(kept_ | (1U << h));
        if ((kept_ & calib::kFrameMask) != calib::kFrameMask) {
            return;
        }
        kept_ = static_cast<std::uint8_t>(kept_ | kFed);
        fed_ = false;
        if (epochs_ % schedule_.feed_every != 0U) {
            return;
        }
        const std::uint32_t start = meter.now();
        const HeadTemperatures<T>* t[N];
        for (std::size_t k = 0; k < N; ++k) {
            t[k] = &temperatures_[k];
        }
        fed_ = Calls::feed(*estimator_, t_us_, model_, solutions_, t,
                           static_cast<std::uint8_t>(kept_ & ~(kFed | calib::kFrameMask)));
        feeds_ += fed_ ? 1U : 0U;
        meter.add(Stage::kFeed, start);
        for (int i = 0; i < schedule_.steps_after_feed && Calls::step(*estimator_); ++i) {
        }
    }

    // A further head after the epoch's feed: into the same cycle's sums.
    template <typename Meter>
    void keep_late(std::uint8_t h, const CorrectedSolution<T>& c, const HeadTemperatures<T>& tp,
                   Meter& meter) noexcept {
        kept_ = static_cast<std::uint8_t>(kept_ | (1U << h));
        if (!fed_) {
            return;
        }
        const std::uint32_t start = meter.now();
        (void)Calls::feed_head(*estimator_, h, t_us_, model_, c, tp);
        meter.add(Stage::kFeed, start);
    }

    static constexpr std::uint8_t kFed = 0x80U;
    static_assert(N < 8U, "kept_ holds a bit per head below kFed");
    // Two solutions of every head: room for a repeated head, whose second
    // solution the combiner leaves out.
    static constexpr std::uint8_t kCombineSlots = 2U * kMaxHeads;

    FeedSchedule schedule_;
    HeadLags<T>* lags_ = nullptr;
    const ThermalModel<T>* fixed_ = nullptr;
    calib::Estimator<T, N>* estimator_ = nullptr;
    bool have_epoch_ = false;
    std::int64_t t_us_ = 0;
    std::uint32_t epochs_ = 0U;  // epochs begun before the current one
    std::uint8_t kept_ = 0U;     // bit h: head h kept; kFed: the epoch is done with the feed
    bool fed_ = false;           // the epoch's cycle fed the estimator (kFed set)
    const ThermalModel<T>* model_ = nullptr;
    std::uint32_t version_ = 0U;
    std::uint32_t feeds_ = 0U;
    CorrectedSolution<T> solutions_[N]{};
    HeadTemperatures<T> temperatures_[N]{};
    const combine::Combiner<T>* combiner_ = nullptr;
    combine::HeadAttitude<T> combined_[kCombineSlots]{};
    std::uint8_t combined_n_ = 0U;
    bool overflow_ = false;
    // Last, so that a Calls without the Sun term keeps the other members'
    // offsets, hence its code.
    const SunTermModel<T>* sun_ = nullptr;
    Vector3<T> sun_s_{};      // the Sun's direction at t_us_ (use_sun_term)
    bool sun_known_ = false;  // sun_s_ was formed
};

}  // namespace ascorr::pipeline
