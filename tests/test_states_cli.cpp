// `ascorr correct --states`: the velocity of rows without vx,vy,vz from
// spacecraft states, by the on-board service in the chosen scalar. The
// executable's answers are compared with a DPU-like sequential service in
// process (states pushed in time order, one advance per solution), bad states,
// staleness, rows with their own velocity, and malformed states files.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "ascorr/nav/velocity_service.hpp"
#include "ascorr_host/correct/states_velocity.hpp"
#include "cli_run.hpp"
#include "test_support.hpp"

namespace ascorr::test {
namespace {

namespace fs = std::filesystem;
using V3 = Vector3<double>;

constexpr double kT0 = 801964800.184;  // 2025-06-01, on .184 like GNSS
constexpr double kMaxPropagation = 120.0;

struct State {
    double t;
    V3 r;
    V3 v;
};

// GCRS → ITRF by inverting the service's own rotation: input data only (the
// frame's accuracy is tested against ERFA in test_velocity_service.cpp).
State to_itrf(const State& g) {
    TtTime t{};
    EXPECT_TRUE(tt_from_seconds(g.t, t));
    const CelestialFromTerrestrial m = celestial_from_terrestrial(t, kDefaultTtMinusUt1Us);
    const auto qt = [&](const V3& x) {  // Qᵀ·x
        const auto& q = m.q_gcrs_cirs.row;
        return V3{q[0].x * x.x + q[1].x * x.y + q[2].x * x.z, q[0].y * x.x + q[1].y * x.y + q[2].y * x.z,
                  q[0].z * x.x + q[1].z * x.y + q[2].z * x.z};
    };
    const auto r3 = [&](const V3& x) {  // R3(θ)·x
        return V3{m.era.c * x.x + m.era.s * x.y, -m.era.s * x.x + m.era.c * x.y, x.z};
    };
    const V3 r = r3(qt(g.r));
    const V3 vi = r3(qt(g.v));
    const double w = kEarthRotationRateRadS;
    return {g.t, r, {vi.x + w * r.y, vi.y - w * r.x, vi.z}};
}

// 1 Hz states for two minutes, from a near-polar 460 km orbit.
std::vector<State> gcrs_states() {
    const double r0 = kEarthEquatorialRadiusKm + 460.0;
    OrbitState s{{r0, 0.0, 0.0}, {0.0, 0.35, std::sqrt(kEarthGmKm3S2 / r0)}};
    std::vector<State> out;
    for (int k = 0; k < 120; ++k) {
        out.push_back({kT0 + k, s.r_km, s.v_kms});
        for (int i = 0; i < 10; ++i) {
            s = rk4_step(s, gravity_j2(s.r_km, {0, 0, 1}), {0, 0, 1}, 0.1);
        }
    }
    return out;
}

std::string states_csv(const std::vector<State>& states, bool with_bad) {
    std::string out = "t,x,y,z,vx,vy,vz\n";
    char buf[256];
    for (std::size_t i = 0; i < states.size(); ++i) {
        const State& s = states[i];
        std::snprintf(buf, sizeof buf, "%.3f,%.9f,%.9f,%.9f,%.12f,%.12f,%.12f\n", s.t, s.r.x, s.r.y, s.r.z, s.v.x,
                      s.v.y, s.v.z);
        out += buf;
        if (with_bad && i == 30) {  // a refused state of each kind after the 31st
            std::snprintf(buf, sizeof buf, "%.3f,nan,1,1,1,1,1\n", s.t + 0.5);
            out += buf;
            std::snprintf(buf, sizeof buf, "%.3f,100,0,0,7,0,0\n", s.t + 0.5);
            out += buf;
            std::snprintf(buf, sizeof buf, "%.3f,%.9f,%.9f,%.9f,1,2,3\n", s.t, s.r.x, s.r.y, s.r.z);  // duplicate
            out += buf;
            std::snprintf(buf, sizeof buf, "%.3f,%.9f,%.9f,%.9f,1,2,3\n", s.t - 10.0, s.r.x, s.r.y, s.r.z);
            out += buf;
        }
    }
    return out;
}

struct Row {
    double t;
    Eigen::Quaterniond q;
    bool own_velocity;
};

std::vector<Row> rows() {
    std::mt19937_64 rng(7);
    std::vector<Row> out;
    for (double dt = -5.0; dt < 300.0; dt += 2.7) {  // before the first state ... beyond the horizon
        out.push_back({kT0 + dt, random_attitude(rng), false});
    }
    out.push_back({kT0 + 50.0, random_attitude(rng), true});
    return out;
}

std::string solutions_csv(const std::vector<Row>& rs) {
    std::string out = "t,chu,qw,qx,qy,qz,t_chu,t_029,t_032,vx,vy,vz,flags,confidence\n";
    char buf[320];
    for (const Row& r : rs) {
        std::snprintf(buf, sizeof buf, "%.6f,A,%.17g,%.17g,%.17g,%.17g,20,21,22,%s,0,1\n", r.t, r.q.w(), r.q.x(),
                      r.q.y(), r.q.z(), r.own_velocity ? "1.5,-6.5,2.25" : ",,");
        out += buf;
    }
    return out;
}

struct OutRow {
    Quaternion<double> q;
    unsigned status;
    std::string line;
};

std::vector<OutRow> read_out(const fs::path& p) {
    std::string storage;
    const auto recs = read_records(p.string(), storage);
    std::ifstream f(p);
    std::vector<std::string> lines;
    for (std::string l; std::getline(f, l);) {
        lines.push_back(l);
    }
    std::vector<OutRow> out;
    for (std::size_t i = 0; i < recs.size(); ++i) {
        const std::string& l = lines.at(i + 1);
        out.push_back({recs[i].q_chu_icrf, static_cast<unsigned>(std::stoul(l.substr(l.rfind(',') + 1))), l});
    }
    return out;
}

// What a DPU computes: states pushed in time order (bad ones refused by the
// same checks), one advance and one query per solution, the core in T.
template <typename T>
std::vector<CorrectedSolution<T>> sequential(const std::vector<State>& states_in, const std::string& states_text,
                                             const std::vector<Row>& rs, StateFrame frame) {
    static_cast<void>(states_in);
    // Parse the states text back (what the executable reads, bad rows included).
    std::vector<State> all;
    std::istringstream in(states_text);
    std::string line;
    std::getline(in, line);
    while (std::getline(in, line)) {
        State s{};
        double f[7];
        std::istringstream ls(line);
        for (double& x : f) {
            std::string field;
            std::getline(ls, field, ',');
            x = std::strtod(field.c_str(), nullptr);
        }
        s = {f[0], {f[1], f[2], f[3]}, {f[4], f[5], f[6]}};
        all.push_back(s);
    }
    VelocityService<T> svc(host::service_config(kMaxPropagation));
    std::size_t next = 0;
    std::vector<CorrectedSolution<T>> out;
    using Tr = ScalarTraits<T>;
    for (const Row& r : rs) {
        TtTime t{};
        EXPECT_TRUE(tt_from_seconds(r.t, t));
        TtTime ts{};
        while (next < all.size() && tt_from_seconds(all[next].t, ts) && ts <= t) {
            svc.push_state(ts, all[next].r, all[next].v, frame);
            ++next;
        }
        SolutionInput<T> si{};
        si.q_chu_icrf = {Tr::from_double(r.q.w()), Tr::from_double(r.q.x()), Tr::from_double(r.q.y()),
                         Tr::from_double(r.q.z())};
        si.head = 0;
        si.temperatures = {{Tr::celsius(20), true}, {Tr::celsius(21), true}, {Tr::celsius(22), true}};
        svc.advance(t, OnBoardEarth{});
        const ServiceVelocity<T> v = svc.velocity_at(t);
        si.velocity = v.velocity;
        CorrectedSolution<T> c = correct_solution(si, CorrectionConfig<T>{true, nullptr});
        c.status = with_service_status(c.status, v.status, true);
        out.push_back(c);
    }
    return out;
}

template <typename T>
void check_against_sequential(const char* scalar, StateFrame frame) {
    const fs::path dir = scratch_dir(std::string("states_cli_") + scalar + (frame == StateFrame::kGcrs ? "_g" : "_i"));
    std::vector<State> st = gcrs_states();
    if (frame == StateFrame::kItrf) {
        for (State& s : st) {
            s = to_itrf(s);
        }
    }
    const std::string states_text = states_csv(st, true);
    const std::vector<Row> rs = rows();
    write(dir / "states.csv", states_text);
    write(dir / "in.csv", solutions_csv(rs));
    const std::string common = "correct --in " + (dir / "in.csv").string() + " --scalar " + scalar;
    const CliRun r =
        run_here(common + " --out " + (dir / "out.csv").string() + " --states " + (dir / "states.csv").string() +
                     " --states-frame " + (frame == StateFrame::kGcrs ? "gcrs" : "itrf") + " --max-propagation 120",
                 dir);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    // Each refused state named with its line (header = line 1; the bad rows follow line 32).
    for (const char* what : {"states.csv:33: state refused: position or velocity not finite",
                             "states.csv:34: state refused: not a plausible Earth orbit",
                             "states.csv:35: state refused: same time", "states.csv:36: state refused: time earlier"}) {
        EXPECT_NE(r.err.find(what), std::string::npos) << what << "\n" << r.err;
    }
    EXPECT_NE(r.err.find("no accepted state at or before t"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("older than --max-propagation"), std::string::npos) << r.err;

    const std::vector<OutRow> got = read_out(dir / "out.csv");
    const auto want = sequential<T>(st, states_text, rs, frame);
    ASSERT_EQ(got.size(), rs.size());
    std::size_t n4 = 0;
    std::size_t n_stale = 0;
    std::size_t n_ok = 0;
    for (std::size_t i = 0; i + 1 < rs.size(); ++i) {
        EXPECT_EQ(got[i].status, want[i].status) << i;
        const Quaternion<double> w{
            ScalarTraits<T>::to_double(want[i].q_chu_icrf.w), ScalarTraits<T>::to_double(want[i].q_chu_icrf.x),
            ScalarTraits<T>::to_double(want[i].q_chu_icrf.y), ScalarTraits<T>::to_double(want[i].q_chu_icrf.z)};
        EXPECT_LE(angle_arcsec(got[i].q, w), 1e-9) << i;  // the file's 15 decimals
        n4 += got[i].status == status::kNoVelocity ? 1U : 0U;
        n_stale += got[i].status == (status::kNoVelocity | status::kStale) ? 1U : 0U;
        n_ok += got[i].status == status::kAberrationApplied ? 1U : 0U;
    }
    EXPECT_EQ(n4, 2U);        // t0 − 5 s, t0 − 2.3 s
    EXPECT_EQ(n_ok, 89U);     // t0 + 0.4 … t0 + 239 s
    EXPECT_EQ(n_stale, 22U);  // beyond 120 s after the last state (t0 + 119)
    // The row with its own velocity keeps it: the same line as without --states.
    const CliRun plain = run_here(common + " --out " + (dir / "plain.csv").string(), dir);
    ASSERT_EQ(plain.exit_code, 0) << plain.err;
    const std::vector<OutRow> p = read_out(dir / "plain.csv");
    EXPECT_EQ(got.back().line, p.back().line);
    EXPECT_EQ(got.back().status, status::kAberrationApplied);
    EXPECT_EQ(p[10].status, status::kNoVelocity);  // and without --states the others have none
}

TEST(StatesCli, DoubleItrfMatchesTheSequentialService) {
    check_against_sequential<double>("double", StateFrame::kItrf);
}
TEST(StatesCli, FloatItrfMatchesTheSequentialService) {
    check_against_sequential<float>("float", StateFrame::kItrf);
}
TEST(StatesCli, FixedGcrsMatchesTheSequentialService) {
    check_against_sequential<Q30>("fixed", StateFrame::kGcrs);
}

TEST(StatesCli, MalformedStatesFileNamesLineAndColumnAndWritesNothing) {
    const fs::path dir = scratch_dir("states_cli_bad");
    write(dir / "in.csv", solutions_csv(rows()));
    const std::string head = "t,x,y,z,vx,vy,vz\n";
    const std::string good = "801964800.184,6838,0,0,0,0.3,7.6\n";
    struct Case {
        std::string text;
        std::string message;
    };
    const std::vector<Case> cases{
        {"", "states.csv:1:1: empty states file"},
        {"t,x,y,z,vx,vy\n" + good, "states.csv:1:1: required column 'vz' is missing"},
        {head, "states.csv:2:1: the states file has no rows"},
        {head + good + "801964801.184,6838,abc,0,0,0.3,7.6\n", "states.csv:3:20: column 'y': expected a number"},
        {head + good + "801964801.184,6838,0,0,0,0.3\n", "states.csv:3:29: expected 7 fields"},
        {head + good + "801964801.184,6838,0,0,0,0.3,7.6,9\n", "states.csv:3:34: expected 7 fields"},
        {head + "nan,6838,0,0,0,0.3,7.6\n", "states.csv:2:1: column 't': time must be finite"},
        {head + "1e12,6838,0,0,0,0.3,7.6\n", "states.csv:2:1: column 't': time must be finite and within"},
    };
    for (const Case& c : cases) {
        write(dir / "states.csv", c.text);
        fs::remove(dir / "out.csv");
        const CliRun r = run_here("correct --in " + (dir / "in.csv").string() + " --out " + (dir / "out.csv").string() +
                                      " --states " + (dir / "states.csv").string(),
                                  dir);
        EXPECT_EQ(r.exit_code, 1) << c.text;
        EXPECT_NE(r.err.find(c.message), std::string::npos) << c.message << "\n" << r.err;
        EXPECT_FALSE(fs::exists(dir / "out.csv")) << c.text;
    }
    // A bad option value: refused before anything is written.
    write(dir / "states.csv", head + good);
    for (const std::string opt :
         {"--max-propagation 0", "--max-propagation -5", "--max-propagation 1e9", "--states-frame teme"}) {
        const CliRun r = run_here("correct --in " + (dir / "in.csv").string() + " --out " + (dir / "out.csv").string() +
                                      " --states " + (dir / "states.csv").string() + " " + opt,
                                  dir);
        EXPECT_NE(r.exit_code, 0) << opt;
        EXPECT_FALSE(fs::exists(dir / "out.csv")) << opt;
    }
}

}  // namespace
}  // namespace ascorr::test
