// The Sun term on the link (issue 40): SUN_TERM_UPLOAD, the target folding
// each head's term into its thermal stage (the flight form,
// core/correct.hpp) with the Sun's direction at the epoch's time, and
// `replay --model` of a model with a Sun term on the loopback targets against
// `ascorr correct` (the contract's form); the QEMU boards:
// test_replay_qemu.cpp. The mission is simulate's, with an orbit-periodic
// term; the model is its truth with a Sun term of 2″ per coefficient.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <limits>
#include <sstream>
#include <string>
#include <type_traits>
#include <vector>

#include "ascorr/core/fixed_point.hpp"
#include "ascorr/nav/sun_direction.hpp"
#include "ascorr/nav/tt_time.hpp"
#include "ascorr_host/formats/model_csv.hpp"
#include "ascorr_host/link/link_client.hpp"
#include "ascorr_host/link/link_transport.hpp"
#include "ascorr_host/link/replay.hpp"
#include "ascorr_link/messages.hpp"
#include "cli_run.hpp"
#include "corrected_files.hpp"
#include "lagged_models.hpp"
#include "restarting_target.hpp"
#include "test_support.hpp"

namespace ascorr::test {
namespace {

namespace fs = std::filesystem;

// The mission (0.3 days, an orbit term of 2″), m.csv its truth and
// m_sun.csv the same with a Sun term of 2″ per coefficient.
const fs::path& mission() {
    static const fs::path dir = [] {
        const fs::path d = scratch_dir("sun-on-link");
        EXPECT_EQ(run_in("simulate --days 0.3 --orbit-term 2 --out s.csv > /dev/null", d).exit_code, 0);
        write_truth_models(d, "900");
        write_sun_model(d, "m.csv", "m_sun.csv", 2.0);
        return d;
    }();
    return dir;
}

host::ModelFile model_file(const char* name) {
    return host::read_model_file((mission() / name).string());
}

// SUN_TERM_UPLOAD: the head and nine words, each as the target's scalar holds
// it; refused (decode false) for a bad head or length, a word that is not
// finite, or an axis whose |S| row sum passes the core's domain (1°).
template <typename T>
void expect_upload_round_trip() {
    using S = ScalarTraits<T>;
    link::SunTermUpload<T> m{};
    m.head = 2;
    for (std::size_t a = 0; a < kModelAxes; ++a) {
        for (std::size_t c = 0; c < kSunComponents; ++c) {
            const double sign = (a + c) % 2 == 0 ? 1.0 : -1.0;
            m.coefficient[a][c] = S::from_double(sign * static_cast<double>(3 * a + c + 1) * kArcsecToRad);
        }
    }
    std::uint8_t p[link::kMaxPayload] = {};
    const std::size_t n = link::encode(m, p);
    EXPECT_EQ(n, 1U + 9U * 4U);
    link::SunTermUpload<T> back{};
    ASSERT_TRUE(link::decode(p, n, back));
    EXPECT_EQ(back.head, 2U);
    EXPECT_EQ(std::memcmp(&back.coefficient, &m.coefficient, sizeof m.coefficient), 0);
    EXPECT_FALSE(link::decode(p, n - 1U, back));
    EXPECT_FALSE(link::decode(p, n + 1U, back));
    link::SunTermUpload<T> bad = m;
    bad.head = kMaxHeads;
    EXPECT_FALSE(link::decode(p, link::encode(bad, p), back));
    // Beyond the domain: 0.6° + 0.6° on one axis (each word alone within it).
    bad = m;
    bad.coefficient[1][0] = S::from_double(0.6 * kMaxThermalAngleRad);
    bad.coefficient[1][2] = S::from_double(-0.6 * kMaxThermalAngleRad);
    EXPECT_FALSE(link::decode(p, link::encode(bad, p), back));
    bad.coefficient[1][2] = S::from_double(0.4 * kMaxThermalAngleRad);
    bad.coefficient[1][1] = constant<T>(0.0);
    EXPECT_TRUE(link::decode(p, link::encode(bad, p), back));  // 1° exactly: the edge is in
    if constexpr (std::is_same_v<T, float>) {
        bad = m;
        bad.coefficient[2][1] = std::numeric_limits<float>::quiet_NaN();
        EXPECT_FALSE(link::decode(p, link::encode(bad, p), back));
        bad.coefficient[2][1] = std::numeric_limits<float>::infinity();
        EXPECT_FALSE(link::decode(p, link::encode(bad, p), back));
    }
}

TEST(SunLink, TheUploadCarriesNineWordsAndRefusesWhatTheCoreCannotTake) {
    expect_upload_round_trip<float>();
    expect_upload_round_trip<Q30>();
}

// What the target should answer for `in` at t_us (0: no time): the core's
// flight form with the Sun's direction at t, as the target forms it once per
// epoch (nav/sun_direction.hpp, rounded to float).
CorrectedSolution<float> flight_form(const SolutionInput<float>& in, const ThermalModel<float>& model,
                                     const SunTermModel<float>& sun, std::int64_t t_us) {
    Vector3<double> s{};
    const bool known = t_us != 0 && nav::sun_direction_icrf(tt_seconds(TtTime{t_us}), s);
    const Vector3<float> s_f{static_cast<float>(s.x), static_cast<float>(s.y), static_cast<float>(s.z)};
    return correct_solution(in, CorrectionConfig<float>{true, &model}, SunTermInput<float>{&sun, s_f, known});
}

bool same(const CorrectedSolution<float>& want, const link::SolutionOut<float>& got) {
    return want.status == got.status && std::memcmp(&want.q_chu_icrf, &got.q_chu_icrf, sizeof got.q_chu_icrf) == 0;
}

// m_sun.csv in float, with head B's term taken out (B: no term).
SunTermModel<float> sun_without_b(const host::ModelFile& mf) {
    SunTermModel<float> sun = host::sun_term_of<float>(mf);
    for (auto& axis : sun.coefficient[1]) {
        for (float& c : axis) {
            c = 0.0F;
        }
    }
    keep_present_where_terms(sun);
    return sun;
}

// A solution of head A: its attitude, velocity and temperatures (head 0).
SolutionInput<float> head_a_solution() {
    SolutionInput<float> in{};
    in.q_chu_icrf = {0.5F, 0.5F, -0.5F, 0.5F};
    in.velocity = {{2.5e-5F, -1e-5F, 8e-6F}, 1.0F, true};
    in.temperatures = {{{12.0F}, true}, {{-3.0F}, true}, {{-18.0F}, true}};
    return in;
}

constexpr std::int64_t kT2025 = 800'000'000'000'000;

// A float client over a RestartingTarget (restart_after answers), connected,
// with m_sun.csv's model and its Sun terms (B: none) uploaded.
struct SunSession {
    explicit SunSession(int restart_after)
        : target(restart_after),
          transport([this](const std::uint8_t* p, std::size_t n, const host::LoopbackTransport::Reply& r) {
              target.serve(p, n, r);
          }),
          client(transport, 1, 20) {
        client.connect();
        client.upload_model(model);
        client.upload_sun_term(sun);
    }
    host::ModelFile mf = model_file("m_sun.csv");
    ThermalModel<float> model = host::to_core<float>(mf);
    SunTermModel<float> sun = sun_without_b(mf);
    RestartingTarget target;
    host::LoopbackTransport transport;
    host::LinkClient<float> client;
};

// The target's answers, head by head: a head with a term takes the flight
// form at the epoch's Sun, bit for bit (and differs from the core without
// it: the mutation check); a head without one the core's bytes, with or
// without a time; a solution of a head with a term with no time, or at a
// time outside the Sun's span (2052), 128 with the aberration alone; an
// all-zero upload ends the term, and so does a MODEL_UPLOAD. A restart (here
// at the first solution) restores the terms with the model. While the
// estimator runs an upload is refused.
TEST(SunLink, TheTargetFoldsTheTermIntoEachEpochAndNeedsItsTime) {
    SunSession session(11);  // connect 1, model 4, Sun term 4, velocity 1, temperatures 1: then a restart
    const ThermalModel<float>& model = session.model;
    const SunTermModel<float>& sun = session.sun;
    host::LinkClient<float>& client = session.client;
    SolutionInput<float> in = head_a_solution();
    client.set_velocity(in.velocity);
    const std::int64_t t_2025 = kT2025;
    const std::int64_t t_2052 = 1'650'000'000'000'000;
    std::uint32_t id = 0;
    const auto answer = [&](std::uint8_t h, std::int64_t t_us) {
        in.head = h;
        client.set_temperatures(h, in.temperatures);
        return client.correct(id++, h, in.q_chu_icrf, TtTime{t_us}, false, false, t_us == 0 ? link::kCalibNoTime : 0U);
    };
    const CorrectedSolution<float> plain_a = [&] {
        in.head = 0;
        return correct_solution(in, CorrectionConfig<float>{true, &model});
    }();
    const link::SolutionOut<float> a = answer(0, t_2025);
    EXPECT_EQ(client.stats().restarts, 1U);
    EXPECT_TRUE(same(flight_form(in, model, sun, t_2025), a));
    EXPECT_EQ(a.status, status::kAberrationApplied | status::kThermalApplied);
    EXPECT_GT(angle_arcsec(in_double(a.q_chu_icrf), in_double(plain_a.q_chu_icrf)), 0.5);
    for (const std::int64_t t_us : {t_2025, std::int64_t{0}}) {  // a head without a term needs no time
        const link::SolutionOut<float> b = answer(1, t_us);
        EXPECT_TRUE(same(correct_solution(in, CorrectionConfig<float>{true, &model}), b)) << t_us;
        EXPECT_EQ(b.status, status::kAberrationApplied | status::kThermalApplied) << t_us;
    }
    for (const std::int64_t unknown : {std::int64_t{0}, t_2052}) {
        const link::SolutionOut<float> u = answer(0, unknown);
        EXPECT_EQ(u.status, status::kAberrationApplied | status::kThermalOutOfRange) << unknown;
        EXPECT_TRUE(same(flight_form(in, model, sun, unknown), u)) << unknown;
    }
    client.upload_sun_term(SunTermModel<float>{});
    EXPECT_TRUE(same(plain_a, answer(0, t_2025 + 1'000'000)));
    // A model ends its heads' terms: the next SUN_TERM_UPLOAD gives the new one's.
    client.upload_sun_term(sun);
    EXPECT_TRUE(same(flight_form(in, model, sun, t_2025 + 2'000'000), answer(0, t_2025 + 2'000'000)));
    client.upload_model(model);
    EXPECT_TRUE(same(plain_a, answer(0, t_2025 + 3'000'000)));
    client.start_calibration(5'700'000'000, 30.0, nullptr);
    EXPECT_THROW(client.upload_sun_term(sun), host::LinkError);
}

// A restart in the middle of the terms' upload (at head C's, after A's and
// B's were taken): the restore sends the model and every term again, so
// head A's first answer has its term.
TEST(SunLink, ARestartDuringTheUploadRestoresEveryTerm) {
    SunSession session(7);  // connect 1, model 4, Sun terms of A and B: then a restart
    host::LinkClient<float>& client = session.client;
    EXPECT_EQ(client.stats().restarts, 1U);
    SolutionInput<float> in = head_a_solution();
    client.set_velocity(in.velocity);
    client.set_temperatures(0, in.temperatures);
    const link::SolutionOut<float> a = client.correct(0, 0, in.q_chu_icrf, TtTime{kT2025});
    EXPECT_TRUE(same(flight_form(in, session.model, session.sun, kT2025), a));
    EXPECT_EQ(a.status, status::kAberrationApplied | status::kThermalApplied);
}

// `replay` of a model with a Sun term: the loopback target (float) folds it
// in (the flight form), bit for bit as the host's pipeline, within the float
// bound of the replay tests (0.05″) of the double reference (the contract's
// form) and of `ascorr correct`'s file, every status the same. Mutation: the
// same model without its term is arcseconds away, so the term is applied.
// Q30: the QEMU M3 board (test_replay_qemu.cpp).
TEST(ReplaySun, TheLoopbackTargetAnswersAsCorrectDoesWithinItsBound) {
    (void)expect_replay_as_correct(mission(), "m_sun.csv", "the Sun term");
}

// The link's loader: a head whose polynomial and Sun term together can pass
// ±1° at temperatures the core accepts is refused before the target sees it
// (where the flight form would skip the stage and the contract's form apply
// both rotations), naming the file, line, head and axis; at 1° it is taken,
// and so is an axis without a term. So is a term that rounds to 0 in the
// target's scalar (which would take it as none: no 128 where `correct` gives
// it), named at the head's first axis with a term. `correct` takes every one
// of them, and in every scalar gives such a term's rows beyond 2051 its 128.
TEST(ReplaySun, AModelTheTargetWouldEvaluateOtherwiseIsRefused) {
    const fs::path& dir = mission();
    // Head A's alpha: c1 (3500″ at 200 °C for 17.5″/°C) and its Sun term;
    // head B's gamma its own term; the other rows a term of 0.75″ and a
    // polynomial of 20″.
    const auto model = [&](const char* c1, const char* a_sun, const char* b_sun = "0.5,0.25,0") {
        std::string text = "chu,axis,c0,c1,c2,c3,sun_x,sun_y,sun_z\n";
        for (const std::string h : {"A", "B", "C"}) {
            for (const std::string a : {"alpha", "beta", "gamma"}) {
                const bool edge = h == "A" && a == "alpha";
                const std::string b_term = a == "gamma" ? b_sun : "0,0,0";
                const std::string term = edge ? a_sun : h == "B" ? b_term : "0.5,0.25,0";
                text += h + "," + a + ",0," + (edge ? c1 : "0.1") + ",0,0," + term + "\n";
            }
        }
        return text;
    };
    write(dir / "big.csv", model("17.5", "200,0.25,0"));
    write(dir / "edge.csv", model("17", "199.75,0.25,0"));
    write(dir / "none.csv", model("18.5", "0,0,0"));
    write(dir / "tiny.csv", model("0.1", "0.5,0.25,0", "1e-40,0,0"));
    const CliRun refused = run_in("replay --target loopback-float --in s.csv --model big.csv --out rb.csv", dir);
    expect_refused(refused, 1,
                   {"big.csv:2:1: A alpha: the polynomial (up to 3500 arcsec over temperatures within 200 degrees "
                    "C) and the Sun term (up to 200.25 arcsec) together can pass a thermal angle's 3600 arcsec"});
    const CliRun tiny = run_in("replay --target loopback-float --in s.csv --model tiny.csv --out rb.csv", dir);
    expect_refused(tiny, 1, {"tiny.csv:7:1: B gamma: the Sun term rounds to 0 in the target's scalar"});
    expect_absent(dir, {"rb.csv"});
    for (const char* taken : {"edge.csv", "none.csv"}) {
        const CliRun r = run_in(std::string("replay --target loopback-float --in s.csv --model ") + taken +
                                    " --out r_taken.csv > /dev/null",
                                dir);
        EXPECT_EQ(r.exit_code, 0) << taken << ": " << r.err;
    }
    // The mission's first rows of B moved to 2052.
    std::vector<std::string> late{lines_of_file(dir / "s.csv")[0]};
    for (const std::string& row : lines_of_file(dir / "s.csv")) {
        if (late.size() < 4 && row.find(",B,") != std::string::npos) {
            late.push_back("1650000000" + row.substr(row.find(',')));
        }
    }
    write_lines(dir / "late.csv", late);
    for (const char* scalar : {"double", "float", "fixed"}) {
        EXPECT_EQ(run_in(std::string("correct --in s.csv --model big.csv --out cb.csv --scalar ") + scalar +
                             " > /dev/null 2>&1",
                         dir)
                      .exit_code,
                  0)
            << scalar;
        const CliRun r =
            run_in(std::string("correct --in late.csv --model tiny.csv --out cl.csv --scalar ") + scalar, dir);
        EXPECT_EQ(r.exit_code, 0) << scalar << ": " << r.err;
        const auto rows = corrected_of(dir / "cl.csv");  // by t and head: the three rows are one key
        EXPECT_EQ(rows.size(), 1U) << scalar;
        for (const auto& [key, row] : rows) {
            EXPECT_EQ(row.status, std::to_string(status::kAberrationApplied | status::kThermalOutOfRange))
                << scalar << " " << key;
        }
        EXPECT_TRUE(has(r.err, "thermal skipped (status 128)")) << scalar;
    }
}

}  // namespace
}  // namespace ascorr::test
