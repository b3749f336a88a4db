// Issue 28's acceptance checks of `align` on simulated missions (simulate ->
// correct -> [fit] -> align), against the simulator's truth: its mountings
// and noise (OUT.mountings.csv, simulate.hpp) and its thermal model.
//
// Runtime bound: missions of 3 days at 20 s (12961 epochs) and 30 days at
// 120 s (21601 epochs); the whole program takes a few seconds.
//
// The combined attitude is computed here independently of the combiner, in
// the information form: per epoch each head's CRF estimate
// q_crf_icrf_i = q_chu_crf_i* ⊗ q_chu_icrf_i, its rotation θ_i from a
// reference, and (Σ W_i)⁻¹ Σ W_i θ_i over the heads of a set.
#include <gtest/gtest.h>

#include <unistd.h>

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "ascorr/core/constants.hpp"
#include "ascorr/pipeline/epoch_key.hpp"
#include "ascorr_host/analysis/align.hpp"
#include "ascorr_host/analysis/epochs.hpp"
#include "ascorr_host/analysis/fit.hpp"
#include "ascorr_host/analysis/simulate.hpp"
#include "ascorr_host/correct/correct_file.hpp"
#include "ascorr_host/formats/combined_csv.hpp"
#include "ascorr_host/formats/mountings_csv.hpp"
#include "cli_run.hpp"

