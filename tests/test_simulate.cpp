// `ascorr simulate` and `ascorr plot` end to end: determinism, the embedded
// truth, raw solutions that `correct` with the truth turns back into the
// noise floor, bad options, the figure.
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <sstream>

#include "ascorr_host/analysis/plot.hpp"
#include "ascorr_host/analysis/stats.hpp"
#include "ascorr_host/formats/embedded_model.hpp"
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
    EXPECT_EQ(run_cli("simulate --step 0 --out " + data.string(), dir), 2);  // usage errors
    EXPECT_NE(slurp(dir / "err.txt").find("--step: 0 is out of range: the range is [1, 600]"), std::string::npos)
        << slurp(dir / "err.txt");
    EXPECT_EQ(run_cli("simulate --days -3 --out " + data.string(), dir), 2);
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

// PNG height from the IHDR chunk (bytes 20..23, big-endian).
unsigned png_height(const std::string& bytes) {
    unsigned h = 0;
    for (std::size_t i = 20; i < 24 && i < bytes.size(); ++i) {
        h = (h << 8U) | static_cast<unsigned char>(bytes[i]);
    }
    return h;
}

TEST(Plot, TemperaturePanelsAndAWindow) {
    const fs::path dir = scratch_dir("plot-temperatures");
    const fs::path data = dir / "m.csv";
    ASSERT_EQ(run_cli("simulate --days 2 --step 120 --out " + data.string(), dir), 0) << slurp(dir / "err.txt");
    const std::string model = data.string() + ".truth.csv";
    const fs::path png = dir / "t.png";
    ASSERT_EQ(
        run_cli("plot --temperatures --in " + data.string() + " --model " + model + " --out " + png.string(), dir), 0)
        << slurp(dir / "err.txt");
    EXPECT_EQ(png_height(slurp(png)), 2000U);  // 3 IBA + 2 temperature panels of 400 px
    const fs::path win = dir / "w.png";
    ASSERT_EQ(run_cli("plot --temperatures --window-from 456170000 --window-to 456200000 --in " + data.string() +
                          " --model " + model + " --out " + win.string(),
                      dir),
              0)
        << slurp(dir / "err.txt");
    EXPECT_EQ(png_height(slurp(win)), 2000U);
    ASSERT_EQ(run_cli("plot --window-from 456170000 --window-to 456200000 --in " + data.string() + " --model " + model +
                          " --out " + win.string(),
                      dir),
              0);
    EXPECT_EQ(png_height(slurp(win)), 1200U);
    // An empty window, and one without data: errors that say so, no figure.
    EXPECT_EQ(run_cli("plot --window-from 456200000 --window-to 456170000 --in " + data.string() + " --model " + model +
                          " --out " + (dir / "x.png").string(),
                      dir),
              1);
    EXPECT_NE(slurp(dir / "err.txt").find("the plot window is empty"), std::string::npos) << slurp(dir / "err.txt");
    EXPECT_EQ(run_cli("plot --window-from 400000000 --window-to 400100000 --in " + data.string() + " --model " + model +
                          " --out " + (dir / "x.png").string(),
                      dir),
              1);
    EXPECT_NE(slurp(dir / "err.txt").find("no clean epoch for pair A-B in the window"), std::string::npos)
        << slurp(dir / "err.txt");
    EXPECT_EQ(
        run_cli("plot --width 10 --in " + data.string() + " --model " + model + " --out " + (dir / "x.png").string(),
                dir),
        2);  // a usage error
    EXPECT_NE(slurp(dir / "err.txt").find("--width: 10 is out of range: expected an integer in [400, 4000]"),
              std::string::npos)
        << slurp(dir / "err.txt");
    EXPECT_EQ(run_cli("plot --window-from 456170000 --in " + data.string() + " --model " + model + " --out " +
                          (dir / "x.png").string(),
                      dir),
              2);  // --window-from needs --window-to
    EXPECT_FALSE(fs::exists(dir / "x.png"));
}

