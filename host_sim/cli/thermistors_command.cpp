// `ascorr thermistors`: run the thermistor acquisition and print every
// channel and the voted T1/T2/T3 with their validity and faults.
//
//   ascorr thermistors --config board.cfg [--chip gpiochip0] [--frames N] [--interval S]
//   ascorr thermistors --config board.cfg --replay recorded.csv
//   ascorr thermistors --config board.cfg --simulate history.csv [--inject NAME:KIND:FROM:TO[:VALUE]]...
//
// Output (stdout, CSV): t,name,role,counts,ohm,celsius,valid,faults with one
// row per configured channel and then one row per voted value (name t_chu,
// t_029, t_032; role "voted"; t_chu is the --head's). faults is the '|'-joined
// list of fault names (faults.hpp), empty when valid. A summary goes to stderr.
#include <algorithm>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <iterator>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "ascorr_hal/acquisition.hpp"
#include "ascorr_hal_linux/config_file.hpp"
#include "ascorr_hal_linux/replay_source.hpp"
#include "ascorr_hal_linux/simulated_source.hpp"
#include "ascorr_host/formats/atomic_file.hpp"
#include "ascorr_host/formats/solutions_csv.hpp"
#include "commands.hpp"
#include "number_options.hpp"
#ifdef ASCORR_HAVE_GPIOD
#include "ascorr_hal_linux/gpiod_backend.hpp"
#include "ascorr_text/c_format.hpp"
#endif

