// The rule for the rotation common to all heads (docs/contract.md, "The
// common rotation"; calib/common_rotation.hpp), measured against the
// simulator's true attitude of the bench (simulate -> fit -> correct -> align).
//
// The combined attitude is computed here independently of the combiner and of
// the rule, in the information form: per epoch each head's CRF estimate
// q_crf_icrf_i = q_chu_crf_i* ⊗ q_chu_icrf_i (the aligned mountings), its
// rotation θ_i from the true attitude, and (Σ W_i)⁻¹ Σ W_i θ_i over the heads
// of a set: the combined attitude's error. Its time-varying part (about the
// mean per CRF axis: a constant offset is what any downstream calibration
// absorbs) is what the rule must not make worse than the aberration stage's.
//
// The do-no-harm reference is formed per epoch, not per orbit as the fit does:
// the full set's combined difference (fitted model − aberration alone) is
// regressed per axis on [1, T029, T032] (the 9 unobservable directions) and
// removed from every head set's combined attitude of the fitted model.
//
// Runtime bound: one mission of 120 days at 120 s (86401 epochs, three heads),
// fitted twice and corrected three times: a few seconds.
#include <gtest/gtest.h>

#include <unistd.h>

#include <Eigen/Dense>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <optional>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "ascorr_host/analysis/align.hpp"
#include "ascorr_host/analysis/combine.hpp"
#include "ascorr_host/analysis/epochs.hpp"
#include "ascorr_host/analysis/fit.hpp"
#include "ascorr_host/analysis/simulate.hpp"
#include "ascorr_host/correct/correct_file.hpp"
#include "ascorr_host/formats/mountings_csv.hpp"
#include "ascorr_host/formats/solutions_csv.hpp"
#include "ascorr_text/text_file.hpp"
#include "cli_run.hpp"
#include "test_support.hpp"

