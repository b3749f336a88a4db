#include <iostream>
#include <memory>

#include "ascorr_host/analysis/interpolate.hpp"
#include "commands.hpp"
#include "number_options.hpp"

namespace ascorr::cli {

void add_interpolate_command(CLI::App& app) {
    auto opt = std::make_shared<host::InterpolateOptions>();
    CLI::App* cmd = app.add_subcommand(
        "interpolate",
        "the combined attitude at given times, on the rotation group, its formal sigma grown between "
        "epochs");
    cmd->add_option("--in", opt->in, "combined file (CSV, as ascorr combine writes it); '-': standard input")
        ->required()
        ->check(non_empty_path());
    cmd->add_option("--at", opt->at, "the times: a CSV whose column t is read, in its order")
        ->required()
        ->check(non_empty_path());
    cmd->add_option("--out", opt->out,
                    "combined file at those times, one row each in --at's order, written whole or not at all; '-': "
                    "standard output")
        ->required()
        ->check(non_empty_path());
    cmd->add_option("--max-gap", opt->max_gap_s,
                    "seconds to the usable epoch on either side beyond which a time gets status 8, [0.001, 1e6] "
                    "(default 10)")
        ->check(real_in(host::kMinMaxGapS, host::kMaxMaxGapS));
    cmd->callback([opt]() {
        host::OutputSet outputs =
            open_run_files({{"--in", &opt->in}, {"--at", &opt->at}}, host::interpolate_outputs(*opt));
        const host::InterpolateSummary s = host::interpolate_file(*opt, outputs);
        outputs.commit();
        std::cerr << "ascorr interpolate: " << opt->out << ": " << host::describe(s) << '\n';
    });
}

}  // namespace ascorr::cli
