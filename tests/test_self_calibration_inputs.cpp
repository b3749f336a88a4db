// Self-calibration's inputs and outputs as a user meets them (issue 30, the
// third hostile probe): the initial model's form, the orbit period, the model
// history's times and heads, the memory of rows out of order. Each through
// `ascorr correct --self-calibrate` (and host::self_calibrate, which Python
// and replay run), on a short simulated mission.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "ascorr/core/fixed_point.hpp"
#include "ascorr_host/correct/self_calibration.hpp"
#include "ascorr_host/formats/embedded_model.hpp"
#include "ascorr_host/formats/model_csv.hpp"
#include "cli_run.hpp"
#include "test_support.hpp"

namespace ascorr::test {
namespace {

namespace fs = std::filesystem;

// Four simulated days at 300 s (3 heads, 2751 rows): the estimator adopts a
// model on day 3.
fs::path simulated(const std::string& name, const std::string& extra = "") {
    const fs::path dir = scratch_dir(name);
    const CliRun r = run_in("simulate --out sim.csv --days 4 --step 300 --seed 3" + extra, dir);
    EXPECT_EQ(r.exit_code, 0) << r.err;
    return dir;
}

std::vector<std::string> lines_of(const std::string& text) {
    std::vector<std::string> out;
    std::istringstream in(text);
    for (std::string l; std::getline(in, l);) {
        out.push_back(l);
    }
    return out;
}

void write_lines(const fs::path& p, const std::vector<std::string>& lines) {
    std::ofstream f(p);
    for (const std::string& l : lines) {
        f << l << '\n';
    }
}

// Class 5: a quadratic --model is refused for self-calibration, as replay
// refuses it (one rule, refuse_quadratic_initial_model): the history could
// only list c0..c3 beside the quadratic model's CRC, and the target could not
// start from it. A quadratic file whose quadratic terms are zero is linear.
TEST(SelfCalibrationInputs, AQuadraticInitialModelIsRefusedAsReplayRefusesIt) {
    const fs::path dir = simulated("sc_in_quadratic");
    host::ModelFile m = host::table2_model();
    m.quadratic = true;
    host::write_model_file((dir / "zero_quadratic.csv").string(), m);
    m.coefficients[1][2][5] = 1e-3;  // B gamma c2_2
    host::write_model_file((dir / "quadratic.csv").string(), m);
    const CliRun r =
        run_in("correct --in sim.csv --out c.csv --self-calibrate --model quadratic.csv --model-history h.csv", dir);
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_NE(r.err.find("quadratic.csv: head B gamma has a quadratic term (c2_2): self-calibration starts from a "
                         "linear model"),
              std::string::npos)
        << r.err;
    EXPECT_FALSE(fs::exists(dir / "c.csv"));
    EXPECT_FALSE(fs::exists(dir / "h.csv"));
    // The library refuses it too, whoever calls it.
    EXPECT_THROW(host::self_calibrate<double>(
                     "sim.csv", [](const std::function<void(const host::SolutionRecord&)>&) {}, m,
                     calib::EstimatorConfig{}, std::nullopt),
                 std::runtime_error);
    // Control: the same model with zero quadratic terms is taken.
    const CliRun z = run_in(
        "correct --in sim.csv --out c.csv --self-calibrate --model zero_quadratic.csv --model-history h.csv", dir);
    EXPECT_EQ(z.exit_code, 0) << z.err;
    EXPECT_NE(slurp(dir / "h.csv").find(",0,A,alpha,"), std::string::npos);
}

// The rows of a solutions file as a RowSource (records point into storage).
struct Rows {
    std::string storage;
    std::vector<host::SolutionRecord> records;
    host::RowSource source() const {
        return [this](const std::function<void(const host::SolutionRecord&)>& fn) {
            for (const host::SolutionRecord& r : records) {
                fn(r);
            }
        };
    }
};

Rows rows_of(const fs::path& file) {
    Rows r;
    r.records = read_records(file.string(), r.storage);
    return r;
}

// The rows' times moved by dt seconds (4 decimals).
void shift_times(const fs::path& file, double dt) {
    std::vector<std::string> lines = lines_of(slurp(file));
    for (std::size_t i = 1; i < lines.size(); ++i) {
        const std::size_t comma = lines[i].find(',');
        char t[40];
        std::snprintf(t, sizeof t, "%.4f", std::stod(lines[i].substr(0, comma)) + dt);
        lines[i] = t + lines[i].substr(comma);
    }
    write_lines(file, lines);
}

// Class 7: the history states exactly which rows each version covers. Times
// at ...0006 s (22 Hz data are not on the millisecond): the version active at
// a row (the run's schedule) is the last whose tt_us (TT µs of the on-board
// clock, an integer column) is at or before the row's t rounded to the
// microsecond. `t` keeps its 3 decimals (its meaning does not change): on its
// own it says a row at ...0006 comes before a version that it uses.
TEST(SelfCalibrationInputs, TheHistoryStatesExactlyWhichRowsAVersionCovers) {
    const fs::path dir = simulated("sc_in_tt_us");
    shift_times(dir / "sim.csv", 0.0006);
    const CliRun r = run_in("correct --in sim.csv --out c.csv --self-calibrate --model-history h.csv", dir);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const std::vector<std::string> h = lines_of(slurp(dir / "h.csv"));
    ASSERT_GE(h.size(), 10U);
    const std::string header = h[0];
    const std::size_t tt_col = static_cast<std::size_t>(
        std::count(header.begin(), header.begin() + static_cast<std::ptrdiff_t>(header.find("tt_us")), ','));
    ASSERT_NE(header.find(",tt_us"), std::string::npos) << header;
    EXPECT_EQ(header.rfind("t,version,chu,axis,c0,c1,c2,c3,crc32c", 0), 0U) << header;  // t's meaning kept
    const auto field = [](const std::string& line, std::size_t k) {
        std::size_t at = 0;
        for (std::size_t i = 0; i < k; ++i) {
            at = line.find(',', at) + 1;
        }
        return line.substr(at, line.find(',', at) - at);
    };
    std::vector<std::pair<long long, unsigned>> from;  // (tt_us, version), in time order
    std::vector<double> t_written;
    for (std::size_t i = 1; i < h.size(); ++i) {
        const long long us = std::stoll(field(h[i], tt_col));
        const auto v = static_cast<unsigned>(std::stoul(field(h[i], 1)));
        if (from.empty() || from.back().second != v) {
            from.emplace_back(us, v);
            t_written.push_back(std::stod(field(h[i], 0)));
        }
    }
    const Rows rows = rows_of(dir / "sim.csv");
    const host::SelfCalibration sc = host::self_calibrate<double>((dir / "sim.csv").string(), rows.source(),
                                                                  std::nullopt, calib::EstimatorConfig{}, std::nullopt);
    const host::ModelSchedule<double> schedule(sc.history);
    std::size_t before_t = 0;  // rows using a version whose written t is after theirs
    for (const host::SolutionRecord& rec : rows.records) {
        const auto us = static_cast<long long>(std::llround(rec.t * 1e6));
        std::optional<unsigned> by_column;
        std::optional<double> t_of_version;
        for (std::size_t k = 0; k < from.size() && from[k].first <= us; ++k) {
            by_column = from[k].second;
            t_of_version = t_written[k];
        }
        const std::optional<std::uint32_t> used = schedule.version_at(rec.t);
        ASSERT_EQ(used.has_value(), by_column.has_value()) << rec.line;
        if (used) {
            EXPECT_EQ(*used, *by_column) << "line " << rec.line;
            before_t += rec.t < *t_of_version ? 1U : 0U;
        }
    }
    EXPECT_GT(before_t, 0U) << "no row at ...0006 uses a version: the check above would be vacuous";
}

// The value of column `name` in each data line of a CSV text.
std::vector<std::string> column(const std::vector<std::string>& lines, const std::string& name) {
    std::vector<std::string> header;
    {
        std::istringstream h(lines.at(0));
        for (std::string f; std::getline(h, f, ',');) {
            header.push_back(f);
        }
    }
    const auto k = static_cast<std::size_t>(std::find(header.begin(), header.end(), name) - header.begin());
    std::vector<std::string> out;
    for (std::size_t i = 1; i < lines.size(); ++i) {
        std::istringstream in(lines[i]);
        std::string f;
        for (std::size_t j = 0; j <= k && std::getline(in, f, ','); ++j) {
        }
        out.push_back(k < header.size() ? f : std::string("(no column ") + name + ")");
    }
    return out;
}

// Class 13: on a four-head file the estimator learns D as well: D's rows keep
// a thermal stage in every adopted model, and the history says so (origin
// "learnt" for A to C; for D once its own orbits reach min_orbits, "kept"
// before; version 0 "given"). Was: D's rows got 256 from the first adopted
// model on; then D kept the given model.
TEST(SelfCalibrationInputs, AFourthHeadIsLearntAndKeepsItsThermalStage) {
    const fs::path dir = simulated("sc_in_head_d", " --heads ABCD");
    const CliRun r = run_in(
        "correct --in sim.csv --out c.csv --self-calibrate --model sim.csv.truth.csv --model-history h.csv", dir);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const std::vector<std::string> c = lines_of(slurp(dir / "c.csv"));
    const std::vector<std::string> chu = column(c, "chu");
    const std::vector<std::string> st = column(c, "status");
    std::size_t d_rows = 0;
    std::size_t d_thermal = 0;
    for (std::size_t i = 0; i < chu.size(); ++i) {
        if (chu[i] == "D") {
            ++d_rows;
            const unsigned s = static_cast<unsigned>(std::stoul(st[i]));
            EXPECT_EQ(s & 256U, 0U) << "line " << i + 2;
            d_thermal += (s & 2U) != 0U ? 1U : 0U;
        }
    }
    EXPECT_GT(d_rows, 1000U);
    EXPECT_GT(d_thermal, d_rows * 9 / 10);
    const std::vector<std::string> h = lines_of(slurp(dir / "h.csv"));
    const std::vector<std::string> version = column(h, "version");
    const std::vector<std::string> head = column(h, "chu");
    const std::vector<std::string> origin = column(h, "origin");
    const std::vector<std::string> c1 = column(h, "c1");
    std::vector<std::string> given_d;
    std::size_t learnt = 0;
    std::size_t changed = 0;
    for (std::size_t i = 0; i < version.size(); ++i) {
        const bool v0 = version[i] == "0";
        if (head[i] != "D" || v0) {
            EXPECT_EQ(origin[i], v0 ? "given" : "learnt") << h[i + 1];
        }
        if (head[i] == "D") {
            if (v0) {
                given_d.push_back(c1[i]);
            } else if (origin[i] == "learnt") {
                changed += c1[i] != given_d.at(learnt % 3) ? 1U : 0U;
                ++learnt;
            } else {
                EXPECT_EQ(origin[i], "kept") << h[i + 1];
                EXPECT_EQ(learnt, 0U) << "D kept after it was learnt: " << h[i + 1];
                EXPECT_EQ(c1[i], given_d.at(i % 3)) << h[i + 1];
            }
        }
    }
    EXPECT_GE(learnt, 3U) << "no adopted model: the checks above would be vacuous";
    EXPECT_GT(changed, 0U) << "D's coefficients were never learnt";
}

// The count in "N epochs with A, B and C selected" of a run's terminal line.
std::size_t epochs_selected(const std::string& err) {
    const std::size_t at = err.find(" epochs with A, B and C selected");
    EXPECT_NE(at, std::string::npos) << err;
    if (at == std::string::npos) {
        return 0;
    }
    const std::size_t from = err.rfind(' ', at - 1) + 1;
    return static_cast<std::size_t>(std::stoul(err.substr(from, at - from)));
}

// Per-head selection (docs/contract.md): A, B and C learn from the epochs in
// which the three are clean, whatever D is. D's rows flagged (not clean) in
// one epoch of three, or removed: the same epochs and orbits for A, B and C
// as in the file as simulated, and D is still learnt from its clean epochs
// (two of three: above the orbit's min_coverage). (An estimator that took an
// epoch only with all four heads clean, the mutation, counts about two
// thirds of the epochs with D flagged and fails.)
TEST(SelfCalibrationInputs, HeadDNotCleanLeavesTheEpochsOfABAndC) {
    const fs::path dir = simulated("sc_in_head_d_dirty", " --heads ABCD");
    std::vector<std::string> lines = lines_of(slurp(dir / "sim.csv"));
    const std::vector<std::string> chu = column(lines, "chu");
    std::vector<std::string> flagged{lines[0]};
    std::vector<std::string> without{lines[0]};
    std::size_t d_seen = 0;
    for (std::size_t i = 1; i < lines.size(); ++i) {
        std::string l = lines[i];
        if (chu[i - 1] == "D") {
            if (d_seen++ % 3 == 0) {
                const std::size_t flags = l.rfind(',', l.rfind(',') - 1);  // flags,confidence at the end
                l = l.substr(0, flags) + ",1" + l.substr(l.rfind(','));
            }
            flagged.push_back(l);
            continue;
        }
        flagged.push_back(l);
        without.push_back(l);
    }
    write_lines(dir / "flagged.csv", flagged);
    write_lines(dir / "without.csv", without);
    const auto run = [&](const std::string& in) {
        const CliRun r = run_in("correct --in " + in + " --out c_" + in +
                                    " --self-calibrate --model sim.csv.truth.csv --model-history h_" + in,
                                dir);
        EXPECT_EQ(r.exit_code, 0) << r.err;
        return r.err;
    };
    const std::string all = run("sim.csv");
    const std::string dirty = run("flagged.csv");
    const std::string none = run("without.csv");
    EXPECT_GT(epochs_selected(all), 300U);
    EXPECT_EQ(epochs_selected(dirty), epochs_selected(all)) << dirty;
    EXPECT_EQ(epochs_selected(none), epochs_selected(all)) << none;
    const auto orbits = [](const std::string& err) { return err.substr(err.find("orbits used"), 20); };
    EXPECT_EQ(orbits(dirty), orbits(all));
    EXPECT_NE(slurp(dir / "h_flagged.csv").find(",D,alpha,"), std::string::npos);
    EXPECT_NE(slurp(dir / "h_flagged.csv").find(",learnt\n"), std::string::npos);
    for (const std::string& l : lines_of(slurp(dir / "h_without.csv"))) {
        EXPECT_FALSE(l.find(",D,") != std::string::npos && l.find(",learnt") != std::string::npos) << l;
    }
}

// The velocity columns (vx, vy, vz) of data lines `which` scaled by f.
void scale_velocity(const fs::path& file, const std::vector<std::size_t>& which, double f) {
    std::vector<std::string> lines = lines_of(slurp(file));
    for (const std::size_t i : which) {
        std::vector<std::string> fields;
        std::istringstream in(lines.at(i));
        for (std::string x; std::getline(in, x, ',');) {
            fields.push_back(x);
        }
        std::string out;
        for (std::size_t k = 0; k < fields.size(); ++k) {
            char v[40];
            if (k >= 9 && k <= 11) {
                std::snprintf(v, sizeof v, "%.9g", std::stod(fields[k]) * f);
            }
            out += (k > 0 ? "," : "") + (k >= 9 && k <= 11 ? std::string(v) : fields[k]);
        }
        lines[i] = out;
    }
    write_lines(file, lines);
}

double period_of(const fs::path& file) {
    const Rows rows = rows_of(file);
    return host::self_calibrate<double>(file.string(), rows.source(), std::nullopt, calib::EstimatorConfig{},
                                        std::nullopt)
        .orbit_period_s;
}

// Class 6: no single row decides the orbit period. The first row's velocity
// scaled by 0.6 leaves it (the median of the first 99 rows learnt from); was
// 26053 s instead of 5627 s. A set in which more than a quarter disagree is
// refused, naming --orbit-period, which then serves (also for replay and
// Python); --orbit-period is checked as --time-constant is.
TEST(SelfCalibrationInputs, NoSingleRowDecidesTheOrbitPeriod) {
    const fs::path dir = simulated("sc_in_period");
    const double clean = period_of(dir / "sim.csv");
    EXPECT_NEAR(clean, 5627.5, 1.0);
    fs::copy_file(dir / "sim.csv", dir / "one.csv");
    scale_velocity(dir / "one.csv", {1}, 0.6);
    EXPECT_NEAR(period_of(dir / "one.csv") / clean, 1.0, 1e-3);
    fs::copy_file(dir / "sim.csv", dir / "many.csv");
    std::vector<std::size_t> many;
    for (std::size_t i = 1; i < 120; i += 4) {
        many.push_back(i);
    }
    scale_velocity(dir / "many.csv", many, 0.6);
    expect_refused(run_in("correct --in many.csv --out c.csv --self-calibrate --model-history h.csv", dir), 1,
                   {"many.csv:", "rows the self-calibration learns from disagree", "give --orbit-period"});
    expect_absent(dir, {"c.csv", "h.csv"});
    const CliRun g = run_in("correct --in many.csv --out c.csv --self-calibrate --orbit-period 5627", dir);
    EXPECT_EQ(g.exit_code, 0) << g.err;
    EXPECT_NE(g.err.find("orbit period 5627.0 s"), std::string::npos) << g.err;
    for (const char* bad : {"correct --in sim.csv --out c.csv --orbit-period 5627",
                            "correct --in sim.csv --out c.csv --self-calibrate --orbit-period 599",
                            "correct --in sim.csv --out c.csv --self-calibrate --orbit-period nan",
                            "replay --target loopback-float --in sim.csv --out c.csv --model sim.csv.truth.csv "
                            "--orbit-period 5627"}) {
        const CliRun b = run_in(bad, dir);
        EXPECT_EQ(b.exit_code, 2) << bad;
        EXPECT_NE(b.err.find("--orbit-period"), std::string::npos) << b.err;
    }
}

// Class 16: rows out of time order are sorted within a memory budget: beyond
// it in sorted runs on a temporary file, merged. The same history, report
// and schedule as the rows in time order, in every scalar, whatever the number
// of runs (the budget: 16 KiB, 1 MiB, the default). Was: every row's key and
// every fed row's input kept in memory (140-190 B a row: 1.75 GB for 8.4 M
// rows; the figure: bench/self-calibration-memory).
template <typename T>
void expect_same_from_runs(const fs::path& dir) {
    const Rows ordered = rows_of(dir / "sim.csv");
    const Rows shuffled = rows_of(dir / "shuffled.csv");
    const std::string file = (dir / "shuffled.csv").string();
    const host::SelfCalibration want =
        host::self_calibrate<T>(file, ordered.source(), std::nullopt, calib::EstimatorConfig{}, std::nullopt);
    ASSERT_GE(want.history.size(), 1U) << "no model adopted: the comparison would be vacuous";
    for (const std::size_t budget : {std::size_t{16} << 10, std::size_t{1} << 20, host::kSelfCalibrationMemoryBytes}) {
        const host::SelfCalibration got = host::self_calibrate<T>(file, shuffled.source(), std::nullopt,
                                                                  calib::EstimatorConfig{}, std::nullopt, budget);
        EXPECT_EQ(host::format_model_history(got.history), host::format_model_history(want.history)) << budget;
        EXPECT_EQ(host::describe(got), host::describe(want)) << budget;
        if (budget == (std::size_t{16} << 10)) {
            EXPECT_GT(got.runs, 10U);
        }
        if (budget == host::kSelfCalibrationMemoryBytes) {
            EXPECT_EQ(got.runs, 1U);
        }
    }
}

TEST(SelfCalibrationInputs, RowsOutOfOrderAreSortedWithinAMemoryBudget) {
    const fs::path dir = simulated("sc_in_runs");
    std::vector<std::string> lines = lines_of(slurp(dir / "sim.csv"));
    std::mt19937 rng(7);
    std::shuffle(lines.begin() + 1, lines.end(), rng);
    write_lines(dir / "shuffled.csv", lines);
    expect_same_from_runs<double>(dir);
    expect_same_from_runs<float>(dir);
    expect_same_from_runs<Q30>(dir);
}

}  // namespace
}  // namespace ascorr::test
