// `ascorr simulate`: the mission, epoch by epoch (Mission), and the command's files.
#include "ascorr_host/analysis/simulate.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "ascorr_host/formats/atomic_file.hpp"
#include "ascorr_host/formats/combined_csv.hpp"
#include "ascorr_host/formats/model_csv.hpp"
#include "ascorr_host/formats/progress.hpp"
#include "ascorr_host/formats/solutions_csv.hpp"
#include "simulate_parts.hpp"

namespace ascorr::host {

namespace detail {

namespace {

// Exclusion angles from the boresight (head blinded: no solution).
constexpr double kSunExclusionDeg = 40.0;
constexpr double kMoonExclusionDeg = 20.0;

bool in_window(const DayWindow& w, double day) {
    return day >= w.from_day && day < w.to_day;
}

// The temperatures each head's row records, by head index: t_chu, t_029, t_032.
using RecordedTemperatures = std::array<std::array<double, 3>, kMaxHeads>;

// The mission, epoch by epoch: everything simulate() writes and counts.
class Mission {
public:
    Mission(const SimulateOptions& opt, const std::vector<Truth>& truths)
        : opt_(opt),
          truths_(truths),
          rnd_(opt.seed),
          orbit_(opt.start_t, sky_),
          heaters_(opt.start_t, rnd_.engine),
          stuck_(opt.thermistor_faults.size()),
          lag_(opt.bench.lag_s, opt.step_s),
          solved_(kPaperHeads | opt.heads),
          pairs_(pairs_of(opt.heads)) {
        for (int h = 0; h < kMaxHeads; ++h) {
            mount_[static_cast<std::size_t>(h)] = head_mounting(h);
        }
        // A head beyond C draws from its own stream, mt19937_64 seeded by
        // seed_seq{seed, h}: A, B and C's rows do not depend on which other heads are simulated.
        for (std::uint8_t h = kOwnHeads; h < kMaxHeads; ++h) {
            if (has_head(opt.heads, h)) {
                std::seed_seq seq{static_cast<std::uint64_t>(opt.seed), static_cast<std::uint64_t>(h)};
                extra_[h].emplace(seq);
            }
        }
        sum_.heads = opt.heads;
        sum_.pairs = pairs_;
    }

    // Appends epoch k's rows to buf and its true CRF attitude to attitude.
    void epoch(std::size_t k, std::string& buf, std::string& attitude) {
        EpochState e;
        const double dt = static_cast<double>(k) * opt_.step_s;
        e.t = std::round((opt_.start_t + dt) * 1000.0) / 1000.0;  // as written
        e.orbit = orbit_.at(dt);
        append_attitude_row(attitude, e.t, from_eigen(Eigen::Quaterniond(e.orbit.body_icrf)));
        sky_.at(e.t, e.sun, e.moon);
        double op = 0.0;
        double surv = 0.0;
        heaters_.at(e.t, op, surv);
        e.temp = temperatures(e.orbit, e.sun, op, surv, wander_, opt_.step_s, rnd_);
        for (std::size_t h = kOwnHeads; h < kMaxHeads; ++h) {
            if (extra_[h]) {
                e.extra_chu[h] =
                    extra_chu_temperature(h, exposure(e.orbit, e.sun), op, extra_wander_[h], opt_.step_s, *extra_[h]);
            }
        }
        bench_dynamics(e);
        e.no_temperature = telemetry_gap_.step(2e-4, 10, 120, rnd_.engine);
        e.no_velocity = gps_gap_.step(1e-4, 5, 60, rnd_.engine);

        const double day = dt / kSecondsPerDay;
        const auto day_index = static_cast<std::size_t>(std::floor(day));
        daily_.resize(std::max(daily_.size(), day_index + 1));
        const bool gap =
            std::any_of(opt_.gaps.begin(), opt_.gaps.end(), [day](const DayWindow& w) { return in_window(w, day); });
        const HeadsAtEpoch heads = solve_heads(e, dt, recorded_temperatures(e, day), gap, buf);
        if (gap) {
            ++sum_.gap_epochs;
            return;
        }
        for (std::size_t pr = 0; pr < pairs_.count; ++pr) {
            const auto i = pairs_.pair[pr].first;
            const auto j = pairs_.pair[pr].second;
            if (heads.clean[i] && heads.clean[j]) {
                const double iba = angle_arcsec(heads.z_floor[i], heads.z_floor[j]);
                if (opt_.noise_iba) {
                    append_noise_iba_row(noise_iba_, e.t, pairs_.pair[pr], iba);
                }
                floor_t_[pr].push_back(e.t);
                floor_v_[pr].push_back(iba);
                FloorSums& f = daily_[day_index][pr];
                ++f.n;
                f.sum += static_cast<long double>(iba);
                f.sum_sq += static_cast<long double>(iba) * static_cast<long double>(iba);
            }
        }
        ++sum_.epochs;
    }

