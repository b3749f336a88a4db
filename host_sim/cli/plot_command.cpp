#include <iostream>
#include <memory>

#include "ascorr_host/analysis/plot.hpp"
#include "commands.hpp"
#include "number_options.hpp"

namespace ascorr::cli {

void add_plot_command(CLI::App& app) {
    auto opt = std::make_shared<host::PlotOptions>();
    auto combined = std::make_shared<host::CombinedPlotOptions>();
    CLI::App* cmd = app.add_subcommand("plot", "PNG of the IBA per pair for the three stages (gnuplot)");
    CLI::Option* in =
        cmd->add_option("--in", opt->in,
                        "solutions file (CSV), raw (a corrected file is refused: plot applies the stages)")
            ->check(non_empty_path());
    CLI::Option* model = cmd->add_option("--model", opt->model, "thermal model file (CSV)")->check(non_empty_path());
    CLI::Option* comb = cmd->add_option("--combined", combined->combined,
                                        "instead of --in and --model: a combined file's error against "
                                        "--truth-attitude in the window --window-from/--window-to, per CRF axis, "
                                        "coloured by head set")
                            ->check(non_empty_path());
    CLI::Option* truth =
        cmd->add_option("--truth-attitude", combined->truth, "with --combined: the true CRF attitude (t,qw,qx,qy,qz)")
            ->check(non_empty_path());
    in->excludes(comb);
    model->excludes(comb);
    comb->needs(truth);
    truth->needs(comb);
    cmd->add_option("--out", opt->out, "PNG file; '-': standard output")->required()->check(non_empty_path());
    CLI::Option* from =
        cmd->add_option("--from", opt->period_from, "start of the modelling period to shade, s since J2000 TT")
            ->check(real_number());
    CLI::Option* to = cmd->add_option("--to", opt->period_to, "end of the modelling period to shade, s since J2000 TT")
                          ->check(real_number());
    from->needs(to);
    to->needs(from);
    CLI::Option* temperatures =
        cmd->add_flag("--temperatures", opt->temperatures,
                      "add panels of T_CHU (A, B, C), T029 and T032 on the same time axis (the paper's Fig. 4)");
    CLI::Option* wfrom = cmd->add_option("--window-from", opt->window_from,
                                         "draw only from this epoch (s since J2000 TT), IBA as 200 s running means")
                             ->check(real_number());
    CLI::Option* wto = cmd->add_option("--window-to", opt->window_to, "draw only up to this epoch (s since J2000 TT)")
                           ->check(real_number());
    cmd->add_option("--width", opt->width, "figure width in pixels, 400..4000 (default 1400; panels 2/7 of it high)")
        ->transform(integer_in<int>(400, 4000));
    wfrom->needs(wto);
    wto->needs(wfrom);
    for (CLI::Option* o : {from, to, temperatures}) {
        o->excludes(comb);
    }
    cmd->callback([opt, combined, comb, in, model]() {
        if (comb->count() != 0) {
            if (!opt->window_from || !opt->window_to) {
                throw CLI::RequiredError("--window-from and --window-to (with --combined)");
            }
            combined->out = opt->out;
            combined->from = *opt->window_from;
            combined->to = *opt->window_to;
            combined->width = opt->width;
            read_dash_from_standard_input(
                {{"--combined", &combined->combined}, {"--truth-attitude", &combined->truth}});
            host::plot_combined(*combined, std::cerr);
            std::cerr << "ascorr plot: " << opt->out << '\n';
            return;
        }
        if (in->count() == 0 || model->count() == 0) {
            throw CLI::RequiredError(in->count() == 0 ? "--in" : "--model");
        }
        read_dash_from_standard_input({{"--in", &opt->in}, {"--model", &opt->model}});
        host::plot_iba(*opt, std::cerr);
        std::cerr << "ascorr plot: " << opt->out << '\n';
    });
}

}  // namespace ascorr::cli
