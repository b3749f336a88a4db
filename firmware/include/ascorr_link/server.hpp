// ascorr_link/server.hpp: the target's end of the link (DPU firmware).
//
// LinkServer<T> owns the correction state a DPU keeps between solutions: the
// thermal model per head, the last observer velocity and each head's last
// temperatures. It takes received bytes one at a time and hands each response
// frame to a sink. Requests and answers:
//   kHelloRequest      → kHello
//   kModelUpload       → kAck (kBadPayload for a bad head, length or lag, or
//                        a lag while the estimator runs); with a lag τ, the
//                        head's temperatures go through the lag stage from
//                        then on, its lag started afresh (pipeline/head_lags.hpp);
//                        while the estimator runs, the lags stay kCalibStart's;
//                        the head's Sun term ends (kSunTermUpload gives the
//                        new model's)
//   kSunTermUpload     → kAck (kBadPayload for a bad head, length or word, or
//                        while the estimator runs): the head's Sun term,
//                        folded into the uploaded model's thermal stage with
//                        the Sun's direction at each epoch's time (the
//                        epoch pipeline's stage 1); all 0: none
//   kVelocityUpdate    → kAck
//   kTemperatureUpdate → kAck
//   kStateUpdate       → kAck (the state goes to the velocity service, which
//                        may refuse it: velocity_service.hpp)
//   kSolutionIn        → kSolutionOut (corrected by correct_solution<T>, with
//                        the last velocity update or, if from_states, the
//                        service's velocity at the solution's time tag; a
//                        lagged head's solution flagged kCalibNoTime has no
//                        lagged temperatures: status 8)
//   kServiceConfig     → kAck: the velocity service restarts with the horizon
//                        (its states are dropped)
//   kCalibStart        → kAck: from then on the estimator (calib/estimator.hpp),
//                        with its lags (each head's lag started afresh, or
//                        none: a MODEL_UPLOAD's lag ends),
//                        runs on the solutions through the epoch pipeline
//                        (pipeline/epoch_pipeline.hpp says which solutions
//                        feed it and which model corrects an epoch). A
//                        solution flagged kCalibNoTime is corrected without
//                        a model. Before kCalibStart: the uploaded model.
//                        With common_rotation 1, the rule for the rotation
//                        common to all heads takes the weights of the
//                        mountings staged so far (kMountingLoad first).
//                        With sun_term 1, the Sun term's learner
//                        (calib/sun_learner.hpp, one cycle per
//                        kSunLearnOnBoardIntervalUs) takes the fed cycles'
//                        frame heads as the polynomial corrected them, and
//                        solves after each orbit closed, a few bounded
//                        steps after each answer and the rest, if any,
//                        when it next takes an epoch (SunLearner::settle);
//                        each model version takes the term taken when
//                        it becomes active, for the heads it has, applied to
//                        the answers after the feed (epoch_pipeline.hpp).
//   kCalibCommand      → kAck (freeze, resume, reset)
//   kCalibModelLoad    → kAck (a head staged; with `load`, the staged model
//                        becomes the estimator's, active from the next epoch)
//   kCalibReportRequest → kCalibReport (the estimator's report)
//   kCalibModelRequest → kCalibModel (one head of the active model)
//   kCalibSunTermRequest → kCalibSunTerm (one head's Sun term of the active
//                        model's version: kCalibStart's sun_term)
//   kStackReportRequest → kStackReport (StackProbe's: the image's stack
//                        high-water mark and size; 0, 0 unmeasured)
//   kSunLearnerReportRequest → kSunLearnerReport (the Sun learner's state:
//                        counts, scores, decision, its candidate's rank and
//                        CRC; zeros when kCalibStart's sun_term is 0)
//   kMountingLoad      → kAck (a head's mounting staged; with `build`, the
//                        staged mountings become the combiner's, refused with
//                        kBadPayload when not usable: combine::check_mountings)
//   kCombineRequest    → kCombined: the solutions corrected since the last
//                        request combined into the bench's attitude (the
//                        epoch pipeline's stage 6; without mountings built,
//                        status 8)
//   broken frame       → kNak with the FrameError, so the host resends at once
//   unknown type       → kAck kUnknownType
// A request whose sequence number equals the last one served is a duplicate
// (the host resent because a response was lost): the cached response is sent
// again and nothing is applied twice. kHelloRequest starts a host session and
// forgets the last sequence number. Every call is bounded; nothing allocates.
// A refused payload (kBadPayload) changes nothing.
#pragma once

