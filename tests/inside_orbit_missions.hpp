// Simulated missions of a bench inside the orbit (issue 40) and the measures
// the self-calibration's tests take of them: the systematic IBA residual
// against the simulator's noise-only IBAs from a day of the mission on.
#pragma once

#include <gtest/gtest.h>

#include <array>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include "ascorr_host/analysis/stats.hpp"
#include "cli_run.hpp"
#include "test_support.hpp"

namespace ascorr::test {

// `simulate <args> --noise-iba --out m.csv` in a scratch directory `name`.
inline std::filesystem::path simulated_mission(const std::string& name, const std::string& args) {
    const std::filesystem::path d = scratch_dir(name);
    const CliRun r = run_in("simulate " + args + " --noise-iba --out m.csv > /dev/null", d);
    EXPECT_EQ(r.exit_code, 0) << r.err;
    return d;
}

// The first row's t of the mission in dir, + days.
inline double mission_day(const std::filesystem::path& dir, double days) {
    const std::vector<std::string> lines = lines_of_file(dir / "m.csv");
    return std::stod(lines.at(1).substr(0, lines.at(1).find(','))) + days * 86400.0;
}

// The systematic residual per pair (A-B, A-C, B-C) of `corrected` in dir
// from `from` on (arcsec).
inline std::array<double, 3> systematic_from(const std::filesystem::path& dir, const std::string& corrected,
                                             double from) {
    host::StatsOptions s;
    s.in = (dir / corrected).string();
    s.from = from;
    s.noise_iba = (dir / "m.csv.noise-iba.csv").string();
    s.log_empty_pairs = false;
    std::ostringstream log;
    const host::StatsResult r = host::compute_stats(s, log);
    return {r.systematic_rms[0][0].rms, r.systematic_rms[1][0].rms, r.systematic_rms[2][0].rms};
}

// `correct --in m.csv --self-calibrate` in dir into `out` and its history `out`.history.csv.
inline CliRun self_calibrate_mission(const std::filesystem::path& dir, const std::string& args,
                                     const std::string& out) {
    return run_in(
        "correct --in m.csv --self-calibrate --out " + out + " --model-history " + out + ".history.csv " + args, dir);
}

// A static bench (today's missions: 60 days, an epoch every 240 s, seed 40),
// simulated once per test program.
inline const std::filesystem::path& static_mission() {
    static const std::filesystem::path dir = simulated_mission("static-bench", "--days 60 --step 240 --seed 40");
    return dir;
}

// `correct --self-calibrate` on the static bench without and with `option`
// (a learner that must find nothing there): every byte of the corrected file
// and of the history the same. The runs, for the caller's account checks.
struct StaticBenchRuns {
    CliRun none;
    CliRun with;
};

inline StaticBenchRuns expect_static_bench_unchanged_by(const std::string& option) {
    namespace fs = std::filesystem;
    const fs::path& dir = static_mission();
    StaticBenchRuns r{self_calibrate_mission(dir, "", "s_none.csv"), self_calibrate_mission(dir, option, "s_with.csv")};
    EXPECT_EQ(r.none.exit_code, 0) << r.none.err;
    EXPECT_EQ(r.with.exit_code, 0) << r.with.err;
    EXPECT_EQ(slurp(dir / "s_with.csv"), slurp(dir / "s_none.csv")) << option;
    EXPECT_EQ(slurp(dir / "s_with.csv.history.csv"), slurp(dir / "s_none.csv.history.csv")) << option;
    return r;
}

}  // namespace ascorr::test
