// The fixed-point instantiation (Q30, fixed_point.hpp): the Q-format
// operations' rounding and saturation, the thermal angle against double, and
// the whole core against the double reference on the worked examples, on
// randomized data, on bad inputs and through `ascorr correct --scalar fixed`.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <random>

#include "ascorr/ascorr.hpp"
#include "ascorr/core/fixed_point.hpp"
#include "ascorr_host/correct/solution_input.hpp"
#include "ascorr_host/formats/model_csv.hpp"
#include "test_support.hpp"

namespace ascorr::test {
namespace {

using QT = ScalarTraits<Q30>;
constexpr double kLsb = 1.0 / 1073741824.0;  // 2^-30

Q30 q(double x) {
    return QT::from_double(x);
}
double d(Q30 x) {
    return QT::to_double(x);
}

TEST(FixedPoint, ConversionRoundsAndSaturates) {
    EXPECT_EQ(q(1.0).raw, 1 << 30);
    EXPECT_EQ(q(-1.0).raw, -(1 << 30));
    EXPECT_EQ(q(0.4 * kLsb).raw, 0);
    EXPECT_EQ(q(0.6 * kLsb).raw, 1);
    EXPECT_EQ(q(-0.6 * kLsb).raw, -1);
    EXPECT_EQ(q(2.0).raw, INT32_MAX);
    EXPECT_EQ(q(-2.0).raw, -INT32_MAX);  // conversions saturate symmetrically
    EXPECT_EQ(q(1e300).raw, INT32_MAX);
    EXPECT_EQ(q(-std::numeric_limits<double>::infinity()).raw, -INT32_MAX);
    EXPECT_EQ(q(std::nan("")).raw, INT32_MAX);
    EXPECT_EQ(QT::celsius(std::nan("")).raw, INT32_MAX);
    EXPECT_DOUBLE_EQ(QT::to_double(QT::celsius(-40.25)), -40.25);
    EXPECT_NEAR(QT::to_double(QT::coefficient(3.5e-6)), 3.5e-6, 0.5 / 68719476736.0);
}

TEST(FixedPoint, AddSubNegSaturate) {
    EXPECT_EQ((q(1.5) + q(1.5)).raw, INT32_MAX);
    EXPECT_EQ((q(-1.5) + q(-1.5)).raw, INT32_MIN);  // operations saturate to the format's ends
    EXPECT_EQ((q(-1.5) - q(1.5)).raw, INT32_MIN);
    EXPECT_EQ((q(1.5) - q(-1.5)).raw, INT32_MAX);
    EXPECT_EQ((-Q30{INT32_MIN}).raw, INT32_MAX);
    EXPECT_EQ((q(0.75) + q(-0.25)).raw, q(0.5).raw);
    EXPECT_EQ((q(0.75) - q(0.25)).raw, q(0.5).raw);
}

TEST(FixedPoint, MultiplyRoundsToNearestAndSaturates) {
    std::mt19937_64 rng(30);
    std::uniform_int_distribution<std::int32_t> raw(INT32_MIN, INT32_MAX);
    for (int i = 0; i < 100000; ++i) {
        const Q30 a{raw(rng) / 2};  // |a|, |b| < 1: in range
        const Q30 b{raw(rng) / 2};
        const long double exact = static_cast<long double>(a.raw) * b.raw / 1073741824.0L;
        EXPECT_LE(std::fabs(static_cast<long double>((a * b).raw) - exact), 0.5L);
    }
    EXPECT_EQ((q(1.75) * q(1.75)).raw, INT32_MAX);
    EXPECT_EQ((q(-1.75) * q(1.75)).raw, INT32_MIN);
    EXPECT_EQ((Q30{INT32_MIN} * Q30{INT32_MAX}).raw, INT32_MIN);
    EXPECT_EQ((Q30{INT32_MIN} * Q30{INT32_MIN}).raw, INT32_MAX);
    EXPECT_EQ((Q30{1} * Q30{1 << 29}).raw, 1);   // 0.5 LSB: tie rounds up
    EXPECT_EQ((Q30{-1} * Q30{1 << 29}).raw, 0);  // -0.5 LSB: tie rounds towards +inf
}

// fx::mul_high: ⌊a·b·2⁻³²⌋ exactly, for any raws (the ends included), against
// long double (64-bit mantissa: every a·b exact).
TEST(FixedPoint, MulHighIsTheProductsFloorAtTwoToThe32) {
    static_assert(std::numeric_limits<long double>::digits >= 63, "the reference needs every a·b exact");
    std::mt19937_64 rng(32);
    std::uniform_int_distribution<std::int32_t> raw(INT32_MIN, INT32_MAX);
    const auto floor_high = [](std::int32_t a, std::int32_t b) {
        return static_cast<std::int64_t>(std::floor(static_cast<long double>(a) * b / 4294967296.0L));
    };
    for (int i = 0; i < 100000; ++i) {
        const std::int32_t a = raw(rng);
        const std::int32_t b = raw(rng);
        ASSERT_EQ(fx::mul_high(a, b), floor_high(a, b)) << a << " " << b;
    }
    EXPECT_EQ(fx::mul_high(INT32_MIN, INT32_MIN), 1 << 30);
    EXPECT_EQ(fx::mul_high(INT32_MIN, INT32_MAX), -(1 << 30));  // −2³⁰ + 1/2, floored
    EXPECT_EQ(fx::mul_high(-1, 1), -1);                         // −2⁻³²: the floor, not towards zero
    EXPECT_EQ(fx::mul_high(1 << 30, 1 << 30), 1 << 28);
}

// The fixed-point thermal angle against the same polynomial in double on the
// fixed-point inputs (coefficients and temperatures as quantised), with
// quadratic terms and with none.
TEST(FixedPoint, ThermalAngleMatchesDouble) {
    std::mt19937_64 rng(31);
    std::uniform_real_distribution<double> c0(-2e-3, 2e-3);
    std::uniform_real_distribution<double> c1(-3e-5, 3e-5);
    std::uniform_real_distribution<double> c2q(-3e-8, 3e-8);
    std::uniform_real_distribution<double> temp(-200.0, 200.0);
    double worst = 0.0;
    for (int i = 0; i < 100000; ++i) {
        const bool quad = (i % 2) == 0;
        AxisPolynomial<Q30> p{};
        p = {QT::coefficient(c0(rng)),
             QT::coefficient(c1(rng)),
             QT::coefficient(c1(rng)),
             QT::coefficient(c1(rng)),
             QT::quadratic_coefficient(quad ? c2q(rng) : 0.0),
             QT::quadratic_coefficient(quad ? c2q(rng) : 0.0),
             QT::quadratic_coefficient(quad ? c2q(rng) : 0.0)};
        const QCelsius t1 = QT::celsius(temp(rng));
        const QCelsius t2 = QT::celsius(temp(rng));
        const QCelsius t3 = QT::celsius(temp(rng));
        AxisPolynomial<double> pd{QT::to_double(p.c0),  QT::to_double(p.c1),   QT::to_double(p.c2),
                                  QT::to_double(p.c3),  QT::to_double(p.c1_2), QT::to_double(p.c2_2),
                                  QT::to_double(p.c3_2)};
        const double want = thermal_angle<double>(pd, QT::to_double(t1), QT::to_double(t2), QT::to_double(t3));
        const double got = d(thermal_angle<Q30>(p, t1, t2, t3));
        if (std::fabs(want) < 0.017) {
            worst = std::max(worst, std::fabs(got - want));
        }
    }
    // One final rounding (2^-31) plus the T^2 roundings (2^-13 °C^2 · 3e-8).
    EXPECT_LE(worst, 0.6 * kLsb);
    // Saturates, never wraps, for a model far beyond the domain.
    AxisPolynomial<Q30> big{QT::coefficient(0.03),           QT::coefficient(0.03),
                            QT::coefficient(0.03),           QT::coefficient(0.03),
                            QT::quadratic_coefficient(7e-6), QT::quadratic_coefficient(7e-6),
                            QT::quadratic_coefficient(7e-6)};
    const QCelsius hot = QT::celsius(2000.0);
    const QCelsius cold = QT::celsius(-2000.0);
    EXPECT_EQ(thermal_angle<Q30>(big, hot, hot, hot).raw, INT32_MAX);
    EXPECT_EQ(thermal_angle<Q30>(big, cold, hot, hot).raw, INT32_MAX);   // -7.7 + 2*15.4 + quadratic rad
    EXPECT_EQ(thermal_angle<Q30>(big, hot, cold, cold).raw, INT32_MIN);  // 7.7 - 2*15.4 + quadratic rad
}

SolutionInput<Q30> to_fixed(const SolutionInput<double>& in) {
    SolutionInput<Q30> o{};
    o.q_chu_icrf = {q(in.q_chu_icrf.w), q(in.q_chu_icrf.x), q(in.q_chu_icrf.y), q(in.q_chu_icrf.z)};
    o.head = in.head;
    const auto t = [](const TemperatureReading<double>& r) {
        return TemperatureReading<Q30>{QT::celsius(r.value), r.valid};
    };
    o.temperatures = {t(in.temperatures.t_chu), t(in.temperatures.t_029), t(in.temperatures.t_032)};
    o.velocity = {{q(in.velocity.beta_icrf.x), q(in.velocity.beta_icrf.y), q(in.velocity.beta_icrf.z)},
                  q(in.velocity.inv_sun_distance_au),
                  in.velocity.valid};
    return o;
}

Quaternion<double> widen(const Quaternion<Q30>& x) {
    return {d(x.w), d(x.x), d(x.y), d(x.z)};
}

// A random model in the paper's class: c0 up to 100", linear to 5"/°C,
// optionally quadratic to 0.01"/°C².
host::ModelFile random_model(std::mt19937_64& rng, bool quadratic) {
    std::uniform_real_distribution<double> c0(-100.0, 100.0);
    std::uniform_real_distribution<double> c1(-5.0, 5.0);
    std::uniform_real_distribution<double> c2(-0.01, 0.01);
    host::ModelFile m;
    for (std::size_t h = 0; h < kMaxHeads; ++h) {
        m.present[h] = h != 3;
        for (auto& axis : m.coefficients[h]) {
            axis = {c0(rng),
                    c1(rng),
                    c1(rng),
                    c1(rng),
                    quadratic ? c2(rng) : 0.0,
                    quadratic ? c2(rng) : 0.0,
                    quadratic ? c2(rng) : 0.0};
        }
    }
    m.quadratic = quadratic;
    return m;
}

TEST(FixedPoint, RandomizedAgainstDoubleWithin0p01Arcsec) {
    std::mt19937_64 rng(40);
    std::uniform_real_distribution<double> speed(0.0, 100.0);
    std::uniform_real_distribution<double> temp(-40.0, 60.0);
    double worst = 0.0;
    for (int block = 0; block < 4; ++block) {
        const host::ModelFile m =
            block == 0 ? host::read_model_file(data_path("model_table2.csv")) : random_model(rng, block >= 2);
        const ThermalModel<double> model_d = host::to_core<double>(m);
        const ThermalModel<Q30> model_q = host::to_core<Q30>(m);
        for (int i = 0; i < 25000; ++i) {
            const Eigen::Quaterniond qe = random_attitude(rng);
            const Eigen::Vector3d beta = random_unit_vector(rng) * (speed(rng) / kSpeedOfLightKmS);
            SolutionInput<double> in{};
            in.q_chu_icrf = from_eigen(qe);
            in.head = static_cast<std::uint8_t>(i % 4);
            in.temperatures = {{temp(rng), true}, {temp(rng), true}, {temp(rng), true}};
            in.velocity = {{beta.x(), beta.y(), beta.z()}, 1.0 / (0.983 + 0.034 * (i % 7) / 6.0), true};
            const auto ref = correct_solution(in, CorrectionConfig<double>{true, &model_d});
            const auto got = correct_solution(to_fixed(in), CorrectionConfig<Q30>{true, &model_q});
            ASSERT_EQ(got.status, ref.status) << i;
            ASSERT_GE(got.q_chu_icrf.w.raw, 0);
            const double e = angle_arcsec(widen(got.q_chu_icrf), ref.q_chu_icrf);
            worst = std::max(worst, e);
            const Quaternion<double> w = widen(got.q_chu_icrf);
            ASSERT_NEAR(squared_norm(w), 1.0, 2e-8);
        }
    }
    std::printf("fixed point, max over 1e5 solutions: %.5f\"\n", worst);
    RecordProperty("max_error_arcsec", std::to_string(worst));
    EXPECT_LE(worst, 0.01);
}

// At the edges of the core's domain, where the reduced series and the scaled
// thermal rotation (q_th/(c1c2c3), norm² up to 1 + 2.3e-4) are at their
// worst: thermal angles up to 0.999° on each axis and |v| up to 999 km/s.
// Float and Q30 against the double core: the error bound and a unit result
// (the renormalisation takes the thermal rotation's scale out).
// Bounds: the angle, 0.01" (Q30) and 0.05" (float), the bounds of the random
// tests (measured here: 0.0014" and 0.032"). The norm: Q30, 2⁻²⁸ = 3.7e-9 from
// quaternion.hpp's Q30 renormalized_sum: g rounded twice (≤ 2⁻³⁰, a change of
// ‖r‖² ≤ 2·2⁻³⁰) and each component once (≤ 2⁻³¹, ≤ 2·‖s‖₁·2⁻³¹ ≤ 2⁻²⁹ with
// ‖s‖₁ ≤ 2), truncation 5ε³/8 < 1e-11 (measured 2.9e-9; without the
// second-order term of g it is 3.9e-8). Float: 4e-7, twice the measured
// 1.9e-7: the first-order step leaves 3ε²/4 ≤ 4e-8 at ε = 2.3e-4, and float's
// rounding of the step and the components (≤ 2⁻²⁴ relative each) the rest.
template <typename T>
void check_domain_edge(double bound_arcsec, double norm_tolerance, const char* what) {
    std::mt19937_64 rng(1999);
    std::uniform_real_distribution<double> c0(-3596.0, 3596.0);  // arcsec; ±0.999°
    std::uniform_real_distribution<double> speed(900.0, 999.0);
    std::uniform_real_distribution<double> temp(-40.0, 60.0);
    double worst = 0.0;
    double worst_norm = 0.0;
    for (int trial = 0; trial < 20000; ++trial) {
        host::ModelFile m{};
        m.present = {true, true, true, true};
        for (auto& head : m.coefficients) {
            for (auto& axis : head) {
                axis = {c0(rng), 0.0, 0.0, 0.0, 0.0, 0.0, 0.0};  // temperature-independent: the angle is c0
            }
        }
        const ThermalModel<double> model_d = host::to_core<double>(m);
        const ThermalModel<T> model_t = host::to_core<T>(m);
        const Eigen::Vector3d beta = random_unit_vector(rng) * (speed(rng) / kSpeedOfLightKmS);
        SolutionInput<double> in{};
        in.q_chu_icrf = from_eigen(random_attitude(rng));
        in.head = static_cast<std::uint8_t>(trial % 4);
        in.temperatures = {{temp(rng), true}, {temp(rng), true}, {temp(rng), true}};
        in.velocity = {{beta.x(), beta.y(), beta.z()}, 1.0, true};
        const auto ref = correct_solution(in, CorrectionConfig<double>{true, &model_d});
        SolutionInput<T> in_t{};
        const auto s = [](double x) { return ScalarTraits<T>::from_double(x); };
        const auto c = [](double x) { return ScalarTraits<T>::celsius(x); };
        in_t.q_chu_icrf = {s(in.q_chu_icrf.w), s(in.q_chu_icrf.x), s(in.q_chu_icrf.y), s(in.q_chu_icrf.z)};
        in_t.head = in.head;
        in_t.temperatures = {{c(in.temperatures.t_chu.value), true},
                             {c(in.temperatures.t_029.value), true},
                             {c(in.temperatures.t_032.value), true}};
        in_t.velocity = {{s(beta.x()), s(beta.y()), s(beta.z())}, s(1.0), true};
        const auto got = correct_solution(in_t, CorrectionConfig<T>{true, &model_t});
        ASSERT_EQ(got.status, ref.status) << what << " " << trial;
        ASSERT_EQ(ref.status, status::kAberrationApplied | status::kThermalApplied) << what << " " << trial;
        const auto w = [](const T& x) { return ScalarTraits<T>::to_double(x); };
        const Quaternion<double> out{w(got.q_chu_icrf.w), w(got.q_chu_icrf.x), w(got.q_chu_icrf.y),
                                     w(got.q_chu_icrf.z)};
        worst = std::max(worst, angle_arcsec(out, ref.q_chu_icrf));
        worst_norm = std::max(worst_norm, std::abs(squared_norm(out) - 1.0));
    }
    std::printf("%s at the domain edges: max %.5f\", |norm^2 - 1| max %.2e\n", what, worst, worst_norm);
    EXPECT_LE(worst, bound_arcsec) << what;
    EXPECT_LE(worst_norm, norm_tolerance) << what;
}

TEST(ReducedPrecision, DomainEdgesWithinBounds) {
    check_domain_edge<Q30>(0.01, 0x1p-28, "Q30");
    check_domain_edge<float>(0.05, 4e-7, "float");
}

class FixedWorkedExample : public ::testing::TestWithParam<const char*> {};

TEST_P(FixedWorkedExample, Within0p01Arcsec) {
    const std::string name = GetParam();
    const bool aberration = name != "expected_thermal_only.csv";
    const bool thermal = name != "expected_aberration_only.csv";
    std::string in_text;
    std::string exp_text;
    const auto rows = read_records(data_path("solutions.csv"), in_text);
    const auto expected = read_records(data_path(name), exp_text);
    ASSERT_EQ(rows.size(), expected.size());
    const ThermalModel<Q30> model = host::to_core<Q30>(host::read_model_file(data_path("model_table2.csv")));
    const CorrectionConfig<Q30> cfg{aberration, thermal ? &model : nullptr};
    host::EarthVelocity earth;
    double worst = 0.0;
    for (std::size_t i = 0; i < rows.size(); ++i) {
        const auto out = correct_solution(host::to_core_input<Q30>(rows[i], &earth), cfg);
        const StatusBits want = (aberration ? status::kAberrationApplied : 0) | (thermal ? status::kThermalApplied : 0);
        EXPECT_EQ(out.status, want) << "row " << i;
        worst = std::max(worst, angle_arcsec(widen(out.q_chu_icrf), expected[i].q_chu_icrf));
    }
    RecordProperty("max_error_arcsec", std::to_string(worst));
    EXPECT_LE(worst, 0.01) << name;
}

INSTANTIATE_TEST_SUITE_P(Examples, FixedWorkedExample,
                         ::testing::Values("expected_aberration_only.csv", "expected_thermal_only.csv",
                                           "expected_both.csv"));

// Bad inputs get the status bits the double path gives them: non-finite and
// out-of-range values saturate to outside the domains and are flagged.
TEST(FixedPoint, BadInputsFlaggedAsInDouble) {
    const ThermalModel<double> model_d = host::to_core<double>(host::read_model_file(data_path("model_table2.csv")));
    const ThermalModel<Q30> model_q = host::to_core<Q30>(host::read_model_file(data_path("model_table2.csv")));
    const double nan = std::nan("");
    const double inf = std::numeric_limits<double>::infinity();
    SolutionInput<double> base{};
    base.q_chu_icrf = {0.5, 0.5, 0.5, 0.5};
    base.head = 1;
    base.temperatures = {{10.0, true}, {-5.0, true}, {-15.0, true}};
    base.velocity = {{1e-4, -2e-5, 3e-5}, 1.0, true};
    std::vector<SolutionInput<double>> cases;
    for (double bad : {nan, inf, -inf, 1e9, 250.0}) {
        auto c = base;
        c.temperatures.t_029.value = bad;
        cases.push_back(c);
        c = base;
        c.velocity.beta_icrf.y = bad;
        cases.push_back(c);
        c = base;
        c.q_chu_icrf.z = bad;
        cases.push_back(c);
    }
    auto c = base;
    c.head = 7;
    cases.push_back(c);
    c = base;
    c.q_chu_icrf = {0.5, 0.5, 0.5, 0.5001};
    cases.push_back(c);
    c = base;
    c.velocity.beta_icrf = {2e-3, 2e-3, 2e-3};  // 1040 km/s
    cases.push_back(c);
    for (std::size_t i = 0; i < cases.size(); ++i) {
        const auto ref = correct_solution(cases[i], CorrectionConfig<double>{true, &model_d});
        const auto got = correct_solution(to_fixed(cases[i]), CorrectionConfig<Q30>{true, &model_q});
        EXPECT_EQ(got.status, ref.status) << "case " << i;
    }
}

// `ascorr correct --scalar fixed` runs this core on the worked examples.
TEST(FixedPoint, CliScalarFixed) {
    const auto dir = scratch_dir("fixed");
    const std::string out = (dir / "out.csv").string();
    const std::string cmd = std::string(ASCORR_EXE) + " correct --scalar fixed --in " + data_path("solutions.csv") +
                            " --model " + data_path("model_table2.csv") + " --out " + out + " 2> " +
                            (dir / "err.txt").string();
    ASSERT_EQ(std::system(cmd.c_str()), 0);
    std::string a;
    std::string b;
    const auto got = read_records(out, a);
    const auto want = read_records(data_path("expected_both.csv"), b);
    ASSERT_EQ(got.size(), want.size());
    double worst = 0.0;
    for (std::size_t i = 0; i < got.size(); ++i) {
        worst = std::max(worst, angle_arcsec(got[i].q_chu_icrf, want[i].q_chu_icrf));
    }
    EXPECT_LE(worst, 0.01);
    // A model the coefficient format cannot hold is refused, not saturated.
    std::ofstream(dir / "big.csv") << "chu,axis,c0,c1,c2,c3\nA,alpha,7000,0,0,0\nA,beta,0,0,0,0\nA,gamma,0,0,0,0\n";
    const std::string bad = std::string(ASCORR_EXE) + " correct --scalar fixed --in " + data_path("solutions.csv") +
                            " --model " + (dir / "big.csv").string() + " --out " + (dir / "o2.csv").string() + " 2> " +
                            (dir / "err2.txt").string();
    EXPECT_NE(std::system(bad.c_str()), 0);
}

}  // namespace
}  // namespace ascorr::test