#include <cstddef>
#include <cstdint>
#include <new>
#include <type_traits>

#include "ascorr/calib/estimator.hpp"
#include "ascorr/calib/sun_learner.hpp"
#include "ascorr/core/correct.hpp"
#include "ascorr/nav/velocity_service.hpp"
#include "ascorr/pipeline/common_rotation_weights.hpp"
#include "ascorr/pipeline/epoch_pipeline.hpp"
#include "ascorr/pipeline/version_sun_term.hpp"
#include "frame.hpp"
#include "messages.hpp"

namespace ascorr::link {

// The link's estimator and pipeline: every head of the core (kMaxHeads); A,
// B and C learn from the epochs they all pass the selection, a further head
// from those of them it passes too (calib/estimator_types.hpp), so a file of
// three heads takes the decisions of a three-head estimator.
template <typename T>
using LinkEstimator = calib::Estimator<T, kMaxHeads>;
template <typename T>
using LinkPipeline = pipeline::EpochPipeline<T, pipeline::InlineCalls<T>, kMaxHeads>;

// A server that does not measure its stack (StackProbe's default): 0, 0.
struct NoStackProbe {
    StackReport operator()() const noexcept { return {0U, 0U}; }
};

// CycleCounter: a callable returning a free-running std::uint32_t counter
// (SysTick or DWT on target), read around correct_solution(). StackProbe: a
// callable returning the image's StackReport (firmware/app/link_main.cpp's
// paints the stack; bounded).
template <typename T, typename CycleCounter, typename StackProbe = NoStackProbe>
class LinkServer {
public:
    LinkServer(std::uint32_t boot_id, CycleCounter counter) noexcept : boot_id_(boot_id), counter_(counter) {
        for (auto& t : temperatures_) {
            t = {};  // all readings invalid until the host sends them
        }
        velocity_.valid = false;
        pipeline_.use_model(&model_);
    }

    // Sends kHello unprompted (at boot), so the host learns of a restart.
    template <typename Sink>
    void announce(Sink&& sink) noexcept {
        send_hello(0, sink);
    }

    template <typename Sink>
    void on_byte(std::uint8_t b, Sink&& sink) noexcept {
        switch (decoder_.push(b)) {
            case FrameDecoder::Event::kNone:
                return;
            case FrameDecoder::Event::kError: {
                ++frame_errors_;
                std::uint8_t p[1] = {static_cast<std::uint8_t>(decoder_.error())};
                emit(MessageType::kNak, 0, p, 1, sink, false);
                return;
            }
            case FrameDecoder::Event::kFrame:
                serve(decoder_.frame(), sink);
                return;
        }
    }