    // The summary, once every epoch is in (t_last: the last epoch's time).
    SimulateSummary finish(double t_last) {
        for (std::size_t pr = 0; pr < pairs_.count; ++pr) {
            sum_.floor[pr] = rms_about_mean(floor_t_[pr], floor_v_[pr]);
        }
        sum_.truth_path = opt_.out + ".truth.csv";
        sum_.truth_history_path = opt_.out + ".truth-history.csv";
        sum_.floor_path = opt_.out + ".floor.json";
        sum_.floor_daily_path = opt_.out + ".floor-daily.csv";
        sum_.heaters_path = opt_.out + ".heaters.csv";
        sum_.mountings_path = opt_.out + ".mountings.csv";
        sum_.attitude_path = opt_.out + ".attitude.csv";
        sum_.noise_iba_path = opt_.noise_iba ? opt_.out + ".noise-iba.csv" : std::string();
        for (const HeaterEvent& ev : heaters_.events()) {
            if (ev.start <= t_last) {
                sum_.heaters.push_back(ev);
            }
        }
        return sum_;
    }

    const DailyFloor& daily() const { return daily_; }
    // --noise-iba: the rows since the caller last took them.
    std::string& noise_iba_rows() { return noise_iba_; }

private:
    // Which heads are written and clean at an epoch, and their floor boresights.
    struct HeadsAtEpoch {
        std::array<bool, kMaxHeads> clean{};
        std::array<Vector3<double>, kMaxHeads> z_floor{};
    };

    // Every head's solution at the epoch (drawn in a gap too: the random
    // streams stay those of a mission without gaps), written outside gaps.
    // A, B and C are drawn even when not simulated (--heads), so that the
    // others' draws stay the same; only the heads simulated are written.
    HeadsAtEpoch solve_heads(const EpochState& e, double dt, const RecordedTemperatures& recorded, bool gap,
                             std::string& buf) {
        HeadsAtEpoch out;
        const Truth& truth = truth_at(e.t);
        const HeadList solved = heads_of(solved_);
        for (std::size_t i = 0; i < solved.count; ++i) {
            const std::size_t h = solved.head[i];
            const bool written = has_head(opt_.heads, static_cast<std::uint8_t>(h));
            const Eigen::Matrix3d r_true = mount_[h] * e.orbit.body_icrf;
            const Eigen::Vector3d z_icrf = r_true.row(2).transpose();
            const double sun_deg = std::acos(std::clamp(z_icrf.dot(e.sun), -1.0, 1.0)) / kDegToRad;
            const double moon_deg = std::acos(std::clamp(z_icrf.dot(e.moon), -1.0, 1.0)) / kDegToRad;
            if (sun_deg < kSunExclusionDeg || moon_deg < kMoonExclusionDeg) {
                sum_.outage_rows[h] += gap || !written ? 0U : 1U;  // blinded: no solution
                continue;
            }
            Random& rnd = h < kOwnHeads ? rnd_ : *extra_[h];
            const HeadSolution s =
                solve_head(h, r_true, moon_deg, e, truth, bias_rad(h, dt / kSecondsPerDay), earth_, rnd);
            if (gap || !written) {
                continue;
            }
            append_row(buf, e, h, s, recorded[h]);
            count(e, s);
            out.clean[h] = !s.quality.bad && !(e.no_temperature || s.quality.chu_temperature_missing) && !e.no_velocity;
            out.z_floor[h] = s.z_floor;
        }
        return out;
    }

