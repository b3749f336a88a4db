#include <iostream>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "ascorr_host/correct/states_velocity.hpp"
#include "ascorr_host/formats/model_csv.hpp"
#include "ascorr_host/link/qemu_targets.hpp"
#include "ascorr_host/link/replay.hpp"
#include "commands.hpp"
#include "number_options.hpp"

namespace ascorr::cli {

void add_replay_command(CLI::App& app) {
    auto opt = std::make_shared<host::ReplayOptions>();
    auto speed = std::make_shared<std::string>("max");
    CLI::App* cmd = app.add_subcommand("replay", "replay a recorded file through a target over the serial link");
    // The QEMU boards come from toolchain/targets.txt (the generated ascorr_host/link/qemu_targets.hpp).
    cmd->add_option("--target", opt->target,
                    host::qemu_target_choices() + ", " + host::kLoopbackFloat + ", " + host::kLoopbackFixed +
                        ", or a serial device such as /dev/ttyUSB0")
        ->required();
    cmd->add_option("--firmware", opt->firmware, "qemu targets: the link image (default: the one of this build)")
        ->check(non_empty_path());
    cmd->add_option("--in", opt->in, "solutions file (CSV); '-': standard input")->required()->check(non_empty_path());
    cmd->add_option("--model", opt->model,
                    "thermal model file (CSV); with --self-calibrate the estimator's first model (optional)")
        ->check(non_empty_path());
    cmd->add_option("--out", opt->out, "corrected file (CSV) as returned by the target")
        ->required()
        ->check(non_empty_path())
        ->check(not_standard_output("standard output carries replay's summary (JSON); give a path"));
    cmd->add_option("--states", opt->states,
                    "spacecraft states (CSV t,x,y,z,vx,vy,vz), sent to the target in time order with the solutions; "
                    "the target computes the velocity of rows without vx,vy,vz; a file of which no state is accepted "
                    "fails the run")
        ->check(non_empty_path());
    cmd->add_option("--states-frame", opt->states_gcrs, "frame of the states: itrf (GNSS, default) or gcrs, any case")
        ->transform(one_of<bool>({{"itrf", false}, {"gcrs", true}}))
        ->type_name("NAME");
    cmd->add_option("--max-propagation", opt->max_propagation_s,
                    "seconds the target's velocity service may propagate a state, [1e-06, 604800] (default: its "
                    "firmware's, 21600); later rows get status 4+512")
        ->check(real_in(host::kMinPropagationS, host::kMaxPropagationLimitS));
    cmd->add_flag("--self-calibrate", opt->self_calibrate,
                  "the target runs its estimator of the thermal model on the solutions, starting from --model or from "
                  "none; its answers, model versions, models and final report are compared bit for bit with the "
                  "host's run of ascorr correct --self-calibrate in the target's scalar (with a lag, over the rows "
                  "lagged as the target lags them)");
    cmd->add_option("--model-history", opt->model_history,
                    "with --self-calibrate: write every model the target made active (CSV, as ascorr correct's)")
        ->check(non_empty_path());
    const SelfCalibrationOptions self_cal =
        add_self_calibration_options(*cmd, opt->time_constant_days, opt->orbit_period_s, opt->lag_s, nullptr);
    CLI::Option* sun_term =
        cmd->add_option("--sun-term", opt->sun_auto,
                        "with --self-calibrate: auto (the target learns the Sun term beside its estimator, one "
                        "epoch per 120 s, and each model version takes the term taken when it becomes active; "
                        "compared bit for bit with the host's run thinned alike) or none (default)")
            ->transform(one_of<bool>({{"auto", true}, {"none", false}}))
            ->type_name("NAME");
    CLI::Option* mountings =
        cmd->add_option("--mountings", opt->mountings,
                        "with --combined: mountings file (CSV chu,qw,qx,qy,qz,sigma_cross,sigma_about), built into "
                        "the target's combiner")
            ->check(non_empty_path());
    CLI::Option* combined =
        cmd->add_option("--combined", opt->combined,
                        "the target also combines each epoch into the bench's attitude; written here (CSV, as "
                        "ascorr combine's) and compared with the host's bit for bit")
            ->check(non_empty_path());
    mountings->needs(combined);
    combined->needs(mountings);
    add_gate_options(*cmd, opt->gate, combined, GateDefault::kFlight);
    cmd->add_option("--inject-errors", opt->inject_errors, "fraction of frames to fault in each direction")

        ->check(real_in(0.0, 0.5));
    cmd->add_option("--speed", *speed, "realtime (paced by t) or max (default), any case")
        ->transform(one_of<std::string>({{"realtime", "realtime"}, {"max", "max"}}))
        ->type_name("NAME");
    cmd->add_option("--timeout-ms", opt->timeout_ms, "answer time-out before a resend (default: 20 qemu, 500 serial)")
        ->transform(integer_in<int>(1, 60000));
    cmd->add_option("--seed", opt->seed, "seed of the fault injection")->transform(integer_in<std::uint64_t>());
    cmd->add_option("--baud", opt->baud, "serial baud rate (serial devices)")->transform(integer_in<unsigned>());
    cmd->callback([opt, speed, self_cal, sun_term]() {
        opt->realtime = *speed == "realtime";
        if (!opt->self_calibrate && opt->model.empty()) {
            throw CLI::RequiredError("--model (or --self-calibrate)");
        }
        check_needs_self_calibrate(opt->self_calibrate, opt->model_history, self_cal);
        if (!opt->self_calibrate && sun_term->count() > 0) {
            throw CLI::ValidationError("--sun-term", host::kSunTermNeedsSelfCalibration);
        }
        std::vector<host::NamedPath> outputs = host::replay_outputs(*opt);
        outputs.push_back(host::kStandardOutput);  // the summary
        host::OutputSet files = open_run_files({{"--in", &opt->in},
                                                {"--model", &opt->model},
                                                {"--states", &opt->states},
                                                {"--firmware", &opt->firmware},
                                                {"--mountings", &opt->mountings}},
                                               std::move(outputs));
        const host::ReplaySummary s = host::replay(*opt, files, std::cerr);
        files[host::kStandardOutput.option].write(host::to_json(s) + "\n");
        files.commit();
        if (!host::agrees(s)) {
            throw FailedResult(host::disagreement(s));
        }
    });
}

}  // namespace ascorr::cli
