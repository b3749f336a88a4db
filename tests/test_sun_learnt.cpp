// The Sun term's shared least squares (calib/sun_moments.hpp, with its Jacobi
// eigen-decomposition, calib/symmetric_eigen.hpp) against the test's own
// explicit design solved by Eigen, and the Sun term learnt by the
// self-calibration (issue 40: `correct --self-calibrate --sun-term auto`,
// calib/sun_learner.hpp), measured against the simulator's noise-only IBAs on
// a mission whose bench lags and turns with the Sun.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <functional>
#include <iomanip>
#include <iostream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "ascorr/calib/frame.hpp"
#include "ascorr/calib/head_rotation.hpp"
#include "ascorr/calib/sun_learner.hpp"
#include "ascorr/calib/sun_moments.hpp"
#include "ascorr/calib/symmetric_eigen.hpp"
#include "ascorr_host/analysis/stats.hpp"
#include "ascorr_host/correct/self_calibration.hpp"
#include "ascorr_host/formats/model_csv.hpp"
#include "ascorr_host/formats/solutions_csv.hpp"
#include "ascorr_host/link/replay.hpp"
#include "cli_run.hpp"
#include "corrected_files.hpp"
#include "inside_orbit_missions.hpp"
#include "test_support.hpp"

namespace ascorr::test {
namespace {

namespace fs = std::filesystem;

// ---- symmetric_eigen against Eigen's SelfAdjointEigenSolver

constexpr std::size_t kMax = 36;
// a = V·diag·Vᵀ and the eigenvalues to the off-diagonal part the sweeps
// leave (kJacobiTolerance of ‖a‖) and double's rounding.
constexpr double kDecomposed = calib::kJacobiTolerance + 1e-13;

TEST(SymmetricEigen, ReconstructsAndMatchesEigenOnRandomMatrices) {
    std::mt19937_64 rng(7);
    std::normal_distribution<double> g(0.0, 1.0);
    for (Eigen::Index n : {1, 2, 3, 9, 27, 36}) {
        const auto un = static_cast<std::size_t>(n);
        for (int trial = 0; trial < 5; ++trial) {
            Eigen::MatrixXd m(n, n);
            for (Eigen::Index i = 0; i < n; ++i) {
                for (Eigen::Index j = 0; j <= i; ++j) {
                    // A rank-deficient part at trial 0, as the Sun term's normal equations are.
                    m(i, j) = m(j, i) = trial == 0 && (i % 3 == 2 || j % 3 == 2) ? 0.0 : g(rng);
                }
            }
            double a[kMax][kMax] = {};
            double v[kMax][kMax] = {};
            for (Eigen::Index i = 0; i < n; ++i) {
                for (Eigen::Index j = 0; j < n; ++j) {
                    a[i][j] = m(i, j);
                }
            }
            const int sweeps = calib::symmetric_eigen(a, v, un);
            ASSERT_GE(sweeps, 0);
            ASSERT_LE(sweeps, calib::kMaxJacobiSweeps) << n;
            Eigen::MatrixXd vm(n, n);
            Eigen::VectorXd lambda(n);
            for (Eigen::Index i = 0; i < n; ++i) {
                lambda(i) = a[i][i];
                for (Eigen::Index j = 0; j < n; ++j) {
                    vm(i, j) = v[i][j];
                }
            }
            const double scale = m.norm();
            EXPECT_LT((vm * lambda.asDiagonal() * vm.transpose() - m).norm(), kDecomposed * scale) << n;
            EXPECT_LT((vm.transpose() * vm - Eigen::MatrixXd::Identity(n, n)).norm(), 1e-13 * static_cast<double>(n))
                << n;
            std::sort(lambda.data(), lambda.data() + n);
            const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> reference(m);
            EXPECT_LT((lambda - reference.eigenvalues()).norm(), kDecomposed * scale) << n;
        }
    }
}

// The whole sweeps as symmetric_eigen() ran them before its steps
// (jacobi_start, jacobi_row), copied from it, with its threshold: the steps
// must give its bits.
template <std::size_t N>
int whole_sweeps(double (&a)[N][N], double (&v)[N][N], std::size_t n) {
    double total = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
        for (std::size_t j = 0; j < n; ++j) {
            v[i][j] = i == j ? 1.0 : 0.0;
            total += a[i][j] * a[i][j];
        }
    }
    const double bound = calib::kJacobiTolerance * calib::kJacobiTolerance * total;
    const double skip = bound / static_cast<double>(n * n);  // the threshold's (jacobi_row)
    for (int sweep = 0; sweep < calib::kMaxJacobiSweeps; ++sweep) {
        double off = 0.0;
        for (std::size_t i = 0; i < n; ++i) {
            for (std::size_t j = 0; j < n; ++j) {
                off += i == j ? 0.0 : a[i][j] * a[i][j];
            }
        }
        if (off <= bound) {
            return sweep;
        }
        for (std::size_t p = 0; p + 1U < n; ++p) {
            for (std::size_t q = p + 1U; q < n; ++q) {
                if (a[p][q] * a[p][q] > skip) {
                    calib::jacobi_rotation(a, v, n, p, q);
                }
            }
        }
    }
    return calib::kMaxJacobiSweeps + 1;
}

TEST(SymmetricEigen, ItsStepsGiveTheBitsOfTheWholeSweeps) {
    std::mt19937_64 rng(8);
    std::normal_distribution<double> g(0.0, 1.0);
    int compared = 0;
    for (std::size_t n : {std::size_t{0}, std::size_t{1}, std::size_t{2}, std::size_t{9}, std::size_t{27}}) {
        for (int trial = 0; trial < 3; ++trial) {
            static double a[kMax][kMax];
            static double b[kMax][kMax];
            static double va[kMax][kMax];
            static double vb[kMax][kMax];
            for (std::size_t i = 0; i < kMax; ++i) {
                for (std::size_t j = 0; j <= i; ++j) {
                    a[i][j] = a[j][i] = trial == 0 && (i % 3 == 2 || j % 3 == 2) ? 0.0 : g(rng);
                }
            }
            std::memcpy(b, a, sizeof a);
            std::memset(va, 0, sizeof va);
            std::memset(vb, 0, sizeof vb);
            EXPECT_EQ(calib::symmetric_eigen(a, va, n), whole_sweeps(b, vb, n)) << n;
            EXPECT_EQ(std::memcmp(a, b, sizeof a), 0) << n;
            EXPECT_EQ(std::memcmp(va, vb, sizeof va), 0) << n;
            ++compared;
        }
    }
    EXPECT_EQ(compared, 15);
}

// The rotation as it was before it copied rows p and q (both passes formed
// in full), the test's own: on a symmetric matrix the copy gives its bits.
template <std::size_t N>
void two_pass_rotation(double (&a)[N][N], double (&v)[N][N], std::size_t n, std::size_t p, std::size_t q) {
    const double apq = a[p][q];
    if (apq == 0.0) {
        return;
    }
    const double tau = (a[q][q] - a[p][p]) / (2.0 * apq);
    const double t =
        std::fabs(tau) > 1e150 ? 0.5 / tau : (tau >= 0.0 ? 1.0 : -1.0) / (std::fabs(tau) + std::sqrt(1.0 + tau * tau));
    const double c = 1.0 / std::sqrt(1.0 + t * t);
    const double s = t * c;
    for (std::size_t k = 0; k < n; ++k) {
        const double akp = a[k][p];
        const double akq = a[k][q];
        a[k][p] = c * akp - s * akq;
        a[k][q] = s * akp + c * akq;
    }
    for (std::size_t k = 0; k < n; ++k) {
        const double apk = a[p][k];
        const double aqk = a[q][k];
        a[p][k] = c * apk - s * aqk;
        a[q][k] = s * apk + c * aqk;
    }
    a[p][q] = 0.0;
    a[q][p] = 0.0;
    for (std::size_t k = 0; k < n; ++k) {
        const double vkp = v[k][p];
        const double vkq = v[k][q];
        v[k][p] = c * vkp - s * vkq;
        v[k][q] = s * vkp + c * vkq;
    }
}

TEST(SymmetricEigen, ItsRotationGivesTheTwoPassFormsBits) {
    std::mt19937_64 rng(10);
    std::normal_distribution<double> g(0.0, 1.0);
    int rotations = 0;
    for (std::size_t n : {std::size_t{2}, std::size_t{9}, std::size_t{27}, std::size_t{36}}) {
        static double a[kMax][kMax];
        static double b[kMax][kMax];
        static double va[kMax][kMax];
        static double vb[kMax][kMax];
        for (std::size_t i = 0; i < kMax; ++i) {
            for (std::size_t j = 0; j <= i; ++j) {
                a[i][j] = a[j][i] = std::ldexp(g(rng), static_cast<int>((i + j) % 7) - 3);  // graded
            }
            for (std::size_t j = 0; j < kMax; ++j) {
                va[i][j] = i == j ? 1.0 : 0.0;
            }
        }
        std::memcpy(b, a, sizeof a);
        std::memcpy(vb, va, sizeof va);
        for (int sweep = 0; sweep < 6; ++sweep) {
            for (std::size_t p = 0; p + 1U < n; ++p) {
                for (std::size_t q = p + 1U; q < n; ++q) {
                    calib::jacobi_rotation(a, va, n, p, q);
                    two_pass_rotation(b, vb, n, p, q);
                    ++rotations;
                }
            }
        }
        EXPECT_EQ(std::memcmp(a, b, sizeof a), 0) << n;
        EXPECT_EQ(std::memcmp(va, vb, sizeof va), 0) << n;
    }
    EXPECT_GT(rotations, 0);
}

// The warm start (jacobi_to_basis, jacobi_resume): a matrix near one
// decomposed, begun in that decomposition's basis, decomposes as Eigen does,
// in fewer sweeps than from the identity, whatever the lines per step.
TEST(SymmetricEigen, FromAnEarlierBasisItDecomposesInFewerSweeps) {
    std::mt19937_64 rng(9);
    std::normal_distribution<double> g(0.0, 1.0);
    constexpr std::size_t n = 27;
    static double a0[kMax][kMax];
    static double a[kMax][kMax];
    static double v[kMax][kMax];
    static double cold_v[kMax][kMax];
    Eigen::MatrixXd m(n, n);
    for (std::size_t i = 0; i < n; ++i) {
        for (std::size_t j = 0; j <= i; ++j) {
            a0[i][j] = a0[j][i] = g(rng);
        }
    }
    std::memcpy(a, a0, sizeof a);
    ASSERT_GE(calib::symmetric_eigen(a, v, n), 0);
    for (std::size_t i = 0; i < n; ++i) {  // the next orbit's: 0.3 % more
        for (std::size_t j = 0; j <= i; ++j) {
            a0[i][j] = a0[j][i] = a0[i][j] + 3e-3 * g(rng);
            m(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j)) = a0[i][j];
            m(static_cast<Eigen::Index>(j), static_cast<Eigen::Index>(i)) = a0[i][j];
        }
    }
    std::memcpy(a, a0, sizeof a);
    const int cold = calib::symmetric_eigen(a, cold_v, n);
    for (std::size_t lines : {std::size_t{1}, std::size_t{8}, std::size_t{54}}) {
        static double w[kMax][kMax];
        static double wv[kMax][kMax];
        std::memcpy(w, a0, sizeof w);
        std::memcpy(wv, v, sizeof wv);
        std::size_t line = 0;
        int calls = 0;
        while (!calib::jacobi_to_basis(w, wv, n, line, lines)) {
            ++calls;
        }
        EXPECT_EQ(calls + 1, static_cast<int>((2 * n + lines - 1) / lines)) << lines;
        calib::JacobiProgress progress;
        ASSERT_TRUE(calib::jacobi_resume(w, wv, n, progress));
        calib::JacobiStep s = calib::JacobiStep::kRunning;
        for (int i = 0; i < calib::jacobi_max_steps(n) && s == calib::JacobiStep::kRunning; ++i) {
            s = calib::jacobi_row(w, wv, progress);
        }
        ASSERT_EQ(s, calib::JacobiStep::kConverged);
        EXPECT_LT(progress.sweep, cold) << "the warm start must save sweeps: " << progress.sweep << " of " << cold;
        Eigen::MatrixXd vm(n, n);
        Eigen::VectorXd lambda(n);
        for (std::size_t i = 0; i < n; ++i) {
            lambda(static_cast<Eigen::Index>(i)) = w[i][i];
            for (std::size_t j = 0; j < n; ++j) {
                vm(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j)) = wv[i][j];
            }
        }
        const double scale = m.norm();
        EXPECT_LT((vm * lambda.asDiagonal() * vm.transpose() - m).norm(), kDecomposed * scale) << lines;
        EXPECT_LT((vm.transpose() * vm - Eigen::MatrixXd::Identity(n, n)).norm(), 1e-13 * 27.0) << lines;
        std::sort(lambda.data(), lambda.data() + n);
        const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> reference(m);
        EXPECT_LT((lambda - reference.eigenvalues()).norm(), kDecomposed * scale) << lines;
        RecordProperty("sweeps_cold", cold);
        RecordProperty("sweeps_warm", progress.sweep);
    }
}