    // The truth in force at t: the last whose t_from is not after t.
    const Truth& truth_at(double t) const {
        std::size_t v = 0;
        while (v + 1 < truths_.size() && truths_[v + 1].t_from <= t) {
            ++v;
        }
        return truths_[v];
    }

    // --bench-lag, --orbit-term: what the bench deforms with at the epoch
    // (every epoch, in gaps too, so that the lag runs on).
    void bench_dynamics(EpochState& e) {
        for (std::size_t i = 0; i < e.temp.size(); ++i) {
            e.bench[i] = lag_.follow(i, e.temp[i]);
        }
        for (std::size_t h = kOwnHeads; h < kMaxHeads; ++h) {
            e.bench_extra_chu[h] = extra_[h] ? lag_.follow(e.temp.size() + h, e.extra_chu[h]) : 0.0;
        }
        const Eigen::Vector3d v_hat = e.orbit.body_icrf.row(0).transpose();
        e.orbit_term_arcsec = opt_.bench.orbit_arcsec * v_hat.dot(e.sun);
    }

    // --head-bias: the rotation of head h at `day`, radians (the sum of the windows holding it).
    double bias_rad(std::size_t h, double day) const {
        double arcsec = 0.0;
        for (const HeadBias& b : opt_.head_biases) {
            arcsec += b.head == h && in_window(b.window, day) ? b.arcsec : 0.0;
        }
        return arcsec * kArcsecToRad;
    }

    // The temperatures as each head's row records them: the real ones, but
    // for --thermistor-fault (stuck at the window's first value, or drifting),
    // rounded as written.
    RecordedTemperatures recorded_temperatures(const EpochState& e, double day) {
        RecordedTemperatures rec{};
        for (std::size_t h = 0; h < kMaxHeads; ++h) {
            rec[h] = {t_chu(e, h), e.temp[3], e.temp[4]};
        }
        for (std::size_t i = 0; i < opt_.thermistor_faults.size(); ++i) {
            const ThermistorFault& f = opt_.thermistor_faults[i];
            if (!in_window(f.window, day)) {
                continue;
            }
            double& x = rec[f.head][f.channel];
            if (f.kind == ThermistorFaultKind::kStuck) {
                stuck_[i] = stuck_[i].value_or(x);
                x = *stuck_[i];
            } else {
                x = std::round((x + f.rate_c_per_day * (day - f.window.from_day)) * 1000.0) / 1000.0;
            }
        }
        return rec;
    }

    void count(const EpochState& e, const HeadSolution& s) {
        ++sum_.rows;
        sum_.flagged_rows += s.quality.bad ? 1U : 0U;
        sum_.rows_without_temperature += e.no_temperature || s.quality.chu_temperature_missing ? 1U : 0U;
        sum_.rows_without_velocity += e.no_velocity ? 1U : 0U;
    }

