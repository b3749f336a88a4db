// `ascorr replay --self-calibrate`: the target runs the on-board estimator on
// the replayed solutions (link protocol v4), and the host compares every
// answer and model version, every model the target adopts and its final
// report with its own run over the file in the target's scalar. The data come
// from `ascorr simulate` (a bench that deforms with temperature), which the
// estimator did not produce. In process (loopback, float) the replayed file
// and model history must equal `ascorr correct --self-calibrate --scalar
// float` byte for byte, and a target that is told no solution is clean must
// be caught; under QEMU (label target) each board against its own scalar.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "ascorr_host/formats/model_csv.hpp"
#include "ascorr_host/link/link_transport.hpp"
#include "ascorr_host/link/qemu_targets.hpp"
#include "ascorr_host/link/replay.hpp"
#include "ascorr_link/frame.hpp"
#include "ascorr_link/messages.hpp"
#include "ascorr_link/server.hpp"
#include "cli_run.hpp"
#include "lagged_models.hpp"
#include "replay_boards.hpp"
#include "rewriting_loopback.hpp"
#include "test_support.hpp"

namespace ascorr::test {
namespace {

// Four simulated days at 300 s (2751 rows): enough orbits (≥ 30 with ≥ 4
// epochs each) for the estimator to adopt a model on day 3.
std::filesystem::path simulated(const std::string& name, const std::string& extra = "") {
    return simulated_in(name, "--days 4 --step 300 --seed 3" + extra);
}

host::ReplayOptions options(const std::filesystem::path& dir, const std::string& target) {
    host::ReplayOptions o = replay_options(dir, target);
    o.model_history = (dir / "replayed.history.csv").string();
    o.self_calibrate = true;
    return o;
}

// What the host says, for the same rows in the target's scalar.
void expect_same_as_correct(const std::filesystem::path& dir, const std::string& scalar,
                            const std::string& extra = "") {
    const CliRun r = run_in("correct --in sim.csv --out corrected.csv --self-calibrate --scalar " + scalar +
                                " --model-history corrected.history.csv" + extra,
                            dir);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const std::string history = slurp(dir / "corrected.history.csv");
    EXPECT_GT(history.size(), 40U) << "no model was adopted: the comparison would be vacuous";
    EXPECT_EQ(slurp(dir / "replayed.history.csv"), history);
    EXPECT_EQ(slurp(dir / "replayed.csv"), slurp(dir / "corrected.csv"));
}

// Whether a model history has a row of head `head` that says "learnt".
bool learnt(const std::string& history, const std::string& head) {
    std::istringstream in(history);
    for (std::string l; std::getline(in, l);) {
        if (l.find("," + head + ",") != std::string::npos && l.size() > 7 &&
            l.compare(l.size() - 7, 7, ",learnt") == 0) {
            return true;
        }
    }
    return false;
}

// Every answer, model version, adopted model and the final report as the host's.
void expect_models_agree(const host::ReplaySummary& s, const std::string& log) {
    EXPECT_EQ(s.mismatches, 0U) << log;
    EXPECT_EQ(s.version_mismatches, 0U);
    EXPECT_EQ(s.history_mismatches, 0U);
    EXPECT_TRUE(s.report_matches);
}

void expect_agreement(const host::ReplaySummary& s) {
    EXPECT_TRUE(s.self_calibrate);
    EXPECT_EQ(s.returned, 2751U);
    EXPECT_GE(s.models, 1U);
    expect_models_agree(s, "");
}

// Replays the simulated file of `dir` through `target` from the model dir/model, printed after `label`.
host::ReplaySummary replay_from_model(const std::filesystem::path& dir, const std::string& target,
                                      const std::string& model, std::ostringstream& log,
                                      const std::string& label = "") {
    host::ReplayOptions o = options(dir, target);
    o.model = (dir / model).string();
    return replay_printed(o, log, label);
}

TEST(ReplaySelfCalibration, LoopbackEqualsCorrectSelfCalibrate) {
    const auto dir = simulated("replay_sc_loop");
    std::ostringstream log;
    const host::ReplaySummary s = replay_printed(options(dir, "loopback-float"), log);
    expect_agreement(s);
    expect_same_as_correct(dir, "float");
}

// The rule for the rotation common to all heads over the link: with
// --mountings M --combined A the target's estimator (CALIB_START's
// common_rotation 1, after M's MOUNTING_LOADs) re-gauges its models as
// `correct --self-calibrate --mountings M --combined A` does, bit for bit.
void expect_rule_as_correct(const std::string& target, const std::string& scalar, const std::string& name) {
    const auto dir = simulated(name);
    host::ReplayOptions o = options(dir, target);
    o.mountings = (dir / "sim.csv.mountings.csv").string();
    o.combined = (dir / "replayed.combined.csv").string();
    std::ostringstream log;
    const host::ReplaySummary s = replay_printed(o, log, target + ": ");
    expect_agreement(s);
    expect_same_as_correct(dir, scalar, " --mountings sim.csv.mountings.csv --combined corrected.combined.csv");
    const std::string history = slurp(dir / "replayed.history.csv");
    EXPECT_NE(history.find(",learnt,combined\n"), std::string::npos) << history.substr(0, 300);
    // Mutation: without the rule the models differ (the test can fail).
    const CliRun plain = run_in("correct --in sim.csv --out plain.csv --self-calibrate --scalar " + scalar +
                                    " --model-history plain.history.csv",
                                dir);
    ASSERT_EQ(plain.exit_code, 0) << plain.err;
    EXPECT_NE(slurp(dir / "plain.csv"), slurp(dir / "replayed.csv"));
}

TEST(ReplaySelfCalibration, TheCommonRotationRuleOnTheLinkEqualsCorrect) {
    expect_rule_as_correct("loopback-float", "float", "replay_sc_rule");
}

// Starting from a model (version 0, active from the first epoch: its epoch
// must agree too), with the rows shuffled and, every 50th epoch, a second row
// of head A within the same microsecond (0.3 µs earlier, later in the file):
// target and host take the rows in the on-board clock's order (TT µs, then
// line), so the same row feeds the estimator on both sides.
TEST(ReplaySelfCalibration, FromAModelWithRowsOutOfOrderAndWithinAMicrosecond) {
    const auto dir = simulated("replay_sc_model");
    {
        const auto lines = [&] {
            std::vector<std::string> v;
            std::istringstream in(slurp(dir / "sim.csv"));
            for (std::string l; std::getline(in, l);) {
                v.push_back(l);
            }
            return v;
        }();
        std::vector<std::string> rows(lines.begin() + 1, lines.end());
        std::vector<std::string> extra;
        for (std::size_t i = 0; i < rows.size(); i += 150) {  // 3 rows an epoch: every 50th epoch's A
            const std::string& r = rows[i];
            const std::size_t comma = r.find(',');
            if (r.compare(comma + 1, 2, "A,") != 0) {
                continue;
            }
            char t[64];
            std::snprintf(t, sizeof t, "%.7f", std::stod(r.substr(0, comma)) - 3e-7);
            std::string twin = t + r.substr(comma);
            twin[twin.find(",A,") + 10] ^= 1;  // another quaternion (a digit of qw)
            extra.push_back(twin);
        }
        std::mt19937 rng(11);
        std::shuffle(rows.begin(), rows.end(), rng);
        std::ofstream out(dir / "sim.csv");
        out << lines[0] << '\n';
        for (const std::string& r : rows) {
            out << r << '\n';
        }
        for (const std::string& r : extra) {
            out << r << '\n';
        }
    }
    host::write_model_file((dir / "initial.csv").string(), host::read_model_file(data_path("model_table2.csv")));
    std::ostringstream log;
    expect_models_agree(replay_from_model(dir, "loopback-float", "initial.csv", log), log.str());
    const CliRun r = run_in(
        "correct --in sim.csv --out corrected.csv --self-calibrate --scalar float --model "
        "initial.csv --model-history corrected.history.csv",
        dir);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    expect_same_files(dir, {{"replayed.history.csv", "corrected.history.csv"}, {"replayed.csv", "corrected.csv"}});
    EXPECT_NE(slurp(dir / "corrected.history.csv").find(",0,A,alpha,"), std::string::npos);  // version 0
}

// Four heads from a model: the link's estimator learns D as `correct
// --self-calibrate` does (A, B and C from the epochs the three are clean, D
// from those of them it is clean too; its solutions come after A, B and C,
// so they are fed alone into the cycle): the target's models (CALIB_MODEL of
// every head compared) and report are the host's, and replay's outputs are
// correct's, bit for bit, D's learnt rows included.
TEST(ReplaySelfCalibration, FourHeadsFromAModelLearnHeadDOnTheTargetAsOnTheHost) {
    const auto dir = scratch_dir("replay_sc_four");
    const CliRun sim = run_in("simulate --out sim.csv --days 4 --step 300 --seed 3 --heads ABCD", dir);
    ASSERT_EQ(sim.exit_code, 0) << sim.err;
    std::ostringstream log;
    const host::ReplaySummary s = replay_from_model(dir, "loopback-float", "sim.csv.truth.csv", log);
    expect_models_agree(s, log.str());
    EXPECT_GE(s.models, 2U);
    const CliRun r = run_in(
        "correct --in sim.csv --out corrected.csv --self-calibrate --scalar float --model sim.csv.truth.csv "
        "--model-history corrected.history.csv",
        dir);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const std::string history = slurp(dir / "replayed.history.csv");
    EXPECT_EQ(history, slurp(dir / "corrected.history.csv"));
    EXPECT_EQ(slurp(dir / "replayed.csv"), slurp(dir / "corrected.csv"));
    EXPECT_NE(history.find(",1,D,alpha,"), std::string::npos);
    EXPECT_TRUE(learnt(history, "D")) << "D never learnt on the target: " << history;
    EXPECT_EQ(log.str().find("no model for head"), std::string::npos) << log.str();
}

// A quadratic model cannot start the target's estimator (CALIB_MODEL_LOAD
// carries c0..c3): refused, naming the file and the term.
TEST(ReplaySelfCalibration, AQuadraticInitialModelIsRefused) {
    const auto dir = simulated("replay_sc_quadratic");
    host::ModelFile m = host::read_model_file(data_path("model_table2.csv"));
    m.coefficients[1][2][5] = 1e-3;  // B gamma c2_2
    m.quadratic = true;
    host::write_model_file((dir / "quadratic.csv").string(), m);
    host::ReplayOptions o = options(dir, "loopback-float");
    o.model = (dir / "quadratic.csv").string();
    std::ostringstream log;
    try {
        (void)host::replay(o, log);
        ADD_FAILURE() << "accepted";
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find("head B gamma has a quadratic term (c2_2)"), std::string::npos)
            << e.what();
    }
    EXPECT_FALSE(std::filesystem::exists(o.out));
}

// The target's LinkServer in process, behind a link that clears the clean
// bit of some SOLUTION_INs (every head-B solution from `from_id` on): the
// target learns from other epochs than the host, which the comparison must
// see.
struct CleanBitEraser {
    explicit CleanBitEraser(std::uint32_t from_id)
        : target([this, from_id](std::uint8_t& type, std::uint8_t* payload, std::size_t& n) {
              link::SolutionIn<float> s{};
              if (type == static_cast<std::uint8_t>(link::MessageType::kSolutionIn) && link::decode(payload, n, s) &&
                  s.head == 1U && s.id >= from_id && (s.calib & link::kCalibClean) != 0U) {
                  s.calib = static_cast<std::uint8_t>(s.calib & ~link::kCalibClean);
                  n = link::encode(s, payload);
                  ++erased;
              }
          }) {}
    host::Transport& transport() { return target.transport(); }

