// The command line's inputs and outputs: every output checked
// against every input, never a second correction, empty paths refused, a
// states file with no usable row fails the run, a one-epoch plot window, bounded
// lines in every reader, usage errors before any input is read, one spelling of
// the enumerations, '-' on both sides, and a firmware image checked before the
// emulator starts. Each case is a row of docs/bad-input.md.
#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <string>
#include <vector>

#include "ascorr_host/analysis/fit.hpp"
#include "ascorr_host/analysis/fit_terms.hpp"
#include "ascorr_host/link/qemu_targets.hpp"
#include "cli_run.hpp"
#include "test_support.hpp"

namespace ascorr::test {
namespace {

namespace fs = std::filesystem;

const std::string kSolutions = data_path("solutions.csv");
const std::string kModel = data_path("model_table2.csv");

// ---- every output against every input ---------------------------------------

// A model kept beside simulate's outputs under the name of one of them is an
// input: simulate refuses before reading it, and the file stays as it was.
TEST(CliInputsAndOutputs, SimulateRefusesATruthModelThatIsOneOfItsOwnOutputs) {
    const fs::path dir = scratch_dir("probe-sim-truth");
    for (const std::string suffix : {".heaters.csv", ".truth.csv", ".floor.json", ""}) {
        SCOPED_TRACE(suffix);
        const fs::path truth = dir / ("F" + suffix);
        fs::remove(truth);
        fs::copy_file(kModel, truth);
        const CliRun r = run_in("simulate --days 0.05 --out F --truth F" + suffix, dir);
        EXPECT_EQ(r.exit_code, 1) << r.err;
        EXPECT_TRUE(has(r.err, "is the same file as the input --truth F" + suffix)) << r.err;
        EXPECT_EQ(slurp(truth), slurp(kModel));
        fs::remove(truth);
        for (const std::string other : {".heaters.csv", ".truth.csv", ".floor.json", ""}) {
            EXPECT_FALSE(fs::exists(dir / ("F" + other))) << other;
        }
    }
}

// ---- never a second correction ----------------------------------------------

// stats and plot apply the stages themselves: with a model, a corrected file
// is refused (the thermal stage would be applied twice); stats without a model
// shows it as it is, its one stage under "original", the others null.
TEST(CliInputsAndOutputs, StatsAndPlotNeverCorrectACorrectedFileAgain) {
    const fs::path dir = scratch_dir("probe-twice");
    ASSERT_EQ(run_in("simulate --days 0.2 --out s.csv", dir).exit_code, 0);
    ASSERT_EQ(run_in("correct --in s.csv --model " + kModel + " --out c.csv", dir).exit_code, 0);
    for (const std::string& c :
         {"stats --in c.csv --model " + kModel, "plot --in c.csv --model " + kModel + " --out p.png"}) {
        SCOPED_TRACE(c);
        const CliRun r = run_in(c + " > out.txt", dir);
        EXPECT_EQ(r.exit_code, 1) << r.err;
        EXPECT_TRUE(has(r.err, "c.csv:1:")) << r.err;
        EXPECT_TRUE(has(r.err, "this file is already corrected")) << r.err;
        EXPECT_EQ(slurp(dir / "out.txt"), "");
        EXPECT_FALSE(fs::exists(dir / "p.png"));
    }
    // Without a model: the corrected file's IBA, as stats --model gives it on the raw file.
    ASSERT_EQ(run_in("stats --json --in s.csv --model " + kModel + " > raw.json", dir).exit_code, 0);
    const CliRun r = run_in("stats --json --in c.csv > c.json", dir);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_TRUE(has(r.err, "c.csv: a corrected file (status column): shown as it is")) << r.err;
    const std::string raw = slurp(dir / "raw.json");
    const std::string cor = slurp(dir / "c.json");
    EXPECT_TRUE(has(cor, "\"aberration\": null, \"thermal\": null")) << cor;
    // The first pair's thermal RMS of the raw file is the corrected file's original.
    const auto value = [](const std::string& j, const std::string& key) {
        const std::size_t at = j.find("\"" + key + "\": ");
        return at == std::string::npos ? std::string("absent") : j.substr(at + key.size() + 4, 8);
    };
    EXPECT_EQ(value(cor, "original"), value(raw, "thermal")) << raw << cor;
    EXPECT_NE(value(raw, "original"), value(raw, "thermal"));  // the comparison can fail
    EXPECT_NE(value(cor, "original"), "null, \"a");
}

// ---- empty paths ------------------------------------------------------------

TEST(CliInputsAndOutputs, AnEmptyPathIsAUsageErrorNotNone) {
    const fs::path dir = scratch_dir("probe-empty-path");
    const std::string cmds[] = {
        "correct --in " + kSolutions + " --out o.csv --states ''",
        "correct --in '' --out o.csv",
        "correct --in " + kSolutions + " --out ''",
        "stats --in ''",
        "fit --in '' --out m.csv",
        "fit --in " + kSolutions + " --out ''",
        "plot --in '' --model " + kModel + " --out o.csv",
        "simulate --days 0.01 --out ''",
        "replay --target loopback-float --in '' --model " + kModel + " --out o.csv",
        "replay --target loopback-float --in " + kSolutions + " --model " + kModel + " --out o.csv --states ''",
        "replay --target loopback-float --in " + kSolutions + " --model " + kModel + " --out o.csv --firmware ''",
        "thermistors --config " + std::string(ASCORR_HAL_EXAMPLES) + "/board.cfg --simulate '' > o.csv",
        "thermistors --config " + std::string(ASCORR_HAL_EXAMPLES) + "/board.cfg --replay '' > o.csv",
    };
    for (const std::string& c : cmds) {
        SCOPED_TRACE(c);
        fs::remove(dir / "o.csv");
        const CliRun r = run_in(c, dir);
        EXPECT_EQ(r.exit_code, 2) << r.err;
        EXPECT_TRUE(has(r.err, "an empty path names no file")) << r.err;
        EXPECT_TRUE(has(r.err, "Run with --help")) << r.err;
        EXPECT_TRUE(!fs::exists(dir / "o.csv") || fs::file_size(dir / "o.csv") == 0);
    }
}

// ---- a states file with no usable state -------------------------------------

TEST(CliInputsAndOutputs, AStatesFileWithNoAcceptedStateFailsTheRun) {
    const fs::path dir = scratch_dir("probe-states-none");
    const std::string head = "t,x,y,z,vx,vy,vz\n";
    const std::string metres = head + "447534180.184,6838000,0,0,0,300,7600\n447534190.184,6838000,0,0,0,300,7600\n";
    const std::string backwards = head + "447534190.184,6838,0,0,0,0.3,7.6\n447534180.184,6838,0,0,0,0.3,7.6\n";
    std::ofstream(dir / "metres.csv") << metres;
    std::ofstream(dir / "bad.csv") << head << "447534180.184,6838,abc,0,0,0.3,7.6\n";
    for (const std::string& c :
         {std::string("correct --in ") + kSolutions + " --out o.csv --states metres.csv",
          std::string("correct --in ") + kSolutions + " --out o.csv --states metres.csv --skip-bad",
          std::string("correct --in ") + kSolutions + " --out o.csv --states bad.csv --skip-bad",
          "replay --target loopback-float --in " + kSolutions + " --model " + kModel +
              " --out o.csv --states metres.csv"}) {
        SCOPED_TRACE(c);
        const CliRun r = run_in(c, dir);
        EXPECT_EQ(r.exit_code, 1) << r.err;
        EXPECT_TRUE(has(r.err, "no state of the file is usable")) << r.err;
        EXPECT_FALSE(fs::exists(dir / "o.csv"));
    }
    // One good state: the run succeeds; the summary counts the refused and skipped states;
    // the duplicate's message says once that the first state is kept.
    std::ofstream(dir / "mixed.csv") << head << "447534180.184,6838,0,0,0,0.3,7.6\n"
                                     << "447534180.184,6838,0,0,0,0.3,7.6\n"
                                     << "447534181.184,6838,abc,0,0,0.3,7.6\n"
                                     << "447534170.184,6838,0,0,0,0.3,7.6\n";
    const CliRun ok = run_in("correct --in " + kSolutions + " --out o.csv --states mixed.csv --skip-bad", dir);
    ASSERT_EQ(ok.exit_code, 0) << ok.err;
    EXPECT_TRUE(has(ok.err, "states: 1 accepted, 2 refused, 1 malformed skipped")) << ok.err;
    EXPECT_TRUE(has(ok.err, "mixed.csv:4:20: column 'y'")) << ok.err;
    EXPECT_TRUE(has(ok.err, "same time as the previous accepted state (kept the previous one)")) << ok.err;
    EXPECT_FALSE(has(ok.err, "(the first is kept) (kept")) << ok.err;
    // Without --skip-bad, the malformed states row stops the run.
    fs::remove(dir / "o.csv");
    EXPECT_EQ(run_in("correct --in " + kSolutions + " --out o.csv --states mixed.csv", dir).exit_code, 1);
    EXPECT_FALSE(fs::exists(dir / "o.csv"));
    std::ofstream(dir / "backwards.csv") << backwards;
    EXPECT_EQ(run_in("correct --in " + kSolutions + " --out o.csv --states backwards.csv", dir).exit_code, 0);
}

// ---- usage errors: exit 2, before any input is read, the value as given -------

TEST(CliInputsAndOutputs, RangeErrorsAreUsageErrorsWithTheValueAsGiven) {
    const fs::path dir = scratch_dir("probe-ranges");
    struct Case {
        std::string args;
        std::string message;
    };
    // The inputs do not exist: a usage error must be found before any is read.
    const std::vector<Case> cases{
        {"fit --in none.csv --out m.csv --holdout 0.50000001",
         "--holdout: 0.50000001 is out of range: the range is [0, 0.5]"},
        {"fit --in none.csv --out m.csv --holdout -0", ""},
        {"fit --in none.csv --out m.csv --min-days 0", "--min-days: 0 is out of range"},
        {"fit --in none.csv --out m.csv --min-days 1e-400", "--min-days: 1e-400 is out of range"},
        {"plot --in none.csv --model none.csv --out p.png --width 399", "--width: 399 is out of range"},
        {"simulate --out s.csv --days 36600.000001", "--days: 36600.000001 is out of range: the range is (0, 36600]"},
        {"simulate --out s.csv --days 0", "--days: 0 is out of range"},
        {"correct --in none.csv --out o.csv --max-propagation 604800.5", "--max-propagation: 604800.5 is out of range"},
        {"correct --in none.csv --out o.csv --max-propagation 0", "--max-propagation: 0 is out of range"},
        {"replay --target loopback-float --in none.csv --model none.csv --out o.csv --max-propagation -1",
         "--max-propagation: -1 is out of range"},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.args);
        const CliRun r = run_in(c.args, dir);
        if (c.message.empty()) {  // accepted: the missing input is what stops it
            EXPECT_EQ(r.exit_code, 1) << r.err;
            EXPECT_TRUE(has(r.err, "none.csv")) << r.err;
            continue;
        }
        EXPECT_EQ(r.exit_code, 2) << r.err;
        EXPECT_TRUE(has(r.err, c.message)) << r.err;
        EXPECT_TRUE(has(r.err, "Run with --help")) << r.err;
        EXPECT_FALSE(has(r.err, "none.csv")) << r.err;
    }
    EXPECT_TRUE(fs::is_empty(dir / "") || !fs::exists(dir / "s.csv"));
}

// ---- one spelling of the enumerations ----------------------------------------

TEST(CliInputsAndOutputs, ChoiceOptionsTakeNamesInAnyCaseAndNeverNumbers) {
    const fs::path dir = scratch_dir("probe-choices");
    std::ofstream(dir / "st.csv") << "t,x,y,z,vx,vy,vz\n447534180.184,6838,0,0,0,0.3,7.6\n";
    for (const std::string bad : {"--states-frame 1", "--states-frame 0", "--scalar 2", "--scalar 0", "--scalar dbl"}) {
        SCOPED_TRACE(bad);
        const CliRun r = run_in("correct --in " + kSolutions + " --states st.csv --out o.csv " + bad, dir);
        EXPECT_EQ(r.exit_code, 2) << r.err;
        EXPECT_TRUE(has(r.err, "is not one of {")) << r.err;
        EXPECT_TRUE(has(r.err, "numbers are not names")) << r.err;
        EXPECT_FALSE(fs::exists(dir / "o.csv"));
    }
    for (const std::string bad : {"--terms 1", "--terms 0", "--terms cubic"}) {
        SCOPED_TRACE(bad);
        const CliRun r = run_in("fit --in " + kSolutions + " --out m.csv " + bad, dir);
        EXPECT_EQ(r.exit_code, 2) << r.err;
        EXPECT_TRUE(has(r.err, "is not one of {linear,quadratic}")) << r.err;
    }
    const CliRun speed = run_in(
        "replay --target loopback-float --in " + kSolutions + " --model " + kModel + " --out o.csv --speed 1", dir);
    EXPECT_EQ(speed.exit_code, 2) << speed.err;
    // Names in any case, the same result as in lower case.
    ASSERT_EQ(
        run_in("correct --in " + kSolutions + " --states st.csv --out a.csv --states-frame gcrs --scalar float", dir)
            .exit_code,
        0);
    const CliRun upper =
        run_in("correct --in " + kSolutions + " --states st.csv --out b.csv --states-frame GCRS --scalar Float", dir);
    ASSERT_EQ(upper.exit_code, 0) << upper.err;
    EXPECT_EQ(slurp(dir / "a.csv"), slurp(dir / "b.csv"));
    // The help names the choices, not CLI11's mapping.
    ASSERT_EQ(run_in("correct --help > help.txt", dir).exit_code, 0);
    const std::string h = slurp(dir / "help.txt");
    EXPECT_TRUE(has(h, "--states-frame NAME:{itrf,gcrs}")) << h;
    EXPECT_TRUE(has(h, "--scalar NAME:{double,float,fixed}")) << h;
    EXPECT_FALSE(has(h, "->")) << h;
}

// ---- bounded lines in every reader ---------------------------------------------

// A line beyond 1 MiB is refused with file:line as soon as it is read, in every
// reader; /dev/zero is refused at once (before this, --states /dev/zero read
// until memory ran out). The line just within the limit is read as usual.
TEST(CliInputsAndOutputs, EveryReaderBoundsItsLinesAndNamesFileAndLine) {
    const fs::path dir = scratch_dir("probe-long-lines");
    const std::size_t limit = std::size_t{1} << 20;
    const std::string cfg = std::string(ASCORR_HAL_EXAMPLES) + "/board.cfg";
    const std::string header = "t,chu,qw,qx,qy,qz,t_chu,t_029,t_032,vx,vy,vz,flags,confidence\n";
    std::ofstream(dir / "states.csv") << "t,x,y,z,vx,vy,vz\n" << std::string(limit + 1, ',') << "\n";
    std::ofstream(dir / "solutions.csv") << header << std::string(3 * limit, '9') << "\n";
    std::ofstream(dir / "model.csv") << "chu,axis,c0,c1,c2,c3\n" << std::string(limit + 1, 'x') << "\n";
    std::ofstream(dir / "board.cfg") << slurp(cfg) << "#" << std::string(limit + 1, ' ') << "\n";
    std::ofstream(dir / "history.csv") << "t,t_chu,t_029,t_032\n0,1,2,3\n" << std::string(limit + 1, '1') << "\n";
    std::ofstream(dir / "replay.csv") << "t,x\n" << std::string(limit + 1, '1');  // no line end at all
    std::ofstream(dir / "noise.csv") << "t,pair,iba\n" << std::string(limit + 1, '1') << "\n";
    struct Case {
        std::string args;
        std::string where;
    };
    const std::vector<Case> cases{
        {"correct --in " + kSolutions + " --out o.csv --states states.csv", "states.csv:2: line longer than 1048576"},
        {"correct --in " + kSolutions + " --out o.csv --states /dev/zero", "/dev/zero:1:1: binary data (byte 0x00)"},
        {"correct --in solutions.csv --out o.csv", "solutions.csv:2: line longer than 1048576"},
        {"stats --in solutions.csv", "solutions.csv:2: line longer than 1048576"},
        {"stats --in " + kSolutions + " --noise-iba noise.csv", "noise.csv:2: line longer than 1048576"},
        {"stats --in " + kSolutions + " --noise-iba /dev/zero", "/dev/zero:1: line longer than 1048576"},
        {"replay --target loopback-float --in solutions.csv --model " + kModel + " --out o.csv",
         "solutions.csv:2: line longer than 1048576"},
        {"correct --in " + kSolutions + " --model model.csv --out o.csv", "model.csv:2: line longer than 1048576"},
        {"thermistors --config board.cfg --replay " + std::string(ASCORR_HAL_EXAMPLES) + "/replay.csv", "board.cfg:"},
        // NUL bytes: refused at the first read, as in every reader (text_file.hpp).
        {"thermistors --config /dev/zero", "/dev/zero:1:1: binary data (byte 0x00)"},
        {"thermistors --config " + cfg + " --simulate history.csv", "history.csv:3: line longer than 1048576"},
        {"thermistors --config " + cfg + " --replay replay.csv", "replay.csv:2: line longer than 1048576"},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.args);
        const CliRun r = run_in(c.args + " > stdout.txt", dir);
        EXPECT_EQ(r.exit_code, 1) << r.err;
        EXPECT_TRUE(has(r.err, c.where)) << r.err;
        EXPECT_FALSE(has(r.err, "bad_alloc")) << r.err;
        EXPECT_FALSE(fs::exists(dir / "o.csv"));
    }
    // Just within the limit: read as usual (an unknown column of 1 MiB - 100 bytes, copied).
    std::ofstream(dir / "wide.csv")
        << "note," << header << std::string(limit - 200, 'n') << ","
        << slurp(kSolutions).substr(header.size(), 200).substr(0, slurp(kSolutions).substr(header.size()).find('\n'))
        << "\n";
    const CliRun wide = run_in("correct --in wide.csv --out o.csv", dir);
    EXPECT_EQ(wide.exit_code, 0) << wide.err;
}