    const SimulateOptions& opt_;
    const std::vector<Truth>& truths_;
    Random rnd_;
    SunMoon sky_;
    Orbit orbit_;
    std::array<Eigen::Matrix3d, kMaxHeads> mount_;
    EarthVelocity earth_;
    Heaters heaters_;
    std::array<Wander, 5> wander_;                        // T_CHU A, B, C, T029, T032
    std::array<std::optional<Random>, kMaxHeads> extra_;  // the streams of the heads beyond C simulated
    std::array<Wander, kMaxHeads> extra_wander_;          // their T_CHU
    Gap telemetry_gap_;
    Gap gps_gap_;
    SimulateSummary sum_;
    std::array<std::vector<double>, kMaxPairs> floor_t_;
    std::array<std::vector<double>, kMaxPairs> floor_v_;
    DailyFloor daily_;
    std::vector<std::optional<double>> stuck_;  // per --thermistor-fault: the stuck value once in its window
    BenchLag lag_;
    std::string noise_iba_;  // --noise-iba: rows not yet written
    HeadMask solved_;        // A, B, C and the heads simulated
    PairList pairs_;         // of the heads simulated
};

}  // namespace

}  // namespace detail

std::vector<NamedPath> simulate_inputs(const SimulateOptions& opt) {
    std::vector<NamedPath> inputs = {{"--truth", opt.truth}};
    for (const TruthChange& c : opt.truth_changes) {
        inputs.push_back({"--truth-change", c.model});
    }
    return inputs;
}

std::vector<NamedPath> simulate_outputs(const SimulateOptions& opt) {
    std::vector<NamedPath> out = {{"--out", opt.out},
                                  {"--out (truth model)", opt.out + ".truth.csv"},
                                  {"--out (truth history)", opt.out + ".truth-history.csv"},
                                  {"--out (noise floor)", opt.out + ".floor.json"},
                                  {"--out (daily noise floor)", opt.out + ".floor-daily.csv"},
                                  {"--out (heater events)", opt.out + ".heaters.csv"},
                                  {"--out (mountings)", opt.out + ".mountings.csv"},
                                  {"--out (true attitude)", opt.out + ".attitude.csv"}};
    if (opt.noise_iba) {
        out.push_back({"--out (noise-only IBAs)", opt.out + ".noise-iba.csv"});
    }
    return out;
}

SimulateSummary simulate(const SimulateOptions& opt, OutputSet& outputs) {
    refuse_output_over_input(simulate_inputs(opt), simulate_outputs(opt));
    detail::refuse_bad_options(opt);
    const std::vector<detail::Truth> truths = detail::truth_models(opt);
    detail::Mission mission(opt, truths);

    AtomicFile& out = outputs["--out"];
    std::string buf;
    buf.reserve(2U << 20);
    buf += kSolutionsHeader;
    buf += '\n';
    AtomicFile& attitude = outputs["--out (true attitude)"];
    std::string attitude_buf;
    attitude_buf.reserve(2U << 20);
    attitude_buf += kAttitudeHeader;
    attitude_buf += '\n';
    AtomicFile* noise_iba = opt.noise_iba ? &outputs["--out (noise-only IBAs)"] : nullptr;
    if (noise_iba != nullptr) {
        noise_iba->write(std::string(kNoiseIbaHeader) + '\n');
    }
    const auto epochs = static_cast<std::size_t>(std::floor(opt.days * kSecondsPerDay / opt.step_s)) + 1;
    // Writes what a buffer holds once it is beyond `at` bytes.
    const auto flush = [](AtomicFile& f, std::string& b, std::size_t at) {
        if (b.size() > at) {
            f.write(b);
            b.clear();
        }
    };
    Progress progress("simulate");
    for (std::size_t k = 0; k < epochs; ++k) {
        if ((k & 4095U) == 0) {
            progress.update(static_cast<double>(k) / static_cast<double>(epochs));
        }
        mission.epoch(k, buf, attitude_buf);
        flush(out, buf, 1U << 20);
        flush(attitude, attitude_buf, 1U << 20);
        if (noise_iba != nullptr) {
            flush(*noise_iba, mission.noise_iba_rows(), 1U << 20);
        }
    }
    if (noise_iba != nullptr) {
        noise_iba->write(mission.noise_iba_rows());
    }
    out.write(buf);
    attitude.write(attitude_buf);
    progress.done();
    const SimulateSummary sum = mission.finish(opt.start_t + static_cast<double>(epochs - 1) * opt.step_s);
    outputs["--out (mountings)"].write(format_mountings(simulated_mountings(opt.heads)));
    outputs["--out (truth model)"].write(format_model(truths.front().file));
    outputs["--out (truth history)"].write(detail::truth_history_csv(truths));
    outputs["--out (noise floor)"].write(floor_json(sum.floor, sum.pairs));
    outputs["--out (daily noise floor)"].write(floor_daily_csv(mission.daily(), opt.start_t, sum.pairs));
    outputs["--out (heater events)"].write(heaters_csv(sum.heaters));
    return sum;
}

SimulateSummary simulate(const SimulateOptions& opt) {
    OutputSet outputs(simulate_outputs(opt), simulate_inputs(opt));
    const SimulateSummary sum = simulate(opt, outputs);
    outputs.commit();
    return sum;
}

}  // namespace ascorr::host