    std::size_t erased = 0;
    RewritingLoopback target;
};

TEST(ReplaySelfCalibration, UntouchedLinkDoubleAgrees) {
    // The control of the mutation below: the same double, erasing nothing.
    const auto dir = simulated("replay_sc_double");
    CleanBitEraser target(0xFFFFFFFFU);
    std::ostringstream log;
    const host::ReplaySummary s = host::replay_over(options(dir, "link double"), target.transport(), log);
    EXPECT_EQ(target.erased, 0U);
    expect_agreement(s);
}

TEST(ReplaySelfCalibration, ATargetThatLearnsOtherwiseIsCaught) {
    const auto dir = simulated("replay_sc_mutant");
    CleanBitEraser target(1500U);  // day 2 on: the estimator loses head B
    std::ostringstream log;
    const host::ReplaySummary s = host::replay_over(options(dir, "link double"), target.transport(), log);
    std::cout << host::to_json(s) << "\n" << log.str();
    EXPECT_GT(target.erased, 100U);
    EXPECT_EQ(s.returned, 2751U);
    EXPECT_FALSE(s.report_matches);
    EXPECT_GT(s.version_mismatches + s.history_mismatches, 0U);
    EXPECT_GT(s.mismatches, 0U);  // rows corrected with no model instead of the host's
    EXPECT_NE(log.str().find("differs from the host's"), std::string::npos) << log.str();
}

// ---- A firmware from before a report: the target answers its request
// kUnknownType (here: the request's type made one no target knows, so the
// in-process server answers as such a firmware does).

constexpr std::uint8_t kTypeNoTargetKnows = 0xEE;

// A loopback target asked requests of type `request` (counted), which it
// knows or (a firmware before it) does not.
struct TargetWithout {
    TargetWithout(link::MessageType request, bool knows)
        : target([this, request, knows](std::uint8_t& type, std::uint8_t*, std::size_t&) {
              if (type == static_cast<std::uint8_t>(request)) {
                  ++asked;
                  type = knows ? type : kTypeNoTargetKnows;
              }
          }) {}
    std::size_t asked = 0;
    RewritingLoopback target;
};

// Its stack is not known; everything it corrected and learnt still is, and
// the run's outputs are written (before STACK_REPORT the replay ended with
// an error and lost them).
TEST(ReplaySelfCalibration, ATargetBeforeTheStackReportStillReplays) {
    const auto dir = simulated("replay_sc_before_stack");
    TargetWithout old(link::MessageType::kStackReportRequest, false);
    std::ostringstream log;
    const host::ReplaySummary s = host::replay_over(options(dir, "link double"), old.target.transport(), log);
    EXPECT_EQ(old.asked, 1U);
    expect_agreement(s);
    EXPECT_NE(log.str().find("the target does not report its stack (firmware before STACK_REPORT)"), std::string::npos)
        << log.str();
    expect_same_as_correct(dir, "float");
}

// Its Sun learner cannot be compared: the replay ends, but does not agree.
// Control: the same target answering it agrees.
TEST(ReplaySelfCalibration, ATargetThatCannotReportItsSunLearnerDoesNotMatch) {
    const auto dir = simulated("replay_sc_before_sun_report", " --orbit-term 0.8");
    host::ReplayOptions o = options(dir, "link double");
    o.sun_auto = true;
    for (const bool reports : {true, false}) {
        TargetWithout old(link::MessageType::kSunLearnerReportRequest, reports);
        std::ostringstream log;
        const host::ReplaySummary s = host::replay_over(o, old.target.transport(), log);
        EXPECT_EQ(old.asked, 1U);
        EXPECT_EQ(s.returned, 2751U);
        EXPECT_EQ(s.mismatches, 0U) << log.str();
        EXPECT_EQ(s.report_matches, reports) << log.str();
        EXPECT_EQ(
            log.str().find("does not report its Sun learner (firmware before SUN_LEARNER_REPORT)") != std::string::npos,
            !reports)
            << log.str();
        EXPECT_TRUE(std::filesystem::exists(o.out));
    }
}

TEST(ReplaySelfCalibration, OptionsAreChecked) {
    const auto dir = scratch_dir("replay_sc_options");
    host::ReplayOptions o = options(dir, "loopback-float");
    std::ostringstream log;
    o.model_history = o.out;
    EXPECT_THROW(host::replay(o, log), std::runtime_error);  // two outputs, one path
    o = options(dir, "loopback-float");
    o.states = data_path("model_table2.csv");
    EXPECT_THROW(host::replay(o, log), std::runtime_error);  // --states: refused as by correct
    o = options(dir, "loopback-float");
    o.time_constant_days = 0.5;
    EXPECT_THROW(host::replay(o, log), std::runtime_error);
    o = options(dir, "loopback-float");
    o.self_calibrate = false;
    EXPECT_THROW(host::replay(o, log), std::runtime_error);  // no --model, no --self-calibrate
    EXPECT_FALSE(std::filesystem::exists(o.out));
}

// ---- The estimator with the bench's lag on the link (CALIB_START's lags):
// the target lags in its scalar and learns from what it lagged, bit for bit
// as the host's run of the same rows lagged as the target lags them.

constexpr double kLagS = 900.0;

std::filesystem::path lagged_mission(const std::string& name) {
    const auto dir = simulated(name, " --bench-lag 900");
    write_truth_models(dir, "900", "sim.csv");
    return dir;
}

host::ReplaySummary replay_lagged(const std::filesystem::path& dir, const std::string& target,
                                  const std::string& label) {
    host::ReplayOptions o = options(dir, target);
    o.lag_s = std::array<double, kMaxHeads>{kLagS, kLagS, kLagS, 0.0};
    std::ostringstream log;
    return replay_printed(o, log, label);
}

// The first four columns (t, version, chu, axis) of each history row, and
// whether the header has lag_s and every row ends with the lag.
std::vector<std::string> versions_of(const std::string& history, bool& lagged) {
    std::vector<std::string> out;
    std::istringstream in(history);
    const auto ends_with = [](const std::string& l, const std::string& end) {
        return l.size() >= end.size() && l.compare(l.size() - end.size(), end.size(), end) == 0;
    };
    lagged = true;
    for (std::string l; std::getline(in, l);) {
        std::size_t cut = 0;
        for (int k = 0; k < 4; ++k) {
            cut = l.find(',', cut) + 1;
        }
        out.push_back(l.substr(0, cut));
        lagged = lagged && ends_with(l, out.size() == 1 ? ",lag_s" : ",900");
    }
    return out;
}

// The lagged estimator on the target and on the host, and against `correct
// --self-calibrate --lag` (which lags in double): the same versions at the
// same times, the corrections within the float bound.
void expect_lagged_as_the_host(const std::filesystem::path& dir, const host::ReplaySummary& s,
                               const std::string& scalar) {
    expect_agreement(s);
    EXPECT_LE(s.max_error_arcsec, 0.05);
    const CliRun c = run_in("correct --in sim.csv --out corrected.csv --self-calibrate --lag 900 --scalar " + scalar +
                                " --model-history corrected.history.csv",
                            dir);
    ASSERT_EQ(c.exit_code, 0) << c.err;
    bool lagged_target = false;
    bool lagged_host = false;
    const std::vector<std::string> target = versions_of(slurp(dir / "replayed.history.csv"), lagged_target);
    const std::vector<std::string> host = versions_of(slurp(dir / "corrected.history.csv"), lagged_host);
    ASSERT_GT(target.size(), 9U) << "no model was adopted: the comparison would be vacuous";
    EXPECT_EQ(target, host);
    EXPECT_TRUE(lagged_target);
    EXPECT_TRUE(lagged_host);
    // Mutation: the estimator without the lag learns other coefficients.
    const CliRun plain = run_in("correct --in sim.csv --out plain.csv --self-calibrate --scalar " + scalar +
                                    " --model-history plain.history.csv",
                                dir);
    ASSERT_EQ(plain.exit_code, 0) << plain.err;
    std::string replayed = slurp(dir / "replayed.history.csv");
    for (const std::string end : {",lag_s\n", ",900\n"}) {
        for (std::size_t at = replayed.find(end); at != std::string::npos; at = replayed.find(end, at)) {
            replayed.replace(at, end.size(), "\n");
        }
    }
    EXPECT_EQ(replayed.substr(0, replayed.find('\n')), slurp(dir / "plain.history.csv").substr(0, replayed.find('\n')));
    EXPECT_NE(replayed, slurp(dir / "plain.history.csv"));
}

TEST(ReplaySelfCalibration, ALaggedEstimatorOnTheLinkIsTheHostsBitForBit) {
    const auto dir = lagged_mission("replay_sc_lag");
    const host::ReplaySummary s = replay_lagged(dir, "loopback-float", "");
    expect_lagged_as_the_host(dir, s, "float");
    // From a lagged model (its lag: CALIB_START's), and the same from --lag.
    std::ostringstream log;
    const host::ReplaySummary m = replay_from_model(dir, "loopback-float", "m_lag.csv", log);
    expect_models_agree(m, log.str());
    const std::string history = slurp(dir / "replayed.history.csv");
    EXPECT_NE(history.find(",given,900\n"), std::string::npos) << history.substr(0, 300);
    // A lagged model with another lag than --lag's is refused before the target sees it.
    host::ReplayOptions o = options(dir, "loopback-float");
    o.model = (dir / "m_lag.csv").string();
    o.lag_s = std::array<double, kMaxHeads>{1800.0, 1800.0, 1800.0, 0.0};
    std::ostringstream refused;
    try {
        (void)host::replay(o, refused);
        ADD_FAILURE() << "another lag than the model's was taken";
    } catch (const std::runtime_error& e) {
        EXPECT_TRUE(has(e.what(), "m_lag.csv: head A lags by 900 s, but the self-calibration lags it by 1800 s"))
            << e.what();
    }
}

#ifdef ASCORR_REPLAY_QEMU
class ReplaySelfCalibrationQemu : public ::testing::TestWithParam<host::QemuTarget> {};

// The rule for the common rotation on each board, bit for bit.
TEST_P(ReplaySelfCalibrationQemu, TheCommonRotationRuleAsTheHost) {
    const host::QemuTarget& board = GetParam();
    expect_rule_as_correct(std::string(board.replay), board_scalar(board), "replay_sc_rule_" + board_name(board));
}

// Each board against the host in its own scalar (Q30 on the M3, float on the
// M4F, whose link image does not fuse multiply-adds), bit for bit.
TEST_P(ReplaySelfCalibrationQemu, SameModelsAndAnswersAsTheHost) {
    const host::QemuTarget& board = GetParam();
    const auto dir = simulated("replay_sc_" + board_name(board));
    const host::ReplaySummary s = replay_on_board(board, options(dir, std::string(board.replay)));
    expect_agreement(s);
    expect_same_as_correct(dir, board_scalar(board));
    EXPECT_EQ(s.restarts, 0U);
}

// Four heads from a model, on each board: D learnt on board as on the host,
// bit for bit (the link's estimator has every head of the core).
TEST_P(ReplaySelfCalibrationQemu, FourHeadsLearnHeadDAsTheHost) {
    const host::QemuTarget& board = GetParam();
    const auto dir = simulated("replay_sc4_" + board_name(board), " --heads ABCD");
    std::ostringstream log;
    const host::ReplaySummary s =
        replay_from_model(dir, std::string(board.replay), "sim.csv.truth.csv", log, std::string(board.replay) + ": ");
    expect_models_agree(s, log.str());
    EXPECT_EQ(s.restarts, 0U);
    expect_same_as_correct(dir, board_scalar(board), " --model sim.csv.truth.csv");
    EXPECT_TRUE(learnt(slurp(dir / "replayed.history.csv"), "D")) << "D never learnt on the board";
}

// The lagged estimator on each board (Q30 on the M3, float on the M4F), bit
// for bit as the host's run of the rows lagged in the board's scalar.
TEST_P(ReplaySelfCalibrationQemu, ALaggedEstimatorAsTheHost) {
    const host::QemuTarget& board = GetParam();
    const auto dir = lagged_mission("replay_sc_lag_" + board_name(board));
    const host::ReplaySummary s = replay_lagged(dir, std::string(board.replay), std::string(board.replay) + ": ");
    expect_lagged_as_the_host(dir, s, board_scalar(board));
    EXPECT_EQ(s.restarts, 0U);
}

// The line of `log` that holds `key` (empty: none).
std::string line_with(const std::string& log, const std::string& key) {
    const std::size_t at = log.find(key);
    if (at == std::string::npos) {
        return {};
    }
    const std::size_t newline = log.rfind('\n', at);
    const std::size_t begin = newline == std::string::npos ? 0 : newline + 1;
    const std::size_t end = log.find('\n', at);
    return log.substr(begin, end == std::string::npos ? end : end - begin);
}

// The Sun learner beside the estimator on each board: its report
// (SUN_LEARNER_REPORT) as the host's learner at its last epoch, every answer
// and model as the host's, and the link image's stack, painted at boot and
// now holding the learner's solve steps, within 1 KiB to three quarters of
// its size (as ReplayQemu.CleanLink's without the learner).
TEST_P(ReplaySelfCalibrationQemu, TheSunLearnerAsTheHostWithinTheStack) {
    const host::QemuTarget& board = GetParam();
    const auto dir = simulated("replay_sc_sun_" + board_name(board), " --orbit-term 0.8");
    host::ReplayOptions o = options(dir, std::string(board.replay));
    o.sun_auto = true;
    o.timeout_ms = 2000;  // an answer may wait for a solve's rest (settle)
    std::ostringstream log;
    const host::ReplaySummary s = replay_printed(o, log, std::string(board.replay) + ": ");
    expect_agreement(s);
    EXPECT_EQ(s.restarts, 0U);
    // Not two empty learners: the target's own account (from its report).
    const std::string account = line_with(log.str(), "on the target, ");
    EXPECT_NE(account.find("the learner scored 8 orbits"), std::string::npos) << log.str();
    EXPECT_NE(log.str().find("finished 8 solves in a cycle"), std::string::npos) << log.str();
    EXPECT_EQ(s.target_stack_size, 8192U);
    EXPECT_GE(s.target_stack_bytes, 1024U);
    EXPECT_LE(4U * s.target_stack_bytes, 3U * s.target_stack_size);
    RecordProperty("target_stack_bytes", std::to_string(s.target_stack_bytes));
}

INSTANTIATE_TEST_SUITE_P(Boards, ReplaySelfCalibrationQemu, ::testing::ValuesIn(host::kQemuTargets), board_test_name);
#endif

}  // namespace
}  // namespace ascorr::test
