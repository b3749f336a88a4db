// The host tools never destroy data: an output that
// is an input is refused before anything is read; outputs that are not regular
// files are written as streams; links and permissions are kept; a corrected
// file is not corrected again; a run ended by a signal leaves no temporary
// output, no temporary folder and no child process behind.
//
// Signals are sent when the run is provably mid-way (the temporary file, or a
// stand-in child's marker, exists), never after a wall-clock delay.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "ascorr_host/link/qemu_targets.hpp"
#include "cli_run.hpp"
#include "test_support.hpp"

namespace ascorr::test {
namespace {

namespace fs = std::filesystem;

// Starts ascorr with argv, PATH prefixed by path_prefix (stand-in programs),
// TMPDIR set when tmpdir is not empty; stdout and stderr to files in dir.
pid_t spawn(const std::vector<std::string>& args, const fs::path& dir, const std::string& path_prefix = "",
            const std::string& tmpdir = "") {
    const pid_t pid = ::fork();
    if (pid == 0) {
        ::signal(SIGPIPE, SIG_DFL);  // the test ignores it; the tool must not inherit that
        if (!path_prefix.empty()) {
            const char* old = std::getenv("PATH");
            ::setenv("PATH", (path_prefix + ":" + (old ? old : "/usr/bin:/bin")).c_str(), 1);
        }
        if (!tmpdir.empty()) {
            ::setenv("TMPDIR", tmpdir.c_str(), 1);
        }
        const int out = ::open((dir / "stdout.txt").c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
        const int err = ::open((dir / "stderr.txt").c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
        ::dup2(out, STDOUT_FILENO);
        ::dup2(err, STDERR_FILENO);
        std::vector<char*> argv{const_cast<char*>(ASCORR_EXE)};
        for (const auto& a : args) {
            argv.push_back(const_cast<char*>(a.c_str()));
        }
        argv.push_back(nullptr);
        ::execv(ASCORR_EXE, argv.data());
        ::_exit(127);
    }
    return pid;
}

// Waits (bounded: 60 s, a hang guard, not a measurement) until pred holds.
template <typename Pred>
bool eventually(Pred pred) {
    for (int i = 0; i < 60000; ++i) {
        if (pred()) {
            return true;
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    return pred();
}

bool process_gone(pid_t pid) {
    if (::kill(pid, 0) != 0) {
        return true;
    }
    // Reparented and dead but not reaped yet (a zombie) counts as gone.
    const std::string stat = slurp("/proc/" + std::to_string(pid) + "/stat");
    const std::size_t paren = stat.rfind(')');
    return paren == std::string::npos || (paren + 2 < stat.size() && stat[paren + 2] == 'Z');
}

std::vector<std::string> names_in(const fs::path& dir) {
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(dir)) {
        names.push_back(e.path().filename().string());
    }
    std::sort(names.begin(), names.end());
    return names;
}

// An executable stand-in for a program the tool starts: it notes its pid and
// waits to be killed.
void stand_in(const fs::path& bin, const std::string& name, const fs::path& marker) {
    fs::create_directories(bin);
    write(bin / name, "#!/bin/sh\necho $$ > " + marker.string() + ".tmp && mv " + marker.string() + ".tmp " +
                          marker.string() + "\nexec sleep 1000000\n");
    fs::permissions(bin / name, fs::perms::owner_all);
}

// The temporary file of OUT written by process pid (OUT.tmp-PID-XXXXXXXX), if any.
std::optional<fs::path> temporary_of(const fs::path& out, pid_t pid) {
    const std::string prefix = out.filename().string() + ".tmp-" + std::to_string(pid) + "-";
    for (const auto& e : fs::directory_iterator(out.parent_path())) {
        if (e.path().filename().string().rfind(prefix, 0) == 0) {
            return e.path();
        }
    }
    return std::nullopt;
}

pid_t pid_in(const fs::path& marker) {
    return static_cast<pid_t>(std::stol(slurp(marker)));
}

const std::string kSolutions = data_path("solutions.csv");
const std::string kModel = data_path("model_table2.csv");

// ---- item 1: an output that is an input is refused, before reading ----------

TEST(OutputSafety, CorrectRefusesAnOutputThatIsItsInputByAnyPath) {
    const fs::path dir = scratch_dir("same");
    fs::copy_file(kSolutions, dir / "s.csv");
    fs::copy_file(kModel, dir / "m.csv");
    fs::create_symlink("s.csv", dir / "link.csv");
    fs::create_hard_link(dir / "s.csv", dir / "hard.csv");
    const std::string before = slurp(dir / "s.csv");
    for (const std::string& out :
         std::vector<std::string>{"s.csv", "./s.csv", (dir / "s.csv").string(), "link.csv", "hard.csv", "m.csv"}) {
        SCOPED_TRACE(out);
        const CliRun r = run_in("correct --in s.csv --model m.csv --out " + out, dir);
        EXPECT_EQ(r.exit_code, 1);
        EXPECT_NE(r.err.find("is the same file as the input"), std::string::npos) << r.err;
        EXPECT_EQ(slurp(dir / "s.csv"), before);
        EXPECT_EQ(slurp(dir / "m.csv"), slurp(kModel));
        EXPECT_TRUE(fs::is_symlink(dir / "link.csv"));
    }
    EXPECT_EQ(names_in(dir), (std::vector<std::string>{"hard.csv", "link.csv", "m.csv", "s.csv", "stderr.txt"}));
}

TEST(OutputSafety, FitPlotSimulateReplayAndThermistorsRefuseToOverwriteAnInput) {
    const fs::path dir = scratch_dir("same-all");
    fs::copy_file(kSolutions, dir / "s.csv");
    fs::copy_file(kModel, dir / "m.csv");
    fs::copy_file(kModel, dir / "sim.truth.csv");
    fs::copy_file(std::string(ASCORR_HAL_EXAMPLES) + "/board.cfg", dir / "board.cfg");
    fs::copy_file(std::string(ASCORR_HAL_EXAMPLES) + "/replay.csv", dir / "rec.csv");
    const std::string cmds[] = {
        "fit --in s.csv --out s.csv",
        "plot --in s.csv --model m.csv --out m.csv",
        "plot --in s.csv --model m.csv --out s.csv",
        "simulate --days 1 --truth m.csv --out m.csv",
        "simulate --days 1 --truth sim.truth.csv --out sim",  // its truth output is the input
        "replay --target loopback-float --in s.csv --model m.csv --out s.csv",
        "thermistors --config board.cfg --replay rec.csv >> rec.csv",
        "stats --in s.csv >> s.csv",
    };
    const std::string s = slurp(dir / "s.csv");
    const std::string rec = slurp(dir / "rec.csv");
    for (const std::string& c : cmds) {
        SCOPED_TRACE(c);
        const CliRun r = run_in(c, dir);
        EXPECT_EQ(r.exit_code, 1);
        EXPECT_NE(r.err.find("is the same file as the input"), std::string::npos) << r.err;
        EXPECT_EQ(slurp(dir / "s.csv"), s);
        EXPECT_EQ(slurp(dir / "m.csv"), slurp(kModel));
        EXPECT_EQ(slurp(dir / "sim.truth.csv"), slurp(kModel));
        EXPECT_EQ(slurp(dir / "rec.csv"), rec);
    }
    EXPECT_FALSE(fs::exists(dir / "sim"));
}

// ---- item 1: outputs that are not regular files, links, permissions ---------

// The states file is an input too (--states): correct and replay
// refuse to write over it.
TEST(OutputSafety, TheStatesFileIsAnInputCorrectAndReplayDoNotOverwrite) {
    const fs::path dir = scratch_dir("same-states");
    fs::copy_file(kSolutions, dir / "s.csv");
    fs::copy_file(kModel, dir / "m.csv");
    {
        std::ofstream st(dir / "st.csv");
        st << "t,x,y,z,vx,vy,vz\n447534180.184,6838.0,0.0,0.0,0.0,1.0,7.5\n";
    }
    const std::string before = slurp(dir / "st.csv");
    for (const std::string& c : {std::string("correct --in s.csv --states st.csv --out st.csv"),
                                 std::string("replay --target loopback-float --in s.csv --model m.csv "
                                             "--states st.csv --out st.csv")}) {
        SCOPED_TRACE(c);
        const CliRun r = run_in(c, dir);
        EXPECT_EQ(r.exit_code, 1);
        EXPECT_NE(r.err.find("--states"), std::string::npos) << r.err;
        EXPECT_EQ(slurp(dir / "st.csv"), before);
    }
}

TEST(OutputSafety, DashAndDevStdoutAreStreamsNotFiles) {
    const fs::path dir = scratch_dir("dash");
    ASSERT_EQ(run_in("correct --in " + kSolutions + " --out ref.csv", dir).exit_code, 0);
    const CliRun r = run_in("correct --in " + kSolutions + " --out - > dash.csv", dir);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(slurp(dir / "dash.csv"), slurp(dir / "ref.csv"));
    EXPECT_FALSE(fs::exists(dir / "-"));
    // /dev/stdout into a pipe (it cannot be renamed over).
    const CliRun p = run_in("correct --in " + kSolutions + " --out /dev/stdout | cat > piped.csv", dir);
    ASSERT_EQ(p.exit_code, 0) << p.err;
    EXPECT_EQ(slurp(dir / "piped.csv"), slurp(dir / "ref.csv"));
    EXPECT_TRUE(fs::is_character_file("/dev/null"));
}

TEST(OutputSafety, AFifoOutputIsWrittenIntoAndStaysAFifo) {
    const fs::path dir = scratch_dir("fifo");
    ASSERT_EQ(run_in("correct --in " + kSolutions + " --out ref.csv", dir).exit_code, 0);
    ASSERT_LT(fs::file_size(dir / "ref.csv"), 60000U);  // fits in the pipe's buffer: no reader thread needed
    ASSERT_EQ(::mkfifo((dir / "out.fifo").c_str(), 0644), 0);
    const int rd = ::open((dir / "out.fifo").c_str(), O_RDONLY | O_NONBLOCK);
    ASSERT_GE(rd, 0);
    const CliRun r = run_in("correct --in " + kSolutions + " --out out.fifo", dir);
    EXPECT_EQ(r.exit_code, 0) << r.err;
    std::string got;
    char buf[4096];
    for (ssize_t n; (n = ::read(rd, buf, sizeof buf)) > 0;) {
        got.append(buf, static_cast<std::size_t>(n));
    }
    ::close(rd);
    EXPECT_TRUE(fs::is_fifo(dir / "out.fifo"));
    EXPECT_EQ(got, slurp(dir / "ref.csv"));
    EXPECT_EQ(names_in(dir), (std::vector<std::string>{"out.fifo", "ref.csv", "stderr.txt"}));
}

TEST(OutputSafety, ALinkedOutputReplacesTheTargetAndKeepsLinkAndPermissions) {
    const fs::path dir = scratch_dir("link");
    ASSERT_EQ(run_in("correct --in " + kSolutions + " --out ref.csv", dir).exit_code, 0);
    fs::create_directories(dir / "real");
    write(dir / "real" / "out.csv", "old\n");
    ::chmod((dir / "real" / "out.csv").c_str(), 0604);  // not what any umask gives a new file
    fs::create_symlink("real/out.csv", dir / "out.csv");
    fs::create_symlink("real/new.csv", dir / "dangling.csv");  // target does not exist yet
    ASSERT_EQ(run_in("correct --in " + kSolutions + " --out out.csv", dir).exit_code, 0);
    ASSERT_EQ(run_in("correct --in " + kSolutions + " --out dangling.csv", dir).exit_code, 0);
    EXPECT_TRUE(fs::is_symlink(dir / "out.csv"));
    EXPECT_TRUE(fs::is_symlink(dir / "dangling.csv"));
    EXPECT_EQ(slurp(dir / "real" / "out.csv"), slurp(dir / "ref.csv"));
    EXPECT_EQ(slurp(dir / "real" / "new.csv"), slurp(dir / "ref.csv"));
    struct stat st {};
    ASSERT_EQ(::stat((dir / "real" / "out.csv").c_str(), &st), 0);
    EXPECT_EQ(st.st_mode & 07777, 0604U);
    EXPECT_EQ(names_in(dir / "real"), (std::vector<std::string>{"new.csv", "out.csv"}));
}

TEST(OutputSafety, ADirectoryOutputIsRefusedNamingTheOutput) {
    const fs::path dir = scratch_dir("dirout");
    fs::create_directories(dir / "d");
    const CliRun r = run_in("correct --in " + kSolutions + " --out d", dir);
    expect_refused(r, 1, {"d: is a directory"});
    EXPECT_EQ(r.err.find(".tmp-"), std::string::npos) << r.err;
    EXPECT_TRUE(fs::is_empty(dir / "d"));
}

TEST(OutputSafety, ACorrectedFileFedBackIsRefused) {
    const fs::path dir = scratch_dir("twice");
    ASSERT_EQ(run_in("correct --in " + kSolutions + " --model " + kModel + " --out once.csv", dir).exit_code, 0);
    for (const std::string& c : std::vector<std::string>{
             "correct --in once.csv --out twice.csv", "fit --in once.csv --out m.csv",
             "replay --target loopback-float --in once.csv --model " + kModel + " --out twice.csv"}) {
        SCOPED_TRACE(c);
        expect_refused(run_in(c, dir), 1, {"once.csv:1:", "column 'status': this file is already corrected"});
        expect_absent(dir, {"twice.csv", "m.csv"});
    }
    // The column named is the header's character column of `status`, its
    // quoted names counted as written (was: unquoted, 2 short per quoted name).
    const std::vector<std::string> once = lines_of_file(dir / "once.csv");
    const std::string header = "\"my \"\"note\"\"\"," + once.at(0);
    std::ofstream quoted(dir / "quoted.csv");
    quoted << header << '\n';
    for (std::size_t i = 1; i < once.size(); ++i) {
        quoted << "x," << once[i] << '\n';
    }
    quoted.close();
    const std::string at = "quoted.csv:1:" + std::to_string(header.find(",status") + 2) + ": column 'status'";
    expect_refused(run_in("correct --in quoted.csv --out twice.csv", dir), 1, {at});
}

// Issue 30 item 3: the temporary output was OUT.tmp-PID, opened with O_TRUNC
// and without O_EXCL: an input of exactly that name was truncated, then
// removed. The run is started by a child that knows its own pid (the one exec
// keeps) and names its input after it.
TEST(OutputSafety, AnInputNamedLikeTheTemporaryOutputIsNeverTouched) {
    const fs::path dir = scratch_dir("temp-name");
    ASSERT_EQ(run_in("correct --in " + kSolutions + " --out ref.csv", dir).exit_code, 0);
    const pid_t pid = ::fork();
    if (pid == 0) {
        const std::string in = (dir / ("out.csv.tmp-" + std::to_string(::getpid()))).string();
        std::error_code ec;
        fs::copy_file(kSolutions, in, ec);
        const int err = ::open((dir / "stderr.txt").c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
        ::dup2(err, STDERR_FILENO);
        ::execl(ASCORR_EXE, ASCORR_EXE, "correct", "--in", in.c_str(), "--out", (dir / "out.csv").c_str(),
                static_cast<char*>(nullptr));
        ::_exit(127);
    }
    int status = 0;
    ASSERT_EQ(::waitpid(pid, &status, 0), pid);
    const fs::path in = dir / ("out.csv.tmp-" + std::to_string(pid));
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << status << slurp(dir / "stderr.txt");
    ASSERT_TRUE(fs::exists(in));
    EXPECT_EQ(slurp(in), slurp(kSolutions));  // neither truncated nor removed
    EXPECT_EQ(slurp(dir / "out.csv"), slurp(dir / "ref.csv"));
    EXPECT_EQ(names_in(dir), (std::vector<std::string>{"out.csv", in.filename().string(), "ref.csv", "stderr.txt"}));
}

// ---- item 2: interrupted runs leave nothing behind ---------------------------

// The input is a FIFO: after one block (32 MiB) the run waits for more, its
// temporary output provably open; then the signal comes.
TEST(OutputSafety, ASignalledCorrectRemovesItsTemporaryFileAndKeepsTheOldOutput) {
    std::string rows;
    {
        std::ifstream f(kSolutions);
        std::string header;
        std::getline(f, header);
        std::string body;
        for (std::string l; std::getline(f, l);) {
            body += l + '\n';
        }
        rows = header + '\n';
        while (rows.size() < (1U << 20)) {
            rows += body;
        }
    }
    const fs::path base = scratch_dir("signal");
    ::signal(SIGPIPE, SIG_IGN);  // our FIFO writer sees EPIPE when the tool is gone
    for (const int sig : {SIGINT, SIGTERM, SIGHUP, SIGPIPE}) {
        SCOPED_TRACE(sig);
        const fs::path dir = base / std::to_string(sig);
        fs::create_directories(dir);
        write(dir / "out.csv", "the previous output\n");
        ASSERT_EQ(::mkfifo((dir / "in.csv").c_str(), 0644), 0);
        const pid_t pid =
            spawn({"correct", "--in", (dir / "in.csv").string(), "--out", (dir / "out.csv").string()}, base);
        const int wr = ::open((dir / "in.csv").c_str(), O_WRONLY);
        ASSERT_GE(wr, 0);
        // One block and a bit; the writer stops at EPIPE once the reader is gone.
        std::thread writer([&] {
            std::size_t sent = 0;
            for (bool first = true; sent < (33U << 20); first = false) {
                const std::string_view chunk =
                    first ? std::string_view(rows) : std::string_view(rows).substr(rows.find('\n') + 1);
                if (::write(wr, chunk.data(), chunk.size()) != static_cast<ssize_t>(chunk.size())) {
                    return;
                }
                sent += chunk.size();
            }
        });
        const bool started = eventually([&] { return temporary_of(dir / "out.csv", pid).has_value(); });
        EXPECT_TRUE(started);
        ASSERT_EQ(::kill(pid, sig), 0);
        int status = 0;
        ASSERT_EQ(::waitpid(pid, &status, 0), pid);
        writer.join();
        ::close(wr);
        EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == sig) << status;  // a shell: 128 + sig
        EXPECT_EQ(names_in(dir), (std::vector<std::string>{"in.csv", "out.csv"}));
        EXPECT_EQ(slurp(dir / "out.csv"), "the previous output\n");
        fs::remove_all(dir);
    }
}

// Issue 30 items 1 and 18: every output of a run is open before its input is
// read, and a signal leaves every one as it was. The input is a FIFO whose
// writer never closes it: the run is provably inside the copy of its input,
// its two temporary outputs open.
TEST(OutputSafety, ASignalBeforeTheCommitLeavesEveryOutputOfTheRunAsItWas) {
    const fs::path dir = scratch_dir("signal-set");
    fs::create_directories(dir / "tmp");
    write(dir / "out.csv", "the previous output\n");
    write(dir / "history.csv", "the previous history\n");
    ASSERT_EQ(::mkfifo((dir / "in.csv").c_str(), 0644), 0);
    const pid_t pid = spawn({"correct", "--in", (dir / "in.csv").string(), "--self-calibrate", "--out",
                             (dir / "out.csv").string(), "--model-history", (dir / "history.csv").string()},
                            dir, "", (dir / "tmp").string());
    const int wr = ::open((dir / "in.csv").c_str(), O_WRONLY);
    ASSERT_GE(wr, 0);
    const std::string rows = slurp(kSolutions);
    ASSERT_EQ(::write(wr, rows.data(), rows.size()), static_cast<ssize_t>(rows.size()));
    EXPECT_TRUE(eventually([&] {
        return temporary_of(dir / "out.csv", pid).has_value() && temporary_of(dir / "history.csv", pid).has_value() &&
               !fs::is_empty(dir / "tmp");
    }));
    ASSERT_EQ(::kill(pid, SIGTERM), 0);
    int status = 0;
    ASSERT_EQ(::waitpid(pid, &status, 0), pid);
    ::close(wr);
    EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGTERM) << status;
    EXPECT_EQ(slurp(dir / "out.csv"), "the previous output\n");
    EXPECT_EQ(slurp(dir / "history.csv"), "the previous history\n");
    EXPECT_TRUE(fs::is_empty(dir / "tmp"));  // the copy of the input too
    EXPECT_EQ(names_in(dir),
              (std::vector<std::string>{"history.csv", "in.csv", "out.csv", "stderr.txt", "stdout.txt", "tmp"}));
}

TEST(OutputSafety, ASignalledPlotRemovesItsTemporaryFolderAndGnuplot) {
    const fs::path dir = scratch_dir("plot");
    ASSERT_EQ(run_in("simulate --days 1 --out sim.csv", dir).exit_code, 0);
    fs::create_directories(dir / "tmp");
    stand_in(dir / "bin", "gnuplot", dir / "gnuplot.pid");
    const pid_t pid = spawn({"plot", "--in", (dir / "sim.csv").string(), "--model",
                             (dir / "sim.csv.truth.csv").string(), "--out", (dir / "iba.png").string()},
                            dir, (dir / "bin").string(), (dir / "tmp").string());
    ASSERT_TRUE(eventually([&] { return fs::exists(dir / "gnuplot.pid"); })) << slurp(dir / "stderr.txt");
    ASSERT_FALSE(fs::is_empty(dir / "tmp"));  // the plot's folder, with its data files
    const pid_t gnuplot = pid_in(dir / "gnuplot.pid");
    ASSERT_EQ(::kill(pid, SIGTERM), 0);
    int status = 0;
    ASSERT_EQ(::waitpid(pid, &status, 0), pid);
    EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGTERM) << status;
    EXPECT_TRUE(fs::is_empty(dir / "tmp")) << names_in(dir / "tmp").front();
    EXPECT_TRUE(eventually([&] { return process_gone(gnuplot); }));
    EXPECT_FALSE(fs::exists(dir / "iba.png"));
    ::kill(gnuplot, SIGKILL);
}

TEST(OutputSafety, ReplaysEmulatorDiesWithItsParentEvenOnSigkill) {
    const fs::path dir = scratch_dir("pdeath");
    stand_in(dir / "bin", "qemu-system-arm", dir / "qemu.pid");
    // The header of a soft-float ARM executable, which replay checks before it
    // starts the emulator; the stand-in never reads the rest.
    std::string header(52, '\0');
    const unsigned char elf[] = {0x7f, 'E', 'L', 'F', 1, 1, 1};
    std::copy(std::begin(elf), std::end(elf), header.begin());
    header[16] = 2;     // executable
    header[18] = 40;    // ARM
    header[20] = 1;     // version
    header[24] = 0x41;  // entry point, in the board's code memory
    write(dir / "image.elf", header);
    const pid_t pid = spawn(
        {"replay", "--target", std::string(host::kQemuTargets[0].replay), "--firmware", (dir / "image.elf").string(),
         "--in", kSolutions, "--model", kModel, "--out", (dir / "out.csv").string(), "--timeout-ms", "60000"},
        dir, (dir / "bin").string());
    ASSERT_TRUE(eventually([&] { return fs::exists(dir / "qemu.pid"); })) << slurp(dir / "stderr.txt");
    const pid_t emulator = pid_in(dir / "qemu.pid");
    ASSERT_FALSE(process_gone(emulator));
    ASSERT_EQ(::kill(pid, SIGKILL), 0);
    int status = 0;
    ASSERT_EQ(::waitpid(pid, &status, 0), pid);
    EXPECT_TRUE(eventually([&] { return process_gone(emulator); }));
    ::kill(emulator, SIGKILL);
    EXPECT_FALSE(fs::exists(dir / "out.csv"));
}

}  // namespace
}  // namespace ascorr::test
