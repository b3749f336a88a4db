// tests/replay_boards.hpp: what the replay tests share about the QEMU boards
// (host::kQemuTargets) and about a replay's summary: the boards' names in
// GoogleTest and scratch folders, the scalar of a board, a replay printed.
#pragma once

#include <gtest/gtest.h>

#include <filesystem>
#include <iostream>
#include <ostream>
#include <sstream>
#include <string>

#include "ascorr/core/q_formats.hpp"
#include "ascorr_host/link/qemu_targets.hpp"
#include "ascorr_host/link/replay.hpp"
#include "cli_run.hpp"
#include "test_support.hpp"

namespace ascorr::host {
// GoogleTest shows a board by its replay name (not its bytes) in test names.
inline void PrintTo(const QemuTarget& board, std::ostream* os) {
    *os << board.replay;
}
}  // namespace ascorr::host

namespace ascorr::test {

// The board's replay name with '_' for '-': a GoogleTest name, a scratch folder's.
inline std::string board_name(const host::QemuTarget& board) {
    std::string s(board.replay);
    for (char& c : s) {
        c = c == '-' ? '_' : c;
    }
    return s;
}

// Each test once per board: Boards/Suite.Test/qemu_m3, ...
inline std::string board_test_name(const ::testing::TestParamInfo<host::QemuTarget>& i) {
    return board_name(i.param);
}

// The board's scalar as `correct --scalar` names it.
inline std::string board_scalar(const host::QemuTarget& board) {
    return board.scalar == host::ScalarKind::kFixed ? "fixed" : "float";
}

// f(Q30{}) on a board of fixed point, f(float{}) on one of float.
template <typename F>
void with_board_scalar(const host::QemuTarget& board, F&& f) {
    if (board.scalar == host::ScalarKind::kFixed) {
        f(Q30{});
    } else {
        f(float{});
    }
}

// host::replay(o, log), its summary and log printed after `label`.
inline host::ReplaySummary replay_printed(const host::ReplayOptions& o, std::ostringstream& log,
                                          const std::string& label = "") {
    const host::ReplaySummary s = host::replay(o, log);
    std::cout << label << host::to_json(s) << "\n" << log.str();
    return s;
}

// A scratch folder NAME in which `simulate --out sim.csv ARGS` has run.
inline std::filesystem::path simulated_in(const std::string& name, const std::string& args) {
    const auto dir = scratch_dir(name);
    const CliRun r = run_in("simulate --out sim.csv " + args, dir);
    EXPECT_EQ(r.exit_code, 0) << r.err;
    return dir;
}

// A replay through TARGET of dir/sim.csv into dir/replayed.csv.
inline host::ReplayOptions replay_options(const std::filesystem::path& dir, const std::string& target) {
    host::ReplayOptions o;
    o.target = target;
    o.in = (dir / "sim.csv").string();
    o.out = (dir / "replayed.csv").string();
    return o;
}

// replay_printed of O on BOARD, with a log of its own, after the board's replay name.
inline host::ReplaySummary replay_on_board(const host::QemuTarget& board, const host::ReplayOptions& o) {
    std::ostringstream log;
    return replay_printed(o, log, std::string(board.replay) + ": ");
}

}  // namespace ascorr::test