// ---- plot: one epoch; reasons said once -------------------------------------------

TEST(CliInputsAndOutputs, PlotDrawsAOneEpochWindowAndSaysEachReasonOnce) {
    const fs::path dir = scratch_dir("probe-plot-one");
    ASSERT_EQ(run_in("simulate --days 0.05 --out s.csv", dir).exit_code, 0);
    // The second epoch of the file (A and B at 60 s), alone in its window: one clean A-B epoch.
    std::ifstream f(dir / "s.csv");
    std::string line;
    std::getline(f, line);
    std::getline(f, line);
    const double t0 = std::stod(line.substr(0, line.find(',')));
    const std::string window =
        " --window-from " + std::to_string(t0 + 59.0) + " --window-to " + std::to_string(t0 + 61.0);
    const CliRun r = run_in("plot --in s.csv --model " + kModel + " --out p.png" + window, dir);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_FALSE(has(r.err, "gnuplot")) << r.err;
    EXPECT_EQ(slurp(dir / "p.png").substr(1, 3), "PNG");
    // Each pair's reason once, on standard error.
    const std::string reason = "s.csv: pair A-C: no clean epochs:";
    ASSERT_TRUE(has(r.err, reason)) << r.err;
    EXPECT_EQ(r.err.find(reason), r.err.rfind(reason)) << r.err;
    // Nothing to plot at all: each reason once, in the error.
    const CliRun none =
        run_in("plot --in s.csv --model " + kModel + " --out q.png --window-from 1e9 --window-to 2e9", dir);
    EXPECT_EQ(none.exit_code, 1);
    const std::string b_c = "pair B-C";
    ASSERT_TRUE(has(none.err, b_c)) << none.err;
    EXPECT_EQ(none.err.find(b_c), none.err.rfind(b_c)) << none.err;
    EXPECT_FALSE(fs::exists(dir / "q.png"));
}