    std::uint32_t frame_errors() const noexcept { return frame_errors_; }
    std::uint32_t duplicates() const noexcept { return duplicates_; }
    std::uint32_t solutions() const noexcept { return solutions_; }

private:
    template <typename Sink>
    void serve(const Frame& f, Sink& sink) noexcept {
        if (have_last_ && f.seq == last_seq_ && f.type != static_cast<std::uint8_t>(MessageType::kHelloRequest)) {
            ++duplicates_;
            sink(last_response_, last_response_n_);
            return;
        }
        switch (static_cast<MessageType>(f.type)) {
            case MessageType::kHelloRequest:
                have_last_ = false;  // a new host session: its sequence numbers start afresh
                send_hello(f.seq, sink);
                return;
            case MessageType::kModelUpload:
                // A lag is refused while the estimator runs: its lags are
                // kCalibStart's, which the ground run reproduces.
                update<ModelUpload<T>>(
                    f, sink, [this](const ModelUpload<T>& m) { upload_model(m); },
                    [this](const ModelUpload<T>& m) { return m.lag_s == 0.0 || !pipeline_.calibrating(); });
                return;
            case MessageType::kSunTermUpload:
                // The estimator's versions take the learnt term alone
                // (kCalibStart's sun_term): refused while it runs.
                update<SunTermUpload<T>>(
                    f, sink, [this](const SunTermUpload<T>& m) { set_sun_term(m.head, m.coefficient); },
                    [this](const SunTermUpload<T>&) { return !pipeline_.calibrating(); });
                return;
            case MessageType::kVelocityUpdate:
                // A velocity outside the core's domain (|v| > 1000 km/s, 1/s
                // outside [1/40, 1/0.6] au⁻¹, non-finite) is refused with
                // kBadPayload, and the velocity held so far is dropped: a
                // refused update must not leave an older one in use.
                if (!update<ObserverVelocity<T>>(
                        f, sink, [this](const ObserverVelocity<T>& v) { velocity_ = v; },
                        [](const ObserverVelocity<T>& v) { return !v.valid || velocity_in_domain(v); })) {
                    velocity_.valid = false;
                }
                return;
            case MessageType::kStateUpdate:
                update<StateUpdate>(f, sink, [this](const StateUpdate& m) {
                    service_.push_state(m.t, m.r_km, m.v_kms,
                                        m.reference_frame == 1U ? StateFrame::kGcrs : StateFrame::kItrf);
                });
                return;
            case MessageType::kTemperatureUpdate:
                update<TemperatureUpdate<T>>(
                    f, sink, [this](const TemperatureUpdate<T>& t) { temperatures_[t.head] = t.temperatures; });
                return;
            case MessageType::kCalibStart:
                update<CalibStart>(f, sink, [this](const CalibStart& m) { start_estimator(m); });
                return;
            case MessageType::kServiceConfig:
                update<ServiceConfig>(f, sink, [this](const ServiceConfig& m) {
                    new (&service_) VelocityService<T>(velocity_service_config(m.horizon_us));
                });
                return;
            case MessageType::kCalibModelRequest:
                reply(
                    f, f.length == 1U && f.payload[0] < kMaxHeads, MessageType::kCalibModel,
                    [this, &f] { return active_model(f.payload[0]); }, sink);
                return;
            case MessageType::kCalibSunTermRequest:
                reply(
                    f, f.length == 1U && f.payload[0] < kMaxHeads, MessageType::kCalibSunTerm,
                    [this, &f] { return active_sun_term(f.payload[0]); }, sink);
                return;
            case MessageType::kCalibCommand:
                update<CalibCommand>(f, sink, [this](CalibCommand c) { command_estimator(c); });
                return;
            case MessageType::kCalibModelLoad:
                update<CalibModelLoad>(f, sink, [this](const CalibModelLoad& m) { stage_model(m); });
                return;
            case MessageType::kCalibReportRequest:
                reply(
                    f, f.length == 0U, MessageType::kCalibReport, [this] { return estimator_.report(); }, sink);
                return;
            case MessageType::kStackReportRequest:
                reply(
                    f, f.length == 0U, MessageType::kStackReport, [this] { return stack_(); }, sink);
                return;
            case MessageType::kSunLearnerReportRequest:
                reply(
                    f, f.length == 0U, MessageType::kSunLearnerReport, [this] { return sun_learner_report(); }, sink);
                return;
            case MessageType::kSolutionIn: {
                SolutionIn<T> s{};
                if (!decode(f.payload, f.length, s)) {
                    ack(f.seq, AckResult::kBadPayload, sink);
                    return;
                }
                const SolutionOut<T> out = correct(s);
                std::uint8_t p[kMaxPayload];
                emit(MessageType::kSolutionOut, f.seq, p, encode(out, p), sink, true);
                step_sun_learner();  // after the answer: the link's idle time
                return;
            }
            case MessageType::kMountingLoad:
                update<MountingLoad>(
                    f, sink, [this](const MountingLoad& m) { load_mounting(m); },
                    [this](const MountingLoad& m) { return m.build == 0U || buildable(m); });
                return;
            case MessageType::kCombineRequest:
                reply(
                    f, f.length == 0U, MessageType::kCombined, [this] { return close_epoch(); }, sink);
                return;
            case MessageType::kHello:
            case MessageType::kCombined:
            case MessageType::kCalibReport:
            case MessageType::kCalibModel:
            case MessageType::kCalibSunTerm:
            case MessageType::kSunLearnerReport:
            case MessageType::kStackReport:
            case MessageType::kSolutionOut:
            case MessageType::kAck:
            case MessageType::kNak:
                break;
        }
        ack(f.seq, AckResult::kUnknownType, sink);
    }