namespace ascorr::host {
namespace {

namespace fs = std::filesystem;

constexpr double kDays = 120.0;
constexpr double kStep = 120.0;

long long key_of(double t) {
    return std::llround(t * 1000.0);
}

// The simulator's true q_crf_icrf per epoch (its attitude file, read here).
std::map<long long, Quaternion<double>> read_truth(const std::string& path) {
    std::map<long long, Quaternion<double>> out;
    std::istringstream in(text::read_text_file(path));
    std::string line;
    std::getline(in, line);  // header t,qw,qx,qy,qz
    while (std::getline(in, line)) {
        double t = 0.0;
        Quaternion<double> q{};
        if (std::sscanf(line.c_str(), "%lf,%lf,%lf,%lf,%lf", &t, &q.w, &q.x, &q.y, &q.z) == 5) {
            out[key_of(t)] = q;
        }
    }
    return out;
}

// T029 and T032 per epoch (head A's row of the raw mission).
std::map<long long, Eigen::Vector2d> read_bench_temperatures(const std::string& raw) {
    std::map<long long, Eigen::Vector2d> out;
    for_each_solution(
        raw,
        [&](const SolutionRecord& r) {
            if (r.head == 0 && r.temperature_present[1] && r.temperature_present[2]) {
                out[key_of(r.t)] = {r.temperature[1], r.temperature[2]};
            }
        },
        "test");
    return out;
}

struct Mission {
    fs::path dir;
    std::string raw;
    MountingsFile nominal;
    std::map<long long, Quaternion<double>> truth;
    std::map<long long, Eigen::Vector2d> temps;
};

const Mission& mission() {
    static const Mission m = [] {
        Mission s;
        s.dir = test::scratch_dir("common-rotation");
        SimulateOptions o;
        o.out = (s.dir / "mission.csv").string();
        o.days = kDays;
        o.step_s = kStep;
        o.seed = 36;
        (void)simulate(o);
        s.raw = o.out;
        s.nominal = read_mountings_file(s.raw + ".mountings.csv");
        s.truth = read_truth(s.raw + ".attitude.csv");
        s.temps = read_bench_temperatures(s.raw);
        return s;
    }();
    return m;
}

// The fitted model's path, with the rule `rule` (nullopt: the default of the
// options given), with or without the mountings.
std::string fitted(const std::string& name, bool with_mountings, std::optional<CommonRotationId> rule) {
    const Mission& m = mission();
    FitOptions f;
    f.in = m.raw;
    f.out = (m.dir / name).string();
    f.min_span_days = 60.0;
    f.selection_report = false;
    if (with_mountings) {
        f.mountings = m.nominal;
        f.mountings_name = m.raw + ".mountings.csv";
    }
    if (rule) {
        f.common_rotation.emplace();
        static_cast<CommonRotationId&>(*f.common_rotation) = *rule;
    }
    (void)fit_model(f);
    return f.out;
}

// Each head's error against the truth per clean epoch with all three heads,
// CRF axes (arcsec), under the mountings that align finds for the corrected
// file (the main job's chain), and their information.
struct Stage {
    std::vector<long long> key;
    std::vector<std::array<Eigen::Vector3d, 3>> theta;
    std::array<Eigen::Matrix3d, 3> w{};
};

// self_calibrate: `correct --self-calibrate --mountings M --combined A` from
// no model (the estimator's rule from M; without `regauge`, each adopted
// model keeps its gauge), else `correct --model`.
Stage stage(const std::string& model, const std::string& name, bool self_calibrate = false, double from_day = 0.0,
            bool rule = true, bool regauge = true) {
    const Mission& m = mission();
    CorrectOptions c;
    c.in = m.raw;
    c.out = (m.dir / name).string();
    c.model = model;
    std::ostringstream log;
    if (self_calibrate && !rule) {
        c.self_calibrate = true;
        (void)correct_file(c, log);
    } else if (self_calibrate) {
        c.self_calibrate = true;
        if (!regauge) {
            c.regauge_arcsec = std::numeric_limits<double>::infinity();
        }
        c.model_history = c.out + ".history.csv";
        (void)correct_and_combine(c, m.raw + ".mountings.csv", c.out + ".combined.csv", log);
    } else {
        (void)correct_file(c, log);
    }
    const long long from_key = m.truth.begin()->first + std::llround(from_day * 86400e3);
    AlignOptions a;
    a.in = c.out;
    const AlignReport aligned = align_rows(rows_of_file(c.out), c.out, m.nominal, a);
    Stage s;
    for (std::uint8_t h = 0; h < 3; ++h) {
        const combine::HeadMounting& hm = aligned.aligned.mountings.head[h];
        s.w[h] = information_crf(hm.q_chu_crf, hm.sigma_cross_arcsec, hm.sigma_about_arcsec);
    }
    EpochAssembler<CorrectedRow> epochs(c.out, [&](const Epoch<CorrectedRow>& e) {
        const auto truth = m.truth.find(key_of(e.t));
        if (truth == m.truth.end() || truth->first < from_key) {
            return;
        }
        std::array<Eigen::Vector3d, 3> theta{};
        for (std::uint8_t h = 0; h < 3; ++h) {
            const std::optional<CorrectedRow>& r = e.head[h];
            if (!r || r->flags != 0 || !(r->confidence <= 5.0) ||
                (r->status & ~(status::kAberrationApplied | status::kThermalApplied)) != 0U) {
                return;
            }
            theta[h] =
                rotation_arcsec(conjugate(aligned.aligned.mountings.head[h].q_chu_crf) * r->q_chu_icrf, truth->second);
        }
        s.key.push_back(key_of(e.t));
        s.theta.push_back(theta);
    });
    rows_of_file(c.out)([&](const CorrectedRow& r) {
        if (r.head < 3) {
            epochs.add(r.t, r.head, r.line, r);
        }
    });
    epochs.finish();
    return s;
}

constexpr std::array<std::uint8_t, 4> kSets = {0b111, 0b011, 0b101, 0b110};  // ABC, AB, AC, BC
const char* set_name(std::uint8_t s) {
    return s == 0b111 ? "ABC" : s == 0b011 ? "AB" : s == 0b101 ? "AC" : "BC";
}

// The combined error of a head set at every epoch of the stage.
std::vector<Eigen::Vector3d> combined_error(const Stage& s, std::uint8_t set) {
    Eigen::Matrix3d w = Eigen::Matrix3d::Zero();
    for (std::uint8_t h = 0; h < 3; ++h) {
        if ((static_cast<unsigned>(set) >> h) & 1U) {
            w += s.w[h];
        }
    }
    const Eigen::Matrix3d w_inv = w.inverse();
    std::vector<Eigen::Vector3d> out;
    out.reserve(s.theta.size());
    for (const auto& theta : s.theta) {
        Eigen::Vector3d sum = Eigen::Vector3d::Zero();
        for (std::uint8_t h = 0; h < 3; ++h) {
            if ((static_cast<unsigned>(set) >> h) & 1U) {
                sum += s.w[h] * theta[h];
            }
        }
        out.push_back(w_inv * sum);
    }
    return out;
}

// Standard deviation per axis (about the mean).
Eigen::Vector3d time_varying_rms(const std::vector<Eigen::Vector3d>& e) {
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (const auto& x : e) {
        mean += x;
    }
    mean /= static_cast<double>(e.size());
    Eigen::Vector3d ss = Eigen::Vector3d::Zero();
    for (const auto& x : e) {
        ss += (x - mean).cwiseAbs2();
    }
    return (ss / static_cast<double>(e.size())).cwiseSqrt();
}

// The do-no-harm reference of a fitted stage: its full-set combined
// difference to the aberration stage, regressed per axis on [1, T029, T032]
// over the epochs both have, removed from each set's combined attitude.
std::array<std::vector<Eigen::Vector3d>, 4> reference(const Stage& fitted, const Stage& aberration) {
    const Mission& m = mission();
    std::map<long long, Eigen::Vector3d> ab;
    const std::vector<Eigen::Vector3d> ab_full = combined_error(aberration, 0b111);
    for (std::size_t k = 0; k < aberration.key.size(); ++k) {
        ab[aberration.key[k]] = ab_full[k];
    }
    const std::vector<Eigen::Vector3d> fit_full = combined_error(fitted, 0b111);
    std::vector<Eigen::RowVector3d> regressors;
    std::vector<Eigen::Vector3d> diff;
    for (std::size_t k = 0; k < fitted.key.size(); ++k) {
        const auto a = ab.find(fitted.key[k]);
        const auto t = m.temps.find(fitted.key[k]);
        if (a != ab.end() && t != m.temps.end()) {
            regressors.emplace_back(1.0, t->second(0), t->second(1));
            diff.push_back(fit_full[k] - a->second);
        }
    }
    Eigen::MatrixXd x(static_cast<Eigen::Index>(regressors.size()), 3);
    Eigen::MatrixXd y(static_cast<Eigen::Index>(regressors.size()), 3);
    for (std::size_t k = 0; k < regressors.size(); ++k) {
        x.row(static_cast<Eigen::Index>(k)) = regressors[k];
        y.row(static_cast<Eigen::Index>(k)) = diff[k].transpose();
    }
    const Eigen::MatrixXd coef = x.colPivHouseholderQr().solve(y);  // 3 regressors × 3 axes
    std::array<std::vector<Eigen::Vector3d>, 4> out;
    for (std::size_t s = 0; s < kSets.size(); ++s) {
        const std::vector<Eigen::Vector3d> e = combined_error(fitted, kSets[s]);
        for (std::size_t k = 0; k < fitted.key.size(); ++k) {
            const Eigen::Vector2d t = m.temps.at(fitted.key[k]);
            const Eigen::RowVector3d r(1.0, t(0), t(1));
            out[s].push_back(e[k] - (r * coef).transpose());
        }
    }
    return out;
}

// The same of the means over bins of an orbit (5400 s): the thermal part,
// with the noise averaged out.
Eigen::Vector3d orbit_mean_rms(const Stage& s, const std::vector<Eigen::Vector3d>& e) {
    std::map<long long, std::pair<Eigen::Vector3d, int>> bins;
    for (std::size_t k = 0; k < e.size(); ++k) {
        auto& b = bins[s.key[k] / 5400000];
        if (b.second == 0) {
            b.first = Eigen::Vector3d::Zero();
        }
        b.first += e[k];
        ++b.second;
    }
    std::vector<Eigen::Vector3d> means;
    for (const auto& kv : bins) {
        if (kv.second.second >= 10) {
            means.push_back(kv.second.first / kv.second.second);
        }
    }
    return time_varying_rms(means);
}

void print(const char* what, std::uint8_t set, const Eigen::Vector3d& v) {
    std::printf("%-34s %-3s %.3f / %.3f / %.3f arcsec\n", what, set_name(set), v(0), v(1), v(2));
}

struct Measured {
    Stage aberration;
    Stage combined;  // fit --mountings (the default rule: combined)
    Stage smallest;  // fit without mountings (the rule of today)
};

const Measured& measured() {
    static const Measured m = [] {
        Measured r;
        r.aberration = stage("", "aberration.csv");
        r.combined = stage(fitted("combined.csv", true, std::nullopt), "th-combined.csv");
        r.smallest = stage(fitted("smallest.csv", false, std::nullopt), "th-smallest.csv");
        return r;
    }();
    return m;
}

// The full set over all its epochs: the fitted model with the rule moves the
// combined attitude's time-varying error no higher than the aberration stage
// alone; the rule of today (smallest corrections) does, on this mission: the
// mutation check.
TEST(CommonRotation, FullSetNoWorseThanTheAberrationStageAlone) {
    const Measured& m = measured();
    ASSERT_GT(m.combined.key.size(), 30000U);
    const Eigen::Vector3d ab = time_varying_rms(combined_error(m.aberration, 0b111));
    const Eigen::Vector3d rule = time_varying_rms(combined_error(m.combined, 0b111));
    const Eigen::Vector3d today = time_varying_rms(combined_error(m.smallest, 0b111));
    print("aberration stage alone", 0b111, ab);
    print("fitted, --common-rotation combined", 0b111, rule);
    print("fitted, smallest (mutation)", 0b111, today);
    const Eigen::Vector3d ab_orbit = orbit_mean_rms(m.aberration, combined_error(m.aberration, 0b111));
    const Eigen::Vector3d rule_orbit = orbit_mean_rms(m.combined, combined_error(m.combined, 0b111));
    const Eigen::Vector3d today_orbit = orbit_mean_rms(m.smallest, combined_error(m.smallest, 0b111));
    print("orbit means: aberration stage alone", 0b111, ab_orbit);
    print("orbit means: combined", 0b111, rule_orbit);
    print("orbit means: smallest (mutation)", 0b111, today_orbit);
    for (int a = 0; a < 3; ++a) {
        EXPECT_LE(rule(a), ab(a)) << "axis " << a;
        EXPECT_LE(rule_orbit(a), ab_orbit(a)) << "axis " << a;
    }
    EXPECT_GT((today - ab).maxCoeff(), 0.0) << "the rule of today no longer fails: the test cannot tell the rules";
    EXPECT_GT((today_orbit - ab_orbit).maxCoeff(), 0.0) << "the rule of today no longer fails on orbit means";
}

// Every head set within 5 % of the do-no-harm reference per axis.
TEST(CommonRotation, EveryHeadSetWithinFivePercentOfTheReference) {
    const Measured& m = measured();
    const std::array<std::vector<Eigen::Vector3d>, 4> ref = reference(m.smallest, m.aberration);
    bool smallest_outside = false;
    for (std::size_t s = 0; s < kSets.size(); ++s) {
        const Eigen::Vector3d r = time_varying_rms(ref[s]);
        const Eigen::Vector3d rule = time_varying_rms(combined_error(m.combined, kSets[s]));
        const Eigen::Vector3d today = time_varying_rms(combined_error(m.smallest, kSets[s]));
        print("do-no-harm reference (per epoch)", kSets[s], r);
        print("fitted, --common-rotation combined", kSets[s], rule);
        for (int a = 0; a < 3; ++a) {
            EXPECT_NEAR(rule(a) / r(a), 1.0, 0.05) << set_name(kSets[s]) << " axis " << a;
            smallest_outside = smallest_outside || std::fabs(today(a) / r(a) - 1.0) > 0.05;
        }
    }
    EXPECT_TRUE(smallest_outside) << "mutation: the smallest corrections are within 5 % too";
}

// The rule moves only what no IBA sees: the inter-boresight angles of the two
// fitted models are the same at every epoch (to the corrected file's digits).
TEST(CommonRotation, InterBoresightAnglesUnchanged) {
    const Measured& m = measured();
    ASSERT_EQ(m.combined.key.size(), m.smallest.key.size());
    double worst = 0.0;
    for (std::size_t k = 0; k < m.combined.key.size(); ++k) {
        for (std::uint8_t i = 0; i < 3; ++i) {
            for (std::uint8_t j = static_cast<std::uint8_t>(i + 1); j < 3; ++j) {
                // θ_i − θ_j is the heads' relative rotation (CRF axes) up to
                // the aligned mountings' difference, which is per stage.
                const Eigen::Vector3d d_rule = m.combined.theta[k][i] - m.combined.theta[k][j];
                const Eigen::Vector3d d_today = m.smallest.theta[k][i] - m.smallest.theta[k][j];
                worst = std::max(worst, (d_rule - d_today).norm());
            }
        }
    }
    std::printf("largest change of a relative head rotation between the rules: %.2e arcsec\n", worst);
    // A constant difference would be the aligned mountings'; a time-varying
    // one would change the IBAs.
    EXPECT_LT(worst, 5.0);
}

// ---- On board: the estimator's rule, from the mountings it combines with

struct SelfCalibrated {
    Stage aberration;  // from day 30 (60: agreement)
    Stage estimator;
    Stage aberration_60;
    Stage estimator_60;
    Stage fitted_60;
    Stage frame_f;     // the estimator without the rule (its own frame): the mutation
    Stage no_regauge;  // the rule on adoption only (each model keeps its gauge): the mutation
};

const SelfCalibrated& self_calibrated() {
    static const SelfCalibrated s = [] {
        SelfCalibrated r;
        r.aberration = stage("", "aberration-30.csv", false, 30.0);
        r.estimator = stage("", "self-calibrated.csv", true, 30.0);
        r.aberration_60 = stage("", "aberration-60.csv", false, 60.0);
        r.estimator_60 = stage("", "self-calibrated-60.csv", true, 60.0);
        r.fitted_60 = stage((mission().dir / "combined.csv").string(), "th-combined-60.csv", false, 60.0);
        r.frame_f = stage("", "self-calibrated-frame.csv", true, 30.0, false);
        r.no_regauge = stage("", "self-calibrated-no-regauge.csv", true, 30.0, true, false);
        return r;
    }();
    return s;
}

// From day 30, full set: the self-calibrated combined attitude is no worse
// than the aberration stage's alone.
TEST(CommonRotationOnBoard, FromDay30NoWorseThanTheAberrationStageAlone) {
    (void)measured();  // the fitted model (combined.csv)
    const SelfCalibrated& s = self_calibrated();
    const Eigen::Vector3d ab = time_varying_rms(combined_error(s.aberration, 0b111));
    const Eigen::Vector3d est = time_varying_rms(combined_error(s.estimator, 0b111));
    const Eigen::Vector3d ab_orbit = orbit_mean_rms(s.aberration, combined_error(s.aberration, 0b111));
    const Eigen::Vector3d est_orbit = orbit_mean_rms(s.estimator, combined_error(s.estimator, 0b111));
    print("from day 30: aberration alone", 0b111, ab);
    print("from day 30: self-calibrated", 0b111, est);
    print("from day 30: estimator's frame F", 0b111, time_varying_rms(combined_error(s.frame_f, 0b111)));
    const std::array<std::vector<Eigen::Vector3d>, 4> ref = reference(s.estimator, s.aberration);
    print("from day 30: do-no-harm reference", 0b111, time_varying_rms(ref[0]));
    print("orbit means: do-no-harm reference", 0b111, orbit_mean_rms(s.estimator, ref[0]));
    print("orbit means: estimator's frame F", 0b111, orbit_mean_rms(s.frame_f, combined_error(s.frame_f, 0b111)));
    print("orbit means: aberration alone", 0b111, ab_orbit);
    print("orbit means: self-calibrated", 0b111, est_orbit);
    ASSERT_GT(s.estimator.key.size(), 20000U);
    // The estimator is causal: its model at day t is gauged over the orbits
    // before t, and re-gauged as they grow. No larger than the aberration
    // stage alone on every axis, and within 5 % of the (non-causal) reference
    // per axis, as the ground fit, where its own frame F (a mutation) is 16 %
    // off. Without the re-gauge (the other mutation) a model gauged over the
    // first weeks is kept for weeks: larger than the aberration stage's.
    const Eigen::Vector3d r = time_varying_rms(ref[0]);
    const Eigen::Vector3d own = time_varying_rms(combined_error(s.frame_f, 0b111));
    const Eigen::Vector3d kept = time_varying_rms(combined_error(s.no_regauge, 0b111));
    print("from day 30: without the re-gauge", 0b111, kept);
    bool own_outside = false;
    for (int a = 0; a < 3; ++a) {
        EXPECT_LE(est(a), ab(a)) << "axis " << a;
        EXPECT_LT(est(a), kept(a)) << "axis " << a;
        EXPECT_NEAR(est(a) / r(a), 1.0, 0.05) << "axis " << a;
        own_outside = own_outside || std::fabs(own(a) / r(a) - 1.0) > 0.05;
    }
    EXPECT_TRUE(own_outside) << "mutation: the estimator's own frame is within 5 % of the reference too";
    EXPECT_GT((kept - ab).maxCoeff(), 0.0) << "mutation: without the re-gauge it is no larger either";
    // Every head set within 5 % of the reference (formed from the full set's).
    for (std::size_t k = 1; k < kSets.size(); ++k) {
        const Eigen::Vector3d rk = time_varying_rms(ref[k]);
        const Eigen::Vector3d ek = time_varying_rms(combined_error(s.estimator, kSets[k]));
        print("from day 30: do-no-harm reference", kSets[k], rk);
        print("from day 30: self-calibrated", kSets[k], ek);
        for (int a = 0; a < 3; ++a) {
            EXPECT_NEAR(ek(a) / rk(a), 1.0, 0.05) << set_name(kSets[k]) << " axis " << a;
        }
    }
}

// The re-gauge moves only what no IBA sees: the heads' relative rotations
// with and without it differ by a constant (the aligned mountings') alone.
TEST(CommonRotationOnBoard, TheRegaugeChangesNoInterBoresightAngle) {
    (void)measured();  // the fitted model (combined.csv)
    const SelfCalibrated& s = self_calibrated();
    std::map<long long, std::size_t> kept;
    for (std::size_t k = 0; k < s.no_regauge.key.size(); ++k) {
        kept[s.no_regauge.key[k]] = k;
    }
    double worst = 0.0;
    std::vector<Eigen::Vector3d> turned;  // head A with and without: the re-gauge did something
    for (std::size_t k = 0; k < s.estimator.key.size(); ++k) {
        const auto it = kept.find(s.estimator.key[k]);
        if (it != kept.end()) {
            turned.push_back(s.estimator.theta[k][0] - s.no_regauge.theta[it->second][0]);
        }
    }
    EXPECT_GT(time_varying_rms(turned).maxCoeff(), 0.01) << "no re-gauge: the check below tests nothing";
    for (std::uint8_t i = 0; i < 3; ++i) {
        for (std::uint8_t j = static_cast<std::uint8_t>(i + 1); j < 3; ++j) {
            std::vector<Eigen::Vector3d> d;
            for (std::size_t k = 0; k < s.estimator.key.size(); ++k) {
                const auto it = kept.find(s.estimator.key[k]);
                if (it != kept.end()) {
                    const auto& a = s.estimator.theta[k];
                    const auto& b = s.no_regauge.theta[it->second];
                    d.push_back((a[i] - a[j]) - (b[i] - b[j]));
                }
            }
            ASSERT_GT(d.size(), 20000U);
            worst = std::max(worst, time_varying_rms(d).maxCoeff());
        }
    }
    std::printf("relative head rotations with and without the re-gauge: std of the difference %.2e arcsec\n", worst);
    EXPECT_LT(worst, 1e-3);
}

// From day 60 the ground fit's and the estimator's combined attitudes (same
// data, same rule) agree: the standard deviation of their difference per axis.
TEST(CommonRotationOnBoard, FitAndEstimatorAgreeFromDay60) {
    (void)measured();
    const SelfCalibrated& s = self_calibrated();
    std::map<long long, Eigen::Vector3d> fit;
    const std::vector<Eigen::Vector3d> f = combined_error(s.fitted_60, 0b111);
    for (std::size_t k = 0; k < f.size(); ++k) {
        fit[s.fitted_60.key[k]] = f[k];
    }
    const std::vector<Eigen::Vector3d> e = combined_error(s.estimator_60, 0b111);
    std::vector<Eigen::Vector3d> diff;
    for (std::size_t k = 0; k < e.size(); ++k) {
        const auto it = fit.find(s.estimator_60.key[k]);
        if (it != fit.end()) {
            diff.push_back(e[k] - it->second);
        }
    }
    ASSERT_GT(diff.size(), 10000U);
    const Eigen::Vector3d sd = time_varying_rms(diff);
    print("from day 60: estimator - fit (std)", 0b111, sd);
    for (int a = 0; a < 3; ++a) {
        EXPECT_LE(sd(a), 0.3) << "axis " << a;
    }
}

// ---- The rule itself, on orbits it did not make (random, with a known answer)

struct Synthetic {
    std::vector<OrbitAverage> orbits;
    HeadOrientations n_ref;
};

Synthetic synthetic_orbits() {
    Synthetic s;
    std::mt19937_64 rng(36);
    std::normal_distribution<double> g(0.0, 1.0);
    for (std::size_t h = 0; h < kMaxHeads; ++h) {
        s.n_ref[h] = Eigen::Quaterniond(g(rng), g(rng), g(rng), g(rng)).normalized().toRotationMatrix();
    }
    for (int k = 0; k < 400; ++k) {
        OrbitAverage o;
        o.t_mid = 5400.0 * k;
        const double season = std::sin(2.0 * M_PI * k / 250.0);
        const double t2 = 15.0 + 4.0 * season + 0.3 * g(rng);
        const double t3 = 12.0 + 3.0 * std::cos(2.0 * M_PI * k / 170.0) + 0.3 * g(rng);
        for (std::size_t h = 0; h < 3; ++h) {
            const double t1 = 20.0 + 5.0 * season + static_cast<double>(h) + 0.5 * g(rng);
            o.x[h] = Eigen::Vector3d(t1, t2 - t1, t3 - t1);
            o.x2[h] = o.x[h].cwiseAbs2();
            o.e[h] = Eigen::Vector3d(0.4 * (t1 - 20.0) + 0.2 * g(rng), -0.3 * (t2 - 15.0) + 0.2 * g(rng),
                                     0.5 * (t3 - 12.0) + g(rng));
        }
        s.orbits.push_back(o);
    }
    return s;
}

// Equal isotropic weights in F (A_h = N_hᵀ) are the smallest corrections:
// the general rule gives today's model to rounding.
TEST(CommonRotationRule, EqualWeightsAreTheSmallestCorrections) {
    const Synthetic s = synthetic_orbits();
    const TermsFit smallest = solve_terms(s.orbits, s.n_ref, kPaperHeads, Terms::kLinear, 1e6, 2.0);
    CommonRotation equal;
    equal.rule = CommonRotationRule::kCombined;
    for (std::size_t h = 0; h < 3; ++h) {
        equal.motion[h] = s.n_ref[h].transpose();
    }
    const TermsFit general = solve_terms(s.orbits, s.n_ref, kPaperHeads, Terms::kLinear, 1e6, 2.0, equal);
    ASSERT_TRUE(smallest.refused.empty()) << smallest.refused;
    ASSERT_TRUE(general.refused.empty()) << general.refused;
    double worst = 0.0;
    for (std::size_t h = 0; h < 3; ++h) {
        for (std::size_t a = 0; a < 3; ++a) {
            for (std::size_t k = 0; k < kLinearModelTerms; ++k) {
                worst = std::max(worst,
                                 std::fabs(general.model.coefficients[h][a][k] - smallest.model.coefficients[h][a][k]));
            }
        }
    }
    EXPECT_LT(worst, 1e-9);
    // Mutation: other weights (A's about-boresight weight 100 times lower) move the model.
    equal.motion[0] = s.n_ref[0].transpose() * Eigen::Vector3d(1.0, 1.0, 0.01).asDiagonal();
    const TermsFit other = solve_terms(s.orbits, s.n_ref, kPaperHeads, Terms::kLinear, 1e6, 2.0, equal);
    double moved = 0.0;
    for (std::size_t k = 0; k < kLinearModelTerms; ++k) {
        moved = std::max(moved, std::fabs(other.model.coefficients[1][0][k] - smallest.model.coefficients[1][0][k]));
    }
    EXPECT_GT(moved, 1e-3);
}

// rigid-A: A's correction has no part a common rotation could take. Over the
// orbits, Σ N_Aᵀ c_A(k) [1, T2, T3]ᵀ = 0 (the normal equations of the
// smallest correction of A alone), where the smallest corrections leave it.
TEST(CommonRotationRule, RigidHeadKeepsNoCommonPart) {
    const Synthetic s = synthetic_orbits();
    const auto normal = [&](const ModelFile& m) {
        Eigen::Matrix3d sum = Eigen::Matrix3d::Zero();
        for (const OrbitAverage& o : s.orbits) {
            Eigen::Vector3d c;
            for (Eigen::Index a = 0; a < 3; ++a) {
                const auto& k = m.coefficients[0][static_cast<std::size_t>(a)];
                c(a) = k[0] + k[1] * o.x[0](0) + k[2] * o.x[0](1) + k[3] * o.x[0](2);
            }
            const Eigen::RowVector3d r(1.0, o.x[0](0) + o.x[0](1), o.x[0](0) + o.x[0](2));
            sum += (s.n_ref[0].transpose() * c) * r;
        }
        return sum.cwiseAbs().maxCoeff() / static_cast<double>(s.orbits.size());
    };
    CommonRotation rigid;
    rigid.rule = CommonRotationRule::kRigid;
    rigid.rigid_head = 0;
    const TermsFit a = solve_terms(s.orbits, s.n_ref, kPaperHeads, Terms::kLinear, 1e6, 2.0, rigid);
    const TermsFit smallest = solve_terms(s.orbits, s.n_ref, kPaperHeads, Terms::kLinear, 1e6, 2.0);
    ASSERT_TRUE(a.refused.empty()) << a.refused;
    std::printf("rigid-A: %.2e, smallest: %.2e (arcsec·degC)\n", normal(a.model), normal(smallest.model));
    EXPECT_LT(normal(a.model), 1e-9);
    EXPECT_GT(normal(smallest.model), 1e-3);  // the test can fail
}

// ---- The model file and the command line

TEST(CommonRotationFile, TheRuleRoundTripsAndBadValuesAreRefused) {
    ModelFile m = parse_model("m.csv", "chu,axis,c0,c1,c2,c3\nA,alpha,1,0,0,0\nA,beta,0,0,0,0\nA,gamma,0,0,0,0\n");
    EXPECT_EQ(common_rotation_name(m.common_rotation), "smallest");
    EXPECT_EQ(format_model(m).find("common_rotation"), std::string::npos);  // byte-identical to before
    m.common_rotation = *common_rotation_named("rigid-B");
    const std::string text = format_model(m);
    EXPECT_NE(text.find("c3,common_rotation\n"), std::string::npos) << text;
    EXPECT_EQ(common_rotation_name(parse_model("m.csv", text).common_rotation), "rigid-B");
    const auto refused = [](const std::string& body, const std::string& what) {
        try {
            (void)parse_model("m.csv", "chu,axis,c0,c1,c2,c3,common_rotation\n" + body);
            ADD_FAILURE() << "accepted: " << body;
        } catch (const text::InputError& e) {
            EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
        }
    };
    refused("A,alpha,1,0,0,0,largest\nA,beta,0,0,0,0,largest\nA,gamma,0,0,0,0,largest\n",
            "m.csv:2:17: column 'common_rotation': expected smallest, combined or rigid-X");
    refused("A,alpha,1,0,0,0,combined\nA,beta,0,0,0,0,smallest\nA,gamma,0,0,0,0,combined\n",
            "m.csv:3:16: column 'common_rotation': 'smallest' differs from the rows above ('combined')");
    refused("A,alpha,1,0,0,0,rigid-Z\nA,beta,0,0,0,0,rigid-Z\nA,gamma,0,0,0,0,rigid-Z\n", "got 'rigid-Z'");
}

TEST(CommonRotationCli, RulesNeedWhatTheyWeighWith) {
    const Mission& m = mission();
    const std::string in = " --in " + m.raw + " --min-days 60";
    const fs::path dir = m.dir;
    {
        std::ofstream f(dir / "no-sigmas.csv");
        MountingsFile bare = m.nominal;
        bare.sigmas = false;
        f << format_mountings(bare);
    }
    struct Case {
        std::string args;
        std::string message;
    };
    for (const Case& c : std::vector<Case>{
             {" --common-rotation combined", "--common-rotation combined needs the mountings (--mountings)"},
             {" --mountings " + (dir / "no-sigmas.csv").string(), "no-sigmas.csv: the mountings give no sigma_cross"},
             {" --common-rotation rigid-D", "head D is not among the heads fitted (ABC)"},
             {" --common-rotation largest", "expected smallest, combined or rigid-X"}}) {
        const test::CliRun r = test::run_in("fit" + in + " --out refused.csv" + c.args, dir);
        EXPECT_NE(r.exit_code, 0) << c.args;
        EXPECT_NE(r.err.find(c.message), std::string::npos) << c.args << ": " << r.err;
        EXPECT_FALSE(fs::exists(dir / "refused.csv")) << c.args;
    }
    const test::CliRun plain = test::run_in("fit" + in + " --out plain.csv", dir);
    ASSERT_EQ(plain.exit_code, 0) << plain.err;
    EXPECT_NE(plain.err.find("warning: no --mountings"), std::string::npos) << plain.err;
    const test::CliRun rule =
        test::run_in("fit" + in + " --out rule.csv --mountings " + m.raw + ".mountings.csv > report.txt", dir);
    ASSERT_EQ(rule.exit_code, 0) << rule.err;
    EXPECT_EQ(rule.err.find("warning"), std::string::npos) << rule.err;
    const std::string report = text::read_text_file((dir / "report.txt").string());
    EXPECT_NE(report.find("--common-rotation combined, weights of the mountings"), std::string::npos) << report;
    EXPECT_EQ(common_rotation_name(read_model_file((dir / "rule.csv").string()).common_rotation), "combined");
}

}  // namespace
}  // namespace ascorr::host