// ---- the fit report: no number where there is none --------------------------------

TEST(CliInputsAndOutputs, TheFitReportSaysNaForAPairWithoutEpochsAndNeverLowerByANegativePercentage) {
    host::Selection s;
    s.holdout = 0.25;
    host::ModelScore m;
    m.in[0] = {1.5, 1.0, 100};
    m.in[1] = {1.25, 1.0, 80};
    m.out[0] = {1.75, 1.0, 30};  // pairs 1 and 2 held out, and pair 2 in the period: no epoch
    s.models.push_back(m);
    s.verdict = "no selection: a pair has no held-out epoch";
    const std::string report = host::describe_selection(s);
    EXPECT_TRUE(has(report, "IBA RMS in the period A-B 1.500 A-C 1.250 B-C n/a; held out A-B 1.750 A-C n/a B-C n/a"))
        << report;
    // A quadratic model worse than the linear one raises the RMS; it does not lower it by -176.91 %.
    const std::string worse = host::selection_verdict(1.0, 2.7691);
    EXPECT_EQ(worse,
              "linear: the quadratic terms raise the held-out IBA RMS (mean over the pairs) by 176.91 %: they "
              "fit noise");
    EXPECT_TRUE(has(host::selection_verdict(1.0, 0.999), "lower the held-out IBA RMS (mean over the pairs) by 0.10 %"));
    EXPECT_TRUE(
        has(host::selection_verdict(1.0, 0.5), "quadratic: its held-out IBA RMS (mean over the pairs) is 50.00 %"));
}

