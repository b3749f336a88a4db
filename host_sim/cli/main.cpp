// ascorr: thermal and aberration correction of µASC attitude solutions.
//
// Exit status: 0 when every output is complete; 1 for bad input or an I/O
// error (the message names file, line and column; standard output or error
// that could not be written is one); 2 for a usage error and input a command
// refuses as such (align); 3
// when the outputs are complete but say the run failed (replay: the target's
// answers, models or report differ from the host's);
// ended by SIGINT, SIGTERM, SIGHUP or SIGPIPE: that signal (128 + signal in a
// shell), with no temporary output left behind.
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <exception>
#include <iostream>
#include <string>

#include "ascorr_host/formats/atomic_file.hpp"
#include "ascorr_host/version.hpp"
#include "commands.hpp"

namespace {

// Every result on standard output (reports, JSON, tables, help) reaches it, or
// the run fails: the flush at exit is checked, and so is any write that failed
// before it (stdio keeps the error). Standard error likewise, without a
// message (there is nowhere to write one). code: the command's exit status.
int checked_exit(int code) {
    errno = 0;
    const bool out_failed = std::fflush(stdout) != 0 || std::ferror(stdout) != 0;
    const int out_errno = errno;
    if (out_failed && code != 1) {  // with 1, the command has said what failed
        std::cerr << "ascorr: standard output: write failed"
                  << (out_errno != 0 ? std::string(": ") + std::strerror(out_errno) : std::string()) << '\n';
    }
    const bool err_failed = std::fflush(stderr) != 0 || std::ferror(stderr) != 0;
    return (out_failed || err_failed) && code != 2 ? 1 : code;
}

int run(CLI::App& app, int argc, char** argv) {
    try {
        app.parse(argc, argv);
    } catch (const CLI::CallForHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForVersion& e) {
        return app.exit(e);
    } catch (const CLI::ParseError& e) {
        app.exit(e);
        return 2;
    } catch (const ascorr::cli::RefusedInput& e) {
        std::cerr << "ascorr: " << e.what() << '\n';
        return 2;
    } catch (const ascorr::cli::FailedResult& e) {
        std::cerr << "ascorr: " << e.what() << '\n';
        return 3;
    } catch (const std::exception& e) {
        std::cerr << "ascorr: " << e.what() << '\n';
        return 1;
    }
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    // SIGINT, SIGTERM, SIGHUP, SIGPIPE: temporary outputs removed, children
    // killed, then the process ends by the signal (atomic_file.hpp).
    ascorr::host::install_signal_cleanup();
    CLI::App app{"ascorr: thermal and aberration correction of uASC star-tracker attitude solutions"};
    app.require_subcommand(1);
    app.set_version_flag("--version", std::string("ascorr ") + ascorr::cli::kVersion);
    ascorr::cli::add_correct_command(app);
    ascorr::cli::add_replay_command(app);
    ascorr::cli::add_thermistors_command(app);
    ascorr::cli::add_simulate_command(app);
    ascorr::cli::add_fit_command(app);
    ascorr::cli::add_stats_command(app);
    ascorr::cli::add_plot_command(app);
    ascorr::cli::add_combine_command(app);
    ascorr::cli::add_align_command(app);
    ascorr::cli::add_interpolate_command(app);
    ascorr::cli::add_import_command(app);
    return checked_exit(run(app, argc, argv));
}
