// Silent wrong results become flagged, and bad options are refused,
// through the `ascorr` executable.
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "ascorr_host/correct/correct_file.hpp"
#include "cli_run.hpp"
#include "test_support.hpp"

namespace ascorr::test {
namespace {

namespace fs = std::filesystem;

// The status column of each row of a corrected file.
std::vector<int> statuses(const fs::path& p) {
    std::ifstream f(p);
    std::vector<int> s;
    std::string line;
    std::getline(f, line);
    while (std::getline(f, line)) {
        s.push_back(std::stoi(line.substr(line.rfind(',') + 1)));
    }
    return s;
}

const std::string kHeader = "t,chu,qw,qx,qy,qz,t_chu,t_029,t_032,vx,vy,vz,flags,confidence\n";
const std::string kRow = "0.5,0.5,0.5,0.5,10.0,-8.0,-19.0";  // after t,chu

// A command line and a message its standard error must hold.
struct ArgsCase {
    std::string args;
    std::string message;
};

TEST(Refusals, ATimeOutsideTheEphemerisIsFlaggedNotCorrected) {
    const fs::path dir = scratch_dir("ephemeris");
    std::ofstream(dir / "in.csv") << kHeader << "750000000.000,A," << kRow << ",1.0,2.0,3.0,0,1.00\n"
                                  << "750000000000.000,A," << kRow << ",1.0,2.0,3.0,0,1.00\n"  // ms, not s
                                  << "-3200000000.000,B," << kRow << ",1.0,2.0,3.0,0,1.00\n";  // before 1900
    const CliRun r = run_in("correct --in in.csv --out out.csv", dir);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(statuses(dir / "out.csv"), (std::vector<int>{1, 4 | 32, 4 | 32}));
    EXPECT_NE(r.err.find("in.csv:3: t = 7.5e+11 s is outside the span of the Earth ephemeris"), std::string::npos)
        << r.err;
    EXPECT_NE(r.err.find("in.csv:4: t = -3.2e+09 s is outside"), std::string::npos) << r.err;
}

TEST(Refusals, ReplayAndCorrectGiveTheSameStatusBits) {
    const fs::path dir = scratch_dir("same-status");
    std::ofstream(dir / "in.csv") << kHeader << "750000000.000,A," << kRow << ",1.0,2.0,3.0,0,1.00\n"
                                  << "750000001.000,A," << kRow << ",1.0,,3.0,0,1.00\n"  // incomplete velocity
                                  << "750000002.000,B," << kRow << ",,,,0,1.00\n"        // none
                                  << "750000000000.000,C," << kRow << ",1.0,2.0,3.0,0,1.00\n";
    const std::string model = data_path("model_table2.csv");
    ASSERT_EQ(run_in("correct --in in.csv --model " + model + " --out c.csv", dir).exit_code, 0);
    const CliRun r = run_in("replay --target loopback-float --in in.csv --model " + model + " --out r.csv", dir);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(statuses(dir / "c.csv"), (std::vector<int>{3, 4 | 32 | 2, 4 | 2, 4 | 32 | 2}));
    EXPECT_EQ(statuses(dir / "r.csv"), statuses(dir / "c.csv"));
    EXPECT_NE(r.err.find("in.csv:3: only 2 of vx,vy,vz given: aberration skipped"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("in.csv:5: t = 7.5e+11 s is outside"), std::string::npos) << r.err;
}

TEST(Refusals, AModelWithAnUnknownColumnIsRefused) {
    const fs::path dir = scratch_dir("model-column");
    std::string text = slurp(data_path("model_table2.csv"));
    const std::size_t nl = text.find('\n');
    std::string header = text.substr(0, nl);
    if (!header.empty() && header.back() == '\r') {
        header.pop_back();
    }
    std::string body;
    std::istringstream rows(text.substr(nl + 1));
    for (std::string l; std::getline(rows, l);) {
        if (!l.empty()) {
            body += l + ",0.001\n";
        }
    }
    std::ofstream(dir / "m.csv") << header << ",c1_2x\n" << body;  // a misspelt quadratic column
    const CliRun r = run_in("correct --in " + data_path("solutions.csv") + " --model m.csv --out out.csv", dir);
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_NE(r.err.find("m.csv:1:" + std::to_string(header.size() + 2) + ": unknown column 'c1_2x'"),
              std::string::npos)
        << r.err;
    EXPECT_FALSE(fs::exists(dir / "out.csv"));
}

TEST(Refusals, AnEmptyModelPathIsRefused) {
    const fs::path dir = scratch_dir("empty-model");
    for (const std::string& c :
         std::vector<std::string>{"correct --in " + data_path("solutions.csv") + " --out out.csv --model ''",
                                  "stats --in " + data_path("solutions.csv") + " --model ''",
                                  "simulate --days 1 --out out.csv --truth ''"}) {
        SCOPED_TRACE(c);
        const CliRun r = run_in(c, dir);
        EXPECT_EQ(r.exit_code, 2);  // a usage error
        EXPECT_NE(r.err.find("an empty path names no file"), std::string::npos) << r.err;
        EXPECT_FALSE(fs::exists(dir / "out.csv"));
    }
}

TEST(Refusals, BadTimeRangesAndThresholdsAreRefused) {
    const fs::path dir = scratch_dir("options");
    const std::string in = data_path("solutions.csv");
    const std::string model = data_path("model_table2.csv");
    const std::vector<ArgsCase> cases = {
        {"stats --in " + in + " --from 5e8 --to 4e8", "is not before --to"},
        {"stats --in " + in + " --from nan", "--from nan: not a finite time"},
        {"plot --in " + in + " --model " + model + " --out p.png --from 5e8 --to 4e8", "is not before --to"},
        {"plot --in " + in + " --model " + model + " --out p.png --from nan --to 4e8", "not a finite time"},
        {"fit --in " + in + " --out m.csv --to nan", "--to nan: not a finite time"},
        {"simulate --days 1 --out s.csv --start nan", "--start nan: the mission must lie within the Earth ephemeris"},
        {"simulate --days 1 --out s.csv --start 1e13", "the mission must lie within the Earth ephemeris"},
    };
    for (const ArgsCase& c : cases) {
        SCOPED_TRACE(c.args);
        const CliRun r = run_in(c.args, dir);
        EXPECT_EQ(r.exit_code, 1);
        EXPECT_NE(r.err.find(c.message), std::string::npos) << r.err;
    }
    // Thresholds out of their range are usage errors (exit 2), the value as given.
    const std::vector<ArgsCase> usage = {
        {"fit --in " + in + " --out m.csv --min-days nan", "--min-days: nan is out of range: the range is (0, inf)"},
        {"fit --in " + in + " --out m.csv --min-days 0", "--min-days: 0 is out of range"},
        {"fit --in " + in + " --out m.csv --min-days -3", "--min-days: -3 is out of range"},
        {"fit --in " + in + " --out m.csv --max-condition nan", "--max-condition: nan is out of range"},
        {"fit --in " + in + " --out m.csv --max-condition -1", "--max-condition: -1 is out of range"},
    };
    for (const ArgsCase& c : usage) {
        SCOPED_TRACE(c.args);
        const CliRun r = run_in(c.args, dir);
        EXPECT_EQ(r.exit_code, 2);
        EXPECT_NE(r.err.find(c.message), std::string::npos) << r.err;
    }
    EXPECT_FALSE(fs::exists(dir / "m.csv"));
    EXPECT_FALSE(fs::exists(dir / "p.png"));
    EXPECT_FALSE(fs::exists(dir / "s.csv"));
}

TEST(Refusals, SkipBadThatDropsEveryRowFails) {
    const fs::path dir = scratch_dir("skip-all");
    std::ofstream(dir / "in.csv") << kHeader << "x,A," << kRow << ",1,2,3,0,1.00\n"
                                  << "750000000.0,A,nope,0.5,0.5,0.5,1,2,3,1,2,3,0,1.00\n";
    const CliRun r = run_in("correct --in in.csv --out out.csv --skip-bad", dir);
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_NE(r.err.find("every one of the 2 data rows is malformed"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir / "out.csv"));
    // One good row left: a success, the bad one reported.
    std::ofstream(dir / "in.csv", std::ios::app) << "750000000.0,A," << kRow << ",1,2,3,0,1.00\n";
    EXPECT_EQ(run_in("correct --in in.csv --out out.csv --skip-bad", dir).exit_code, 0);
}

TEST(Refusals, TheFloorFileIsValidJsonWithNullForEmptyPairs) {
    const fs::path dir = scratch_dir("floor");
    // Three minutes of mission: pair A-B has epochs, A-C and B-C none (C is
    // blinded then), so they have no RMS.
    ASSERT_EQ(run_in("simulate --days 0.002 --step 60 --out s.csv", dir).exit_code, 0);
    const std::string json = slurp(dir / "s.csv.floor.json");
    EXPECT_NE(json.find("\"A-C\": {\"rms\": null, \"rms_200s\": null, \"n\": 0}"), std::string::npos) << json;
    EXPECT_NE(json.find("\"A-B\": {\"rms\": 1."), std::string::npos) << json;
    EXPECT_EQ(json.find("nan"), std::string::npos) << json;
}

TEST(Refusals, AUtf8ByteOrderMarkIsAcceptedByEveryReader) {
    const fs::path dir = scratch_dir("bom");
    const std::string bom = "\xEF\xBB\xBF";
    std::ofstream(dir / "s.csv", std::ios::binary) << bom << slurp(data_path("solutions.csv"));
    std::ofstream(dir / "m.csv", std::ios::binary) << bom << slurp(data_path("model_table2.csv"));
    const std::string ex = ASCORR_HAL_EXAMPLES;
    std::ofstream(dir / "board.cfg", std::ios::binary) << bom << slurp(ex + "/board.cfg");
    std::ofstream(dir / "rec.csv", std::ios::binary) << bom << slurp(ex + "/replay.csv");
    const std::string model = data_path("model_table2.csv");
    ASSERT_EQ(
        run_in("correct --in " + data_path("solutions.csv") + " --model " + model + " --out ref.csv", dir).exit_code,
        0);
    const CliRun r = run_in("correct --in s.csv --model m.csv --out bom.csv", dir);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(slurp(dir / "bom.csv"), slurp(dir / "ref.csv"));  // the mark is not copied into the output
    ASSERT_EQ(
        run_in("thermistors --config " + ex + "/board.cfg --replay " + ex + "/replay.csv > t_ref.csv", dir).exit_code,
        0);
    const CliRun t = run_in("thermistors --config board.cfg --replay rec.csv > t_bom.csv", dir);
    ASSERT_EQ(t.exit_code, 0) << t.err;
    EXPECT_EQ(slurp(dir / "t_bom.csv"), slurp(dir / "t_ref.csv"));
}

TEST(Refusals, MessagesNameDirectoriesAndCrOnlyLineEndsAndNeverLineZero) {
    const fs::path dir = scratch_dir("messages");
    fs::create_directories(dir / "d");
    const CliRun r = run_in("correct --in d --out out.csv", dir);
    expect_refused(r, 1, {"cannot open d: is a directory, not a file"});
    EXPECT_EQ(r.err.find(":0"), std::string::npos) << r.err;
    expect_refused(run_in("correct --in missing.csv --out out.csv", dir), 1,
                   {"cannot open missing.csv: No such file or directory"});
    std::string text = slurp(data_path("solutions.csv"));
    for (char& c : text) {
        c = c == '\n' ? '\r' : c;
    }
    std::ofstream(dir / "mac.csv", std::ios::binary) << text;
    expect_refused(run_in("correct --in mac.csv --out out.csv", dir), 1, {"mac.csv:1:", "CR-only line ends"});
    EXPECT_FALSE(fs::exists(dir / "out.csv"));
}

// One reader of files (ascorr_text/text_file.hpp): a NUL byte is refused at
// its line and column with an escaped excerpt, in the host's block reader
// (solutions), its whole-file reader (model) and the HAL's (board
// configuration) alike; before, the host said "binary data (NUL byte) in a
// text file" without a column.
TEST(Refusals, ANulByteIsRefusedAtItsLineAndColumnByEveryReader) {
    const fs::path dir = scratch_dir("nul");
    const auto with_nul = [&](const std::string& from, const std::string& name) {
        std::string text = slurp(from);
        const std::size_t line3 = text.find('\n', text.find('\n') + 1) + 1;  // the third line's first byte
        text.insert(line3 + 2, 1, '\0');
        std::ofstream(dir / name, std::ios::binary) << text;
    };
    with_nul(data_path("solutions.csv"), "s.csv");
    with_nul(data_path("model_table2.csv"), "m.csv");
    const std::string ex = ASCORR_HAL_EXAMPLES;
    with_nul(ex + "/board.cfg", "board.cfg");
    const std::string nul = "binary data (byte 0x00): not a text file, line starts";
    expect_refused(run_in("correct --in s.csv --out out.csv", dir), 1, {"s.csv:3:3: " + nul});
    expect_refused(run_in("correct --in " + data_path("solutions.csv") + " --model m.csv --out out.csv", dir), 1,
                   {"m.csv:3:3: " + nul});
    expect_refused(run_in("thermistors --config board.cfg --replay " + ex + "/replay.csv", dir), 1,
                   {"board.cfg:3:3: " + nul});
    EXPECT_FALSE(fs::exists(dir / "out.csv"));
}

// A seed is an unsigned 64-bit integer, in decimal. On
// ed4f56e `--seed -1` ran with seed 2^64 − 1, `--seed 99999999999999999999`
// with 2^64 − 1 and `--seed 010` with 8 (CLI11 reads base 0), all silently.
TEST(Refusals, OutOfRangeSeedsAreRefusedNamingTheOptionAndTheRange) {
    const fs::path dir = scratch_dir("seeds");
    const std::string range = "expected an integer in [0, 18446744073709551615]";
    struct Case {
        std::string seed;
        std::string message;
    };
    const std::vector<Case> cases = {
        {"-1", "--seed: -1 is out of range: " + range},
        {"18446744073709551616", "--seed: 18446744073709551616 is out of range: " + range},
        {"99999999999999999999", "is out of range: " + range},
        {"1e999", "--seed: 1e999 is out of range: " + range},
        {"1.5", "--seed: 1.5 is not an integer (decimal digits only): " + range},
        {"nan", "--seed: nan is not an integer: " + range},
        {"0x10", "--seed: 0x10 is not a number: " + range},
    };
    const std::string in = data_path("solutions.csv");
    const std::string model = data_path("model_table2.csv");
    for (const Case& c : cases) {
        for (const std::string& cmd :
             {"simulate --days 0.01 --out s.csv --seed=" + c.seed,
              "replay --target loopback-float --in " + in + " --model " + model + " --out r.csv --seed=" + c.seed}) {
            SCOPED_TRACE(cmd);
            const CliRun r = run_in(cmd, dir);
            EXPECT_EQ(r.exit_code, 2);  // a usage error, before anything is read or written
            EXPECT_NE(r.err.find(c.message), std::string::npos) << r.err;
        }
    }
    EXPECT_FALSE(fs::exists(dir / "s.csv"));
    EXPECT_FALSE(fs::exists(dir / "r.csv"));
    // The largest seed is accepted, and a leading zero is decimal: 010 is 10, not 8.
    ASSERT_EQ(run_in("simulate --days 0.01 --out max.csv --seed 18446744073709551615", dir).exit_code, 0);
    ASSERT_EQ(run_in("simulate --days 0.01 --out ten.csv --seed 10", dir).exit_code, 0);
    ASSERT_EQ(run_in("simulate --days 0.01 --out ten0.csv --seed 010", dir).exit_code, 0);
    ASSERT_EQ(run_in("simulate --days 0.01 --out eight.csv --seed 8", dir).exit_code, 0);
    EXPECT_EQ(slurp(dir / "ten0.csv"), slurp(dir / "ten.csv"));
    EXPECT_NE(slurp(dir / "ten0.csv"), slurp(dir / "eight.csv"));  // mutation check: seeds do change the file
}

// A refused value is printed as number_text prints it: the shortest text
// that reads back as the value, never rounded to six decimals (std::to_string
// printed 0.500000 and 0.000000 and a 1e300 with 300 digits).
TEST(Refusals, RefusedValuesArePrintedExactly) {
    const fs::path dir = scratch_dir("refused-values");
    // One clean epoch of A, B and C at 0.5 km/s and one at 1.0000001e-7 km/s:
    // no Earth orbit. The earliest row, on line 2, is the slow one.
    std::ofstream f(dir / "slow.csv");
    f << kHeader;
    for (const char* head : {"A", "B", "C"}) {
        f << "750000000.0," << head << "," << kRow << ",1.0000001e-7,0,0,0,1.00\n";
    }
    for (const char* head : {"A", "B", "C"}) {
        f << "750000001.0," << head << "," << kRow << ",0.5,0,0,0,1.00\n";
    }
    f.close();
    std::ofstream(dir / "hot.csv") << kHeader
                                   << "750000000.0,A,0.5,0.5,0.5,0.5,1000.123456789,-8.0,-19.0,1,2,3,0,1.00\n";
    std::ofstream(dir / "m.csv") << "chu,axis,c0,c1,c2,c3\n"
                                 << "A,alpha,0,0,0,0\nA,beta,0,1.23456789e9,0,0\nA,gamma,0,0,0,0\n";
    const std::string in = data_path("solutions.csv");
    const struct {
        std::string args;
        std::string message;
    } cases[] = {
        // (self-calibration: the median of the six speeds, the third slow row's, and the set disagrees)
        {"correct --in slow.csv --out o.csv --self-calibrate",
         "slow.csv:4:1: the spacecraft speeds of the first 6 rows the self-calibration learns from disagree: 3 are "
         "within 1 % of their median 1.0000001e-07 km/s"},
        {"fit --in slow.csv --out o.csv",
         "slow.csv:2:1: spacecraft speed 1.0000001e-07 km/s is not that of an Earth orbit"},
        {"correct --scalar fixed --in " + in + " --model m.csv --out o.csv",
         "m.csv:3:10: A beta c1 = 1234567890 arcsec/degC is beyond the fixed-point coefficient range (|c1| < "},
        // A diagnostic (the row is kept, exit 0), with the temperatures as given.
        {"correct --in hot.csv --model m.csv --out hot-out.csv", "hot.csv:2: temperature outside +-"},
        {"correct --in hot.csv --model m.csv --out hot-out.csv", "(t_chu=1000.123456789, t_029=-8, t_032=-19)"},
    };
    for (const auto& c : cases) {
        SCOPED_TRACE(c.args);
        const CliRun r = run_in(c.args, dir);
        EXPECT_EQ(r.exit_code == 0, c.args.find("hot-out.csv") != std::string::npos) << r.err;
        EXPECT_NE(r.err.find(c.message), std::string::npos) << r.err;
    }
    EXPECT_FALSE(fs::exists(dir / "o.csv"));
    // The library's own check of the time constant (the command line's option
    // refuses it first, with the text as given).
    for (const auto& [days, text] : {std::pair<double, const char*>{0.123456789, "got 0.123456789"},
                                     std::pair<double, const char*>{1e300, "got 1e+300"}}) {
        host::CorrectOptions opt;
        opt.in = in;
        opt.out = (dir / "o.csv").string();
        opt.self_calibrate = true;
        opt.time_constant_days = days;
        std::ostringstream log;
        try {
            host::correct_file(opt, log);
            ADD_FAILURE() << days << " accepted";
        } catch (const std::runtime_error& e) {
            EXPECT_NE(std::string(e.what()).find(std::string("--time-constant must be in [1, 10000] days, ") + text),
                      std::string::npos)
                << e.what();
        }
    }
    EXPECT_FALSE(fs::exists(dir / "o.csv"));
}

// A number that is a number but beyond its range says "out of
// range" and gives the range, in options and in every CSV reader (on ed4f56e:
// "expected a number", "Could not convert", or 1e999 taken as infinity).
TEST(Refusals, OutOfRangeNumbersSayOutOfRangeWithTheRange) {
    const fs::path dir = scratch_dir("out-of-range");
    const std::string in = data_path("solutions.csv");
    const std::string model = data_path("model_table2.csv");
    struct Case {
        std::string args;
        int exit_code;
        std::string message;
    };
    // Files with one field beyond range.
    std::ofstream(dir / "big_q.csv") << kHeader << "750000000.0,A,1e999,0.5,0.5,0.5,10.0,-8.0,-19.0,1,2,3,0,1.00\n";
    std::ofstream(dir / "tiny_v.csv") << kHeader << "750000000.0,A," << kRow << ",1e-999,2,3,0,1.00\n";
    std::ofstream(dir / "flags.csv") << kHeader << "750000000.0,A," << kRow << ",1,2,3,-1,1.00\n";
    std::ofstream(dir / "flags64.csv") << kHeader << "750000000.0,A," << kRow << ",1,2,3,99999999999999999999,1.00\n";
    std::ofstream(dir / "m.csv") << "chu,axis,c0,c1,c2,c3\nA,alpha,1e400,0,0,0\nA,beta,0,0,0,0\nA,gamma,0,0,0,0\n";
    std::ofstream(dir / "states.csv") << "t,x,y,z,vx,vy,vz\n750000000.0,7000,0,0,0,7.5,1e999\n";
    const std::string flags_range = "expected an integer in [0, 9223372036854775807]";
    const std::string replay = "replay --target loopback-float --in " + in + " --model " + model + " --out o.csv";
    const std::string thermistors = "thermistors --config " + std::string(ASCORR_HAL_EXAMPLES) + "/board.cfg";
    const std::vector<Case> cases = {
        {"correct --in big_q.csv --out o.csv", 1,
         "big_q.csv:2:15: column 'qw': '1e999' is out of range: a number's magnitude is at most 1.797693e+308"},
        {"correct --in tiny_v.csv --out o.csv", 1,
         "column 'vx': '1e-999' is out of range: a nonzero number's magnitude is at least 4.940656e-324"},
        {"correct --in flags.csv --out o.csv", 1, "column 'flags': '-1' is out of range: " + flags_range},
        {"correct --in flags64.csv --out o.csv", 1,
         "column 'flags': '99999999999999999999' is out of range: " + flags_range},
        {"correct --in " + in + " --model m.csv --out o.csv", 1,
         "m.csv:2:9: column 'c0': '1e400' is out of range: a number's magnitude is at most 1.797693e+308"},
        {"correct --in " + in + " --states states.csv --out o.csv", 1,
         "states.csv:2:28: column 'vz': '1e999' is out of range"},
        {"simulate --out o.csv --days 1e999", 2, "--days: 1e999 is out of range: a number's magnitude is at most"},
        {"stats --in " + in + " --from -1e999", 2, "--from: -1e999 is out of range"},
        {"fit --in " + in + " --out o.csv --min-orbits 99999999999999999999", 2,
         "--min-orbits: 99999999999999999999 is out of range: expected an integer in [0, 18446744073709551615]"},
        {"fit --in " + in + " --out o.csv --holdout 1e-400", 2, "--holdout: 1e-400 is out of range"},
        {"plot --in " + in + " --model " + model + " --out o.csv --width 3000000000", 2,
         "--width: 3000000000 is out of range: expected an integer in [400, 4000]"},
        {replay + " --timeout-ms 0", 2, "--timeout-ms: 0 is out of range: expected an integer in [1, 60000]"},
        {thermistors + " --frames 0 --head B", 2, "--frames: 0 is out of range: expected an integer in [1, 1000000]"},
        {thermistors + " --head 7", 2, "--head: 7 is out of range: a head is A, B, C or D"},
        // NaN is out of every range (CLI::Range let it through: --inject-errors nan injected nothing).
        {replay + " --inject-errors nan", 2, "--inject-errors: nan is out of range: the range is [0, 0.5]"},
        {replay + " --inject-errors 0.6", 2, "--inject-errors: 0.6 is out of range: the range is [0, 0.5]"},
        {thermistors + " --interval nan", 2, "--interval: nan is out of range: the range is [0, 3600]"},
        // Text that is no number still says so.
        {"simulate --out o.csv --days ten", 2, "--days: ten is not a number"},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.args);
        const CliRun r = run_in(c.args, dir);
        expect_refused(r, c.exit_code, {c.message});
        EXPECT_EQ(r.err.find("expected a number"), std::string::npos) << r.err;
    }
    EXPECT_FALSE(fs::exists(dir / "o.csv"));
    // A '+' before flags is a sign, as before a real field (it said "'+0' is
    // out of range" before); "+-1" and "+" stay malformed.
    std::ofstream(dir / "plus.csv") << kHeader << "750000000.0,A," << kRow << ",1,2,3,+0,1.00\n";
    const CliRun plus = run_in("correct --in plus.csv --out o.csv", dir);
    EXPECT_EQ(plus.exit_code, 0) << plus.err;
    for (const char* bad : {"+-1", "+"}) {
        std::ofstream(dir / "plus_bad.csv") << kHeader << "750000000.0,A," << kRow << ",1,2,3," << bad << ",1.00\n";
        const CliRun r = run_in("correct --in plus_bad.csv --out o2.csv", dir);
        EXPECT_EQ(r.exit_code, 1) << bad;
        EXPECT_EQ(r.err.find("out of range"), std::string::npos) << r.err;
    }
}

// A model beyond a range names file:line:column and its
// numbers in %g (on ed4f56e: "m.csv: A beta c1 = 1000000000.000000 is beyond
// the fixed-point coefficient range (+-...)" without a line, and a truth model
// beyond 1 degree named neither file nor line).
TEST(Refusals, ModelRangeErrorsNameFileLineAndColumnWithNumbersInG) {
    const fs::path dir = scratch_dir("model-range");
    const std::string in = data_path("solutions.csv");
    std::ofstream(dir / "m.csv") << "chu,axis,c0,c1,c2,c3\n"
                                 << "A,alpha,0,0,0,0\nA,beta,0,1e9,0,0\nA,gamma,0,0,0,0\n";
    {
        const CliRun r = run_in("correct --scalar fixed --in " + in + " --model m.csv --out o.csv", dir);
        EXPECT_EQ(r.exit_code, 1);
        // Line 3 (A beta), column 10 (c1); the value and the limit in %g.
        EXPECT_NE(r.err.find("m.csv:3:10: A beta c1 = 1e+09 arcsec/degC is beyond the fixed-point coefficient range "
                             "(|c1| < "),
                  std::string::npos)
            << r.err;
        EXPECT_EQ(r.err.find("000000 "), std::string::npos) << r.err;  // no %f padding
    }
    std::ofstream(dir / "q.csv") << "chu,axis,c0,c1,c2,c3,c1_2,c2_2,c3_2\n"
                                 << "B,alpha,0,0,0,0,0,0,0\nB,beta,0,0,0,0,0,0,0\nB,gamma,0,0,0,0,0,0,-2.5e11\n";
    expect_refused(run_in("correct --scalar fixed --in " + in + " --model q.csv --out o.csv", dir), 1,
                   {"q.csv:4:21: B gamma c3_2 = -2.5e+11 arcsec/degC^2 is beyond"});
    // A truth model whose angle exceeds the core's 1-degree domain: the file and
    // the line of the axis beyond it, with the angle, the epoch and the
    // temperatures.
    std::ofstream(dir / "t.csv") << "chu,axis,c0,c1,c2,c3\n"
                                 << "A,alpha,0,0,0,0\nA,beta,0,0,0,0\nA,gamma,0,0,0,0\n"
                                 << "B,alpha,0,0,0,0\nB,beta,0,0,0,0\nB,gamma,0,0,0,0\n"
                                 << "C,alpha,0,0,0,0\nC,beta,3500,100,0,0\nC,gamma,0,0,0,0\n";
    expect_refused(run_in("simulate --days 0.01 --truth t.csv --out s.csv", dir), 1,
                   {"t.csv:9: CHU C beta: the truth model gives ", " degrees, beyond 1 degree, at t = ", "degC)"});
    expect_absent(dir, {"o.csv", "s.csv"});
}

// RFC 4180 quoting in columns ascorr ignores is accepted
// and copied verbatim (on ed4f56e a comma inside quotes split the field: "expected
// 15 fields as in the header, found 16"); in a column it reads it is refused,
// naming the column; a line break inside quotes is refused as unterminated.
TEST(Refusals, QuotedFieldsInIgnoredColumnsAreAcceptedAndCopiedVerbatim) {
    const fs::path dir = scratch_dir("quoted");
    const std::string header = "t,chu,qw,qx,qy,qz,t_chu,t_029,t_032,vx,vy,vz,flags,confidence,\"note, free text\"\n";
    const std::string row1 = "750000000.0,A," + kRow + ",1,2,3,0,1.00,";
    const std::string row2 = "750000001.0,B," + kRow + ",1,2,3,0,1.00,";
    std::ofstream(dir / "in.csv") << header << row1 << "\"a, \"\"quoted\"\" note\"\n" << row2 << "\"\"\n";
    std::ofstream(dir / "plain.csv") << kHeader << "750000000.0,A," << kRow << ",1,2,3,0,1.00\n"
                                     << "750000001.0,B," << kRow << ",1,2,3,0,1.00\n";
    const std::string model = data_path("model_table2.csv");
    const CliRun r = run_in("correct --in in.csv --model " + model + " --out out.csv", dir);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    ASSERT_EQ(run_in("correct --in plain.csv --model " + model + " --out plain_out.csv", dir).exit_code, 0);
    // Every line of the output: the plain file's, plus the note column as written.
    std::istringstream quoted(slurp(dir / "out.csv"));
    std::istringstream plain(slurp(dir / "plain_out.csv"));
    const std::vector<std::string> notes = {"\"note, free text\"", "\"a, \"\"quoted\"\" note\"", "\"\""};
    std::string q;
    std::string p;
    for (const std::string& note : notes) {
        ASSERT_TRUE(std::getline(quoted, q));
        ASSERT_TRUE(std::getline(plain, p));
        const std::size_t cut = p.rfind(',');  // before status
        EXPECT_EQ(q, p.substr(0, cut) + "," + note + p.substr(cut));
    }
    // stats reads the same file.
    EXPECT_EQ(run_in("stats --in in.csv > stats.txt", dir).exit_code, 0);

    // Quoted fields in columns that are read: refused, naming the column.
    struct Case {
        std::string file;
        std::string text;
        std::string message;
    };
    const std::vector<Case> cases = {
        {"qw.csv", kHeader + "750000000.0,A,\"0.5\",0.5,0.5,0.5,10,-8,-19,1,2,3,0,1.00\n",
         "qw.csv:2:15: column 'qw': \"0.5\" is a quoted field in a column ascorr reads"},
        {"chu.csv", kHeader + "750000000.0,\"A\"," + kRow + ",1,2,3,0,1.00\n",
         "chu.csv:2:13: column 'chu': \"A\" is a quoted field in a column ascorr reads"},
        {"flags.csv", kHeader + "750000000.0,A," + kRow + ",1,2,3,\"0\",1.00\n",
         "column 'flags': \"0\" is a quoted field in a column ascorr reads"},
        {"open.csv", header + row1 + "\"a note that goes on\nto the next line\"\n",
         "open.csv:2:60: quoted field without its closing quote (a line break inside quotes is not supported"},
        {"after.csv", header + row1 + "\"a\"b\n", "after.csv:2:63: text after the closing quote"},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.file);
        std::ofstream(dir / c.file) << c.text;
        const CliRun e = run_in("correct --in " + c.file + " --out bad.csv", dir);
        EXPECT_EQ(e.exit_code, 1);
        EXPECT_NE(e.err.find(c.message), std::string::npos) << e.err;
    }
    std::ofstream(dir / "m.csv") << "chu,axis,c0,c1,c2,c3\nA,alpha,\"1\",0,0,0\nA,beta,0,0,0,0\nA,gamma,0,0,0,0\n";
    const CliRun m = run_in("correct --in plain.csv --model m.csv --out bad.csv", dir);
    EXPECT_EQ(m.exit_code, 1);
    EXPECT_NE(m.err.find("m.csv:2:9: column 'c0': \"1\" is a quoted field"), std::string::npos) << m.err;
    EXPECT_FALSE(fs::exists(dir / "bad.csv"));
}

// Rows of heads A, B and C at n epochs 10 s apart; C's rows get c_flags and
// c_dt seconds added to their time.
std::string three_heads(int n, int c_flags, double c_dt) {
    std::ostringstream s;
    s << kHeader;
    for (int i = 0; i < n; ++i) {
        const double t = 750000000.0 + 10.0 * i;
        for (const char h : {'A', 'B', 'C'}) {
            s.precision(15);
            s << (h == 'C' ? t + c_dt : t) << ',' << h << ',' << kRow << ",1,2,3," << (h == 'C' ? c_flags : 0)
              << ",1.00\n";
        }
    }
    return s.str();
}

// `stats` and `plot` say why a pair has no epochs, and
// `plot` draws the pairs it has (on ed4f56e: stats printed "0" and "-" without
// a reason; plot failed with "no clean epoch for pair A-C: nothing to plot").
TEST(Refusals, StatsAndPlotSayWhyAPairHasNoEpochsAndPlotDrawsTheOthers) {
    const fs::path dir = scratch_dir("no-epochs");
    std::ofstream(dir / "flagged.csv") << three_heads(6, 2, 0.0);
    std::ofstream(dir / "shifted.csv") << three_heads(6, 0, 0.5);
    std::string no_c = three_heads(6, 0, 0.0);
    std::string kept;
    std::istringstream lines(no_c);
    for (std::string l; std::getline(lines, l);) {
        if (l.find(",C,") == std::string::npos) {
            kept += l + "\n";
        }
    }
    std::ofstream(dir / "no_c.csv") << kept;
    struct Case {
        std::string args;
        std::vector<std::string> messages;
    };
    const std::vector<Case> cases = {
        {"stats --in flagged.csv",
         {"flagged.csv: pair A-C: no clean epochs: none of CHU C's 6 rows is clean (6 flags set)",
          "flagged.csv: pair B-C: no clean epochs: none of CHU C's 6 rows is clean (6 flags set)"}},
        {"stats --in shifted.csv",
         {"pair A-C: no clean epochs: CHU A and CHU C never have a row at the same epoch (t to the millisecond)",
          "pair B-C: no clean epochs: CHU B and CHU C never have a row at the same epoch"}},
        {"stats --in no_c.csv", {"pair A-C: no clean epochs: CHU C has no rows", "pair B-C: no clean epochs: CHU C"}},
        {"stats --in flagged.csv --from 1e9 --to 2e9",
         {"pair A-B: no clean epochs: no rows in [1000000000, 2000000000] s (--from/--to) (the file has 18)"}},
        {"stats --in no_c.csv --to 750000020",
         {"pair A-C: no clean epochs: CHU C has no rows in [-inf, 750000020] s (--from/--to)"}},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.args);
        const CliRun r = run_in(c.args + " > table.txt", dir);
        EXPECT_EQ(r.exit_code, 0) << r.err;
        for (const std::string& m : c.messages) {
            EXPECT_NE(r.err.find(m), std::string::npos) << r.err;
        }
    }
    // Pair A-B has epochs: no reason is given for it.
    EXPECT_EQ(run_in("stats --in flagged.csv > table.txt", dir).err.find("pair A-B"), std::string::npos);

    // plot draws A-B and says why A-C and B-C are empty.
    const std::string model = data_path("model_table2.csv");
    const CliRun p = run_in("plot --in flagged.csv --model " + model + " --out p.png", dir);
    ASSERT_EQ(p.exit_code, 0) << p.err;
    EXPECT_NE(p.err.find("pair A-C: no clean epochs: none of CHU C's 6 rows is clean (6 flags set)"), std::string::npos)
        << p.err;
    EXPECT_EQ(slurp(dir / "p.png").substr(1, 3), "PNG");
    // With no pair at all there is nothing to plot: the reasons, exit 1, no figure.
    const CliRun w =
        run_in("plot --in flagged.csv --model " + model + " --out q.png --window-from 1e9 --window-to 2e9", dir);
    EXPECT_EQ(w.exit_code, 1);
    EXPECT_NE(w.err.find("nothing to plot"), std::string::npos) << w.err;
    EXPECT_NE(w.err.find("no clean epoch for pair B-C in the window: no rows in [1000000000, 2000000000] s "
                         "(--window-from/--window-to)"),
              std::string::npos)
        << w.err;
}

}  // namespace
}  // namespace ascorr::test
