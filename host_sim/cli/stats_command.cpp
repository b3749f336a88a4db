#include <iostream>
#include <memory>

#include "ascorr_host/analysis/stats.hpp"
#include "commands.hpp"
#include "number_options.hpp"

namespace ascorr::cli {

void add_stats_command(CLI::App& app) {
    auto opt = std::make_shared<host::StatsOptions>();
    auto json = std::make_shared<bool>(false);
    CLI::App* cmd = app.add_subcommand("stats", "IBA RMS per pair for the original, aberration and thermal stages");
    cmd->add_option("--in", opt->in,
                    "solutions file (CSV), raw; a corrected file is shown as it is, under \"original\", and refused "
                    "with --model (never corrected twice)")
        ->required()
        ->check(non_empty_path());
    cmd->add_option("--model", opt->model, "thermal model file (CSV); without it the thermal stage is null")
        ->check(non_empty_path());
    cmd->add_option("--from", opt->from, "first epoch, s since J2000 TT")->check(real_number());
    cmd->add_option("--to", opt->to, "last epoch, s since J2000 TT")->check(real_number());
    cmd->add_flag("--json", *json, "print JSON (docs/contract.md) instead of the table");
    cmd->callback([opt, json]() {
        host::OutputSet outputs =
            open_run_files({{"--in", &opt->in}, {"--model", &opt->model}}, {host::kStandardOutput});
        const host::StatsResult r = host::compute_stats(*opt, std::cerr);
        outputs[host::kStandardOutput.option].write(*json ? host::stats_json(r) : host::stats_table(r));
        outputs.commit();
    });
}

}  // namespace ascorr::cli
