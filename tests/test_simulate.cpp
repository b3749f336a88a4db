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

#include <Eigen/Geometry>
#include "ascorr_host/analysis/plot.hpp"
#include "ascorr_host/analysis/simulate.hpp"
#include "ascorr_host/analysis/stats.hpp"
#include "ascorr_host/formats/embedded_model.hpp"
#include "cli_run.hpp"
#include "test_support.hpp"

namespace ascorr::test {
namespace {

namespace fs = std::filesystem;

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
    for (std::size_t p = 0; p < host::kPaperPairs.count; ++p) {
        const std::regex re(std::string("\"") + host::pair_name(host::kPaperPairs.pair[p]) +
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
    // Columns: T_CHU by head index (heads.hpp), T029, T032.
    constexpr std::size_t kSeries = kMaxHeads + 2U;
    std::map<long long, std::array<std::pair<double, int>, kSeries>> ref;
    for (const auto& r : recs) {
        auto& b = ref[static_cast<long long>(std::floor(r.t / 3600.0))];
        const std::pair<std::size_t, std::size_t> cols[3] = {{r.head, 0}, {kMaxHeads, 1}, {kMaxHeads + 1U, 2}};
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
        for (std::size_t i = 0; i < kSeries; ++i) {
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

// ---- The events for testing a self-calibrating model (--truth-change, --gap,
// --thermistor-fault, --head-bias) and the daily floor. Each event is measured
// against the same mission without it (same seed: the events draw no random
// numbers, so every difference is the event's).

constexpr double kStart = host::kDefaultSimStartT;
constexpr double kDayS = 86400.0;

// The floor of days [from, to) by `stats` with the truth (its clean epochs are the floor's).
std::array<double, host::kPaperPairs.count> stats_floor(const std::string& data, const std::string& model,
                                                        double from_day, double to_day) {
    host::StatsOptions o;
    o.in = data;
    o.model = model;
    o.from = kStart + from_day * kDayS;
    o.to = kStart + to_day * kDayS - 5e-4;  // [from, to) of rows written to the millisecond
    const host::StatsResult r = host::compute_stats(o, std::cerr);
    std::array<double, host::kPaperPairs.count> rms{};
    for (std::size_t p = 0; p < host::kPaperPairs.count; ++p) {
        rms[p] = r.rms[p][2].rms;
    }
    return rms;
}

TEST(SimulateEvents, DailyFloorGivesTheFloorOfTheMissionAndOfAnyWindowOfDays) {
    const fs::path dir = scratch_dir("floor-daily");
    const std::string data = (dir / "m.csv").string();
    ASSERT_EQ(run_cli("simulate --days 4 --out " + data, dir), 0) << slurp(dir / "err.txt");
    const std::string floor = slurp(data + ".floor.json");
    const auto whole = host::floor_of_days(data + ".floor-daily.csv", 0, 5);
    const auto window = host::floor_of_days(data + ".floor-daily.csv", 1, 3);
    const auto by_stats = stats_floor(data, data + ".truth.csv", 1.0, 3.0);
    for (std::size_t p = 0; p < host::kPaperPairs.count; ++p) {
        const std::regex re(std::string("\"") + host::pair_name(host::kPaperPairs.pair[p]) +
                            "\": \\{\"rms\": ([0-9.]+), .*?\"n\": ([0-9]+)\\}");
        std::smatch m;
        ASSERT_TRUE(std::regex_search(floor, m, re)) << floor;
        EXPECT_EQ(whole[p].n, std::stoul(m[2].str()));
        EXPECT_NEAR(whole[p].rms, std::stod(m[1].str()), 1e-6);  // floor.json has 6 decimals
        EXPECT_NEAR(window[p].rms, by_stats[p], 1e-6);
        EXPECT_GT(window[p].n, 300U);
        EXPECT_LT(window[p].n, whole[p].n * 2 / 3);
    }
    // A window without days has no floor; a malformed file names line and column.
    EXPECT_TRUE(std::isnan(host::floor_of_days(data + ".floor-daily.csv", 10, 20)[0].rms));
    std::ofstream(dir / "bad.csv") << "day,t_start,pair,n,sum,sum_sq\n0,1,A-B,3,x,4\n";
    try {
        host::floor_of_days((dir / "bad.csv").string(), 0, 1);
        ADD_FAILURE() << "a malformed daily floor was accepted";
    } catch (const std::exception& e) {
        EXPECT_NE(std::string(e.what()).find("bad.csv:2:11"), std::string::npos) << e.what();
    }
}

// Table 2 after a settling bench: head A's mount c0 shifted by 1.5" and 3",
// head B's gains 35 % larger.
std::string settled_model() {
    host::ModelFile m = host::table2_model();
    m.coefficients[0][0][0] += 1.5;
    m.coefficients[0][1][0] += 3.0;
    for (std::size_t a = 0; a < 3; ++a) {
        for (std::size_t i = 1; i < 4; ++i) {
            m.coefficients[1][a][i] *= 1.35;
        }
    }
    return host::format_model(m);
}

TEST(SimulateEvents, TruthChangeHoldsFromItsDayAndIsInTheTruthHistory) {
    const fs::path dir = scratch_dir("truth-change");
    const std::string data = (dir / "m.csv").string();
    const std::string settled = (dir / "settled.csv").string();
    std::ofstream(settled) << settled_model();
    std::ofstream(dir / "table2.csv") << host::format_model(host::table2_model());
    ASSERT_EQ(run_cli("simulate --days 6 --truth-change 3:" + settled + " --out " + data, dir), 0)
        << slurp(dir / "err.txt");
    const std::string before = (dir / "table2.csv").string();
    const auto floor_before = host::floor_of_days(data + ".floor-daily.csv", 0, 3);
    const auto floor_after = host::floor_of_days(data + ".floor-daily.csv", 3, 7);
    const auto old_before = stats_floor(data, before, 0.0, 3.0);
    const auto old_after = stats_floor(data, before, 3.0, 7.0);
    const auto new_after = stats_floor(data, settled, 3.0, 7.0);
    // Across the change (days 2 to 4) neither truth alone reaches the floor:
    // head A's mount steps by 1.5" and 3" on day 3 (an RMS about the mean sees
    // a constant c0 only as such a step).
    const auto floor_across = host::floor_of_days(data + ".floor-daily.csv", 2, 4);
    const auto old_across = stats_floor(data, before, 2.0, 4.0);
    const auto new_across = stats_floor(data, settled, 2.0, 4.0);
    for (std::size_t p = 0; p < host::kPaperPairs.count; ++p) {
        std::printf(
            "%s floor %.4f / %.4f / across %.4f; old truth %.4f / %.4f / across %.4f; new truth after %.4f / "
            "across %.4f\n",
            host::pair_name(host::kPaperPairs.pair[p]).c_str(), floor_before[p].rms, floor_after[p].rms,
            floor_across[p].rms, old_before[p], old_after[p], old_across[p], new_after[p], new_across[p]);
        EXPECT_NEAR(old_before[p], floor_before[p].rms, 1e-6);
        EXPECT_NEAR(new_after[p], floor_after[p].rms, 1e-6);
        // A-B sees A's step most (A-C least: the projection), B-C B's gains.
        const double ratio = p == 0 ? 1.3 : 1.02;
        EXPECT_GT(old_across[p], ratio * floor_across[p].rms);
        EXPECT_GT(new_across[p], ratio * floor_across[p].rms);
    }
    EXPECT_GT(std::fabs(old_after[2] - floor_after[2].rms), 1e-5);                    // head B's gains changed
    EXPECT_EQ(slurp(data + ".truth.csv"), host::format_model(host::table2_model()));  // the initial truth
    // The history: version 0 from the first epoch, version 1 from day 3, each a model file's rows.
    std::string expected = "t,version,chu,axis,c0,c1,c2,c3\n";
    const std::pair<const char*, std::string> versions[2] = {{"456148800.000,0,", slurp(before)},
                                                             {"456408000.000,1,", settled_model()}};
    for (const auto& v : versions) {
        std::istringstream rows(v.second);
        std::string row;
        std::getline(rows, row);
        while (std::getline(rows, row)) {
            expected += v.first + row + "\n";
        }
    }
    EXPECT_EQ(slurp(data + ".truth-history.csv"), expected);
}

// The lines of a file.
std::vector<std::string> lines_of(const std::string& path) {
    std::istringstream in(slurp(path));
    std::vector<std::string> lines;
    for (std::string line; std::getline(in, line);) {
        lines.push_back(line);
    }
    return lines;
}

TEST(SimulateEvents, GapRemovesItsRowsAndNothingElse) {
    const fs::path dir = scratch_dir("gap");
    const std::string plain = (dir / "plain.csv").string();
    const std::string gapped = (dir / "gap.csv").string();
    ASSERT_EQ(run_cli("simulate --days 4 --out " + plain, dir), 0) << slurp(dir / "err.txt");
    ASSERT_EQ(run_cli("simulate --days 4 --gap 1:2.5 --gap 3.25:3.5 --out " + gapped, dir), 0)
        << slurp(dir / "err.txt");
    const auto in_gap = [](double t) {
        const double day = (t - kStart) / kDayS;
        return (day >= 1.0 && day < 2.5) || (day >= 3.25 && day < 3.5);
    };
    std::vector<std::string> kept;
    std::size_t removed = 0;
    for (const std::string& line : lines_of(plain)) {
        const bool header = line[0] == 't';
        if (!header && in_gap(std::stod(line))) {
            ++removed;
        } else {
            kept.push_back(line);
        }
    }
    EXPECT_GT(removed, 5000U);
    EXPECT_EQ(lines_of(gapped), kept);
    // The floor leaves the gap out too.
    const auto daily = host::floor_of_days(gapped + ".floor-daily.csv", 1, 2);
    EXPECT_EQ(daily[0].n, 0U);
}

TEST(SimulateEvents, ThermistorFaultsChangeTheRecordedTemperatureOnly) {
    const fs::path dir = scratch_dir("thermistor-fault");
    const std::string plain = (dir / "plain.csv").string();
    const std::string faulty = (dir / "fault.csv").string();
    ASSERT_EQ(run_cli("simulate --days 4 --out " + plain, dir), 0) << slurp(dir / "err.txt");
    ASSERT_EQ(run_cli("simulate --days 4 --thermistor-fault A:t_chu:stuck:1:2 --thermistor-fault "
                      "B:t_032:drift:2:3:4 --out " +
                          faulty,
                      dir),
              0)
        << slurp(dir / "err.txt");
    std::string s1;
    std::string s2;
    const auto a = read_records(plain, s1);
    const auto b = read_records(faulty, s2);
    ASSERT_EQ(a.size(), b.size());
    std::size_t stuck_rows = 0;
    std::size_t drift_rows = 0;
    double stuck_value = std::nan("");
    double plain_min = 1e9;
    double plain_max = -1e9;
    for (std::size_t i = 0; i < a.size(); ++i) {
        const double day = (a[i].t - kStart) / kDayS;
        ASSERT_EQ(a[i].t, b[i].t);
        // The bench follows the real temperature: the attitudes are the same.
        EXPECT_EQ(a[i].q_chu_icrf.w, b[i].q_chu_icrf.w);
        EXPECT_EQ(a[i].q_chu_icrf.x, b[i].q_chu_icrf.x);
        EXPECT_EQ(a[i].temperature_present, b[i].temperature_present);
        for (std::size_t c = 0; c < 3; ++c) {
            if (!a[i].temperature_present[c]) {
                continue;
            }
            const bool stuck = a[i].head == 0 && c == 0 && day >= 1.0 && day < 2.0;
            const bool drift = a[i].head == 1 && c == 2 && day >= 2.0 && day < 3.0;
            if (stuck) {
                stuck_value = std::isnan(stuck_value) ? b[i].temperature[c] : stuck_value;
                EXPECT_EQ(b[i].temperature[c], stuck_value) << "t = " << a[i].t;
                plain_min = std::min(plain_min, a[i].temperature[c]);
                plain_max = std::max(plain_max, a[i].temperature[c]);
                ++stuck_rows;
            } else if (drift) {
                EXPECT_NEAR(b[i].temperature[c] - a[i].temperature[c], 4.0 * (day - 2.0), 1.5e-3);
                ++drift_rows;
            } else {
                EXPECT_EQ(b[i].temperature[c], a[i].temperature[c]) << "t = " << a[i].t << " column " << c;
            }
        }
    }
    EXPECT_GT(stuck_rows, 1000U);
    EXPECT_GT(drift_rows, 500U);
    EXPECT_GT(plain_max - plain_min, 1.0);  // the real temperature moved meanwhile
}

TEST(SimulateEvents, HeadBiasShiftsItsPairsIbaByTheRotationInTheWindowOnly) {
    const fs::path dir = scratch_dir("head-bias");
    const std::string plain = (dir / "plain.csv").string();
    const std::string biased = (dir / "bias.csv").string();
    constexpr double kBias = 5.0;
    ASSERT_EQ(run_cli("simulate --days 3 --out " + plain, dir), 0) << slurp(dir / "err.txt");
    ASSERT_EQ(run_cli("simulate --days 3 --head-bias C:1:2:5 --out " + biased, dir), 0) << slurp(dir / "err.txt");
    EXPECT_EQ(slurp(plain + ".floor.json"), slurp(biased + ".floor.json"));  // not in the floor
    // Expected change of each pair's IBA: C's boresight rotated by kBias about C's x axis (body frame).
    const Eigen::Matrix3d rotated =
        Eigen::AngleAxisd(kBias * kArcsecToRad, Eigen::Vector3d::UnitX()).toRotationMatrix() * host::head_mounting(2);
    const auto angle = [](const Eigen::Vector3d& u, const Eigen::Vector3d& v) {
        return std::atan2(u.cross(v).norm(), u.dot(v)) / kArcsecToRad;
    };
    const std::array<double, host::kPaperPairs.count> expected = {
        0.0,
        angle(host::head_mounting(0).row(2), rotated.row(2)) -
            angle(host::head_mounting(0).row(2), host::head_mounting(2).row(2)),
        angle(host::head_mounting(1).row(2), rotated.row(2)) -
            angle(host::head_mounting(1).row(2), host::head_mounting(2).row(2))};
    // Per epoch, the IBA of the biased run minus the plain run's (same noise).
    std::string s1;
    std::string s2;
    const auto a = read_records(plain, s1);
    const auto b = read_records(biased, s2);
    ASSERT_EQ(a.size(), b.size());
    std::map<std::pair<double, std::size_t>, Eigen::Vector3d> za;
    std::map<std::pair<double, std::size_t>, Eigen::Vector3d> zb;
    for (std::size_t i = 0; i < a.size(); ++i) {
        const auto z = [](const host::SolutionRecord& r) {
            const Eigen::Quaterniond q(r.q_chu_icrf.w, r.q_chu_icrf.x, r.q_chu_icrf.y, r.q_chu_icrf.z);
            return Eigen::Vector3d(q.normalized().toRotationMatrix().row(2).transpose());
        };
        za[{a[i].t, a[i].head}] = z(a[i]);
        zb[{b[i].t, b[i].head}] = z(b[i]);
    }
    std::array<double, host::kPaperPairs.count> worst_in{};
    std::array<double, host::kPaperPairs.count> worst_out{};
    std::array<std::size_t, host::kPaperPairs.count> n_in{};
    for (const auto& kv : za) {
        const double t = kv.first.first;
        const bool in = t >= kStart + kDayS && t < kStart + 2.0 * kDayS;
        for (std::size_t p = 0; p < host::kPaperPairs.count; ++p) {
            const auto i = host::kPaperPairs.pair[p].first;
            const auto j = host::kPaperPairs.pair[p].second;
            if (kv.first.second != i || za.count({t, j}) == 0) {
                continue;
            }
            const double shift = angle(zb[{t, i}], zb[{t, j}]) - angle(za[{t, i}], za[{t, j}]);
            double& worst = in ? worst_in[p] : worst_out[p];
            worst = std::max(worst, std::fabs(shift - (in ? expected[p] : 0.0)));
            n_in[p] += in ? 1U : 0U;
        }
    }
    for (std::size_t p = 0; p < host::kPaperPairs.count; ++p) {
        std::printf("%s: expected shift %.4f\", worst deviation in the window %.2e\", outside %.2e\"\n",
                    host::pair_name(host::kPaperPairs.pair[p]).c_str(), expected[p], worst_in[p], worst_out[p]);
        EXPECT_GT(n_in[p], 200U);
        EXPECT_LT(worst_in[p], 0.01);  // the aberration of the rotated boresight differs by ~1e-4 of 5"
        EXPECT_LT(worst_out[p], 1e-6);
    }
    EXPECT_GT(std::fabs(expected[1]) + std::fabs(expected[2]), 0.5 * kBias);
}

TEST(SimulateEvents, MalformedEventOptionsAreUsageErrorsThatWriteNothing) {
    const fs::path dir = scratch_dir("bad-events");
    const std::string data = (dir / "m.csv").string();
    std::ofstream(dir / "settled.csv") << settled_model();
    const std::string settled = (dir / "settled.csv").string();
    const std::pair<std::string, std::string> cases[] = {
        {"--truth-change 5", "--truth-change: 5 is not DAY:MODEL"},
        {"--truth-change x:" + settled, "is not DAY:MODEL"},
        {"--truth-change 3:" + settled + " --truth-change 2:" + settled, "DAY increasing"},
        {"--truth-change 9:" + settled, "DAY in (0, 4)"},
        {"--gap 3", "--gap: 3 is not FROM_DAY:TO_DAY"},
        {"--gap 2:1", "--gap 2:1: expected FROM_DAY:TO_DAY with 0 <= FROM_DAY < TO_DAY <= 4"},
        {"--gap 1:nan", "must be finite numbers"},
        {"--thermistor-fault D:t_chu:stuck:1:2", "HEAD must be A, B or C"},
        {"--thermistor-fault A:t_999:stuck:1:2", "CHANNEL must be t_chu, t_029 or t_032"},
        {"--thermistor-fault A:t_chu:melt:1:2", "the kind must be stuck or drift"},
        {"--thermistor-fault A:t_chu:drift:1:2", "a drift needs RATE"},
        {"--thermistor-fault A:t_chu:stuck:1:2:3", "stuck takes none"},
        {"--thermistor-fault A:t_chu:drift:1:2:500", "RATE 500: expected a drift's RATE in [-100, 100]"},
        {"--head-bias A:1:2", "--head-bias: A:1:2 is not HEAD:FROM_DAY:TO_DAY:ARCSEC"},
        {"--head-bias A:1:2:1e999", "ARCSEC must be a finite number"},
        {"--head-bias A:1:2:5000", "ARCSEC 5000: expected a rotation in [-3600, 3600]"},
        {"--head-bias B:3:5:1", "<= 4 (--days)"},
    };
    for (const auto& c : cases) {
        EXPECT_EQ(run_cli("simulate --days 4 " + c.first + " --out " + data, dir), 2) << c.first;
        const std::string err = slurp(dir / "err.txt");
        EXPECT_NE(err.find(c.second), std::string::npos) << c.first << ": " << err;
        EXPECT_NE(err.find("Run with --help"), std::string::npos) << c.first << ": " << err;
    }
    for (const char* suffix : {"", ".truth.csv", ".truth-history.csv", ".floor.json", ".floor-daily.csv"}) {
        EXPECT_FALSE(fs::exists(data + suffix)) << suffix;
    }
}

}  // namespace
}  // namespace ascorr::test