// ---- replay --firmware: the image is checked before the emulator starts -----------

// The 52-byte header of a 32-bit little-endian ELF (the rest of an image does
// not matter to the check).
std::string elf_header(std::uint8_t elf_class, std::uint16_t type, std::uint16_t machine, std::uint32_t entry,
                       std::uint32_t flags) {
    std::string h(52, '\0');
    h[0] = '\x7f';
    h[1] = 'E';
    h[2] = 'L';
    h[3] = 'F';
    h[4] = static_cast<char>(elf_class);
    h[5] = 1;  // little-endian
    h[6] = 1;
    const auto put = [&](std::size_t at, std::uint32_t v, int bytes) {
        for (int i = 0; i < bytes; ++i) {
            h[at + static_cast<std::size_t>(i)] = static_cast<char>((v >> (8 * i)) & 0xFFU);
        }
    };
    put(16, type, 2);
    put(18, machine, 2);
    put(20, 1, 4);
    put(24, entry, 4);
    put(36, flags, 4);
    return h;
}

TEST(CliInputsAndOutputs, ReplayChecksTheFirmwareImageBeforeStartingTheEmulator) {
    const fs::path dir = scratch_dir("probe-firmware");
    const std::uint32_t soft = 0x5000200U;
    const std::uint32_t hard = 0x5000400U;
    std::ofstream(dir / "text.elf") << "not an image\n";
    std::ofstream(dir / "x86.elf", std::ios::binary) << elf_header(1, 2, 3, 0x41, 0);
    std::ofstream(dir / "elf64.elf", std::ios::binary) << elf_header(2, 2, 40, 0x41, soft);
    std::ofstream(dir / "object.elf", std::ios::binary) << elf_header(1, 1, 40, 0x41, soft);
    std::ofstream(dir / "hard.elf", std::ios::binary) << elf_header(1, 2, 40, 0x41, hard);
    std::ofstream(dir / "far.elf", std::ios::binary) << elf_header(1, 2, 40, 0x10000041U, soft);
    struct Case {
        std::string target;
        std::string image;
        std::string why;
    };
    // The boards of toolchain/targets.txt; a hard-float image is refused on one without an FPU.
    std::vector<Case> cases;
    for (const host::QemuTarget& t : host::kQemuTargets) {
        const std::string name(t.replay);
        cases.push_back({name, "text.elf", "not an ELF file"});
        cases.push_back({name, "x86.elf", "ELF machine 3, not ARM (40)"});
        cases.push_back({name, "elf64.elf", "not a 32-bit little-endian ELF"});
        cases.push_back({name, "object.elf", "ELF type 1, not an executable (2)"});
        cases.push_back({name, "far.elf", "entry point 0x10000041 is outside the board's code memory [0, 0x400000)"});
        if (t.cpu.back() != 'f') {
            cases.push_back(
                {name, "hard.elf", "a hard-float image, and the board's cpu (" + std::string(t.cpu) + ") has no FPU"});
        }
    }
    ASSERT_GT(cases.size(), 5U * std::size(host::kQemuTargets));  // a board without an FPU is tested
    for (const Case& c : cases) {
        SCOPED_TRACE(c.image);
        const CliRun r = run_in("replay --target " + c.target + " --firmware " + c.image + " --in " + kSolutions +
                                    " --model " + kModel + " --out o.csv",
                                dir);
        EXPECT_EQ(r.exit_code, 1) << r.err;
        EXPECT_TRUE(has(r.err, "--firmware " + c.image + ": not a link image for --target " + c.target)) << r.err;
        EXPECT_TRUE(has(r.err, c.why)) << r.err;
        EXPECT_FALSE(has(r.err, "closed the link")) << r.err;
        EXPECT_FALSE(has(r.err, "R00=")) << r.err;  // no register dump of QEMU's
        EXPECT_FALSE(fs::exists(dir / "o.csv"));
    }
}

