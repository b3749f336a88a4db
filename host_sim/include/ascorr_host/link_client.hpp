// ascorr_host/link_client.hpp: the host end of the link (protocol v3).
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
// then resends the request in flight. So is a solution corrected without the model or velocity the
// client gave the target (a restart whose HELLO was lost on the link).
// A restart while the target's estimator runs (start_calibration) is an
// error: what it had learnt is lost with it.
#pragma once

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstring>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "ascorr/status.hpp"
#include "ascorr_host/link_transport.hpp"
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

template <typename T>
class LinkClient {
public:
    LinkClient(Transport& t, int timeout_ms, int max_attempts)
        : transport_(t), timeout_ms_(timeout_ms), max_attempts_(max_attempts) {}

    // HELLO_REQUEST → HELLO, with the protocol checked: what the target is
    // (its scalar kind says which client it needs; see replay()).
    link::Hello request_hello() {
        const auto p = transact(link::MessageType::kHelloRequest, {}, link::MessageType::kHello);
        link::Hello h{};
        link::decode(p.data(), p.size(), h);
        if (h.protocol != link::kProtocolVersion) {
            throw LinkError("target speaks link protocol " + std::to_string(h.protocol) + ", this host " +
                            std::to_string(link::kProtocolVersion));
        }
        return h;
    }

    // Opens a session: request_hello(), and the scalar kind must be T's.
    link::Hello connect() {
        const link::Hello h = request_hello();
        if (h.scalar_kind != link::WireTraits<T>::kKind) {
            throw LinkError("target computes in scalar kind " + std::to_string(h.scalar_kind) + ", the host expected " +
                            std::to_string(link::WireTraits<T>::kKind));
        }
        boot_id_ = h.boot_id;
        return h;
    }

    void upload_model(const ThermalModel<T>& model) {
        model_ = model;
        for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
            send_model(h);
        }
    }

    void set_velocity(const ObserverVelocity<T>& v) {
        if (velocity_ && same(*velocity_, v)) {
            return;
        }
        velocity_ = v;
        send_velocity();
    }

    void set_temperatures(std::uint8_t head, const HeadTemperatures<T>& t) {
        if (head >= kMaxHeads) {
            return;  // the target would refuse it; the solution itself carries the bad head
        }
        if (temperatures_[head] && same(*temperatures_[head], t)) {
            return;
        }
        temperatures_[head] = t;
        send_temperatures(head);
    }

    // A spacecraft state for the target's velocity service; `accepted`: the
    // on-board checks (run by the caller) accept it, so a restore resends it.
    void send_state(const link::StateUpdate& s, bool accepted) {
        if (accepted) {
            state_ = s;
        }
        send_state_frame(s);
    }

    // t and from_states: the solution's time tag and whether the target takes
    // the velocity from its service (then velocity_expected: the caller's
    // mirror of the service has one, so an answer without is a lost restart).
    link::SolutionOut<T> correct(std::uint32_t id, std::uint8_t head, const Quaternion<T>& q, TtTime t = {0},
                                 bool from_states = false, bool velocity_expected = false) {
        std::uint8_t p[link::kMaxPayload];
        const std::size_t n =
            link::encode(link::SolutionIn<T>{id, head, q, t, static_cast<std::uint8_t>(from_states ? 1U : 0U)}, p);
        from_states_ = from_states;
        velocity_expected_ = velocity_expected;
        for (int attempt = 0; attempt < max_attempts_; ++attempt) {
            const auto a = transact(link::MessageType::kSolutionIn, {p, p + n}, link::MessageType::kSolutionOut);
            link::SolutionOut<T> out{};
            if (!link::decode(a.data(), a.size(), out) || out.id != id || out.head != head) {
                ++stats_.stale_answers;  // well framed but not ours: ask again
                ++stats_.retries;
                continue;
            }
            if (lost_state(out)) {
                restore();  // a restart whose HELLO was lost on the link
                continue;
            }
            return out;
        }
        throw LinkError("no acceptable answer for solution " + std::to_string(id) + " after " +
                        std::to_string(max_attempts_) + " attempts");
    }

    // Self-calibration (protocol v3). `initial`: the estimator's version 0
    // (staged head by head, then started with it); none: no model.
    void start_calibration(std::int64_t orbit_period_us, double time_constant_days, const ModelCoefficients* initial) {
        if (initial != nullptr) {
            send_calib_model(*initial, false);
        }
        std::uint8_t p[link::kMaxPayload];
        const std::size_t n = link::encode(
            link::CalibStart{orbit_period_us, time_constant_days, static_cast<std::uint8_t>(initial ? 1U : 0U)}, p);
        expect_ok(transact(link::MessageType::kCalibStart, {p, p + n}, link::MessageType::kAck), "calibration start");
        calibrating_ = true;
    }
    void calib_command(link::CalibCommand c) {
        std::uint8_t p[link::kMaxPayload];
        const std::size_t n = link::encode(c, p);
        expect_ok(transact(link::MessageType::kCalibCommand, {p, p + n}, link::MessageType::kAck),
                  "calibration command");
    }
    // A model for the estimator, active from the next epoch (version + 1).
    void load_calib_model(const ModelCoefficients& m) { send_calib_model(m, true); }
    calib::EstimatorReport calib_report() {
        const auto a = transact(link::MessageType::kCalibReportRequest, {}, link::MessageType::kCalibReport);
        calib::EstimatorReport r{};
        if (!link::decode(a.data(), a.size(), r)) {
            throw LinkError("malformed calibration report from the target (" + std::to_string(a.size()) + " bytes)");
        }
        return r;
    }

    const LinkStats& stats() const { return stats_; }

