#include "ascorr_host/link/link_client.hpp"

#include <algorithm>
#include <cstring>
#include <string>

#include "ascorr/core/fixed_point.hpp"
#include "ascorr/core/status.hpp"
#include "ascorr_host/formats/solutions_csv.hpp"

namespace ascorr::host {

namespace {

// A request is given up after max_attempts and at least this long: a target
// that is booting (QEMU takes 0.3–1 s on a loaded machine, before its first
// byte) must not exhaust a few short time-outs.
constexpr int kMinPatienceMs = 3000;

// Byte equality: at worst (padding that differs) an update is sent twice.
template <typename A>
bool same(const A& a, const A& b) {
    return std::memcmp(&a, &b, sizeof a) == 0;
}

template <typename M>
std::vector<std::uint8_t> encoded(const M& m) {
    std::uint8_t p[link::kMaxPayload];
    const std::size_t n = link::encode(m, p);
    return {p, p + n};
}

const char* ack_result_name(link::AckResult r) {
    switch (r) {
        case link::AckResult::kOk:
            return "ok";
        case link::AckResult::kUnknownType:
            return "unknown message type";
        case link::AckResult::kBadPayload:
            return "bad payload";
    }
    return "unknown result";
}

LinkRefused refusal(const char* what, link::MessageType type, link::AckResult r) {
    return {std::string(what) + " refused by the target (result " + std::to_string(static_cast<int>(r)) + ": " +
                ack_result_name(r) + ")",
            type, r};
}

// An ACK to the request `what` of type `type` (its payload, n bytes):
// returns when it is ok; a LinkError when it does not decode, a
// LinkRefused when it refuses.
void expect_ok(const std::uint8_t* p, std::size_t n, const char* what, link::MessageType type) {
    link::Ack a{};
    if (!link::decode(p, n, a)) {
        throw LinkError(std::string("malformed acknowledgement of ") + what + " from the target (" + std::to_string(n) +
                        " bytes)");
    }
    if (a.result != link::AckResult::kOk) {
        throw refusal(what, type, a.result);
    }
}

// The answer of `ask` (a request of type `type`), or none when the target
// does not know that type (a firmware from before it). Any other refusal
// propagates, a refusal of `type` for another reason, and one of another
// request on the way (a restart's restore).
template <typename F>
auto unless_unknown(link::MessageType type, F ask) -> std::optional<decltype(ask())> {
    try {
        return ask();
    } catch (const LinkRefused& e) {
        if (e.result() != link::AckResult::kUnknownType || e.request() != type) {
            throw;
        }
        return std::nullopt;
    }
}

// An answer's payload decoded as M and accepted by `fits` (the request's
// own fields echoed), or a LinkError naming `what` and its size.
template <typename M, typename Fits>
M answer_of(const std::vector<std::uint8_t>& a, const char* what, Fits fits) {
    M m{};
    if (!link::decode(a.data(), a.size(), m) || !fits(m)) {
        throw LinkError(std::string("malformed ") + what + " from the target (" + std::to_string(a.size()) + " bytes)");
    }
    return m;
}
template <typename M>
M answer_of(const std::vector<std::uint8_t>& a, const char* what) {
    return answer_of<M>(a, what, [](const M&) { return true; });
}

}  // namespace

// ---------------------------------------------------------------------------
// The caller's requests.

template <typename T>
link::Hello LinkClient<T>::request_hello() {
    const auto p = request({link::MessageType::kHelloRequest, {}, "hello request"}, link::MessageType::kHello);
    link::Hello h{};
    link::decode(p.data(), p.size(), h);
    if (h.protocol != link::kProtocolVersion) {
        throw LinkError("target speaks link protocol " + std::to_string(h.protocol) + ", this host " +
                        std::to_string(link::kProtocolVersion));
    }
    return h;
}

template <typename T>
link::Hello LinkClient<T>::connect() {
    const link::Hello h = request_hello();
    if (h.scalar_kind != link::WireTraits<T>::kKind) {
        throw LinkError("target computes in scalar kind " + std::to_string(h.scalar_kind) + ", the host expected " +
                        std::to_string(link::WireTraits<T>::kKind));
    }
    boot_id_ = h.boot_id;
    return h;
}

template <typename T>
void LinkClient<T>::upload_model(const ThermalModel<T>& model, const std::array<double, kMaxHeads>& lag_s) {
    if (calibrating_) {
        // The target keeps CALIB_START's lags while its estimator runs.
        for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
            if (lag_s[h] != 0.0) {
                throw LinkError(std::string("a lag for head ") + head_name(h) +
                                " while the target's estimator runs: its lags are CALIB_START's");
            }
        }
    } else {
        lag_s_ = lag_s;
    }
    model_ = model;
    sun_.reset();  // the target ends each head's Sun term with its model
    for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
        update(model_message(h));
    }
}

