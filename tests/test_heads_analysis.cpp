// The analysis of more heads than the paper's three: a simulated four-head
// mission (`simulate --heads ABCD`) fitted, corrected and scored against the
// noise floor the simulator writes; the pairs derived from the heads present;
// frame F's heads an option; a mission without head C fitted on the heads it
// has (fit --heads); usage errors for --heads and --frame-heads.
// Everything is written under the build tree (ASCORR_TEST_WORK_DIR).
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "ascorr/core/heads.hpp"
#include "ascorr_host/analysis/iba.hpp"
#include "ascorr_host/formats/model_csv.hpp"
#include "cli_run.hpp"

namespace ascorr::test {
namespace {

namespace fs = std::filesystem;

constexpr double kFloorTolerance = 0.05;  // the thermal-corrected IBA RMS within 5 % of the floor

fs::path work_dir(const std::string& name) {
    const fs::path dir = fs::path(ASCORR_TEST_WORK_DIR) / name;
    fs::remove_all(dir);
    fs::create_directories(dir);
    return dir;
}

// The value of `key` in the object of pair `pair` of a stats or floor JSON;
// NaN when the pair is absent or the value null.
double json_value(const std::string& json, const std::string& pair, const std::string& key) {
    const std::regex re("\"" + pair + "\": \\{[^}]*\"" + key + "\": ([-0-9.]+)");
    std::smatch m;
    return std::regex_search(json, m, re) ? std::stod(m[1].str()) : std::nan("");
}

// The pairs a stats or floor JSON lists, in order.
std::vector<std::string> json_pairs(const std::string& json) {
    std::vector<std::string> pairs;
    const std::regex re("\"([A-Z]-[A-Z])\": \\{");
    for (auto it = std::sregex_iterator(json.begin(), json.end(), re); it != std::sregex_iterator(); ++it) {
        pairs.push_back((*it)[1].str());
    }
    return pairs;
}

// 120 days (the fit's span and orbit counts lowered to match), one epoch
// every 2 minutes: about 1500 orbits, a few seconds.
const std::string kMission = "simulate --heads ABCD --days 120 --step 120";
const std::string kFitLimits = " --min-days 100 --min-orbits 50 --holdout 0";

TEST(HeadsAnalysis, PairsAreEveryTwoHeadsInHeadsOrder) {
    const host::PairList all = host::pairs_of(host::kAllHeads);
    ASSERT_EQ(all.count, std::size_t{kMaxHeads} * (kMaxHeads - 1U) / 2U);
    std::vector<std::string> names;
    for (std::size_t p = 0; p < all.count; ++p) {
        names.emplace_back(all.pair[p].name);
        EXPECT_LT(all.pair[p].first, all.pair[p].second);
    }
    EXPECT_EQ(names, (std::vector<std::string>{"A-B", "A-C", "A-D", "B-C", "B-D", "C-D"}));
    const host::PairList paper = host::pairs_of(host::kPaperHeads);
    ASSERT_EQ(paper.count, 3U);
    EXPECT_STREQ(paper.pair[2].name, "B-C");
    // The paper's heads are always analysed; others when they have rows.
    EXPECT_EQ(host::analysis_heads(0U), host::kPaperHeads);
    EXPECT_EQ(host::head_letters(host::analysis_heads(head_bit(3))), "ABCD");
    EXPECT_EQ(host::head_words(host::kAllHeads), "A, B, C and D");
    EXPECT_FALSE(host::parse_head_letters("BA").has_value());
    EXPECT_FALSE(host::parse_head_letters("AA").has_value());
    EXPECT_FALSE(host::parse_head_letters("AE").has_value());
    EXPECT_EQ(host::parse_head_letters("ACD"), head_bit(0) | head_bit(2) | head_bit(3));
}

TEST(HeadsAnalysis, FourHeadMissionIsFittedAndCorrectedToTheFloor) {
    const fs::path dir = work_dir("four-heads");
    const std::string data = (dir / "m.csv").string();
    const std::string model = (dir / "model.csv").string();
    const std::string corrected = (dir / "corrected.csv").string();
    ASSERT_EQ(run_cli(kMission + " --out " + data, dir), 0) << slurp(dir / "err.txt");
    ASSERT_EQ(run_cli("fit --in " + data + " --out " + model + kFitLimits, dir), 0) << slurp(dir / "err.txt");
    EXPECT_NE(slurp(dir / "out.txt").find("epochs with A, B, C and D selected"), std::string::npos);
    const host::ModelFile m = host::read_model_file(model);
    for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
        EXPECT_TRUE(m.present[h]) << "no coefficients for CHU " << head_letter(h);
    }
    ASSERT_EQ(run_cli("correct --in " + data + " --model " + model + " --out " + corrected, dir), 0)
        << slurp(dir / "err.txt");
    // The corrected file as it is ("original"): both stages applied by `correct`.
    ASSERT_EQ(run_cli("stats --json --in " + corrected, dir), 0) << slurp(dir / "err.txt");
    const std::string stats = slurp(dir / "out.txt");
    const std::string floor = slurp(data + ".floor.json");
    const std::vector<std::string> six = {"A-B", "A-C", "A-D", "B-C", "B-D", "C-D"};
    EXPECT_EQ(json_pairs(stats), six) << stats;
    EXPECT_EQ(json_pairs(floor), six) << floor;
    for (const std::string& pair : six) {
        const double got = json_value(stats, pair, "original");
        const double fl = json_value(floor, pair, "rms");
        std::printf("  %s: corrected %.3f\" vs floor %.3f\" (%+.2f %%)\n", pair.c_str(), got, fl,
                    100.0 * (got / fl - 1.0));
        EXPECT_LT(std::fabs(got / fl - 1.0), kFloorTolerance) << pair << ": " << got << " vs floor " << fl;
        EXPECT_EQ(json_value(stats, pair, "n"), json_value(floor, pair, "n")) << pair;
    }