namespace ascorr::host {
namespace {

namespace fs = std::filesystem;

// A folder of this process (CTest runs the tests of this program in parallel
// processes, each building the missions it needs), removed at exit.
fs::path scratch(const std::string& name) {
    struct Root {
        fs::path path = fs::path(testing::TempDir()) / ("ascorr_align_" + std::to_string(getpid()));
        ~Root() {
            std::error_code ec;
            fs::remove_all(path, ec);
        }
    };
    static const Root root;
    const fs::path d = root.path / name;
    fs::remove_all(d);
    fs::create_directories(d);
    return d;
}

// A simulated mission, raw.
std::string simulate_mission(const fs::path& dir, double days, double step_s, std::uint64_t seed) {
    SimulateOptions s;
    s.out = (dir / "mission.csv").string();
    s.days = days;
    s.step_s = step_s;
    s.seed = seed;
    (void)simulate(s);
    return s.out;
}

// The mission corrected: model empty for the aberration stage alone.
std::string corrected(const std::string& raw, const std::string& model, const std::string& name) {
    CorrectOptions c;
    c.in = raw;
    c.out = (fs::path(raw).parent_path() / name).string();
    c.model = model;
    std::ostringstream log;
    (void)correct_file(c, log);
    return c.out;
}

AlignReport run_align(const std::string& in, const MountingsFile& m) {
    AlignOptions opt;
    opt.in = in;
    return align_rows(rows_of_file(in), in, m, opt);
}

Eigen::Matrix3d information_of(const combine::HeadMounting& m) {
    return information_crf(m.q_chu_crf, m.sigma_cross_arcsec, m.sigma_about_arcsec);
}

// ---- The noise estimated from the data

struct NoiseMission {
    std::string corrected;
    MountingsFile truth;
    AlignReport report;
};

const NoiseMission& noise_mission() {
    static const NoiseMission m = [] {
        NoiseMission n;
        const fs::path dir = scratch("noise");
        const std::string raw = simulate_mission(dir, 3.0, 20.0, 11);
        n.truth = read_mountings_file(raw + ".mountings.csv");
        n.corrected = corrected(raw, raw + ".truth.csv", "corrected.csv");
        MountingsFile given = n.truth;  // the true mountings without their sigmas
        given.sigmas = false;
        n.report = run_align(n.corrected, given);
        return n;
    }();
    return m;
}

// Row order decides nothing: the same rows shuffled and reversed give the
// same mountings file byte for byte, and as many degrees of freedom as in
// time order (epochs that lack a head were handed on after all the others,
// in hash order: 1426 -> 18..55 degrees of freedom on a shuffled file).
TEST(AlignMission, RowOrderDecidesNothing) {
    const NoiseMission& m = noise_mission();
    std::vector<std::string> lines;
    {
        std::istringstream in(test::slurp(m.corrected));
        for (std::string l; std::getline(in, l);) {
            lines.push_back(l);
        }
    }
    const fs::path dir = fs::path(m.corrected).parent_path();
    MountingsFile given = m.truth;
    given.sigmas = false;
    const AlignReport ordered = run_align(m.corrected, given);
    std::mt19937 rng(37);
    for (const char* order : {"shuffled", "reversed"}) {
        std::vector<std::string> rows(lines.begin() + 1, lines.end());
        if (std::string(order) == "shuffled") {
            std::shuffle(rows.begin(), rows.end(), rng);
        } else {
            std::reverse(rows.begin(), rows.end());
        }
        const std::string path = (dir / (std::string(order) + ".csv")).string();
        {
            std::ofstream f(path);
            f << lines[0] << '\n';
            for (const std::string& r : rows) {
                f << r << '\n';
            }
        }
        const AlignReport r = run_align(path, given);
        EXPECT_TRUE(r.rows_sorted) << order;
        EXPECT_EQ(format_mountings(r.aligned), format_mountings(ordered.aligned)) << order;
        EXPECT_EQ(r.noise.dof, ordered.noise.dof) << order;
    }
    EXPECT_FALSE(ordered.rows_sorted);
    std::printf("degrees of freedom: %.0f in any row order\n", ordered.noise.dof);
}

// The estimated σc and σa of each head within 3 % of the simulator's truth
// (1.5" across, 10" about), and within 4 of their formal σ.
TEST(AlignMission, EstimatedNoiseIsTheSimulatorsWithinThreePercent) {
    const NoiseMission& m = noise_mission();
    EXPECT_EQ(m.report.noise.model, NoiseModel::kPerHead);
    EXPECT_TRUE(m.report.noise.converged);
    for (std::uint8_t h = 0; h < 3; ++h) {
        SCOPED_TRACE(std::string("CHU ") + kHeadLetters[h]);
        const HeadNoise& n = m.report.head[h].noise;
        const combine::HeadMounting& t = m.truth.mountings.head[h];
        std::printf("CHU %c: sigma_cross %.4f +- %.4f (truth %.2f), sigma_about %.4f +- %.4f (truth %.2f)\n",
                    kHeadLetters[h], n.sigma_cross_arcsec, n.sd_cross_arcsec, t.sigma_cross_arcsec,
                    n.sigma_about_arcsec, n.sd_about_arcsec, t.sigma_about_arcsec);
        EXPECT_NEAR(n.sigma_cross_arcsec, t.sigma_cross_arcsec, 0.03 * t.sigma_cross_arcsec);
        EXPECT_NEAR(n.sigma_about_arcsec, t.sigma_about_arcsec, 0.03 * t.sigma_about_arcsec);
        EXPECT_NEAR(n.sigma_cross_arcsec, t.sigma_cross_arcsec, 4.0 * n.sd_cross_arcsec);
        EXPECT_NEAR(n.sigma_about_arcsec, t.sigma_about_arcsec, 4.0 * n.sd_about_arcsec);
    }
}

// The expected error per CRF axis of the combination weighted with `used`
// (gains K_i = (Σ Ŵ)⁻¹ Ŵ_i) when the heads' true noise is `truth`, over the
// optimal bound sqrt(diag((Σ W_i)⁻¹)): the largest ratio over the axes.
double worst_ratio(HeadMask set, const std::array<Eigen::Matrix3d, kMaxHeads>& used, const MountingsFile& truth) {
    Eigen::Matrix3d w_used = Eigen::Matrix3d::Zero();
    Eigen::Matrix3d w_true = Eigen::Matrix3d::Zero();
    for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
        if (has_head(set, h)) {
            w_used += used[h];
            w_true += information_of(truth.mountings.head[h]);
        }
    }
    Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
    for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
        if (has_head(set, h)) {
            const Eigen::Matrix3d k = w_used.inverse() * used[h];
            cov += k * information_of(truth.mountings.head[h]).inverse() * k.transpose();
        }
    }
    const Eigen::Vector3d bound = w_true.inverse().diagonal().cwiseSqrt();
    return (cov.diagonal().cwiseSqrt().array() / bound.array()).maxCoeff();
}

