// The host–DPU link: CRC, COBS, framing, messages and the target's server,
// including every kind of corruption the replay must survive.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <utility>
#include <vector>

#include "ascorr/core/table2.hpp"
#include "ascorr_host/formats/model_csv.hpp"
#include "ascorr_link/server.hpp"
#include "test_support.hpp"

namespace ascorr::link {
namespace {

using Bytes = std::vector<std::uint8_t>;

Bytes wire_frame(MessageType type, std::uint16_t seq, const Bytes& payload) {
    Bytes out(kMaxWire);
    const std::size_t n =
        encode_frame(static_cast<std::uint8_t>(type), seq, payload.data(), payload.size(), out.data(), out.size());
    out.resize(n);
    return out;
}

struct Decoded {
    std::vector<Frame> frames;
    std::vector<Bytes> payloads;
    std::vector<FrameError> errors;
};

Decoded decode_all(const Bytes& wire) {
    FrameDecoder d;
    Decoded out;
    for (std::uint8_t b : wire) {
        switch (d.push(b)) {
            case FrameDecoder::Event::kFrame:
                out.frames.push_back(d.frame());
                out.payloads.emplace_back(d.frame().payload, d.frame().payload + d.frame().length);
                break;
            case FrameDecoder::Event::kError:
                out.errors.push_back(d.error());
                break;
            case FrameDecoder::Event::kNone:
                break;
        }
    }
    return out;
}

TEST(Crc32c, CheckValue) {
    const char* s = "123456789";
    EXPECT_EQ(crc32c(reinterpret_cast<const std::uint8_t*>(s), 9), 0xE3069283U);
    EXPECT_EQ(crc32c(nullptr, 0), 0U);
}

TEST(Cobs, KnownVectorsAndRoundTrip) {
    // Vectors from the COBS paper (Cheshire & Baker 1999) examples.
    const Bytes in1 = {0x00};
    const Bytes in2 = {0x11, 0x22, 0x00, 0x33};
    std::uint8_t enc[300];
    ASSERT_EQ(cobs_encode(in1.data(), in1.size(), enc, sizeof enc), 2U);
    EXPECT_EQ(Bytes(enc, enc + 2), (Bytes{0x01, 0x01}));
    ASSERT_EQ(cobs_encode(in2.data(), in2.size(), enc, sizeof enc), 5U);
    EXPECT_EQ(Bytes(enc, enc + 5), (Bytes{0x03, 0x11, 0x22, 0x02, 0x33}));
    std::mt19937 rng(1);
    for (int trial = 0; trial < 2000; ++trial) {
        Bytes raw(static_cast<std::size_t>(rng() % 600));
        for (auto& b : raw) {
            b = static_cast<std::uint8_t>(rng() % 4 == 0 ? 0 : rng());
        }
        Bytes e(cobs_max_encoded(raw.size()));
        const std::size_t n = cobs_encode(raw.data(), raw.size(), e.data(), e.size());
        ASSERT_GT(n, 0U);
        for (std::size_t i = 0; i < n; ++i) {
            ASSERT_NE(e[i], 0U);
        }
        Bytes back(raw.size() + 1);
        const std::size_t m = cobs_decode(e.data(), n, back.data(), back.size());
        if (raw.empty()) {
            EXPECT_EQ(m, 0U);
        } else {
            ASSERT_EQ(m, raw.size());
            back.resize(m);
            EXPECT_EQ(back, raw);
        }
    }
    // Capacity is never exceeded.
    EXPECT_EQ(cobs_encode(in2.data(), in2.size(), enc, 4), 0U);
    EXPECT_EQ(cobs_decode(enc, 5, enc + 100, 3), 0U);
}

TEST(Frame, RoundTripAndResync) {
    Bytes stream = {0x00, 0x00};  // idle delimiters are ignored
    for (std::uint16_t seq = 0; seq < 50; ++seq) {
        Bytes p(seq % 30, static_cast<std::uint8_t>(seq));
        const Bytes f = wire_frame(MessageType::kSolutionIn, seq, p);
        stream.insert(stream.end(), f.begin(), f.end());
        if (seq % 7 == 0) {  // line noise between frames
            for (int g : {0x13, 0x37, 0x00}) {
                stream.push_back(static_cast<std::uint8_t>(g));
            }
        }
    }
    const Decoded d = decode_all(stream);
    ASSERT_EQ(d.frames.size(), 50U);
    for (std::uint16_t seq = 0; seq < 50; ++seq) {
        EXPECT_EQ(d.frames[seq].seq, seq);
        EXPECT_EQ(d.payloads[seq], Bytes(seq % 30, static_cast<std::uint8_t>(seq)));
    }
    EXPECT_EQ(d.errors.size(), 8U);  // each burst of noise is one broken frame, then resync
}

// Every single-bit error and every truncation of a frame is detected; no
// corrupted frame is ever accepted.
TEST(Frame, EveryBitFlipAndTruncationIsDetected) {
    Bytes payload(40);
    for (std::size_t i = 0; i < payload.size(); ++i) {
        payload[i] = static_cast<std::uint8_t>(i * 37 + 1);
    }
    const Bytes good = wire_frame(MessageType::kModelUpload, 0x1234, payload);
    for (std::size_t byte = 0; byte + 1 < good.size(); ++byte) {
        for (int bit = 0; bit < 8; ++bit) {
            Bytes bad = good;
            bad[byte] = static_cast<std::uint8_t>(bad[byte] ^ (1U << bit));
            bad.push_back(0);  // the receiver resynchronises at a delimiter in any case
            const Decoded d = decode_all(bad);
            EXPECT_TRUE(d.frames.empty()) << "flip at " << byte << ":" << bit;
        }
    }
    for (std::size_t cut = 1; cut + 1 < good.size(); ++cut) {
        Bytes bad(good.begin(), good.begin() + static_cast<std::ptrdiff_t>(cut));
        bad.push_back(0);
        const Decoded d = decode_all(bad);
        EXPECT_TRUE(d.frames.empty()) << "cut at " << cut;
        EXPECT_EQ(d.errors.size(), 1U);
    }
    const Decoded ok = decode_all(good);
    ASSERT_EQ(ok.frames.size(), 1U);
    EXPECT_EQ(ok.frames[0].seq, 0x1234);
}

TEST(Frame, OverlongInputIsBoundedAndReported) {
    Bytes noise(5 * kMaxEncoded, 0x55);
    noise.push_back(0);
    const Decoded d = decode_all(noise);
    ASSERT_EQ(d.errors.size(), 1U);
    EXPECT_EQ(d.errors[0], FrameError::kOverlong);
    std::uint8_t out[kMaxWire];
    std::uint8_t big[kMaxPayload + 1] = {};
    EXPECT_EQ(encode_frame(1, 0, big, sizeof big, out, sizeof out), 0U);
}

TEST(Frame, RandomGarbageNeverCrashesNorPassesAsAFrame) {
    std::mt19937 rng(9);
    FrameDecoder d;
    std::size_t frames = 0;
    for (int i = 0; i < 2000000; ++i) {
        const auto b = static_cast<std::uint8_t>(rng() % 16 == 0 ? 0 : rng());
        frames += d.push(b) == FrameDecoder::Event::kFrame ? 1U : 0U;
    }
    EXPECT_EQ(frames, 0U);  // 2e6 random bytes, a CRC-32C match is a 1 in 4e9 event per candidate
}

// ---- the server, driven in memory as the host would drive the target.
struct Loop {
    std::uint32_t fake_cycles = 0;
    struct Counter {
        std::uint32_t* c;
        std::uint32_t operator()() const { return *c += 100; }
    };
    LinkServer<float, Counter> server{0xC0FFEEU, Counter{&fake_cycles}};
    Bytes received;

