// Results do not depend on row order: `fit` on a shuffled
// copy of a simulated mission gives the same model as on the file in time
// order, up to the rounding of sums taken in another order; `stats` the same
// epochs and figures.
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "ascorr_host/formats/model_csv.hpp"
#include "cli_run.hpp"
#include "test_support.hpp"

namespace ascorr::test {
namespace {

namespace fs = std::filesystem;

int run(const std::string& args, const std::string& out = "/dev/null") {
    const std::string cmd = std::string(ASCORR_EXE) + " " + args + " > " + out + " 2> /dev/null";
    const int rc = std::system(cmd.c_str());
    return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
}

void shuffle_rows(const fs::path& in, const fs::path& out, std::uint64_t seed) {
    std::ifstream f(in);
    std::string header;
    std::getline(f, header);
    std::vector<std::string> rows;
    for (std::string l; std::getline(f, l);) {
        rows.push_back(l);
    }
    std::mt19937_64 rng(seed);
    std::shuffle(rows.begin(), rows.end(), rng);
    std::ofstream o(out);
    o << header << '\n';
    for (const auto& r : rows) {
        o << r << '\n';
    }
}

TEST(RowOrder, FitGivesTheSameModelForAShuffledCopy) {
    const fs::path dir = scratch_dir("order");
    const std::string sim = (dir / "sim.csv").string();
    ASSERT_EQ(run("simulate --days 40 --out " + sim), 0);
    const std::string fit_opts = " --min-days 30 --min-orbits 50 --lag 0";  // auto's order: FitLag.*
    ASSERT_EQ(run("fit --in " + sim + " --out " + (dir / "m_time.csv").string() + fit_opts), 0);
    const host::ModelFile ref = host::read_model_file((dir / "m_time.csv").string());
    for (const std::uint64_t seed : {1U, 2U}) {
        shuffle_rows(sim, dir / "shuffled.csv", seed);
        const fs::path m = dir / ("m_shuffled" + std::to_string(seed) + ".csv");
        ASSERT_EQ(run("fit --in " + (dir / "shuffled.csv").string() + " --out " + m.string() + fit_opts), 0);
        const host::ModelFile got = host::read_model_file(m.string());
        // Every coefficient times the largest temperature term of the mission
        // (|T| ≤ 40 °C): how far the two models' angles can differ, arcsec.
        double worst = 0.0;
        for (std::size_t h = 0; h < 3; ++h) {
            for (std::size_t a = 0; a < 3; ++a) {
                for (std::size_t k = 0; k < 4; ++k) {
                    const double d = std::abs(got.coefficients[h][a][k] - ref.coefficients[h][a][k]);
                    worst = std::max(worst, d * (k == 0 ? 1.0 : 40.0));
                }
            }
        }
        std::printf("seed %llu: largest model angle difference %.3g arcsec\n", static_cast<unsigned long long>(seed),
                    worst);
        // Summation order only (measured 6e-11"); before the fix 0.32" on this
        // data (the first row read chose N_i and the orbit period).
        EXPECT_LT(worst, 1e-9);
    }
}

// Before the fix a shuffled copy lost a few pair epochs (814 → 813 A-B on
// this mission): an epoch was handed on with the heads seen so far, before a
// head's first row came.
TEST(RowOrder, StatsGivesTheSameEpochsForAShuffledCopy) {
    const fs::path dir = scratch_dir("order_stats");
    const std::string sim = (dir / "sim.csv").string();
    ASSERT_EQ(run("simulate --days 1 --seed 1 --bench-lag 900 --out " + sim), 0);
    // A lagged model too: stats lags over the rows as `correct` does.
    std::ifstream truth(sim + ".truth.csv");
    std::ofstream lagged(dir / "lagged.csv");
    std::string line;
    std::getline(truth, line);
    lagged << line << ",lag_s\n";
    while (std::getline(truth, line)) {
        lagged << line << ",900\n";
    }
    lagged.close();
    for (const std::string& model : {std::string(), " --model " + (dir / "lagged.csv").string()}) {
        const fs::path ref = dir / "time.json";
        ASSERT_EQ(run("stats --json --in " + sim + model, ref.string()), 0);
        const std::string want = slurp(ref);
        ASSERT_NE(want.find("\"n\": 814"), std::string::npos) << want;
        for (const std::uint64_t seed : {1U, 2U, 3U, 4U}) {
            shuffle_rows(sim, dir / "shuffled.csv", seed);
            const fs::path got = dir / "shuffled.json";
            ASSERT_EQ(run("stats --json --in " + (dir / "shuffled.csv").string() + model, got.string()), 0);
            EXPECT_EQ(slurp(got), want) << "seed " << seed << model;
        }
    }
}

// A second row of a head in an epoch is an input error wherever it comes: at
// the end of a file in time order, or anywhere in a shuffled one (before,
// one that came after its epoch was handed on was taken silently).
TEST(RowOrder, ASecondRowOfAHeadIsRefusedWhereverItComes) {
    const fs::path dir = scratch_dir("order_second");
    const fs::path sim = dir / "sim.csv";
    ASSERT_EQ(run("simulate --days 1 --seed 1 --out " + sim.string()), 0);
    const std::vector<std::string> lines = lines_of_file(sim);
    ASSERT_GT(lines.size(), 100U);
    // Line 12 again, last: a row of an epoch of every head (t = 456149100,
    // lines 12 to 14), which is handed on before the second comes.
    std::ofstream(dir / "late.csv") << slurp(sim) << lines[11] << '\n';
    shuffle_rows(dir / "late.csv", dir / "late_shuffled.csv", 3U);
    const std::string fit_opts = " --out " + (dir / "m.csv").string() + " --min-days 0.5 --min-orbits 5 --lag 0";
    for (const char* file : {"late.csv", "late_shuffled.csv"}) {
        const std::string in = (dir / file).string();
        for (const std::string& args : {"stats --in " + in, "fit --in " + in + fit_opts}) {
            const CliRun r = run_shell(std::string(ASCORR_EXE) + " " + args + " > /dev/null", dir);
            EXPECT_EQ(r.exit_code, 1) << args;
            EXPECT_TRUE(has(r.err, "second solution of CHU ")) << args << ": " << r.err;
        }
    }
    // The line of the second row and of the first are named (in time order:
    // the last line and line 12).
    const CliRun r =
        run_shell(std::string(ASCORR_EXE) + " stats --in " + (dir / "late.csv").string() + " > /dev/null", dir);
    EXPECT_TRUE(has(r.err, "late.csv:" + std::to_string(lines.size() + 1) + ":1: second solution of CHU")) << r.err;
    EXPECT_TRUE(has(r.err, "at t = 456149100.000 (the first is on line 12)")) << r.err;
    EXPECT_FALSE(fs::exists(dir / "m.csv"));
}

}  // namespace
}  // namespace ascorr::test