// With the noise estimated by align (and its mountings), the combined error
// per CRF axis is within 5 % of the optimal bound for every head set; equal
// weights (the mutation) are not.
TEST(AlignMission, CombinedErrorWithEstimatedNoiseIsWithinFivePercentOfTheBound) {
    const NoiseMission& m = noise_mission();
    std::array<Eigen::Matrix3d, kMaxHeads> estimated{};
    std::array<Eigen::Matrix3d, kMaxHeads> equal{};
    for (std::uint8_t h = 0; h < 3; ++h) {
        estimated[h] = information_of(m.report.aligned.mountings.head[h]);
        equal[h] = information_crf(m.report.aligned.mountings.head[h].q_chu_crf, 1.0, 1.0);
    }
    double worst_equal = 0.0;
    for (HeadMask set = 1; set <= kPaperHeads; ++set) {
        const double r = worst_ratio(set, estimated, m.truth);
        std::printf("heads %s: error / bound %.4f (equal weights %.3f)\n", head_letters(set).c_str(), r,
                    worst_ratio(set, equal, m.truth));
        EXPECT_LE(r, 1.05) << head_letters(set);
        worst_equal = std::max(worst_equal, worst_ratio(set, equal, m.truth));
    }
    EXPECT_GT(worst_equal, 2.0);  // equal weights: about 3 times the bound
}

// ---- Mountings: a known perturbation, and the CRF kept

// The true mountings with head A's turned by 20" (CRF axes): align removes the
// relative error. Every head's M2 is then the truth turned by one common
// rotation c, the datum's: c = (Σ W)⁻¹ W_A p (the weighted mean of the
// corrections is zero, and only A's was not). Bound: 4 formal σ of the
// estimate per axis (each below 0.1").
TEST(AlignMission, RecoversAKnownPerturbationAndKeepsTheCrf) {
    const NoiseMission& m = noise_mission();
    const Eigen::Vector3d p(12.0, -16.0, 0.0);  // 20"
    MountingsFile given = m.truth;
    given.mountings.head[0].q_chu_crf = given.mountings.head[0].q_chu_crf * rotation_quaternion(p);
    const fs::path dir = scratch("perturbed");
    write_mountings_file((dir / "given.csv").string(), given);
    AlignOptions opt;
    opt.in = m.corrected;
    opt.mountings = (dir / "given.csv").string();
    opt.out = (dir / "aligned.csv").string();
    const AlignReport r = align_file(opt);
    const MountingsFile m2 = read_mountings_file(opt.out);
    Eigen::Matrix3d w_sum = Eigen::Matrix3d::Zero();
    for (std::uint8_t h = 0; h < 3; ++h) {
        w_sum += information_of(m2.mountings.head[h]);
    }
    const Eigen::Vector3d c = w_sum.inverse() * information_of(m2.mountings.head[0]) * p;
    Eigen::Vector3d weighted = Eigen::Vector3d::Zero();
    for (std::uint8_t h = 0; h < 3; ++h) {
        SCOPED_TRACE(std::string("CHU ") + kHeadLetters[h]);
        const Eigen::Vector3d from_truth = rotation_arcsec(
            conjugate(m.truth.mountings.head[h].q_chu_crf) * m2.mountings.head[h].q_chu_crf, {1.0, 0.0, 0.0, 0.0});
        std::printf("CHU %c: M2 from the truth %+.4f %+.4f %+.4f, expected %+.4f %+.4f %+.4f\n", kHeadLetters[h],
                    from_truth.x(), from_truth.y(), from_truth.z(), c.x(), c.y(), c.z());
        for (int axis = 0; axis < 3; ++axis) {
            EXPECT_NEAR(from_truth(axis), c(axis), 4.0 * r.head[h].rotation_sd_arcsec(axis)) << axis;
            EXPECT_LT(r.head[h].rotation_sd_arcsec(axis), 0.1);
        }
        const Eigen::Vector3d from_given = rotation_arcsec(
            conjugate(given.mountings.head[h].q_chu_crf) * m2.mountings.head[h].q_chu_crf, {1.0, 0.0, 0.0, 0.0});
        weighted += information_of(m2.mountings.head[h]) * from_given;
    }
    // The CRF of M is kept: the information-weighted mean of M -> M2 is zero
    // (to the file's digits and the composition of small rotations).
    EXPECT_LT((w_sum.inverse() * weighted).norm(), 1e-6);
    // Mutation check: the perturbation was seen (A turned back by about 20").
    const Eigen::Vector3d a_back = rotation_arcsec(
        conjugate(given.mountings.head[0].q_chu_crf) * m2.mountings.head[0].q_chu_crf, {1.0, 0.0, 0.0, 0.0});
    EXPECT_GT(a_back.norm(), 15.0);
}

