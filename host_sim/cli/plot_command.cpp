#include <iostream>
#include <memory>

#include "ascorr_host/analysis/plot.hpp"
#include "commands.hpp"
#include "number_options.hpp"

namespace ascorr::cli {

void add_plot_command(CLI::App& app) {
    auto opt = std::make_shared<host::PlotOptions>();
    CLI::App* cmd = app.add_subcommand("plot", "PNG of the IBA per pair for the three stages (gnuplot)");
    cmd->add_option("--in", opt->in, "solutions file (CSV), raw (a corrected file is refused: plot applies the stages)")
        ->required()
        ->check(non_empty_path());
    cmd->add_option("--model", opt->model, "thermal model file (CSV)")->required()->check(non_empty_path());
    cmd->add_option("--out", opt->out, "PNG file; '-': standard output")->required()->check(non_empty_path());
    CLI::Option* from =
        cmd->add_option("--from", opt->period_from, "start of the modelling period to shade, s since J2000 TT")
            ->check(real_number());
    CLI::Option* to = cmd->add_option("--to", opt->period_to, "end of the modelling period to shade, s since J2000 TT")
                          ->check(real_number());
    from->needs(to);
    to->needs(from);
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
    cmd->callback([opt]() {
        host::OutputSet outputs = open_run_files({{"--in", &opt->in}, {"--model", &opt->model}}, {{"--out", opt->out}});
        host::plot_iba(*opt, outputs, std::cerr);
        outputs.commit();
        std::cerr << "ascorr plot: " << opt->out << '\n';
    });
}

}  // namespace ascorr::cli