// replay's --max-propagation goes to the target (SERVICE_CONFIG): it is
// accepted, and what it does to the answers is tested in test_replay_states
// (ReplayStates.LoopbackMaxPropagationEqualsCorrect).
TEST(CliInputsAndOutputs, ReplayMaxPropagationIsTheTargetsHorizon) {
    const fs::path dir = scratch_dir("probe-replay-horizon");
    const std::string run = "replay --target loopback-float --in " + kSolutions + " --model " + kModel + " --out o.csv";
    const CliRun other = run_in(run + " --max-propagation 120 > summary.json", dir);
    EXPECT_EQ(other.exit_code, 0) << other.err;
    EXPECT_TRUE(fs::exists(dir / "o.csv"));
    const CliRun bad = run_in(run + " --max-propagation 604801", dir);
    EXPECT_EQ(bad.exit_code, 2) << bad.err;
}

// ---- '-' is a stream on both sides ------------------------------------------------

TEST(CliInputsAndOutputs, DashIsStandardInputAndOutputAndRefusedWhereOneStreamCannotCarryIt) {
    const fs::path dir = scratch_dir("probe-dash");
    // simulate writes eight files: '-' is refused naming why, and nothing is created.
    const CliRun sim = run_in("simulate --days 0.01 --out -", dir);
    EXPECT_EQ(sim.exit_code, 2) << sim.err;
    EXPECT_TRUE(has(sim.err, "simulate writes eight files")) << sim.err;
    EXPECT_TRUE(fs::is_empty(dir) || !fs::exists(dir / "-.truth.csv"));
    EXPECT_FALSE(fs::exists(dir / "-"));
    EXPECT_FALSE(fs::exists(dir / "-.heaters.csv"));
    // Standard output carries fit's report and replay's summary.
    EXPECT_EQ(run_in("fit --in " + kSolutions + " --out -", dir).exit_code, 2);
    EXPECT_EQ(
        run_in("replay --target loopback-float --in " + kSolutions + " --model " + kModel + " --out -", dir).exit_code,
        2);
    // --in - is standard input, in every command that reads it (stats reads the header twice).
    ASSERT_EQ(run_in("correct --in " + kSolutions + " --model " + kModel + " --out ref.csv", dir).exit_code, 0);
    const CliRun c = run_in("correct --in - --model " + kModel + " --out - < " + kSolutions + " > dash.csv", dir);
    ASSERT_EQ(c.exit_code, 0) << c.err;
    EXPECT_EQ(slurp(dir / "dash.csv"), slurp(dir / "ref.csv"));
    ASSERT_EQ(run_in("stats --json --in " + kSolutions + " --model " + kModel + " > s1.json", dir).exit_code, 0);
    const CliRun st = run_shell("cat " + kSolutions + " | " + std::string(ASCORR_EXE) +
                                    " stats --json --in - --model " + kModel + " > " + (dir / "s2.json").string(),
                                dir);
    ASSERT_EQ(st.exit_code, 0) << st.err;
    EXPECT_EQ(slurp(dir / "s2.json"), slurp(dir / "s1.json"));
    EXPECT_FALSE(fs::exists(dir / "-"));
    // One standard input, one input.
    const CliRun two = run_in("correct --in - --model - --out o.csv < " + kSolutions, dir);
    EXPECT_EQ(two.exit_code, 2) << two.err;
    EXPECT_TRUE(has(two.err, "--model -: standard input is already --in")) << two.err;
}