// ---- Steps at head-set changes, with a fitted model

// The clean epochs of a corrected file with all three heads: each head's CRF
// estimate under the mountings m.
struct FullEpoch {
    double t = 0.0;
    std::array<Quaternion<double>, 3> q_crf_icrf{};
};

std::vector<FullEpoch> full_epochs(const std::string& path, const MountingsFile& m) {
    std::vector<FullEpoch> out;
    EpochAssembler<CorrectedRow> epochs(path, [&](const Epoch<CorrectedRow>& e) {
        FullEpoch f;
        f.t = e.t;
        for (std::uint8_t h = 0; h < 3; ++h) {
            const std::optional<CorrectedRow>& r = e.head[h];
            const StatusBits bad = status::kRejected | status::kNoVelocity | status::kNoTemperature |
                                   status::kThermalOutOfRange | status::kNoModelForHead;
            if (!r || r->flags != 0 || !(r->confidence <= 5.0) || (r->status & bad) != 0U) {
                return;
            }
            f.q_crf_icrf[h] = conjugate(m.mountings.head[h].q_chu_crf) * r->q_chu_icrf;
        }
        out.push_back(f);
    });
    rows_of_file(path)([&](const CorrectedRow& r) {
        if (r.head < 3) {
            epochs.add(r.t, r.head, r.line, r);
        }
    });
    epochs.finish();
    return out;
}

// The step when one head is dropped: RMS over days of the daily mean of
// (combined with A, B, C) − (combined without the head), the largest over
// the dropped heads and the CRF axes, arcsec.
double largest_step(const std::vector<FullEpoch>& epochs, const MountingsFile& m) {
    std::array<Eigen::Matrix3d, 3> w{};
    for (std::uint8_t h = 0; h < 3; ++h) {
        w[h] = information_of(m.mountings.head[h]);
    }
    double worst = 0.0;
    for (std::uint8_t dropped = 0; dropped < 3; ++dropped) {
        std::map<long long, std::pair<Eigen::Vector3d, std::size_t>> days;
        for (const FullEpoch& e : epochs) {
            Eigen::Matrix3d w_all = Eigen::Matrix3d::Zero();
            Eigen::Matrix3d w_sub = Eigen::Matrix3d::Zero();
            Eigen::Vector3d s_all = Eigen::Vector3d::Zero();
            Eigen::Vector3d s_sub = Eigen::Vector3d::Zero();
            for (std::uint8_t h = 0; h < 3; ++h) {
                const Eigen::Vector3d theta = rotation_arcsec(e.q_crf_icrf[h], e.q_crf_icrf[0]);
                w_all += w[h];
                s_all += w[h] * theta;
                if (h != dropped) {
                    w_sub += w[h];
                    s_sub += w[h] * theta;
                }
            }
            const Eigen::Vector3d step = w_all.inverse() * s_all - w_sub.inverse() * s_sub;
            auto& d = days[static_cast<long long>(std::floor((e.t - epochs.front().t) / 86400.0))];
            if (d.second == 0U) {
                d.first = Eigen::Vector3d::Zero();
            }
            d.first += step;
            ++d.second;
        }
        Eigen::Vector3d sum_sq = Eigen::Vector3d::Zero();
        std::size_t n = 0;
        for (const auto& kv : days) {
            if (kv.second.second >= 50U) {  // whole days only (the last may be short)
                sum_sq += (kv.second.first / static_cast<double>(kv.second.second)).cwiseAbs2();
                ++n;
            }
        }
        worst = std::max(worst, (sum_sq / static_cast<double>(n)).cwiseSqrt().maxCoeff());
    }
    return worst;
}

