// host_sim/cli/commands.hpp: one registration function per `ascorr` command.
//
// Each command lives in its own file and adds a CLI11 subcommand whose
// callback does the work; main() only dispatches and maps errors to exit codes.
#pragma once

#include <CLI/CLI.hpp>

#include <array>
#include <cctype>
#include <optional>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "ascorr/core/heads.hpp"
#include "ascorr_host/analysis/iba.hpp"
#include "ascorr_host/formats/atomic_file.hpp"

namespace ascorr::host {
struct GateOptions;
struct CombinedColumns;
}  // namespace ascorr::host

namespace ascorr::cli {

// A command that ran to its end and wrote every output, whose result is a
// failure (replay: the target disagrees with the host): main() prints the
// message and exits 3.
class FailedResult : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

// Input a command refuses (align: a malformed file, too few epochs, a head
// without clean epochs): main() prints the message (file:line:column where
// it has one) and exits 2, as for a usage error.
class RefusedInput : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

// Heads by their letters (--heads ABCD, --frame-heads AC): heads.hpp's, in its
// order, none twice, at least `min` and at most `max` of them. A refused value
// is a usage error (exit 2), found before any input is read.
inline CLI::Validator head_letters_in(std::size_t min, std::size_t max) {
    return CLI::Validator(
        [min, max](std::string& s) {
            const std::optional<HeadMask> set = host::parse_head_letters(s);
            const std::size_t n = set ? head_count(*set) : 0;
            if (set && n >= min && n <= max) {
                return std::string();
            }
            const std::string count = min == max ? std::to_string(min) : std::to_string(min) + " or more";
            return "'" + s + "' is not " + count + " of the heads " + kHeadLetters +
                   " (their letters, in that order, none twice)";
        },
        "LETTERS");
}

// Refuses an empty path (--model "", --states ""), which would otherwise read
// as "no model", "no states".
inline CLI::Validator non_empty_path() {
    return CLI::Validator(
        [](std::string& s) { return s.empty() ? std::string("an empty path names no file") : std::string(); }, "FILE");
}

// An output that cannot be standard output ("-"), and why: the command writes
// more than one file, or standard output carries its report.
inline CLI::Validator not_standard_output(const std::string& why) {
    return CLI::Validator(
        [why](std::string& s) {
            return s == "-" ? "'-' (standard output) cannot be this output: " + why : std::string();
        },
        "FILE");
}

// The one spelling rule of every choice option (--scalar, --states-frame,
// --terms, --speed): one of its names, in any case ("GCRS" is gcrs); a number is
// not a name ("--states-frame 1" is refused, whatever the option's type). The
// option's variable receives the name's value. Help: NAME:{a,b,c}.
template <typename T>
CLI::Validator one_of(std::vector<std::pair<std::string, T>> names) {
    std::string list;
    for (const auto& n : names) {
        list += (list.empty() ? "" : ",") + n.first;
    }
    return CLI::Validator(
        [names, list](std::string& s) {
            std::string lower = s;
            for (char& c : lower) {
                c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
            }
            for (const auto& [name, value] : names) {
                if (lower == name) {
                    if constexpr (std::is_enum_v<T>) {
                        s = std::to_string(static_cast<std::underlying_type_t<T>>(value));
                    } else if constexpr (std::is_same_v<T, bool>) {
                        s = value ? "1" : "0";
                    } else {
                        s = value;
                    }
                    return std::string();
                }
            }
            return "'" + s + "' is not one of {" + list + "} (names, any case; numbers are not names)";
        },
        "{" + list + "}");
}

// The files of one run, before its work (standard_input.cpp), the same for
// every command: the outputs checked against the inputs and each other and
// opened (host::OutputSet: a path that cannot be written fails now, before any
// input is read); then every input that is a stream ("-" is standard input; a
// pipe, a FIFO or a socket given by path) read once,
// whole, into a private temporary file, whose path replaces the input's
// (inputs may be read twice). Two inputs "-" are a usage error. The command
// writes into the set, then commits it: all its outputs or none.
host::OutputSet open_run_files(const std::vector<std::pair<const char*, std::string*>>& inputs,
                               std::vector<host::NamedPath> outputs);
// The second half of open_run_files alone: "-" and every other stream read
// once (the name is older than the streams; it is kept for the callers that
// have no outputs yet in a set).
void read_dash_from_standard_input(const std::vector<std::pair<const char*, std::string*>>& inputs);

void add_correct_command(CLI::App& app);
void add_replay_command(CLI::App& app);
void add_thermistors_command(CLI::App& app);
void add_simulate_command(CLI::App& app);
void add_fit_command(CLI::App& app);
// --time-constant DAYS and --orbit-period SECONDS of `correct` and `replay`
// --self-calibrate (their ranges and defaults the estimator's, the period's
// as fit's; correct_command.cpp).
struct SelfCalibrationOptions {
    CLI::Option* time_constant;
    CLI::Option* orbit_period;
    CLI::Option* lag;
};
// What is wrong with a --lag (host::parse_lags: TAU, X:TAU,... or auto);
// empty when nothing is (fit_command.cpp).
std::string lag_option_problem(const std::string& text);
// --time-constant, --orbit-period and --lag (the estimator's bench lag, as
// fit --lag; auto, learnt, where lag_auto is given: correct's) of correct and
// replay.
SelfCalibrationOptions add_self_calibration_options(CLI::App& cmd, double& days, std::optional<double>& seconds,
                                                    std::optional<std::array<double, kMaxHeads>>& lag_s,
                                                    bool* lag_auto);
// Refuses --model-history, --time-constant, --orbit-period and --lag without --self-calibrate.
void check_needs_self_calibrate(bool self_calibrate, const std::string& model_history,
                                const SelfCalibrationOptions& given);
void add_stats_command(CLI::App& app);
void add_plot_command(CLI::App& app);
void add_combine_command(CLI::App& app);
// --gate-sigmas K and --gate-floor ARCSEC of combine, correct and replay
// (--combined: each needs `combined`); combine_command.cpp.
enum class GateDefault { kGround, kFlight };  // which default --gate-floor's help names
void add_gate_options(CLI::App& cmd, host::GateOptions& gate, CLI::Option* combined, GateDefault floor);
// --covariance of combine and correct --combined (combine_command.cpp).
CLI::Option* add_covariance_option(CLI::App& cmd, host::CombinedColumns& columns);
void add_align_command(CLI::App& app);
void add_interpolate_command(CLI::App& app);
void add_import_command(CLI::App& app);  // import gracefo

}  // namespace ascorr::cli