    Decoded send(const Bytes& wire) {
        received.clear();
        auto sink = [this](const std::uint8_t* p, std::size_t n) { received.insert(received.end(), p, p + n); };
        for (std::uint8_t b : wire) {
            server.on_byte(b, sink);
        }
        return decode_all(received);
    }
    template <typename M>
    Decoded request(MessageType type, std::uint16_t seq, const M& m) {
        std::uint8_t p[kMaxPayload];
        const std::size_t n = encode(m, p);
        return send(wire_frame(type, seq, Bytes(p, p + n)));
    }
};

TEST(LinkServer, CorrectsLikeTheHostCoreBitForBit) {
    const host::ModelFile mf = host::read_model_file(test::data_path("model_table2.csv"));
    const ThermalModel<float> model = host::to_core<float>(mf);
    Loop loop;
    const Decoded hello = loop.send(wire_frame(MessageType::kHelloRequest, 1, {}));
    ASSERT_EQ(hello.frames.size(), 1U);
    Hello h{};
    ASSERT_TRUE(decode(hello.payloads[0].data(), hello.payloads[0].size(), h));
    EXPECT_EQ(h.boot_id, 0xC0FFEEU);
    EXPECT_EQ(h.scalar_kind, WireTraits<float>::kKind);
    std::uint16_t seq = 2;
    for (std::uint8_t head = 0; head < 3; ++head) {
        const Decoded a = loop.request(MessageType::kModelUpload, seq++, ModelUpload<float>{head, model.head[head]});
        ASSERT_EQ(a.frames.size(), 1U);
        Ack ack{};
        ASSERT_TRUE(decode(a.payloads[0].data(), a.payloads[0].size(), ack));
        EXPECT_EQ(ack.result, AckResult::kOk);
    }
    std::mt19937_64 rng(5);
    for (int i = 0; i < 500; ++i) {
        SolutionInput<float> in{};
        const Eigen::Quaterniond q = test::random_attitude(rng);
        in.q_chu_icrf = {static_cast<float>(q.w()), static_cast<float>(q.x()), static_cast<float>(q.y()),
                         static_cast<float>(q.z())};
        in.head = static_cast<std::uint8_t>(i % 4);  // head D has no model: status 256
        in.temperatures = {{static_cast<float>(i % 40) - 10.0F, i % 17 != 0}, {-5.0F, true}, {-20.0F, true}};
        const Eigen::Vector3d v = test::random_unit_vector(rng) * 1e-4;
        in.velocity = {
            {static_cast<float>(v.x()), static_cast<float>(v.y()), static_cast<float>(v.z())}, 1.0F, i % 11 != 0};
        loop.request(MessageType::kVelocityUpdate, seq++, in.velocity);
        loop.request(MessageType::kTemperatureUpdate, seq++, TemperatureUpdate<float>{in.head, in.temperatures});
        const Decoded r =
            loop.request(MessageType::kSolutionIn, seq++,
                         SolutionIn<float>{static_cast<std::uint32_t>(i), in.head, in.q_chu_icrf, {0}, 0, 0});
        ASSERT_EQ(r.frames.size(), 1U);
        ASSERT_EQ(r.frames[0].type, static_cast<std::uint8_t>(MessageType::kSolutionOut));
        SolutionOut<float> out{};
        ASSERT_TRUE(decode(r.payloads[0].data(), r.payloads[0].size(), out));
        const CorrectedSolution<float> want = correct_solution(in, CorrectionConfig<float>{true, &model});
        EXPECT_EQ(out.id, static_cast<std::uint32_t>(i));
        EXPECT_EQ(out.status, want.status);
        EXPECT_EQ(std::memcmp(&out.q_chu_icrf, &want.q_chu_icrf, sizeof want.q_chu_icrf), 0) << i;
        EXPECT_EQ(out.instructions, 100U);
    }
}

TEST(LinkServer, DuplicatesAreAnsweredFromCacheAndNotReapplied) {
    Loop loop;
    loop.send(wire_frame(MessageType::kHelloRequest, 1, {}));
    const SolutionIn<float> s{7, 0, {1.0F, 0.0F, 0.0F, 0.0F}, {0}, 0, 0};
    const Decoded first = loop.request(MessageType::kSolutionIn, 2, s);
    const Decoded again = loop.request(MessageType::kSolutionIn, 2, s);
    ASSERT_EQ(first.frames.size(), 1U);
    ASSERT_EQ(again.frames.size(), 1U);
    EXPECT_EQ(first.payloads[0], again.payloads[0]);
    EXPECT_EQ(loop.server.duplicates(), 1U);
    EXPECT_EQ(loop.server.solutions(), 1U);
}

TEST(LinkServer, BrokenFramesGetANakAndBadPayloadsAreRefused) {
    Loop loop;
    Bytes f = wire_frame(MessageType::kSolutionIn, 3, Bytes(21, 1));
    f[4] ^= 0x10;
    const Decoded nak = loop.send(f);
    ASSERT_EQ(nak.frames.size(), 1U);
    EXPECT_EQ(nak.frames[0].type, static_cast<std::uint8_t>(MessageType::kNak));
    EXPECT_EQ(loop.server.frame_errors(), 1U);
    // A well-framed request with a wrong payload: refused, never applied.
    const Decoded bad = loop.send(wire_frame(MessageType::kModelUpload, 4, Bytes(10, 0)));
    Ack ack{};
    ASSERT_TRUE(decode(bad.payloads.at(0).data(), bad.payloads.at(0).size(), ack));
    EXPECT_EQ(ack.result, AckResult::kBadPayload);
    ModelUpload<float> m{};
    m.head = 9;  // no such head
    const Decoded bad_head = loop.request(MessageType::kModelUpload, 5, m);
    ASSERT_TRUE(decode(bad_head.payloads.at(0).data(), bad_head.payloads.at(0).size(), ack));
    EXPECT_EQ(ack.result, AckResult::kBadPayload);
    const Decoded unknown = loop.send(wire_frame(static_cast<MessageType>(77), 6, {}));
    ASSERT_TRUE(decode(unknown.payloads.at(0).data(), unknown.payloads.at(0).size(), ack));
    EXPECT_EQ(ack.result, AckResult::kUnknownType);
    // Temperatures with an undefined validity bit are refused.
    Bytes t(14, 0);
    t[1] = 8;
    const Decoded bad_t = loop.send(wire_frame(MessageType::kTemperatureUpdate, 7, t));
    ASSERT_TRUE(decode(bad_t.payloads.at(0).data(), bad_t.payloads.at(0).size(), ack));
    EXPECT_EQ(ack.result, AckResult::kBadPayload);
}

// A velocity outside the core's domain is refused (kBadPayload), and the
// velocity held before it is dropped, so the next solution is flagged 4, not
// corrected with an older velocity.
TEST(LinkServer, VelocityOutsideTheDomainIsRefusedAndDropsTheHeldOne) {
    Loop loop;
    loop.send(wire_frame(MessageType::kHelloRequest, 1, {}));
    const auto ack_of = [](const Decoded& d) {
        Ack ack{};
        EXPECT_TRUE(decode(d.payloads.at(0).data(), d.payloads.at(0).size(), ack));
        return ack.result;
    };
    const auto status_of = [&loop](std::uint16_t seq) {
        const Decoded r =
            loop.request(MessageType::kSolutionIn, seq, SolutionIn<float>{seq, 0, {1.0F, 0, 0, 0}, {0}, 0, 0});
        SolutionOut<float> out{};
        EXPECT_TRUE(decode(r.payloads.at(0).data(), r.payloads.at(0).size(), out));
        EXPECT_NE(out.status & status::kNoModelForHead, 0U);  // no model uploaded: thermal skipped
        return static_cast<StatusBits>(out.status & ~status::kNoModelForHead);
    };
    const ObserverVelocity<float> good{{1e-4F, 0.0F, 0.0F}, 1.0F, true};
    EXPECT_EQ(ack_of(loop.request(MessageType::kVelocityUpdate, 2, good)), AckResult::kOk);
    EXPECT_EQ(status_of(3), status::kAberrationApplied);
    ObserverVelocity<float> bad = good;
    bad.inv_sun_distance_au = 1e9F;
    EXPECT_EQ(ack_of(loop.request(MessageType::kVelocityUpdate, 4, bad)), AckResult::kBadPayload);
    EXPECT_EQ(status_of(5), status::kNoVelocity);
    bad = good;
    bad.beta_icrf.x = 1.0F;  // |v| = c
    EXPECT_EQ(ack_of(loop.request(MessageType::kVelocityUpdate, 6, good)), AckResult::kOk);
    EXPECT_EQ(ack_of(loop.request(MessageType::kVelocityUpdate, 7, bad)), AckResult::kBadPayload);
    EXPECT_EQ(status_of(8), status::kNoVelocity);
    // "Not available" is a valid update whatever its numbers.
    ObserverVelocity<float> none = bad;
    none.valid = false;
    EXPECT_EQ(ack_of(loop.request(MessageType::kVelocityUpdate, 9, none)), AckResult::kOk);
}

// The learnt Sun term on the wire (issue 40): CALIB_START's sun_term after
// the lags (absent, the message as it was; beyond 1, refused), and
// CALIB_SUN_TERM whole, within a frame's payload.
TEST(LinkCodecs, TheLearntSunTermsMessagesDecodeWholeOrAsBefore) {
    std::uint8_t p[kMaxPayload] = {};
    CalibStart start{5'640'000'000, 30.0, 0};
    EXPECT_EQ(encode(start, p), 17U);
    start.sun_term = 1U;
    const std::size_t n = encode(start, p);
    EXPECT_EQ(n, 17U + 1U + 8U * kMaxHeads + 1U);  // common_rotation and the lags (0) come with it
    CalibStart back{};
    EXPECT_TRUE(decode(p, n, back) && back.sun_term == 1U && !pipeline::any_lagged(back.lag_s));
    EXPECT_TRUE(decode(p, n - 1U, back) && back.sun_term == 0U);  // a host before it: none
    EXPECT_FALSE(decode(p, n + 1U, back));
    p[n - 1U] = 2U;
    EXPECT_FALSE(decode(p, n, back));

    CalibSunTerm m{2, 7, {}};
    m.sun[2][1] = -0.75;
    const std::size_t k = encode(m, p);
    EXPECT_EQ(k, 1U + 4U + 8U * kModelAxes * kSunComponents);
    EXPECT_LE(k, kMaxPayload);
    CalibSunTerm got{};
    ASSERT_TRUE(decode(p, k, got));
    EXPECT_EQ(got.head, 2U);
    EXPECT_EQ(got.version, 7U);
    EXPECT_EQ(got.sun[2][1], -0.75);
    EXPECT_FALSE(decode(p, k - 1U, got));
    EXPECT_FALSE(decode(p, k + 1U, got));
    p[0] = kMaxHeads;
    EXPECT_FALSE(decode(p, k, got));

    // STACK_REPORT: two counts, exactly 8 bytes.
    const StackReport st{4224U, 8192U};
    const std::size_t ks = encode(st, p);
    EXPECT_EQ(ks, 8U);
    StackReport st_back{};
    ASSERT_TRUE(decode(p, ks, st_back));
    EXPECT_TRUE(st_back.high_water == 4224U && st_back.size == 8192U);
    EXPECT_FALSE(decode(p, ks - 1U, st_back));
    EXPECT_FALSE(decode(p, ks + 1U, st_back));

    // SUN_LEARNER_REPORT: every field through, the candidate by its CRC.
    SunLearnerReport r{1U, {}, 0xC0FFEE11U};
    r.report.orbits = 461U;
    r.report.cycles = 21'000'000'000ULL;
    r.report.score[0] = 2.5;
    r.report.score[1] = 1.25;
    r.report.gain = 0.5;
    r.report.rms_arcsec = 0.31;
    r.report.deciding = true;
    r.report.orbits_held = 455.5;
    r.report.orbits_to_decide = 450.0;
    r.report.taken = true;
    r.report.candidate.heads = 7U;
    r.report.candidate.rank = 18;
    r.report.candidate.orbits = 460U;
    r.report.candidate.epochs = 21'620ULL;
    r.report.candidate.solved = true;
    r.report.candidate.sun[0][0][0] = 0.8;  // not carried
    r.report.without_sun = 3U;
    r.report.not_finite = 4U;
    r.report.thinned = 5U;
    r.report.late = 6U;
    r.report.late_steps = 77;
    const std::size_t kr = encode(r, p);
    EXPECT_EQ(kr, 118U);
    EXPECT_LE(kr, kMaxPayload);
    SunLearnerReport back_r{};
    ASSERT_TRUE(decode(p, kr, back_r));
    EXPECT_EQ(back_r.learning, 1U);
    EXPECT_EQ(back_r.candidate_crc, 0xC0FFEE11U);
    const calib::SunLearnReport& b = back_r.report;
    EXPECT_TRUE(b.orbits == 461U && b.cycles == 21'000'000'000ULL && b.score[0] == 2.5 && b.score[1] == 1.25 &&
                b.gain == 0.5 && b.rms_arcsec == 0.31 && b.deciding && b.orbits_held == 455.5 &&
                b.orbits_to_decide == 450.0 && b.taken && b.without_sun == 3U && b.not_finite == 4U &&
                b.thinned == 5U && b.late == 6U && b.late_steps == 77);
    EXPECT_TRUE(b.candidate.heads == 7U && b.candidate.rank == 18 && b.candidate.orbits == 460U &&
                b.candidate.epochs == 21'620ULL && b.candidate.solved);
    EXPECT_EQ(b.candidate.sun[0][0][0], 0.0);
    EXPECT_FALSE(decode(p, kr - 1U, back_r));
    EXPECT_FALSE(decode(p, kr + 1U, back_r));
    p[0] = 2U;  // learning is 0 or 1
    EXPECT_FALSE(decode(p, kr, back_r));
    p[0] = 1U;
    p[kr - 4U - 8U - 4U - 1U] = 28U;  // a rank beyond the fit's 27 unknowns
    EXPECT_FALSE(decode(p, kr, back_r));
}

// Self-calibration on the link (protocol v3): the commands act on the
// estimator, a loaded model corrects from the next epoch, and every bad
// payload is refused with kBadPayload and changes nothing (the report, bit
// for bit, and the staged model: a later load gives the same CRC).
TEST(LinkServer, SelfCalibrationCommandsAndBadPayloads) {
    Loop loop;
    loop.send(wire_frame(MessageType::kHelloRequest, 1, {}));
    std::uint16_t seq = 2;
    const auto ack_of = [](const Decoded& d) {
        Ack ack{};
        EXPECT_TRUE(d.frames.size() == 1U && decode(d.payloads[0].data(), d.payloads[0].size(), ack));
        return ack.result;
    };
    const auto report_bytes = [&loop, &seq]() {
        const Decoded r = loop.send(wire_frame(MessageType::kCalibReportRequest, seq++, {}));
        EXPECT_EQ(r.frames.size(), 1U);
        EXPECT_EQ(r.frames.at(0).type, static_cast<std::uint8_t>(MessageType::kCalibReport));
        return r.payloads.at(0);
    };
    const auto report = [&report_bytes]() {
        const Bytes b = report_bytes();
        calib::EstimatorReport r{};
        EXPECT_TRUE(decode(b.data(), b.size(), r));
        return r;
    };
    const auto solution = [&loop, &seq](std::uint8_t head, std::int64_t t_us, std::uint8_t calib = 0U) {
        loop.request(MessageType::kTemperatureUpdate, seq++,
                     TemperatureUpdate<float>{head, {{12.0F, true}, {-5.0F, true}, {-20.0F, true}}});
        loop.request(MessageType::kVelocityUpdate, seq++, ObserverVelocity<float>{{1e-4F, 0.0F, 0.0F}, 1.0F, true});
        const Decoded r = loop.request(MessageType::kSolutionIn, seq++,
                                       SolutionIn<float>{seq, head, {0.5F, 0.5F, 0.5F, 0.5F}, {t_us}, 0, calib});
        SolutionOut<float> out{};
        EXPECT_TRUE(r.frames.size() == 1U && decode(r.payloads[0].data(), r.payloads[0].size(), out));
        return out;
    };

    const CalibStart start{5'640'000'000, 30.0, 0};
    {
        // common_rotation 0 is the 17 bytes of a host before it (a target
        // before it takes them); 1 adds the byte; one byte more is refused.
        std::uint8_t p[kMaxPayload] = {};
        EXPECT_EQ(encode(CalibStart{5'640'000'000, 30.0, 1, 0}, p), 17U);
        const std::size_t n = encode(CalibStart{5'640'000'000, 30.0, 1, 1}, p);
        EXPECT_EQ(n, 18U);
        CalibStart m{};
        EXPECT_TRUE(decode(p, n, m) && m.common_rotation == 1U && m.initial == 1U);
        EXPECT_TRUE(decode(p, n - 1U, m) && m.common_rotation == 0U);
        EXPECT_FALSE(decode(p, n + 1U, m));
    }
    EXPECT_EQ(ack_of(loop.request(MessageType::kCalibStart, seq++, start)), AckResult::kOk);
    EXPECT_NE(solution(0, 1'000'000).status & status::kNoModelForHead, 0U);  // no model yet: 256
    const Bytes before = report_bytes();

    // Bad payloads: each refused, nothing changed.
    std::vector<std::pair<MessageType, Bytes>> bad;
    bad.emplace_back(MessageType::kCalibCommand, Bytes{0});
    bad.emplace_back(MessageType::kCalibCommand, Bytes{4});
    bad.emplace_back(MessageType::kCalibCommand, Bytes{1, 0});
    bad.emplace_back(MessageType::kCalibCommand, Bytes{});
    bad.emplace_back(MessageType::kCalibReportRequest, Bytes{0});
    constexpr std::int64_t kOrbit = 5'640'000'000;
    for (const CalibStart& s :
         {CalibStart{0, 30.0, 0}, CalibStart{-5, 30.0, 0}, CalibStart{calib::kMinOrbitPeriodUs - 1, 30.0, 0},
          CalibStart{calib::kMaxOrbitPeriodUs + 1, 30.0, 0}, CalibStart{kOrbit, 0.0, 0}, CalibStart{kOrbit, 0.999, 0},
          CalibStart{kOrbit, 10000.001, 0}, CalibStart{kOrbit, std::nan(""), 0}, CalibStart{kOrbit, 30.0, 2},
          CalibStart{kOrbit, 30.0, 0, 2}}) {
        std::uint8_t p[kMaxPayload];
        bad.emplace_back(MessageType::kCalibStart, Bytes(p, p + encode(s, p)));
    }
    for (const ServiceConfig& c : {ServiceConfig{0}, ServiceConfig{-1}, ServiceConfig{kMaxHorizonUs + 1}}) {
        std::uint8_t p[kMaxPayload];
        bad.emplace_back(MessageType::kServiceConfig, Bytes(p, p + encode(c, p)));
    }
    bad.emplace_back(MessageType::kServiceConfig, Bytes{1, 2, 3});
    // SOLUTION_IN: a calibration bit beyond the two defined; "no time" with a
    // time tag or with the service's velocity.
    for (const SolutionIn<float>& in : {SolutionIn<float>{9, 0, {1.0F, 0, 0, 0}, {5}, 0, 4},
                                        SolutionIn<float>{9, 0, {1.0F, 0, 0, 0}, {5}, 0, kCalibNoTime},
                                        SolutionIn<float>{9, 0, {1.0F, 0, 0, 0}, {0}, 1, kCalibNoTime}}) {
        std::uint8_t p[kMaxPayload];
        bad.emplace_back(MessageType::kSolutionIn, Bytes(p, p + encode(in, p)));
    }
    bad.emplace_back(MessageType::kCalibModelRequest, Bytes{4});     // a head beyond D
    bad.emplace_back(MessageType::kCalibModelRequest, Bytes{0, 0});  // a byte too many
    bad.emplace_back(MessageType::kCalibModelRequest, Bytes{});
    bad.emplace_back(MessageType::kCalibSunTermRequest, Bytes{4});  // a head beyond D
    bad.emplace_back(MessageType::kCalibSunTermRequest, Bytes{0, 0});
    bad.emplace_back(MessageType::kSunLearnerReportRequest, Bytes{0});  // it has no payload
    bad.emplace_back(MessageType::kStackReportRequest, Bytes{0});       // it has no payload
    CalibModelLoad good{};
    good.head = 0;
    good.present = 1;
    good.load = 1;
    for (std::size_t a = 0; a < kModelAxes; ++a) {
        for (std::size_t t = 0; t < kLinearModelTerms; ++t) {
            good.c[a][t] = kTable2.coefficient[0][a][t];
        }
    }
    std::vector<CalibModelLoad> bad_models(6, good);
    bad_models[0].head = 4;
    bad_models[1].present = 2;
    bad_models[2].load = 2;
    bad_models[3].c[1][2] = std::nan("");
    bad_models[4].c[2][0] = kMaxLoadCoefficient;
    bad_models[5].c[0][3] = -std::numeric_limits<double>::infinity();
    for (const CalibModelLoad& m : bad_models) {
        std::uint8_t p[kMaxPayload];
        bad.emplace_back(MessageType::kCalibModelLoad, Bytes(p, p + encode(m, p)));
    }
    {
        std::uint8_t p[kMaxPayload];
        const std::size_t n = encode(good, p);
        bad.emplace_back(MessageType::kCalibModelLoad, Bytes(p, p + n - 1));  // truncated
        Bytes longer(p, p + n);
        longer.push_back(0);
        bad.emplace_back(MessageType::kCalibModelLoad, longer);  // a byte too many
    }
    for (const auto& [type, payload] : bad) {
        EXPECT_EQ(ack_of(loop.send(wire_frame(type, seq++, payload))), AckResult::kBadPayload);
    }
    EXPECT_EQ(report_bytes(), before);

    // Commands.
    EXPECT_EQ(ack_of(loop.request(MessageType::kCalibCommand, seq++, CalibCommand::kFreeze)), AckResult::kOk);
    EXPECT_TRUE(report().frozen);
    EXPECT_EQ(ack_of(loop.request(MessageType::kCalibCommand, seq++, CalibCommand::kResume)), AckResult::kOk);
    EXPECT_FALSE(report().frozen);
    EXPECT_EQ(ack_of(loop.request(MessageType::kCalibCommand, seq++, CalibCommand::kReset)), AckResult::kOk);

    // Load Table 2 (linear), head by head: active from the next epoch, version 1.
    ModelCoefficients want{};
    for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
        CalibModelLoad m = good;
        m.head = h;
        m.present = kTable2.present[h] ? 1U : 0U;
        m.load = h == kMaxHeads - 1U ? 1U : 0U;
        want.present[h] = kTable2.present[h];
        for (std::size_t a = 0; a < kModelAxes; ++a) {
            for (std::size_t t = 0; t < kLinearModelTerms; ++t) {
                m.c[a][t] = kTable2.present[h] ? kTable2.coefficient[h][a][t] : 0.0;
                want.coefficient[h][a][t] = m.c[a][t];
            }
        }
        EXPECT_EQ(ack_of(loop.request(MessageType::kCalibModelLoad, seq++, m)), AckResult::kOk);
    }
    const SolutionOut<float> out = solution(1, 2'000'000);
    const ThermalModel<float> model = thermal_model<float>(want, kArcsecToRad);
    SolutionInput<float> in{};
    in.q_chu_icrf = {0.5F, 0.5F, 0.5F, 0.5F};
    in.head = 1;
    in.temperatures = {{12.0F, true}, {-5.0F, true}, {-20.0F, true}};
    in.velocity = {{1e-4F, 0.0F, 0.0F}, 1.0F, true};
    const CorrectedSolution<float> c = correct_solution(in, CorrectionConfig<float>{true, &model});
    EXPECT_EQ(out.status, c.status);
    EXPECT_EQ(out.status, status::kAberrationApplied | status::kThermalApplied);
    EXPECT_EQ(std::memcmp(&out.q_chu_icrf, &c.q_chu_icrf, sizeof c.q_chu_icrf), 0);
    EXPECT_EQ(out.model_version, 1U);  // the loaded model: version 1
    // A solution without a time tag belongs to no epoch: no model (256), no version.
    const SolutionOut<float> untimed = solution(1, 0, kCalibNoTime);
    EXPECT_NE(untimed.status & status::kNoModelForHead, 0U);
    EXPECT_EQ(untimed.status & status::kThermalApplied, 0U);
    EXPECT_EQ(untimed.model_version, kNoModelVersion);
    {
        // CALIB_MODEL: head B of the active model, as loaded.
        const Decoded d = loop.send(wire_frame(MessageType::kCalibModelRequest, seq++, Bytes{1}));
        CalibModel m{};
        ASSERT_EQ(d.frames.size(), 1U);
        ASSERT_EQ(d.frames.at(0).type, static_cast<std::uint8_t>(MessageType::kCalibModel));
        ASSERT_TRUE(decode(d.payloads.at(0).data(), d.payloads.at(0).size(), m));
        EXPECT_EQ(m.head, 1U);
        EXPECT_EQ(m.version, 1U);
        EXPECT_EQ(m.active_from_us, 2'000'000);
        for (std::size_t a = 0; a < kModelAxes; ++a) {
            for (std::size_t t = 0; t < kLinearModelTerms; ++t) {
                EXPECT_EQ(m.c[a][t], want.coefficient[1][a][t]);
            }
        }
    }
    const calib::EstimatorReport r = report();
    EXPECT_TRUE(r.has_active);
    EXPECT_EQ(r.active_version, 1U);
    EXPECT_EQ(r.active_crc, calib::model_crc(want));
}
}  // namespace
}  // namespace ascorr::link