// Fitted model (30 days; --min-days 20) and align: dropping any head moves
// the combined attitude by at most 0.2" (RMS over days of the daily mean).
// Without the thermal stage (aberration alone, aligned the same way) the
// steps are the bench's deformation: larger, and the test says by how much.
TEST(AlignMission, FittedModelAndAlignLeaveNoStepWhenAHeadDrops) {
    const fs::path dir = scratch("steps");
    const std::string raw = simulate_mission(dir, 30.0, 120.0, 5);
    FitOptions f;
    f.in = raw;
    f.out = (dir / "fitted.csv").string();
    f.min_span_days = 20.0;
    f.selection_report = false;
    (void)fit_model(f);
    const MountingsFile nominal = read_mountings_file(raw + ".mountings.csv");
    double step[2] = {0.0, 0.0};
    const char* names[2] = {"thermal", "aberration only"};
    for (int stage = 0; stage < 2; ++stage) {
        const std::string in = corrected(raw, stage == 0 ? f.out : std::string(), stage == 0 ? "th.csv" : "ab.csv");
        AlignReport r = run_align(in, nominal);
        const std::vector<FullEpoch> epochs = full_epochs(in, r.aligned);
        ASSERT_GT(epochs.size(), 3000U);
        step[stage] = largest_step(epochs, r.aligned);
        std::printf("%s: largest step when a head drops %.3f arcsec (RMS over days of the daily mean, %zu epochs)\n",
                    names[stage], step[stage], epochs.size());
    }
    EXPECT_LE(step[0], 0.2);
    EXPECT_GT(step[1], 2.0 * step[0]);  // what the thermal stage removes
}

// ---- Refusals: exit 2, naming what and where

// ---- What align refuses or leaves out (issue 37, classes 2, 3 and 7)

// The noise mission's rows, changed by `change` (which may drop a row by
// returning false), as a row source.
CorrectedRowSource changed_rows(const std::function<bool(CorrectedRow&)>& change) {
    auto kept = std::make_shared<std::vector<CorrectedRow>>();
    rows_of_file(noise_mission().corrected)([&](const CorrectedRow& r) {
        CorrectedRow c = r;
        if (change(c)) {
            kept->push_back(c);
        }
    });
    return [kept](const std::function<void(const CorrectedRow&)>& fn) {
        for (const CorrectedRow& r : *kept) {
            fn(r);
        }
    };
}

// q turned by `arcsec` about the head's own x axis (CHU axes, on the left).
Quaternion<double> turned_about_x(const Quaternion<double>& q, double arcsec) {
    const double half = 0.5 * arcsec * kArcsecToRad;
    return Quaternion<double>{std::cos(half), std::sin(half), 0.0, 0.0} * q;
}

AlignReport align_changed(const CorrectedRowSource& rows, const GateOptions& gate = {}) {
    MountingsFile given = noise_mission().truth;
    given.sigmas = false;
    AlignOptions opt;
    opt.in = "changed.csv";
    opt.gate = gate;
    return align_rows(rows, opt.in, given, opt);
}

TEST(AlignMission, OutliersOfOneHeadAreLeftOutByTheCombinationsGate) {
    // 2 % of A's rows 300 arcsec off: rows combine leaves out as inconsistent.
    // Before: A's sigma_cross 31.4 arcsec here (28.8 in the probe;
    // truth 1.5), its mounting 6.7 arcsec off.
    std::mt19937 rng(2);
    std::size_t bad = 0;
    const auto outliers = [&](CorrectedRow& r) {
        if (r.head == 0 && std::uniform_real_distribution<double>(0.0, 1.0)(rng) < 0.02) {
            r.q_chu_icrf = turned_about_x(r.q_chu_icrf, 300.0);
            ++bad;
        }
        return true;
    };
    const CorrectedRowSource rows = changed_rows(outliers);
    const AlignReport r = align_changed(rows);
    const AlignReport clean = noise_mission().report;
    ASSERT_GT(bad, 100U);
    EXPECT_GE(r.rows_left_out[static_cast<std::size_t>(LeftOut::kInconsistent)], bad);
    for (std::uint8_t h = 0; h < 3; ++h) {
        SCOPED_TRACE(std::string("CHU ") + kHeadLetters[h]);
        EXPECT_NEAR(r.head[h].noise.sigma_cross_arcsec, clean.head[h].noise.sigma_cross_arcsec,
                    2.0 * r.head[h].noise.sd_cross_arcsec);
        EXPECT_NEAR(r.head[h].noise.sigma_about_arcsec, clean.head[h].noise.sigma_about_arcsec,
                    2.0 * r.head[h].noise.sd_about_arcsec);
        for (Eigen::Index a = 0; a < 3; ++a) {
            EXPECT_NEAR(r.head[h].rotation_arcsec(a), clean.head[h].rotation_arcsec(a),
                        2.0 * r.head[h].rotation_sd_arcsec(a));
        }
    }
    // Mutation: a gate that never trips (100 sigmas, a floor of 3600") gives
    // the outliers' noise.
    const AlignReport open = align_changed(rows, GateOptions{100.0, 3600.0});
    EXPECT_GT(open.head[0].noise.sigma_cross_arcsec, 10.0);
    std::printf("%zu outliers of 300 arcsec in A: sigma_cross %.3f (gated), %.3f (not), clean %.3f\n", bad,
                r.head[0].noise.sigma_cross_arcsec, open.head[0].noise.sigma_cross_arcsec,
                clean.head[0].noise.sigma_cross_arcsec);
}