TEST(Plot, TemperatureSeriesAreBinMeansOfTheRows) {
    const fs::path dir = scratch_dir("plot-series");
    const fs::path data = dir / "m.csv";
    ASSERT_EQ(run_cli("simulate --days 1 --step 300 --out " + data.string(), dir), 0) << slurp(dir / "err.txt");
    const fs::path out = dir / "t.dat";
    const std::size_t bins =
        host::write_temperature_series(data.string(), out.string(), 3600.0, std::nullopt, std::nullopt, 0.0);
    // The same means, computed here from the rows.
    std::string storage;
    const auto recs = read_records(data.string(), storage);
    std::map<long long, std::array<std::pair<double, int>, 5>> ref;
    for (const auto& r : recs) {
        auto& b = ref[static_cast<long long>(std::floor(r.t / 3600.0))];
        const std::pair<std::size_t, std::size_t> cols[3] = {{r.head, 0}, {3, 1}, {4, 2}};
        for (const auto& c : cols) {
            if (r.temperature_present[c.second]) {
                b[c.first].first += r.temperature[c.second];
                ++b[c.first].second;
            }
        }
    }
    ASSERT_EQ(bins, ref.size());
    std::ifstream f(out);
    double worst = 0.0;
    for (const auto& kv : ref) {
        double t = 0.0;
        f >> t;
        for (std::size_t i = 0; i < 5; ++i) {
            std::string v;
            f >> v;
            if (kv.second[i].second == 0) {
                EXPECT_EQ(v, "NaN");  // a bin without that temperature: a gap in the line
                continue;
            }
            worst = std::max(worst, std::fabs(std::stod(v) - kv.second[i].first / kv.second[i].second));
        }
    }
    EXPECT_LT(worst, 1e-9);
}

TEST(Simulate, HeaterWindowsAreWhereTheTemperaturesRise) {
    // The windows simulate writes beside the data, checked against the
    // temperatures it wrote: the operational heater warms T032 and the CHUs,
    // the survival heater T029.
    const fs::path dir = scratch_dir("heaters");
    const fs::path data = dir / "m.csv";
    ASSERT_EQ(run_cli("simulate --days 200 --step 600 --out " + data.string(), dir), 0) << slurp(dir / "err.txt");
    std::string storage;
    const auto recs = read_records(data.string(), storage);
    const auto mean = [&](double from, double to, std::size_t column, std::size_t head) {
        double sum = 0.0;
        int n = 0;
        for (const auto& r : recs) {
            if (r.t >= from && r.t <= to && r.head == head && r.temperature_present[column]) {
                sum += r.temperature[column];
                ++n;
            }
        }
        return n > 0 ? sum / n : std::nan("");
    };
    std::ifstream f(data.string() + ".heaters.csv");
    std::string line;
    std::getline(f, line);
    EXPECT_EQ(line, "start,end,heater");
    int events = 0;
    while (std::getline(f, line)) {
        double start = 0.0;
        double end = 0.0;
        char kind[32] = {};
        ASSERT_EQ(std::sscanf(line.c_str(), "%lf,%lf,%31s", &start, &end, kind), 3) << line;
        if (end > recs.back().t) {
            continue;
        }
        const bool operational = std::string(kind) == "operational";
        EXPECT_TRUE(operational || std::string(kind) == "survival") << line;
        EXPECT_GT(end - start, 3.0 * 86400.0 - 1.0);
        EXPECT_LT(end - start, 5.0 * 86400.0 + 1.0);
        // Rise from the day before to the last half day of the heater: the
        // survival heater's T029 (+3 degC), the operational heater's T032 and
        // the three T_CHU together (+9.5 degC); each has 0.6 degC of wander.
        const auto rise = [&](std::size_t column, std::size_t head) {
            return mean(end - 43200.0, end, column, head) - mean(start - 86400.0, start, column, head);
        };
        const double r = operational ? rise(2, 0) + rise(0, 0) + rise(0, 1) + rise(0, 2) : rise(1, 0);
        std::printf("%s heater %.0f..%.0f: rise %.2f degC\n", kind, start, end, r);
        EXPECT_GT(r, operational ? 4.0 : 1.5) << line;
        ++events;
    }
    EXPECT_GE(events, 2);
}

}  // namespace
}  // namespace ascorr::test
