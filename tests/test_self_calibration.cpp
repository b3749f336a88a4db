// The on-board estimator (calib/estimator.hpp) on simulated missions it did
// not produce (host simulate: its truth, its noise floor per day), scored as
// the ground team would: the thermal-stage IBA RMS per pair of each window,
// about its mean, over the simulator's noise floor of the same days.
// Scenarios: a bench that settles (truth change), heater events, a stuck and a
// drifting thermistor, a head biased for a day, gaps of days, and the done-when
// mission; mutation checks: without forgetting the settling case fails,
// without the gate a corrupted week makes the model worse.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "ascorr/core/correct.hpp"
#include "ascorr/core/fixed_point.hpp"
#include "ascorr_host/analysis/fit.hpp"
#include "ascorr_host/analysis/iba.hpp"
#include "ascorr_host/analysis/simulate.hpp"
#include "ascorr_host/correct/earth_velocity.hpp"
#include "ascorr_host/correct/self_calibration.hpp"
#include "ascorr_host/correct/solution_input.hpp"
#include "ascorr_host/formats/embedded_model.hpp"
#include "ascorr_host/formats/model_csv.hpp"
#include "cli_run.hpp"
#include "test_support.hpp"

namespace ascorr::test {
namespace {

namespace fs = std::filesystem;
constexpr double kDay = 86400.0;

constexpr std::size_t kPairs = host::kPaperPairs.count;  // A-B, A-C, B-C

struct Mission {
    fs::path dir;
    std::string data;
    double t0 = 0.0;
    std::string storage;
    std::vector<host::SolutionRecord> records;
};

// A 300 s-step mission of `days` days (seed fixed) with the simulator's events.
Mission simulate(const std::string& name, double days, const std::function<void(host::SimulateOptions&)>& events) {
    Mission m;
    m.dir = scratch_dir(name);
    host::SimulateOptions o;
    o.out = (m.dir / "mission.csv").string();
    o.days = days;
    o.step_s = 300.0;
    o.seed = 5;
    events(o);
    host::simulate(o);
    m.data = o.out;
    m.t0 = o.start_t;
    m.records = read_records(m.data, m.storage);
    return m;
}

host::RowSource rows_of(const Mission& m) {
    return [&m](const std::function<void(const host::SolutionRecord&)>& fn) {
        for (const auto& r : m.records) {
            fn(r);
        }
    };
}

// The thermal-stage IBAs of the clean epochs, each row corrected with the
// model active at its t (double path).
struct Ibas {
    std::array<std::vector<double>, host::kMaxPairs> t;
    std::array<std::vector<double>, host::kMaxPairs> v;
};

Ibas thermal_ibas(const Mission& m, const std::vector<host::ActiveModel>& history,
                  const host::PairList& pairs = host::kPaperPairs) {
    std::vector<std::pair<double, ThermalModel<double>>> schedule;
    for (const auto& a : history) {
        schedule.emplace_back(a.t, host::to_core<double>(a.model));
    }
    host::EarthVelocity earth;
    std::map<double, std::array<std::optional<Vector3<double>>, kMaxHeads>> epochs;
    for (const auto& rec : m.records) {
        if (rec.head >= kMaxHeads || host::fit_selection(rec) != host::Drop::kNone) {
            continue;
        }
        auto it = std::upper_bound(schedule.begin(), schedule.end(), rec.t,
                                   [](double x, const auto& s) { return x < s.first; });
        if (it == schedule.begin()) {
            continue;  // no model yet
        }
        const CorrectionConfig<double> cfg{true, &(it - 1)->second};
        const CorrectedSolution<double> c = correct_solution(host::to_core_input<double>(rec, &earth), cfg);
        if ((c.status & status::kThermalApplied) != 0U) {
            epochs[rec.t][rec.head] = boresight(c.q_chu_icrf);
        }
    }
    Ibas out;
    for (const auto& [t, z] : epochs) {
        for (std::size_t p = 0; p < pairs.count; ++p) {
            const auto& a = z[pairs.pair[p].first];
            const auto& b = z[pairs.pair[p].second];
            if (a && b) {
                out.t[p].push_back(t);
                out.v[p].push_back(host::angle_arcsec(*a, *b));
            }
        }
    }
    return out;
}

// One pair's IBA RMS about its mean over days [a, b) (NaN: fewer than two epochs).
double day_rms(const Mission& m, const std::vector<double>& t, const std::vector<double>& v, long long a, long long b) {
    double s = 0.0;
    double s2 = 0.0;
    std::size_t n = 0;
    const double ref = v.empty() ? 0.0 : v.front();
    for (std::size_t i = 0; i < t.size(); ++i) {
        const double d = (t[i] - m.t0) / kDay;
        if (d >= static_cast<double>(a) && d < static_cast<double>(b)) {
            s += v[i] - ref;
            s2 += (v[i] - ref) * (v[i] - ref);
            ++n;
        }
    }
    return n > 1 ? std::sqrt(std::max(
                       0.0, s2 / static_cast<double>(n) - (s / static_cast<double>(n)) * (s / static_cast<double>(n))))
                 : std::nan("");
}

// Per pair: IBA RMS about its mean over days [a, b) / the floor's.
std::array<double, kPairs> ratio(const Mission& m, const Ibas& ibas, long long a, long long b) {
    const auto floor = host::floor_of_days(m.data + ".floor-daily.csv", a, b);
    std::array<double, kPairs> r{};
    for (std::size_t p = 0; p < kPairs; ++p) {
        r[p] = day_rms(m, ibas.t[p], ibas.v[p], a, b) / floor[p].rms;
    }
    return r;
}

double worst(const std::array<double, kPairs>& r) {
    double w = 0.0;
    for (double x : r) {
        w = std::isnan(x) ? x : std::max(w, x);
    }
    return w;
}

std::string text(const std::array<double, kPairs>& r) {
    char buf[120];
    std::snprintf(buf, sizeof buf, "A-B %.3f, A-C %.3f, B-C %.3f", r[0], r[1], r[2]);
    return buf;
}

// The settled bench: head B's mount shifts by 1.5" (alpha) and 3" (beta),
// some of its and A's gains change by 30-40 % (cross-boresight axes: the IBAs see them).
std::string settled_truth(const fs::path& dir) {
    host::ModelFile m = host::table2_model();
    m.coefficients[1][0][0] += 1.5;
    m.coefficients[1][1][0] += 3.0;
    m.coefficients[1][0][1] *= 1.35;
    m.coefficients[1][1][1] *= 1.4;
    m.coefficients[1][0][3] *= 0.7;
    m.coefficients[0][1][3] *= 1.3;
    const std::string path = (dir / "settled.csv").string();
    host::write_model_file(path, m);
    return path;
}

struct Learnt {
    host::SelfCalibration sc;
    Ibas ibas;
};

template <typename T = double>
Learnt run(const Mission& m, const calib::EstimatorConfig& cfg) {
    Learnt r;
    r.sc = host::self_calibrate<T>(m.data, rows_of(m), std::nullopt, cfg, std::nullopt);
    r.ibas = thermal_ibas(m, r.sc.history);
    return r;
}

// The done-when mission: 600 days, gaps, the simulator's bad rows, no model at
// the start, the bench settles on day 400.
Mission settling_mission(const std::string& name) {
    return simulate(name, 600.0, [](host::SimulateOptions& o) {
        const fs::path dir = fs::path(o.out).parent_path();
        o.truth_changes.push_back({400.0, settled_truth(dir)});
        o.gaps.push_back({150.0, 153.0});
        o.gaps.push_back({470.0, 472.0});
    });
}

TEST(SelfCalibration, SettlingMissionReachesTheFloor) {
    const Mission m = settling_mission("settling");
    const Learnt r = run(m, calib::EstimatorConfig{});
    const auto before = ratio(m, r.ibas, 30, 400);
    const auto after30 = ratio(m, r.ibas, 400, 430);
    const auto later = ratio(m, r.ibas, 430, 600);
    std::printf("settling, tau %.0f d: days 30-400 %s; 400-430 %s; 430-600 %s; %zu models\n",
                calib::EstimatorConfig{}.time_constant_days, text(before).c_str(), text(after30).c_str(),
                text(later).c_str(), r.sc.history.size());
    std::printf("%s\n", host::describe(r.sc).c_str());
    EXPECT_LE(worst(before), 1.03);
    EXPECT_LE(worst(after30), 1.10);
    EXPECT_LE(worst(later), 1.03);
    // The simulator's heater events (a heat flow the seasons do not show): the
    // IBA RMS from each heater on to a day after it is off, each window after
    // day 30, over the floor of the same days.
    std::ifstream heaters(m.data + ".heaters.csv");
    std::string line;
    std::getline(heaters, line);
    std::array<double, kPairs> worst_heater{};
    std::size_t events = 0;
    while (std::getline(heaters, line)) {
        const double on = std::stod(line);
        const double off = std::stod(line.substr(line.find(',') + 1));
        const auto a = static_cast<long long>(std::floor((on - m.t0) / kDay));
        const auto b = static_cast<long long>(std::ceil((off - m.t0) / kDay)) + 1;
        if (a < 30 || b > 600) {
            continue;
        }
        const auto x = ratio(m, r.ibas, a, b);
        for (std::size_t p = 0; p < kPairs; ++p) {
            worst_heater[p] = std::max(worst_heater[p], x[p]);
        }
        ++events;
    }
    std::printf("heater events (%zu): worst %s\n", events, text(worst_heater).c_str());
    EXPECT_GE(events, 5U);
    EXPECT_LE(worst(worst_heater), 1.03);
}

// ---- Settlings on many missions (the worst case, not one mission's).

struct Settling {
    std::uint64_t seed;
    double day;           // of the settling
    int heads[2];         // shifted heads (-1: none)
    double shift_arcsec;  // c0 of alpha; beta gets twice it
    bool gains;           // cross-boresight gains change by 30-40 % too
};

// Eight missions: seeds, days, sizes 0.5" to 5" on one or two heads, with
// and without gain changes.
constexpr Settling kSettlings[] = {
    {11, 250.0, {1, -1}, 1.5, true},  {12, 300.0, {0, -1}, 0.5, false}, {13, 350.0, {2, -1}, 5.0, true},
    {14, 220.0, {0, 2}, 2.0, false},  {15, 280.0, {1, 2}, 3.0, true},   {16, 330.0, {0, 1}, 1.0, true},
    {17, 260.0, {2, -1}, 2.5, false}, {18, 310.0, {1, -1}, 4.0, true},
};

std::string settled_truth_of(const Settling& s, const fs::path& dir) {
    host::ModelFile m = host::table2_model();
    for (const int h : s.heads) {
        if (h < 0) {
            continue;
        }
        const auto i = static_cast<std::size_t>(h);
        m.coefficients[i][0][0] += s.shift_arcsec;
        m.coefficients[i][1][0] += 2.0 * s.shift_arcsec;
        if (s.gains) {
            m.coefficients[i][0][1] *= 1.35;
            m.coefficients[i][1][1] *= 1.4;
            m.coefficients[i][0][3] *= 0.7;
        }
    }
    const std::string path = (dir / "settled.csv").string();
    host::write_model_file(path, m);
    return path;
}

struct SettlingScore {
    double before = 0.0;   // day 30 to the settling
    double after30 = 0.0;  // the 30 days after it
    double later = 0.0;    // from 30 days after it to the end
};

// The worst over the eight missions of each configuration in cfgs (each
// mission simulated once).
std::vector<SettlingScore> score_settlings(const std::vector<calib::EstimatorConfig>& cfgs) {
    std::vector<SettlingScore> w(cfgs.size());
    int k = 0;
    for (const Settling& s : kSettlings) {
        const double end = s.day + 120.0;
        const Mission m = simulate("settlings-" + std::to_string(k++), end, [&s](host::SimulateOptions& o) {
            o.seed = s.seed;
            o.truth_changes.push_back({s.day, settled_truth_of(s, fs::path(o.out).parent_path())});
            o.gaps.push_back({s.day - 90.0, s.day - 88.0});
        });
        const auto d = static_cast<long long>(s.day);
        for (std::size_t c = 0; c < cfgs.size(); ++c) {
            const Learnt r = run(m, cfgs[c]);
            const double b = worst(ratio(m, r.ibas, 30, d));
            const double a = worst(ratio(m, r.ibas, d, d + 30));
            const double l = worst(ratio(m, r.ibas, d + 30, static_cast<long long>(end)));
            std::printf(
                "config %zu, seed %llu day %.0f %.1f\" heads %d,%d%s: before %.3f, 30 days after %.3f, "
                "later %.3f\n",
                c, static_cast<unsigned long long>(s.seed), s.day, s.shift_arcsec, s.heads[0], s.heads[1],
                s.gains ? " +gains" : "", b, a, l);
            w[c].before = std::max(w[c].before, b);
            w[c].after30 = std::max(w[c].after30, a);
            w[c].later = std::max(w[c].later, l);
        }
    }
    return w;
}

// Issue 31's done-when, worst over eight settling missions. Mutation: the
// estimator as it was (a change taken after 24 held orbits, orbits below half
// a typical one's count unused) fails the 30 days after (1.50).
TEST(SelfCalibration, SettlingsOnEightMissionsWorstCase) {
    calib::EstimatorConfig before_issue_31;
    before_issue_31.persistence_orbits = 24;
    before_issue_31.min_coverage = 0.5;
    const std::vector<SettlingScore> w = score_settlings({calib::EstimatorConfig{}, before_issue_31});
    for (std::size_t c = 0; c < w.size(); ++c) {
        std::printf("config %zu, worst of %zu missions: before %.3f, 30 days after %.3f, later %.3f\n", c,
                    std::size(kSettlings), w[c].before, w[c].after30, w[c].later);
    }
    EXPECT_LE(w[0].before, 1.03);
    EXPECT_LE(w[0].after30, 1.10);
    EXPECT_LE(w[0].later, 1.03);
    EXPECT_GT(w[1].after30, 1.10);
}

// A quadratic truth (B's alpha and beta 0.04 arcsec/degC^2 in T_CHU): the
// linear model with forgetting follows the curvature over the seasons.
TEST(SelfCalibration, AQuadraticTruthIsFollowed) {
    const Mission m = simulate("quadratic", 300.0, [](host::SimulateOptions& o) {
        host::ModelFile t = host::table2_model();
        t.quadratic = true;
        t.coefficients[1][0][4] = 0.04;
        t.coefficients[1][1][4] = -0.04;
        o.truth = (fs::path(o.out).parent_path() / "quadratic.csv").string();
        host::write_model_file(o.truth, t);
    });
    const Learnt r = run(m, calib::EstimatorConfig{});
    const auto x = ratio(m, r.ibas, 30, 300);
    std::printf("quadratic truth: days 30-300 %s\n", text(x).c_str());
    EXPECT_LE(worst(x), 1.03);
}

// Mutation check: the same mission without forgetting (τ = 10⁹ days) keeps
// the old bench in its model for the rest of the mission.
TEST(SelfCalibration, WithoutForgettingTheSettlingFails) {
    const Mission m = settling_mission("no-forgetting");
    calib::EstimatorConfig c;
    c.time_constant_days = 1e9;
    const Learnt r = run(m, c);
    const auto later = ratio(m, r.ibas, 430, 600);
    std::printf("no forgetting: days 30-400 %s; 400-430 %s; 430-600 %s\n", text(ratio(m, r.ibas, 30, 400)).c_str(),
                text(ratio(m, r.ibas, 400, 430)).c_str(), text(later).c_str());
    EXPECT_GT(worst(later), 1.03);
}

// The corrupted week's outcome: every model adopted from its start to 30
// days after its end, applied to the same mission without the corruption,
// has an IBA RMS over that period at most 1.05 × the model active when the
// week began (each model held fixed over the whole period).
struct WeekOutcome {
    double worst_ratio = 0.0;  // max over models and pairs of RMS(model) / RMS(before)
    std::size_t models = 0;    // adopted in the period
};

WeekOutcome corrupted_week(const std::string& name, const calib::EstimatorConfig& cfg,
                           const std::function<void(host::SimulateOptions&)>& corruption, double from_day,
                           double to_day) {
    const Mission clean = simulate(name + "-clean", 200.0, [](host::SimulateOptions&) {});
    const Mission bad = simulate(name, 200.0, corruption);
    const Learnt r = run(bad, cfg);
    const double t_from = bad.t0 + from_day * kDay;
    const double t_end = bad.t0 + (to_day + 30.0) * kDay;
    const host::ActiveModel* before = nullptr;
    std::vector<const host::ActiveModel*> during;
    for (const auto& a : r.sc.history) {
        if (a.t <= t_from) {
            before = &a;
        } else if (a.t < t_end) {
            during.push_back(&a);
        }
    }
    EXPECT_NE(before, nullptr) << "no model before the corrupted week";
    WeekOutcome out;
    if (before == nullptr) {
        return out;
    }
    Mission period;  // the clean mission's rows of the period only (records point into clean.storage)
    period.data = clean.data;
    period.t0 = clean.t0;
    for (const auto& rec : clean.records) {
        if (rec.t >= t_from && rec.t < t_end) {
            period.records.push_back(rec);
        }
    }
    const auto rms_of = [&](const host::ActiveModel& a) {
        host::ActiveModel fixed = a;
        fixed.t = clean.t0;
        const Ibas ibas = thermal_ibas(period, {fixed});
        return ratio(clean, ibas, static_cast<long long>(from_day), static_cast<long long>(to_day + 30.0));
    };
    const auto ref = rms_of(*before);
    out.models = during.size();
    for (const auto* a : during) {
        const auto x = rms_of(*a);
        for (std::size_t p = 0; p < kPairs; ++p) {
            out.worst_ratio = std::max(out.worst_ratio, x[p] / ref[p]);
        }
    }
    return out;
}

// Days 120-127: head B's T_CHU stuck, and head C biased by 5" all week.
void stuck_and_biased(host::SimulateOptions& o) {
    o.thermistor_faults.push_back({1, 0, host::ThermistorFaultKind::kStuck, {120.0, 127.0}, 0.0});
    o.head_biases.push_back({2, {120.0, 127.0}, 5.0});
}

TEST(SelfCalibration, ACorruptedWeekNeverMakesTheModelWorse) {
    const WeekOutcome w = corrupted_week("corrupted", calib::EstimatorConfig{}, stuck_and_biased, 120.0, 127.0);
    std::printf("corrupted week: %zu models adopted, worst IBA RMS %.4f x the model before\n", w.models, w.worst_ratio);
    EXPECT_LE(w.worst_ratio, 1.05);
}

// Mutation check: without the gate (no hold-back of outlier orbits, every
// candidate adopted), the same week makes the model worse.
TEST(SelfCalibration, WithoutTheGateACorruptedWeekMakesTheModelWorse) {
    calib::EstimatorConfig c;
    c.outlier_gate = 1e9;
    c.adoption_margin = -1e9;
    const WeekOutcome w = corrupted_week("ungated", c, stuck_and_biased, 120.0, 127.0);
    std::printf("corrupted week, no gate: %zu models adopted, worst IBA RMS %.4f x the model before\n", w.models,
                w.worst_ratio);
    EXPECT_GT(w.worst_ratio, 1.05);
}

// A thermistor drifting by 1 degC/day for a week (head A's T029): the same outcome.
TEST(SelfCalibration, ADriftingThermistorNeverMakesTheModelWorse) {
    const WeekOutcome w = corrupted_week(
        "drift", calib::EstimatorConfig{},
        [](host::SimulateOptions& o) {
            o.thermistor_faults.push_back({0, 1, host::ThermistorFaultKind::kDrift, {120.0, 127.0}, 1.0});
        },
        120.0, 127.0);
    std::printf("drifting thermistor: %zu models adopted, worst IBA RMS %.4f x the model before\n", w.models,
                w.worst_ratio);
    EXPECT_LE(w.worst_ratio, 1.05);
}

// A head biased by 4" for one day: longer than the persistence, so it is
// followed while it lasts (taken as a change after 3 held orbits) and undone
// at its end (3 more held orbits, the second change); the IBAs of the 50 days
// after it are at the floor. Mutation: were the running RMS restarted at a
// change, the end would be fed as ordinary orbits (1 change, 1.020 after).
TEST(SelfCalibration, AHeadBiasedForADayIsFollowedAndUndone) {
    const Mission m = simulate("bias-day", 200.0, [](host::SimulateOptions& o) {
        o.head_biases.push_back({1, {150.0, 151.0}, 4.0});
    });
    const Learnt r = run(m, calib::EstimatorConfig{});
    std::printf("biased day: %u orbits held back, %u changes; days 151-200 %s\n", r.sc.report.orbits_held,
                r.sc.report.changes, text(ratio(m, r.ibas, 151, 200)).c_str());
    EXPECT_GE(r.sc.report.orbits_held, 2U * calib::EstimatorConfig{}.persistence_orbits);
    EXPECT_EQ(r.sc.report.changes, 2U);
    EXPECT_LE(worst(ratio(m, r.ibas, 151, 200)), 1.03);
}

// A head biased by 4" for 1.5 h (one orbit, within at most two orbit bins):
// shorter than the persistence, held back, no change taken as real.
TEST(SelfCalibration, AHeadBiasedForAnOrbitIsHeldBack) {
    const Mission m = simulate("bias-orbit", 200.0, [](host::SimulateOptions& o) {
        o.head_biases.push_back({1, {150.0, 150.0 + 5400.0 / kDay}, 4.0});
    });
    const Learnt r = run(m, calib::EstimatorConfig{});
    std::printf("biased orbit: %u orbits held back, %u changes; days 150-200 %s\n", r.sc.report.orbits_held,
                r.sc.report.changes, text(ratio(m, r.ibas, 150, 200)).c_str());
    EXPECT_GE(r.sc.report.orbits_held, 1U);
    EXPECT_EQ(r.sc.report.changes, 0U);
    EXPECT_LE(worst(ratio(m, r.ibas, 151, 200)), 1.03);
}

// Gaps of days: 10 days without rows; the forgetting spans the gap (exp(-10/30)),
// the model before it stays active through it, and the IBAs after it are at the floor.
TEST(SelfCalibration, GapsOfDaysAreBridged) {
    const Mission m = simulate("gaps", 200.0, [](host::SimulateOptions& o) {
        o.gaps.push_back({100.0, 110.0});
        o.gaps.push_back({140.0, 143.0});
    });
    const Learnt r = run(m, calib::EstimatorConfig{});
    const auto after = ratio(m, r.ibas, 110, 200);
    std::printf("gaps: days 110-200 %s, %zu models\n", text(after).c_str(), r.sc.history.size());
    EXPECT_LE(worst(after), 1.03);
    EXPECT_LE(worst(ratio(m, r.ibas, 30, 100)), 1.03);
}

// The per-cycle accumulation in the flight scalars (float on the M4F, Q30 on
// the M3) learns models as good as double's.
TEST(SelfCalibration, FlightScalarsReachTheFloor) {
    const Mission m = simulate("scalars", 150.0, [](host::SimulateOptions&) {});
    const Learnt d = run<double>(m, calib::EstimatorConfig{});
    const Learnt f = run<float>(m, calib::EstimatorConfig{});
    const Learnt q = run<Q30>(m, calib::EstimatorConfig{});
    std::printf("days 30-150: double %s; float %s; Q30 %s\n", text(ratio(m, d.ibas, 30, 150)).c_str(),
                text(ratio(m, f.ibas, 30, 150)).c_str(), text(ratio(m, q.ibas, 30, 150)).c_str());
    EXPECT_LE(worst(ratio(m, d.ibas, 30, 150)), 1.03);
    EXPECT_LE(worst(ratio(m, f.ibas, 30, 150)), 1.03);
    EXPECT_LE(worst(ratio(m, q.ibas, 30, 150)), 1.03);
    EXPECT_GE(f.sc.history.size(), 2U);
    EXPECT_GE(q.sc.history.size(), 2U);
}

// A four-head mission (A, B, C, D): the estimator learns D as it learns A, B
// and C, so every pair with D reaches the floor from day 30. Both runs start
// from the simulator's truth with D's cross-boresight slopes 0.5"/°C off;
// the mutation runs the estimator on A, B and C only (D's rows withheld): D
// keeps the wrong slopes and its pairs stay above the floor.
TEST(SelfCalibration, AFourthHeadIsLearntAndItsPairsReachTheFloor) {
    constexpr host::PairList kPairs4 = host::pairs_of(host::kAllHeads);
    const Mission m = simulate("four-heads", 120.0, [](host::SimulateOptions& o) { o.heads = host::kAllHeads; });
    host::ModelFile start = host::read_model_file(m.data + ".truth.csv");
    ASSERT_TRUE(start.present[3]);
    for (std::size_t a = 0; a < 2; ++a) {
        for (std::size_t t = 1; t < 4; ++t) {
            start.coefficients[3][a][t] += 0.5;
        }
    }
    const auto learn = [&m, &start](bool with_d) {
        const host::RowSource rows = [&m, with_d](const std::function<void(const host::SolutionRecord&)>& fn) {
            for (const auto& r : m.records) {
                if (with_d || r.head != 3) {
                    fn(r);
                }
            }
        };
        return host::self_calibrate<double>(m.data, rows, start, calib::EstimatorConfig{}, std::nullopt);
    };
    // Per pair of the four heads: the thermal-stage IBA RMS over days 30-120 / the floor's.
    const auto ratios = [&m, &kPairs4](const host::SelfCalibration& sc) {
        const Ibas all = thermal_ibas(m, sc.history, kPairs4);
        const auto floor = host::floor_of_days(m.data + ".floor-daily.csv", 30, 120, kPairs4);
        std::array<double, host::kMaxPairs> r{};
        for (std::size_t p = 0; p < kPairs4.count; ++p) {
            r[p] = day_rms(m, all.t[p], all.v[p], 30, 120) / floor[p].rms;
            std::printf("%s %.3f  ", kPairs4.pair[p].name, r[p]);
        }
        std::printf("\n");
        return r;
    };
    const host::SelfCalibration learnt = learn(true);
    const host::SelfCalibration kept = learn(false);
    ASSERT_GE(learnt.history.size(), 2U);
    EXPECT_EQ(learnt.history.back().learnt, 15U);  // A, B, C and D
    EXPECT_STREQ(host::head_origin(learnt.history.back().version, 3, learnt.history.back().learnt), "learnt");
    EXPECT_EQ(kept.history.back().learnt, 7U);
    EXPECT_STREQ(host::head_origin(1U, 3, kept.history.back().learnt), "kept");
    const auto r = ratios(learnt);
    const auto r_kept = ratios(kept);
    double worst_d = 0.0;
    double worst_d_kept = 0.0;
    for (std::size_t p = 0; p < kPairs4.count; ++p) {
        EXPECT_LE(r[p], 1.03) << kPairs4.pair[p].name;
        if (kPairs4.pair[p].second == 3U) {
            worst_d = std::max(worst_d, r[p]);
            worst_d_kept = std::max(worst_d_kept, r_kept[p]);
        }
    }
    EXPECT_LE(worst_d, 1.03);
    EXPECT_GT(worst_d_kept, 1.03) << "the mutation (D not learnt) must fail the bound";
}

// Lines of a text, the first (header) apart.
std::vector<std::string> lines_of(const std::string& text) {
    std::vector<std::string> out;
    std::size_t start = 0;
    while (start < text.size()) {
        const std::size_t nl = text.find('\n', start);
        out.push_back(text.substr(start, nl - start));
        start = nl == std::string::npos ? text.size() : nl + 1;
    }
    return out;
}

// The command line as the contract says: status 256 before the first adopted
// model, the model history's form, any row order, --model as version 0, the
// scalars, and the refusals.
TEST(SelfCalibrationCli, CorrectSelfCalibrate) {
    const Mission m = simulate("cli", 12.0, [](host::SimulateOptions&) {});
    const CliRun r = run_in("correct --in mission.csv --out c.csv --self-calibrate --model-history h.csv", m.dir);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const auto hist = lines_of(slurp(m.dir / "h.csv"));
    ASSERT_GE(hist.size(), 10U);
    EXPECT_EQ(hist[0], "t,version,chu,axis,c0,c1,c2,c3,crc32c,tt_us,origin");
    EXPECT_EQ(hist[1].substr(hist[1].find(',') + 1, 10), "1,A,alpha,");
    const double t_first = std::stod(hist[1]);
    // Rows before the first model: 256 and no thermal stage; after it, the thermal stage.
    const auto rows = lines_of(slurp(m.dir / "c.csv"));
    std::size_t before = 0;
    std::size_t after_thermal = 0;
    for (std::size_t i = 1; i < rows.size(); ++i) {
        const double t = std::stod(rows[i]);
        const unsigned st = static_cast<unsigned>(std::stoul(rows[i].substr(rows[i].rfind(',') + 1)));
        if (t < t_first) {
            EXPECT_EQ(st & 2U, 0U) << rows[i];
            before += (st & 256U) != 0U ? 1U : 0U;
        } else {
            after_thermal += (st & 2U) != 0U ? 1U : 0U;
        }
    }
    EXPECT_GT(before, 100U);
    EXPECT_GT(after_thermal, 1000U);
    // Rows in reverse order: the same history, the same corrected rows.
    {
        const auto in = lines_of(slurp(m.dir / "mission.csv"));
        std::ofstream f(m.dir / "reversed.csv");
        f << in[0] << '\n';
        for (std::size_t i = in.size() - 1; i >= 1; --i) {
            f << in[i] << '\n';
        }
    }
    const CliRun rr = run_in("correct --in reversed.csv --out cr.csv --self-calibrate --model-history hr.csv", m.dir);
    ASSERT_EQ(rr.exit_code, 0) << rr.err;
    EXPECT_EQ(slurp(m.dir / "hr.csv"), slurp(m.dir / "h.csv"));
    auto a = lines_of(slurp(m.dir / "c.csv"));
    auto b = lines_of(slurp(m.dir / "cr.csv"));
    std::sort(a.begin(), a.end());
    std::sort(b.begin(), b.end());
    EXPECT_EQ(a, b);
    // --model: version 0 from the first row, its coefficients.
    host::write_model_file((m.dir / "table2.csv").string(), host::table2_model());
    const CliRun rm = run_in(
        "correct --in mission.csv --out cm.csv --self-calibrate --model table2.csv --model-history hm.csv", m.dir);
    ASSERT_EQ(rm.exit_code, 0) << rm.err;
    const auto hm = lines_of(slurp(m.dir / "hm.csv"));
    ASSERT_GE(hm.size(), 10U);
    const std::string first_row = lines_of(slurp(m.dir / "mission.csv"))[1];
    EXPECT_EQ(hm[1].substr(0, hm[1].find(',')), first_row.substr(0, first_row.find(',')));
    EXPECT_EQ(hm[1].substr(hm[1].find(',') + 1, 10), "0,A,alpha,");
    EXPECT_EQ(std::stod(hm[1].substr(hm[1].find("alpha,") + 6)), host::table2_model().coefficients[0][0][0]);
    // The estimator in the flight scalars.
    for (const char* scalar : {"float", "fixed"}) {
        const CliRun rs = run_in(std::string("correct --in mission.csv --out cs.csv --self-calibrate --scalar ") +
                                     scalar + " --model-history hs.csv",
                                 m.dir);
        ASSERT_EQ(rs.exit_code, 0) << rs.err;
        EXPECT_GE(lines_of(slurp(m.dir / "hs.csv")).size(), 10U) << scalar;
    }
    // Refusals: nothing written.
    const std::string c = "correct --in mission.csv --out x.csv";
    expect_refused(run_in(c + " --model-history hx.csv", m.dir), kAnyFailure, {"--model-history"});
    expect_refused(run_in(c + " --self-calibrate --no-thermal", m.dir), kAnyFailure, {"--no-thermal"});
    // --time-constant needs --self-calibrate; --states and a history at --out's path are refused.
    expect_refused(run_in(c + " --time-constant 20", m.dir), 2, {"--time-constant"});
    expect_refused(run_in(c + " --self-calibrate --states mission.csv", m.dir), kAnyFailure, {"--states"});
    expect_refused(run_in(c + " --self-calibrate --model-history ./x.csv", m.dir), kAnyFailure, {"is also --out"});
    expect_absent(m.dir, {"x.csv", "hx.csv"});
}

// Rows whose t the on-board clock cannot hold (|t| > 1e11 s, tt_from_seconds)
// take no part in the estimation: the history and every other row are as
// without them, in each scalar; each such row belongs to no epoch, gets no
// model (256, also with --model) and is counted on the terminal.
// (Before: t * 1e6 went through llround unchecked, and --model's version 0
// was active "from t = -1e300", a 300-digit time in the history.)
TEST(SelfCalibrationCli, TimesTheClockCannotHoldTakeNoPart) {
    const Mission m = simulate("clock", 4.0, [](host::SimulateOptions&) {});
    host::write_model_file((m.dir / "table2.csv").string(), host::table2_model());
    const auto in = lines_of(slurp(m.dir / "mission.csv"));
    const std::string first_row = in[1];
    const auto with_t = [&](const std::string& t) { return t + first_row.substr(first_row.find(',')); };
    {
        std::ofstream f(m.dir / "unclocked.csv");
        f << in[0] << '\n' << with_t("-1e300") << '\n';
        for (std::size_t i = 1; i < in.size(); ++i) {
            f << in[i] << '\n';
            if (i == in.size() / 2) {
                f << with_t("1.0000001e11") << '\n';
            }
        }
        f << with_t("1e300") << '\n';
    }
    for (const char* scalar : {"double", "float", "fixed"}) {
        SCOPED_TRACE(scalar);
        for (const std::string model : {"", " --model table2.csv"}) {
            SCOPED_TRACE(model);
            const std::string opts = std::string(" --self-calibrate --scalar ") + scalar + model;
            const CliRun a = run_in("correct --in mission.csv --out a.csv --model-history ha.csv" + opts, m.dir);
            ASSERT_EQ(a.exit_code, 0) << a.err;
            const CliRun b = run_in("correct --in unclocked.csv --out b.csv --model-history hb.csv" + opts, m.dir);
            ASSERT_EQ(b.exit_code, 0) << b.err;
            EXPECT_NE(b.err.find("3 row(s) with a time the on-board clock cannot hold (|t| > 1e11 s) left out of "
                                 "the estimation: no model for them (256)"),
                      std::string::npos)
                << b.err;
            EXPECT_EQ(slurp(m.dir / "hb.csv"), slurp(m.dir / "ha.csv"));
            EXPECT_GE(lines_of(slurp(m.dir / "ha.csv")).size(), model.empty() ? 2U : 10U);
            const auto ra = lines_of(slurp(m.dir / "a.csv"));
            auto rb = lines_of(slurp(m.dir / "b.csv"));
            ASSERT_EQ(rb.size(), ra.size() + 3U);
            const auto status = [](const std::string& row) {
                return static_cast<unsigned>(std::stoul(row.substr(row.rfind(',') + 1)));
            };
            EXPECT_EQ(rb[1].substr(0, 7), "-1e300,");
            EXPECT_NE(status(rb[1]) & 256U, 0U) << rb[1];  // before the first model
            EXPECT_EQ(status(rb[1]) & 36U, 36U) << rb[1];  // outside the ephemeris, as in correct
            EXPECT_EQ(rb.back().substr(0, 6), "1e300,");
            EXPECT_NE(status(rb.back()) & 256U, 0U) << rb.back();  // no epoch: no model
            EXPECT_EQ(status(rb.back()) & 36U, 36U) << rb.back();
            rb.erase(rb.begin() + 1);
            rb.pop_back();
            rb.erase(std::find_if(rb.begin(), rb.end(),
                                  [](const std::string& r) { return r.rfind("1.0000001e11,", 0) == 0; }));
            EXPECT_EQ(rb, ra);
        }
    }
}

}  // namespace
}  // namespace ascorr::test
