// Hardware-in-the-loop replay without hardware: the host's LinkClient against
// the firmware's LinkServer in process, with faults injected on the link,
// target restarts and wrong answers.
#include <gtest/gtest.h>

#include <memory>
#include <random>
#include <sstream>

#include "ascorr_host/link_client.hpp"
#include "ascorr_host/model_csv.hpp"
#include "ascorr_host/replay.hpp"
#include "ascorr_link/server.hpp"
#include "replay_recording.hpp"
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

TEST(Replay, QemuTargetWithoutItsImageIsAnError) {
    host::ReplayOptions o;
    o.target = "qemu-m3";
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

}  // namespace
}  // namespace ascorr::test
