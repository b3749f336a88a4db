#include <iostream>
#include <memory>

#include "ascorr_host/analysis/align.hpp"
#include "ascorr_host/analysis/combine.hpp"
#include "ascorr_text/input_error.hpp"
#include "commands.hpp"
#include "number_options.hpp"

namespace ascorr::cli {

void add_gate_options(CLI::App& cmd, host::GateOptions& gate, CLI::Option* combined, GateDefault floor) {
    CLI::Option* k =
        cmd.add_option_function<double>(
               "--gate-sigmas", [&gate](const double& v) { gate.sigmas = v; },
               "the consistency gate: a head is left out beyond this many sigmas of its disagreement with the others, "
               "[3, 100] (default 6)")
            ->check(real_in(combine::kMinGateSigmas, combine::kMaxGateSigmas));
    CLI::Option* f = cmd.add_option_function<double>(
                            "--gate-floor", [&gate](const double& v) { gate.floor_arcsec = v; },
                            std::string("the consistency gate's floor in arcsec, [1, 3600], added to the heads' "
                                        "noise (default: ") +
                                (floor == GateDefault::kFlight
                                     ? "10, the flight's: the mountings in flash are pre-flight)"
                                     : "2 for rows with the aberration and the thermal stage applied, 10 otherwise)"))
                         ->check(real_in(combine::kMinGateFloorArcsec, combine::kMaxGateFloorArcsec));
    if (combined != nullptr) {
        k->needs(combined);
        f->needs(combined);
    }
}

CLI::Option* add_covariance_option(CLI::App& cmd, host::CombinedColumns& columns) {
    return cmd.add_flag("--covariance", columns.covariance,
                        "also write the formal covariance's off-diagonal, columns cov_xy,cov_xz,cov_yz (arcsec^2; "
                        "the diagonal's roots are sigma_x,sigma_y,sigma_z)");
}

void add_combine_command(CLI::App& app) {
    auto opt = std::make_shared<host::CombineOptions>();
    CLI::App* cmd = app.add_subcommand(
        "combine", "one attitude of the bench (CRF) per epoch from the heads' solutions, weighted by their noise");
    cmd->add_option("--in", opt->in,
                    "corrected file (CSV; or a solutions file: its attitudes as they are); '-': standard input")
        ->required()
        ->check(non_empty_path());
    cmd->add_option("--mountings", opt->mountings,
                    "mountings file (CSV chu,qw,qx,qy,qz[,sigma_cross,sigma_about]: q_chu_crf and each head's noise "
                    "in arcsec; without the sigmas the noise is estimated from --in and reported)")
        ->required()
        ->check(non_empty_path());
    cmd->add_option("--out", opt->out,
                    "combined file (CSV t,qw,qx,qy,qz,heads,sigma_x,sigma_y,sigma_z,status), written whole or not at "
                    "all; '-': standard output")
        ->required()
        ->check(non_empty_path());
    add_gate_options(*cmd, opt->gate, nullptr, GateDefault::kGround);
    add_covariance_option(*cmd, opt->columns);
    cmd->callback([opt]() {
        host::OutputSet outputs =
            open_run_files({{"--in", &opt->in}, {"--mountings", &opt->mountings}}, host::combine_outputs(*opt));
        try {
            const host::CombineSummary s = host::combine_file(*opt, outputs, std::cerr);
            outputs.commit();
            std::cerr << "ascorr combine: " << opt->out << ": " << host::describe(s) << '\n';
        } catch (const text::InputError& e) {
            throw RefusedInput(e.what());  // as align: refused input exits 2
        } catch (const host::AlignRefused& e) {
            throw RefusedInput(std::string(e.what()) + " (estimating the heads' noise: the mountings have no sigmas)");
        }
    });
}

}  // namespace ascorr::cli
