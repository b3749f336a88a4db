// ascorr_host/link/link_client.hpp: the host end of the link (protocol v4).
//
// One request in flight. Each request keeps its sequence number across
// retries, so the target can recognise a resend and answer from its cache.
// An answer is accepted only if it decodes exactly, has the request's type
// and sequence number and (for solutions) the request's id and head: a wrong
// solution is never accepted. An unprompted HELLO (sequence number 0, which
// the client never uses for a request) means the target restarted, whatever
// its boot id (an emulator boots identically every time): the client uploads
// the model, velocity, temperatures and the latest accepted spacecraft state
// it last sent (the velocity service's answers depend on that state only),
// then resends the request in flight. So is a solution corrected without the
// model or velocity the client gave the target (a restart whose HELLO was
// lost on the link).
//
// The implementation (src/link/link_client.cpp), for T = float and Q30, has
// three parts:
//   transactions  a Request is sent until its answer arrives, the target
//                 announces a restart, or the attempts run out (exchange());
//                 a restart suspends the request, which resumes where it was;
//   the session   what the client gave the target, as the Messages that give
//                 it again (session()); restore() sends them in rounds until
//                 a round passes without a restart;
//   detection     answer_shows_restart(): the guess from an answer's status
//                 bits (the HELLO is the transaction's).
// To add an update the target keeps: a Message builder, a public setter that
// records it and sends it with update(), and its line in session().
#pragma once

#include <array>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "ascorr_host/link/link_transport.hpp"
#include "ascorr_link/frame.hpp"
#include "ascorr_link/messages.hpp"

namespace ascorr::host {

struct LinkStats {
    std::size_t requests = 0;
    std::size_t retries = 0;
    std::size_t timeouts = 0;
    std::size_t naks = 0;            // target saw a broken frame (host → target corruption)
    std::size_t broken_answers = 0;  // host saw a broken frame (target → host corruption)
    std::size_t stale_answers = 0;   // well-formed answers to an earlier request (duplicates, late)
    std::size_t restarts = 0;        // target restarts detected
};

class LinkError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

// The target answered a request with an ACK that is not kOk: it refused it
// (kBadPayload) or does not know its type (kUnknownType: a firmware from
// before that message). The caller decides which of these it can live with,
// for which request (a restart's restore may refuse another on the way).
class LinkRefused : public LinkError {
public:
    LinkRefused(const std::string& what, link::MessageType request, link::AckResult result)
        : LinkError(what), request_(request), result_(result) {}
    link::MessageType request() const noexcept { return request_; }
    link::AckResult result() const noexcept { return result_; }

private:
    link::MessageType request_;
    link::AckResult result_;
};

template <typename T>
class LinkClient {
public:
    LinkClient(Transport& t, int timeout_ms, int max_attempts)
        : transport_(t), timeout_ms_(timeout_ms), max_attempts_(max_attempts) {}

    // HELLO_REQUEST → HELLO, with the protocol checked: what the target is
    // (its scalar kind says which client it needs; see replay()).
    link::Hello request_hello();

    // Opens a session: request_hello(), and the scalar kind must be T's.
    link::Hello connect();

    // lag_s: each head's lag τ (0: none), sent with its model; a restart
    // once a lagged head's timed solution was sent is an error (restore()
    // refuses it): the lag's state is lost with it.
    void upload_model(const ThermalModel<T>& model, const std::array<double, kMaxHeads>& lag_s = {});
    // The uploaded model's Sun terms (SUN_TERM_UPLOAD), every head (one
    // without a term as 0: none), after upload_model (whose MODEL_UPLOAD
    // ends a head's term); restored after a restart with the model. The
    // target refuses them while its estimator runs (a LinkError; the client
    // keeps the terms it held before).
    void upload_sun_term(const SunTermModel<T>& sun);
    void set_velocity(const ObserverVelocity<T>& v);
    void set_temperatures(std::uint8_t head, const HeadTemperatures<T>& t);

    // A spacecraft state for the target's velocity service; `accepted`: the
    // on-board checks (run by the caller) accept it, so a restore resends it.
    void send_state(const link::StateUpdate& s, bool accepted);

    // t and from_states: the solution's time tag and whether the target takes
    // the velocity from its service (then velocity_expected: the caller's
    // mirror of the service has one, so an answer without is a lost restart).
    // calib: link::kCalibClean | link::kCalibNoTime (used while the target's
    // estimator runs).
    link::SolutionOut<T> correct(std::uint32_t id, std::uint8_t head, const Quaternion<T>& q, TtTime t = {0},
                                 bool from_states = false, bool velocity_expected = false, std::uint8_t calib = 0U);

    // The velocity service's horizon (µs, (0, kMaxHorizonUs]); the target's
    // service restarts: call before the first state.
    void set_service_horizon(std::int64_t horizon_us);