TEST(SymmetricEigen, RefusesWhatIsNotFiniteOrTooLarge) {
    double a[3][3] = {{1.0, 0.0, 0.0}, {0.0, std::nan(""), 0.0}, {0.0, 0.0, 1.0}};
    double v[3][3] = {};
    EXPECT_EQ(calib::symmetric_eigen(a, v, 3), -1);
    double b[3][3] = {{1.0, 2.0, 0.0}, {2.0, 1.0, 0.0}, {0.0, 0.0, 1.0}};
    EXPECT_EQ(calib::symmetric_eigen(b, v, 4), -1);
    EXPECT_EQ(b[0][1], 2.0) << "left as it was";
}

// ---- SunMoments against the explicit design

Quaternion<double> unit(const Quaternion<double>& q) {
    const double n = std::sqrt(q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z);
    return {q.w / n, q.x / n, q.y / n, q.z / n};
}

// A unit quaternion turned by a small rotation (rad) about each axis.
Quaternion<double> turned(const Quaternion<double>& q, double x, double y, double z) {
    const Quaternion<double> d = unit(Quaternion<double>{1.0, 0.5 * x, 0.5 * y, 0.5 * z});
    return unit(d * q);
}

struct Synthetic {
    std::vector<std::array<Quaternion<double>, kMaxHeads>> q;  // by epoch, by head
    std::vector<Vector3<double>> s;
    std::vector<int> orbit;
};