template <typename T>
void LinkClient<T>::upload_sun_term(const SunTermModel<T>& sun) {
    const std::optional<SunTermModel<T>> before = sun_;
    sun_ = sun;  // a restart in the middle restores them all
    try {
        for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
            update(sun_term_message(sun, h));
        }
    } catch (const LinkError&) {
        sun_ = before;  // refused: the client holds what it held
        throw;
    }
}

template <typename T>
void LinkClient<T>::set_velocity(const ObserverVelocity<T>& v) {
    if (velocity_ && same(*velocity_, v)) {
        return;
    }
    velocity_ = v;
    update(velocity_message());
}

template <typename T>
void LinkClient<T>::set_temperatures(std::uint8_t head, const HeadTemperatures<T>& t) {
    if (head >= kMaxHeads) {
        return;  // the target would refuse it; the solution itself carries the bad head
    }
    if (temperatures_[head] && same(*temperatures_[head], t)) {
        return;
    }
    temperatures_[head] = t;
    update(temperatures_message(head));
}

template <typename T>
void LinkClient<T>::set_service_horizon(std::int64_t horizon_us) {
    horizon_us_ = horizon_us;
    update(service_message());
}

template <typename T>
void LinkClient<T>::send_state(const link::StateUpdate& s, bool accepted) {
    if (accepted) {
        state_ = s;
    }
    update(state_message(s));
}

template <typename T>
link::SolutionOut<T> LinkClient<T>::correct(std::uint32_t id, std::uint8_t head, const Quaternion<T>& q, TtTime t,
                                            bool from_states, bool velocity_expected, std::uint8_t calib) {
    const Message m{
        link::MessageType::kSolutionIn,
        encoded(link::SolutionIn<T>{id, head, q, t, static_cast<std::uint8_t>(from_states ? 1U : 0U), calib}),
        "solution"};
    from_states_ = from_states;
    velocity_expected_ = velocity_expected;
    calib_ = calib;
    if (lagging_ == kUnknownHead && head < kMaxHeads && lag_s_[head] != 0.0 && (calib & link::kCalibNoTime) == 0U) {
        lagging_ = head;  // from now on the target holds lag state a restart would lose
    }
    for (int attempt = 0; attempt < max_attempts_; ++attempt) {
        const auto a = request(m, link::MessageType::kSolutionOut);
        link::SolutionOut<T> out{};
        if (!link::decode(a.data(), a.size(), out) || out.id != id || out.head != head) {
            ++stats_.stale_answers;  // well framed but not ours: ask again
            ++stats_.retries;
            continue;
        }
        if (answer_shows_restart(out)) {
            restore();  // a restart whose HELLO was lost on the link
            continue;
        }
        had_version_ = had_version_ || out.model_version != link::kNoModelVersion;
        return out;
    }
    throw LinkError("no acceptable answer for solution " + std::to_string(id) + " after " +
                    std::to_string(max_attempts_) + " attempts");
}

// ---------------------------------------------------------------------------
// Transactions: one request in flight, its resends, and what is heard.