namespace ascorr::cli {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

struct ThermistorOptions {
    std::string config;
    std::string chip;
    std::string replay;
    std::string simulate;
    std::vector<std::string> inject;
    unsigned frames = 1;
    double interval = 1.0;
    char head = kHeadLetters[0];
};

std::string fault_list(hal::FaultBits f) {
    std::string s;
    for (int i = 0; i < hal::fault::kCount; ++i) {
        if ((f & (1U << i)) != 0U) {
            if (!s.empty()) {
                s += '|';
            }
            s += hal::kFaultNames[i];
        }
    }
    return s;
}

void print_row(std::FILE* out, std::uint64_t t_us, const char* name, const char* role, long counts, double ohm,
               double celsius, hal::FaultBits faults) {
    char c[32] = "";
    char o[400] = "";
    char t[400] = "";  // %.3f of any finite double: at most 309 digits before the point
    if (counts >= 0) {
        text::c_snprintf(c, sizeof c, "%ld", counts);
    }
    if (std::isfinite(ohm)) {
        text::c_snprintf(o, sizeof o, "%.1f", ohm);
    } else if (std::isinf(ohm)) {
        text::c_snprintf(o, sizeof o, "inf");
    }
    if (std::isfinite(celsius)) {
        text::c_snprintf(t, sizeof t, "%.3f", celsius);
    }
    text::c_fprintf(out, "%" PRIu64 ".%06" PRIu64 ",%s,%s,%s,%s,%s,%d,%s\n", t_us / 1000000U, t_us % 1000000U, name,
                    role, c, o, t, faults == 0U ? 1 : 0, fault_list(faults).c_str());
}

// A fault whose window misses the history faults nothing: said, not silent.
void warn_faults_outside(const ThermistorOptions& opt, const std::vector<hal::InjectedFault>& faults,
                         const std::vector<hal::HistoryEpoch>& history) {
    if (history.empty()) {
        return;
    }
    double first = std::numeric_limits<double>::infinity();
    double last = -first;
    for (const hal::HistoryEpoch& e : history) {
        const double t = static_cast<double>(e.t_us) * 1e-6;
        first = std::min(first, t);
        last = std::max(last, t);
    }
    for (std::size_t i = 0; i < faults.size(); ++i) {
        if (faults[i].to_s < first || faults[i].from_s > last) {
            char span[96];
            text::c_snprintf(span, sizeof span, "[%.17g, %.17g] s", first, last);
            std::cerr << "ascorr thermistors: warning: --inject " << opt.inject[i] << ": its window is outside the "
                      << "history " << opt.simulate << " " << span << ": it faults nothing\n";
        }
    }
}

// The frames' source: --replay's file, --simulate's history (with
// --inject's faults) or, with neither, the GPIO backend (its clock in
// live_clock).
std::unique_ptr<hal::SampleSetSource<double>> open_source(const ThermistorOptions& opt, const hal::HalConfig& cfg,
                                                          std::unique_ptr<hal::Clock>& live_clock) {
    const hal::AcquisitionConfig<double>& acfg = cfg.acquisition;
    if (!opt.replay.empty() && !opt.simulate.empty()) {
        throw std::runtime_error("--replay and --simulate exclude each other");
    }
    if (!opt.inject.empty() && opt.simulate.empty()) {
        throw std::runtime_error("--inject needs --simulate");
    }
    if (!opt.replay.empty()) {
        return hal::ReplaySource::from_file(opt.replay, acfg);
    }
    if (!opt.simulate.empty()) {
        std::vector<hal::InjectedFault> faults;
        for (const std::string& s : opt.inject) {
            faults.push_back(hal::parse_fault(s, acfg));
        }
        std::vector<hal::HistoryEpoch> history = hal::read_history(opt.simulate);
        warn_faults_outside(opt, faults, history);
        return std::make_unique<hal::SimulatedSource>(acfg, std::move(history), std::move(faults));
    }
#ifdef ASCORR_HAVE_GPIOD
    live_clock = std::make_unique<hal::SteadyClock>();
    return std::make_unique<hal::GpiodSampleSetSource>(cfg, *live_clock);
#else
    (void)live_clock;
    throw std::runtime_error("this build has no libgpiod backend: use --replay or --simulate");
#endif
}

// One row per channel, with kOutvoted from the vote of its role.
void print_channels(std::FILE* out, hal::TemperatureAcquisition<double>& acq,
                    const hal::AcquisitionConfig<double>& acfg, std::uint64_t now) {
    hal::ChannelReading<double> readings[hal::kMaxChannels];
    for (std::uint8_t i = 0; i < acfg.channels; ++i) {
        readings[i] = acq.channel(i, now);
    }
    for (std::uint8_t r = 0; r < hal::kRoleCount; ++r) {
        hal::ChannelReading<double> members[hal::kMaxVoters];
        std::uint8_t index[hal::kMaxVoters] = {};
        const hal::VotedTemperature<double> v = acq.role(static_cast<hal::Role>(r), now, members, index);
        for (std::uint8_t k = 0; r != 0U && k < v.members; ++k) {
            readings[index[k]] = members[k];
        }
    }
    for (std::uint8_t i = 0; i < acfg.channels; ++i) {
        const hal::ChannelReading<double>& r = readings[i];
        const hal::ChannelConfig<double>& c = acfg.channel[i];
        const bool has_counts = !std::isnan(r.ohm);
        print_row(out, r.t_us, c.name, hal::kRoleNames[static_cast<int>(c.role)], has_counts ? r.counts : -1, r.ohm,
                  r.celsius, r.faults);
    }
}

// The head's three voted values, counting the withheld ones and their faults.
void print_voted(std::FILE* out, hal::TemperatureAcquisition<double>& acq, std::uint8_t head, std::uint64_t now,
                 std::size_t& invalid, std::size_t* per_fault) {
    const hal::HeadAcquisition<double> h = acq.head(head, now);
    const hal::VotedTemperature<double> v[3] = {acq.role(hal::chu_role(head), now), acq.role(hal::Role::kT029, now),
                                                acq.role(hal::Role::kT032, now)};
    const hal::FaultBits f[3] = {h.faults_chu, h.faults_029, h.faults_032};
    const char* names[3] = {"t_chu", "t_029", "t_032"};
    for (int k = 0; k < 3; ++k) {
        print_row(out, now, names[k], "voted", -1, kNaN, f[k] == 0U ? v[k].celsius : kNaN, f[k]);
        if (f[k] != 0U) {
            ++invalid;
            for (int b = 0; b < hal::fault::kCount; ++b) {
                per_fault[b] += (f[k] >> b) & 1U;
            }
        }
    }
}

void run(const ThermistorOptions& opt) {
    host::refuse_output_over_input({{"--config", opt.config}, {"--replay", opt.replay}, {"--simulate", opt.simulate}},
                                   {}, true);
    const hal::HalConfig cfg_file = hal::read_config(opt.config);
    hal::HalConfig cfg = cfg_file;
    if (!opt.chip.empty()) {
        cfg.gpio.chip = opt.chip;
    }
    const hal::AcquisitionConfig<double>& acfg = cfg.acquisition;
    std::unique_ptr<hal::Clock> live_clock;
    const bool live = opt.replay.empty() && opt.simulate.empty();
    const std::unique_ptr<hal::SampleSetSource<double>> source = open_source(opt, cfg, live_clock);
    const std::uint8_t head = head_index(opt.head);
    hal::TemperatureAcquisition<double> acq(acfg);
    std::FILE* out = stdout;
    text::c_fprintf(out, "t,name,role,counts,ohm,celsius,valid,faults\n");
    std::size_t frames = 0;
    std::size_t invalid = 0;
    std::size_t per_fault[hal::fault::kCount] = {};
    hal::SampleSet<double> samples{};
    while (!live || frames < opt.frames) {
        if (live && frames > 0U) {
            live_clock->wait_us(static_cast<std::uint32_t>(std::llround(opt.interval * 1e6)));
        }
        if (!source->acquire(samples)) {
            break;
        }
        acq.update(samples);
        ++frames;
        const std::uint64_t now = samples.t_us;
        print_channels(out, acq, acfg, now);
        print_voted(out, acq, head, now, invalid, per_fault);
    }
    std::fflush(out);
    std::cerr << "ascorr thermistors: " << frames << " frames, " << invalid << " voted values withheld";
    for (int b = 0; b < hal::fault::kCount; ++b) {
        if (per_fault[b] != 0U) {
            std::cerr << ", " << hal::kFaultNames[b] << " " << per_fault[b];
        }
    }
    std::cerr << '\n';
}

}  // namespace