// Three heads on a bench turning through an orbit, each turned by its own
// small noise; the Sun along a slowly moving direction.
Synthetic synthetic(std::size_t orbits, std::size_t per_orbit, std::uint64_t seed) {
    std::mt19937_64 rng(seed);
    std::normal_distribution<double> noise(0.0, 5e-6);
    const Quaternion<double> mount[3] = {unit(Quaternion<double>{0.9, 0.1, -0.3, 0.2}),
                                         unit(Quaternion<double>{0.2, 0.8, 0.1, -0.4}),
                                         unit(Quaternion<double>{-0.3, 0.2, 0.9, 0.1})};
    Synthetic out;
    for (std::size_t o = 0; o < orbits; ++o) {
        for (std::size_t k = 0; k < per_orbit; ++k) {
            const double phase = 2.0 * kPi * static_cast<double>(k) / static_cast<double>(per_orbit);
            const Quaternion<double> bench{std::cos(0.5 * phase), 0.0, std::sin(0.5 * phase), 0.0};
            std::array<Quaternion<double>, kMaxHeads> q{};
            for (std::size_t h = 0; h < 3; ++h) {
                q[h] = turned(mount[h] * bench, noise(rng), noise(rng), noise(rng));
            }
            const double season = 0.01 * static_cast<double>(o);
            out.q.push_back(q);
            out.s.push_back({std::cos(season), std::sin(season) * 0.9, std::sin(season) * 0.43589});
            out.orbit.push_back(static_cast<int>(o));
        }
    }
    return out;
}

// The explicit least squares: per epoch the 3H equations e = X·θ (X's rows
// s_hᵀ in the columns of head h's axis), the orbit's means taken out of e and
// X, then projected by P; solved by Eigen's eigen-decomposition with the same
// rank tolerance.
Eigen::VectorXd explicit_solution(const Synthetic& d) {
    const int n = 9;
    const int u = 27;
    Eigen::MatrixXd normal = Eigen::MatrixXd::Zero(u, u);
    Eigen::VectorXd rhs = Eigen::VectorXd::Zero(u);
    std::array<Quaternion<double>, 3> ref{};
    Eigen::MatrixXd p(n, n);
    std::size_t begin = 0;
    while (begin < d.q.size()) {
        std::size_t end = begin;
        while (end < d.q.size() && d.orbit[end] == d.orbit[begin]) {
            ++end;
        }
        std::vector<Eigen::VectorXd> es;
        std::vector<Eigen::MatrixXd> xs;
        for (std::size_t k = begin; k < end; ++k) {
            const Quaternion<double> q_f = calib::q_f_icrf(d.q[k][0], d.q[k][2]);
            Eigen::VectorXd e(n);
            Eigen::MatrixXd x = Eigen::MatrixXd::Zero(n, u);
            for (int h = 0; h < 3; ++h) {
                const auto uh = static_cast<std::size_t>(h);
                const Quaternion<double> q_hf = calib::q_head_f(d.q[k][uh], q_f);
                if (k == 0) {
                    ref[uh] = q_hf;
                }
                const Vector3<double> a = calib::small_angle(calib::relative_to(q_hf, ref[uh]));
                e.segment<3>(3 * h) << a.x * kRadToArcsec, a.y * kRadToArcsec, a.z * kRadToArcsec;
                const Vector3<double> s = rotated(d.q[k][uh], d.s[k]);
                for (int ax = 0; ax < 3; ++ax) {
                    x.block<1, 3>(3 * h + ax, 9 * h + 3 * ax) << s.x, s.y, s.z;
                }
            }
            es.push_back(e);
            xs.push_back(x);
        }
        if (begin == 0) {
            Eigen::MatrixXd g(n, 3);
            for (int h = 0; h < 3; ++h) {
                const Quaternion<double>& q = ref[static_cast<std::size_t>(h)];
                const Eigen::Quaterniond r(q.w, q.x, q.y, q.z);
                g.block<3, 3>(3 * h, 0) = r.toRotationMatrix();
            }
            p = Eigen::MatrixXd::Identity(n, n) - g * (g.transpose() * g).inverse() * g.transpose();
        }
        Eigen::VectorXd e_mean = Eigen::VectorXd::Zero(n);
        Eigen::MatrixXd x_mean = Eigen::MatrixXd::Zero(n, u);
        for (std::size_t i = 0; i < es.size(); ++i) {
            e_mean += es[i] / static_cast<double>(es.size());
            x_mean += xs[i] / static_cast<double>(es.size());
        }
        for (std::size_t i = 0; i < es.size(); ++i) {
            const Eigen::MatrixXd x = p * (xs[i] - x_mean);
            normal += x.transpose() * x;
            rhs += x.transpose() * (p * (es[i] - e_mean));
        }
        begin = end;
    }
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(normal);
    const double floor = calib::kSunRankTolerance * eig.eigenvalues().maxCoeff();
    Eigen::VectorXd theta = Eigen::VectorXd::Zero(u);
    for (int k = 0; k < u; ++k) {
        if (eig.eigenvalues()(k) > floor) {
            const Eigen::VectorXd v = eig.eigenvectors().col(k);
            theta += v * (v.dot(rhs) / eig.eigenvalues()(k));
        }
    }
    return theta;
}

// N_h of the synthetic epochs: each head's rotation in F at the first epoch.
std::array<Eigen::Matrix3d, 3> references_of(const Synthetic& d) {
    std::array<Eigen::Matrix3d, 3> n{};
    const Quaternion<double> q_f = calib::q_f_icrf(d.q[0][0], d.q[0][2]);
    for (std::size_t h = 0; h < 3; ++h) {
        const Quaternion<double> r = calib::q_head_f(d.q[0][h], q_f);
        n[h] = Eigen::Quaterniond(r.w, r.x, r.y, r.z).toRotationMatrix();
    }
    return n;
}