template <typename T>
typename LinkClient<T>::Request LinkClient<T>::begin(const Message& m, link::MessageType answer) {
    seq_ = static_cast<std::uint16_t>(seq_ == 0xFFFFU ? 1U : seq_ + 1U);  // 0 is the target's unprompted HELLO
    ++stats_.requests;
    std::uint8_t wire[link::kMaxWire];
    const std::size_t w = link::encode_frame(static_cast<std::uint8_t>(m.type), seq_, m.payload.data(),
                                             m.payload.size(), wire, sizeof wire);
    return Request{m.what,
                   m.type,
                   answer,
                   seq_,
                   {wire, wire + w},
                   0,
                   std::chrono::steady_clock::now() + std::chrono::milliseconds(kMinPatienceMs)};
}

// Sends r until its answer arrives (returned) or the target announces a
// restart (empty: r is suspended; the resend that resumes it is the same
// attempt, since a restart is not the request's failure).
template <typename T>
std::optional<std::vector<std::uint8_t>> LinkClient<T>::exchange(Request& r) {
    while (r.attempt < max_attempts_ || std::chrono::steady_clock::now() < r.give_up_after) {
        if (r.attempt > 0) {
            ++stats_.retries;
        }
        transport_.write(r.wire.data(), r.wire.size());
        std::vector<std::uint8_t> answer;
        switch (await(r, answer)) {
            case Heard::kAnswer:
                return answer;
            case Heard::kRestart:
                return std::nullopt;
            case Heard::kResend:
                ++r.attempt;
                break;
        }
    }
    throw LinkError("no answer from the target after " + std::to_string(max_attempts_) + " attempts");
}

// Reads until r's answer, a restart, or the time-out. The bytes of a read
// after the frame that ends a wait (an answer, a NAK, a restart, a refusal
// thrown) stay in unread_ for the next wait: a restart's HELLO that shares a
// read with an answer is heard, and the decoder never sees a frame with a
// hole in it.
template <typename T>
typename LinkClient<T>::Heard LinkClient<T>::await(const Request& r, std::vector<std::uint8_t>& answer) {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(timeout_ms_);
    std::uint8_t buf[256];
    for (;;) {
        while (unread_at_ < unread_.size()) {
            const std::uint8_t byte = unread_[unread_at_++];  // taken before hear(), which may throw
            if (const std::optional<Heard> heard = hear(r, byte, answer)) {
                return *heard;
            }
        }
        // Read what is there even when the time is up: an answer that has
        // arrived is never thrown away for a resend.
        const auto left =
            std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
        const std::size_t n = transport_.read(buf, sizeof buf, static_cast<int>(std::max<long long>(0, left.count())));
        if (n == 0) {
            ++stats_.timeouts;
            return Heard::kResend;
        }
        unread_.assign(buf, buf + n);
        unread_at_ = 0;
    }
}

// One byte into the frame decoder; what it completes, if that ends the wait.
template <typename T>
std::optional<typename LinkClient<T>::Heard> LinkClient<T>::hear(const Request& r, std::uint8_t byte,
                                                                 std::vector<std::uint8_t>& answer) {
    switch (decoder_.push(byte)) {
        case link::FrameDecoder::Event::kNone:
            break;
        case link::FrameDecoder::Event::kError:
            ++stats_.broken_answers;
            break;  // its answer may still follow intact; otherwise the time-out resends
        case link::FrameDecoder::Event::kFrame:
            return hear_frame(r, decoder_.frame(), answer);
    }
    return std::nullopt;
}