    // A request's reply: `type` with make()'s message when the payload is
    // well formed, kBadPayload otherwise.
    template <typename Make, typename Sink>
    void reply(const Frame& f, bool well_formed, MessageType type, Make make, Sink& sink) noexcept {
        if (!well_formed) {
            ack(f.seq, AckResult::kBadPayload, sink);
            return;
        }
        std::uint8_t p[kMaxPayload];
        emit(type, f.seq, p, encode(make(), p), sink, true);
    }

    // A head's model and lag (decode() checked τ's range); the lag stage
    // runs only while some head lags. While the estimator runs the model
    // waits for a restart, and the lags are its own (start_estimator).
    // A model ends its head's Sun term (a SUN_TERM_UPLOAD after it gives the
    // new model's), so that no term outlives the model it was uploaded with.
    void upload_model(const ModelUpload<T>& m) noexcept {
        model_.head[m.head] = m.model;
        set_sun_term(m.head, SunTermUpload<T>{}.coefficient);
        if (!pipeline_.calibrating()) {
            (void)lags_.configure(m.head, m.lag_s);
            pipeline_.use_lags(&lags_);
        }
    }

    // Head h's Sun term (decode() checked its domain; all 0: none); the
    // pipeline folds the terms in only while some head has one.
    void set_sun_term(std::uint8_t h, const T (&coefficient)[kModelAxes][kSunComponents]) noexcept {
        for (std::size_t a = 0; a < kModelAxes; ++a) {
            for (std::size_t c = 0; c < kSunComponents; ++c) {
                sun_.coefficient[h][a][c] = coefficient[a][c];
            }
        }
        sun_.present[h] = any_sun_coefficient(sun_, h);
        if (!pipeline_.calibrating()) {  // while calibrating, the versions' (follow_version)
            pipeline_.use_sun_term(any_sun_term(sun_) ? &sun_ : nullptr);
        }
    }

    // The learner's per-orbit solve in bounded steps after each answer; what
    // is left when it next takes an epoch runs then (SunLearner::settle),
    // so that where the steps run changes no bit.
    void step_sun_learner() noexcept {
        for (int i = 0; learning_sun_ && i < kSunStepsPerSolution && sun_learner_.step(); ++i) {
        }
    }

    // At an epoch of a model version new to the Sun term's learning: the
    // term the learner has taken, for the heads the version has
    // (pipeline/version_sun_term.hpp; kCalibSunTerm reports its arcsec), as
    // `correct --self-calibrate --sun-term auto` makes the history's models.
    void follow_version() noexcept {
        if (learning_sun_) {
            version_term_.follow(sun_learner_, estimator_.active_coefficients(), pipeline_);
        }
    }

    void start_estimator(const CalibStart& m) noexcept {
        calib::EstimatorConfig cfg{};
        cfg.orbit_period_us = m.orbit_period_us;
        cfg.time_constant_days = m.time_constant_days;
        if (m.common_rotation == 1U) {
            cfg.common_rotation = pipeline::common_rotation_weights(staged_mountings_);
        }
        // In place: no 10-KiB temporary on the stack (trivially destructible).
        new (&estimator_) LinkEstimator<T>(cfg, m.initial == 1U ? &staged_ : nullptr);
        new (&sun_learner_) calib::SunLearner(cfg, calib::kSunLearnOnBoardIntervalUs);
        learning_sun_ = m.sun_term == 1U;
        version_term_ = {};
        pipeline_.use_sun_term(nullptr);     // an uploaded model's term is not the versions'
        (void)lags_.configure_all(m.lag_s);  // decode() checked each τ
        pipeline_.use_lags(&lags_);
        pipeline_.use_estimator(&estimator_);
    }

