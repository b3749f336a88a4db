// host_sim/cli/commands.hpp: one registration function per `ascorr` command.
//
// Each command lives in its own file and adds a CLI11 subcommand whose
// callback does the work; main() only dispatches and maps errors to exit codes.
#pragma once

#include <CLI/CLI.hpp>

namespace ascorr::cli {

void add_correct_command(CLI::App& app);
void add_replay_command(CLI::App& app);
void add_thermistors_command(CLI::App& app);
void add_simulate_command(CLI::App& app);
void add_fit_command(CLI::App& app);
void add_stats_command(CLI::App& app);
void add_plot_command(CLI::App& app);

}  // namespace ascorr::cli
