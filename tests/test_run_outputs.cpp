// The outputs of one run: committed together or not at all, results on
// standard output checked to the last flush, two outputs onto one stream
// refused, a pipe or FIFO given by path read once, and every output path
// checked before the work. Each case is a row of DEVELOPERS.md's
// bad-input table. Nothing here waits on a clock: `timeout` only guards
// against a hang, it measures nothing.
#include <gtest/gtest.h>

#include <sys/stat.h>
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "cli_run.hpp"
#include "test_support.hpp"

namespace ascorr::test {
namespace {

namespace fs = std::filesystem;

// One simulated day (sim.csv, its truth model sim.csv.truth.csv), made once.
const fs::path& simulated_day() {
    static const fs::path dir = [] {
        const fs::path d = fs::temp_directory_path() / ("ascorr-test-" + std::to_string(::getpid()) + "-io-sim");
        fs::remove_all(d);
        fs::create_directories(d);
        scratch_cleaner().add(d);  // shared by the tests: removed when the program passes
        const CliRun r = run_in("simulate --days 1 --out sim.csv", d);
        EXPECT_EQ(r.exit_code, 0) << r.err;
        return d;
    }();
    return dir;
}

std::string sim() {
    return (simulated_day() / "sim.csv").string();
}
std::string truth() {
    return (simulated_day() / "sim.csv.truth.csv").string();
}

// `ascorr ARGS` through bash (process substitution, pipes) in dir, with a hang
// guard; standard error in dir/stderr.txt.
CliRun bash_in(const std::string& args, const fs::path& dir) {
    const std::string script =
        "set -o pipefail; cd " + dir.string() + " || exit 99; timeout 60 " + std::string(ASCORR_EXE) + " " + args;
    return run_shell("bash -c '" + script + "'", dir);
}

// The names in dir that are temporary outputs (OUT.tmp-PID-XXXXXXXX).
std::vector<std::string> temporaries_in(const fs::path& dir) {
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(dir)) {
        if (has(e.path().filename().string(), ".tmp-")) {
            names.push_back(e.path().filename().string());
        }
    }
    return names;
}

// Files by name with their text (or a part of it).
using Files = std::vector<std::pair<std::string, std::string>>;

// The outputs of a previous run: the corrected file, the history, the combined file.
const Files kPrevious = {{"out.csv", "the previous corrected file\n"},
                         {"history.csv", "the previous history\n"},
                         {"combined.csv", "the previous combined file\n"}};

// Writes each of FILES in DIR.
void write_files(const fs::path& dir, const Files& files) {
    for (const auto& [name, text] : files) {
        write(dir / name, text);
    }
}

// Runs COMMAND (its summary to summary.json) in DIR: refused with exit 1 and
// MESSAGE, each of KEPT holding the text it had.
void expect_nothing_committed(const fs::path& dir, const std::string& command, const std::string& message,
                              const Files& kept) {
    expect_refused(run_in(command + " > summary.json", dir), 1, {message});
    for (const auto& [name, text] : kept) {
        EXPECT_EQ(slurp(dir / name), text) << name;
    }
}

// Runs COMMAND (its summary to summary.json) in DIR: exit 0, each of PARTS in its file.
void expect_committed(const fs::path& dir, const std::string& command, const Files& parts) {
    const CliRun ok = run_in(command + " > summary.json", dir);
    EXPECT_EQ(ok.exit_code, 0) << ok.err;
    for (const auto& [name, part] : parts) {
        EXPECT_TRUE(has(slurp(dir / name), part)) << name;
    }
}

// The corrected file and another output of a run, which are committed together.
struct CommitSet {
    std::string option;        // the other output's option
    std::string file;          // and its file
    Files previous;            // written before the runs
    Files kept_without_other;  // as they were when the other output cannot be written
    Files kept_without_out;    // as they were when --out cannot be written
    Files replaced;            // parts of the files a run that can write both writes
};

// COMMAND in DIR with --out and S's output: neither committed when one of them
// is /dev/full, no temporary left; both replaced when both are writable.
void expect_committed_together(const fs::path& dir, const std::string& command, const CommitSet& s) {
    write_files(dir, s.previous);
    expect_nothing_committed(dir, command + " --out out.csv " + s.option + " /dev/full",
                             s.option + " /dev/full: write failed: No space left on device", s.kept_without_other);
    expect_nothing_committed(dir, command + " --out /dev/full " + s.option + " " + s.file,
                             "--out /dev/full: write failed: No space left on device", s.kept_without_out);
    EXPECT_TRUE(temporaries_in(dir).empty());
    // Control: with all writable, all are replaced.
    expect_committed(dir, command + " --out out.csv " + s.option + " " + s.file, s.replaced);
}

// ---- items 1 and 4: the outputs of one run, together or not at all ----------

// The history to /dev/full: its write fails at the flush, after the corrected
// rows are complete. The corrected file was renamed first and the run said
// nothing of it; now nothing is renamed. And the other way round.
TEST(RunOutputs, AFailedHistoryLeavesTheCorrectedFileAsItWasAndTheOtherWayRound) {
    const fs::path dir = scratch_dir("io-history");
    const std::vector<std::string> commands = {
        "correct --in " + sim() + " --self-calibrate",
        "replay --target loopback-float --in " + sim() + " --self-calibrate",
    };
    for (const std::string& c : commands) {
        SCOPED_TRACE(c);
        expect_committed_together(dir, c,
                                  {"--model-history",
                                   "history.csv",
                                   {kPrevious[0], kPrevious[1]},
                                   {kPrevious[0]},
                                   {kPrevious[1]},
                                   {{"out.csv", ",status\n"}, {"history.csv", "t,version,chu,axis"}}});
    }
}

// simulate's eight files: the heater list cannot be written (a link to
// /dev/full, a stream); the seven others keep the previous run's contents.
// Simulate renamed them one by one, the solutions first.
TEST(RunOutputs, SimulateCommitsItsEightFilesTogether) {
    const fs::path dir = scratch_dir("io-simulate");
    ASSERT_EQ(run_in("simulate --days 0.1 --seed 1 --out s.csv", dir).exit_code, 0);
    const std::vector<std::string> kept = {"s.csv",
                                           "s.csv.truth.csv",
                                           "s.csv.truth-history.csv",
                                           "s.csv.floor.json",
                                           "s.csv.floor-daily.csv",
                                           "s.csv.mountings.csv",
                                           "s.csv.attitude.csv"};
    std::vector<std::string> before;
    for (const std::string& f : kept) {
        before.push_back(slurp(dir / f));
    }
    fs::remove(dir / "s.csv.heaters.csv");
    fs::create_symlink("/dev/full", dir / "s.csv.heaters.csv");
    const CliRun r = run_in("simulate --days 0.1 --seed 2 --truth-change 0.05:" + truth() + " --out s.csv", dir);
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_TRUE(has(r.err, "--out (heater events) s.csv.heaters.csv: write failed")) << r.err;
    for (std::size_t i = 0; i < kept.size(); ++i) {
        EXPECT_EQ(slurp(dir / kept[i]), before[i]) << kept[i];
    }
    EXPECT_TRUE(temporaries_in(dir).empty());
    // Control: the same run with a writable heater list replaces all eight.
    fs::remove(dir / "s.csv.heaters.csv");
    ASSERT_EQ(run_in("simulate --days 0.1 --seed 2 --truth-change 0.05:" + truth() + " --out s.csv", dir).exit_code, 0);
    EXPECT_NE(slurp(dir / "s.csv"), before[0]);
    EXPECT_NE(slurp(dir / "s.csv.truth-history.csv"), before[2]);
}

// correct --combined and replay --combined: the corrected file, the model
// history and the combined file are one set. The combined file to /dev/full
// (its write fails at the flush, after the corrected rows are complete) leaves
// the corrected file and the history as they were; the corrected file to
// /dev/full leaves the combined file as it was. The combined file was written
// and committed on its own, after the corrected file.
TEST(RunOutputs, TheCombinedFileIsCommittedWithTheCorrectedFile) {
    const fs::path dir = scratch_dir("io-combined");
    const std::string m = sim() + ".mountings.csv";
    const std::vector<std::string> commands = {
        "correct --in " + sim() + " --model " + truth() + " --mountings " + m,
        "correct --in " + sim() + " --self-calibrate --model-history history.csv --mountings " + m,
        "replay --target loopback-float --in " + sim() + " --model " + truth() + " --mountings " + m,
    };
    for (const std::string& c : commands) {
        SCOPED_TRACE(c);
        expect_committed_together(dir, c,
                                  {"--combined",
                                   "combined.csv",
                                   kPrevious,
                                   {kPrevious[0], kPrevious[1]},
                                   {kPrevious[2]},
                                   {{"out.csv", ",status\n"}, {"combined.csv", "t,qw,qx,qy,qz,heads"}}});
    }
}

// ---- item 2: results on standard output are written or the run fails --------

TEST(RunOutputs, AResultThatCannotReachStandardOutputFailsTheRun) {
    const fs::path dir = scratch_dir("io-stdout");
    const std::vector<std::string> commands = {
        "stats --in " + sim() + " --json",
        "stats --in " + sim() + " --model " + truth(),
        "replay --target loopback-float --in " + sim() + " --model " + truth() + " --out r.csv",
        "fit --in " + sim() + " --out m.csv --min-days 0.5 --min-orbits 10",
        "correct --in " + sim() + " --out -",
        "thermistors --config " + std::string(ASCORR_HAL_EXAMPLES) + "/board.cfg --replay " +
            std::string(ASCORR_HAL_EXAMPLES) + "/replay.csv",
        "--help",
    };
    for (const std::string& c : commands) {
        SCOPED_TRACE(c);
        const CliRun ok = run_in(c + " > out.txt", dir);
        ASSERT_EQ(ok.exit_code, 0) << ok.err;  // control: the same run into a file
        ASSERT_FALSE(slurp(dir / "out.txt").empty());
        fs::remove(dir / "r.csv");
        fs::remove(dir / "m.csv");
        const CliRun full = run_in(c + " > /dev/full", dir);
        EXPECT_EQ(full.exit_code, 1);
        EXPECT_TRUE(has(full.err, "standard output")) << full.err;
        // With the reason, when the failure is the flush's (thermistors' rows fill the buffer before it).
        EXPECT_TRUE(has(full.err, "write failed: No space left on device") ||
                    (has(c, "thermistors") && has(full.err, "write failed (an earlier write to it failed)")))
            << full.err;
        // The report is one of the run's outputs: the files are not written either.
        EXPECT_FALSE(fs::exists(dir / "r.csv"));
        EXPECT_FALSE(fs::exists(dir / "m.csv"));
    }
    // simulate's report is on standard error: lost, the run fails (no message can be read).
    const std::string simulate = "cd " + dir.string() + " && " + ASCORR_EXE + " simulate --days 0.1 --out s.csv";
    const int rc = std::system((simulate + " 2> /dev/full").c_str());
    EXPECT_TRUE(WIFEXITED(rc) && WEXITSTATUS(rc) == 1) << rc;
}

// ---- item 10: two outputs onto one stream -------------------------------------

TEST(RunOutputs, TwoOutputsOntoOneStreamAreRefused) {
    const fs::path dir = scratch_dir("io-one-stream");
    const std::string self = "correct --in " + sim() + " --self-calibrate ";
    const std::vector<std::string> refused = {
        self + "--out /dev/stdout --model-history /dev/fd/1 | cat > both.csv",
        self + "--out - --model-history /dev/stdout > both.csv",
        "fit --in " + sim() + " --out /dev/stdout --min-days 0.5 --min-orbits 10 | cat > both.csv",
        "replay --target loopback-float --in " + sim() + " --model " + truth() + " --out /dev/fd/1 > both.csv",
        "fit --in " + sim() + " --out both.csv --min-days 0.5 --min-orbits 10 > both.csv",
    };
    for (const std::string& c : refused) {
        SCOPED_TRACE(c);
        const CliRun r = bash_in(c, dir);  // pipefail: a pipeline's status is ascorr's
        EXPECT_EQ(r.exit_code, 1);
        EXPECT_TRUE(has(r.err, " is also ")) << r.err;
        EXPECT_TRUE(has(r.err, "two outputs need two files")) << r.err;
        EXPECT_TRUE(!fs::exists(dir / "both.csv") || fs::file_size(dir / "both.csv") == 0);
        fs::remove(dir / "both.csv");
    }
    // The null device takes any number of outputs.
    const CliRun null = run_in(self + "--out /dev/null --model-history /dev/null", dir);
    EXPECT_EQ(null.exit_code, 0) << null.err;
}

// ---- item 14: a stream given by path is read once --------------------------------

TEST(RunOutputs, APipeOrFifoGivenByPathIsReadOnceLikeStandardInput) {
    const fs::path dir = scratch_dir("io-streams");
    const std::string fit_options = " --min-days 0.5 --min-orbits 10";
    struct Case {
        std::string reference;  // with the regular file IN
        std::string output;     // the file compared
    };
    const std::vector<Case> cases = {
        {"stats --in IN --json > OUT", "OUT"},
        {"stats --in IN --model " + truth() + " > OUT", "OUT"},
        {"correct --in IN --self-calibrate --out OUT --model-history OUT.history", "OUT"},
        {"fit --in IN --out OUT" + fit_options + " > OUT.report", "OUT"},
        {"plot --in IN --model " + truth() + " --out OUT", "OUT"},
        {"correct --in IN --out OUT", "OUT"},
    };
    ASSERT_EQ(::mkfifo((dir / "in.fifo").c_str(), 0644), 0);
    for (const Case& c : cases) {
        SCOPED_TRACE(c.reference);
        const auto with = [&](const std::string& in, const std::string& out) {
            std::string s = c.reference;
            s.replace(s.find("IN"), 2, in);
            for (std::size_t at; (at = s.find("OUT")) != std::string::npos;) {
                s.replace(at, 3, out);
            }
            return s;
        };
        const CliRun ref = bash_in(with(sim(), "ref"), dir);
        ASSERT_EQ(ref.exit_code, 0) << ref.err;
        // The stream's path, and what the shell adds after the command.
        const std::vector<std::pair<std::string, std::string>> streams = {
            {"<(cat " + sim() + ")", ""},                            // a pipe by path (/dev/fd/63)
            {"/dev/stdin", " < <(cat " + sim() + ")"},               // standard input by path, a pipe
            {"in.fifo", " & cat " + sim() + " > in.fifo; wait $!"},  // a named FIFO, its writer in the shell
        };
        for (const auto& [in, after] : streams) {
            SCOPED_TRACE(in);
            fs::remove(dir / "got");
            const std::string cmd = with(in, "got") + after;
            const CliRun r = bash_in(cmd, dir);
            EXPECT_EQ(r.exit_code, 0) << r.err;
            EXPECT_FALSE(has(r.err, "empty file")) << r.err;
            EXPECT_FALSE(has(r.err, "ascorr-stdin-")) << r.err;  // messages name the input as given
            EXPECT_TRUE(slurp(dir / "got") == slurp(dir / "ref"));
            EXPECT_FALSE(slurp(dir / "got").empty());
        }
    }
}

// ---- item 18: every output path checked before the work -------------------------

// The input is malformed at its last row: a run that checked its outputs only
// at the end stopped at that row and never said the output could not be
// written; now the output is named first, before any input is read.
TEST(RunOutputs, AnOutputThatCannotBeWrittenFailsBeforeAnyInputIsRead) {
    const fs::path dir = scratch_dir("io-early");
    std::string text = slurp(sim());
    text += "1.0,A,not-a-number\n";
    write(dir / "bad.csv", text);
    write(dir / "bad-model.csv", "chu,axis,c0\nA,x,nope\n");
    fs::create_directories(dir / "a-folder");
    // The simulated heads' mountings, with and without the sigmas (combine
    // then estimates the noise from --in: it reads it first).
    const std::string m = slurp(sim() + ".mountings.csv");
    write(dir / "m.csv", m);
    std::string without;
    std::istringstream lines(m);
    for (std::string line; std::getline(lines, line);) {
        std::size_t cut = 0;
        for (int field = 0; field < 5 && cut != std::string::npos; ++field) {
            cut = line.find(',', cut == 0 ? 0 : cut + 1);
        }
        without += line.substr(0, cut) + "\n";
    }
    write(dir / "m-without-sigmas.csv", without);
    const std::vector<std::pair<std::string, std::string>> cases = {
        {"correct --in bad.csv --self-calibrate --out ok.csv --model-history no/h.csv", "--model-history no/h.csv"},
        {"correct --in bad.csv --out no/o.csv", "--out no/o.csv"},
        {"correct --in bad.csv --self-calibrate --out ok.csv --model-history a-folder", "--model-history a-folder"},
        {"replay --target loopback-float --in bad.csv --self-calibrate --out no/o.csv", "--out no/o.csv"},
        {"replay --target loopback-float --in bad.csv --self-calibrate --out ok.csv --model-history no/h.csv",
         "--model-history no/h.csv"},
        {"fit --in bad.csv --out no/m.csv", "--out no/m.csv"},
        {"plot --in bad.csv --model bad-model.csv --out no/p.png", "--out no/p.png"},
        {"simulate --days 1 --truth bad-model.csv --out no/s.csv", "--out no/s.csv"},
        {"correct --in bad.csv --out ok.csv --mountings m.csv --combined no/a.csv", "--combined no/a.csv"},
        {"correct --in bad.csv --out no/o.csv --mountings m.csv --combined ok.csv", "--out no/o.csv"},
        {"replay --target loopback-float --in bad.csv --self-calibrate --out ok.csv --mountings m.csv --combined "
         "no/a.csv",
         "--combined no/a.csv"},
        {"combine --in bad.csv --mountings m-without-sigmas.csv --out no/a.csv", "--out no/a.csv"},
        {"align --in bad.csv --mountings m.csv --out no/m.csv", "--out no/m.csv"},
        {"plot --combined bad.csv --truth-attitude bad.csv --window-from 0 --window-to 1 --out no/p.png",
         "--out no/p.png"},
    };
    for (const auto& [c, named] : cases) {
        SCOPED_TRACE(c);
        const CliRun r = run_in(c, dir);
        EXPECT_EQ(r.exit_code, 1);
        EXPECT_TRUE(has(r.err, "ascorr: " + named + ": ")) << r.err;
        EXPECT_FALSE(has(r.err, "bad")) << r.err;  // no input was read
        EXPECT_FALSE(fs::exists(dir / "ok.csv"));
        EXPECT_TRUE(temporaries_in(dir).empty());
    }
}

}  // namespace
}  // namespace ascorr::test
