#include <cmath>
#include <iostream>
#include <memory>

#include "ascorr_host/analysis/fit.hpp"
#include "commands.hpp"
#include "number_options.hpp"

namespace ascorr::cli {

std::string lag_option_problem(const std::string& text) {
    try {
        (void)host::parse_lags(text);
        return {};
    } catch (const host::FitRefused& e) {
        return e.what();
    }
}

void add_fit_command(CLI::App& app) {
    auto opt = std::make_shared<host::FitOptions>();
    auto frame = std::make_shared<std::string>(host::frame_heads_text(host::kDefaultFrameHeads));
    auto heads = std::make_shared<std::string>();
    CLI::App* cmd = app.add_subcommand("fit", "fit the thermal model on a modelling period (the paper's procedure)");
    cmd->add_option("--in", opt->in, "solutions file (CSV); '-': standard input")->required()->check(non_empty_path());
    cmd->add_option("--out", opt->out, "model file to write (CSV)")
        ->required()
        ->check(non_empty_path())
        ->check(not_standard_output("standard output carries fit's report; give a path"));
    cmd->add_option("--from", opt->from, "start of the modelling period, s since J2000 TT")->check(real_number());
    cmd->add_option("--to", opt->to, "end of the modelling period, s since J2000 TT")->check(real_number());
    cmd->add_option("--min-days", opt->min_span_days, "shortest accepted period in days, above 0 (default 267)")
        ->check(real_in(0.0, HUGE_VAL, End::kOpen, End::kOpen));
    cmd->add_option("--min-orbits", opt->min_orbits, "fewest accepted orbit averages (default 100)")
        ->transform(integer_in<std::size_t>());
    cmd->add_option("--max-condition", opt->max_condition, "largest accepted condition number, above 0 (default 1e6)")
        ->check(real_in(0.0, HUGE_VAL, End::kOpen));
    cmd->add_option("--orbit-period", opt->orbit_period_s, "orbit period in s, 600..86400 (default: from the velocity)")
        ->check(real_in(600.0, 86400.0));
    cmd->add_option("--terms", opt->terms, "linear (default) or quadratic: also c1_2, c2_2, c3_2 (any case)")
        ->transform(one_of<host::Terms>({{"linear", host::Terms::kLinear}, {"quadratic", host::Terms::kQuadratic}}))
        ->type_name("NAME");
    cmd->add_option("--holdout", opt->holdout,
                    "fraction of the period (its end) held out for the model-selection report, 0..0.5 (default 0.25)")
        ->check(real_in(0.0, 0.5));
    cmd->add_option("--min-temperature-range", opt->min_temperature_range_c,
                    "smallest range (degC) of each regressor for quadratic terms, 0 or more (default 2)")
        ->check(real_in(0.0, HUGE_VAL, End::kClosed, End::kOpen));
    cmd->add_option("--frame-heads", *frame,
                    "the two heads of frame F (eqs. 1-3), in heads' order, the first in A's role, the second in C's "
                    "(default " +
                        host::frame_heads_text(host::kDefaultFrameHeads) +
                        "); without --heads the fit's heads are A, B, C, these two and every head with rows")
        ->check(head_letters_in(2, 2));
    cmd->add_option("--heads", *heads,
                    "the heads to fit, two or more in heads' order, frame F's among them; rows of others are left "
                    "out (default: A, B, C, F's two and every head with rows)")
        ->check(head_letters_in(2, kMaxHeads));
    auto mountings = std::make_shared<std::string>();
    cmd->add_option("--mountings", *mountings,
                    "mountings file (CSV, with sigma_cross,sigma_about): the common rotation, which no IBA sees, is "
                    "then fixed so that the heads' combined attitude moves least (--common-rotation combined)")
        ->check(non_empty_path());
    auto rule = std::make_shared<std::string>();
    cmd->add_option("--common-rotation", *rule,
                    "the rule for the rotation common to all heads: combined (default with --mountings: the "
                    "combined attitude moves least), smallest (default without: the smallest corrections), rigid-X "
                    "(head X taken as rigid to the bench)")
        ->type_name("RULE")
        ->check([](const std::string& v) {
            return host::common_rotation_named(v) ? std::string() : "expected " + host::common_rotation_choices();
        });
    auto lag = std::make_shared<std::string>();
    cmd->add_option("--lag", *lag,
                    "the bench's lag in s: auto (default: chosen per head on the held-out part, none unless the data "
                    "support one), TAU for every head, or X:TAU,... for the heads named (the others none); each TAU "
                    "0 (none) or in [1, 86400]. The terms take each head's temperatures through a first-order lag "
                    "of TAU, and the model says so (lag_s), for correct")
        ->type_name("LAG")
        ->check([](const std::string& v) { return lag_option_problem(v); });
    cmd->add_option("--sun-term", opt->sun_term,
                    "auto (default: the Sun term, the rotation with the Sun's direction in the head's frame, fitted "
                    "inside the orbit and taken when the held-out part supports it; the model's sun_x, sun_y, "
                    "sun_z) or none")
        ->transform(
            one_of<host::SunTermChoice>({{"auto", host::SunTermChoice::kAuto}, {"none", host::SunTermChoice::kNone}}))
        ->type_name("NAME");
    cmd->callback([opt, frame, heads, mountings, rule, lag]() {
        if (!lag->empty()) {
            opt->lag_s = host::parse_lags(*lag);  // checked already; "auto": nullopt
        }
        opt->frame_heads = {head_index((*frame)[0]), head_index((*frame)[1])};  // checked already
        if (!heads->empty()) {
            opt->heads = host::parse_head_letters(*heads);  // checked already
            if ((host::frame_set(opt->frame_heads) & ~*opt->heads) != 0U) {
                throw CLI::ValidationError("--heads " + *heads,
                                           "frame F's heads " + *frame + " (--frame-heads) are not among them");
            }
        }
        if (!rule->empty()) {
            opt->common_rotation.emplace();
            static_cast<host::CommonRotationId&>(*opt->common_rotation) = *host::common_rotation_named(*rule);
        }
        host::OutputSet outputs = open_run_files({{"--in", &opt->in}, {"--mountings", mountings.get()}},
                                                 {{"--out", opt->out}, host::kStandardOutput});
        if (!mountings->empty()) {
            opt->mountings = host::read_mountings_file(*mountings);
            opt->mountings_name = *mountings;
        }
        const host::FitReport r = host::fit_model(*opt, outputs);
        if (r.common_rotation.rule == host::CommonRotationRule::kSmallest && !opt->common_rotation) {
            std::cerr << "ascorr fit: warning: no --mountings: the rotation common to all heads, which no IBA sees, "
                         "is fixed as the smallest correction; the heads' combined attitude is not protected from "
                         "it (give --mountings M)\n";
        }
        outputs[host::kStandardOutput.option].write(host::describe(r));
        outputs.commit();
        std::cerr << "ascorr fit: model written to " << opt->out << '\n';
    });
}

}  // namespace ascorr::cli