    void command_estimator(CalibCommand c) noexcept {
        switch (c) {
            case CalibCommand::kFreeze:
                estimator_.freeze();
                return;
            case CalibCommand::kResume:
                estimator_.resume();
                return;
            case CalibCommand::kReset:
                estimator_.reset();
                // The learner forgets too (the active version keeps its term).
                new (&sun_learner_) calib::SunLearner(estimator_.config(), calib::kSunLearnOnBoardIntervalUs);
                return;
        }
    }

    void stage_model(const CalibModelLoad& m) noexcept {
        staged_.present[m.head] = m.present == 1U;
        for (std::size_t a = 0; a < kModelAxes; ++a) {
            for (std::size_t t = 0; t < kModelTerms; ++t) {
                staged_.coefficient[m.head][a][t] = t < kLinearModelTerms ? m.c[a][t] : 0.0;
            }
        }
        if (m.load == 1U) {
            estimator_.load_model(staged_);
        }
    }

    // The meter of a solution's cost: one window, from the first stage's
    // start to the end of the correction (the lag, model, velocity and
    // correction stages; not the estimator's feed and steps), two counter reads.
    struct CostMeter {
        CycleCounter& counter;
        bool started;
        std::uint32_t first;
        std::uint32_t cost;
        std::uint32_t now() noexcept {
            if (!started) {
                started = true;
                first = counter();
            }
            return 0U;
        }
        void add(pipeline::Stage stage, std::uint32_t /*start*/) noexcept {
            if (stage == pipeline::Stage::kCorrect) {
                cost = counter() - first;
            }
        }
    };

    // One SOLUTION_IN through the epoch pipeline (epoch_pipeline.hpp): the
    // velocity of the last update or, if from_states, the service's at the
    // solution's time tag; self-calibrating, the epoch's model and the feed
    // (a solution flagged kCalibNoTime belongs to no epoch: no model, 256).
    SolutionOut<T> correct(const SolutionIn<T>& s) noexcept {
        SolutionInput<T> in{};
        in.q_chu_icrf = s.q_chu_icrf;
        in.head = s.head;
        in.temperatures = temperatures_[s.head < kMaxHeads ? s.head : 0];
        in.velocity = velocity_;
        const bool from_states = s.from_states == 1U;
        if (from_states) {
            service_.advance(s.t, OnBoardEarth{});  // double, before the measured part
        }
        const auto velocity = [&]() {
            return from_states ? pipeline::from_service(service_.velocity_at(s.t))
                               : pipeline::given_velocity(velocity_);
        };
        const bool in_epoch = pipeline_.in_epoch(in.head, (s.calib & kCalibNoTime) == 0U);
        CostMeter meter{counter_, false, 0U, 0U};
        CorrectedSolution<T> c{};
        if (in_epoch) {
            (void)pipeline_.begin(s.t.us, meter);
            follow_version();
            const std::uint32_t feeds = pipeline_.feeds();
            c = pipeline_.solution(in, velocity, (s.calib & kCalibClean) != 0U, true, meter);
            if (learning_sun_ && pipeline::learner_takes_feed(pipeline_, feeds, estimator_)) {
                (void)sun_learner_.take_kept(s.t.us, pipeline_.kept_solutions());
            }
        } else {
            const std::uint32_t start = counter_();
            c = pipeline_.untimed_solution(in, velocity);
            meter.cost = counter_() - start;
        }
        ++solutions_;
        const std::uint32_t version =
            pipeline_.calibrating() && in_epoch && pipeline_.model() != nullptr ? pipeline_.version() : kNoModelVersion;
        return {s.id, s.head, c.status, c.q_chu_icrf, meter.cost, version};
    }

