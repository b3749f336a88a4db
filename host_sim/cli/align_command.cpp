#include <iostream>
#include <memory>

#include "ascorr_host/analysis/align.hpp"
#include "ascorr_host/analysis/combine.hpp"
#include "ascorr_text/input_error.hpp"
#include "commands.hpp"
#include "number_options.hpp"

namespace ascorr::cli {

void add_align_command(CLI::App& app) {
    auto opt = std::make_shared<host::AlignOptions>();
    CLI::App* cmd = app.add_subcommand(
        "align", "estimate each head's mounting and noise from the data, keeping the CRF of the given mountings");
    cmd->add_option("--in", opt->in,
                    "corrected file (CSV; or a solutions file: the raw attitudes as they are); '-': standard input")
        ->required()
        ->check(non_empty_path());
    cmd->add_option("--mountings", opt->mountings, "mountings file (CSV): chu,qw,qx,qy,qz[,sigma_cross,sigma_about]")
        ->required()
        ->check(non_empty_path());
    cmd->add_option("--out", opt->out, "mountings file to write, with the estimated sigmas (CSV)")
        ->required()
        ->check(non_empty_path())
        ->check(not_standard_output("standard output carries align's report; give a path"));
    cmd->add_option("--from", opt->from, "start of the period, s since J2000 TT")->check(real_number());
    cmd->add_option("--to", opt->to, "end of the period, s since J2000 TT")->check(real_number());
    cmd->add_option("--noise-window", opt->noise_window_s,
                    "window (s) of the slowly varying mean the noise is measured about, 0: one mean over the period "
                    "(default " +
                        std::to_string(static_cast<int>(host::kDefaultNoiseWindowS)) + ")")
        ->check(zero_or_in(host::kMinNoiseWindowS, host::kMaxNoiseWindowS));
    cmd->add_option(
           "--min-epochs", opt->min_epochs,
           "fewest epochs with two or more usable heads (default " + std::to_string(host::kMinAlignEpochs) + ")")
        ->transform(integer_in<std::size_t>(2));
    add_gate_options(*cmd, opt->gate, nullptr, GateDefault::kGround);
    cmd->callback([opt]() {
        host::OutputSet outputs = open_run_files({{"--in", &opt->in}, {"--mountings", &opt->mountings}},
                                                 {{"--out", opt->out}, host::kStandardOutput});
        try {
            const host::AlignReport r = host::align_file(*opt, outputs);
            outputs[host::kStandardOutput.option].write(host::describe(r));
            outputs.commit();
            std::cerr << "ascorr align: mountings written to " << opt->out << '\n';
        } catch (const text::InputError& e) {
            throw RefusedInput(e.what());
        } catch (const host::AlignRefused& e) {
            throw RefusedInput(e.what());
        }
    });
}

}  // namespace ascorr::cli