// A whole frame: r's answer, a NAK, the target's restart, a refusal (thrown),
// or anything else (stale: the wait goes on).
template <typename T>
std::optional<typename LinkClient<T>::Heard> LinkClient<T>::hear_frame(const Request& r, const link::Frame& f,
                                                                       std::vector<std::uint8_t>& answer) {
    const auto t = static_cast<link::MessageType>(f.type);
    if (t == link::MessageType::kNak) {
        ++stats_.naks;
        return Heard::kResend;  // at once
    }
    // The target's unprompted HELLO: it has restarted.
    if (t == link::MessageType::kHello && f.seq == 0U && r.answer != link::MessageType::kHello) {
        link::Hello h{};
        if (link::decode(f.payload, f.length, h)) {
            boot_id_ = h.boot_id;
            return Heard::kRestart;
        }
        ++stats_.stale_answers;
        return std::nullopt;
    }
    if (f.seq == r.seq && t == r.answer) {
        answer.assign(f.payload, f.payload + f.length);
        return Heard::kAnswer;
    }
    if (f.seq == r.seq && t == link::MessageType::kAck) {
        expect_ok(f.payload, f.length, r.what, r.type);  // ok: not the answer wanted, stale
    }
    ++stats_.stale_answers;
    return std::nullopt;
}

// ---------------------------------------------------------------------------
// The session: what the target was given, given again after a restart.

// m's answer; a restart on the way restores the session, then m resumes.
template <typename T>
std::vector<std::uint8_t> LinkClient<T>::request(const Message& m, link::MessageType answer) {
    Request r = begin(m, answer);
    for (;;) {
        if (auto a = exchange(r)) {
            return *std::move(a);
        }
        restore();
    }
}

template <typename T>
void LinkClient<T>::update(const Message& m) {
    const std::vector<std::uint8_t> ack = request(m, link::MessageType::kAck);
    expect_ok(ack.data(), ack.size(), m.what, m.type);
}

// In the order a restore sends them: models and their Sun terms, velocity, the service's horizon, state,
// temperatures.
template <typename T>
std::vector<typename LinkClient<T>::Message> LinkClient<T>::session() const {
    std::vector<Message> s;
    if (model_) {
        for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
            s.push_back(model_message(h));
        }
    }
    if (sun_) {
        for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
            s.push_back(sun_term_message(*sun_, h));
        }
    }
    if (velocity_) {
        s.push_back(velocity_message());
    }
    if (horizon_us_) {
        s.push_back(service_message());  // it restarts the service: before the state
    }
    if (state_) {
        s.push_back(state_message(*state_));
    }
    for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
        if (temperatures_[h]) {
            s.push_back(temperatures_message(h));
        }
    }
    return s;
}

// The target restarted: give it back everything it had, in rounds, until a
// round passes without another restart.
template <typename T>
void LinkClient<T>::restore() {
    if (calibrating_) {
        throw LinkError("the target restarted during self-calibration: its estimator's state is lost");
    }
    if (combining_) {
        throw LinkError("the target restarted while combining: its mountings and the epoch's solutions are lost");
    }
    if (lagging_ != kUnknownHead) {
        throw LinkError(std::string("the target restarted while head ") + head_name(lagging_) +
                        " lags: the lag's state of its temperatures is lost");
    }
    for (int round = 0; round < max_attempts_; ++round) {
        ++stats_.restarts;
        if (!restore_round()) {
            return;
        }
    }
    throw LinkError("the target restarted " + std::to_string(max_attempts_) + " times while being restored");
}

// One round of the session's messages; true if the target restarted during
// it (each message interrupted by the restart is resent, then the round goes
// on: the next round sends everything again).
template <typename T>
bool LinkClient<T>::restore_round() {
    bool restarted = false;
    for (const Message& m : session()) {
        Request r = begin(m, link::MessageType::kAck);
        std::optional<std::vector<std::uint8_t>> a;
        while (!(a = exchange(r))) {
            restarted = true;
        }
        expect_ok(a->data(), a->size(), m.what, m.type);
    }
    return restarted;
}

// ---------------------------------------------------------------------------
// Restart detection from an answer: the target corrected without the model
// or velocity this client gave it, so it has restarted and its HELLO did not
// arrive. Such an answer is not accepted.