    static combine::HeadMounting mounting_of(const MountingLoad& m) noexcept {
        return {m.present == 1U, m.q_chu_crf, m.sigma_cross_arcsec, m.sigma_about_arcsec};
    }

    // Whether the staged mountings with m's head are ones the combiner takes.
    bool buildable(const MountingLoad& m) const noexcept {
        combine::Mountings trial = staged_mountings_;
        trial.head[m.head] = mounting_of(m);
        std::uint8_t head = kUnknownHead;
        HeadMask subset = 0;
        // The gates too: tables a combiner could not hold would make every
        // epoch status 8 after an ACK.
        return combine::check_mountings(trial, &head) == combine::MountingsProblem::kNone &&
               combine::check_gates(trial, m.gate, &head, &subset) == combine::MountingsProblem::kNone;
    }

    // Stages m's head; with `build`, the combiner's tables from the staged
    // mountings (in place: no 5-KiB temporary on the stack).
    void load_mounting(const MountingLoad& m) noexcept {
        staged_mountings_.head[m.head] = mounting_of(m);
        if (m.build == 1U) {
            new (&combiner_) combine::Combiner<T>(staged_mountings_, m.gate);
            pipeline_.use_combiner(&combiner_);
        }
    }

    // kCombineRequest: stage 6 of the pipeline over the solutions since the
    // last request, and its cost.
    Combined<T> close_epoch() noexcept {
        struct WindowMeter {
            CycleCounter& counter;
            std::uint32_t start;
            std::uint32_t cost;
            std::uint32_t now() noexcept { return start = counter(); }
            void add(pipeline::Stage /*stage*/, std::uint32_t /*start*/) noexcept { cost = counter() - start; }
        } meter{counter_, 0U, 0U};
        const combine::CombinedAttitude<T> a = pipeline_.close(meter);
        return {a.status, a.used, a.left_out, a.inconsistent, a.q_crf_icrf, meter.cost};
    }

    // Head h of the estimator's active model, as kCalibModel.
    CalibModel active_model(std::uint8_t h) const noexcept {
        CalibModel m{};
        m.head = h;
        m.version = kNoModelVersion;
        if (const ModelCoefficients* c = estimator_.active_coefficients()) {
            m.present = c->present[h] ? 1U : 0U;
            m.version = estimator_.active_version();
            m.crc = estimator_.active_crc();
            m.active_from_us = estimator_.adopted_at_us();
            for (std::size_t a = 0; a < kModelAxes; ++a) {
                for (std::size_t t = 0; t < kLinearModelTerms; ++t) {
                    m.c[a][t] = c->coefficient[h][a][t];
                }
            }
        }
        return m;
    }

    // The Sun learner's state, as kSunLearnerReport (not learning: zeros).
    SunLearnerReport sun_learner_report() const noexcept {
        if (!learning_sun_) {
            return SunLearnerReport{0U, calib::SunLearnReport{}, 0U};
        }
        const calib::SunLearnReport r = sun_learner_.report();
        return SunLearnerReport{1U, r, calib::sun_fit_crc(r.candidate)};
    }

    // Head h's Sun term of the active model's version, as kCalibSunTerm (0
    // until an epoch of that version took one: follow_version).
    CalibSunTerm active_sun_term(std::uint8_t h) const noexcept {
        CalibSunTerm m{};
        m.head = h;
        m.version = estimator_.active_coefficients() != nullptr ? estimator_.active_version() : kNoModelVersion;
        if (version_term_.set && version_term_.version == m.version) {
            for (std::size_t a = 0; a < kModelAxes; ++a) {
                for (std::size_t k = 0; k < kSunComponents; ++k) {
                    m.sun[a][k] = version_term_.arcsec[h][a][k];
                }
            }
        }
        return m;
    }

