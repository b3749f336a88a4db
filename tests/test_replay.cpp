// Hardware-in-the-loop replay without hardware: the host's LinkClient against
// the firmware's LinkServer in process, with faults injected on the link,
// target restarts and wrong answers.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <poll.h>
#include <unistd.h>

#include <atomic>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <optional>
#include <random>
#include <sstream>
#include <thread>
#include <type_traits>

#include "ascorr/core/fixed_point.hpp"
#include "ascorr_host/formats/model_csv.hpp"
#include "ascorr_host/link/link_client.hpp"
#include "ascorr_host/link/qemu_targets.hpp"
#include "ascorr_host/link/replay.hpp"
#include "ascorr_link/server.hpp"
#include "cli_run.hpp"
#include "replay_recording.hpp"
#include "rewriting_loopback.hpp"
#include "test_support.hpp"

namespace ascorr::test {
namespace {

namespace fs = std::filesystem;

host::ReplaySummary run_replay(const fs::path& dir, int rows, double inject, std::uint64_t seed) {
    host::ReplayOptions o;
    o.target = "loopback-float";
    o.in = make_recording(dir, rows);
    o.model = data_path("model_table2.csv");
    o.out = (dir / "out.csv").string();
    o.inject_errors = inject;
    o.seed = seed;
    o.timeout_ms = 1;
    std::ostringstream log;
    return host::replay(o, log);
}

TEST(Replay, CleanLinkReturnsEverySolutionBitForBit) {
    const auto dir = scratch_dir("replay");
    const host::ReplaySummary s = run_replay(dir, 3000, 0.0, 1);
    EXPECT_EQ(s.frames, 3000U);
    EXPECT_EQ(s.returned, 3000U);
    EXPECT_EQ(s.mismatches, 0U);
    EXPECT_LE(s.max_error_arcsec, 0.05);
    EXPECT_EQ(s.crc_errors, 0U);
    EXPECT_EQ(s.retries, 0U);
}

TEST(Replay, FaultsInBothDirectionsAreRecovered) {
    const auto dir = scratch_dir("replay");
    for (double rate : {0.01, 0.05}) {
        const host::ReplaySummary s = run_replay(dir, 3000, rate, 7);
        EXPECT_EQ(s.returned, 3000U) << rate;
        EXPECT_EQ(s.mismatches, 0U) << rate;
        EXPECT_LE(s.max_error_arcsec, 0.05) << rate;
        EXPECT_GT(s.injected, 0U) << rate;
        EXPECT_GT(s.crc_errors, 0U) << rate;
        EXPECT_GT(s.retries, 0U) << rate;
    }
    // The file written under faults equals the one written on a clean link.
    run_replay(dir, 500, 0.0, 1);
    const std::string clean = host::read_text_file((dir / "out.csv").string());
    run_replay(dir, 500, 0.05, 3);
    EXPECT_EQ(host::read_text_file((dir / "out.csv").string()), clean);
}

// A target that restarts (loses its model) after a number of solutions, and
// one that answers with a well-framed solution for the wrong request.
class MisbehavingTarget {
public:
    struct Counter {
        std::uint32_t operator()() const { return 0; }
    };
    using Server = link::LinkServer<float, Counter>;

    // announce = false: the HELLO after the restart is lost on the link.
    explicit MisbehavingTarget(int restart_after, int wrong_id_every, bool announce = true)
        : restart_after_(restart_after),
          wrong_id_every_(wrong_id_every),
          announce_(announce),
          server_(new Server(1, Counter{})) {}