template <typename T>
bool LinkClient<T>::answer_shows_restart(const link::SolutionOut<T>& out) const {
    const bool no_model = (out.status & status::kNoModelForHead) != 0U && model_ && out.head < kMaxHeads &&
                          model_->head[out.head].present;
    const bool no_velocity = (out.status & (status::kNoVelocity | status::kVelocityInvalid)) == status::kNoVelocity &&
                             velocity_ && velocity_->valid && !from_states_;
    const bool no_state =
        from_states_ && velocity_expected_ &&
        (out.status & (status::kNoVelocity | status::kVelocityInvalid | status::kStale)) == status::kNoVelocity;
    // Self-calibrating: a timed solution corrected without any model once the
    // target has had one (its estimator never drops its active model).
    const bool no_estimator = calibrating_ && had_version_ && (calib_ & link::kCalibNoTime) == 0U &&
                              out.model_version == link::kNoModelVersion;
    return no_model || no_velocity || no_state || no_estimator;
}

// ---------------------------------------------------------------------------
// The messages.

template <typename T>
typename LinkClient<T>::Message LinkClient<T>::model_message(std::uint8_t head) const {
    // While the estimator runs, the lags are CALIB_START's: MODEL_UPLOAD sends none.
    const double tau = calibrating_ ? 0.0 : lag_s_[head];
    return {link::MessageType::kModelUpload, encoded(link::ModelUpload<T>{head, model_->head[head], tau}),
            "model upload"};
}

template <typename T>
typename LinkClient<T>::Message LinkClient<T>::sun_term_message(const SunTermModel<T>& sun, std::uint8_t head) {
    link::SunTermUpload<T> m{};
    m.head = head;
    for (std::size_t a = 0; a < kModelAxes; ++a) {
        for (std::size_t c = 0; c < kSunComponents; ++c) {
            m.coefficient[a][c] = sun.present[head] ? sun.coefficient[head][a][c] : constant<T>(0.0);
        }
    }
    return {link::MessageType::kSunTermUpload, encoded(m), "Sun term upload"};
}

template <typename T>
typename LinkClient<T>::Message LinkClient<T>::velocity_message() const {
    return {link::MessageType::kVelocityUpdate, encoded(*velocity_), "velocity update"};
}

template <typename T>
typename LinkClient<T>::Message LinkClient<T>::service_message() const {
    return {link::MessageType::kServiceConfig, encoded(link::ServiceConfig{*horizon_us_}), "service configuration"};
}

template <typename T>
typename LinkClient<T>::Message LinkClient<T>::state_message(const link::StateUpdate& s) const {
    return {link::MessageType::kStateUpdate, encoded(s), "state update"};
}

template <typename T>
typename LinkClient<T>::Message LinkClient<T>::temperatures_message(std::uint8_t head) const {
    return {link::MessageType::kTemperatureUpdate, encoded(link::TemperatureUpdate<T>{head, *temperatures_[head]}),
            "temperature update"};
}

// ---------------------------------------------------------------------------
// Self-calibration (protocol v3; the model request v4).

template <typename T>
void LinkClient<T>::start_calibration(std::int64_t orbit_period_us, double time_constant_days,
                                      const ModelCoefficients* initial, bool common_rotation,
                                      const std::array<double, kMaxHeads>& lag_s, bool learn_sun) {
    if (initial != nullptr) {
        send_calib_model(*initial, false);
    }
    link::CalibStart start{orbit_period_us, time_constant_days, static_cast<std::uint8_t>(initial ? 1U : 0U),
                           static_cast<std::uint8_t>(common_rotation ? 1U : 0U)};
    std::copy(lag_s.begin(), lag_s.end(), start.lag_s);
    start.sun_term = learn_sun ? 1U : 0U;
    update({link::MessageType::kCalibStart, encoded(start), "calibration start"});
    lag_s_ = lag_s;  // the target's lags from now on (a restart is an error while calibrating anyway)
    calibrating_ = true;
}

template <typename T>
void LinkClient<T>::calib_command(link::CalibCommand c) {
    update({link::MessageType::kCalibCommand, encoded(c), "calibration command"});
}

template <typename T>
void LinkClient<T>::load_calib_model(const ModelCoefficients& m) {
    send_calib_model(m, true);
}

