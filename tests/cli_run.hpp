// tests/cli_run.hpp: runs the `ascorr` executable under test (ASCORR_EXE), in
// a scratch folder (run_in) or in the test's directory (run_here, run_cli),
// for the tests of its command-line behaviour.
#pragma once

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace ascorr::test {

struct CliRun {
    int exit_code;    // -1 when it did not exit normally
    std::string err;  // its standard error
};

// Writes TEXT to the file P, replacing it.
inline void write(const std::filesystem::path& p, const std::string& text) {
    std::ofstream(p, std::ios::binary) << text;
}

// The lines of the file P, without their line ends.
inline std::vector<std::string> lines_of_file(const std::filesystem::path& p) {
    std::ifstream f(p);
    std::vector<std::string> out;
    for (std::string l; std::getline(f, l);) {
        out.push_back(l);
    }
    return out;
}

// Whether TEXT holds PART.
inline bool has(const std::string& text, const std::string& part) {
    return text.find(part) != std::string::npos;
}

inline std::string slurp(const std::filesystem::path& p) {
    std::ifstream f(p, std::ios::binary);
    std::stringstream ss;
    ss << f.rdbuf();
    return ss.str();
}

// Runs COMMAND through sh with its standard error in dir/stderr.txt.
inline CliRun run_shell(const std::string& command, const std::filesystem::path& dir) {
    const std::filesystem::path err = dir / "stderr.txt";
    const std::string cmd = command + " 2> " + err.string();
    const int rc = std::system(cmd.c_str());
    return {WIFEXITED(rc) ? WEXITSTATUS(rc) : -1, slurp(err)};
}

// Runs `ascorr ARGS` through sh in `dir` (ARGS may use paths relative to it and
// redirect standard output); standard error goes to dir/stderr.txt.
inline CliRun run_in(const std::string& args, const std::filesystem::path& dir) {
    return run_shell("cd " + dir.string() + " && " + std::string(ASCORR_EXE) + " " + args, dir);
}

// The same without changing directory: relative paths in ARGS are the test's
// working directory's; dir only receives stderr.txt.
inline CliRun run_here(const std::string& args, const std::filesystem::path& dir) {
    return run_shell(std::string(ASCORR_EXE) + " " + args, dir);
}

// Runs `ascorr ARGS` with its standard output in `out` and its standard
// error in `err`; its exit code, -1 when it did not exit normally.
inline int run_cli(const std::string& args, const std::filesystem::path& out, const std::filesystem::path& err) {
    const std::string cmd = std::string(ASCORR_EXE) + " " + args + " > " + out.string() + " 2> " + err.string();
    const int rc = std::system(cmd.c_str());
    return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
}

// The same with dir/out.txt and dir/err.txt.
inline int run_cli(const std::string& args, const std::filesystem::path& dir) {
    return run_cli(args, dir / "out.txt", dir / "err.txt");
}

// For expect_refused: any exit code but 0.
constexpr int kAnyFailure = -2;

// Expects R to have exited with CODE (kAnyFailure: with any code but 0) and
// its standard error to hold each of PARTS.
inline void expect_refused(const CliRun& r, int code, std::initializer_list<std::string> parts) {
    if (code == kAnyFailure) {
        EXPECT_NE(r.exit_code, 0) << r.err;
    } else {
        EXPECT_EQ(r.exit_code, code) << r.err;
    }
    for (const std::string& part : parts) {
        EXPECT_TRUE(has(r.err, part)) << "no '" << part << "' in: " << r.err;
    }
}

// Writes ROWS to the file P, each with a line end.
inline void write_lines(const std::filesystem::path& p, const std::vector<std::string>& rows) {
    std::string text;
    for (const std::string& l : rows) {
        text += l + "\n";
    }
    write(p, text);
}

// Expects each pair of files in DIR to hold the same bytes.
inline void expect_same_files(const std::filesystem::path& dir,
                              std::initializer_list<std::pair<std::string, std::string>> pairs) {
    for (const auto& [a, b] : pairs) {
        EXPECT_EQ(slurp(dir / a), slurp(dir / b)) << a << " vs " << b;
    }
}

// Expects none of FILES to exist in DIR.
inline void expect_absent(const std::filesystem::path& dir, std::initializer_list<std::string> files) {
    for (const std::string& f : files) {
        EXPECT_FALSE(std::filesystem::exists(dir / f)) << f;
    }
}

}  // namespace ascorr::test