// The three heads' moments, F of A and C.
calib::SunMoments<3> three_heads() {
    const std::uint8_t heads[3] = {0, 1, 2};
    return calib::SunMoments<3>(heads, 3, 0, 2);
}

// Every synthetic epoch into m, each orbit closed with `keep` (the last too).
void feed(const Synthetic& d, calib::SunMoments<3>& m, double keep) {
    for (std::size_t k = 0; k < d.q.size(); ++k) {
        if (k > 0 && d.orbit[k] != d.orbit[k - 1]) {
            m.close_orbit(keep);
        }
        ASSERT_TRUE(m.add(d.q[k].data(), d.s[k])) << k;
    }
    m.close_orbit(keep);
}

TEST(SunMoments, TheSumsSolveAsTheExplicitDesign) {
    const Synthetic d = synthetic(12, 40, 11);
    calib::SunMoments<3> moments = three_heads();
    feed(d, moments, 1.0);
    calib::SunTermFit fit;
    ASSERT_TRUE(moments.solve(calib::SunRule{}, fit));
    const Eigen::VectorXd reference = explicit_solution(d);
    double largest = 0.0;
    for (int h = 0; h < 3; ++h) {
        for (int a = 0; a < 3; ++a) {
            for (int m = 0; m < 3; ++m) {
                const double ref = reference(9 * h + 3 * a + m);
                largest = std::max(largest, std::fabs(ref));
                EXPECT_NEAR(fit.sun[h][a][m], ref, 1e-6 + 1e-6 * std::fabs(ref)) << h << a << m;
            }
        }
    }
    EXPECT_GT(largest, 0.0) << "the noise alone must give a term: the test must be able to fail";
    EXPECT_EQ(fit.orbits, 12U);
    EXPECT_EQ(fit.epochs, 480U);
    EXPECT_EQ(fit.heads, 7U);
}

TEST(SunMoments, ARigidHeadIsExactlyZeroAndForgettingWeighsTheLatestOrbits) {
    const Synthetic d = synthetic(6, 40, 12);
    calib::SunMoments<3> kept = three_heads();
    calib::SunMoments<3> forgot = three_heads();
    feed(d, kept, 1.0);
    feed(d, forgot, 0.0);  // only the last orbit counts
    calib::SunRule rigid;
    rigid.rigid_head = 1;
    calib::SunTermFit fit;
    ASSERT_TRUE(kept.solve(rigid, fit));
    for (const auto& axis : fit.sun[1]) {
        for (const double c : axis) {
            EXPECT_EQ(c, 0.0);
        }
    }
    calib::SunTermFit all;
    calib::SunTermFit last;
    ASSERT_TRUE(kept.solve(calib::SunRule{}, all));
    // The rule adds one common rotation to every head: S_h − S_h(smallest) =
    // N_h·C·N_hᵀ with the same C, which the rigid head's difference gives.
    const std::array<Eigen::Matrix3d, 3> n = references_of(d);
    const auto diff = [&](int h) {
        Eigen::Matrix3d m;
        for (int a = 0; a < 3; ++a) {
            for (int c = 0; c < 3; ++c) {
                const auto ua = static_cast<std::size_t>(a);
                const auto uc = static_cast<std::size_t>(c);
                const auto uh = static_cast<std::size_t>(h);
                m(a, c) = fit.sun[uh][ua][uc] - all.sun[uh][ua][uc];
            }
        }
        return m;
    };
    const Eigen::Matrix3d common = n[1].transpose() * diff(1) * n[1];
    EXPECT_GT(common.norm(), 1e-3) << "the smallest coefficients are not rigid-B's";
    for (int h : {0, 2}) {
        EXPECT_LT(
            (n[static_cast<std::size_t>(h)] * common * n[static_cast<std::size_t>(h)].transpose() - diff(h)).norm(),
            1e-9 * common.norm())
            << h;
    }
    ASSERT_TRUE(forgot.solve(calib::SunRule{}, last));
    Synthetic tail;
    const std::size_t from = 5 * 40;
    tail.q.assign(d.q.begin() + from, d.q.end());
    tail.s.assign(d.s.begin() + from, d.s.end());
    tail.orbit.assign(d.orbit.begin() + from, d.orbit.end());
    // The last orbit alone, referred to its own first epoch: the same term as
    // the explicit design of that orbit (the reference cancels in e's mean).
    const Eigen::VectorXd reference = explicit_solution(tail);
    EXPECT_NEAR(last.sun[0][0][0], reference(0), 1e-6 + 1e-6 * std::fabs(reference(0)));
    EXPECT_NE(last.sun[0][0][0], all.sun[0][0][0]);
}

// With weights A_h, the rule's terms move the weighted bench by nothing:
// Σ_h A_h·S_h·N_h = 0 (for every Sun direction in F); the smallest
// coefficients' do not (the test can fail).
TEST(SunMoments, WeightedRuleLeavesTheWeightedBenchUnmoved) {
    const Synthetic d = synthetic(8, 40, 13);
    calib::SunMoments<3> moments = three_heads();
    feed(d, moments, 1.0);
    std::mt19937_64 rng(5);
    std::normal_distribution<double> g(0.0, 1.0);
    calib::Matrix3 weights[kMaxHeads]{};
    for (std::size_t h = 0; h < 3; ++h) {
        for (auto& row : weights[h].m) {
            for (double& v : row) {
                v = 1e4 * g(rng);  // 1/σ²-sized
            }
        }
    }
    calib::SunRule rule;
    rule.weight = weights;
    calib::SunTermFit weighted;
    calib::SunTermFit smallest;
    ASSERT_TRUE(moments.solve(rule, weighted));
    ASSERT_TRUE(moments.solve(calib::SunRule{}, smallest));
    const std::array<Eigen::Matrix3d, 3> n = references_of(d);
    const auto motion = [&](const calib::SunTermFit& f) {
        Eigen::Matrix3d m = Eigen::Matrix3d::Zero();
        double size = 0.0;
        for (std::size_t h = 0; h < 3; ++h) {
            Eigen::Matrix3d a;
            Eigen::Matrix3d s;
            for (int r = 0; r < 3; ++r) {
                for (int c = 0; c < 3; ++c) {
                    const auto ur = static_cast<std::size_t>(r);
                    const auto uc = static_cast<std::size_t>(c);
                    a(r, c) = weights[h].m[ur][uc];
                    s(r, c) = f.sun[h][ur][uc];
                }
            }
            m += a * s * n[h];
            size += (a * s * n[h]).norm();
        }
        return m.norm() / size;
    };
    EXPECT_LT(motion(weighted), 1e-9);
    EXPECT_GT(motion(smallest), 1e-3);
}

