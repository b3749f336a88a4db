// Alignment and noise estimation from relative attitudes (ascorr_host/analysis/align.hpp),
// on synthetic epochs whose truth is known exactly: each head's CRF estimate
// is exp(δ_i + drift_i(t) + e_i) ⊗ q_crf_icrf, e_i of covariance
// C_i = σc²(I − bbᵀ) + σa² bbᵀ in CRF axes.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <optional>
#include <random>

#include "ascorr_host/analysis/align.hpp"
#include "ascorr_host/analysis/simulate.hpp"

namespace ascorr::host {
namespace {

struct Truth {
    HeadMask heads = kPaperHeads;
    std::array<Quaternion<double>, kMaxHeads> q_chu_crf{};
    std::array<double, kMaxHeads> cross{1.5, 1.2, 2.0, 1.5};
    std::array<double, kMaxHeads> about{10.0, 8.0, 12.0, 10.0};
    std::array<Eigen::Vector3d, kMaxHeads> delta{};
    double drift_arcsec = 0.0;  // amplitude of each head's orbital (5640 s) disagreement
    std::size_t epochs = 20000;
    double step_s = 60.0;
    double blind_fraction = 0.0;  // epochs where one head (in turn) is missing
};

Truth swarm_like() {
    Truth t;
    for (int h = 0; h < static_cast<int>(kMaxHeads); ++h) {
        const Eigen::Quaterniond q(head_mounting(h));
        t.q_chu_crf[static_cast<std::size_t>(h)] = {q.w(), q.x(), q.y(), q.z()};
    }
    t.delta[0] = {20.0, -5.0, 3.0};
    t.delta[1] = {-7.0, 11.0, -30.0};
    t.delta[2] = {2.0, 4.0, 15.0};
    t.delta[3] = {-3.0, 9.0, 1.0};
    return t;
}

AlignSums sums_of(const Truth& truth, double window_s, std::uint64_t seed = 7) {
    std::mt19937_64 rng(seed);
    std::normal_distribution<double> normal;
    std::uniform_real_distribution<double> unif;
    AlignSums sums(window_s);
    const HeadList l = heads_of(truth.heads);
    for (std::size_t k = 0; k < truth.epochs; ++k) {
        const double t = static_cast<double>(k) * truth.step_s;
        const Eigen::Quaterniond q_crf_icrf = Eigen::Quaterniond::UnitRandom();
        std::array<std::optional<Quaternion<double>>, kMaxHeads> q{};
        const bool blind = unif(rng) < truth.blind_fraction;
        const std::uint8_t blinded = l.head[k % l.count];
        for (std::size_t i = 0; i < l.count; ++i) {
            const std::uint8_t h = l.head[i];
            const Eigen::Matrix3d m = Eigen::Quaterniond(truth.q_chu_crf[h].w, truth.q_chu_crf[h].x,
                                                         truth.q_chu_crf[h].y, truth.q_chu_crf[h].z)
                                          .toRotationMatrix();
            const Eigen::Vector3d e_chu(truth.cross[h] * normal(rng), truth.cross[h] * normal(rng),
                                        truth.about[h] * normal(rng));
            const double phase = 2.0 * 3.14159265358979 * t / 5640.0 + static_cast<double>(h);
            const Eigen::Vector3d drift = truth.drift_arcsec * Eigen::Vector3d(std::sin(phase), std::cos(phase), 0.5);
            const Eigen::Vector3d theta = truth.delta[h] + drift + m.transpose() * e_chu;
            if (blind && h == blinded) {
                continue;
            }
            const Quaternion<double> qe = rotation_quaternion(theta);
            q[h] = qe * Quaternion<double>{q_crf_icrf.w(), q_crf_icrf.x(), q_crf_icrf.y(), q_crf_icrf.z()};
        }
        sums.add(t, q);
    }
    sums.finish();
    return sums;
}

std::array<Eigen::Vector3d, kMaxHeads> boresights(const Truth& t) {
    std::array<Eigen::Vector3d, kMaxHeads> b{};
    for (std::size_t h = 0; h < kMaxHeads; ++h) {
        b[h] = boresight_crf(t.q_chu_crf[h]);
    }
    return b;
}

TEST(AlignMath, RotationVectorAndItsExponentialAreInverse) {
    const Eigen::Vector3d theta(12.5, -300.0, 7.25);
    const Quaternion<double> b{0.5, 0.5, -0.5, 0.5};
    const Quaternion<double> a = rotation_quaternion(theta) * b;
    EXPECT_LT((rotation_arcsec(a, b) - theta).norm(), 1e-9);
    const Quaternion<double> minus_a{-a.w, -a.x, -a.y, -a.z};
    EXPECT_LT((rotation_arcsec(minus_a, b) - theta).norm(), 1e-9);  // either sign
}

// Three heads, orbital disagreement of 3": the per-head σc and σa within 4
// formal σ of the truth (the formal σ about 1 %), and the formal σ honest.
TEST(AlignNoise, ThreeHeadsRecoverEachHeadsCrossAndAboutNoise) {
    Truth truth = swarm_like();
    truth.drift_arcsec = 3.0;
    truth.blind_fraction = 0.3;
    const AlignSums sums = sums_of(truth, kDefaultNoiseWindowS);
    const NoiseEstimate est = estimate_noise(sums, kPaperHeads, boresights(truth));
    EXPECT_TRUE(est.converged);
    EXPECT_EQ(est.model, NoiseModel::kPerHead);
    for (std::uint8_t h = 0; h < 3; ++h) {
        const HeadNoise& n = est.head[h];
        SCOPED_TRACE(std::string("CHU ") + kHeadLetters[h]);
        EXPECT_NEAR(n.sigma_cross_arcsec, truth.cross[h], 4.0 * n.sd_cross_arcsec);
        EXPECT_NEAR(n.sigma_about_arcsec, truth.about[h], 4.0 * n.sd_about_arcsec);
        EXPECT_LT(n.sd_cross_arcsec, 0.02 * truth.cross[h]);
        EXPECT_LT(n.sd_about_arcsec, 0.03 * truth.about[h]);
        EXPECT_GT(n.sd_cross_arcsec, 0.0);
    }
}

// The window's effect: the same data with one mean over the period see the
// 3" orbital disagreement as noise. σc is inflated by far more than its
// formal σ (the mutation check of the window).
TEST(AlignNoise, OneMeanOverThePeriodInflatesTheNoiseWithTheDrift) {
    Truth truth = swarm_like();
    truth.drift_arcsec = 3.0;
    const NoiseEstimate windowed = estimate_noise(sums_of(truth, kDefaultNoiseWindowS), kPaperHeads, boresights(truth));
    const NoiseEstimate whole = estimate_noise(sums_of(truth, 0.0), kPaperHeads, boresights(truth));
    double worst = 0.0;  // of the period mean: the largest error in its formal σ
    for (std::uint8_t h = 0; h < 3; ++h) {
        EXPECT_NEAR(windowed.head[h].sigma_cross_arcsec, truth.cross[h], 4.0 * windowed.head[h].sd_cross_arcsec);
        std::printf("CHU %c: window %.3f %.3f, period %.3f (sd %.3f) %.3f (sd %.3f)\n", kHeadLetters[h],
                    windowed.head[h].sigma_cross_arcsec, windowed.head[h].sigma_about_arcsec,
                    whole.head[h].sigma_cross_arcsec, whole.head[h].sd_cross_arcsec, whole.head[h].sigma_about_arcsec,
                    whole.head[h].sd_about_arcsec);
        worst = std::max(worst,
                         std::abs(whole.head[h].sigma_cross_arcsec - truth.cross[h]) / whole.head[h].sd_cross_arcsec);
    }
    EXPECT_GT(worst, 10.0);
}

// Two heads: four components, three numbers per epoch for orthogonal
// boresights. The estimate shares one σc (stated) and recovers it and each σa.
TEST(AlignNoise, TwoHeadsShareOneCrossNoise) {
    Truth truth = swarm_like();
    truth.heads = 0x3U;
    truth.cross = {1.4, 1.4, 1.4, 1.4};
    const AlignSums sums = sums_of(truth, kDefaultNoiseWindowS);
    const NoiseEstimate est = estimate_noise(sums, truth.heads, boresights(truth));
    EXPECT_EQ(est.model, NoiseModel::kEqualCross);
    for (std::uint8_t h = 0; h < 2; ++h) {
        EXPECT_NEAR(est.head[h].sigma_cross_arcsec, 1.4, 4.0 * est.head[h].sd_cross_arcsec);
        EXPECT_NEAR(est.head[h].sigma_about_arcsec, truth.about[h], 4.0 * est.head[h].sd_about_arcsec);
    }
    EXPECT_EQ(est.head[0].sigma_cross_arcsec, est.head[1].sigma_cross_arcsec);
}

std::array<Eigen::Matrix3d, kMaxHeads> information_of(const Truth& t) {
    std::array<Eigen::Matrix3d, kMaxHeads> w{};
    for (std::size_t h = 0; h < kMaxHeads; ++h) {
        w[h] = information_crf(t.q_chu_crf[h], t.cross[h], t.about[h]);
    }
    return w;
}

// The δ_i are fixed up to a common rotation: the estimate is the truth less
// its information-weighted mean, within 4 formal σ per axis, and its own
// weighted mean is zero.
TEST(AlignMountings, RecoverRelativeErrorsUnderTheDatum) {
    for (const HeadMask heads : {HeadMask{0x7U}, HeadMask{0xFU}, HeadMask{0x5U}}) {
        Truth truth = swarm_like();
        truth.heads = heads;
        truth.blind_fraction = 0.4;
        truth.epochs = 5000;
        const AlignSums sums = sums_of(truth, kDefaultNoiseWindowS);
        const std::array<Eigen::Matrix3d, kMaxHeads> w = information_of(truth);
        const Alignment a = solve_alignment(sums, heads, w);
        Eigen::Matrix3d w_sum = Eigen::Matrix3d::Zero();
        Eigen::Vector3d wd = Eigen::Vector3d::Zero();
        for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
            if (has_head(heads, h)) {
                w_sum += w[h];
                wd += w[h] * truth.delta[h];
            }
        }
        const Eigen::Vector3d mean = w_sum.inverse() * wd;
        EXPECT_LT(a.weighted_mean_arcsec.norm(), 1e-9);
        for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
            if (!has_head(heads, h)) {
                continue;
            }
            SCOPED_TRACE(head_letters(heads) + ", CHU " + kHeadLetters[h]);
            for (int axis = 0; axis < 3; ++axis) {
                const double sd = std::sqrt(a.covariance[h](axis, axis));
                EXPECT_GT(sd, 0.0);
                EXPECT_LT(sd, 0.5);
                EXPECT_NEAR(a.delta_arcsec[h](axis), truth.delta[h](axis) - mean(axis), 4.0 * sd);
            }
        }
    }
}

TEST(AlignMountings, AHeadThatNeverSharesAnEpochIsRefused) {
    Truth truth = swarm_like();
    truth.heads = 0x3U;
    const AlignSums sums = sums_of(truth, kDefaultNoiseWindowS);
    try {
        (void)solve_alignment(sums, 0x7U, information_of(truth));
        FAIL() << "C has no epoch and was not refused";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("CHU C shares no clean epoch"), std::string::npos) << e.what();
    }
}

}  // namespace
}  // namespace ascorr::host
