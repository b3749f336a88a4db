// host_sim/cli/commands.hpp: one registration function per `ascorr` command.
//
// Each command lives in its own file and adds a CLI11 subcommand whose
// callback does the work; main() only dispatches and maps errors to exit codes.
#pragma once

#include <CLI/CLI.hpp>

namespace ascorr::cli {

// Refuses an empty path (--model ""), which would otherwise read as "no model".
inline CLI::Validator non_empty_path() {
    return CLI::Validator(
        [](std::string& s) { return s.empty() ? std::string("an empty path names no file") : std::string(); }, "FILE");
}

void add_correct_command(CLI::App& app);
void add_replay_command(CLI::App& app);
void add_thermistors_command(CLI::App& app);
void add_simulate_command(CLI::App& app);
void add_fit_command(CLI::App& app);
void add_stats_command(CLI::App& app);
void add_plot_command(CLI::App& app);

}  // namespace ascorr::cli