TEST(SunMoments, ANonFiniteEpochIsRefusedAndSpoilsNothing) {
    const Synthetic d = synthetic(3, 40, 14);
    calib::SunMoments<3> clean = three_heads();
    calib::SunMoments<3> with_nan = three_heads();
    // Before the first epoch (the references must come from a finite one) and
    // inside the first orbit: refused, nothing summed.
    std::array<Quaternion<double>, kMaxHeads> bad = d.q[0];
    bad[1].x = std::nan("");
    EXPECT_FALSE(with_nan.add(bad.data(), d.s[0]));
    feed(d, clean, 1.0);
    for (std::size_t k = 0; k < d.q.size(); ++k) {
        if (k > 0 && d.orbit[k] != d.orbit[k - 1]) {
            with_nan.close_orbit(1.0);
        }
        if (k == 50) {
            EXPECT_FALSE(with_nan.add(bad.data(), d.s[k]));
            EXPECT_FALSE(with_nan.add(d.q[k].data(), {std::nan(""), 0.0, 1.0}));
        }
        ASSERT_TRUE(with_nan.add(d.q[k].data(), d.s[k]));
    }
    with_nan.close_orbit(1.0);
    calib::SunTermFit a;
    calib::SunTermFit b;
    ASSERT_TRUE(clean.solve(calib::SunRule{}, a));
    ASSERT_TRUE(with_nan.solve(calib::SunRule{}, b));
    EXPECT_EQ(a.sun[2][1][0], b.sun[2][1][0]);
    EXPECT_EQ(a.epochs, b.epochs);
}

// Cycles outside the Sun ephemeris' span are not learnt from, and counted.
TEST(SunLearner, CyclesWhereTheSunIsNotKnownAreCountedNotLearnt) {
    calib::SunLearner learner{calib::EstimatorConfig{}};
    const Quaternion<double> q[calib::kFrameHeads] = {{1.0, 0.0, 0.0, 0.0}, {0.0, 1.0, 0.0, 0.0}, {0.0, 0.0, 1.0, 0.0}};
    const std::int64_t after_2051 = 1'620'000'000'000'000;  // TT µs since J2000: 2051-05
    EXPECT_FALSE(learner.take(after_2051, q));
    EXPECT_FALSE(learner.take(after_2051 + 1'000'000, q));
    Quaternion<double> bad[calib::kFrameHeads] = {q[0], q[1], q[2]};
    bad[2].w = std::nan("");
    EXPECT_FALSE(learner.take(600'000'000'000'000, bad));
    learner.finish();
    const calib::SunLearnReport r = learner.report();
    EXPECT_EQ(r.without_sun, 2U);
    EXPECT_EQ(r.not_finite, 1U);
    EXPECT_EQ(r.orbits, 0U);
    EXPECT_EQ(learner.taken(), nullptr);
}

// The learner's warm start (solve_step with its Solve kept from one solve
// to the next, as SunLearner keeps it): each fit the ground's cold solve()
// of the same sums to twice the decomposition's bound on either
// (symmetric_eigen.hpp: kJacobiTolerance/kSunRankTolerance·√27 relative),
// the same rank, in fewer steps; every kWarmSolves-th from the identity,
// with the cold one's bits.
TEST(SunMoments, AWarmStartSolvesAsTheColdOneInFewerSteps) {
    using Moments = calib::SunMoments<3>;
    constexpr std::size_t kOrbits = 70;
    static_assert(kOrbits > Moments::kWarmSolves, "a cold restart is in the run");
    const Synthetic d = synthetic(kOrbits, 40, 13);
    Moments m = three_heads();
    static Moments::Solve kept;  // 12 KiB
    static Moments::Solve fresh;
    const auto run = [&m](Moments::Solve& w) {
        int n = 0;
        calib::SunSolveStep r = calib::SunSolveStep::kRunning;
        for (; r == calib::SunSolveStep::kRunning && n < Moments::kMaxSolveSteps; ++n) {
            r = m.solve_step(w, calib::SunRule{});
        }
        EXPECT_EQ(r, calib::SunSolveStep::kSolved);
        return n;
    };
    long warm_steps = 0;
    long cold_steps = 0;
    double worst = 0.0;
    std::size_t k = 0;
    for (std::size_t o = 0; o < kOrbits; ++o) {
        for (; k < d.q.size() && d.orbit[k] == static_cast<int>(o); ++k) {
            ASSERT_TRUE(m.add(d.q[k].data(), d.s[k])) << k;
        }
        m.close_orbit(0.998);  // the on-board memory's forgetting: 30 days of 94-min orbits
        const int nw = run(kept);
        fresh = Moments::Solve{};
        const int nc = run(fresh);
        ASSERT_EQ(kept.fit.rank, fresh.fit.rank) << o;
        if (o % Moments::kWarmSolves == 0U) {  // from the identity: the cold solve's bits
            EXPECT_EQ(nw, nc) << o;
            EXPECT_EQ(std::memcmp(kept.fit.sun, fresh.fit.sun, sizeof kept.fit.sun), 0) << o;
            continue;
        }
        warm_steps += nw;
        cold_steps += nc;
        double largest = 0.0;
        double diff = 0.0;
        for (std::size_t h = 0; h < 3; ++h) {
            for (std::size_t a = 0; a < 3; ++a) {
                for (std::size_t c = 0; c < 3; ++c) {
                    largest = std::max(largest, std::fabs(fresh.fit.sun[h][a][c]));
                    diff = std::max(diff, std::fabs(kept.fit.sun[h][a][c] - fresh.fit.sun[h][a][c]));
                }
            }
        }
        ASSERT_GT(largest, 0.0) << o;
        worst = std::max(worst, diff / largest);
    }
    const double bound = 2.0 * calib::kJacobiTolerance / calib::kSunRankTolerance * std::sqrt(27.0);
    EXPECT_LT(worst, bound) << "the warm fit is the cold one to the decomposition's tolerance";
    // Steps are rows of sweeps (a warm sweep's rows skip most rotations:
    // fewer instructions still, target_bench.cpp); 44 % here, 100 % cold.
    EXPECT_LT(warm_steps * 10, cold_steps * 7) << warm_steps << " steps warm, " << cold_steps << " cold";
    RecordProperty("warm_steps", std::to_string(warm_steps));
    RecordProperty("cold_steps", std::to_string(cold_steps));
    std::ostringstream worst_text;
    worst_text << std::setprecision(3) << worst;
    RecordProperty("worst_relative_difference", worst_text.str());
}

TEST(SunMoments, NothingToSolveIsNoTerm) {
    const calib::SunMoments<3> moments = three_heads();
    calib::SunTermFit fit;
    EXPECT_FALSE(moments.solve(calib::SunRule{}, fit));
    EXPECT_FALSE(fit.solved);
    EXPECT_EQ(fit.heads, 0U);
}