TEST(AlignMission, MountingsGivenAlmostADegreeOffConvergeWithTheGate) {
    // A given 0.99 degree off (the refusal's "within a degree") is still
    // tens of arcsec off after the first pass; the gate waits for a pass that
    // moved no head by more than 1 arcsec, and leaves out nothing.
    MountingsFile given = noise_mission().truth;
    given.sigmas = false;
    const double off = 0.99 * 3600.0;
    given.mountings.head[0].q_chu_crf =
        given.mountings.head[0].q_chu_crf * rotation_quaternion(Eigen::Vector3d(off, 0.0, 0.0));
    AlignOptions opt;
    opt.in = noise_mission().corrected;
    const AlignReport r = align_rows(rows_of_file(opt.in), opt.in, given, opt);
    EXPECT_EQ(r.rows_left_out[static_cast<std::size_t>(LeftOut::kInconsistent)], 0U);
    const AlignReport& clean = noise_mission().report;
    for (std::uint8_t h = 0; h < 3; ++h) {
        EXPECT_NEAR(r.head[h].noise.sigma_cross_arcsec, clean.head[h].noise.sigma_cross_arcsec, 0.01);
    }
    std::printf("A given 0.99 degree off: %zu passes\n", r.passes);
}

TEST(AlignMission, NoiseTheDataDoNotDetermineIsRefused) {
    // C in 4 epochs only: before, sigma_cross 0.011 +- 328 arcsec and exit 0.
    std::size_t c_rows = 0;
    const CorrectedRowSource rows = changed_rows([&](CorrectedRow& r) { return r.head != 2 || ++c_rows <= 4; });
    try {
        (void)align_changed(rows);
        ADD_FAILURE() << "accepted";
    } catch (const AlignRefused& e) {
        // Which head's noise comes out undetermined depends on what the rest
        // can separate (here B's, as A and B are then mostly alone).
        EXPECT_NE(std::string(e.what()).find(": its noise is not determined by the data"), std::string::npos)
            << e.what();
    }
}

TEST(AlignMission, NoiseOutsideTheMountingsFilesRangeIsRefused) {
    // Every head sees the truth exactly (noise-free), or with 1500" of noise:
    // before, sigmas of 1e-9 and 1527 arcsec that combine then refused.
    const fs::path dir = fs::path(noise_mission().corrected).parent_path();
    std::map<std::int64_t, Quaternion<double>> truth;
    {
        AttitudeReader a((dir / "mission.csv.attitude.csv").string());
        for (AttitudeRow row; a.next(row);) {
            truth[epoch_key(row.t)] = row.q_crf_icrf;
        }
    }
    const MountingsFile& m = noise_mission().truth;
    const CorrectedRowSource exact = changed_rows([&](CorrectedRow& r) {
        r.q_chu_icrf = m.mountings.head[r.head].q_chu_crf * truth.at(epoch_key(r.t));
        return true;
    });
    std::mt19937 rng(5);
    std::normal_distribution<double> noise(0.0, 1500.0);
    const CorrectedRowSource loud = changed_rows([&](CorrectedRow& r) {
        r.q_chu_icrf = turned_about_x(r.q_chu_icrf, noise(rng));
        return true;
    });
    const std::pair<const CorrectedRowSource*, const char*> cases[] = {{&exact, "carry no noise"},
                                                                       {&loud, "is not determined by the data"}};
    for (const auto& [rows, says] : cases) {
        try {
            (void)align_changed(*rows);
            ADD_FAILURE() << "accepted: " << says;
        } catch (const AlignRefused& e) {
            EXPECT_NE(std::string(e.what()).find(says), std::string::npos) << e.what();
        }
    }
}