    void serve(const std::uint8_t* p, std::size_t n, const host::LoopbackTransport::Reply& reply) {
        for (std::size_t i = 0; i < n; ++i) {
            if (p[i] == 0U && ++frames_seen_ > 0 && solutions_ == restart_after_) {
                ++solutions_;
                server_ = std::make_unique<Server>(++boot_, Counter{});  // power cycle: state lost
                if (announce_) {
                    server_->announce(reply);
                }
                continue;  // the request in flight was lost with it
            }
            server_->on_byte(p[i], [&](const std::uint8_t* r, std::size_t m) {
                link::FrameDecoder d;
                for (std::size_t k = 0; k < m; ++k) {
                    if (d.push(r[k]) == link::FrameDecoder::Event::kFrame &&
                        d.frame().type == static_cast<std::uint8_t>(link::MessageType::kSolutionOut)) {
                        ++solutions_;
                        if (wrong_id_every_ > 0 && solutions_ % wrong_id_every_ == 0 && !lied_) {
                            lied_ = true;
                            link::SolutionOut<float> s{};
                            link::decode(d.frame().payload, d.frame().length, s);
                            s.id += 1;  // an answer for another solution, perfectly framed
                            std::uint8_t pl[link::kMaxPayload];
                            std::uint8_t w[link::kMaxWire];
                            const std::size_t wn =
                                link::encode_frame(d.frame().type, d.frame().seq, pl, link::encode(s, pl), w, sizeof w);
                            reply(w, wn);
                            return;
                        }
                        lied_ = false;
                    }
                }
                reply(r, m);
            });
        }
    }

private:
    int restart_after_;
    int wrong_id_every_;
    bool announce_;
    int solutions_ = 0;
    std::size_t frames_seen_ = 0;
    bool lied_ = false;
    std::uint32_t boot_ = 1;
    std::unique_ptr<Server> server_;
};

void check_against_host_core(MisbehavingTarget& target, std::size_t expect_restarts) {
    host::LoopbackTransport t(
        [&](const std::uint8_t* p, std::size_t n, const host::LoopbackTransport::Reply& r) { target.serve(p, n, r); });
    host::LinkClient<float> client(t, 1, 20);
    client.connect();
    const ThermalModel<float> model = host::to_core<float>(host::read_model_file(data_path("model_table2.csv")));
    client.upload_model(model);
    std::mt19937_64 rng(3);
    for (std::uint32_t i = 0; i < 300; ++i) {
        SolutionInput<float> in{};
        const Eigen::Quaterniond q = random_attitude(rng);
        in.q_chu_icrf = {static_cast<float>(q.w()), static_cast<float>(q.x()), static_cast<float>(q.y()),
                         static_cast<float>(q.z())};
        in.head = static_cast<std::uint8_t>(i % 3);
        in.temperatures = {{10.0F, true}, {-5.0F, true}, {-20.0F + static_cast<float>(i % 5), true}};
        in.velocity = {{1e-4F, -2e-5F, static_cast<float>(i) * 1e-7F}, 1.0F, true};
        client.set_velocity(in.velocity);
        client.set_temperatures(in.head, in.temperatures);
        const auto got = client.correct(i, in.head, in.q_chu_icrf);
        const auto want = correct_solution(in, CorrectionConfig<float>{true, &model});
        ASSERT_EQ(got.id, i);
        ASSERT_EQ(got.status, want.status) << i;
        ASSERT_EQ(std::memcmp(&got.q_chu_icrf, &want.q_chu_icrf, sizeof want.q_chu_icrf), 0) << i;
    }
    EXPECT_EQ(client.stats().restarts, expect_restarts);
}

TEST(Replay, TargetRestartIsDetectedAndStateRestored) {
    MisbehavingTarget target(120, 0);
    check_against_host_core(target, 1);
}

TEST(Replay, RestartWithItsHelloLostIsDetectedFromTheAnswer) {
    MisbehavingTarget target(120, 0, false);
    check_against_host_core(target, 1);
}

TEST(Replay, AnAnswerForAnotherSolutionIsNeverAccepted) {
    MisbehavingTarget target(-1, 10);
    check_against_host_core(target, 0);
}

// A request the target refuses is a LinkRefused with its result and the
// request named; a report the target does not know (a firmware from before
// it) is none, not an error; any other refusal of it is.
TEST(Replay, RefusalsCarryTheirResultAndNameTheRequest) {
    std::optional<std::uint8_t> rewrite_to;
    std::size_t pad = 0;
    RewritingLoopback target([&](std::uint8_t& type, std::uint8_t* payload, std::size_t& n) {
        if (type != static_cast<std::uint8_t>(link::MessageType::kStackReportRequest)) {
            return;
        }
        type = rewrite_to.value_or(type);
        for (; pad > 0 && n < link::kMaxPayload; --pad) {
            payload[n++] = 0U;
        }
    });
    host::LinkClient<float> client(target.transport(), 50, 3);
    client.connect();
    ASSERT_TRUE(client.stack_report().has_value());  // in process: 0 of 0 bytes, not measured
    EXPECT_EQ(client.stack_report()->size, 0U);
    rewrite_to = std::uint8_t{0xEE};  // a type no target knows
    EXPECT_FALSE(client.stack_report().has_value());
    rewrite_to.reset();
    pad = 1;  // the request with a payload it must not have
    try {
        (void)client.stack_report();
        ADD_FAILURE() << "a refused stack report was accepted";
    } catch (const host::LinkRefused& e) {
        EXPECT_EQ(e.result(), link::AckResult::kBadPayload);
        EXPECT_STREQ(e.what(), "stack report request refused by the target (result 2: bad payload)");
    }
    try {
        (void)client.calib_sun_term(9);  // no such head
        ADD_FAILURE() << "a Sun term of head 9 was answered";
    } catch (const host::LinkRefused& e) {
        EXPECT_EQ(e.result(), link::AckResult::kBadPayload);
        EXPECT_NE(std::string(e.what()).find("calibration Sun term request refused"), std::string::npos) << e.what();
    }
}

// An ACK that does not decode (here: cut to its first byte) is an error of
// its own, naming the request, not a refusal and not a stale answer to
// resend for: the answer cannot be read.
TEST(Replay, AMalformedAcknowledgementNamesTheRequest) {
    using Counter = std::uint32_t (*)();
    link::LinkServer<float, Counter> server(0x54455354U, [] { return std::uint32_t{0}; });
    link::FrameDecoder from_target;
    bool cut_acks = false;
    host::LoopbackTransport transport([&](const std::uint8_t* p, std::size_t n,
                                          const host::LoopbackTransport::Reply& reply) {
        const auto cut = [&](const std::uint8_t* q, std::size_t m) {
            for (std::size_t i = 0; i < m; ++i) {
                if (from_target.push(q[i]) != link::FrameDecoder::Event::kFrame) {
                    continue;
                }
                const link::Frame& f = from_target.frame();
                const bool ack = f.type == static_cast<std::uint8_t>(link::MessageType::kAck);
                std::uint8_t wire[link::kMaxWire];
                const std::size_t w =
                    link::encode_frame(f.type, f.seq, f.payload, cut_acks && ack ? 1U : f.length, wire, sizeof wire);
                reply(wire, w);
            }
        };
        for (std::size_t i = 0; i < n; ++i) {
            server.on_byte(p[i], cut);
        }
    });
    host::LinkClient<float> client(transport, 50, 3);
    client.connect();
    cut_acks = true;
    try {
        (void)client.calib_sun_term(9);  // refused (no such head), its ACK cut
        ADD_FAILURE() << "a malformed acknowledgement was accepted";
    } catch (const host::LinkRefused& e) {
        ADD_FAILURE() << "a malformed acknowledgement read as a refusal: " << e.what();
    } catch (const host::LinkError& e) {
        EXPECT_STREQ(e.what(), "malformed acknowledgement of calibration Sun term request from the target (1 bytes)");
    }
    EXPECT_EQ(client.stats().stale_answers, 0U);
}

// A restart's HELLO that arrives in the same read as the answer before it
// (a DPU that resets just after answering) is heard at the next request, not
// dropped with the rest of the read: the session is restored before that
// request is answered, and the target corrects as the host's core does.
TEST(Replay, ARestartsHelloInTheSameReadAsAnAnswerIsHeard) {
    using Counter = std::uint32_t (*)();
    using Server = link::LinkServer<float, Counter>;
    auto server = std::make_unique<Server>(1, [] { return std::uint32_t{0}; });
    bool restart_after_answer = false;
    std::size_t hellos = 0;
    host::LoopbackTransport transport(
        [&](const std::uint8_t* p, std::size_t n, const host::LoopbackTransport::Reply& reply) {
            for (std::size_t i = 0; i < n; ++i) {
                bool answered = false;
                server->on_byte(p[i], [&](const std::uint8_t* r, std::size_t m) {
                    answered = true;
                    reply(r, m);
                });
                if (answered && restart_after_answer) {  // power cycle: state lost, the HELLO queued after the answer
                    restart_after_answer = false;
                    server = std::make_unique<Server>(2, [] { return std::uint32_t{0}; });
                    server->announce(reply);
                    ++hellos;
                }
            }
        });
    host::LinkClient<float> client(transport, 50, 3);
    client.connect();
    const ThermalModel<float> model = host::to_core<float>(host::read_model_file(data_path("model_table2.csv")));
    client.upload_model(model);
    SolutionInput<float> in{};
    in.q_chu_icrf = {0.5F, 0.5F, 0.5F, 0.5F};
    in.head = 1;
    in.temperatures = {{10.0F, true}, {-5.0F, true}, {-20.0F, true}};
    in.velocity = {{1e-4F, -2e-5F, 3e-5F}, 1.0F, true};
    client.set_velocity(in.velocity);
    restart_after_answer = true;
    client.set_temperatures(0, in.temperatures);  // answered, then the target restarts
    ASSERT_EQ(hellos, 1U);
    EXPECT_EQ(client.stats().restarts, 0U);
    client.set_temperatures(in.head, in.temperatures);
    EXPECT_EQ(client.stats().restarts, 1U);  // heard before any solution could show it
    const auto got = client.correct(7, in.head, in.q_chu_icrf);
    const auto want = correct_solution(in, CorrectionConfig<float>{true, &model});
    EXPECT_EQ(got.status, want.status);
    EXPECT_EQ(std::memcmp(&got.q_chu_icrf, &want.q_chu_icrf, sizeof want.q_chu_icrf), 0);
    EXPECT_EQ(client.stats().restarts, 1U);
}

// A serial device without hardware: a pseudo-terminal whose master end is
// served, in a thread, by the firmware's LinkServer<T>, as a DPU on a UART
// would. The host opens the slave end (/dev/pts/N) as it would /dev/ttyUSB0.
template <typename T>
class PtyTarget {
public:
    struct Counter {
        std::uint32_t operator()() const { return 0; }
    };
    PtyTarget() : server_(0x50545900U, Counter{}) {
        master_ = ::posix_openpt(O_RDWR | O_NOCTTY);
        if (master_ < 0 || ::grantpt(master_) != 0 || ::unlockpt(master_) != 0 || ::ptsname(master_) == nullptr) {
            throw std::runtime_error("no pseudo-terminal");
        }
        device_ = ::ptsname(master_);
        thread_ = std::thread([this] { serve(); });
    }
    ~PtyTarget() {
        stop_ = true;
        thread_.join();
        ::close(master_);
    }
    const std::string& device() const { return device_; }
    std::uint32_t solutions() const { return solutions_; }

private:
    void serve() {
        std::uint8_t buf[512];
        while (!stop_) {
            pollfd p{master_, POLLIN, 0};
            if (::poll(&p, 1, 20) <= 0 || (p.revents & POLLIN) == 0) {
                continue;  // also POLLHUP while the host has the slave closed
            }
            const ssize_t n = ::read(master_, buf, sizeof buf);
            for (ssize_t i = 0; i < n; ++i) {
                server_.on_byte(buf[i], [this](const std::uint8_t* r, std::size_t m) {
                    for (std::size_t k = 0; k < m;) {
                        const ssize_t w = ::write(master_, r + k, m - k);
                        k += w > 0 ? static_cast<std::size_t>(w) : 0U;
                    }
                });
            }
            solutions_ = server_.solutions();
        }
    }
    link::LinkServer<T, Counter> server_;
    int master_ = -1;
    std::string device_;
    std::atomic<bool> stop_{false};
    std::atomic<std::uint32_t> solutions_{0};
    std::thread thread_;
};

template <typename T>
void replay_over_serial(const char* what) {
    PtyTarget<T> target;
    const auto dir = scratch_dir("replay-serial");
    host::ReplayOptions o;
    o.target = target.device();
    o.in = make_recording(dir, 400);
    o.model = data_path("model_table2.csv");
    o.out = (dir / "out.csv").string();
    std::ostringstream log;
    const host::ReplaySummary s = host::replay(o, log);
    EXPECT_EQ(s.returned, 400U) << what;
    EXPECT_EQ(s.mismatches, 0U) << what;  // bit for bit with the host core in the target's scalar
    const double bound = std::is_same_v<T, Q30> ? 0.01 : 0.05;
    EXPECT_LE(s.max_error_arcsec, bound) << what;
    EXPECT_NE(log.str().find("scalar kind " + std::to_string(link::WireTraits<T>::kKind)), std::string::npos)
        << log.str();
    EXPECT_GE(target.solutions(), 400U) << what;
}

// The session's scalar comes from the target's HELLO: a float DPU and a
// fixed-point one on the same serial path.
TEST(Replay, SerialDeviceSpeaksTheTargetsScalar) {
    replay_over_serial<float>("float target");
    replay_over_serial<Q30>("Q30 target");
}

// A model the Q30 formats cannot hold is refused before anything is sent, as
// `ascorr correct --scalar fixed` refuses it, with the coefficient named.
TEST(Replay, FixedPointTargetRefusesAModelBeyondItsFormats) {
    PtyTarget<Q30> target;
    const auto dir = scratch_dir("replay-serial");
    const std::string model = (dir / "big.csv").string();
    std::ofstream(model) << "chu,axis,c0,c1,c2,c3\nA,alpha,7000,0,0,0\nA,beta,0,0,0,0\nA,gamma,0,0,0,0\n";
    host::ReplayOptions o;
    o.target = target.device();
    o.in = make_recording(dir, 10);
    o.model = model;
    o.out = (dir / "out.csv").string();
    std::ostringstream log;
    try {
        host::replay(o, log);
        ADD_FAILURE() << "accepted";
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find("A alpha c0 = 7000"), std::string::npos) << e.what();
    }
    EXPECT_EQ(target.solutions(), 0U);
    EXPECT_FALSE(std::ifstream(o.out).good());
}

TEST(Replay, QemuTargetWithoutItsImageIsAnError) {
    host::ReplayOptions o;
    o.target = std::string(host::kQemuTargets[0].replay);
    o.firmware = (scratch_dir("replay") / "missing.elf").string();
    std::ostringstream log;
    EXPECT_THROW(host::replay(o, log), std::runtime_error);
}

TEST(Replay, UnknownTargetIsAnError) {
    host::ReplayOptions o;
    o.target = "qemu-z80";
    std::ostringstream log;
    EXPECT_THROW(host::replay(o, log), std::runtime_error);
}

// `ascorr replay --help` offers every board of toolchain/targets.txt with its
// image's scalar, and no other (the text is built from the generated table).
TEST(Replay, HelpOffersEveryQemuTargetOfTheTableWithItsScalar) {
    const fs::path dir = scratch_dir("replay_help");
    const CliRun r = run_here("replay --help > " + (dir / "help.txt").string(), dir);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    std::string help = slurp(dir / "help.txt");
    for (char& c : help) {  // CLI11 wraps long descriptions
        if (c == '\n') {
            c = ' ';
        }
    }
    std::string squeezed;
    for (const char c : help) {
        if (c != ' ' || squeezed.empty() || squeezed.back() != ' ') {
            squeezed += c;
        }
    }
    for (const host::QemuTarget& t : host::kQemuTargets) {
        const std::string choice =
            std::string(t.replay) + (t.scalar == host::ScalarKind::kFixed ? " (Q30)" : " (float)");
        EXPECT_NE(squeezed.find(choice), std::string::npos) << choice << " not in:\n" << help;
    }
    EXPECT_NE(squeezed.find(host::qemu_target_choices() + ", " + host::kLoopbackFloat + ", " + host::kLoopbackFixed),
              std::string::npos)
        << help;
}

}  // namespace
}  // namespace ascorr::test