TEST(SunLearner, TheRuleTakesOnlyBeyondTheMarginAndLeavesAlike) {
    const double m = calib::kSunLearnMargin;
    EXPECT_FALSE(calib::SunLearner::next_taken({1.0, 1.0 - 0.5 * m}, false));
    EXPECT_TRUE(calib::SunLearner::next_taken({1.0, 1.0 - 1.5 * m}, false));
    EXPECT_TRUE(calib::SunLearner::next_taken({1.0, 1.0 + 0.5 * m}, true)) << "kept within the margin";
    EXPECT_FALSE(calib::SunLearner::next_taken({1.0, 1.0 + 1.5 * m}, true));
}

// Three heads on a bench turning once per orbit (period_us), each with its
// own noise (rng), at t_us.
void turning_bench(std::int64_t t_us, std::int64_t period_us, std::mt19937_64& rng,
                   Quaternion<double> (&q)[calib::kFrameHeads]) {
    const Quaternion<double> mount[3] = {unit(Quaternion<double>{0.9, 0.1, -0.3, 0.2}),
                                         unit(Quaternion<double>{0.2, 0.8, 0.1, -0.4}),
                                         unit(Quaternion<double>{-0.3, 0.2, 0.9, 0.1})};
    std::normal_distribution<double> noise(0.0, 5e-6);
    const double phase = 2.0 * kPi * static_cast<double>(t_us % period_us) / static_cast<double>(period_us);
    const Quaternion<double> bench{std::cos(0.5 * phase), 0.0, std::sin(0.5 * phase), 0.0};
    for (std::size_t h = 0; h < calib::kFrameHeads; ++h) {
        q[h] = turned(mount[h] * bench, noise(rng), noise(rng), noise(rng));
    }
}

// TT µs since J2000 (2026): whole orbits of the default 5640 s, whole 120 s.
constexpr std::int64_t kLearnT0Us = 145'532 * calib::EstimatorConfig{}.orbit_period_us;
static_assert(kLearnT0Us % calib::kSunLearnOnBoardIntervalUs == 0);

// On board the solve runs in idle time, as much of it as there is, and the
// next cycle taken settles the rest (SunLearner::settle): whatever the steps
// in between, none to a whole solve's, the learner is the ground's (which
// solves at once after each cycle) bit for bit, cycle by cycle: candidate,
// scores, decision, and at the end of the data. Starved (0 to 40 steps per
// cycle taken, 47 cycles an orbit, some 290 steps a solve), settles run the
// rest, counted (late), none beyond a solve's steps. Mutation: a candidate
// put to use as its solve ends (not at the next take) fails the comparison.
TEST(SunLearner, IdleStepsOrNoneTheLearnerIsTheGroundsBitForBit) {
    const calib::EstimatorConfig cfg;
    calib::SunLearner ground{cfg};
    calib::SunLearner board{cfg};
    std::mt19937_64 rng(40);
    std::mt19937 idle_rng(7);
    std::uniform_int_distribution<int> idle(0, 40);
    const auto same = [](const calib::SunLearnReport& g, const calib::SunLearnReport& b) {
        return g.candidate.orbits == b.candidate.orbits && g.candidate.rank == b.candidate.rank &&
               g.candidate.solved == b.candidate.solved &&
               std::memcmp(g.candidate.sun, b.candidate.sun, sizeof g.candidate.sun) == 0 &&
               std::memcmp(g.score, b.score, sizeof g.score) == 0 && g.taken == b.taken && g.orbits == b.orbits;
    };
    int solved = 0;
    for (std::int64_t k = 0; k < 40 * 47; ++k) {
        const std::int64_t t_us = kLearnT0Us + k * calib::kSunLearnOnBoardIntervalUs;
        Quaternion<double> q[calib::kFrameHeads];
        turning_bench(t_us, cfg.orbit_period_us, rng, q);
        ASSERT_TRUE(ground.take(t_us, q));
        (void)ground.step_all();
        ASSERT_TRUE(board.take(t_us, q));
        for (int i = 0, n = idle(idle_rng); i < n && board.step(); ++i) {
        }
        ASSERT_TRUE(same(ground.report(), board.report())) << "cycle " << k;
        solved += board.report().candidate.solved ? 1 : 0;
    }
    EXPECT_GT(solved, 30 * 47);
    const calib::SunLearnReport b = board.report();
    EXPECT_GT(b.late, 10U) << "idle time was starved";
    EXPECT_GT(b.late_steps, 100) << "a settle ran most of a solve";
    EXPECT_LE(b.late_steps, calib::SunLearner::kMaxSolveSteps);
    EXPECT_EQ(ground.report().late, 0U);
    board.finish();
    ground.finish();
    EXPECT_TRUE(same(ground.report(), board.report()));
}

// Fed at 10 s, the learner with the DPU's interval takes the first cycle of
// each 120 s and nothing of the others: the same report, bit for bit, as a
// learner without one fed those alone. The orbit (5650 s) is not a whole
// number of intervals, so that a cycle thinned can be an orbit's first (it
// must not close the orbit: the next taken does).
TEST(SunLearner, TakesTheFirstCycleOfEachIntervalAsAThinnedFeedWould) {
    calib::EstimatorConfig cfg;
    cfg.orbit_period_us = 5'650'000'000;
    calib::SunLearner gated{cfg, calib::kSunLearnOnBoardIntervalUs};
    calib::SunLearner fed_firsts{cfg};  // no interval: every cycle it is given
    std::mt19937_64 rng(41);
    constexpr std::int64_t kCycleUs = 10'000'000;
    constexpr std::int64_t kStartUs = kLearnT0Us + 60'000'000;
    const std::int64_t cycles = 6 * cfg.orbit_period_us / kCycleUs;
    std::uint64_t firsts = 0;
    int orbits_begun_thinned = 0;  // orbits whose first cycle is thinned
    for (std::int64_t k = 0; k < cycles; ++k) {
        const std::int64_t t_us = kStartUs + k * kCycleUs;
        Quaternion<double> q[calib::kFrameHeads];
        turning_bench(t_us, cfg.orbit_period_us, rng, q);
        const bool first = k == 0 || t_us % calib::kSunLearnOnBoardIntervalUs == 0;
        firsts += first ? 1U : 0U;
        orbits_begun_thinned += !first && t_us % cfg.orbit_period_us < kCycleUs ? 1 : 0;
        EXPECT_EQ(gated.take(t_us, q), first) << k;
        (void)gated.step_all();
        if (first) {
            ASSERT_TRUE(fed_firsts.take(t_us, q));
            (void)fed_firsts.step_all();
        }
    }
    gated.finish();
    fed_firsts.finish();
    const calib::SunLearnReport a = gated.report();
    const calib::SunLearnReport b = fed_firsts.report();
    EXPECT_GT(orbits_begun_thinned, 0);
    EXPECT_EQ(a.thinned, static_cast<std::uint64_t>(cycles) - firsts);
    EXPECT_EQ(b.thinned, 0U);
    EXPECT_GT(a.cycles, firsts / 2U);
    EXPECT_EQ(a.cycles, b.cycles);
    EXPECT_GE(a.orbits, 4U);
    EXPECT_EQ(a.orbits, b.orbits);
    EXPECT_EQ(std::memcmp(a.score, b.score, sizeof a.score), 0);
    ASSERT_TRUE(a.candidate.solved);
    EXPECT_EQ(a.candidate.epochs, b.candidate.epochs);
    EXPECT_EQ(std::memcmp(a.candidate.sun, b.candidate.sun, sizeof a.candidate.sun), 0);
}