private:
    // Byte equality: at worst (padding that differs) an update is sent twice.
    template <typename A>
    static bool same(const A& a, const A& b) {
        return std::memcmp(&a, &b, sizeof a) == 0;
    }

    // The target corrected without the model or velocity this client gave
    // it: it has restarted, and its HELLO did not arrive. Its answer is not
    // accepted.
    bool lost_state(const link::SolutionOut<T>& out) const {
        const bool no_model = (out.status & status::kNoModelForHead) != 0U && model_ && out.head < kMaxHeads &&
                              model_->head[out.head].present;
        const bool no_velocity =
            (out.status & (status::kNoVelocity | status::kVelocityInvalid)) == status::kNoVelocity && velocity_ &&
            velocity_->valid && !from_states_;
        const bool no_state =
            from_states_ && velocity_expected_ &&
            (out.status & (status::kNoVelocity | status::kVelocityInvalid | status::kStale)) == status::kNoVelocity;
        return no_model || no_velocity || no_state;
    }

    void send_model(std::uint8_t head) {
        std::uint8_t p[link::kMaxPayload];
        const std::size_t n = link::encode(link::ModelUpload<T>{head, model_->head[head]}, p);
        expect_ok(transact(link::MessageType::kModelUpload, {p, p + n}, link::MessageType::kAck), "model upload");
    }
    void send_velocity() {
        std::uint8_t p[link::kMaxPayload];
        const std::size_t n = link::encode(*velocity_, p);
        expect_ok(transact(link::MessageType::kVelocityUpdate, {p, p + n}, link::MessageType::kAck), "velocity update");
    }
    void send_state_frame(const link::StateUpdate& s) {
        std::uint8_t p[link::kMaxPayload];
        const std::size_t n = link::encode(s, p);
        expect_ok(transact(link::MessageType::kStateUpdate, {p, p + n}, link::MessageType::kAck), "state update");
    }
    void send_temperatures(std::uint8_t head) {
        std::uint8_t p[link::kMaxPayload];
        const std::size_t n = link::encode(link::TemperatureUpdate<T>{head, *temperatures_[head]}, p);
        expect_ok(transact(link::MessageType::kTemperatureUpdate, {p, p + n}, link::MessageType::kAck),
                  "temperature update");
    }

    // Heads A..D of m, one frame each; the last with `load`.
    void send_calib_model(const ModelCoefficients& m, bool load) {
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
            std::uint8_t p[link::kMaxPayload];
            const std::size_t n = link::encode(f, p);
            expect_ok(transact(link::MessageType::kCalibModelLoad, {p, p + n}, link::MessageType::kAck),
                      "calibration model load");
        }
    }

    static void expect_ok(const std::vector<std::uint8_t>& p, const char* what) {
        link::Ack a{};
        if (!link::decode(p.data(), p.size(), a) || a.result != link::AckResult::kOk) {
            throw LinkError(std::string(what) + " refused by the target (result " +
                            std::to_string(static_cast<int>(a.result)) + ")");
        }
    }

    // The target restarted: give it back everything it had.
    void restore() {
        if (restoring_) {
            restart_again_ = true;  // a restart during restore: the outer restore starts over
            return;
        }
        if (calibrating_) {
            throw LinkError("the target restarted during self-calibration: its estimator's state is lost");
        }
        restoring_ = true;
        for (int round = 0;; ++round) {
            if (round == max_attempts_) {
                restoring_ = false;
                throw LinkError("the target restarted " + std::to_string(round) + " times while being restored");
            }
            restart_again_ = false;
            ++stats_.restarts;
            if (model_) {
                for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
                    send_model(h);
                }
            }
            if (velocity_) {
                send_velocity();
            }
            if (state_) {
                send_state_frame(*state_);
            }
            for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
                if (temperatures_[h]) {
                    send_temperatures(h);
                }
            }
            if (!restart_again_) {
                break;
            }
        }
        restoring_ = false;
    }

    std::vector<std::uint8_t> transact(link::MessageType type, const std::vector<std::uint8_t>& payload,
                                       link::MessageType answer) {
        seq_ = static_cast<std::uint16_t>(seq_ == 0xFFFFU ? 1U : seq_ + 1U);  // 0 is the target's unprompted HELLO
        const std::uint16_t seq = seq_;
        ++stats_.requests;
        std::uint8_t wire[link::kMaxWire];
        const std::size_t w =
            link::encode_frame(static_cast<std::uint8_t>(type), seq, payload.data(), payload.size(), wire, sizeof wire);
        // Given up after max_attempts and at least kMinPatienceMs: a target
        // that is booting (QEMU takes 0.3–1 s on a loaded machine, before its
        // first byte) must not exhaust 20 short time-outs.
        const auto give_up_after = std::chrono::steady_clock::now() + std::chrono::milliseconds(kMinPatienceMs);
        for (int attempt = 0; attempt < max_attempts_ || std::chrono::steady_clock::now() < give_up_after; ++attempt) {
            if (attempt > 0) {
                ++stats_.retries;
            }
            transport_.write(wire, w);
            bool restarted = false;
            if (auto got = await(seq, answer, restarted)) {
                return *got;
            }
            if (restarted) {
                restore();
                --attempt;  // a restart is not the request's failure
            }
        }
        throw LinkError("no answer from the target after " + std::to_string(max_attempts_) + " attempts");
    }

    // Waits for the answer to seq; empty when it is time to resend.
    std::optional<std::vector<std::uint8_t>> await(std::uint16_t seq, link::MessageType answer, bool& restarted) {
        const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(timeout_ms_);
        std::uint8_t buf[256];
        for (;;) {
            // Read what is there even when the time is up: an answer that has
            // arrived is never thrown away for a resend.
            const auto left =
                std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
            const std::size_t n =
                transport_.read(buf, sizeof buf, static_cast<int>(std::max<long long>(0, left.count())));
            if (n == 0) {
                ++stats_.timeouts;
                return std::nullopt;
            }
            for (std::size_t i = 0; i < n; ++i) {
                switch (decoder_.push(buf[i])) {
                    case link::FrameDecoder::Event::kNone:
                        break;
                    case link::FrameDecoder::Event::kError:
                        ++stats_.broken_answers;
                        break;  // its answer may still follow intact; otherwise the time-out resends
                    case link::FrameDecoder::Event::kFrame: {
                        const link::Frame& f = decoder_.frame();
                        const auto t = static_cast<link::MessageType>(f.type);
                        if (t == link::MessageType::kNak) {
                            ++stats_.naks;
                            return std::nullopt;  // resend at once
                        }
                        if (t == link::MessageType::kHello && f.seq == 0U && answer != link::MessageType::kHello) {
                            link::Hello h{};
                            if (link::decode(f.payload, f.length, h)) {
                                boot_id_ = h.boot_id;
                                restarted = true;
                                return std::nullopt;
                            }
                            ++stats_.stale_answers;
                            break;
                        }
                        if (f.seq == seq && t == answer) {
                            return std::vector<std::uint8_t>(f.payload, f.payload + f.length);
                        }
                        if (f.seq == seq && t == link::MessageType::kAck) {
                            link::Ack a{};
                            if (link::decode(f.payload, f.length, a) && a.result != link::AckResult::kOk) {
                                throw LinkError("request type " + std::to_string(static_cast<int>(answer)) +
                                                " refused by the target (result " +
                                                std::to_string(static_cast<int>(a.result)) + ")");
                            }
                        }
                        ++stats_.stale_answers;
                        break;
                    }
                }
            }
        }
    }

    static constexpr int kMinPatienceMs = 3000;
    Transport& transport_;
    int timeout_ms_;
    int max_attempts_;
    link::FrameDecoder decoder_;
    std::uint16_t seq_ = 0;
    std::uint32_t boot_id_ = 0;
    bool restoring_ = false;
    bool restart_again_ = false;
    std::optional<ThermalModel<T>> model_;
    std::optional<ObserverVelocity<T>> velocity_;
    std::optional<link::StateUpdate> state_;  // the latest accepted spacecraft state
    bool from_states_ = false;
    bool velocity_expected_ = false;
    bool calibrating_ = false;
    std::optional<HeadTemperatures<T>> temperatures_[kMaxHeads];
    LinkStats stats_;
};

}  // namespace ascorr::host