template <typename T>
calib::EstimatorReport LinkClient<T>::calib_report() {
    return answer_of<calib::EstimatorReport>(
        request({link::MessageType::kCalibReportRequest, {}, "calibration report"}, link::MessageType::kCalibReport),
        "calibration report");
}

template <typename T>
link::CalibModel LinkClient<T>::calib_model(std::uint8_t head) {
    return answer_of<link::CalibModel>(
        request({link::MessageType::kCalibModelRequest, {head}, "calibration model request"},
                link::MessageType::kCalibModel),
        "calibration model", [head](const link::CalibModel& m) { return m.head == head; });
}

template <typename T>
link::CalibSunTerm LinkClient<T>::calib_sun_term(std::uint8_t head) {
    return answer_of<link::CalibSunTerm>(
        request({link::MessageType::kCalibSunTermRequest, {head}, "calibration Sun term request"},
                link::MessageType::kCalibSunTerm),
        "calibration Sun term", [head](const link::CalibSunTerm& m) { return m.head == head; });
}

template <typename T>
template <typename A>
std::optional<A> LinkClient<T>::report_if_known(const Message& ask, link::MessageType answer, const char* what) {
    return unless_unknown(ask.type, [&] { return answer_of<A>(request(ask, answer), what); });
}

template <typename T>
std::optional<link::StackReport> LinkClient<T>::stack_report() {
    return report_if_known<link::StackReport>({link::MessageType::kStackReportRequest, {}, "stack report request"},
                                              link::MessageType::kStackReport, "stack report");
}

template <typename T>
std::optional<link::SunLearnerReport> LinkClient<T>::sun_learner_report() {
    return report_if_known<link::SunLearnerReport>(
        {link::MessageType::kSunLearnerReportRequest, {}, "Sun learner report request"},
        link::MessageType::kSunLearnerReport, "Sun learner report");
}

template <typename T>
void LinkClient<T>::send_calib_model(const ModelCoefficients& m, bool load) {
    for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
        link::CalibModelLoad f{};
        f.head = h;
        f.present = m.present[h] ? 1U : 0U;
        f.load = load && h + 1U == kMaxHeads ? 1U : 0U;
        for (std::size_t a = 0; a < kModelAxes; ++a) {
            for (std::size_t t = 0; t < kLinearModelTerms; ++t) {
                f.c[a][t] = m.present[h] ? m.coefficient[h][a][t] : 0.0;
            }
        }
        update({link::MessageType::kCalibModelLoad, encoded(f), "calibration model load"});
    }
}

template <typename T>
void LinkClient<T>::load_mountings(const combine::Mountings& m, const combine::CombinerConfig& gate) {
    for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
        const combine::HeadMounting& hm = m.head[h];
        link::MountingLoad f{};
        f.head = h;
        f.present = hm.present ? 1U : 0U;
        f.build = h + 1U == kMaxHeads ? 1U : 0U;
        f.q_chu_crf = hm.present ? hm.q_chu_crf : Quaternion<double>{1.0, 0.0, 0.0, 0.0};
        f.sigma_cross_arcsec = hm.present ? hm.sigma_cross_arcsec : 1.0;
        f.sigma_about_arcsec = hm.present ? hm.sigma_about_arcsec : 1.0;
        f.gate = gate;
        update({link::MessageType::kMountingLoad, encoded(f), "mountings load"});
    }
    combining_ = true;
}

template <typename T>
link::Combined<T> LinkClient<T>::combine_epoch() {
    const std::vector<std::uint8_t> a =
        request({link::MessageType::kCombineRequest, {}, "combine request"}, link::MessageType::kCombined);
    link::Combined<T> c{};
    if (!link::decode(a.data(), a.size(), c)) {
        throw LinkError("malformed combined attitude from the target (" + std::to_string(a.size()) + " bytes)");
    }
    return c;
}

// The scalars the targets compute in.
template class LinkClient<float>;
template class LinkClient<Q30>;

}  // namespace ascorr::host