    // Decodes a state update, applies it only if it decoded exactly and
    // `acceptable` holds, and acks; returns whether it was applied.
    template <typename M, typename Sink, typename Apply, typename Acceptable>
    bool update(const Frame& f, Sink& sink, Apply apply, Acceptable acceptable) noexcept {
        M m{};
        const bool ok = decode(f.payload, f.length, m) && acceptable(m);
        if (ok) {
            apply(m);
        }
        ack(f.seq, ok ? AckResult::kOk : AckResult::kBadPayload, sink);
        return ok;
    }
    template <typename M, typename Sink, typename Apply>
    bool update(const Frame& f, Sink& sink, Apply apply) noexcept {
        return update<M>(f, sink, apply, [](const M&) { return true; });
    }

    template <typename Sink>
    void send_hello(std::uint16_t seq, Sink& sink) noexcept {
        std::uint8_t p[kMaxPayload];
        const Hello h{boot_id_, kProtocolVersion, WireTraits<T>::kKind};
        emit(MessageType::kHello, seq, p, encode(h, p), sink, false);
    }

    template <typename Sink>
    void ack(std::uint16_t seq, AckResult r, Sink& sink) noexcept {
        std::uint8_t p[kMaxPayload];
        emit(MessageType::kAck, seq, p, encode(Ack{seq, r}, p), sink, true);
    }

    // Frames and sends a response; `cache` keeps it for a duplicate request.
    template <typename Sink>
    void emit(MessageType type, std::uint16_t seq, const std::uint8_t* p, std::size_t n, Sink& sink,
              bool cache) noexcept {
        std::uint8_t wire[kMaxWire];
        const std::size_t w = encode_frame(static_cast<std::uint8_t>(type), seq, p, n, wire, sizeof wire);
        if (cache) {
            for (std::size_t i = 0; i < w; ++i) {
                last_response_[i] = wire[i];
            }
            last_response_n_ = w;
            last_seq_ = seq;
            have_last_ = true;
        }
        sink(static_cast<const std::uint8_t*>(wire), w);
    }

    std::uint32_t boot_id_;
    CycleCounter counter_;
    StackProbe stack_{};
    FrameDecoder decoder_;
    ThermalModel<T> model_{};
    SunTermModel<T> sun_{};         // the uploaded model's Sun terms (kSunTermUpload)
    pipeline::HeadLags<T> lags_{};  // the uploaded model's (use_lags once a head lags)
    ObserverVelocity<T> velocity_{};
    // Catches up to any solution within the horizon in one call (horizon / 10 s + 1 RK4 steps).
    VelocityService<T> service_{default_velocity_service_config()};
    HeadTemperatures<T> temperatures_[kMaxHeads];
    std::uint8_t last_response_[kMaxWire] = {};
    std::size_t last_response_n_ = 0;
    std::uint16_t last_seq_ = 0;
    bool have_last_ = false;
    std::uint32_t frame_errors_ = 0;
    std::uint32_t duplicates_ = 0;
    std::uint32_t solutions_ = 0;
    // Self-calibration (kCalibStart).
    static_assert(std::is_trivially_destructible_v<LinkEstimator<T>>, "restarted in place");
    static_assert(std::is_trivially_destructible_v<VelocityService<T>>, "restarted in place");
    LinkEstimator<T> estimator_{};
    ModelCoefficients staged_{};
    // The Sun term learnt beside it (kCalibStart's sun_term), and the term
    // of the model version the epochs use (follow_version). Its solve's
    // steps per SOLUTION_IN: each at most ~0.72 million instructions
    // (docs/figures.md, "The side learners").
    static constexpr int kSunStepsPerSolution = 8;
    static_assert(std::is_trivially_destructible_v<calib::SunLearner>, "restarted in place");
    calib::SunLearner sun_learner_{calib::EstimatorConfig{}, calib::kSunLearnOnBoardIntervalUs};
    bool learning_sun_ = false;
    pipeline::VersionSunTerm<T> version_term_{};
    // Before kCalibStart: the uploaded model (use_model, in the constructor).
    LinkPipeline<T> pipeline_{};
    // The combination (kMountingLoad with build): none until then.
    static_assert(std::is_trivially_destructible_v<combine::Combiner<T>>, "rebuilt in place");
    combine::Mountings staged_mountings_{};
    combine::Combiner<T> combiner_{combine::Mountings{}};
};

}  // namespace ascorr::link