    // Self-calibration (protocol v3). `initial`: the estimator's version 0
    // (staged head by head, then started with it); none: no model. A restart
    // while the target's estimator runs is an error (restore() refuses it):
    // what it had learnt is lost with it.
    // common_rotation: the rule 'combined' with the mountings loaded before
    // (load_mountings), CALIB_START's common_rotation 1. lag_s: the heads'
    // lags the estimator learns with (CALIB_START's; 0 none). learn_sun:
    // the Sun term learnt beside it (CALIB_START's sun_term 1).
    void start_calibration(std::int64_t orbit_period_us, double time_constant_days, const ModelCoefficients* initial,
                           bool common_rotation = false, const std::array<double, kMaxHeads>& lag_s = {},
                           bool learn_sun = false);
    // The heads' lags the target runs with (start_calibration's once the
    // estimator runs, otherwise the last upload_model's; 0 none).
    const std::array<double, kMaxHeads>& lag_s() const noexcept { return lag_s_; }
    void calib_command(link::CalibCommand c);
    // A model for the estimator, active from the next epoch (version + 1).
    void load_calib_model(const ModelCoefficients& m);
    calib::EstimatorReport calib_report();
    // Head h of the estimator's active model (protocol v4).
    link::CalibModel calib_model(std::uint8_t head);
    // Head h's Sun term of the active model's version (start_calibration's
    // learn_sun; a target before it: a LinkRefused, kUnknownType).
    link::CalibSunTerm calib_sun_term(std::uint8_t head);
    // The target's Sun learner (SUN_LEARNER_REPORT; its candidate's
    // coefficients by their CRC only); none: a firmware before the message
    // (it answered kUnknownType). Any other refusal is a LinkRefused.
    std::optional<link::SunLearnerReport> sun_learner_report();
    // The target's stack high-water mark and size (STACK_REPORT; 0, 0: it
    // does not measure it); none: a firmware before the message, as above.
    std::optional<link::StackReport> stack_report();

    // The combination (protocol v5): the mountings, head by head, built into
    // the target's combiner (a LinkError when the target refuses them); then
    // each call of combine_epoch() has the target combine the solutions it
    // corrected since the previous call. A restart while combining is an
    // error (restore() refuses it): the epoch's solutions are lost with it.
    // gate: the consistency gate of the target's combiner (sent only when it
    // is not CombinerConfig{}'s, combine_messages.hpp).
    void load_mountings(const combine::Mountings& m, const combine::CombinerConfig& gate = {});
    link::Combined<T> combine_epoch();

    const LinkStats& stats() const { return stats_; }

private:
    // A request's type and payload; `what` names it in a refusal.
    struct Message {
        link::MessageType type;
        std::vector<std::uint8_t> payload;
        const char* what;  // a string literal: requests keep the pointer
    };

    // A request on the wire: its frame (with its sequence number, kept across
    // resends), the answer it wants and how far its attempts have gone.
    struct Request {
        const char* what;  // the Message's (a literal: static storage), for a refusal
        link::MessageType type;
        link::MessageType answer;
        std::uint16_t seq;
        std::vector<std::uint8_t> wire;
        int attempt;
        std::chrono::steady_clock::time_point give_up_after;
    };

    // What await() heard for a request.
    enum class Heard {
        kAnswer,   // the answer to the request
        kResend,   // nothing in time, or a NAK: send the request again
        kRestart,  // the target announced a restart
    };

    // Transactions.
    Request begin(const Message& m, link::MessageType answer);
    std::optional<std::vector<std::uint8_t>> exchange(Request& r);
    Heard await(const Request& r, std::vector<std::uint8_t>& answer);
    std::optional<Heard> hear(const Request& r, std::uint8_t byte, std::vector<std::uint8_t>& answer);
    std::optional<Heard> hear_frame(const Request& r, const link::Frame& f, std::vector<std::uint8_t>& answer);

    // The session.
    std::vector<std::uint8_t> request(const Message& m, link::MessageType answer);
    // A report the target may not know: request(ask, answer) decoded as A
    // (`what` names it), or none when the target refused ask's type as unknown
    // (a firmware before the message); any other refusal is a LinkRefused.
    template <typename A>
    std::optional<A> report_if_known(const Message& ask, link::MessageType answer, const char* what);
    void update(const Message& m);
    std::vector<Message> session() const;
    void restore();
    bool restore_round();

    // Restart detection from an answer.
    bool answer_shows_restart(const link::SolutionOut<T>& out) const;

    Message model_message(std::uint8_t head) const;
    static Message sun_term_message(const SunTermModel<T>& sun, std::uint8_t head);
    Message velocity_message() const;
    Message state_message(const link::StateUpdate& s) const;
    Message service_message() const;
    Message temperatures_message(std::uint8_t head) const;
    // Heads A..D of m, one frame each; the last with `load`.
    void send_calib_model(const ModelCoefficients& m, bool load);

    Transport& transport_;
    int timeout_ms_;
    int max_attempts_;
    link::FrameDecoder decoder_;
    // Bytes read but not yet heard: unread_[unread_at_..] (await()).
    std::vector<std::uint8_t> unread_;
    std::size_t unread_at_ = 0;
    std::uint16_t seq_ = 0;
    std::uint32_t boot_id_ = 0;
    std::optional<ThermalModel<T>> model_;
    std::array<double, kMaxHeads> lag_s_{};  // upload_model()'s
    std::optional<SunTermModel<T>> sun_;     // upload_sun_term()'s
    std::uint8_t lagging_ = kUnknownHead;    // a lagged head whose timed solution was sent
    std::optional<ObserverVelocity<T>> velocity_;
    std::optional<std::int64_t> horizon_us_;  // set_service_horizon()
    std::optional<link::StateUpdate> state_;  // the latest accepted spacecraft state
    std::optional<HeadTemperatures<T>> temperatures_[kMaxHeads];
    bool from_states_ = false;  // of the solution in flight
    bool velocity_expected_ = false;
    bool calibrating_ = false;  // start_calibration() sent: a restart is an error
    bool combining_ = false;    // load_mountings() sent: a restart is an error
    std::uint8_t calib_ = 0U;   // of the solution in flight (link::kCalibClean, kCalibNoTime)
    bool had_version_ = false;  // an answer carried a model version
    LinkStats stats_;
};

}  // namespace ascorr::host