void add_thermistors_command(CLI::App& app) {
    auto opt = std::make_shared<ThermistorOptions>();
    CLI::App* cmd = app.add_subcommand(
        "thermistors", "acquire the thermistors (libgpiod board, replay or simulation); print values and validity");
    cmd->add_option("--config", opt->config, "thermistor configuration file")->required()->check(non_empty_path());
    cmd->add_option("--chip", opt->chip, "GPIO chip of the MCP3208 lines (overrides the configuration's)")
        ->check(non_empty_path());
    CLI::Option* replay =
        cmd->add_option("--replay", opt->replay, "recorded file: t and NAME (degC) or NAME.counts columns")
            ->check(non_empty_path());
    CLI::Option* simulate =
        cmd->add_option("--simulate", opt->simulate, "temperature history (t,t_chu,t_029,t_032[,chu]) to simulate")
            ->check(non_empty_path());
    cmd->add_option("--inject", opt->inject, "simulated fault NAME:KIND:FROM:TO[:VALUE] (repeatable)");
    // Live options: --replay and --simulate run their whole file, so they exclude them.
    cmd->add_option("--frames", opt->frames, "live: frames to acquire (not with --replay or --simulate)")
        ->transform(integer_in<unsigned>(1U, 1000000U))
        ->excludes(replay)
        ->excludes(simulate);
    cmd->add_option("--interval", opt->interval, "live: seconds between frames (not with --replay or --simulate)")
        ->check(real_in(0.0, 3600.0))
        ->excludes(replay)
        ->excludes(simulate);
    cmd->add_option("--head", opt->head,
                    "head whose T_CHU is voted and printed (" + std::string(kHeadChoices.text) + ")")
        ->check(CLI::Validator(
            [](std::string& s) {
                return s.size() == 1 && head_index(s[0]) != kUnknownHead
                           ? std::string()
                           : s + " is out of range: a head is " + std::string(kHeadChoices.text);
            },
            kHeadChoices.text));
    cmd->callback([opt]() {
        host::OutputSet outputs =
            open_run_files({{"--config", &opt->config}, {"--replay", &opt->replay}, {"--simulate", &opt->simulate}},
                           {host::kStandardOutput});  // the rows, printed as they come (checked at the commit)
        run(*opt);
        outputs.commit();
    });
}

}  // namespace ascorr::cli
