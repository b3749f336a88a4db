#include <iostream>
#include <memory>

#include "ascorr_host/analysis/combined_stats.hpp"
#include "ascorr_host/analysis/stats.hpp"
#include "commands.hpp"
#include "number_options.hpp"

namespace ascorr::cli {

void add_stats_command(CLI::App& app) {
    auto opt = std::make_shared<host::StatsOptions>();
    auto combined = std::make_shared<host::CombinedStatsOptions>();
    auto json = std::make_shared<bool>(false);
    CLI::App* cmd = app.add_subcommand("stats", "IBA RMS per pair for the original, aberration and thermal stages");
    CLI::Option* in =
        cmd->add_option("--in", opt->in,
                        "solutions file (CSV), raw; a corrected file is shown as it is, under \"original\", and "
                        "refused with --model (never corrected twice)")
            ->check(non_empty_path());
    CLI::Option* model =
        cmd->add_option("--model", opt->model, "thermal model file (CSV); without it the thermal stage is null")
            ->check(non_empty_path());
    CLI::Option* noise =
        cmd->add_option("--noise-iba", opt->noise_iba,
                        "simulate's OUT.noise-iba.csv: also the systematic IBA residual per pair and stage (the IBA "
                        "minus the noise-only IBA, RMS about the mean over the epochs both have)")
            ->check(non_empty_path());
    CLI::Option* from = cmd->add_option("--from", opt->from, "first epoch, s since J2000 TT")->check(real_number());
    CLI::Option* to = cmd->add_option("--to", opt->to, "last epoch, s since J2000 TT")->check(real_number());
    CLI::Option* comb =
        cmd->add_option("--combined", combined->combined,
                        "instead of --in: a combined file's report (counts per head set; with --truth-attitude its "
                        "error per CRF axis and the steps at head-set changes)")
            ->check(non_empty_path());
    CLI::Option* truth = cmd->add_option("--truth-attitude", combined->truth,
                                         "with --combined: the true CRF attitude (CSV t,qw,qx,qy,qz, e.g. "
                                         "simulate's OUT.attitude.csv)")
                             ->check(non_empty_path());
    in->excludes(comb);
    for (CLI::Option* o : {model, from, to, noise}) {
        o->excludes(comb);
    }
    truth->needs(comb);
    cmd->add_flag("--json", *json, "print JSON (docs/contract.md) instead of the table");
    cmd->callback([opt, combined, json, in, comb]() {
        if (in->count() == 0 && comb->count() == 0) {
            throw CLI::RequiredError("--in (or --combined)");
        }
        if (comb->count() != 0) {
            host::OutputSet outputs = open_run_files(
                {{"--combined", &combined->combined}, {"--truth-attitude", &combined->truth}}, {host::kStandardOutput});
            const host::CombinedStats s = host::combined_stats(*combined);
            outputs[host::kStandardOutput.option].write(*json ? host::combined_stats_json(s)
                                                              : host::combined_stats_table(s));
            outputs.commit();
            return;
        }
        host::OutputSet outputs = open_run_files(
            {{"--in", &opt->in}, {"--model", &opt->model}, {"--noise-iba", &opt->noise_iba}}, {host::kStandardOutput});
        const host::StatsResult r = host::compute_stats(*opt, std::cerr);
        outputs[host::kStandardOutput.option].write(*json ? host::stats_json(r) : host::stats_table(r));
        outputs.commit();
    });
}

}  // namespace ascorr::cli
