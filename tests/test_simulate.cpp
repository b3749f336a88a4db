// `ascorr simulate` and `ascorr plot` end to end: determinism, the embedded
// truth, raw solutions that `correct` with the truth turns back into the
// noise floor, bad options, the figure.
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>

#include "ascorr_host/embedded_model.hpp"
#include "ascorr_host/stats.hpp"
#include "test_support.hpp"

namespace ascorr::test {
namespace {

namespace fs = std::filesystem;

int run_cli(const std::string& args, const fs::path& dir) {
    const std::string cmd =
        std::string(ASCORR_EXE) + " " + args + " > " + (dir / "out.txt").string() + " 2> " + (dir / "err.txt").string();
    const int rc = std::system(cmd.c_str());
    return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
}

std::string slurp(const fs::path& p) {
    std::ifstream f(p, std::ios::binary);
    std::stringstream s;
    s << f.rdbuf();
    return s.str();
}

TEST(Simulate, EmbeddedTruthIsTable2) {
    const host::ModelFile a = host::table2_model();
    const host::ModelFile b = host::read_model_file(data_path("model_table2.csv"));
    EXPECT_EQ(a.present, b.present);
    EXPECT_EQ(a.coefficients, b.coefficients);
}

TEST(Simulate, DeterministicForASeed) {
    const fs::path dir = scratch_dir("simulate");
    ASSERT_EQ(run_cli("simulate --days 1 --out " + (dir / "a.csv").string(), dir), 0) << slurp(dir / "err.txt");
    ASSERT_EQ(run_cli("simulate --days 1 --out " + (dir / "b.csv").string(), dir), 0);
    ASSERT_EQ(run_cli("simulate --days 1 --seed 2 --out " + (dir / "c.csv").string(), dir), 0);
    EXPECT_EQ(slurp(dir / "a.csv"), slurp(dir / "b.csv"));
    EXPECT_NE(slurp(dir / "a.csv"), slurp(dir / "c.csv"));
    EXPECT_EQ(slurp(dir / "a.csv.truth.csv"), host::format_model(host::table2_model()));
}

TEST(Simulate, CorrectWithTheTruthGivesTheNoiseFloor) {
    const fs::path dir = scratch_dir("floor");
    const fs::path data = dir / "m.csv";
    ASSERT_EQ(run_cli("simulate --days 4 --out " + data.string(), dir), 0) << slurp(dir / "err.txt");
    host::StatsOptions o;
    o.in = data.string();
    o.model = data.string() + ".truth.csv";
    const host::StatsResult r = host::compute_stats(o, std::cerr);
    const std::string floor = slurp(data.string() + ".floor.json");
    for (std::size_t p = 0; p < host::kPairs; ++p) {
        const std::regex re(std::string("\"") + host::kPairNames[p] +
                            "\": \\{\"rms\": ([0-9.]+), \"rms_200s\": ([0-9.]+), \"n\": ([0-9]+)\\}");
        std::smatch m;
        ASSERT_TRUE(std::regex_search(floor, m, re)) << floor;
        EXPECT_EQ(r.n[p], std::stoul(m[3].str()));
        EXPECT_GT(r.n[p], 1000U);
        // Thermal and aberration undone exactly: the noise alone is left.
        EXPECT_NEAR(r.rms[p][2].rms, std::stod(m[1].str()), 2e-6);
        EXPECT_NEAR(r.rms[p][2].rms_smoothed, std::stod(m[2].str()), 2e-6);
        // Star-tracker noise: 1.5" per axis across the boresight, two heads.
        EXPECT_NEAR(r.rms[p][2].rms, 1.5 * std::sqrt(2.0), 0.1);
        // The raw data carry aberration (up to ~30" on an IBA).
        EXPECT_GT(r.rms[p][0].rms, 3.0 * r.rms[p][2].rms);
    }
}

TEST(Simulate, BadOptionsAndTruthWriteNothing) {
    const fs::path dir = scratch_dir("bad");
    const fs::path data = dir / "m.csv";
    EXPECT_EQ(run_cli("simulate --step 0 --out " + data.string(), dir), 1);
    EXPECT_NE(slurp(dir / "err.txt").find("--step must be in [1, 600] s"), std::string::npos) << slurp(dir / "err.txt");
    EXPECT_EQ(run_cli("simulate --days -3 --out " + data.string(), dir), 1);
    std::ofstream(dir / "truth.csv") << "chu,axis,c0,c1,c2,c3\nA,alpha,1,2,x,4\n";
    EXPECT_EQ(run_cli("simulate --days 1 --truth " + (dir / "truth.csv").string() + " --out " + data.string(), dir), 1);
    EXPECT_NE(slurp(dir / "err.txt").find("truth.csv:2:"), std::string::npos) << slurp(dir / "err.txt");
    EXPECT_FALSE(fs::exists(data));
    EXPECT_FALSE(fs::exists(data.string() + ".truth.csv"));
    EXPECT_FALSE(fs::exists(data.string() + ".floor.json"));
}

TEST(Plot, WritesAPng) {
    const fs::path dir = scratch_dir("plot");
    const fs::path data = dir / "m.csv";
    ASSERT_EQ(run_cli("simulate --days 2 --step 120 --out " + data.string(), dir), 0) << slurp(dir / "err.txt");
    const fs::path png = dir / "iba.png";
    ASSERT_EQ(run_cli("plot --in " + data.string() + " --model " + data.string() + ".truth.csv --from 456148800 --to " +
                          "456200000 --out " + png.string(),
                      dir),
              0)
        << slurp(dir / "err.txt");
    const std::string bytes = slurp(png);
    ASSERT_GT(bytes.size(), 10000U);
    EXPECT_EQ(bytes.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
    // A missing model is an error that names the file; no figure then.
    EXPECT_EQ(run_cli("plot --in " + data.string() + " --model " + (dir / "none.csv").string() + " --out " +
                          (dir / "x.png").string(),
                      dir),
              1);
    EXPECT_NE(slurp(dir / "err.txt").find("none.csv"), std::string::npos) << slurp(dir / "err.txt");
    EXPECT_FALSE(fs::exists(dir / "x.png"));
}

}  // namespace
}  // namespace ascorr::test
