#include <iostream>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "ascorr/calib/estimator.hpp"
#include "ascorr_host/analysis/combine.hpp"
#include "ascorr_host/analysis/fit.hpp"
#include "ascorr_host/correct/correct_file.hpp"
#include "ascorr_host/correct/scalar_kind.hpp"
#include "ascorr_host/correct/self_calibration.hpp"
#include "ascorr_host/correct/states_velocity.hpp"
#include "ascorr_host/formats/csv.hpp"
#include "ascorr_host/formats/model_csv.hpp"
#include "ascorr_text/input_error.hpp"
#include "commands.hpp"
#include "number_options.hpp"

namespace ascorr::cli {

namespace {

// --scalar's names: the host's (scalar_kind.hpp), as Python's scalar= takes them.
std::vector<std::pair<std::string, host::ScalarKind>> scalar_names() {
    std::vector<std::pair<std::string, host::ScalarKind>> names;
    for (const host::ScalarName& n : host::kScalarNames) {
        names.emplace_back(std::string(n.name), n.kind);
    }
    return names;
}

// --mountings M --combined A: the combined attitude in the same pass (combine.hpp).
struct CombineTexts {
    std::string mountings;
    std::string combined;
    host::GateOptions gate;
    host::CombinedColumns columns;
};

void add_combine_options(CLI::App& cmd, CombineTexts& t) {
    CLI::Option* mountings =
        cmd.add_option("--mountings", t.mountings,
                       "with --combined: mountings file (CSV chu,qw,qx,qy,qz,sigma_cross,sigma_about)")
            ->check(non_empty_path());
    CLI::Option* combined = cmd.add_option("--combined", t.combined,
                                           "also combine the corrected rows into the bench's attitude per epoch (CSV "
                                           "t,qw,qx,qy,qz,heads,sigma_x,sigma_y,sigma_z,status), committed with --out")
                                ->check(non_empty_path());
    mountings->needs(combined);
    combined->needs(mountings);
    add_gate_options(cmd, t.gate, combined, GateDefault::kGround);
    add_covariance_option(cmd, t.columns)->needs(combined);
}

void correct_and_combine(host::CorrectOptions& opt, CombineTexts& t) {
    host::OutputSet outputs = open_run_files(
        {{"--in", &opt.in}, {"--model", &opt.model}, {"--states", &opt.states}, {"--mountings", &t.mountings}},
        host::correct_and_combine_outputs(opt, t.combined));
    try {  // the mountings first: refused input exits 2 (as combine and align)
        host::refuse_unusable_mountings(host::read_mountings_file(t.mountings), t.mountings, t.gate);
    } catch (const text::InputError& e) {
        throw RefusedInput(e.what());
    } catch (const std::runtime_error& e) {
        throw RefusedInput(e.what());
    }
    const host::CorrectAndCombine r =
        host::correct_and_combine(opt, t.mountings, t.combined, outputs, std::cerr, t.gate, t.columns);
    outputs.commit();
    if (!r.corrected.self_calibration.empty()) {
        std::cerr << "ascorr correct: " << r.corrected.self_calibration << '\n';
    }
    std::cerr << "ascorr correct: " << opt.out << ": " << host::describe(r.corrected) << '\n';
    std::cerr << "ascorr correct: " << t.combined << ": " << host::describe(r.combined) << '\n';
}

}  // namespace

SelfCalibrationOptions add_self_calibration_options(CLI::App& cmd, double& days, std::optional<double>& seconds,
                                                    std::optional<std::array<double, kMaxHeads>>& lag_s,
                                                    bool* lag_auto) {
    SelfCalibrationOptions o{};
    o.lag = cmd.add_option_function<std::string>(
                   "--lag",
                   [&lag_s, lag_auto](const std::string& v) {
                       lag_s = host::parse_lags(v);  // "auto": nullopt
                       if (lag_auto != nullptr) {
                           *lag_auto = !lag_s;
                       }
                   },
                   std::string("with --self-calibrate: the bench's lag in s the estimator learns with, TAU for every "
                               "head or X:TAU,... for the heads named (the others none), each 0 (none) or in [1, "
                               "86400]; the history's models say so (lag_s). ") +
                       (lag_auto != nullptr ? "auto: learnt as the estimator runs, from none (one lag for every "
                                              "head, a third of an octave from 300 to 6048 s). "
                                            : "") +
                       "Default: --model's lag_s, or none")
                ->type_name("LAG")
                ->check([lag_auto](const std::string& v) {
                    return lag_auto != nullptr || v != "auto"
                               ? lag_option_problem(v)
                               : std::string(
                                     "auto is learnt by ascorr correct --self-calibrate, not yet by the "
                                     "target: give TAU or X:TAU,...");
                });
    o.time_constant = cmd.add_option("--time-constant", days,
                                     "with --self-calibrate: the estimator's forgetting time constant in days, " +
                                         host::time_constant_range() + " (default " +
                                         host::number_text(calib::EstimatorConfig{}.time_constant_days) + ")")
                          ->check(real_in(calib::kMinTimeConstantDays, calib::kMaxTimeConstantDays));
    o.orbit_period = cmd.add_option("--orbit-period", seconds,
                                    "with --self-calibrate: the orbit period in s, " + host::orbit_period_range() +
                                        " (default: from the median speed of the first " +
                                        std::to_string(host::kOrbitPeriodRows) + " rows learnt from)")
                         ->check(real_in(static_cast<double>(calib::kMinOrbitPeriodUs) / 1e6,
                                         static_cast<double>(calib::kMaxOrbitPeriodUs) / 1e6));
    return o;
}

void check_needs_self_calibrate(bool self_calibrate, const std::string& model_history,
                                const SelfCalibrationOptions& given) {
    if (!self_calibrate && !model_history.empty()) {
        throw CLI::ValidationError("--model-history", "needs --self-calibrate");
    }
    if (!self_calibrate && given.time_constant->count() > 0) {
        throw CLI::ValidationError("--time-constant", "needs --self-calibrate");
    }
    if (!self_calibrate && given.orbit_period->count() > 0) {
        throw CLI::ValidationError("--orbit-period", "needs --self-calibrate");
    }
    if (!self_calibrate && given.lag->count() > 0) {
        throw CLI::ValidationError("--lag", host::kLagNeedsSelfCalibration);
    }
}

void add_correct_command(CLI::App& app) {
    auto opt = std::make_shared<host::CorrectOptions>();
    CLI::App* cmd =
        app.add_subcommand("correct", "correct every solution of a recorded file (aberration, then thermal)");
    cmd->add_option("--in", opt->in, "solutions file (CSV), raw (a corrected file is refused); '-': standard input")
        ->required()
        ->check(non_empty_path());
    cmd->add_option("--out", opt->out, "corrected file (CSV), written whole or not at all; '-': standard output")
        ->required()
        ->check(non_empty_path());
    cmd->add_option("--model", opt->model, "thermal model file (CSV); without it, no thermal stage")
        ->check(non_empty_path());
    cmd->add_flag("!--no-aberration", opt->aberration, "skip the aberration stage");
    cmd->add_flag("!--no-thermal", opt->thermal, "skip the thermal stage");
    cmd->add_option("--scalar", opt->scalar, "scalar type of the core: double (default), float or fixed (any case)")
        ->transform(one_of(scalar_names()))
        ->type_name("NAME");
    cmd->add_flag("--skip-bad", opt->skip_bad,
                  "skip malformed rows of --in and --states (each is reported) instead of stopping");
    cmd->add_option("--states", opt->states,
                    "spacecraft states (CSV t,x,y,z,vx,vy,vz): the velocity of rows without vx,vy,vz, computed by "
                    "the on-board service in the --scalar chosen; a file of which no state is accepted fails the run")
        ->check(non_empty_path());
    cmd->add_option("--states-frame", opt->states_gcrs,
                    "frame of the states: itrf (GNSS, default) or gcrs (uplinked), any case")
        ->transform(one_of<bool>({{"itrf", false}, {"gcrs", true}}))
        ->type_name("NAME");
    cmd->add_option("--max-propagation", opt->max_propagation_s,
                    "seconds a state may be propagated, [1e-06, 604800] (default 21600); later rows get status 4+512")
        ->check(real_in(host::kMinPropagationS, host::kMaxPropagationLimitS));
    cmd->add_flag("--self-calibrate", opt->self_calibrate,
                  "estimate the thermal model from the rows themselves with the on-board estimator, causally in time "
                  "order, starting from --model (version 0) or from none (rows before the first model: status 256)");
    cmd->add_option("--model-history", opt->model_history,
                    "with --self-calibrate: write every model that became active (CSV "
                    "t,version,chu,axis,c0..c3,crc32c,tt_us,origin; common_rotation with --combined, lag_s with a lag, "
                    "sun_x,sun_y,sun_z with a Sun term)")
        ->check(non_empty_path());
    const SelfCalibrationOptions self_cal =
        add_self_calibration_options(*cmd, opt->time_constant_days, opt->orbit_period_s, opt->lag_s, &opt->lag_auto);
    CLI::Option* sun_term =
        cmd->add_option(
               "--sun-term", opt->sun_auto,
               "with --self-calibrate: auto (the Sun term, the rotation with the Sun's direction in the "
               "head's frame, learnt as the estimator runs and taken when it predicts the IBAs better; the "
               "history's sun_x, sun_y, sun_z; the rows corrected with it in the run's scalar) or none (default)")
            ->transform(one_of<bool>({{"auto", true}, {"none", false}}))
            ->type_name("NAME");
    auto combine = std::make_shared<CombineTexts>();
    add_combine_options(*cmd, *combine);
    cmd->callback([opt, self_cal, combine, sun_term]() {
        check_needs_self_calibrate(opt->self_calibrate, opt->model_history, self_cal);
        if (!opt->self_calibrate && sun_term->count() > 0) {
            throw CLI::ValidationError("--sun-term", host::kSunTermNeedsSelfCalibration);
        }
        if (!combine->combined.empty()) {
            correct_and_combine(*opt, *combine);
            return;
        }
        host::OutputSet outputs = open_run_files(
            {{"--in", &opt->in}, {"--model", &opt->model}, {"--states", &opt->states}}, host::correct_outputs(*opt));
        const host::CorrectSummary s = host::correct_file(*opt, outputs, std::cerr);
        outputs.commit();
        if (!s.self_calibration.empty()) {
            std::cerr << "ascorr correct: " << s.self_calibration << '\n';
        }
        std::cerr << "ascorr correct: " << opt->out << ": " << host::describe(s) << '\n';
    });
}

}  // namespace ascorr::cli