TEST(AlignCli, RefusesBadInputWithExit2NamingFileAndLine) {
    const NoiseMission& m = noise_mission();
    const fs::path dir = scratch("cli");
    const auto write = [&](const char* name, const std::string& text) {
        std::FILE* fp = std::fopen((dir / name).string().c_str(), "w");
        std::fputs(text.c_str(), fp);
        std::fclose(fp);
    };
    write("not_unit.csv", "chu,qw,qx,qy,qz\nA,1,0,0,0\nB,0.9,0,0,0\n");
    write("with_d.csv", format_mountings(m.truth) + "D,1,0,0,0,1.5,10\n");
    write("short.csv", "t,chu,qw,qx,qy,qz,status\n0.0,A,1,0,0,0,3\n0.0,B,1,0,0,0,3\n");
    write("dup.csv", "t,chu,qw,qx,qy,qz,status\n0.0,A,1,0,0,0,3\n0.0,A,1,0,0,0,3\n");
    write("truth.csv", format_mountings(m.truth));
    MountingsFile ab = m.truth;
    ab.mountings.head[2].present = false;
    write("ab.csv", format_mountings(ab));
    const std::string in = " --in " + m.corrected + " --out " + (dir / "m2.csv").string();
    struct Case {
        std::string args;
        std::string says;
    } cases[] = {
        {in + " --mountings " + (dir / "not_unit.csv").string(), "not_unit.csv:3"},
        {in + " --mountings " + (dir / "with_d.csv").string(), "CHU D (in the mountings) has no clean epoch"},
        {in + " --mountings " + (dir / "truth.csv").string() + " --from 0 --to 1", "the period is empty"},
        {in + " --mountings " + (dir / "truth.csv").string() + " --from 2 --to 1", "the period is empty"},
        {" --in " + (dir / "short.csv").string() + " --out " + (dir / "m2.csv").string() + " --mountings " +
             (dir / "ab.csv").string(),
         "too few epochs: 1 with two or more usable heads"},
        {" --in " + (dir / "dup.csv").string() + " --out " + (dir / "m2.csv").string() + " --mountings " +
             (dir / "truth.csv").string(),
         "dup.csv:3:1: second solution of CHU A"},
        // A window whose index of an epoch would not fit an integer (was: an
        // out-of-range cast before the refusal), and one beyond the range.
        // Usage errors, before any input is read (was, below 0.01: after the
        // mountings, without "Run with --help").
        {in + " --mountings " + (dir / "truth.csv").string() + " --noise-window 1e-300",
         "--noise-window: 1e-300 is out of range: the range is 0 or [0.01, 1e+10]"},
        {in + " --mountings " + (dir / "truth.csv").string() + " --noise-window 1e300", "--noise-window"},
        {in + " --mountings " + (dir / "absent.csv").string() + " --noise-window 0.005",
         "--noise-window: 0.005 is out of range: the range is 0 or [0.01, 1e+10]"},
    };
    for (const Case& c : cases) {
        const test::CliRun r = test::run_here("align" + c.args, dir);
        EXPECT_EQ(r.exit_code, 2) << c.args << "\n" << r.err;
        EXPECT_NE(r.err.find(c.says), std::string::npos) << c.args << "\n" << r.err;
        EXPECT_FALSE(fs::exists(dir / "m2.csv")) << c.args;
    }
    // And the good run, for contrast (the same command can succeed).
    const test::CliRun ok = test::run_here("align" + in + " --mountings " + (dir / "truth.csv").string(), dir);
    EXPECT_EQ(ok.exit_code, 0) << ok.err;
    EXPECT_TRUE(fs::exists(dir / "m2.csv"));
}

}  // namespace
}  // namespace ascorr::host
