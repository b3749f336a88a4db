// ascorr: thermal and aberration correction of µASC attitude solutions.
//
// Exit status: 0 when every output is complete; 1 for bad input or an I/O
// error (the message names file, line and column); 2 for a usage error and
// input a command refuses as such (align); 3
// when the outputs are complete but say the run failed (replay: the target's
// answers, models or report differ from the host's);
// ended by SIGINT, SIGTERM, SIGHUP or SIGPIPE: that signal (128 + signal in a
// shell), with no temporary output left behind.
#include <cstdio>
#include <exception>
#include <iostream>
#include <string>

#include "ascorr_host/formats/atomic_file.hpp"
#include "ascorr_host/version.hpp"
#include "commands.hpp"

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
