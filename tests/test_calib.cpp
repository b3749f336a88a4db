// The calibration maths (firmware/include/ascorr/calib/) against independent
// references: F (eqs. 1–3) against the ground fit's former Eigen code, the
// square-root information filter against a batch weighted least squares and
// an SVD, the common-rotation projector's properties, the model CRC's bytes,
// and the per-cycle orbit sums in float and Q30 against double.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>

#include "ascorr/calib/common_rotation.hpp"
#include "ascorr/calib/estimator.hpp"
#include "ascorr/calib/frame.hpp"
#include "ascorr/calib/model_identity.hpp"
#include "ascorr/calib/orbit_sums.hpp"
#include "ascorr/calib/square_root_information.hpp"
#include "ascorr/core/fixed_point.hpp"
#include "test_support.hpp"

namespace ascorr::test {
namespace {

// The ground fit's F before the calib headers (host fit.cpp, Eigen).
Eigen::Quaterniond eigen_q_f_icrf(const Eigen::Quaterniond& qa, const Eigen::Quaterniond& qc) {
    const Eigen::Vector3d za = qa.toRotationMatrix().row(2).transpose();
    const Eigen::Vector3d zc = qc.toRotationMatrix().row(2).transpose();
    const Eigen::Vector3d z_f = za.cross(zc).normalized();
    const Eigen::Vector3d x_f = (za + zc).normalized();
    const Eigen::Vector3d y_f = z_f.cross(x_f).normalized();
    Eigen::Matrix3d r;
    r.row(0) = x_f.transpose();
    r.row(1) = y_f.transpose();
    r.row(2) = z_f.transpose();
    return Eigen::Quaterniond(r);
}

TEST(CalibFrame, SameBitsAsTheFitsEigenCode) {
    std::mt19937_64 rng(7);
    for (int i = 0; i < 20000; ++i) {
        const Eigen::Quaterniond qa = random_attitude(rng);
        const Eigen::Quaterniond qc = random_attitude(rng);
        const Eigen::Quaterniond ref = eigen_q_f_icrf(qa, qc);
        const Quaternion<double> q = calib::q_f_icrf(from_eigen(qa), from_eigen(qc));
        ASSERT_EQ(q.w, ref.w()) << i;
        ASSERT_EQ(q.x, ref.x()) << i;
        ASSERT_EQ(q.y, ref.y()) << i;
        ASSERT_EQ(q.z, ref.z()) << i;
    }
}

// The ground fit formed q_head_f = q_head_icrf ⊗ q_f_icrf⁻¹ and its re-basing
// with Eigen's quaternion product; calib's double product groups its terms
// the same way, so the fit keeps its bits (on x86-64, where Eigen vectorises
// the product with SSE2; elsewhere they agree to rounding).
TEST(CalibHeadRotation, SameBitsAsEigensProduct) {
    std::mt19937_64 rng(12);
    for (int i = 0; i < 20000; ++i) {
        const Eigen::Quaterniond a = random_attitude(rng);
        const Eigen::Quaterniond b = random_attitude(rng);
        Eigen::Quaterniond ref = a * b.conjugate();
        const Quaternion<double> got = calib::q_head_f(from_eigen(a), from_eigen(b));
#ifdef EIGEN_VECTORIZE_SSE2
        ASSERT_EQ(got.w, ref.w()) << i;
        ASSERT_EQ(got.x, ref.x()) << i;
        ASSERT_EQ(got.y, ref.y()) << i;
        ASSERT_EQ(got.z, ref.z()) << i;
#else
        ASSERT_LT(angle_arcsec(to_eigen(got), ref), 1e-9) << i;
#endif
        if (ref.w() < 0.0) {
            ref.coeffs() = -ref.coeffs();
        }
        const Quaternion<double> rel = calib::relative_to(from_eigen(a), from_eigen(b));
        EXPECT_GE(rel.w, 0.0);
        ASSERT_LT(angle_arcsec(to_eigen(rel), ref), 1e-9) << i;
    }
}

// The IBA's atan2 with + − × ÷ alone (portable_math.hpp's atan2_upper, the
// same bits on the DPU as here) against the C library's atan2 in long
// double, over the upper half-plane's angles and lengths: within 2⁻⁵⁰ rad
// (2e-10″). Its bits are pinned at two points (a reordered polynomial or a
// fused multiply-add would move them, and the DPU's with them), and its
// edges are as its comment says.
TEST(CalibPortableMath, Atan2UpperIsWithinItsBoundOfLongDouble) {
    using calib::atan2_upper;
    std::mt19937_64 rng(40);
    std::uniform_real_distribution<double> angle(0.0, 3.14159265358979323846);
    std::uniform_real_distribution<double> decade(-30.0, 30.0);
    double worst = 0.0;
    for (int i = 0; i < 200000; ++i) {
        const double r = std::pow(10.0, decade(rng));
        const double y = std::fabs(r * std::sin(angle(rng)));
        const double x = r * std::cos(angle(rng) * (i % 2 == 0 ? 1.0 : 0.5));
        const long double ref = std::atan2(static_cast<long double>(y), static_cast<long double>(x));
        const auto err = static_cast<double>(std::fabs(static_cast<long double>(atan2_upper(y, x)) - ref));
        worst = err <= worst ? worst : err;
    }
    EXPECT_LT(worst, 0x1p-50);
    EXPECT_EQ(atan2_upper(0.6309296214223089, -0.7758400690940769), 0x1.3abb5418d3e35p+1);
    EXPECT_EQ(atan2_upper(0.3, 0.9), 0x1.4978fa3269ee1p-2);
    EXPECT_EQ(atan2_upper(0.0, 1.0), 0.0);
    EXPECT_EQ(atan2_upper(0.0, 0.0), 0.0);
    EXPECT_EQ(atan2_upper(0.0, -0.0), 0.0);
    EXPECT_EQ(atan2_upper(1.0, 0.0), std::atan2(1.0, 0.0));
    EXPECT_EQ(atan2_upper(0.0, -1.0), std::atan2(0.0, -1.0));
    EXPECT_EQ(atan2_upper(-0.0, -1.0), std::atan2(0.0, -1.0));
    EXPECT_NEAR(atan2_upper(1.0, 1.0), std::atan2(1.0, 1.0), 0x1p-52);
    const double inf = std::numeric_limits<double>::infinity();
    EXPECT_EQ(atan2_upper(inf, 1.0), std::atan2(inf, 1.0));
    EXPECT_TRUE(std::isnan(atan2_upper(inf, inf)));
    EXPECT_TRUE(std::isnan(atan2_upper(-1.0, 1.0)));
    EXPECT_TRUE(std::isnan(atan2_upper(std::nan(""), 1.0)));
    EXPECT_TRUE(std::isnan(atan2_upper(1.0, std::nan(""))));
    EXPECT_TRUE(std::isnan(calib::atan_unit(1.5)));
}

// F relative to A from C relative to A is F_icrf ⊗ A_icrf⁻¹ (frame.hpp q_f_a).
TEST(CalibFrame, FRelativeToHeadAIsTheSameFrame) {
    std::mt19937_64 rng(8);
    for (int i = 0; i < 2000; ++i) {
        const Eigen::Quaterniond qa = random_attitude(rng);
        const Eigen::Quaterniond qc = random_attitude(rng);
        const double cos_ac = (qa.toRotationMatrix().row(2)).dot(qc.toRotationMatrix().row(2));
        if (std::fabs(cos_ac) > 0.9) {
            continue;  // the heads are 60-120 degrees apart; near-parallel boresights amplify rounding
        }
        const Eigen::Quaterniond f_icrf = eigen_q_f_icrf(qa, qc);
        const Eigen::Quaterniond expect = f_icrf * qa.conjugate();
        const Quaternion<double> got = calib::q_f_a(from_eigen(qc * qa.conjugate()));
        EXPECT_LT(angle_arcsec(to_eigen(got), expect), 1e-8) << i;
    }
}

TEST(CalibCommonRotation, ProjectorRemovesExactlyACommonRotation) {
    std::mt19937_64 rng(9);
    calib::Matrix3 n[3];
    for (auto& m : n) {
        m = calib::rotation_matrix(from_eigen(random_attitude(rng)));
    }
    std::normal_distribution<double> g;
    const double w[3] = {g(rng), g(rng), g(rng)};
    double y[9];
    double common[9];
    for (std::size_t h = 0; h < 3; ++h) {
        for (std::size_t r = 0; r < 3; ++r) {
            common[3 * h + r] = n[h].m[r][0] * w[0] + n[h].m[r][1] * w[1] + n[h].m[r][2] * w[2];
            y[3 * h + r] = common[3 * h + r];
        }
    }
    calib::remove_common_rotation(n, y);
    for (double v : y) {
        EXPECT_NEAR(v, 0.0, 1e-14);
    }
    // Idempotent and symmetric (an orthogonal projector), rank 6.
    double p[9][9];
    calib::common_rotation_projector(n, p);
    Eigen::Matrix<double, 9, 9> pm;
    for (int i = 0; i < 9; ++i) {
        for (int j = 0; j < 9; ++j) {
            pm(i, j) = p[i][j];
        }
    }
    EXPECT_LT((pm * pm - pm).cwiseAbs().maxCoeff(), 1e-14);
    EXPECT_LT((pm - pm.transpose()).cwiseAbs().maxCoeff(), 1e-15);
    EXPECT_NEAR(pm.trace(), 6.0, 1e-13);
}

TEST(CalibSquareRootInformation, EqualsBatchWeightedLeastSquaresWithForgetting) {
    std::mt19937_64 rng(10);
    std::normal_distribution<double> g;
    calib::SquareRootInformation<4, 3> f;
    const int n = 400;
    const double lambda = std::exp(-1.0 / 60.0);
    Eigen::MatrixXd a(n, 4);
    Eigen::MatrixXd y(n, 3);
    Eigen::VectorXd w(n);
    for (int k = 0; k < n; ++k) {
        const double row[4] = {1.0, 5.0 * g(rng), 2.0 * g(rng), 0.5 * g(rng)};
        const double obs[3] = {g(rng) + 3.0 * row[1], g(rng) - row[2], 0.1 * g(rng) + row[3]};
        if (k > 0) {
            f.forget(lambda);
        }
        f.add(row, obs, 1.0);
        for (int j = 0; j < 4; ++j) {
            a(k, j) = row[j];
        }
        for (int j = 0; j < 3; ++j) {
            y(k, j) = obs[j];
        }
        w(k) = std::pow(lambda, n - 1 - k);
    }
    const Eigen::MatrixXd sw = w.cwiseSqrt().asDiagonal() * a;
    const Eigen::MatrixXd ref = sw.colPivHouseholderQr().solve(w.cwiseSqrt().asDiagonal() * y);
    double x[4][3];
    ASSERT_TRUE(f.solve(x));
    for (int j = 0; j < 4; ++j) {
        for (int m = 0; m < 3; ++m) {
            EXPECT_NEAR(x[j][m], ref(j, m), 1e-12 * (1.0 + std::fabs(ref(j, m))));
        }
    }
    // The equilibrated information matrix's condition number, by SVD.
    Eigen::MatrixXd info = sw.transpose() * sw;
    const Eigen::VectorXd d = info.diagonal().cwiseSqrt().cwiseInverse();
    info = d.asDiagonal() * info * d.asDiagonal();
    const Eigen::VectorXd ev = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(info).eigenvalues();
    EXPECT_NEAR(f.condition(), ev.maxCoeff() / ev.minCoeff(), 1e-9 * ev.maxCoeff() / ev.minCoeff());
}

TEST(CalibSquareRootInformation, ASingularProblemIsRefusedNotSolved) {
    calib::SquareRootInformation<4, 3> f;
    for (int k = 0; k < 10; ++k) {
        const double row[4] = {1.0, 2.0, 2.0, 0.0};  // columns 2 and 3 equal, column 4 empty
        const double obs[3] = {1.0, 2.0, 3.0};
        f.add(row, obs, 1.0);
    }
    double x[4][3];
    EXPECT_FALSE(f.solve(x));
    EXPECT_FALSE(std::isfinite(f.condition()));
}

TEST(CalibModelIdentity, CrcOfTheDocumentedByteStream) {
    ModelCoefficients m{};
    m.present[0] = true;
    m.coefficient[0][0][1] = 1.0;  // 0x3FF0000000000000
    std::vector<std::uint8_t> bytes = {1, 0, 0, 0};
    for (std::size_t i = 0; i < std::size_t{kMaxHeads} * kModelAxes * kModelTerms; ++i) {
        const std::uint64_t bits = i == 1 ? 0x3FF0000000000000ULL : 0ULL;
        for (int b = 0; b < 8; ++b) {
            bytes.push_back(static_cast<std::uint8_t>(bits >> (8 * b)));
        }
    }
    EXPECT_EQ(calib::model_crc(m), crc32c(bytes.data(), bytes.size()));
    ModelCoefficients other = m;
    other.coefficient[2][1][3] = 1e-300;
    EXPECT_NE(calib::model_crc(m), calib::model_crc(other));
}

// The per-cycle sums in float and Q30 give the double orbit means within
// their formats' resolution (orbit_sums.hpp): for the rotations, Q30's
// products round to 2^-31 (1e-4"); float's to 2^-24 relative per product
// (0.012" each, 0.005" allowed for the mean of 5000).
template <typename T>
void expect_sums_close_to_double(double tol_arcsec) {
    std::mt19937_64 rng(11);
    std::normal_distribution<double> g;
    const Eigen::Quaterniond qa0 = random_attitude(rng);
    const Eigen::Quaterniond b_a(Eigen::AngleAxisd(1.2, Eigen::Vector3d(0.3, 0.5, 0.8).normalized()));
    const Eigen::Quaterniond c_a(Eigen::AngleAxisd(1.9, Eigen::Vector3d(-0.6, 0.2, 0.7).normalized()));
    calib::OrbitReference<double> rd{};
    calib::OrbitReference<T> rt{};
    rd.r[0] = from_eigen(b_a);
    rd.r[1] = from_eigen(c_a);
    rt.r[0] = {ScalarTraits<T>::from_double(b_a.w()), ScalarTraits<T>::from_double(b_a.x()),
               ScalarTraits<T>::from_double(b_a.y()), ScalarTraits<T>::from_double(b_a.z())};
    rt.r[1] = {ScalarTraits<T>::from_double(c_a.w()), ScalarTraits<T>::from_double(c_a.x()),
               ScalarTraits<T>::from_double(c_a.y()), ScalarTraits<T>::from_double(c_a.z())};
    for (std::size_t h = 0; h < 3; ++h) {
        for (std::size_t j = 0; j < 3; ++j) {
            rd.t_ref[h][j] = 10.0 + static_cast<double>(h + j);
            rt.t_ref[h][j] = ScalarTraits<T>::celsius(rd.t_ref[h][j]);
        }
    }
    calib::OrbitSums<double> sd;
    calib::OrbitSums<T> st;
    for (int k = 0; k < 5000; ++k) {
        const double s = 5e-6;  // rad: arcsecond-level motion of each head
        const Eigen::Quaterniond qa = qa0 * Eigen::Quaterniond(1.0, s * g(rng), s * g(rng), s * g(rng)).normalized();
        const Eigen::Quaterniond jitter_b(1.0, s * g(rng), s * g(rng), s * g(rng));
        const Eigen::Quaterniond jitter_c(1.0, s * g(rng), s * g(rng), s * g(rng));
        const Eigen::Quaterniond qs[3] = {qa, (jitter_b.normalized() * b_a * qa).normalized(),
                                          (jitter_c.normalized() * c_a * qa).normalized()};
        Quaternion<double> q_d[3];
        Quaternion<T> q_t[3];
        HeadTemperatures<double> t_d[3];
        HeadTemperatures<T> t_t[3];
        for (std::size_t h = 0; h < 3; ++h) {
            q_d[h] = from_eigen(qs[h]);
            q_t[h] = {ScalarTraits<T>::from_double(q_d[h].w), ScalarTraits<T>::from_double(q_d[h].x),
                      ScalarTraits<T>::from_double(q_d[h].y), ScalarTraits<T>::from_double(q_d[h].z)};
            const double temps[3] = {12.0 + 3.0 * g(rng), 11.0 + g(rng), 14.0 + g(rng)};
            // The double path sees the T-rounded values: only the sums differ.
            const Quaternion<double> back{ScalarTraits<T>::to_double(q_t[h].w), ScalarTraits<T>::to_double(q_t[h].x),
                                          ScalarTraits<T>::to_double(q_t[h].y), ScalarTraits<T>::to_double(q_t[h].z)};
            q_d[h] = back;
            t_t[h] = {{ScalarTraits<T>::celsius(temps[0]), true},
                      {ScalarTraits<T>::celsius(temps[1]), true},
                      {ScalarTraits<T>::celsius(temps[2]), true}};
            t_d[h] = {{ScalarTraits<T>::to_double(t_t[h].t_chu.value), true},
                      {ScalarTraits<T>::to_double(t_t[h].t_029.value), true},
                      {ScalarTraits<T>::to_double(t_t[h].t_032.value), true}};
        }
        sd.add(q_d, t_d, rd);
        st.add(q_t, t_t, rt);
    }
    st.flush();
    const double n = 5000.0;
    for (std::size_t k = 0; k < 2; ++k) {
        for (std::size_t c = 0; c < 4; ++c) {
            EXPECT_NEAR(st.dq[k][c].value() / n, sd.dq[k][c].value() / n, tol_arcsec * kArcsecToRad) << k << c;
        }
    }
    for (std::size_t h = 0; h < 3; ++h) {
        for (std::size_t j = 0; j < 3; ++j) {
            EXPECT_NEAR(st.dt[h][j].value() / n, sd.dt[h][j].value() / n, 1e-5) << h << j;
        }
    }
}

TEST(CalibOrbitSums, FloatMatchesDouble) {
    expect_sums_close_to_double<float>(5e-3);
}
TEST(CalibOrbitSums, FixedPointMatchesDouble) {
    expect_sums_close_to_double<Q30>(2e-4);
}

// A synthetic bench (not the simulator's): head B turns about its x axis by
// 0.3"/degC of its T_CHU, with three temperatures on incommensurate slow
// periods, one cycle every 300 s.
calib::CalibCycle<double> synthetic_cycle(long k) {
    const double t = 300.0 * static_cast<double>(k);
    const double day = 86400.0;
    const double t1 = 10.0 + 4.0 * std::sin(2.0 * kPi * t / (3.0 * day));
    const double t2 = 5.0 + 3.0 * std::sin(2.0 * kPi * t / (5.0 * day) + 1.0);
    const double t3 = 2.0 * std::sin(2.0 * kPi * t / (7.0 * day) + 2.0);
    const Eigen::Quaterniond qa = Eigen::Quaterniond(Eigen::AngleAxisd(1e-3 * t, Eigen::Vector3d::UnitZ())) *
                                  Eigen::Quaterniond(0.5, 0.5, 0.5, 0.5);
    const Eigen::Quaterniond b_a(Eigen::AngleAxisd(1.3, Eigen::Vector3d(0.2, 0.9, 0.1).normalized()));
    const Eigen::Quaterniond c_a(Eigen::AngleAxisd(1.7, Eigen::Vector3d(-0.7, 0.1, 0.6).normalized()));
    const double bend = 0.3 * (t1 - 10.0) * kArcsecToRad;
    const Eigen::Quaterniond qb = Eigen::Quaterniond(Eigen::AngleAxisd(bend, Eigen::Vector3d::UnitX())) * b_a * qa;
    calib::CalibCycle<double> c{};
    c.t_us = static_cast<std::int64_t>(t * 1e6);
    c.q_chu_icrf[0] = from_eigen(qa);
    c.q_chu_icrf[1] = from_eigen(qb.normalized());
    c.q_chu_icrf[2] = from_eigen((c_a * qa).normalized());
    for (auto& h : c.temperatures) {
        h = {{t1, true}, {t2, true}, {t3, true}};
    }
    return c;
}

// The orbit collector (orbit_collector.hpp): orbits are bins floor(t / P)
// with [start, end) bounds, negative times included; the first orbit's
// references are its first cycle, a later one's those set by
// set_next_reference (once), else the ones before; dropping an orbit keeps
// them. orbit_means() of n equal cycles is that cycle's d_h and temperatures.
TEST(CalibOrbitCollector, BinsReferencesAndMeans) {
    constexpr std::int64_t kP = 5'000'000;  // 5 s orbits
    calib::OrbitCollector<double> col(kP);
    calib::CalibCycle<double> c = synthetic_cycle(3);
    EXPECT_TRUE(col.starts_orbit(c.t_us));
    c.t_us = -1;  // bin -1: [-P, 0)
    col.open(c);
    EXPECT_TRUE(col.is_open());
    EXPECT_FALSE(col.starts_orbit(-kP));
    EXPECT_FALSE(col.starts_orbit(-1));
    EXPECT_TRUE(col.starts_orbit(0));
    EXPECT_TRUE(col.starts_orbit(-kP - 1));
    for (int k = 0; k < 4; ++k) {
        col.add(c);
    }
    calib::ClosedOrbit<double> o;
    col.close(o);
    EXPECT_FALSE(col.is_open());
    EXPECT_EQ(o.bin, -1);
    EXPECT_EQ(o.sums.count, 4U);
    // The first cycle is its own reference: every δ is the identity, every ΔT 0.
    const Quaternion<double> d_b = c.q_chu_icrf[1] * conjugate(c.q_chu_icrf[0]);
    EXPECT_EQ(o.ref.r[0].w, d_b.w);
    EXPECT_EQ(o.ref.t_ref[2][1], c.temperatures[2].t_029.value);
    const calib::OrbitMeans m = calib::orbit_means(o);
    EXPECT_LT(angle_arcsec(m.d[0], d_b), 1e-9);
    EXPECT_NEAR(m.t[1][0], c.temperatures[1].t_chu.value, 1e-12);

    // The next orbit keeps the references (none was set) even after a drop...
    calib::CalibCycle<double> c2 = synthetic_cycle(400);
    c2.t_us = 0;
    col.open(c2);
    col.drop();
    c2.t_us = 7 * kP + 3;
    col.open(c2);
    col.add(c2);
    col.close(o);
    EXPECT_EQ(o.bin, 7);
    EXPECT_EQ(o.ref.r[0].w, d_b.w);
    // ... and takes a set one once, at the next open.
    calib::OrbitReference<double> next = calib::reference_from<double>(calib::orbit_means(o));
    col.set_next_reference(next);
    col.open(c2);
    col.close(o);
    EXPECT_EQ(o.ref.r[1].x, next.r[1].x);
    EXPECT_EQ(o.ref.t_ref[0][2], next.t_ref[0][2]);
    const calib::CalibCycle<double> c3 = synthetic_cycle(800);  // B bent differently, other temperatures
    col.open(c3);
    col.close(o);
    EXPECT_EQ(o.ref.r[0].x, next.r[0].x);  // kept, not taken from the cycle
    EXPECT_EQ(o.ref.t_ref[0][0], next.t_ref[0][0]);
    EXPECT_NE(next.t_ref[0][0], c3.temperatures[0].t_chu.value);  // (the check can fail)
}

// Cycle k with a fourth head D (bent 0.2"/degC of T_CHU about its x axis)
// when with_d; otherwise D is not selected (its bit clear, its data garbage).
calib::CalibCycle<double, 4> synthetic_cycle4(long k, bool with_d) {
    const calib::CalibCycle<double> c3 = synthetic_cycle(k);
    calib::CalibCycle<double, 4> c{};
    c.t_us = c3.t_us;
    for (std::size_t h = 0; h < 3; ++h) {
        c.q_chu_icrf[h] = c3.q_chu_icrf[h];
        c.temperatures[h] = c3.temperatures[h];
    }
    c.temperatures[3] = c3.temperatures[0];
    if (!with_d) {
        c.q_chu_icrf[3] = {0.0, 1.0, 0.0, 0.0};  // not to be read
        c.temperatures[3].t_chu.value = 1e6;
        return c;
    }
    const Eigen::Quaterniond d_a(Eigen::AngleAxisd(2.1, Eigen::Vector3d(0.5, -0.4, 0.7).normalized()));
    const double bend = 0.2 * (c.temperatures[3].t_chu.value - 10.0) * kArcsecToRad;
    const Eigen::Quaterniond qa = to_eigen(c.q_chu_icrf[0]);
    const Eigen::Quaterniond qd = Eigen::Quaterniond(Eigen::AngleAxisd(bend, Eigen::Vector3d::UnitX())) * d_a * qa;
    c.q_chu_icrf[3] = from_eigen(qd.normalized());
    c.heads = static_cast<std::uint8_t>(c.heads | 8U);
    return c;
}

// Per-head selection (estimator_types.hpp). An estimator of four heads whose
// fourth never passes the selection takes the three-head estimator's
// decisions bit for bit (report, versions, CRCs, coefficients), and keeps D
// out of its models. With D selected in two cycles of three (and, in one of
// them, fed after the cycle: accumulate_head), it learns D's slope and says
// so (active_learnt), from the same orbits as A, B and C.
TEST(CalibEstimator, AFourthHeadLearnsFromItsOwnEpochsAndLeavesTheThreeAlone) {
    calib::Estimator<double> e3;
    calib::Estimator<double, 4> e4_absent;
    calib::Estimator<double, 4> e4;
    for (long k = 0; k < 288 * 15; ++k) {
        const calib::CalibCycle<double> c = synthetic_cycle(k);
        const calib::CalibCycle<double, 4> absent = synthetic_cycle4(k, false);
        (void)e3.model_for_cycle(c.t_us);
        (void)e4_absent.model_for_cycle(c.t_us);
        (void)e4.model_for_cycle(c.t_us);
        e3.accumulate(c);
        e4_absent.accumulate(absent);
        if (k % 3 == 1) {  // D after the cycle
            e4.accumulate(absent);
            const calib::CalibCycle<double, 4> d = synthetic_cycle4(k, true);
            EXPECT_TRUE(e4.accumulate_head(3, d.t_us, d.q_chu_icrf[3], d.temperatures[3]));
            EXPECT_FALSE(e4.accumulate_head(3, d.t_us + 1, d.q_chu_icrf[3], d.temperatures[3]));  // no such cycle
        } else {
            e4.accumulate(synthetic_cycle4(k, k % 3 == 0));
        }
        while (e3.step()) {
        }
        while (e4_absent.step()) {
        }
        while (e4.step()) {
        }
        ASSERT_EQ(e3.active_version(), e4_absent.active_version()) << k;
        ASSERT_EQ(e3.active_crc(), e4_absent.active_crc()) << k;
    }
    const calib::EstimatorReport r3 = e3.report();
    const calib::EstimatorReport r4 = e4_absent.report();
    ASSERT_TRUE(r3.has_active);
    EXPECT_GE(r3.active_version, 2U);
    const auto bits = [](double x) {
        std::uint64_t b = 0;
        std::memcpy(&b, &x, sizeof b);
        return b;
    };
    EXPECT_EQ(r3.orbits_used, r4.orbits_used);
    EXPECT_EQ(r3.orbits_short, r4.orbits_short);
    EXPECT_EQ(r3.orbits_held, r4.orbits_held);
    EXPECT_EQ(bits(r3.condition), bits(r4.condition));
    EXPECT_EQ(bits(r3.residual_rms_arcsec), bits(r4.residual_rms_arcsec));
    EXPECT_EQ(bits(r3.candidate_rms_arcsec), bits(r4.candidate_rms_arcsec));
    for (std::size_t i = 0; i < calib::kRefusalKinds; ++i) {
        EXPECT_EQ(r3.refusals[i], r4.refusals[i]) << i;
    }
    EXPECT_EQ(std::memcmp(e3.active_coefficients(), e4_absent.active_coefficients(), sizeof(ModelCoefficients)), 0);
    EXPECT_FALSE(e4_absent.active_coefficients()->present[3]);
    EXPECT_EQ(e4_absent.active_learnt(), 7U);
    // D learnt, from every orbit A, B and C were learnt from.
    const calib::EstimatorReport rd = e4.report();
    EXPECT_EQ(rd.orbits_used, r3.orbits_used);
    EXPECT_EQ(e4.active_learnt(), 15U);
    ASSERT_TRUE(e4.active_coefficients()->present[3]);
    EXPECT_NEAR(e4.active_coefficients()->coefficient[3][0][1], 0.2, 0.01);
    EXPECT_NEAR(e4.active_coefficients()->coefficient[1][0][1], 0.3, 0.01);
}

// The commands and the double buffer: a model becomes active only at the
// next cycle; freeze stops the learning, resume restarts it, reset forgets
// it and keeps the active model, load_model is active at the next cycle with
// the next version and its CRC.
TEST(CalibEstimator, CommandsAndTheDoubleBuffer) {
    calib::Estimator<double> est;
    long k = 0;
    std::uint32_t version = 0;
    const auto cycles = [&](long n) {
        for (long i = 0; i < n; ++i, ++k) {
            const calib::CalibCycle<double> c = synthetic_cycle(k);
            (void)est.model_for_cycle(c.t_us);
            est.accumulate(c);
            bool stepped = false;
            while (est.step()) {
                stepped = true;
            }
            // An adoption in this step is not active before the next cycle.
            if (stepped) {
                EXPECT_EQ(est.report().active_version, version);
            }
            version = est.report().active_version;
        }
    };
    EXPECT_EQ(est.model_for_cycle(0), nullptr);
    cycles(288 * 15);  // 15 days
    const calib::EstimatorReport r = est.report();
    ASSERT_TRUE(r.has_active) << calib::refusal_name(r.last_refusal);
    EXPECT_GE(r.active_version, 1U);
    EXPECT_EQ(r.active_crc, calib::model_crc(*est.active_coefficients()));
    // The slope it learnt: B's alpha, 0.3"/degC of T_CHU.
    EXPECT_NEAR(est.active_coefficients()->coefficient[1][0][1], 0.3, 0.01);
    // freeze: nothing is learnt.
    est.freeze();
    const std::uint32_t used = est.report().orbits_used;
    cycles(288 * 2);
    EXPECT_EQ(est.report().orbits_used, used);
    EXPECT_TRUE(est.report().frozen);
    est.resume();
    cycles(288 * 2);
    EXPECT_GT(est.report().orbits_used, used + 20U);
    // reset: forgotten, the active model stays.
    const std::uint32_t active = est.report().active_version;
    est.reset();
    EXPECT_EQ(est.report().orbits_used, 0U);
    EXPECT_EQ(est.report().active_version, active);
    // load_model: active at the next cycle, version + 1, its CRC.
    ModelCoefficients m{};
    m.present[0] = m.present[1] = m.present[2] = true;
    m.coefficient[2][1][0] = 1.25;
    est.load_model(m);
    EXPECT_EQ(est.report().active_version, active);
    const ThermalModel<double>* core = est.model_for_cycle(synthetic_cycle(k).t_us);
    ASSERT_NE(core, nullptr);
    EXPECT_EQ(est.report().active_version, active + 1U);
    EXPECT_EQ(est.report().active_crc, calib::model_crc(m));
    EXPECT_DOUBLE_EQ(core->head[2].beta.c0, 1.25 * kArcsecToRad);
}

// |Δc_h(T)| per head of two models' corrections at the temperatures T
// (arcsec): a common rotation ω turns each head by N_h·ω, of the same norm.
std::array<double, 3> correction_change(const ModelCoefficients& a, const ModelCoefficients& b,
                                        const double (&x)[kRegressors]) {
    std::array<double, 3> norm{};
    for (std::size_t h = 0; h < 3; ++h) {
        double ss = 0.0;
        for (std::size_t ax = 0; ax < kModelAxes; ++ax) {
            const double d = model_polynomial(a.coefficient[h][ax], x) - model_polynomial(b.coefficient[h][ax], x);
            ss += d * d;
        }
        norm[h] = std::sqrt(ss);
    }
    return norm;
}

// The rule's re-gauge (estimator_orbit.hpp, regauge()): with a threshold of
// 0 every orbit that adopts no candidate re-gauges, with +inf none does; the
// same candidates are adopted at the same cycles, and the two active models
// differ by a common rotation (the same |Δc| for every head), so no IBA
// changes. None after a reset (the active ω is in the frame forgotten), and
// neither the re-gauge nor the gate overwrites a ground model loaded while
// an orbit's work is pending.
TEST(CalibEstimator, TheRuleRegaugesTheActiveModelAndNoIba) {
    calib::EstimatorConfig cfg;
    cfg.common_rotation.heads = 0b111;
    for (std::size_t h = 0; h < 3; ++h) {
        cfg.common_rotation.a[h] = calib::Matrix3{{{1.0 + 0.5 * static_cast<double>(h), 0.0, 0.0},
                                                   {0.0, 1.0, 0.0},
                                                   {0.0, 0.0, 0.2 + static_cast<double>(h)}}};
    }
    calib::EstimatorConfig never = cfg;
    cfg.regauge_arcsec = 0.0;
    never.regauge_arcsec = std::numeric_limits<double>::infinity();
    calib::Estimator<double> on(cfg);
    calib::Estimator<double> off(never);
    long k = 0;
    for (; k < 288 * 15; ++k) {
        const calib::CalibCycle<double> c = synthetic_cycle(k);
        (void)on.model_for_cycle(c.t_us);
        (void)off.model_for_cycle(c.t_us);
        // Every version of `on` is an adoption of `off`'s, at the same cycle, or a re-gauge.
        ASSERT_EQ(on.active_version(), off.active_version() + on.regauges().made) << k;
        on.accumulate(c);
        off.accumulate(c);
        while (on.step()) {
        }
        while (off.step()) {
        }
    }
    (void)on.model_for_cycle(synthetic_cycle(k).t_us);
    (void)off.model_for_cycle(synthetic_cycle(k).t_us);
    EXPECT_GT(on.regauges().made, 20U);
    EXPECT_EQ(on.regauges().beyond_limits, 0U);
    EXPECT_EQ(off.regauges().made, 0U);
    EXPECT_GE(off.active_version(), 1U);
    double largest = 0.0;
    for (const double t1 : {4.0, 10.0, 16.0}) {
        const double x[kRegressors] = {t1, 5.0 - t1, -1.0 - t1};
        const std::array<double, 3> d = correction_change(*on.active_coefficients(), *off.active_coefficients(), x);
        EXPECT_NEAR(d[1], d[0], 1e-9 + 1e-9 * d[0]);
        EXPECT_NEAR(d[2], d[0], 1e-9 + 1e-9 * d[0]);
        largest = std::max(largest, d[0]);
    }
    EXPECT_GT(largest, 1e-6) << "the re-gauged model is the adopted one: nothing was tested";
    // After a reset no re-gauge, until a candidate is adopted (30 orbits).
    on.reset();
    const std::uint32_t made = on.regauges().made;
    const std::uint32_t version = on.active_version();
    for (long i = 0; i < 19L * 25L; ++i, ++k) {
        const calib::CalibCycle<double> c = synthetic_cycle(k);
        (void)on.model_for_cycle(c.t_us);
        on.accumulate(c);
        while (on.step()) {
        }
    }
    EXPECT_EQ(on.regauges().made, made);
    EXPECT_EQ(on.active_version(), version);
    // A ground model loaded when an orbit has closed stays the next model.
    calib::Estimator<double> est(cfg);
    ModelCoefficients m{};
    m.present[0] = m.present[1] = m.present[2] = true;
    m.coefficient[1][0][0] = 2.5;
    bool loaded = false;
    for (long i = 0; i < 288 * 10 && !loaded; ++i) {
        const calib::CalibCycle<double> c = synthetic_cycle(i);
        (void)est.model_for_cycle(c.t_us);
        est.accumulate(c);
        if (est.regauges().made > 3U && est.step()) {  // an orbit closed: its work is under way
            est.load_model(m);
            loaded = true;
        }
        while (est.step()) {
        }
    }
    ASSERT_TRUE(loaded);
    (void)est.model_for_cycle(synthetic_cycle(288 * 10).t_us);
    EXPECT_EQ(est.active_crc(), calib::model_crc(m));
}

}  // namespace
}  // namespace ascorr::test