// Every message about standard input names it "standard input", with the
// line and column, never the private copy the readers open (which it named
// before: /tmp/ascorr-stdin-XXXXXX/standard-input:3:15: ...).
TEST(CliInputsAndOutputs, MessagesNameStandardInputNotItsCopy) {
    const fs::path dir = scratch_dir("probe-stdin-names");
    const std::string header = "t,chu,qw,qx,qy,qz,t_chu,t_029,t_032,vx,vy,vz,flags,confidence\n";
    std::ofstream(dir / "bad.csv") << header << "750000000.0,A,0.5,0.5,0.5,0.5,10.0,-8.0,-19.0,1,2,3,0,1.00\n"
                                   << "750000000.0,A,x,0.5,0.5,0.5,10.0,-8.0,-19.0,1,2,3,0,1.00\n";
    std::ofstream(dir / "hot.csv") << header << "750000000.0,A,0.5,0.5,0.5,0.5,1000.25,-8.0,-19.0,1,2,3,0,1.00\n";
    std::ofstream(dir / "m.csv") << "chu,axis,c0,c1,c2,c3\nA,alpha,1e400,0,0,0\nA,beta,0,0,0,0\nA,gamma,0,0,0,0\n";
    std::ofstream(dir / "one.csv") << header << "750000000.0,A,0.5,0.5,0.5,0.5,10.0,-8.0,-19.0,1,2,3,0,1.00\n";
    std::ofstream(dir / "bad.cfg") << "channel name=T1 adc=0 role=t029 a=1e999 b=2 c=3\n";
    const struct {
        std::string args;
        std::string message;
    } cases[] = {
        {"correct --in - --out o.csv < bad.csv", "standard input:3:15: column 'qw': expected a number, got 'x'"},
        {"correct --in - --out o.csv --model " + kModel + " < hot.csv",
         "standard input:2: temperature outside +-"},  // a diagnostic, not an error
        {"correct --in " + kSolutions + " --model - --out o.csv < m.csv", "standard input:2:9: column 'c0': '1e400'"},
        {"stats --in - < bad.csv", "standard input:3:15: column 'qw'"},
        {"fit --in - --out o.csv < one.csv", "standard input: "},
        {"thermistors --config - --head B < bad.cfg", "standard input:1:35: 'a': '1e999' is out of range"},
    };
    for (const auto& c : cases) {
        SCOPED_TRACE(c.args);
        const CliRun r = run_in(c.args, dir);
        EXPECT_NE(r.err.find(c.message), std::string::npos) << r.err;
        EXPECT_EQ(r.err.find("stdin-"), std::string::npos) << r.err;
        EXPECT_EQ(r.err.find("standard-input"), std::string::npos) << r.err;
    }
}

