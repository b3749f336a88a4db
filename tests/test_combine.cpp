// The combined attitude (firmware/include/ascorr/combine/) against an
// independent reference: the weighted least-squares attitude of the CRF found
// by Gauss–Newton on rotation matrices (Eigen), residuals Log(R_i R̂ᵀ) in CRF
// axes weighted by W_i = Mᵀ diag(1/σc², 1/σc², 1/σa²) M, Jacobians by central
// differences, iterated to convergence: no small-angle step, no gain table,
// no quaternion arithmetic of ours.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include "alloc_counter.hpp"
#include "ascorr/combine/combiner.hpp"
#include "ascorr/combine/usable.hpp"
#include "ascorr/core/constants.hpp"
#include "ascorr/core/fixed_point.hpp"

namespace ascorr::test {
namespace {

using combine::CombinedAttitude;
using combine::Combiner;
using combine::CombinerConfig;
using combine::HeadAttitude;
using combine::left_out_alone;
using combine::left_out_name;
using combine::LeftOut;
using combine::Mountings;
using combine::MountingsProblem;
using combine::Repeated;
using combine::RowFacts;
using combine::select_epoch;
namespace cs = combine::combined_status;

using Mat3 = Eigen::Matrix3d;
using Vec3 = Eigen::Vector3d;
using Quat = Eigen::Quaterniond;

// A vector indexed by any integer (the tests count heads in int).
template <typename T>
struct List : std::vector<T> {
    using std::vector<T>::vector;
    template <typename I>
    T& operator[](I i) {
        return std::vector<T>::operator[](static_cast<std::size_t>(i));
    }
    template <typename I>
    const T& operator[](I i) const {
        return std::vector<T>::operator[](static_cast<std::size_t>(i));
    }
};

constexpr double kSigmaCross = 1.3;  // the contract's noise model, arcsec
constexpr double kSigmaAbout = 9.0;

Quat eigen(const Quaternion<double>& q) {
    return {q.w, q.x, q.y, q.z};
}
Quaternion<double> ours(const Quat& q) {
    return {q.w(), q.x(), q.y(), q.z()};
}

// Rotation vector of R (rad), exact for any angle below π.
Vec3 log_rotation(const Mat3& r) {
    const Eigen::AngleAxisd aa(r);
    return aa.angle() * aa.axis();
}
Mat3 exp_rotation(const Vec3& v) {
    const double a = v.norm();
    return a == 0.0 ? Mat3::Identity() : Eigen::AngleAxisd(a, v / a).toRotationMatrix();
}

struct Head {
    Quat q_chu_crf;
    double sigma_cross;
    double sigma_about;
};

Mat3 information(const Head& h) {
    const Mat3 m = h.q_chu_crf.toRotationMatrix();
    const Vec3 d(1.0 / (h.sigma_cross * h.sigma_cross), 1.0 / (h.sigma_cross * h.sigma_cross),
                 1.0 / (h.sigma_about * h.sigma_about));
    return m.transpose() * d.asDiagonal() * m;
}

// The reference: argmin Σ r_iᵀ W_i r_i, r_i = Log(R_i R̂ᵀ) (CRF axes, rad),
// R_i = R(q_chu_crf_i)ᵀ R(q_chu_icrf_i).
Mat3 reference_attitude(const List<Head>& heads, const List<Quat>& q_chu_icrf) {
    List<Mat3> r(heads.size());
    for (std::size_t i = 0; i < heads.size(); ++i) {
        r[i] = heads[i].q_chu_crf.toRotationMatrix().transpose() * q_chu_icrf[i].toRotationMatrix();
    }
    Mat3 est = r[0];
    constexpr double kStep = 1e-6;
    for (int it = 0; it < 12; ++it) {
        Mat3 normal = Mat3::Zero();
        Vec3 rhs = Vec3::Zero();
        for (std::size_t i = 0; i < heads.size(); ++i) {
            const Mat3 w = information(heads[i]);
            const Vec3 res = log_rotation(r[i] * est.transpose());
            Mat3 jac;  // d res / d δ, est ← Exp(δ) est
            for (int k = 0; k < 3; ++k) {
                const Vec3 e = kStep * Vec3::Unit(k);
                jac.col(k) = (log_rotation(r[i] * (exp_rotation(e) * est).transpose()) -
                              log_rotation(r[i] * (exp_rotation(-e) * est).transpose())) /
                             (2.0 * kStep);
            }
            normal += jac.transpose() * w * jac;
            rhs -= jac.transpose() * w * res;
        }
        est = exp_rotation(normal.ldlt().solve(rhs)) * est;
    }
    return est;
}

// Error of q (q_crf_icrf) against R_true in CRF axes, arcsec.
Vec3 error_arcsec(const Quaternion<double>& q, const Mat3& r_true) {
    return log_rotation(eigen(q).toRotationMatrix() * r_true.transpose()) * kRadToArcsec;
}

Quat random_rotation(std::mt19937& rng) {
    std::normal_distribution<double> n(0.0, 1.0);
    Quat q(n(rng), n(rng), n(rng), n(rng));
    q.normalize();
    return q;
}

Quat small_rotation(const Vec3& v) {
    return Quat(exp_rotation(v));
}

// Three or four heads with boresights near CRF x, y, z (and −x−y−z for a
// fourth), each tilted up to `tilt_deg` and turned about its boresight at random.
List<Head> near_orthogonal_heads(std::mt19937& rng, int n, double tilt_deg, double sc = kSigmaCross,
                                 double sa = kSigmaAbout) {
    const Vec3 axes[4] = {Vec3::UnitX(), Vec3::UnitY(), Vec3::UnitZ(), -Vec3(1, 1, 1).normalized()};
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    List<Head> heads;
    for (int i = 0; i < n; ++i) {
        const Vec3 tilt = Vec3(u(rng), u(rng), u(rng)) * tilt_deg * kDegToRad / std::sqrt(3.0);
        const Vec3 bore_crf = exp_rotation(tilt) * axes[i];
        // q_chu_crf maps CRF components into CHU ones: the boresight (CHU z) in
        // CRF is R(q_chu_crf)ᵀ e_z.
        const Quat to_z = Quat::FromTwoVectors(bore_crf, Vec3::UnitZ());
        const Quat spin(Eigen::AngleAxisd(u(rng) * kPi, Vec3::UnitZ()));
        heads.push_back({(spin * to_z).normalized(), sc, sa});
    }
    return heads;
}

Mountings mountings_of(const List<Head>& heads) {
    Mountings m{};
    for (std::size_t i = 0; i < heads.size(); ++i) {
        m.head[i] = {true, ours(heads[i].q_chu_crf), heads[i].sigma_cross, heads[i].sigma_about};
    }
    return m;
}

// A head's measured q_chu_icrf: the truth with noise σc, σc, σa (arcsec) about
// CHU x, y, z and an extra rotation `offset_crf` (rad, CRF axes).
Quat measure(const Head& h, const Quat& q_crf_icrf, std::mt19937& rng, double noise_scale = 1.0,
             const Vec3& offset_crf = Vec3::Zero()) {
    std::normal_distribution<double> n(0.0, 1.0);
    const Vec3 d =
        Vec3(h.sigma_cross * n(rng), h.sigma_cross * n(rng), h.sigma_about * n(rng)) * noise_scale * kArcsecToRad;
    const Quat q_true = h.q_chu_crf * small_rotation(offset_crf) * q_crf_icrf;
    return (small_rotation(d) * q_true).normalized();
}

template <typename T>
HeadAttitude<T> attitude(const Quat& q, std::uint8_t head, bool usable = true) {
    using Tr = ScalarTraits<T>;
    return {
        {Tr::from_double(q.w()), Tr::from_double(q.x()), Tr::from_double(q.y()), Tr::from_double(q.z())}, head, usable};
}

template <typename T>
Quaternion<double> to_double(const Quaternion<T>& q) {
    using Tr = ScalarTraits<T>;
    return {Tr::to_double(q.w), Tr::to_double(q.x), Tr::to_double(q.y), Tr::to_double(q.z)};
}

double angle_arcsec(const Quaternion<double>& a, const Quaternion<double>& b) {
    return eigen(a).angularDistance(eigen(b)) * kRadToArcsec;
}

// ---- Mountings.

TEST(Combine, CheckMountingsNamesEachProblem) {
    std::mt19937 rng(1);
    const Mountings good = mountings_of(near_orthogonal_heads(rng, 3, 10.0));
    std::uint8_t head = 0;
    EXPECT_EQ(combine::check_mountings(good, &head), MountingsProblem::kNone);
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const double inf = std::numeric_limits<double>::infinity();
    struct Case {
        void (*spoil)(combine::HeadMounting&, double, double);
        MountingsProblem expected;
    };
    const Case cases[] = {
        {[](combine::HeadMounting& h, double n, double) { h.q_chu_crf.x = n; }, MountingsProblem::kQuaternionNotFinite},
        {[](combine::HeadMounting& h, double, double i) { h.q_chu_crf.w = i; }, MountingsProblem::kQuaternionNotFinite},
        {[](combine::HeadMounting& h, double, double) {
             h.q_chu_crf = {0, 0, 0, 0};
         },
         MountingsProblem::kQuaternionZero},
        {[](combine::HeadMounting& h, double, double) { h.q_chu_crf.w *= 1.001; },
         MountingsProblem::kQuaternionNotUnit},
        {[](combine::HeadMounting& h, double n, double) { h.sigma_cross_arcsec = n; },
         MountingsProblem::kSigmaCrossNotFinite},
        {[](combine::HeadMounting& h, double, double i) { h.sigma_cross_arcsec = i; },
         MountingsProblem::kSigmaCrossNotFinite},
        {[](combine::HeadMounting& h, double, double) { h.sigma_cross_arcsec = 0.0; },
         MountingsProblem::kSigmaCrossNotPositive},
        {[](combine::HeadMounting& h, double, double) { h.sigma_cross_arcsec = -1.3; },
         MountingsProblem::kSigmaCrossNotPositive},
        {[](combine::HeadMounting& h, double, double) { h.sigma_cross_arcsec = 1e-9; },
         MountingsProblem::kSigmaCrossOutOfRange},
        {[](combine::HeadMounting& h, double n, double) { h.sigma_about_arcsec = n; },
         MountingsProblem::kSigmaAboutNotFinite},
        {[](combine::HeadMounting& h, double, double i) { h.sigma_about_arcsec = -i; },
         MountingsProblem::kSigmaAboutNotFinite},
        {[](combine::HeadMounting& h, double, double) { h.sigma_about_arcsec = 0.0; },
         MountingsProblem::kSigmaAboutNotPositive},
        {[](combine::HeadMounting& h, double, double) { h.sigma_about_arcsec = 5e3; },
         MountingsProblem::kSigmaAboutOutOfRange},
    };
    for (const Case& c : cases) {
        Mountings m = good;
        c.spoil(m.head[1], nan, inf);
        head = 0;
        EXPECT_EQ(combine::check_mountings(m, &head), c.expected);
        EXPECT_EQ(head, 1);
        EXPECT_STRNE(combine::problem_text(c.expected), "unknown problem");
        const Combiner<double> comb(m);
        EXPECT_FALSE(comb.valid());
        EXPECT_EQ(comb.problem(), c.expected);
    }
    // A head not present is not checked.
    Mountings absent = good;
    absent.head[1].present = false;
    absent.head[1].sigma_about_arcsec = nan;
    EXPECT_EQ(combine::check_mountings(absent, &head), MountingsProblem::kNone);
    EXPECT_EQ(combine::check_mountings(Mountings{}, &head), MountingsProblem::kNoHead);
    EXPECT_EQ(head, kUnknownHead);
    // Three heads with one boresight and one very weak axis: the pair that
    // shares a boresight with the weak axis of a third cannot pin it down.
    Mountings degenerate = good;
    degenerate.head[1].q_chu_crf = degenerate.head[0].q_chu_crf;
    degenerate.head[2].q_chu_crf = degenerate.head[0].q_chu_crf;
    HeadMask subset = 0;
    EXPECT_EQ(combine::check_mountings(degenerate, &head, &subset), MountingsProblem::kNone)
        << "parallel heads are averaged, not ill-conditioned";
    degenerate.head[1].q_chu_crf = ours(eigen(good.head[0].q_chu_crf) * small_rotation(Vec3(1e-4, 0, 0)));
    degenerate.head[1].sigma_about_arcsec = 1000.0;
    degenerate.head[0].sigma_about_arcsec = 1000.0;
    degenerate.head[2].sigma_about_arcsec = 1000.0;
    degenerate.head[1].sigma_cross_arcsec = 0.001;
    degenerate.head[0].sigma_cross_arcsec = 0.001;
    degenerate.head[2].sigma_cross_arcsec = 0.001;
    EXPECT_EQ(combine::check_mountings(degenerate, &head, &subset), MountingsProblem::kIllConditioned);
    EXPECT_NE(subset, 0);
    // The gate configuration.
    EXPECT_EQ(Combiner<double>(good, CombinerConfig{2.0, 10.0}).problem(), MountingsProblem::kGateConfig);
    EXPECT_EQ(Combiner<double>(good, CombinerConfig{6.0, nan}).problem(), MountingsProblem::kGateConfig);
    EXPECT_EQ(Combiner<double>(good, CombinerConfig{6.0, 0.5}).problem(), MountingsProblem::kGateConfig);
    EXPECT_TRUE(Combiner<double>(good).valid());
}

// ---- Against the reference.

// Random epochs of near-orthogonal and of random geometries, 2–4 heads.
TEST(Combine, MatchesTheWeightedLeastSquaresReference) {
    std::mt19937 rng(2);
    double worst = 0.0;
    double worst_sigma = 0.0;
    for (int trial = 0; trial < 400; ++trial) {
        const int n = 2 + trial % 3;
        List<Head> heads = near_orthogonal_heads(rng, n, trial % 2 == 0 ? 15.0 : 60.0);
        std::uniform_real_distribution<double> u(0.5, 2.0);
        for (Head& h : heads) {  // heads that differ
            h.sigma_cross *= u(rng);
            h.sigma_about *= u(rng);
        }
        const Mountings m = mountings_of(heads);
        const Combiner<double> comb(m);
        ASSERT_TRUE(comb.valid()) << trial;
        const Quat truth = random_rotation(rng);
        List<Quat> q(static_cast<std::size_t>(n));
        HeadAttitude<double> in[kMaxHeads];
        for (int i = 0; i < n; ++i) {
            q[i] = measure(heads[i], truth, rng);
            in[i] = attitude<double>(q[i], static_cast<std::uint8_t>(i));
        }
        const CombinedAttitude<double> out = comb.combine(in, static_cast<std::uint8_t>(n));
        ASSERT_EQ(out.status, cs::kTwoOrMoreHeads) << trial;
        ASSERT_EQ(out.used, (1U << n) - 1U);
        EXPECT_GE(out.q_crf_icrf.w, 0.0);
        const Mat3 ref = reference_attitude(heads, q);
        worst = std::max(worst, error_arcsec(out.q_crf_icrf, ref).norm());
        // Formal σ: sqrt(diag((Σ W)⁻¹)).
        Mat3 p = Mat3::Zero();
        for (const Head& h : heads) {
            p += information(h);
        }
        const Mat3 c = p.inverse();
        for (int a = 0; a < 3; ++a) {
            worst_sigma = std::max(worst_sigma, std::fabs(comb.sigma_arcsec(out.subset)[a] / std::sqrt(c(a, a)) - 1.0));
        }
    }
    // The linearisation about one head (kernels.hpp): second order in the
    // heads' differences, here up to ~5σ = 90″ about a boresight.
    EXPECT_LT(worst, 0.005) << "worst difference from the reference, arcsec";
    EXPECT_LT(worst_sigma, 1e-12);
    RecordProperty("worst_arcsec", std::to_string(worst));
    std::printf("double: worst %.5f arcsec from the reference over 400 epochs\n", worst);
}

// The heads' quaternions with either sign give the same combined attitude.
TEST(Combine, EitherSignOfEveryHeadGivesTheSameAttitude) {
    std::mt19937 rng(3);
    for (int trial = 0; trial < 200; ++trial) {
        const List<Head> heads = near_orthogonal_heads(rng, 4, 20.0);
        const Combiner<double> cd(mountings_of(heads));
        const Combiner<float> cf(mountings_of(heads));
        const Quat truth = random_rotation(rng);
        HeadAttitude<double> in[kMaxHeads];
        HeadAttitude<float> inf[kMaxHeads];
        for (int i = 0; i < 4; ++i) {
            const Quat q = measure(heads[i], truth, rng);
            in[i] = attitude<double>(q, static_cast<std::uint8_t>(i));
            inf[i] = attitude<float>(q, static_cast<std::uint8_t>(i));
        }
        const auto base = cd.combine(in, 4);
        const auto basef = cf.combine(inf, 4);
        for (unsigned flips = 1; flips < 16; ++flips) {
            HeadAttitude<double> f[kMaxHeads];
            HeadAttitude<float> ff[kMaxHeads];
            for (int i = 0; i < 4; ++i) {
                f[i] = in[i];
                ff[i] = inf[i];
                if ((flips >> i & 1U) != 0U) {
                    f[i].q_chu_icrf = {-in[i].q_chu_icrf.w, -in[i].q_chu_icrf.x, -in[i].q_chu_icrf.y,
                                       -in[i].q_chu_icrf.z};
                    ff[i].q_chu_icrf = {-inf[i].q_chu_icrf.w, -inf[i].q_chu_icrf.x, -inf[i].q_chu_icrf.y,
                                        -inf[i].q_chu_icrf.z};
                }
            }
            const auto out = cd.combine(f, 4);
            const auto outf = cf.combine(ff, 4);
            // Negation is exact, and every step is odd in the reference's sign.
            EXPECT_EQ(out.q_crf_icrf.w, base.q_crf_icrf.w);
            EXPECT_EQ(out.q_crf_icrf.x, base.q_crf_icrf.x);
            EXPECT_EQ(out.q_crf_icrf.z, base.q_crf_icrf.z);
            EXPECT_EQ(outf.q_crf_icrf.y, basef.q_crf_icrf.y);
            EXPECT_EQ(out.status, cs::kTwoOrMoreHeads);
        }
    }
}

// Every subset of four heads, in any order, against the reference of that subset.
TEST(Combine, EverySubsetMatchesItsReference) {
    std::mt19937 rng(4);
    const List<Head> heads = near_orthogonal_heads(rng, 4, 20.0);
    const Combiner<double> comb(mountings_of(heads));
    ASSERT_TRUE(comb.valid());
    for (int trial = 0; trial < 20; ++trial) {
        const Quat truth = random_rotation(rng);
        List<Quat> q(4);
        for (int i = 0; i < 4; ++i) {
            q[i] = measure(heads[i], truth, rng);
        }
        for (unsigned s = 1; s < 16; ++s) {
            List<Head> hs;
            List<Quat> qs;
            HeadAttitude<double> in[kMaxHeads];
            std::uint8_t n = 0;
            for (int i = 3; i >= 0; --i) {  // reverse order: the input order does not matter
                if ((s >> i & 1U) != 0U) {
                    hs.push_back(heads[i]);
                    qs.push_back(q[i]);
                    in[n++] = attitude<double>(q[i], static_cast<std::uint8_t>(i));
                }
            }
            const auto out = comb.combine(in, n);
            EXPECT_EQ(out.used, s);
            EXPECT_EQ(out.subset, s);
            EXPECT_EQ(out.left_out, 0);
            EXPECT_EQ(out.status, n >= 2 ? cs::kTwoOrMoreHeads : cs::kOneHead);
            EXPECT_LT(error_arcsec(out.q_crf_icrf, reference_attitude(hs, qs)).norm(), 0.005) << s;
        }
    }
}

// One head: its own CRF attitude, formal σ its σa about its boresight.
TEST(Combine, OneHeadIsItsOwnAttitudeWithItsSigma) {
    std::mt19937 rng(5);
    List<Head> heads = near_orthogonal_heads(rng, 3, 0.0);
    const Combiner<double> comb(mountings_of(heads));
    const Quat truth = random_rotation(rng);
    for (std::uint8_t h = 0; h < 3; ++h) {
        const Quat q = measure(heads[h], truth, rng);
        const HeadAttitude<double> in = attitude<double>(q, h);
        const auto out = comb.combine(&in, 1);
        EXPECT_EQ(out.status, cs::kOneHead);
        EXPECT_EQ(out.used, 1U << h);
        const Quat own = heads[h].q_chu_crf.conjugate() * q;
        EXPECT_LT(angle_arcsec(out.q_crf_icrf, ours(own)), 1e-9);
        // Boresights along CRF x, y, z (no tilt): σa about axis h, σc about the others.
        for (int a = 0; a < 3; ++a) {
            EXPECT_NEAR(comb.sigma_arcsec(out.subset)[a], a == h ? kSigmaAbout : kSigmaCross, 1e-9);
        }
    }
}

TEST(Combine, NoUsableHeadGivesTheIdentityAndStatus8) {
    std::mt19937 rng(6);
    const List<Head> heads = near_orthogonal_heads(rng, 3, 10.0);
    const Combiner<double> comb(mountings_of(heads));
    const auto none = comb.combine(nullptr, 0);
    EXPECT_EQ(none.status, cs::kNoHead);
    EXPECT_EQ(none.q_crf_icrf.w, 1.0);
    EXPECT_EQ(none.q_crf_icrf.x, 0.0);
    EXPECT_EQ(none.used | none.left_out | none.inconsistent, 0);
    const Quat truth = random_rotation(rng);
    HeadAttitude<double> in[3];
    for (int i = 0; i < 3; ++i) {
        in[i] = attitude<double>(measure(heads[i], truth, rng), static_cast<std::uint8_t>(i), false);
    }
    const auto all_unusable = comb.combine(in, 3);
    EXPECT_EQ(all_unusable.status, cs::kNoHead | cs::kHeadLeftOut);
    EXPECT_EQ(all_unusable.left_out, 7);
    EXPECT_EQ(all_unusable.inconsistent, 0);
    EXPECT_EQ(all_unusable.q_crf_icrf.w, 1.0);
    EXPECT_EQ(comb.sigma_arcsec(all_unusable.subset)[0], 0.0);
    // Invalid mountings: every epoch has no usable head.
    Mountings bad = mountings_of(heads);
    bad.head[0].sigma_cross_arcsec = -1.0;
    const Combiner<double> invalid(bad);
    in[0].usable = in[1].usable = true;
    const auto refused = invalid.combine(in, 2);
    EXPECT_EQ(refused.status, cs::kNoHead | cs::kHeadLeftOut);
    EXPECT_EQ(refused.left_out, 3);
}

// A second solution of a head, an index that is no head, a head not in the
// mountings, a non-unit quaternion: left out (4), the rest combined as without them.
TEST(Combine, DuplicatesUnknownAndUnmountedHeadsAreLeftOut) {
    std::mt19937 rng(7);
    List<Head> heads = near_orthogonal_heads(rng, 3, 10.0);
    const Combiner<double> comb(mountings_of(heads));  // heads A, B, C; D not mounted
    const Quat truth = random_rotation(rng);
    HeadAttitude<double> in[7];
    for (int i = 0; i < 3; ++i) {
        in[i] = attitude<double>(measure(heads[i], truth, rng), static_cast<std::uint8_t>(i));
    }
    const auto clean = comb.combine(in, 3);
    ASSERT_EQ(clean.status, cs::kTwoOrMoreHeads);
    in[3] = attitude<double>(measure(heads[1], truth, rng, 50.0), 1);  // B again, far off
    in[4] = attitude<double>(measure(heads[0], truth, rng), 3);        // D: not mounted
    in[5] = attitude<double>(measure(heads[0], truth, rng), kUnknownHead);
    const auto out = comb.combine(in, 6);
    EXPECT_EQ(out.status, cs::kTwoOrMoreHeads | cs::kHeadLeftOut);
    EXPECT_EQ(out.used, 7);
    EXPECT_EQ(out.left_out, 2 | 8);
    EXPECT_EQ(out.inconsistent, 0);
    EXPECT_EQ(out.q_crf_icrf.w, clean.q_crf_icrf.w);
    EXPECT_EQ(out.q_crf_icrf.x, clean.q_crf_icrf.x);
    // Only the unknown index: 4, in no mask.
    HeadAttitude<double> two[2] = {in[0], in[5]};
    const auto unknown = comb.combine(two, 2);
    EXPECT_EQ(unknown.status, cs::kOneHead | cs::kHeadLeftOut);
    EXPECT_EQ(unknown.left_out, 0);
    // A quaternion that is not unit, or not finite.
    HeadAttitude<double> bad[3] = {in[0], in[1], in[2]};
    bad[1].q_chu_icrf.w *= 1.01;
    bad[2].q_chu_icrf.x = std::numeric_limits<double>::quiet_NaN();
    const auto nonunit = comb.combine(bad, 3);
    EXPECT_EQ(nonunit.status, cs::kOneHead | cs::kHeadLeftOut);
    EXPECT_EQ(nonunit.left_out, 6);
}

// ---- The selection (usable.hpp).

// Step 1's order: the first reason that applies; step 2: every row of a head
// repeated (kLeaveAllOut) or all but the first (kKeepFirst), over any step-1
// reason; a usable row without a stage another usable row has; then not unit.
TEST(Combine, TheSelectionGivesTheFirstReasonAndDecidesTheEpoch) {
    constexpr HeadMask abc = 0x7U;
    const RowFacts ok{true, 0U, 3U, false, true, true};
    EXPECT_EQ(left_out_alone(ok, abc), LeftOut::kUsed);
    RowFacts r = ok;
    r.flagged = true;
    r.status = status::kRejected;
    EXPECT_EQ(left_out_alone(r, abc), LeftOut::kRejected);  // rejected before flagged
    r.status = status::kNoVelocity;
    EXPECT_EQ(left_out_alone(r, abc), LeftOut::kFlagged);  // flagged before a skipped stage
    r.head = 3U;
    EXPECT_EQ(left_out_alone(r, abc), LeftOut::kNotInMountings);
    r.head = kUnknownHead;
    EXPECT_EQ(left_out_alone(r, abc), LeftOut::kNotAHead);
    r.in_epoch = false;
    EXPECT_EQ(left_out_alone(r, abc), LeftOut::kNoEpoch);
    r = ok;
    r.confident = false;
    EXPECT_EQ(left_out_alone(r, abc), LeftOut::kConfidence);
    r.unit = false;  // a step-2 fact
    r.confident = true;
    EXPECT_EQ(left_out_alone(r, abc), LeftOut::kUsed);

    // A twice (the first flagged), B without the thermal stage, C not unit with
    // both stages, two rows that are no head.
    RowFacts rows[6] = {ok, ok, ok, ok, ok, ok};
    rows[0].flagged = true;
    rows[2].head = 1U;
    rows[2].status = status::kAberrationApplied;
    rows[3].head = 2U;
    rows[3].unit = false;
    rows[4].head = kUnknownHead;
    rows[5].head = kUnknownHead;
    for (const Repeated rule : {Repeated::kLeaveAllOut, Repeated::kKeepFirst}) {
        LeftOut why[6];
        for (std::size_t i = 0; i < 6; ++i) {
            why[i] = left_out_alone(rows[i], abc);
        }
        const StatusBits stages = select_epoch(rows, why, 6, rule);
        EXPECT_EQ(why[0], rule == Repeated::kKeepFirst ? LeftOut::kFlagged : LeftOut::kDuplicate);
        EXPECT_EQ(why[1], LeftOut::kDuplicate);
        // The stages of the usable rows, C's included: B lacks the thermal stage.
        EXPECT_EQ(stages, 3U);
        EXPECT_EQ(why[2], LeftOut::kStageMissing);
        EXPECT_EQ(why[3], LeftOut::kNotUnit);
        EXPECT_EQ(why[4], LeftOut::kNotAHead);  // two rows that are no head are no repeated head
        EXPECT_EQ(why[5], LeftOut::kNotAHead);
    }
    for (std::size_t k = 0; k < combine::kLeftOutKinds; ++k) {
        EXPECT_NE(left_out_name(static_cast<LeftOut>(k)), nullptr);
    }
}

// The on-board combiner applies step 1's head and mounting tests, step 2's
// norm test and Repeated::kKeepFirst itself (its caller gives the status part
// as `usable`): on random epochs of consistent heads, repeated, unusable,
// unmounted, unknown and not unit, it averages in exactly the heads the
// selection keeps.
TEST(Combine, TheCombinerKeepsTheHeadsTheSelectionKeeps) {
    std::mt19937 rng(11);
    const List<Head> heads = near_orthogonal_heads(rng, 3, 10.0);
    const Combiner<double> comb(mountings_of(heads));  // A, B, C; D not mounted
    std::uniform_int_distribution<int> pick(0, 9);
    int epochs_with_a_left_out_row = 0;
    for (int t = 0; t < 2000; ++t) {
        const Quat truth = random_rotation(rng);
        const auto n = static_cast<std::uint8_t>(1 + t % 8);
        HeadAttitude<double> in[8];
        RowFacts facts[8];
        LeftOut why[8];
        for (std::uint8_t i = 0; i < n; ++i) {
            const int kind = pick(rng);
            const auto head = static_cast<std::uint8_t>(kind == 9 ? kUnknownHead : kind % 4);
            const Head& h = heads[head < 3U ? head : 0U];
            in[i] = attitude<double>(measure(h, truth, rng), head, kind != 8);
            if (kind == 7) {
                in[i].q_chu_icrf.w *= 1.01;
            }
            facts[i] = {true,          head, 0U,
                        !in[i].usable, true, norm_within(in[i].q_chu_icrf, ScalarTraits<double>::unit_norm_tolerance)};
            why[i] = left_out_alone(facts[i], comb.mounted());
        }
        (void)select_epoch(facts, why, n, Repeated::kKeepFirst);
        HeadMask kept = 0U;
        bool any_left_out = false;
        for (std::uint8_t i = 0; i < n; ++i) {
            kept = static_cast<HeadMask>(kept | (why[i] == LeftOut::kUsed ? head_bit(in[i].head) : 0U));
            any_left_out = any_left_out || why[i] != LeftOut::kUsed;
        }
        const auto out = comb.combine(in, n);
        ASSERT_EQ(out.inconsistent, 0) << "epoch " << t;  // consistent heads: the gate keeps all
        EXPECT_EQ(out.used, kept) << "epoch " << t;
        EXPECT_EQ((out.status & cs::kHeadLeftOut) != 0U, any_left_out) << "epoch " << t;
        epochs_with_a_left_out_row += any_left_out ? 1 : 0;
    }
    EXPECT_GT(epochs_with_a_left_out_row, 1000);
}

// ---- The gate.

struct GateRun {
    int epochs = 0;
    int caught = 0;         // the offset head, and only it, inconsistent; the rest combined
    double worst_rest = 0;  // the combination of the rest against its reference, arcsec
};

// n heads, head `bad` off by `offset_arcsec` in a random direction.
template <typename T = double>
GateRun run_gate(int n, double offset_arcsec, int epochs, std::uint32_t seed) {
    std::mt19937 rng(seed);
    GateRun run;
    for (int t = 0; t < epochs; ++t) {
        const List<Head> heads = near_orthogonal_heads(rng, n, 20.0);
        const Combiner<T> comb(mountings_of(heads));
        const Quat truth = random_rotation(rng);
        const int bad = t % n;
        std::normal_distribution<double> g(0.0, 1.0);
        const Vec3 dir = Vec3(g(rng), g(rng), g(rng)).normalized();
        HeadAttitude<T> in[kMaxHeads];
        List<Head> rest_h;
        List<Quat> rest_q;
        for (int i = 0; i < n; ++i) {
            const Vec3 off = i == bad ? Vec3(dir * offset_arcsec * kArcsecToRad) : Vec3::Zero();
            const Quat q = measure(heads[i], truth, rng, 1.0, off);
            in[i] = attitude<T>(q, static_cast<std::uint8_t>(i));
            if (i != bad) {
                rest_h.push_back(heads[i]);
                rest_q.push_back(q);
            }
        }
        const auto out = comb.combine(in, static_cast<std::uint8_t>(n));
        ++run.epochs;
        const HeadMask all = static_cast<HeadMask>((1U << n) - 1U);
        if (out.inconsistent == (1U << bad) && out.used == (all & ~(1U << bad)) &&
            out.status == (cs::kTwoOrMoreHeads | cs::kHeadLeftOut)) {
            ++run.caught;
            run.worst_rest = std::max(
                run.worst_rest, error_arcsec(to_double(out.q_crf_icrf), reference_attitude(rest_h, rest_q)).norm());
        }
    }
    return run;
}

TEST(Combine, GateLeavesOutAHead200ArcsecOffWithThreeAndFourHeads) {
    for (const int n : {3, 4}) {
        const GateRun r = run_gate(n, 200.0, 600, 8U + static_cast<std::uint32_t>(n));
        EXPECT_EQ(r.caught, r.epochs) << n << " heads";
        EXPECT_LT(r.worst_rest, 0.005);
    }
    // The same decisions in float and Q30 (within their rounding of the answer).
    for (const int n : {3, 4}) {
        const GateRun f = run_gate<float>(n, 200.0, 300, 50U + static_cast<std::uint32_t>(n));
        EXPECT_EQ(f.caught, f.epochs) << n << " heads, float";
        EXPECT_LT(f.worst_rest, 0.06);
        const GateRun q = run_gate<Q30>(n, 200.0, 300, 50U + static_cast<std::uint32_t>(n));
        EXPECT_EQ(q.caught, q.epochs) << n << " heads, Q30";
        EXPECT_LT(q.worst_rest, 0.006);
        EXPECT_EQ(run_gate<Q30>(n, 3.0, 300, 60U).caught, 0);
        EXPECT_EQ(run_gate<float>(n, 3.0, 300, 60U).caught, 0);
    }
    // Gross errors (1°, 30°, 179°) whichever head has them, the reference included.
    for (const double off : {3600.0, 108000.0, 644400.0}) {
        for (const int n : {3, 4}) {
            const GateRun r = run_gate(n, off, 200, 20U + static_cast<std::uint32_t>(n));
            EXPECT_EQ(r.caught, r.epochs) << n << " heads, " << off << "\"";
            EXPECT_LT(r.worst_rest, 0.005);
        }
    }
}

TEST(Combine, GateKeepsHeadsAFewArcsecApartAndNoise) {
    // 3″ of thermal deformation (and 40″ of misaligned mounting) on one head, with noise.
    for (const double off : {3.0, 40.0}) {
        for (const int n : {2, 3, 4}) {
            const GateRun r = run_gate(n, off, 600, 30U + static_cast<std::uint32_t>(n));
            EXPECT_EQ(r.caught, 0) << n << " heads, " << off << "\"";
        }
    }
    // 5σ noise on one head: never left out.
    std::mt19937 rng(9);
    int tripped = 0;
    for (int t = 0; t < 3000; ++t) {
        const int n = 2 + t % 3;
        const List<Head> heads = near_orthogonal_heads(rng, n, 20.0);
        const Combiner<double> comb(mountings_of(heads));
        const Quat truth = random_rotation(rng);
        HeadAttitude<double> in[kMaxHeads];
        std::normal_distribution<double> g(0.0, 1.0);
        for (int i = 0; i < n; ++i) {
            Vec3 d(g(rng), g(rng), g(rng));
            d = d.normalized() * 5.0;  // a 5σ draw in a random direction of CHU axes
            const Vec3 noise(heads[i].sigma_cross * d.x(), heads[i].sigma_cross * d.y(), heads[i].sigma_about * d.z());
            const Quat q = (small_rotation(noise * kArcsecToRad) * heads[i].q_chu_crf * truth).normalized();
            in[i] = attitude<double>(i == 0 ? q : measure(heads[i], truth, rng), static_cast<std::uint8_t>(i));
        }
        tripped += comb.combine(in, static_cast<std::uint8_t>(n)).inconsistent != 0 ? 1 : 0;
    }
    EXPECT_EQ(tripped, 0);
}

// Two heads that disagree beyond the gate: no combination, both inconsistent.
TEST(Combine, TwoHeadsThatDisagreeGiveNoCombination) {
    for (const double off : {200.0, 3600.0, 108000.0}) {
        const GateRun r = run_gate(2, off, 200, 40U);
        EXPECT_EQ(r.caught, 0);
    }
    std::mt19937 rng(41);
    const List<Head> heads = near_orthogonal_heads(rng, 3, 20.0);
    const Combiner<double> comb(mountings_of(heads));
    const Quat truth = random_rotation(rng);
    HeadAttitude<double> in[2] = {attitude<double>(measure(heads[0], truth, rng), 0),
                                  attitude<double>(measure(heads[2], truth, rng, 1.0, Vec3(0, 1e-3, 0)), 2)};
    const auto out = comb.combine(in, 2);
    EXPECT_EQ(out.status, cs::kNoHead | cs::kHeadLeftOut);
    EXPECT_EQ(out.inconsistent, 5);
    EXPECT_EQ(out.left_out, 5);
    EXPECT_EQ(out.used, 0);
    EXPECT_EQ(out.q_crf_icrf.w, 1.0);
    // Three heads: one 200″ off, a second 1° off: the second goes by the gross
    // gate, the first by the consistency gate, no combination is left.
    HeadAttitude<double> three[3] = {in[0], in[1],
                                     attitude<double>(measure(heads[1], truth, rng, 1.0, Vec3(0.02, 0, 0)), 1)};
    const auto out3 = comb.combine(three, 3);
    EXPECT_EQ(out3.status, cs::kNoHead | cs::kHeadLeftOut);
    EXPECT_EQ(out3.inconsistent, 7);
}

// Four heads: B and D agree, A and C are beyond the gross gate of both and
// within it of each other, yet 495″ apart. The vote's two groups are as large;
// the consistency gate keeps B and D, none of A and C: B and D are averaged
// (before, the tie gave no combination, a review found). Two pairs that are
// each consistent stay ambiguous: no combination.
template <typename T>
void expect_tie_decided_by_the_gate() {
    std::mt19937 rng(43);
    const List<Head> heads = near_orthogonal_heads(rng, 4, 20.0);
    const Combiner<T> comb(mountings_of(heads));
    const Quat truth = random_rotation(rng);
    const Vec3 wild(0.005, 0.0, 0.0);  // 1031″
    const auto four = [&](const Vec3& c_off) {
        return std::array<HeadAttitude<T>, 4>{
            attitude<T>(measure(heads[0], truth, rng, 1.0, wild), 0), attitude<T>(measure(heads[1], truth, rng), 1),
            attitude<T>(measure(heads[2], truth, rng, 1.0, c_off), 2), attitude<T>(measure(heads[3], truth, rng), 3)};
    };
    const std::array<HeadAttitude<T>, 4> apart = four(wild + Vec3(0.0, 0.0024, 0.0));
    const auto out = comb.combine(apart.data(), 4);
    EXPECT_EQ(out.used, 0b1010);
    EXPECT_EQ(out.inconsistent, 0b0101);
    EXPECT_EQ(out.status, cs::kTwoOrMoreHeads | cs::kHeadLeftOut);
    const Vec3 err = error_arcsec(to_double(out.q_crf_icrf), truth.toRotationMatrix());
    EXPECT_LT(err.norm(), 30.0) << err.transpose();
    const std::array<HeadAttitude<T>, 4> pairs = four(wild);
    const auto both = comb.combine(pairs.data(), 4);
    EXPECT_EQ(both.used, 0);
    EXPECT_EQ(both.inconsistent, 0b1111);
    EXPECT_EQ(both.status, cs::kNoHead | cs::kHeadLeftOut);
}

TEST(Combine, ATieOfTheVoteIsDecidedByTheConsistencyGate) {
    expect_tie_decided_by_the_gate<double>();
    expect_tie_decided_by_the_gate<float>();
    expect_tie_decided_by_the_gate<Q30>();
}

// ---- Monte Carlo with the contract's noise model.

struct AxisErrors {
    Vec3 rms = Vec3::Zero();
    Vec3 formal = Vec3::Zero();
};

AxisErrors monte_carlo(const List<Head>& truth_heads, const Mountings& weights, int epochs, std::uint32_t seed) {
    std::mt19937 rng(seed);
    const Combiner<double> comb(weights);
    AxisErrors e;
    for (int t = 0; t < epochs; ++t) {
        const Quat truth = random_rotation(rng);
        HeadAttitude<double> in[3];
        for (int i = 0; i < 3; ++i) {
            in[i] = attitude<double>(measure(truth_heads[i], truth, rng), static_cast<std::uint8_t>(i));
        }
        const auto out = comb.combine(in, 3);
        const Vec3 err = error_arcsec(out.q_crf_icrf, truth.toRotationMatrix());
        e.rms += err.cwiseProduct(err);
    }
    e.rms = (e.rms / epochs).cwiseSqrt();
    // The true covariance of the estimator Σ K_i θ_i: Σ K_i C_i K_iᵀ.
    Mat3 p = Mat3::Zero();
    List<Head> w_heads = truth_heads;
    for (int i = 0; i < 3; ++i) {
        w_heads[i].sigma_cross = weights.head[i].sigma_cross_arcsec;
        w_heads[i].sigma_about = weights.head[i].sigma_about_arcsec;
        p += information(w_heads[i]);
    }
    Mat3 cov = Mat3::Zero();
    for (int i = 0; i < 3; ++i) {
        const Mat3 k = p.inverse() * information(w_heads[i]);
        cov += k * information(truth_heads[i]).inverse() * k.transpose();
    }
    e.formal = cov.diagonal().cwiseSqrt();
    return e;
}

TEST(Combine, MonteCarloErrorMatchesFormalSigmaAndBeatsEqualWeights) {
    std::mt19937 rng(10);
    const List<Head> heads = near_orthogonal_heads(rng, 3, 10.0);
    const Mountings info = mountings_of(heads);
    const AxisErrors e = monte_carlo(heads, info, 20000, 11);
    const Combiner<double> comb(info);
    for (int a = 0; a < 3; ++a) {
        const double formal = comb.sigma_arcsec(7)[a];
        EXPECT_NEAR(e.rms[a] / formal, 1.0, 0.1) << "axis " << a;
        EXPECT_NEAR(e.formal[a] / formal, 1.0, 1e-9);  // optimal: the estimator's covariance is the formal one
    }
    // Mutation check: equal weights (σa = σc) fail the bound the information
    // form passes, by about 3 times (combination.md: 3.07″ against 0.91″).
    Mountings equal = info;
    for (int i = 0; i < 3; ++i) {
        equal.head[i].sigma_about_arcsec = equal.head[i].sigma_cross_arcsec;
    }
    const AxisErrors q = monte_carlo(heads, equal, 20000, 11);
    double worst_ratio = 0.0;
    for (int a = 0; a < 3; ++a) {
        worst_ratio = std::max(worst_ratio, q.rms[a] / comb.sigma_arcsec(7)[a]);
    }
    EXPECT_GT(worst_ratio, 1.1) << "equal weights must fail the 10 % bound";
    EXPECT_GT(q.rms.norm() / e.rms.norm(), 2.5);
    RecordProperty("information_rms_arcsec", std::to_string(e.rms.norm() / std::sqrt(3.0)));
    RecordProperty("equal_rms_arcsec", std::to_string(q.rms.norm() / std::sqrt(3.0)));
    std::printf(
        "Monte Carlo, three heads: information RMS per axis %.3f %.3f %.3f arcsec (formal %.3f %.3f %.3f), "
        "equal weights %.3f %.3f %.3f\n",
        e.rms[0], e.rms[1], e.rms[2], comb.sigma_arcsec(7)[0], comb.sigma_arcsec(7)[1], comb.sigma_arcsec(7)[2],
        q.rms[0], q.rms[1], q.rms[2]);
}

// ---- Float against double.

struct Agreement {
    double worst = 0.0;  // arcsec
    double rms = 0.0;
};

template <typename T>
Agreement against_double(int epochs, std::uint32_t seed) {
    std::mt19937 rng(seed);
    Agreement a;
    for (int t = 0; t < epochs; ++t) {
        const int n = 1 + t % 4;
        List<Head> heads = near_orthogonal_heads(rng, 4, 30.0);
        const Mountings m = mountings_of(heads);
        const Combiner<double> cd(m);
        const Combiner<T> ct(m);
        const Quat truth = random_rotation(rng);
        HeadAttitude<double> ind[kMaxHeads];
        HeadAttitude<T> int_[kMaxHeads];
        for (int i = 0; i < n; ++i) {
            const Quat q = measure(heads[i], truth, rng);
            int_[i] = attitude<T>(q, static_cast<std::uint8_t>(i));
            ind[i] = {to_double(int_[i].q_chu_icrf), static_cast<std::uint8_t>(i), true};  // the same input
        }
        const auto od = cd.combine(ind, static_cast<std::uint8_t>(n));
        const auto ot = ct.combine(int_, static_cast<std::uint8_t>(n));
        EXPECT_EQ(od.status, ot.status);
        EXPECT_EQ(od.used, ot.used);
        const double d = angle_arcsec(od.q_crf_icrf, to_double(ot.q_crf_icrf));
        a.worst = std::max(a.worst, d);
        a.rms += d * d;
    }
    a.rms = std::sqrt(a.rms / epochs);
    return a;
}

// Float: the issue asks for 0.03″; float itself does not allow it as a worst
// case. One float Hamilton product of two unit quaternions is off by up to
// 0.059″ (0.015″ RMS; 200 000 random pairs, also with fused multiply-adds:
// 0.052″), and merely rounding the double answer to float costs up to 0.020″;
// the combination needs at least one such product per head. The bound below
// is the float floor measured here (worst 0.056″ over 20 000 epochs of one to
// four heads, the mountings' rounding taken out, combiner.hpp bias_); the
// test fails on any error of method (a wrong gain or sign is arcseconds).
TEST(Combine, FloatIsWithinItsFloorOfDouble) {
    const Agreement a = against_double<float>(20000, 12);
    EXPECT_LT(a.worst, 0.06);
    EXPECT_LT(a.rms, 0.02);
    RecordProperty("worst_arcsec", std::to_string(a.worst));
    std::printf("float: worst %.4f arcsec, RMS %.4f from double over 20000 epochs\n", a.worst, a.rms);
}

TEST(Combine, FixedPointIsWithin001ArcsecOfDouble) {
    const Agreement a = against_double<Q30>(20000, 14);
    EXPECT_LT(a.worst, 0.01);
    RecordProperty("worst_arcsec", std::to_string(a.worst));
    std::printf("Q30: worst %.5f arcsec, RMS %.5f from double over 20000 epochs\n", a.worst, a.rms);
}

// ---- The usual epoch's one pass (combiner.hpp combine_usual).

// The same heads with one more entry that names no head: the usual pass
// refuses that epoch, so the general path answers it (with bit 4 for the
// extra entry). Both must give the same attitude, bit for bit, in every
// scalar: for usual epochs, for heads beyond the gate or the gross gate, and
// for mountings so noisy (σ 1000″) that the gate's own bound reaches past the
// gross gate, where only the quick bound's cap (quick_bound) keeps the one
// pass from averaging heads 0.5° apart. Mutation: without the cap, the
// 1000″ case's far heads are averaged in by the one pass and this fails.
template <typename T>
int usual_differs_from_general(double sigma, double offset_arcsec, std::uint32_t seed) {
    std::mt19937 rng(seed);
    int differ = 0;
    for (int t = 0; t < 400; ++t) {
        const int n = 2 + t % 3;
        const List<Head> heads = near_orthogonal_heads(rng, 4, 20.0, sigma, sigma);
        const Combiner<T> c(mountings_of(heads));
        const Quat truth = random_rotation(rng);
        HeadAttitude<T> in[kMaxHeads + 1];
        for (int i = 0; i < n; ++i) {
            const Vec3 off = i == t % n ? Vec3(offset_arcsec * kArcsecToRad, 0, 0) : Vec3::Zero();
            in[i] = attitude<T>(measure(heads[i], truth, rng, 0.02, off), static_cast<std::uint8_t>(i));
        }
        in[n] = in[0];
        in[n].head = kMaxHeads + 2;  // no head: only the general path takes this epoch
        const CombinedAttitude<T> one = c.combine(in, static_cast<std::uint8_t>(n));
        const CombinedAttitude<T> general = c.combine(in, static_cast<std::uint8_t>(n + 1));
        const bool same = std::memcmp(&one.q_crf_icrf, &general.q_crf_icrf, sizeof one.q_crf_icrf) == 0 &&
                          one.used == general.used && one.inconsistent == general.inconsistent &&
                          (one.status | combine::combined_status::kHeadLeftOut) == general.status;
        differ += same ? 0 : 1;
    }
    return differ;
}

template <typename T>
void expect_usual_is_general() {
    EXPECT_EQ(usual_differs_from_general<T>(kSigmaCross, 0.0, 71U), 0);
    EXPECT_EQ(usual_differs_from_general<T>(kSigmaCross, 300.0, 72U), 0);   // beyond the gate
    EXPECT_EQ(usual_differs_from_general<T>(kSigmaCross, 1800.0, 73U), 0);  // beyond the gross gate
    EXPECT_EQ(usual_differs_from_general<T>(1000.0, 1800.0, 74U), 0);       // the cap decides
}

TEST(Combine, UsualEpochPassIsTheGeneralPathBitForBit) {
    expect_usual_is_general<double>();
    expect_usual_is_general<float>();
    expect_usual_is_general<Q30>();
}

// ---- No allocation.

TEST(Combine, NeverAllocates) {
    std::mt19937 rng(13);
    const List<Head> heads = near_orthogonal_heads(rng, 4, 20.0);
    const Mountings m = mountings_of(heads);
    arm_allocation_counter();
    const Combiner<double> cd(m);
    const Combiner<float> cf(m);
    double sink = 0.0;
    for (int t = 0; t < 200; ++t) {
        const Quat truth = random_rotation(rng);
        HeadAttitude<double> in[6];
        HeadAttitude<float> inf[6];
        for (int i = 0; i < 6; ++i) {
            const Vec3 off = t % 5 == i ? Vec3(1e-3, 0, 0) : Vec3::Zero();
            const Quat q = measure(heads[i % 4], truth, rng, 1.0, off);
            in[i] = attitude<double>(q, static_cast<std::uint8_t>(i % 5), t % 7 != i);
            inf[i] = attitude<float>(q, static_cast<std::uint8_t>(i % 5), t % 7 != i);
        }
        sink += cd.combine(in, static_cast<std::uint8_t>(t % 7)).q_crf_icrf.w;
        sink += static_cast<double>(cf.combine(inf, static_cast<std::uint8_t>(t % 7)).q_crf_icrf.x);
    }
    EXPECT_EQ(disarm_allocation_counter(), 0);
    EXPECT_TRUE(std::isfinite(sink));
}

}  // namespace
}  // namespace ascorr::test
