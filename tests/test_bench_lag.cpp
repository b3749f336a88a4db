// The bench's lag (issue 40): the model file's lag_s, the lagged temperatures
// `correct` and `fit` give the terms, and `fit --lag auto`'s choice, each
// measured against what the test computes itself: its own first-order filter
// in long double, a file whose temperatures it lagged itself, and the
// simulator's noise-only IBAs (the systematic residual).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <optional>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "ascorr/nav/tt_time.hpp"
#include "ascorr_host/analysis/fit.hpp"
#include "ascorr_host/analysis/stats.hpp"
#include "ascorr_host/correct/correct_file.hpp"
#include "ascorr_host/correct/lagged_temperatures.hpp"
#include "ascorr_host/formats/model_csv.hpp"
#include "cli_run.hpp"
#include "test_support.hpp"

namespace ascorr::test {
namespace {

namespace fs = std::filesystem;

// ---- The test's own lag: L ← L + (1 − e^(−Δt/τ))·(T − L) per channel in
// long double, a reading held over its step, Δt since the channel's last
// reading; L = T at the first one.
struct OwnLag {
    long double tau_s;
    std::array<long double, 3> l{};
    std::array<std::int64_t, 3> t_us{};
    std::array<bool, 3> started{};

    void step(std::int64_t t, const std::array<double, 3>& temp, const std::array<bool, 3>& present) {
        for (std::size_t k = 0; k < 3; ++k) {
            if (!present[k]) {
                continue;
            }
            if (!started[k]) {
                l[k] = temp[k];
                started[k] = true;
            } else if (t > t_us[k]) {
                const long double a = -std::expm1(-static_cast<long double>(t - t_us[k]) * 1e-6L / tau_s);
                l[k] += a * (static_cast<long double>(temp[k]) - l[k]);
            } else {
                continue;  // not after the channel's last reading: unchanged
            }
            t_us[k] = t;
        }
    }
};

host::SolutionRecord record(std::uint8_t head, double t, const std::array<double, 3>& temp,
                            const std::array<bool, 3>& present) {
    host::SolutionRecord rec;
    rec.head = head;
    rec.t = t;
    rec.temperature = temp;
    rec.temperature_present = present;
    return rec;
}

TEST(LaggedTemperatures, AreTheTestsOwnFilterInAnyRowOrder) {
    // Heads A (τ 900 s) and B (1800 s), C without a lag: 45/46 ms steps (22 Hz
    // rounded to ms), an orbit's swing, a channel missing now and then, an hour's
    // gap, and a row twice.
    const std::array<double, kMaxHeads> lag_s{900.0, 1800.0, 0.0, 0.0};
    std::vector<host::SolutionRecord> rows;
    double t = 456148800.0;
    for (int i = 0; i < 30000; ++i) {
        t += (i % 2 == 0 ? 0.045 : 0.046) + (i == 15000 ? 3600.0 : 0.0);
        for (std::uint8_t h = 0; h < 3; ++h) {
            const double w = 2.0 * 3.141592653589793 * (t - 456148800.0) / 5600.0;
            const std::array<double, 3> temp{20.0 + 3.0 * std::sin(w + h), -5.0 + 2.0 * std::cos(w),
                                             -15.0 + std::sin(2.0 * w)};
            rows.push_back(record(h, t, temp, {i % 37 != 5, i % 53 != 7, true}));
        }
    }
    // A second row of head A at one time, its T1 higher: it comes after the
    // first in the lag's order (by reading), so the channel advanced at the
    // first, and both rows get the state after them.
    host::SolutionRecord twice = rows[3000];
    twice.temperature[0] += 0.5;
    rows.insert(rows.begin() + 3001, twice);
    std::vector<host::LagReading> readings;
    for (const host::SolutionRecord& r : rows) {
        host::LagReading x;
        ASSERT_TRUE(host::lag_reading_of(r, x));
        readings.push_back(x);
    }
    std::vector<host::LagReading> shuffled = readings;
    std::shuffle(shuffled.begin(), shuffled.end(), std::mt19937_64(40));
    const host::LaggedTemperatures table(lag_s, readings);
    const host::LaggedTemperatures table_shuffled(lag_s, shuffled);

    std::array<OwnLag, 2> own{OwnLag{900.0L}, OwnLag{1800.0L}};
    double worst = 0.0;
    double deviation = 0.0;
    for (std::size_t i = 0; i < rows.size(); ++i) {
        const host::SolutionRecord& r = rows[i];
        TtTime tt{};
        ASSERT_TRUE(tt_from_seconds(r.t, tt));
        host::SolutionRecord a = r;
        host::SolutionRecord b = r;
        table.apply(a);
        table_shuffled.apply(b);
        for (std::size_t k = 0; k < 3; ++k) {
            EXPECT_EQ(a.temperature[k], b.temperature[k]) << "row " << i;  // the same bits in any order
            EXPECT_EQ(a.temperature_present[k], r.temperature_present[k]);
        }
        if (r.head == 2) {
            EXPECT_EQ(a.temperature, r.temperature) << "a head without a lag keeps its readings";
            continue;
        }
        own[r.head].step(tt.us, r.temperature, r.temperature_present);  // `twice`: not after, unchanged
        if (r.head == 0 && r.temperature_present[0]) {
            deviation = std::max(deviation, std::abs(a.temperature[0] - r.temperature[0]));
        }
        for (std::size_t k = 0; k < 3; ++k) {
            if (r.temperature_present[k]) {
                worst = std::max(worst, std::abs(static_cast<double>(a.temperature[k] - own[r.head].l[k])));
            }
        }
    }
    EXPECT_LT(worst, 1e-9) << "degC";
    host::SolutionRecord first = rows[3000];
    host::SolutionRecord second = rows[3001];
    table_shuffled.apply(first);
    table_shuffled.apply(second);
    EXPECT_EQ(first.temperature, second.temperature) << "rows of a head at one t: one state";
    // Not vacuous: A's T1 falls behind its swing by more than a degree (1.43 °C).
    EXPECT_GT(deviation, 1.0) << "degC";

    // A row of a lagged head whose t is not a time: no unlagged temperature.
    host::SolutionRecord bad = record(0, std::nan(""), {20.0, 0.0, 0.0}, {true, true, true});
    table.apply(bad);
    EXPECT_EQ(bad.temperature_present, (std::array<bool, 3>{false, false, false}));
}

TEST(ModelFileLag, RoundTripsAndTodaysFilesAreUnaffected) {
    const std::string linear =
        "chu,axis,c0,c1,c2,c3\nA,alpha,1,2,3,4\nA,beta,1,2,3,4\nA,gamma,1,2,3,4\n"
        "B,alpha,1,2,3,4\nB,beta,1,2,3,4\nB,gamma,1,2,3,4\n";
    const host::ModelFile plain = host::parse_model("m.csv", linear);
    EXPECT_FALSE(host::has_lag(plain));
    EXPECT_EQ(plain.lag_s, (std::array<double, kMaxHeads>{}));
    EXPECT_EQ(host::format_model(plain).find("lag_s"), std::string::npos);

    host::ModelFile lagged = plain;
    lagged.lag_s = {1800.0, 912.5, 0.0, 0.0};
    lagged.common_rotation.rule = host::CommonRotationRule::kCombined;
    const std::string text = host::format_model(lagged);
    EXPECT_EQ(text.substr(0, text.find('\n')), "chu,axis,c0,c1,c2,c3,common_rotation,lag_s");
    const host::ModelFile back = host::parse_model("m.csv", text);
    EXPECT_EQ(back.lag_s, lagged.lag_s);
    EXPECT_EQ(host::format_model(back), text);
    EXPECT_TRUE(host::has_lag(back));
}

TEST(ModelFileLag, RefusesALagItCannotTake) {
    const auto model = [](const std::string& a, const std::string& b) {
        return "chu,axis,c0,c1,c2,c3,lag_s\nA,alpha,1,2,3,4," + a + "\nA,beta,1,2,3,4," + b + "\nA,gamma,1,2,3,4," + b +
               "\n";
    };
    const std::pair<std::string, std::string> cases[] = {
        {model("-1", "-1"), "m.csv:2:17: column 'lag_s': expected 0 (no lag) or [1, 86400] s, got '-1'"},
        {model("0.5", "0.5"), "got '0.5'"},
        {model("86401", "86401"), "got '86401'"},
        {model("nan", "nan"), "got 'nan'"},
        {model("", ""), "got ''"},
        {model("900", "1800"),
         "m.csv:3:16: column 'lag_s': 1800 differs from head A's rows above (900): one lag "
         "per head"},
        {"chu,axis,c0,c1,c2,c3,lag\nA,alpha,1,2,3,4,1\n", "unknown column 'lag'"},
    };
    for (const auto& [text, part] : cases) {
        const std::string why =
            thrown_by<std::exception>([&] { host::parse_model("m.csv", text); }, "accepted: " + text);
        EXPECT_NE(why.find(part), std::string::npos) << text << ": " << why;
    }
}

TEST(ModelFileLag, ConsumersThatDoNotLagRefuseIt) {
    const fs::path dir = scratch_dir("lag-consumers");
    ASSERT_EQ(run_in("simulate --days 0.3 --out s.csv > /dev/null", dir).exit_code, 0);
    std::ostringstream model;
    model << "chu,axis,c0,c1,c2,c3,lag_s\n";
    for (const char* h : {"A", "B", "C"}) {
        for (const char* a : {"alpha", "beta", "gamma"}) {
            model << h << ',' << a << ",1,0.1,0.2,0.3,900\n";
        }
    }
    write(dir / "m.csv", model.str());
    const std::pair<std::string, std::string> cases[] = {
        {"simulate --days 0.2 --truth-change 0.1:m.csv --out t.csv",
         "a truth model takes no lag: --bench-lag lags the simulated bench"},
        {"simulate --days 0.1 --truth m.csv --out t.csv",
         "a truth model takes no lag: --bench-lag lags the simulated bench"},
    };
    for (const auto& [args, part] : cases) {
        const CliRun r = run_in(args + " > out.txt", dir);
        expect_refused(r, 1, {"m.csv: the model's lag_s makes its terms take lagged temperatures", part});
        expect_absent(dir, {"c.csv", "t.csv"});
    }
    const CliRun ok = run_in("correct --in s.csv --model m.csv --out c.csv", dir);
    EXPECT_EQ(ok.exit_code, 0) << ok.err;
}

TEST(FitLag, ParsesItsOption) {
    EXPECT_FALSE(host::parse_lags("auto").has_value());
    EXPECT_EQ(*host::parse_lags("900"), (std::array<double, kMaxHeads>{900.0, 900.0, 900.0, 900.0}));
    EXPECT_EQ(*host::parse_lags("A:900,C:1800"), (std::array<double, kMaxHeads>{900.0, 0.0, 1800.0, 0.0}));
    for (const char* bad : {"-5", "0.5", "A:900,A:100", "X:5", "A900", "A:", "A:9e9", "", "A:900,"}) {
        EXPECT_NE(
            thrown_by<host::FitRefused>([&] { host::parse_lags(bad); }, std::string("accepted: ") + bad).find("--lag"),
            std::string::npos)
            << bad;
    }
    const fs::path dir = scratch_dir("lag-option");
    const CliRun r = run_in("fit --in none.csv --out m.csv --lag B:-1", dir);
    expect_refused(r, 2, {"--lag B:-1: 'B:-1': the lag must be 0 (no lag) or [1, 86400] s"});
    expect_absent(dir, {"m.csv"});
}

// ---- A mission whose bench lags by 1800 s (40 days, an epoch every 120 s,
// seed 3: small enough for the sanitizers' build), fitted and corrected; the
// systematic residual per pair against its noise-only IBAs.

constexpr double kLagS = 1800.0;
constexpr double kBound = 0.15;  // arcsec per pair, issue 40's

const fs::path& lag_mission() {
    static const fs::path dir = [] {
        const fs::path d = scratch_dir("lag-mission");
        const CliRun r =
            run_in("simulate --days 40 --step 120 --seed 3 --bench-lag 1800 --noise-iba --out m.csv > /dev/null", d);
        EXPECT_EQ(r.exit_code, 0) << r.err;
        return d;
    }();
    return dir;
}

// The systematic residual per pair of the corrected file `corrected` (from
// `from` on, a time in s; all of it by default).
std::array<double, 3> systematic(const fs::path& dir, const std::string& corrected,
                                 std::optional<double> from = std::nullopt) {
    host::StatsOptions s;
    s.in = (dir / corrected).string();
    s.from = from;
    s.noise_iba = (lag_mission() / "m.csv.noise-iba.csv").string();
    s.log_empty_pairs = false;
    std::ostringstream log;
    const host::StatsResult r = host::compute_stats(s, log);
    return {r.systematic_rms[0][0].rms, r.systematic_rms[1][0].rms, r.systematic_rms[2][0].rms};
}

// fit ARGS on IN into MODEL, then correct IN with it into OUT.
void fit_and_correct(const fs::path& dir, const std::string& in, const std::string& args, const std::string& model,
                     const std::string& out) {
    const CliRun f =
        run_in("fit --in " + in + " --out " + model + " --min-days 20 " + args + " > " + model + ".txt", dir);
    ASSERT_EQ(f.exit_code, 0) << f.err;
    const CliRun c = run_in("correct --in " + in + " --model " + model + " --out " + out, dir);
    ASSERT_EQ(c.exit_code, 0) << c.err;
}

TEST(FitLag, TheDefaultFitFindsTheLagAndRemovesTheResidualInsideTheOrbit) {
    const fs::path& dir = lag_mission();
    fit_and_correct(dir, "m.csv", "", "auto.csv", "c_auto.csv");
    const host::ModelFile m = host::read_model_file((dir / "auto.csv").string());
    for (std::uint8_t h = 0; h < 3; ++h) {
        EXPECT_GE(m.lag_s[h], kLagS / 1.5) << host::head_name(h);
        EXPECT_LE(m.lag_s[h], kLagS * 1.5) << host::head_name(h);
    }
    EXPECT_TRUE(has(slurp(dir / "auto.csv.txt"), "bench lag (--lag auto): lagged: the best lags found"));
    const std::array<double, 3> with_lag = systematic(dir, "c_auto.csv");
    // Mutation: the same fit without the lag, nor the Sun term that takes part
    // of the lag's orbit-periodic part (fit_sun.hpp; with it alone the largest
    // pair is 0.16″), leaves the bench's lag inside the orbit.
    fit_and_correct(dir, "m.csv", "--lag 0 --sun-term none", "none.csv", "c_none.csv");
    EXPECT_EQ(slurp(dir / "none.csv").find("lag_s"), std::string::npos);
    const std::array<double, 3> without = systematic(dir, "c_none.csv");
    for (std::size_t p = 0; p < 3; ++p) {
        EXPECT_LE(with_lag[p], kBound) << "pair " << p;
        RecordProperty("systematic_lagged_" + std::to_string(p), std::to_string(with_lag[p]));
    }
    EXPECT_GT(*std::max_element(without.begin(), without.end()), 2.0 * kBound) << "without the lag the bound must fail";
}

// A CSV line's fields (none quoted).
std::vector<std::string> fields_of(const std::string& line) {
    std::vector<std::string> f;
    std::stringstream ss(line);
    for (std::string x; std::getline(ss, x, ',');) {
        f.push_back(x);
    }
    return f;
}

// The file's temperatures lagged by the test itself (OwnLag, each head over
// its rows in time order: simulate writes them so), written back with 9
// decimals.
void write_own_lagged(const fs::path& from, const fs::path& to, double tau_s) {
    std::array<OwnLag, kMaxHeads> own{OwnLag{tau_s}, OwnLag{tau_s}, OwnLag{tau_s}, OwnLag{tau_s}};
    rewrite_csv_rows(from, to, [&](const std::string& line, std::ofstream& out) {
        std::vector<std::string> f = fields_of(line);
        f.resize(14);  // t,chu,qw,qx,qy,qz,t_chu,t_029,t_032,vx,vy,vz,flags,confidence
        const std::uint8_t h = head_index(f[1][0]);
        std::array<double, 3> temp{};
        std::array<bool, 3> present{};
        for (std::size_t k = 0; k < 3; ++k) {
            present[k] = !f[6 + k].empty();
            temp[k] = present[k] ? std::stod(f[6 + k]) : 0.0;
        }
        TtTime tt{};
        ASSERT_TRUE(tt_from_seconds(std::stod(f[0]), tt));
        own[h].step(tt.us, temp, present);
        for (std::size_t k = 0; k < 3; ++k) {
            if (present[k]) {
                char buf[40];
                std::snprintf(buf, sizeof buf, "%.9f", static_cast<double>(own[h].l[k]));
                f[6 + k] = buf;
            }
        }
        for (std::size_t i = 0; i < f.size(); ++i) {
            out << (i == 0 ? "" : ",") << f[i];
        }
        out << '\n';
    });
}

TEST(FitLag, CorrectLagsAsTheTestsOwnFilterDoes) {
    const fs::path& dir = lag_mission();
    write_own_lagged(dir / "m.csv", dir / "own.csv", kLagS);
    fit_and_correct(dir, "own.csv", "--lag 0", "own_model.csv", "c_own.csv");
    fit_and_correct(dir, "m.csv", "--lag 1800", "given.csv", "c_given.csv");
    const std::array<double, 3> own = systematic(dir, "c_own.csv");
    const std::array<double, 3> given = systematic(dir, "c_given.csv");
    for (std::size_t p = 0; p < 3; ++p) {
        EXPECT_NEAR(given[p], own[p], 0.002) << "pair " << p;
        EXPECT_LE(given[p], kBound) << "pair " << p;
    }
    const host::ModelFile a = host::read_model_file((dir / "own_model.csv").string());
    const host::ModelFile b = host::read_model_file((dir / "given.csv").string());
    EXPECT_EQ(b.lag_s, (std::array<double, kMaxHeads>{kLagS, kLagS, kLagS, 0.0}));
    for (std::size_t h = 0; h < 3; ++h) {
        for (std::size_t ax = 0; ax < 3; ++ax) {
            for (std::size_t k = 0; k < kLinearModelTerms; ++k) {
                EXPECT_NEAR(a.coefficients[h][ax][k], b.coefficients[h][ax][k],
                            1e-6 * (1.0 + std::abs(b.coefficients[h][ax][k])));
            }
        }
    }
}

TEST(FitLag, RowOrderDoesNotMatter) {
    // Reversed rows: the same lagged temperatures, so the same model (to the
    // rounding of the fit's sums, which add in another order) and, with one
    // model, the same corrected rows to the bit.
    const fs::path& dir = lag_mission();
    std::vector<std::string> lines = lines_of_file(dir / "m.csv");
    std::reverse(lines.begin() + 1, lines.end());
    write_lines(dir / "reversed.csv", lines);
    if (!fs::exists(dir / "given.csv")) {
        fit_and_correct(dir, "m.csv", "--lag 1800", "given.csv", "c_given.csv");
    }
    const CliRun f = run_in("fit --in reversed.csv --out reversed_model.csv --min-days 20 --lag 1800 > /dev/null", dir);
    ASSERT_EQ(f.exit_code, 0) << f.err;
    const host::ModelFile a = host::read_model_file((dir / "reversed_model.csv").string());
    const host::ModelFile b = host::read_model_file((dir / "given.csv").string());
    EXPECT_EQ(a.lag_s, b.lag_s);
    for (std::size_t h = 0; h < 3; ++h) {
        for (std::size_t ax = 0; ax < 3; ++ax) {
            for (std::size_t k = 0; k < kLinearModelTerms; ++k) {
                EXPECT_NEAR(a.coefficients[h][ax][k], b.coefficients[h][ax][k],
                            1e-9 * (1.0 + std::abs(b.coefficients[h][ax][k])));
            }
        }
    }
    const CliRun c = run_in("correct --in reversed.csv --model given.csv --out c_reversed.csv", dir);
    ASSERT_EQ(c.exit_code, 0) << c.err;
    std::vector<std::string> x = lines_of_file(dir / "c_reversed.csv");
    std::vector<std::string> y = lines_of_file(dir / "c_given.csv");
    ASSERT_EQ(x.size(), y.size());
    std::reverse(x.begin() + 1, x.end());
    EXPECT_TRUE(x == y) << "the corrected rows, reversed back, are the same bytes";
}

TEST(FitLag, TheChoiceTakesEachHeadsOwnTime) {
    // Head B's rows 300 µs after the epoch's others (the same millisecond, so
    // the same epochs): the choice must look each head's lag up at its own t,
    // whichever head's row an epoch met first; reversed rows choose the same.
    const fs::path& dir = lag_mission();
    rewrite_csv_rows(dir / "m.csv", dir / "late_b.csv", [](const std::string& line, std::ofstream& out) {
        const std::size_t comma = line.find(',');
        if (line.compare(comma + 1, 2, "B,") == 0) {
            char t[40];
            std::snprintf(t, sizeof t, "%.4f", std::stod(line.substr(0, comma)) + 0.0003);
            out << t << line.substr(comma) << '\n';
        } else {
            out << line << '\n';
        }
    });
    std::vector<std::string> lines = lines_of_file(dir / "late_b.csv");
    std::reverse(lines.begin() + 1, lines.end());
    write_lines(dir / "late_b_reversed.csv", lines);
    for (const char* in : {"late_b.csv", "late_b_reversed.csv"}) {
        const CliRun f =
            run_in(std::string("fit --in ") + in + " --out " + in + ".model --min-days 20 > " + in + ".txt", dir);
        ASSERT_EQ(f.exit_code, 0) << f.err;
    }
    const host::ModelFile a = host::read_model_file((dir / "late_b.csv.model").string());
    const host::ModelFile b = host::read_model_file((dir / "late_b_reversed.csv.model").string());
    EXPECT_EQ(a.lag_s, b.lag_s);
    EXPECT_TRUE(host::has_lag(a)) << slurp(dir / "late_b.csv.txt");
    const std::string report = slurp(dir / "late_b.csv.txt");
    const std::string verdict = report.substr(report.find("bench lag"));
    EXPECT_EQ(verdict.substr(0, verdict.find(" candidates")), [&] {
        const std::string r = slurp(dir / "late_b_reversed.csv.txt");
        const std::string v = r.substr(r.find("bench lag"));
        return v.substr(0, v.find(" candidates"));
    }()) << "the same scores in either order";
}

TEST(FitLag, StatsWithALaggedModelIsStatsOfTheCorrectedFile) {
    // stats --model lags the temperatures as correct does: its thermal stage
    // is the corrected file's IBAs (written with 15 decimals), the systematic
    // residual too.
    const fs::path& dir = lag_mission();
    if (!fs::exists(dir / "given.csv")) {
        fit_and_correct(dir, "m.csv", "--lag 1800", "given.csv", "c_given.csv");
    }
    host::StatsOptions with_model;
    with_model.in = (dir / "m.csv").string();
    with_model.model = (dir / "given.csv").string();
    with_model.noise_iba = (dir / "m.csv.noise-iba.csv").string();
    host::StatsOptions corrected = with_model;
    corrected.in = (dir / "c_given.csv").string();
    corrected.model.clear();
    std::ostringstream log;
    const host::StatsResult a = host::compute_stats(with_model, log);
    const host::StatsResult b = host::compute_stats(corrected, log);
    for (std::size_t p = 0; p < 3; ++p) {
        EXPECT_NEAR(a.rms[p][2].rms, b.rms[p][0].rms, 1e-6) << "pair " << p;
        EXPECT_NEAR(a.systematic_rms[p][2].rms, b.systematic_rms[p][0].rms, 1e-6) << "pair " << p;
        EXPECT_LE(a.systematic_rms[p][2].rms, kBound);
    }
    const CliRun plot = run_in("plot --in m.csv --model given.csv --out p.png", dir);
    EXPECT_EQ(plot.exit_code, 0) << plot.err;
}

TEST(FitLag, AStaticBenchGetsTodaysModelByteForByte) {
    const fs::path dir = scratch_dir("lag-static");
    ASSERT_EQ(run_in("simulate --days 40 --step 120 --seed 3 --out s.csv > /dev/null", dir).exit_code, 0);
    const CliRun a = run_in("fit --in s.csv --out auto.csv --min-days 20 > auto.txt", dir);
    ASSERT_EQ(a.exit_code, 0) << a.err;
    const CliRun n = run_in("fit --in s.csv --out none.csv --min-days 20 --lag 0 > none.txt", dir);
    ASSERT_EQ(n.exit_code, 0) << n.err;
    EXPECT_EQ(slurp(dir / "auto.csv"), slurp(dir / "none.csv"));
    EXPECT_TRUE(has(slurp(dir / "auto.txt"), "bench lag (--lag auto): no lag: the best lags found"))
        << slurp(dir / "auto.txt");
}

// ---- Self-calibration with the bench's lag (`correct --self-calibrate
// --lag`): the estimator learns the lagged model from none, on the same
// mission, measured from its second half (issue 40 measures a 600-day
// mission from day 60; this one has 40 days).

constexpr double kSelfCalibrationBound = 0.2;  // arcsec per pair, issue 40's
constexpr double kLearntFromDays = 20.0;

// The first row's t of the mission, + days.
double mission_day(double days) {
    const std::vector<std::string> lines = lines_of_file(lag_mission() / "m.csv");
    return std::stod(lines.at(1).substr(0, lines.at(1).find(','))) + days * 86400.0;
}

CliRun self_calibrate_in(const fs::path& dir, const std::string& in, const std::string& args, const std::string& out) {
    return run_in(
        "correct --in " + in + " --self-calibrate --out " + out + " --model-history " + out + ".history.csv " + args,
        dir);
}

TEST(SelfCalibrationLag, LearnsTheLaggedModelFromNoModel) {
    const fs::path& dir = lag_mission();
    const CliRun r = self_calibrate_in(dir, "m.csv", "--lag 1800", "sc_lag.csv");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const double from = mission_day(kLearntFromDays);
    const std::array<double, 3> with_lag = systematic(dir, "sc_lag.csv", from);
    // Mutation: the same estimator without the lag.
    ASSERT_EQ(self_calibrate_in(dir, "m.csv", "", "sc_none.csv").exit_code, 0);
    const std::array<double, 3> without = systematic(dir, "sc_none.csv", from);
    for (std::size_t p = 0; p < 3; ++p) {
        EXPECT_LE(with_lag[p], kSelfCalibrationBound) << "pair " << p;
        RecordProperty("self_calibrated_lagged_" + std::to_string(p), std::to_string(with_lag[p]));
    }
    EXPECT_GT(*std::max_element(without.begin(), without.end()), 1.5 * kSelfCalibrationBound)
        << "without the lag the bound must fail";
    // The history says which lag its models take; without one it is as before.
    const std::vector<std::string> h = lines_of_file(dir / "sc_lag.csv.history.csv");
    ASSERT_GT(h.size(), 10U);
    EXPECT_EQ(h[0], "t,version,chu,axis,c0,c1,c2,c3,crc32c,tt_us,origin,lag_s");
    for (std::size_t i = 1; i < h.size(); ++i) {
        EXPECT_EQ(h[i].substr(h[i].rfind(',')), ",1800") << h[i];
    }
    EXPECT_EQ(lines_of_file(dir / "sc_none.csv.history.csv").at(0),
              "t,version,chu,axis,c0,c1,c2,c3,crc32c,tt_us,origin");
}

// The test's own lag of the rows (OwnLag, long double, written with 9
// decimals) learnt from without a lag: the same models, to the rounding of
// the temperatures written.
TEST(SelfCalibrationLag, LearnsAsFromTheTestsOwnLaggedFile) {
    const fs::path& dir = lag_mission();
    write_own_lagged(dir / "m.csv", dir / "own_sc.csv", kLagS);
    ASSERT_EQ(self_calibrate_in(dir, "own_sc.csv", "", "sc_own.csv").exit_code, 0);
    ASSERT_EQ(self_calibrate_in(dir, "m.csv", "--lag 1800", "sc_given.csv").exit_code, 0);
    const std::vector<std::string> own = lines_of_file(dir / "sc_own.csv.history.csv");
    const std::vector<std::string> given = lines_of_file(dir / "sc_given.csv.history.csv");
    ASSERT_EQ(own.size(), given.size());
    for (std::size_t i = 1; i < own.size(); ++i) {
        const std::vector<std::string> a = fields_of(own[i]);
        const std::vector<std::string> b = fields_of(given[i]);
        ASSERT_EQ(b.size(), a.size() + 1U);  // lag_s
        for (std::size_t c = 0; c < a.size(); ++c) {
            if (c >= 4 && c < 8) {  // c0..c3
                EXPECT_NEAR(std::stod(a[c]), std::stod(b[c]), 1e-5 * (1.0 + std::abs(std::stod(b[c])))) << i;
            } else if (c != 8) {  // not crc32c: the coefficients' bits
                EXPECT_EQ(a[c], b[c]) << i;
            }
        }
    }
    const double from = mission_day(kLearntFromDays);
    const std::array<double, 3> a = systematic(dir, "sc_own.csv", from);
    const std::array<double, 3> b = systematic(dir, "sc_given.csv", from);
    for (std::size_t p = 0; p < 3; ++p) {
        EXPECT_NEAR(a[p], b[p], 0.002) << "pair " << p;
    }
}

TEST(SelfCalibrationLag, StartsFromALaggedModelAndRefusesAnotherLag) {
    const fs::path& dir = lag_mission();
    ASSERT_EQ(run_in("fit --in m.csv --out sc_model.csv --min-days 20 --lag 1800 > /dev/null", dir).exit_code, 0);
    const CliRun ok = self_calibrate_in(dir, "m.csv", "--model sc_model.csv", "sc_start.csv");
    ASSERT_EQ(ok.exit_code, 0) << ok.err;
    const std::vector<std::string> h = lines_of_file(dir / "sc_start.csv.history.csv");
    EXPECT_TRUE(has(h.at(1), ",given,1800")) << h.at(1);
    // The same start with --lag 1800 is the same run, to the byte.
    ASSERT_EQ(self_calibrate_in(dir, "m.csv", "--model sc_model.csv --lag 1800", "sc_same.csv").exit_code, 0);
    EXPECT_EQ(slurp(dir / "sc_same.csv"), slurp(dir / "sc_start.csv"));
    EXPECT_EQ(slurp(dir / "sc_same.csv.history.csv"), slurp(dir / "sc_start.csv.history.csv"));

    const CliRun other = self_calibrate_in(dir, "m.csv", "--model sc_model.csv --lag A:900,B:1800,C:1800", "x.csv");
    expect_refused(other, 1, {"sc_model.csv: head A lags by 1800 s, but the self-calibration lags it by 900 s"});
    const std::pair<std::string, std::string> refused[] = {
        {"correct --in m.csv --lag 900 --out x.csv", "--lag: needs --self-calibrate"},
        {"replay --in m.csv --self-calibrate --lag auto --out x.csv", "auto is learnt by ascorr correct"},
        {"correct --in m.csv --self-calibrate --lag A:0.5 --out x.csv", "the lag must be 0 (no lag) or [1, 86400] s"},
    };
    for (const auto& [args, part] : refused) {
        expect_refused(run_in(args + " > out.txt", dir), 2, {part});
    }
    // A library caller's τ out of range with a lagged model: the range is
    // named, as by the parser, not another τ than the model's.
    host::CorrectOptions o;
    o.in = (dir / "m.csv").string();
    o.out = (dir / "x.csv").string();
    o.model = (dir / "sc_model.csv").string();
    o.self_calibrate = true;
    o.lag_s = std::array<double, kMaxHeads>{0.5, 1800.0, 1800.0, 0.0};
    std::ostringstream log;
    try {
        (void)host::correct_file(o, log);
        ADD_FAILURE() << "a lag of 0.5 s was taken";
    } catch (const std::runtime_error& e) {
        EXPECT_TRUE(has(e.what(), "--lag: head A's 0.5 is not 0 (no lag) or [1, 86400] s")) << e.what();
    }
    expect_absent(dir, {"x.csv", "x.csv.history.csv"});
}

}  // namespace
}  // namespace ascorr::test
