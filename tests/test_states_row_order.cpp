// `ascorr correct --states` with rows out of time order: the same corrected
// rows (byte for byte, in input order) as for the file in time order, in
// every scalar, and the same work of the velocity service, counted
// (states pushed, RK4 steps, velocity nodes: a deterministic measure of cost,
// not a clock). Two feeds: one uplinked state for a week (the rows far from
// it need long propagations) and 1 Hz GNSS states with a gap (every row
// needs another state).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <numeric>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "ascorr/nav/velocity_service.hpp"
#include "ascorr_host/correct/correct_file.hpp"
#include "test_support.hpp"

namespace ascorr::test {
namespace {

namespace fs = std::filesystem;

constexpr double kT0 = 801964800.184;  // 2025-06-01, on .184 like GNSS
constexpr double kWeekS = 604800.0;

// A near-polar 460 km orbit, GCRS.
OrbitState initial_orbit() {
    const double r0 = kEarthEquatorialRadiusKm + 460.0;
    return {{r0, 0.0, 0.0}, {0.0, 0.35, std::sqrt(kEarthGmKm3S2 / r0)}};
}

std::string state_line(double t, const OrbitState& s) {
    char buf[256];
    std::snprintf(buf, sizeof buf, "%.3f,%.9f,%.9f,%.9f,%.12f,%.12f,%.12f\n", t, s.r_km.x, s.r_km.y, s.r_km.z,
                  s.v_kms.x, s.v_kms.y, s.v_kms.z);
    return buf;
}

// One row per epoch, heads A, B, C in turn; every 11th row has its own velocity.
std::vector<std::string> solution_rows(double first, double step, double last, std::uint64_t seed) {
    std::mt19937_64 rng(seed);
    std::vector<std::string> out;
    char buf[320];
    int i = 0;
    for (double t = first; t <= last; t += step, ++i) {
        const Eigen::Quaterniond q = random_attitude(rng);
        const double s = q.w() < 0 ? -1.0 : 1.0;
        std::snprintf(buf, sizeof buf, "%.6f,%c,%.15f,%.15f,%.15f,%.15f,20,21,22,%s,0,1\n", t, "ABC"[i % 3], s * q.w(),
                      s * q.x(), s * q.y(), s * q.z(), i % 11 == 4 ? "1.5,-6.5,2.25" : ",,");
        out.emplace_back(buf);
    }
    return out;
}

const char* const kHeader = "t,chu,qw,qx,qy,qz,t_chu,t_029,t_032,vx,vy,vz,flags,confidence\n";

void write_rows(const fs::path& p, const std::vector<std::string>& rows, const std::vector<std::size_t>& order) {
    std::ofstream f(p);
    f << kHeader;
    for (const std::size_t i : order) {
        f << rows[i];
    }
}

std::vector<std::string> data_lines(const fs::path& p) {
    std::ifstream f(p);
    std::vector<std::string> out;
    std::string l;
    std::getline(f, l);  // header
    while (std::getline(f, l)) {
        out.push_back(l);
    }
    return out;
}

struct Feed {
    std::string name;
    std::string states;  // the states file's text
    bool gcrs;
    double max_propagation_s;
    std::vector<std::string> rows;  // in time order
};

// One GCRS state, rows every 10 min from 20 min before it to 20 min beyond
// the 7-day horizon (status 4 before it, 4|512 beyond).
Feed uplinked_week() {
    Feed f{"week", "t,x,y,z,vx,vy,vz\n" + state_line(kT0, initial_orbit()), true, kWeekS, {}};
    f.rows = solution_rows(kT0 - 1200.0, 600.0, kT0 + kWeekS + 1200.0, 3);
    return f;
}

// 1 Hz GCRS states for an hour with a 20-minute gap, rows every 0.4 s.
Feed gnss_hour() {
    Feed f{"gnss", "t,x,y,z,vx,vy,vz\n", true, 21600.0, {}};
    OrbitState s = initial_orbit();
    for (int k = 0; k < 3600; ++k) {
        if (k < 1200 || k >= 2400) {
            f.states += state_line(kT0 + k, s);
        }
        s = rk4_step(s, gravity_j2(s.r_km, {0, 0, 1}), {0, 0, 1}, 1.0);
    }
    f.rows = solution_rows(kT0 - 2.0, 0.4, kT0 + 3600.0, 4);
    return f;
}

struct Corrected {
    std::vector<std::string> lines;  // corrected rows, in the file's order
    host::ServiceCost cost;
};

Corrected correct(const fs::path& dir, const Feed& feed, const std::string& in, host::ScalarKind scalar) {
    host::CorrectOptions o;
    o.in = (dir / in).string();
    o.out = (dir / ("out_" + in)).string();
    o.model = std::string(ASCORR_TEST_DATA) + "/model_table2.csv";
    o.scalar = scalar;
    o.states = (dir / "states.csv").string();
    o.states_gcrs = feed.gcrs;
    o.max_propagation_s = feed.max_propagation_s;
    std::ostringstream log;
    const host::CorrectSummary s = host::correct_file(o, log);
    EXPECT_EQ(s.rows, feed.rows.size()) << log.str();
    return {data_lines(o.out), s.service_cost};
}

// The service's work in time order (shuffled and reversed: the same).
host::ServiceCost check_orders(const Feed& feed, host::ScalarKind scalar, const char* scalar_name) {
    const fs::path dir = scratch_dir("states_order_" + feed.name + "_" + scalar_name);
    std::ofstream(dir / "states.csv") << feed.states;
    const std::size_t n = feed.rows.size();
    std::vector<std::size_t> time_order(n);
    std::iota(time_order.begin(), time_order.end(), std::size_t{0});
    std::vector<std::size_t> shuffled = time_order;
    std::mt19937_64 rng(11);
    std::shuffle(shuffled.begin(), shuffled.end(), rng);
    const std::vector<std::size_t> reversed(time_order.rbegin(), time_order.rend());
    write_rows(dir / "time.csv", feed.rows, time_order);
    write_rows(dir / "shuffled.csv", feed.rows, shuffled);
    write_rows(dir / "reversed.csv", feed.rows, reversed);

    const Corrected ref = correct(dir, feed, "time.csv", scalar);
    EXPECT_EQ(ref.lines.size(), n);
    if (ref.lines.size() != n) {
        return ref.cost;
    }
    // The feed exercises the service: most rows get its velocity, some none.
    std::size_t applied = 0;
    for (const std::string& l : ref.lines) {
        applied += l.substr(l.rfind(',') + 1) == "3" ? 1U : 0U;  // thermal + aberration
    }
    EXPECT_GT(applied, n / 2) << feed.name;
    EXPECT_LT(applied, n) << feed.name;

    for (const auto& [name, order] : {std::pair{"shuffled.csv", shuffled}, std::pair{"reversed.csv", reversed}}) {
        const Corrected got = correct(dir, feed, name, scalar);
        EXPECT_EQ(got.lines.size(), n) << name;
        if (got.lines.size() != n) {
            continue;
        }
        std::size_t differ = 0;
        for (std::size_t i = 0; i < n; ++i) {
            if (got.lines[i] != ref.lines[order[i]]) {
                if (++differ <= 3) {
                    ADD_FAILURE() << name << " row " << i + 1 << ":\n  " << got.lines[i] << "\nin time order:\n  "
                                  << ref.lines[order[i]];
                }
            }
        }
        EXPECT_EQ(differ, 0U) << name;
        // The service does the same work whatever the order of the rows.
        EXPECT_EQ(got.cost.states_pushed, ref.cost.states_pushed) << name;
        EXPECT_EQ(got.cost.rk4_steps, ref.cost.rk4_steps) << name;
        EXPECT_EQ(got.cost.nodes_built, ref.cost.nodes_built) << name;
    }
    std::printf("%s, %s: %llu states pushed, %llu RK4 steps, %llu nodes for %zu rows\n", feed.name.c_str(), scalar_name,
                static_cast<unsigned long long>(ref.cost.states_pushed),
                static_cast<unsigned long long>(ref.cost.rk4_steps),
                static_cast<unsigned long long>(ref.cost.nodes_built), n);
    return ref.cost;
}

// The work of a DPU fed the same rows in time order: each state pushed once,
// propagated once, as far as the last row that needs it.
TEST(StatesRowOrder, UplinkedWeekSameRowsAndWorkInEveryOrder) {
    const Feed feed = uplinked_week();
    const host::ServiceCost c = check_orders(feed, host::ScalarKind::kDouble, "double");
    check_orders(feed, host::ScalarKind::kFloat, "float");
    check_orders(feed, host::ScalarKind::kFixed, "fixed");
    EXPECT_EQ(c.states_pushed, 1U);
    // The last fresh row is at the horizon, in node 60480 (one week / 10 s):
    // one RK4 step per node, each once.
    EXPECT_LE(c.rk4_steps, static_cast<std::uint64_t>(kWeekS / 10.0));
    EXPECT_LE(c.nodes_built, feed.rows.size());
}

TEST(StatesRowOrder, GnssHourSameRowsAndWorkInEveryOrder) {
    const Feed feed = gnss_hour();
    const host::ServiceCost c = check_orders(feed, host::ScalarKind::kDouble, "double");
    check_orders(feed, host::ScalarKind::kFloat, "float");
    check_orders(feed, host::ScalarKind::kFixed, "fixed");
    EXPECT_LE(c.states_pushed, 2400U);         // each accepted state at most once
    EXPECT_LE(c.rk4_steps, 1200U / 10U + 1U);  // the gap, once
}

}  // namespace
}  // namespace ascorr::test
