#include <iostream>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "ascorr_host/analysis/simulate.hpp"
#include "commands.hpp"
#include "number_options.hpp"

namespace ascorr::cli {

namespace {

// The event options' text, FIELD:FIELD:..., as the structures of
// ascorr_host/analysis/simulate.hpp. Each parser returns what is wrong ("" when
// nothing), in the words of number_options.hpp; the ranges that depend on
// --days are host::refuse_bad_events()'s.

std::vector<std::string> split_colons(const std::string& s) {
    std::vector<std::string> parts;
    std::size_t start = 0;
    for (std::size_t colon = s.find(':'); colon != std::string::npos; colon = s.find(':', start)) {
        parts.push_back(s.substr(start, colon - start));
        start = colon + 1;
    }
    parts.push_back(s.substr(start));
    return parts;
}

// A finite real number (from_chars, as the other real options), else false.
bool finite_real(const std::string& s, double& x) {
    return detail::classify_real(s, x) == detail::RealText::kNumber && std::isfinite(x);
}

// A head's letter (heads.hpp); whether it is simulated is refuse_bad_events'.
bool head_of(const std::string& s, std::size_t& head) {
    if (s.size() != 1 || head_index(s[0]) == kUnknownHead) {
        return false;
    }
    head = head_index(s[0]);
    return true;
}

std::string parse_truth_change(const std::string& s, host::TruthChange& out) {
    const std::size_t colon = s.find(':');
    if (colon == std::string::npos || !finite_real(s.substr(0, colon), out.day) || colon + 1 == s.size()) {
        return s + " is not DAY:MODEL: expected a number of days after the start, a colon and a model file";
    }
    out.model = s.substr(colon + 1);
    return std::string();
}

std::string parse_window(const std::vector<std::string>& parts, std::size_t first, host::DayWindow& w) {
    if (!finite_real(parts[first], w.from_day) || !finite_real(parts[first + 1], w.to_day)) {
        return "FROM_DAY and TO_DAY must be finite numbers of days after the start";
    }
    return std::string();
}

std::string parse_gap(const std::string& s, host::DayWindow& out) {
    const std::vector<std::string> parts = split_colons(s);
    const std::string why = parts.size() == 2 ? parse_window(parts, 0, out) : "expected two fields";
    return why.empty() ? why : s + " is not FROM_DAY:TO_DAY: " + why;
}

std::string parse_thermistor_fault(const std::string& s, host::ThermistorFault& out) {
    const std::vector<std::string> parts = split_colons(s);
    const std::string form = " is not HEAD:CHANNEL:stuck|drift:FROM_DAY:TO_DAY[:RATE]: ";
    if (parts.size() != 5 && parts.size() != 6) {
        return s + form + "expected 5 fields, or 6 for a drift";
    }
    if (!head_of(parts[0], out.head)) {
        return s + form + "HEAD must be " + kHeadChoices.text;
    }
    const char* const channels[3] = {"t_chu", "t_029", "t_032"};
    out.channel = 3;
    for (std::size_t c = 0; c < 3; ++c) {
        out.channel = parts[1] == channels[c] ? c : out.channel;
    }
    if (out.channel == 3) {
        return s + form + "CHANNEL must be t_chu, t_029 or t_032";
    }
    const bool drift = parts[2] == "drift";
    if (!drift && parts[2] != "stuck") {
        return s + form + "the kind must be stuck or drift";
    }
    out.kind = drift ? host::ThermistorFaultKind::kDrift : host::ThermistorFaultKind::kStuck;
    const std::string why = parse_window(parts, 3, out.window);
    if (!why.empty()) {
        return s + form + why;
    }
    if (drift != (parts.size() == 6) || (drift && !finite_real(parts[5], out.rate_c_per_day))) {
        return s + form + "a drift needs RATE, a finite number of degC per day; stuck takes none";
    }
    return std::string();
}

std::string parse_head_bias(const std::string& s, host::HeadBias& out) {
    const std::vector<std::string> parts = split_colons(s);
    const std::string form = " is not HEAD:FROM_DAY:TO_DAY:ARCSEC: ";
    if (parts.size() != 4) {
        return s + form + "expected 4 fields";
    }
    if (!head_of(parts[0], out.head)) {
        return s + form + "HEAD must be " + kHeadChoices.text;
    }
    const std::string why = parse_window(parts, 1, out.window);
    if (!why.empty()) {
        return s + form + why;
    }
    return finite_real(parts[3], out.arcsec) ? std::string() : s + form + "ARCSEC must be a finite number";
}

// A CLI11 check by one of the parsers above.
template <typename T>
CLI::Validator event_text(std::string (*parse)(const std::string&, T&), const std::string& form) {
    return CLI::Validator(
        [parse](std::string& s) {
            T ignored;
            return parse(s, ignored);
        },
        form);
}

template <typename T>
std::vector<T> parsed(const std::vector<std::string>& texts, std::string (*parse)(const std::string&, T&)) {
    std::vector<T> out(texts.size());
    for (std::size_t i = 0; i < texts.size(); ++i) {
        parse(texts[i], out[i]);  // checked by event_text already
    }
    return out;
}

struct EventTexts {
    std::vector<std::string> truth_changes;
    std::vector<std::string> gaps;
    std::vector<std::string> thermistor_faults;
    std::vector<std::string> head_biases;
    std::string heads = "ABC";
};

void add_event_options(CLI::App* cmd, EventTexts& t) {
    cmd->add_option("--truth-change", t.truth_changes,
                    "from DAY days after the start the truth is the model file MODEL (repeatable, DAY increasing); "
                    "OUT.truth-history.csv lists every truth")
        ->check(event_text(&parse_truth_change, "DAY:MODEL"));
    cmd->add_option("--gap", t.gaps, "no rows in the days [FROM_DAY, TO_DAY) after the start (repeatable)")
        ->check(event_text(&parse_gap, "FROM_DAY:TO_DAY"));
    cmd->add_option("--thermistor-fault", t.thermistor_faults,
                    "HEAD's recorded CHANNEL (t_chu, t_029, t_032) stuck at its value at FROM_DAY, or drifting by "
                    "RATE degC/day, in [FROM_DAY, TO_DAY); the bench follows the real temperature (repeatable)")
        ->check(event_text(&parse_thermistor_fault, "HEAD:CHANNEL:stuck|drift:FROM_DAY:TO_DAY[:RATE]"));
    cmd->add_option("--head-bias", t.head_biases,
                    "HEAD's measured attitude rotated by ARCSEC about its x axis in [FROM_DAY, TO_DAY): not in the "
                    "truth, not in the floor (repeatable)")
        ->check(event_text(&parse_head_bias, "HEAD:FROM_DAY:TO_DAY:ARCSEC"));
}

}  // namespace

void add_simulate_command(CLI::App& app) {
    auto opt = std::make_shared<host::SimulateOptions>();
    auto events = std::make_shared<EventTexts>();
    CLI::App* cmd =
        app.add_subcommand("simulate", "write a Swarm-like recorded data set, its truth model and noise floor");
    cmd->add_option("--out", opt->out,
                    "solutions file (CSV); beside it OUT.truth.csv, OUT.truth-history.csv, OUT.floor.json, "
                    "OUT.floor-daily.csv, OUT.heaters.csv, OUT.mountings.csv and OUT.attitude.csv, with --noise-iba "
                    "OUT.noise-iba.csv (not '-')")
        ->required()
        ->check(non_empty_path())
        ->check(not_standard_output("simulate writes eight files (OUT, OUT.truth.csv, OUT.truth-history.csv, "
                                    "OUT.floor.json, OUT.floor-daily.csv, OUT.heaters.csv, OUT.mountings.csv, "
                                    "OUT.attitude.csv; with --noise-iba also OUT.noise-iba.csv); give a path"));
    cmd->add_option("--days", opt->days, "length of the mission in days, (0, 36600] (default 920, 2.5 years)")
        ->check(real_in(0.0, 36600.0, End::kOpen));
    cmd->add_option("--step", opt->step_s, "time between epochs in s, 1..600 (default 60)")->check(real_in(1.0, 600.0));
    cmd->add_option("--seed", opt->seed, "random seed (default 1); the same seed gives the same file")
        ->transform(integer_in<std::uint64_t>());
    cmd->add_option("--truth", opt->truth, "truth thermal model (CSV); default: the paper's Table 2, built in")
        ->check(non_empty_path());
    cmd->add_option("--start", opt->start_t, "first epoch, s since J2000 TT (default 2014-06-16)")
        ->check(real_number());
    cmd->add_option("--heads", events->heads,
                    std::string("the heads simulated: two or more of ") + kHeadLetters +
                        ", in that order (default ABC); a head beyond C is derived from the one three before it "
                        "(docs/contract.md)")
        ->check(head_letters_in(2, kMaxHeads));
    add_event_options(cmd, *events);
    cmd->add_option("--bench-lag", opt->bench.lag_s,
                    "the bench deforms with its temperatures through a first-order lag of this time constant, "
                    "[0, 86400] s (default 0: at once); the rows record the temperatures themselves")
        ->check(real_in(0.0, host::kMaxBenchLagS));
    cmd->add_option("--orbit-term", opt->bench.orbit_arcsec,
                    "an orbit-periodic deformation no thermistor reads, [0, 60] arcsec at full amplitude (default 0: "
                    "none); its amplitude follows the Sun's angle to the orbital plane")
        ->check(real_in(0.0, host::kMaxOrbitTermArcsec));
    cmd->add_flag("--noise-iba", opt->noise_iba,
                  "also write OUT.noise-iba.csv: t,pair,iba, the IBA of the attitudes with noise only at each clean "
                  "epoch (for stats --noise-iba)");
    cmd->callback([opt, events]() {
        opt->heads = host::parse_head_letters(events->heads).value_or(host::kPaperHeads);  // checked already
        opt->truth_changes = parsed(events->truth_changes, &parse_truth_change);
        opt->gaps = parsed(events->gaps, &parse_gap);
        opt->thermistor_faults = parsed(events->thermistor_faults, &parse_thermistor_fault);
        opt->head_biases = parsed(events->head_biases, &parse_head_bias);
        try {
            host::refuse_bad_events(*opt);
        } catch (const std::invalid_argument& e) {
            throw CLI::ValidationError(e.what());  // a usage error, as CLI11's own: exit 2
        }
        std::vector<std::pair<const char*, std::string*>> inputs = {{"--truth", &opt->truth}};
        for (host::TruthChange& c : opt->truth_changes) {
            inputs.emplace_back("--truth-change", &c.model);
        }
        host::OutputSet outputs = open_run_files(inputs, host::simulate_outputs(*opt));
        const host::SimulateSummary s = host::simulate(*opt, outputs);
        outputs.commit();
        std::cerr << "ascorr simulate: " << opt->out << ": " << host::describe(s) << '\n';
    });
}

}  // namespace ascorr::cli