    // Mutation: the same model without head D's rows leaves D's rows
    // thermally uncorrected (`correct` says so) and the pairs with D far from
    // the floor, so the bound above catches a D left out of the fit.
    host::ModelFile without_d = m;
    without_d.present[3] = false;
    const std::string model_abc = (dir / "model-abc.csv").string();
    std::ofstream(model_abc) << host::format_model(without_d);
    const std::string corrected_abc = (dir / "corrected-abc.csv").string();
    ASSERT_EQ(run_cli("correct --in " + data + " --model " + model_abc + " --out " + corrected_abc, dir), 0);
    EXPECT_NE(slurp(dir / "err.txt").find("no coefficients for chu 'D'"), std::string::npos) << slurp(dir / "err.txt");
    ASSERT_EQ(run_cli("stats --json --in " + corrected_abc, dir), 0) << slurp(dir / "err.txt");
    const std::string mutated = slurp(dir / "out.txt");
    double worst = 0.0;
    for (const std::string pair : {"A-D", "B-D", "C-D"}) {
        worst = std::max(worst, json_value(mutated, pair, "original") / json_value(floor, pair, "rms") - 1.0);
    }
    EXPECT_GT(worst, 4.0 * kFloorTolerance) << mutated;
    EXPECT_LT(std::fabs(json_value(mutated, "A-B", "original") / json_value(floor, "A-B", "rms") - 1.0),
              kFloorTolerance);
}

TEST(HeadsAnalysis, FrameHeadsAreAnOptionAndChangeNoIba) {
    const fs::path dir = work_dir("frame-heads");
    const std::string data = (dir / "m.csv").string();
    ASSERT_EQ(run_cli(kMission + " --out " + data, dir), 0) << slurp(dir / "err.txt");
    const std::string floor = slurp(data + ".floor.json");
    for (const std::string frame : {"AB", "BD"}) {
        const std::string model = (dir / ("model-" + frame + ".csv")).string();
        ASSERT_EQ(run_cli("fit --frame-heads " + frame + " --in " + data + " --out " + model + kFitLimits, dir), 0)
            << slurp(dir / "err.txt");
        const std::string words = std::string("frame F of heads ") + frame[0] + " and " + frame[1];
        EXPECT_NE(slurp(dir / "out.txt").find(words), std::string::npos) << slurp(dir / "out.txt");
        ASSERT_EQ(run_cli("stats --json --in " + data + " --model " + model, dir), 0) << slurp(dir / "err.txt");
        const std::string stats = slurp(dir / "out.txt");
        for (const std::string& pair : json_pairs(floor)) {
            const double got = json_value(stats, pair, "thermal");
            const double fl = json_value(floor, pair, "rms");
            EXPECT_LT(std::fabs(got / fl - 1.0), kFloorTolerance) << frame << ' ' << pair << ": " << got;
        }
    }
}

// A mission that never had head C (A, B and D flew): the default fit (A, B,
// C and F = A, C) is refused, naming C and the options that fit the heads
// flown; with them, the three pairs reach the floor. Then two of its heads
// alone, and the usage errors of --heads.
TEST(HeadsAnalysis, AMissionWithoutCIsFittedOnTheHeadsItHas) {
    const fs::path dir = work_dir("without-c");
    const std::string data = (dir / "m.csv").string();
    const std::string model = (dir / "model.csv").string();
    ASSERT_EQ(run_cli("simulate --heads ABD --days 120 --step 120 --out " + data, dir), 0) << slurp(dir / "err.txt");
    EXPECT_EQ(run_cli("fit --in " + data + " --out " + model + kFitLimits, dir), 1);
    const std::string refusal = slurp(dir / "err.txt");
    EXPECT_NE(refusal.find("C has no rows there"), std::string::npos) << refusal;
    EXPECT_NE(refusal.find("(e.g. --heads ABD --frame-heads AD)"), std::string::npos) << refusal;
    EXPECT_FALSE(fs::exists(model));

    ASSERT_EQ(run_cli("fit --heads ABD --frame-heads AD --in " + data + " --out " + model + kFitLimits, dir), 0)
        << slurp(dir / "err.txt");
    EXPECT_NE(slurp(dir / "out.txt").find("epochs with A, B and D selected"), std::string::npos);
    const host::ModelFile m = host::read_model_file(model);
    EXPECT_TRUE(m.present[0] && m.present[1] && m.present[3]);
    EXPECT_FALSE(m.present[2]);
    ASSERT_EQ(run_cli("stats --json --in " + data + " --model " + model, dir), 0) << slurp(dir / "err.txt");
    const std::string stats = slurp(dir / "out.txt");
    const std::string floor = slurp(data + ".floor.json");
    EXPECT_EQ(json_pairs(floor), (std::vector<std::string>{"A-B", "A-D", "B-D"}));
    double worst_uncorrected = 0.0;
    for (const std::string& pair : json_pairs(floor)) {
        const double got = json_value(stats, pair, "thermal");
        const double fl = json_value(floor, pair, "rms");
        std::printf("  %s: thermal %.3f\" vs floor %.3f\" (%+.2f %%)\n", pair.c_str(), got, fl,
                    100.0 * (got / fl - 1.0));
        EXPECT_LT(std::fabs(got / fl - 1.0), kFloorTolerance) << pair << ": " << got << " vs floor " << fl;
        worst_uncorrected = std::max(worst_uncorrected, json_value(stats, pair, "aberration") / fl - 1.0);
    }
    // Control: without the thermal stage the bound fails (the check can).
    EXPECT_GT(worst_uncorrected, kFloorTolerance);
    // The pairs with C are still listed, without epochs (the contract's
    // "A, B and C always").
    EXPECT_EQ(json_value(stats, "A-C", "n"), 0.0) << stats;

    // Two heads: F of A and B, one pair.
    const std::string two = (dir / "two.csv").string();
    ASSERT_EQ(run_cli("fit --heads AB --frame-heads AB --in " + data + " --out " + two + kFitLimits, dir), 0)
        << slurp(dir / "err.txt");
    const host::ModelFile m2 = host::read_model_file(two);
    EXPECT_TRUE(m2.present[0] && m2.present[1]);
    EXPECT_FALSE(m2.present[2] || m2.present[3]);
    EXPECT_NE(slurp(dir / "out.txt").find("rows in the period"), std::string::npos);
    ASSERT_EQ(run_cli("stats --json --in " + data + " --model " + two, dir), 0) << slurp(dir / "err.txt");
    const double ab = json_value(slurp(dir / "out.txt"), "A-B", "thermal");
    EXPECT_LT(std::fabs(ab / json_value(floor, "A-B", "rms") - 1.0), kFloorTolerance) << ab;

    // A head with rows in part of the period only (D failed on day 20): the
    // refusal names it and C, and the heads left; --heads fits them and
    // counts D's rows as left out.
    std::ifstream in(data);
    std::string cut;
    double t0 = std::nan("");
    std::size_t d_rows = 0;
    for (std::string line; std::getline(in, line);) {
        const bool row = !line.empty() && line[0] != 't';
        if (row && std::isnan(t0)) {
            t0 = std::stod(line);
        }
        if (row && line.find(",D,") != std::string::npos && std::stod(line) > t0 + 20.0 * 86400.0) {
            continue;
        }
        d_rows += row && line.find(",D,") != std::string::npos ? 1U : 0U;
        cut += line + '\n';
    }
    const std::string failed = (dir / "d-failed.csv").string();
    std::ofstream(failed) << cut;
    EXPECT_EQ(run_cli("fit --in " + failed + " --out " + model + kFitLimits, dir), 1);
    const std::string partial = slurp(dir / "err.txt");
    EXPECT_NE(partial.find("C has no rows there, D's rows span only t = "), std::string::npos) << partial;
    EXPECT_NE(partial.find("(e.g. --heads AB --frame-heads AB)"), std::string::npos) << partial;
    ASSERT_EQ(run_cli("fit --heads AB --frame-heads AB --in " + failed + " --out " + model + kFitLimits, dir), 0)
        << slurp(dir / "err.txt");
    EXPECT_NE(slurp(dir / "out.txt").find("; rows of other heads left out (--heads) " + std::to_string(d_rows) + "\n"),
              std::string::npos)
        << slurp(dir / "out.txt");
    // One head with rows among those named: no suggestion that would be refused.
    EXPECT_EQ(run_cli("fit --heads CD --frame-heads CD --in " + data + " --out " + model + kFitLimits, dir), 1);
    EXPECT_NE(slurp(dir / "err.txt").find("C has no rows there: a fit needs two heads with rows"), std::string::npos)
        << slurp(dir / "err.txt");
    // No rows at all in the period: the message as it always was.
    EXPECT_EQ(run_cli("fit --from 1e9 --in " + data + " --out " + model + kFitLimits, dir), 1);
    EXPECT_NE(slurp(dir / "err.txt").find("solutions of A, B and C that pass the selection\n"), std::string::npos)
        << slurp(dir / "err.txt");

    // Usage: F's heads must be among --heads; --heads is two or more letters.
    EXPECT_EQ(run_cli("fit --heads ABD --in " + data + " --out " + model + kFitLimits, dir), 2);
    EXPECT_NE(slurp(dir / "err.txt").find("frame F's heads AC (--frame-heads) are not among them"), std::string::npos)
        << slurp(dir / "err.txt");
    EXPECT_EQ(run_cli("fit --heads A --frame-heads AB --in " + data + " --out " + model + kFitLimits, dir), 2);
}

TEST(HeadsAnalysis, HeadsBeyondCLeaveTheOthersRowsAsTheyWere) {
    const fs::path dir = work_dir("derived-head");
    ASSERT_EQ(run_cli("simulate --days 1 --step 300 --out " + (dir / "abc.csv").string(), dir), 0);
    ASSERT_EQ(run_cli("simulate --heads ABCD --days 1 --step 300 --out " + (dir / "abcd.csv").string(), dir), 0);
    std::ifstream abcd(dir / "abcd.csv");
    std::string without_d;
    std::size_t d_rows = 0;
    for (std::string line; std::getline(abcd, line);) {
        if (line.find(",D,") != std::string::npos) {
            ++d_rows;
            continue;
        }
        without_d += line + '\n';
    }
    EXPECT_GT(d_rows, 0U);
    EXPECT_EQ(without_d, slurp(dir / "abc.csv"));
    const std::string floor_abc = slurp(dir / "abc.csv.floor.json");
    const std::string floor_abcd = slurp(dir / "abcd.csv.floor.json");
    for (const std::string pair : {"A-B", "A-C", "B-C"}) {
        EXPECT_EQ(json_value(floor_abc, pair, "rms"), json_value(floor_abcd, pair, "rms")) << pair;
    }
}

TEST(HeadsAnalysis, BadHeadLettersAreUsageErrors) {
    const fs::path dir = work_dir("bad-heads");
    const std::string out = " --out " + (dir / "x.csv").string();
    for (const std::string heads : {"A", "BA", "AAB", "ABE", "abc", "\"\""}) {
        EXPECT_EQ(run_cli("simulate --days 1 --heads " + heads + out, dir), 2) << heads;
        const std::string err = slurp(dir / "err.txt");
        EXPECT_NE(err.find("of the heads ABCD (their letters, in that order, none twice)"), std::string::npos)
            << heads << ": " << err;
        EXPECT_NE(err.find("Run with --help"), std::string::npos) << heads << ": " << err;
    }
    EXPECT_FALSE(fs::exists(dir / "x.csv"));
    EXPECT_EQ(run_cli("simulate --days 1 --heads ABC --head-bias D:0:1:5" + out, dir), 2);
    EXPECT_NE(slurp(dir / "err.txt").find("HEAD must be A, B or C (the heads simulated, --heads)"), std::string::npos)
        << slurp(dir / "err.txt");
    for (const std::string frame : {"A", "CA", "ABC", "AX"}) {
        EXPECT_EQ(run_cli("fit --frame-heads " + frame + " --in x.csv --out " + (dir / "m.csv").string(), dir), 2)
            << frame;
        EXPECT_NE(slurp(dir / "err.txt").find("Run with --help"), std::string::npos) << slurp(dir / "err.txt");
    }
}

}  // namespace
}  // namespace ascorr::test
