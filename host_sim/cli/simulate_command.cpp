#include <iostream>
#include <memory>

#include "ascorr_host/analysis/simulate.hpp"
#include "commands.hpp"
#include "number_options.hpp"

namespace ascorr::cli {

void add_simulate_command(CLI::App& app) {
    auto opt = std::make_shared<host::SimulateOptions>();
    CLI::App* cmd =
        app.add_subcommand("simulate", "write a Swarm-like recorded data set, its truth model and noise floor");
    cmd->add_option("--out", opt->out,
                    "solutions file (CSV); beside it OUT.truth.csv, OUT.floor.json and OUT.heaters.csv (not '-')")
        ->required()
        ->check(non_empty_path())
        ->check(not_standard_output("simulate writes four files (OUT, OUT.truth.csv, OUT.floor.json, "
                                    "OUT.heaters.csv); give a path"));
    cmd->add_option("--days", opt->days, "length of the mission in days, (0, 36600] (default 920, 2.5 years)")
        ->check(real_in(0.0, 36600.0, End::kOpen));
    cmd->add_option("--step", opt->step_s, "time between epochs in s, 1..600 (default 60)")->check(real_in(1.0, 600.0));
    cmd->add_option("--seed", opt->seed, "random seed (default 1); the same seed gives the same file")
        ->transform(integer_in<std::uint64_t>());
    cmd->add_option("--truth", opt->truth, "truth thermal model (CSV); default: the paper's Table 2, built in")
        ->check(non_empty_path());
    cmd->add_option("--start", opt->start_t, "first epoch, s since J2000 TT (default 2014-06-16)")
        ->check(real_number());
    cmd->callback([opt]() {
        read_dash_from_standard_input({{"--truth", &opt->truth}});
        const host::SimulateSummary s = host::simulate(*opt);
        std::cerr << "ascorr simulate: " << opt->out << ": " << host::describe(s) << '\n';
    });
}

}  // namespace ascorr::cli
