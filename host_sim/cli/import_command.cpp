#include <iostream>
#include <memory>

#include "ascorr_host/formats/gracefo.hpp"
#include "commands.hpp"
#include "number_options.hpp"

namespace ascorr::cli {

namespace {

void add_gracefo_command(CLI::App& import) {
    auto opt = std::make_shared<host::GracefoOptions>();
    CLI::App* cmd = import.add_subcommand(
        "gracefo",
        "GRACE Follow-On Level-1 star-camera data (SCA1A, QSA1B; TIM1B, CLK1B, SCA1B) in this contract's "
        "files");
    cmd->add_option("--sca1a", opt->sca1a,
                    "SCA1A file(s) of one satellite (repeatable; taken in the order of their first records)")
        ->required()
        ->check(CLI::ExistingFile);
    cmd->add_option("--qsa1b", opt->qsa1b, "QSA1B file: the heads' mountings")->required()->check(CLI::ExistingFile);
    cmd->add_option("--tim1b", opt->tim1b,
                    "TIM1B file(s): OBC time to receiver time (repeatable: several days; without: OBC time taken as "
                    "receiver time)")
        ->check(CLI::ExistingFile);
    cmd->add_option("--clk1b", opt->clk1b,
                    "CLK1B file(s): receiver time to GPS time (repeatable; without: receiver time taken as GPS)")
        ->check(CLI::ExistingFile);
    CLI::Option* sca1b =
        cmd->add_option("--sca1b", opt->sca1b, "SCA1B file: JPL's combined attitude, written to --reference")
            ->check(CLI::ExistingFile);
    cmd->add_option("--out", opt->out, "solutions file to write (CSV)")
        ->required()
        ->check(non_empty_path())
        ->check(not_standard_output("import writes two or three files; give paths"));
    cmd->add_option("--mountings", opt->mountings, "mountings file to write (CSV, from QSA1B, without sigmas)")
        ->required()
        ->check(non_empty_path())
        ->check(not_standard_output("import writes two or three files; give paths"));
    CLI::Option* reference =
        cmd->add_option("--reference", opt->reference, "attitude file to write from --sca1b (CSV t,qw,qx,qy,qz)")
            ->check(non_empty_path())
            ->check(not_standard_output("import writes two or three files; give paths"));
    sca1b->needs(reference);
    reference->needs(sca1b);
    cmd->add_option("--time-offset", opt->time_offset_s,
                    "seconds added to every SCA1A time, [-10, 10] (default 0: no latency is observable on the public "
                    "sample; tools/gracefo/calibrate_time_offset.py measures it on other data)")
        ->check(real_in(-host::kMaxTimeOffsetS, host::kMaxTimeOffsetS));
    cmd->callback([opt]() {
        host::OutputSet outputs(host::gracefo_outputs(*opt), host::gracefo_inputs(*opt));
        const host::GracefoSummary s = host::import_gracefo_files(*opt, outputs);
        outputs.commit();
        std::cerr << "ascorr import gracefo: " << host::describe(s) << '\n';
    });
}

}  // namespace

void add_import_command(CLI::App& app) {
    CLI::App* import = app.add_subcommand("import", "real flight data in this contract's files");
    import->require_subcommand(1);
    add_gracefo_command(*import);
}

}  // namespace ascorr::cli