// ---- thermistors: live options, fault windows -------------------------------------

TEST(CliInputsAndOutputs, ThermistorsRefusesLiveOptionsWithAFileAndWarnsOfAFaultOutsideTheHistory) {
    const fs::path dir = scratch_dir("probe-thermistors");
    const std::string cfg = std::string(ASCORR_HAL_EXAMPLES) + "/board.cfg";
    std::ofstream(dir / "history.csv") << "t,t_chu,t_029,t_032\n100,3.2,-9.5,-19.8\n101,3.2,-9.5,-19.8\n";
    for (const std::string& opt : {std::string("--frames 5"), std::string("--interval 2")}) {
        for (const std::string& file :
             {std::string("--simulate history.csv"), "--replay " + std::string(ASCORR_HAL_EXAMPLES) + "/replay.csv"}) {
            SCOPED_TRACE(opt + " " + file);
            const CliRun r = run_in("thermistors --config " + cfg + " " + file + " " + opt + " > out.csv", dir);
            EXPECT_EQ(r.exit_code, 2) << r.err;
            EXPECT_TRUE(has(r.err, "excludes")) << r.err;
        }
    }
    const CliRun in =
        run_in("thermistors --config " + cfg + " --simulate history.csv --inject THT00029:open:100:100.5 > o.csv", dir);
    ASSERT_EQ(in.exit_code, 0) << in.err;
    EXPECT_FALSE(has(in.err, "warning")) << in.err;
    const CliRun out =
        run_in("thermistors --config " + cfg + " --simulate history.csv --inject THT00029:open:5000:6000 > o.csv", dir);
    ASSERT_EQ(out.exit_code, 0) << out.err;
    EXPECT_TRUE(has(out.err,
                    "warning: --inject THT00029:open:5000:6000: its window is outside the history "
                    "history.csv [100, 101] s: it faults nothing"))
        << out.err;
}

// The library's own refusals (the Python module reaches them) repeat the value
// unrounded too.
TEST(CliInputsAndOutputs, LibraryRefusalsRepeatTheValueUnrounded) {
    host::FitOptions o;
    o.holdout = 0.50000001;
    const host::RowSource none = [](const std::function<void(const host::SolutionRecord&)>&) {};
    try {
        host::fit_model(o, none);
        ADD_FAILURE() << "--holdout 0.50000001 accepted";
    } catch (const std::exception& e) {
        EXPECT_TRUE(has(e.what(), "got 0.50000001")) << e.what();
        EXPECT_FALSE(has(e.what(), "0.500000,")) << e.what();
    }
    o.holdout = 0.25;
    o.min_span_days = -1e-7;
    try {
        host::fit_model(o, none);
        ADD_FAILURE() << "--min-days -1e-7 accepted";
    } catch (const std::exception& e) {
        EXPECT_TRUE(has(e.what(), "--min-days -1e-07")) << e.what();
    }
}

}  // namespace
}  // namespace ascorr::test