// The gate by itself: intervals floor(t / 120 s) for times of either sign,
// one cycle each; a time that goes back takes again, and one that jumps far
// ahead stops nothing after it comes back.
TEST(SunLearner, TheThinningTakesOncePerIntervalAndRecoversFromAJump) {
    calib::SunLearnThinning every;  // the ground's: no interval
    for (std::int64_t t : {std::int64_t{0}, std::int64_t{1}, std::int64_t{-5}}) {
        EXPECT_TRUE(every.due(t));
        every.mark(t);
    }
    EXPECT_EQ(every.thinned(), 0U);
    calib::SunLearnThinning gate{calib::kSunLearnOnBoardIntervalUs};
    constexpr std::int64_t kI = calib::kSunLearnOnBoardIntervalUs;
    EXPECT_TRUE(gate.due(-kI - 1));  // interval −2
    gate.mark(-kI - 1);
    EXPECT_FALSE(gate.due(-2 * kI));  // interval −2's first µs
    EXPECT_TRUE(gate.due(-1));        // interval −1
    gate.mark(-1);
    EXPECT_FALSE(gate.due(-kI));
    EXPECT_TRUE(gate.due(-kI - 1)) << "back to interval −2: taken again";
    gate.mark(-kI - 1);
    EXPECT_TRUE(gate.due(20 * 365 * 86'400'000'000LL)) << "a jump 20 years ahead";
    gate.mark(20 * 365 * 86'400'000'000LL);
    EXPECT_TRUE(gate.due(0)) << "and back: the learner goes on";
    gate.mark(0);
    EXPECT_FALSE(gate.due(kI - 1));
    EXPECT_TRUE(gate.due(kI));
    EXPECT_EQ(gate.thinned(), 3U);
}

// A refused cycle (no Sun) takes its interval: the bound holds whatever the
// input, and the next interval is taken.
TEST(SunLearner, ARefusedCycleTakesItsIntervalToo) {
    calib::SunLearner gated{calib::EstimatorConfig{}, calib::kSunLearnOnBoardIntervalUs};
    Quaternion<double> q[calib::kFrameHeads] = {{1.0, 0.0, 0.0, 0.0}, {0.0, 1.0, 0.0, 0.0}, {0.0, 0.0, 1.0, 0.0}};
    q[1].w = std::nan("");
    EXPECT_FALSE(gated.take(kLearnT0Us, q));
    EXPECT_FALSE(gated.take(kLearnT0Us + 10'000'000, q));
    EXPECT_FALSE(gated.take(kLearnT0Us + calib::kSunLearnOnBoardIntervalUs, q));
    const calib::SunLearnReport r = gated.report();
    EXPECT_EQ(r.not_finite, 2U);
    EXPECT_EQ(r.thinned, 1U);
}

// The ground learns at every epoch the estimator learns from (the contract:
// docs/contract.md, "The Sun term learnt in self-calibration"): on a mission
// with an epoch every 30 s it takes more cycles than one per 120 s over the
// whole mission could give, and thins none.
TEST(SunLearnt, TheGroundsLearnerTakesEveryEpochAsTheContractSays) {
    const fs::path file = simulated_mission("sun-every-epoch", "--days 6 --step 30 --seed 12") / "m.csv";
    const std::string text = host::read_text_file(file.string());
    host::SolutionsReader reader(file.string(), text);
    std::vector<host::SolutionRecord> rows;
    for (host::SolutionRecord r; reader.next(r);) {
        rows.push_back(r);
    }
    ASSERT_GT(rows.size(), 1U);
    const host::RowSource source = [&rows](const std::function<void(const host::SolutionRecord&)>& fn) {
        for (const host::SolutionRecord& r : rows) {
            fn(r);
        }
    };
    const host::SelfCalibration sc =
        host::self_calibrate<double>(file.string(), source, std::nullopt, calib::EstimatorConfig{}, std::nullopt,
                                     host::kSelfCalibrationMemoryBytes, kMaxHeads, {}, false, true);
    ASSERT_TRUE(sc.sun_learnt.has_value());
    EXPECT_EQ(sc.sun_learnt->thinned, 0U);
    const double span_s = rows.back().t - rows.front().t;
    EXPECT_GT(static_cast<double>(sc.sun_learnt->cycles), span_s / 120.0);
}

// ---- correct --self-calibrate --sun-term auto on missions the code did not make

constexpr double kBound = 0.2;      // arcsec per pair from day 60, issue 40's for self-calibration
constexpr double kFromDays = 60.0;  // issue 40's "from day 60 on"

// 150 days whose bench lags by 900 s and turns with the Sun along the velocity
// (0.8″ × ŝ·v̂ about a fixed axis per head), an epoch every 240 s, seed 40.
const fs::path& orbit_mission() {
    static const fs::path dir =
        simulated_mission("sun-learnt", "--days 150 --step 240 --seed 40 --bench-lag 900 --orbit-term 0.8");
    return dir;
}

TEST(SunLearnt, SelfCalibrationLearnsTheSunTermFromNoModelAndMeetsTheBound) {
    const fs::path& dir = orbit_mission();
    const double from = mission_day(dir, kFromDays);
    // Mutation: the same run without the learner (the lag learnt alone) fails the bound.
    ASSERT_EQ(self_calibrate_mission(dir, "--lag auto", "sc_lag.csv").exit_code, 0);
    const std::array<double, 3> without = systematic_from(dir, "sc_lag.csv", from);
    EXPECT_GT(*std::max_element(without.begin(), without.end()), kBound) << "without the Sun term the bound must fail";
    for (const char* scalar : {"float", "fixed"}) {  // the targets' scalars: the same bound
        const std::string out = std::string("sc_sun_") + scalar + ".csv";
        ASSERT_EQ(
            self_calibrate_mission(dir, std::string("--lag auto --sun-term auto --scalar ") + scalar, out).exit_code,
            0);
        const std::array<double, 3> r = systematic_from(dir, out, from);
        for (std::size_t p = 0; p < 3; ++p) {
            EXPECT_LE(r[p], kBound) << scalar << " pair " << p;
            RecordProperty(std::string("learnt_sun_") + scalar + "_" + std::to_string(p), std::to_string(r[p]));
        }
    }
    const CliRun r = self_calibrate_mission(dir, "--lag auto --sun-term auto", "sc_sun.csv");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_TRUE(has(r.err, "; Sun term (--sun-term auto): the learner scored ")) << r.err;
    EXPECT_TRUE(has(r.err,
                    "; it takes the term (taken 0.3 % below, left 0.3 % above); the models took it from "
                    "version "))
        << r.err;
    const std::array<double, 3> with = systematic_from(dir, "sc_sun.csv", from);
    for (std::size_t p = 0; p < 3; ++p) {
        EXPECT_LE(with[p], kBound) << "pair " << p;
        RecordProperty("learnt_sun_" + std::to_string(p), std::to_string(with[p]));
    }
    // The history: the Sun term's columns, none before the learner took it, then a term.
    const std::vector<std::string> h = lines_of_file(dir / "sc_sun.csv.history.csv");
    ASSERT_GT(h.size(), 2U);
    EXPECT_EQ(h[0].substr(h[0].size() - 24), ",lag_s,sun_x,sun_y,sun_z") << h[0];
    EXPECT_NE(h[1].find(",0.0000000000000000e+00,0.0000000000000000e+00,0.0000000000000000e+00"), std::string::npos)
        << h[1];
    EXPECT_EQ(h.back().find(",0.0000000000000000e+00,0.0000000000000000e+00,0.0000000000000000e+00"), std::string::npos)
        << h.back();
}

TEST(SunLearnt, AStaticBenchIsByteForByteAsWithoutIt) {
    const auto [none, with] = expect_static_bench_unchanged_by("--sun-term auto");
    EXPECT_TRUE(has(with.err, "; it does not take the term (")) << with.err;
    EXPECT_TRUE(has(with.err, "; no model took it")) << with.err;
    EXPECT_FALSE(has(none.err, "Sun term")) << "the learner runs only with --sun-term auto";
}

TEST(SunLearnt, WhatCannotLearnItIsRefused) {
    const fs::path& dir = static_mission();
    const std::pair<std::string, std::string> cases[] = {
        {"correct --in m.csv --sun-term auto --out c.csv", "--sun-term: needs --self-calibrate"},
        {"correct --in m.csv --model start.csv --self-calibrate --sun-term auto --out c.csv",
         "start.csv: the model has a Sun term (its sun_x, sun_y, sun_z): the self-calibration learns a Sun term "
         "from none (--sun-term auto), not from a given one"},
        {"correct --in m.csv --self-calibrate --sun-term sometimes --out c.csv", "--sun-term"},
    };
    host::ModelFile start;
    start.present = {true, true, true, false};
    start.sun[1][2][0] = 1.5;
    host::write_model_file((dir / "start.csv").string(), start);
    for (const auto& [args, part] : cases) {
        const CliRun r = run_in(args, dir);
        EXPECT_NE(r.exit_code, 0) << args;
        EXPECT_TRUE(has(r.err, part)) << args << ": " << r.err;
        EXPECT_FALSE(fs::exists(dir / "c.csv")) << args;
    }
}

// ---- replay --self-calibrate --sun-term auto: the learner on the link

// A bench that turns with the Sun by 0.8″, without a lag (a lag's steps in
// the target's scalar are not `correct`'s double ones, so the models would
// differ in their last bits), over 60 days (seed 41), replayed on the
// in-process targets of both flight scalars (float: the M4F's; Q30: the
// M3's): the target learns the term beside its estimator, bit for bit as
// the host's run thinned alike; with epochs 240 s apart its thinning (one
// per 120 s) takes every epoch, so its history is `correct --sun-term auto`'s
// in its scalar byte for byte, and its file within the replay tests' float
// bound (0.05″). Mutation: correct's file without the term is more than ten
// bounds away, so the target applies it.
TEST(SunLearntOnLink, TheTargetLearnsTheTermAsTheHostAndCorrectsWithIt) {
    const fs::path dir = simulated_mission("sun-on-link", "--days 60 --step 240 --seed 41 --orbit-term 0.8");
    const std::pair<const char*, const char*> targets[] = {{host::kLoopbackFloat, "float"},
                                                           {host::kLoopbackFixed, "fixed"}};
    for (const auto& [target, scalar] : targets) {
        const std::string c = std::string("c_") + scalar + ".csv";
        const std::string c0 = std::string("c0_") + scalar + ".csv";
        ASSERT_EQ(self_calibrate_mission(dir, std::string("--sun-term auto --scalar ") + scalar, c).exit_code, 0);
        ASSERT_EQ(self_calibrate_mission(dir, std::string("--scalar ") + scalar, c0).exit_code, 0);
        host::ReplayOptions o;
        o.target = target;
        o.in = (dir / "m.csv").string();
        o.out = (dir / "r.csv").string();
        o.model_history = (dir / "r.history.csv").string();
        o.self_calibrate = true;
        o.sun_auto = true;
        std::ostringstream log;
        const host::ReplaySummary s = host::replay(o, log);
        EXPECT_EQ(s.returned, s.frames) << target;
        EXPECT_EQ(s.mismatches, 0U) << target << log.str();
        EXPECT_EQ(s.version_mismatches, 0U) << target << log.str();
        EXPECT_EQ(s.history_mismatches, 0U) << target << log.str();
        EXPECT_TRUE(s.report_matches) << target << log.str();
        // The target's learner, read over the link (SUN_LEARNER_REPORT) and
        // compared above with the host's at its last epoch: the account of
        // the target describes it.
        const std::string text = log.str();
        const std::size_t on_target = text.find("ascorr replay: on the target, ");
        ASSERT_NE(on_target, std::string::npos) << text;
        EXPECT_NE(text.substr(on_target, text.find('\n', on_target) - on_target).find("the learner scored "),
                  std::string::npos)
            << text;
        EXPECT_LE(s.max_error_arcsec, 0.05) << target;
        // The target's history: its models took a term, as correct's did.
        const std::vector<std::string> h = lines_of_file(dir / "r.history.csv");
        ASSERT_GT(h.size(), 2U);
        EXPECT_EQ(h[0].substr(h[0].size() - 18), ",sun_x,sun_y,sun_z") << h[0];
        EXPECT_EQ(h.back().find(",0.0000000000000000e+00,0.0000000000000000e+00,0.0000000000000000e+00"),
                  std::string::npos)
            << h.back();
        EXPECT_EQ(slurp(dir / "r.history.csv"), slurp(dir / (c + ".history.csv"))) << target;
        const double against_correct = largest_difference(dir / "r.csv", dir / c);
        EXPECT_LE(against_correct, 0.05) << target;
        const double term = largest_difference(dir / c, dir / c0);
        EXPECT_GT(term, 10 * 0.05) << target;
        RecordProperty(std::string("replayed_against_correct_arcsec_") + scalar, std::to_string(against_correct));
        RecordProperty(std::string("term_arcsec_") + scalar, std::to_string(term));
        std::cout << target << " replayed against correct: " << against_correct
                  << " arcsec (the term moves rows by up to " << term << "); " << host::to_json(s) << "\n";
    }
}

}  // namespace
}  // namespace ascorr::test
