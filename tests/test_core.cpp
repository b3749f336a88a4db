// The correction core against the worked examples, an independent evaluation
// of the paper's equations, its own properties, and every kind of bad input.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "ascorr/ascorr.hpp"
#include "ascorr_host/correct/earth_velocity.hpp"
#include "ascorr_host/correct/solution_input.hpp"
#include "ascorr_host/formats/model_csv.hpp"
#include "test_support.hpp"

namespace ascorr::test {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// ---- Independent reference: the paper's eqs. 4–10 with matrices and std::sin/cos.
Eigen::Matrix3d R1(double a) {
    Eigen::Matrix3d m;
    m << 1, 0, 0, 0, std::cos(a), std::sin(a), 0, -std::sin(a), std::cos(a);
    return m;
}
Eigen::Matrix3d R2(double b) {
    Eigen::Matrix3d m;
    m << std::cos(b), 0, -std::sin(b), 0, 1, 0, std::sin(b), 0, std::cos(b);
    return m;
}
Eigen::Matrix3d R3(double g) {
    Eigen::Matrix3d m;
    m << std::cos(g), std::sin(g), 0, -std::sin(g), std::cos(g), 0, 0, 0, 1;
    return m;
}
double reference_angle_arcsec(const std::array<double, 7>& c, double t1, double t2, double t3) {
    return c[0] + c[1] * t1 + c[2] * (t2 - t1) + c[3] * (t3 - t1) + c[4] * t1 * t1 + c[5] * (t2 - t1) * (t2 - t1) +
           c[6] * (t3 - t1) * (t3 - t1);
}
Eigen::Quaterniond reference_thermal(const Eigen::Quaterniond& q, const host::ModelFile& m, int head, double t1,
                                     double t2, double t3) {
    const auto& c = m.coefficients[static_cast<std::size_t>(head)];
    const double a = reference_angle_arcsec(c[0], t1, t2, t3) * kArcsecToRad;
    const double b = reference_angle_arcsec(c[1], t1, t2, t3) * kArcsecToRad;
    const double g = reference_angle_arcsec(c[2], t1, t2, t3) * kArcsecToRad;
    return Eigen::Quaterniond(Eigen::Matrix3d(R3(g) * R2(b) * R1(a) * q.toRotationMatrix()));
}

SolutionInput<double> input(const Quaternion<double>& q, std::uint8_t head = 0) {
    SolutionInput<double> in{};
    in.q_chu_icrf = q;
    in.head = head;
    in.temperatures = {{10.0, true}, {-5.0, true}, {-20.0, true}};
    in.velocity = {{1e-4, -2e-5, 3e-5}, 1.0, true};
    return in;
}

host::ModelFile table2() {
    return host::read_model_file(data_path("model_table2.csv"));
}

// ---- Worked examples (shared/spec/examples), all three stages.
struct Stage {
    const char* expected;
    bool aberration;
    bool thermal;
};

class WorkedExample : public ::testing::TestWithParam<Stage> {};

TEST_P(WorkedExample, MatchesTo1e6Arcsec) {
    const Stage st = GetParam();
    std::string in_text;
    std::string exp_text;
    const auto rows = read_records(data_path("solutions.csv"), in_text);
    const auto expected = read_records(data_path(st.expected), exp_text);
    ASSERT_EQ(rows.size(), expected.size());
    ASSERT_EQ(rows.size(), 12U);
    const ThermalModel<double> model = host::to_core<double>(table2());
    const CorrectionConfig<double> cfg{st.aberration, st.thermal ? &model : nullptr};
    host::EarthVelocity earth;
    double worst = 0.0;
    for (std::size_t i = 0; i < rows.size(); ++i) {
        const auto out = correct_solution(host::to_core_input<double>(rows[i], &earth), cfg);
        const StatusBits want =
            (st.aberration ? status::kAberrationApplied : 0) | (st.thermal ? status::kThermalApplied : 0);
        EXPECT_EQ(out.status, want) << "row " << i;
        EXPECT_GE(out.q_chu_icrf.w, 0.0);
        worst = std::max(worst, angle_arcsec(out.q_chu_icrf, expected[i].q_chu_icrf));
    }
    EXPECT_LE(worst, 1e-6) << st.expected;
    RecordProperty("max_error_arcsec", std::to_string(worst));
}

INSTANTIATE_TEST_SUITE_P(Examples, WorkedExample,
                         ::testing::Values(Stage{"expected_aberration_only.csv", true, false},
                                           Stage{"expected_thermal_only.csv", false, true},
                                           Stage{"expected_both.csv", true, true}));

// ---- Thermal stage against the independent matrix evaluation, randomized,
// with the quadratic terms and angles up to ~0.9 degree (the series domain is 1 degree).
TEST(Thermal, MatchesMatrixReferenceOverDomain) {
    std::mt19937_64 rng(20170418);
    std::uniform_real_distribution<double> temp(-60.0, 60.0);
    std::uniform_real_distribution<double> coef(-1.0, 1.0);
    double worst = 0.0;
    for (int trial = 0; trial < 20000; ++trial) {
        host::ModelFile m{};
        m.present = {true, true, true, true};
        const double scale = trial % 2 == 0 ? 10.0 : 0.2;  // small angles and angles near the domain edge
        for (auto& head : m.coefficients) {
            for (auto& axis : head) {
                for (std::size_t i = 0; i < 7; ++i) {
                    axis[i] = coef(rng) * (i == 0 ? 50.0 * scale : i < 4 ? scale : 0.02 * scale);
                }
            }
        }
        const auto head = static_cast<std::uint8_t>(trial % 4);
        const double t1 = temp(rng);
        const double t2 = temp(rng);
        const double t3 = temp(rng);
        const Eigen::Quaterniond q = random_attitude(rng);
        const ThermalModel<double> model = host::to_core<double>(m);
        SolutionInput<double> in = input(from_eigen(q), head);
        in.temperatures = {{t1, true}, {t2, true}, {t3, true}};
        const auto out = correct_solution(in, CorrectionConfig<double>{false, &model});
        bool in_domain = true;
        for (const auto& axis : m.coefficients[head]) {
            in_domain =
                in_domain && std::abs(reference_angle_arcsec(axis, t1, t2, t3)) * kArcsecToRad <= kMaxThermalAngleRad;
        }
        if (!in_domain) {
            EXPECT_EQ(out.status, status::kThermalOutOfRange);
            continue;
        }
        ASSERT_EQ(out.status, status::kThermalApplied);
        worst = std::max(worst, angle_arcsec(to_eigen(out.q_chu_icrf), reference_thermal(q, m, head, t1, t2, t3)));
    }
    EXPECT_LE(worst, 1e-6);
    RecordProperty("max_error_arcsec", std::to_string(worst));
}

// The half-angle series against std::sin/cos, at and inside the domain limit.
TEST(Thermal, HalfAngleSeriesWithinStatedBound) {
    for (double a = -kMaxThermalAngleRad; a <= kMaxThermalAngleRad; a += kMaxThermalAngleRad / 5000.0) {
        const HalfAngle<double> h = half_angle(a);
        EXPECT_NEAR(1.0 + h.cm1, std::cos(a / 2), 6.1e-16 + 2.3e-16) << a;
        EXPECT_NEAR(h.s, std::sin(a / 2), 7.6e-19 + 2e-18) << a;
    }
}

TEST(Thermal, ExpandedProductEqualsThreeQuaternionProduct) {
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> ang(-kMaxThermalAngleRad, kMaxThermalAngleRad);
    for (int i = 0; i < 1000; ++i) {
        const double a = ang(rng), b = ang(rng), g = ang(rng);
        const HalfAngle<double> ha = half_angle(a), hb = half_angle(b), hg = half_angle(g);
        const Quaternion<double> q1{1 + ha.cm1, -ha.s, 0, 0}, q2{1 + hb.cm1, 0, -hb.s, 0}, q3{1 + hg.cm1, 0, 0, -hg.s};
        const Quaternion<double> p = q3 * q2 * q1;
        const Quaternion<double> e = to_quaternion(thermal_rotation(a, b, g));
        EXPECT_NEAR(p.w, e.w, 4e-16);
        EXPECT_NEAR(p.x, e.x, 4e-16);
        EXPECT_NEAR(p.y, e.y, 4e-16);
        EXPECT_NEAR(p.z, e.z, 4e-16);
    }
}

// ---- Properties.
TEST(Properties, UnitNormKeptAndCanonicalSign) {
    std::mt19937_64 rng(1);
    const ThermalModel<double> model = host::to_core<double>(table2());
    for (int i = 0; i < 10000; ++i) {
        const auto out = correct_solution(input(from_eigen(random_attitude(rng)), static_cast<std::uint8_t>(i % 3)),
                                          CorrectionConfig<double>{true, &model});
        ASSERT_EQ(out.status, status::kAberrationApplied | status::kThermalApplied);
        EXPECT_NEAR(squared_norm(out.q_chu_icrf), 1.0, 1e-15);  // 4 ulp of rounding
        EXPECT_GE(out.q_chu_icrf.w, 0.0);
    }
}

TEST(Properties, ZeroCoefficientsGiveIdentity) {
    host::ModelFile m{};
    m.present = {true, true, true, true};  // all coefficients zero
    const ThermalModel<double> model = host::to_core<double>(m);
    std::mt19937_64 rng(2);
    for (int i = 0; i < 1000; ++i) {
        const Eigen::Quaterniond q = random_attitude(rng);
        const auto out = correct_solution(input(from_eigen(q)), CorrectionConfig<double>{false, &model});
        EXPECT_EQ(out.status, status::kThermalApplied);
        EXPECT_LE(angle_arcsec(to_eigen(out.q_chu_icrf), q), 1e-10);
    }
}

TEST(Properties, NegatedInputGivesSameAttitude) {
    std::mt19937_64 rng(3);
    const ThermalModel<double> model = host::to_core<double>(table2());
    for (int i = 0; i < 1000; ++i) {
        const Quaternion<double> q = from_eigen(random_attitude(rng));
        const auto a = correct_solution(input(q), CorrectionConfig<double>{true, &model});
        const auto b = correct_solution(input({-q.w, -q.x, -q.y, -q.z}), CorrectionConfig<double>{true, &model});
        EXPECT_LE(angle_arcsec(a.q_chu_icrf, b.q_chu_icrf), 1e-10);
        EXPECT_NEAR(a.q_chu_icrf.w, b.q_chu_icrf.w, 1e-15);  // both canonical
    }
}

// Both stages = thermal applied to the aberration-corrected attitude, and the
// stages do not commute (the order of docs/contract.md matters).
TEST(Properties, StagesComposeAsSpecified) {
    std::mt19937_64 rng(4);
    const ThermalModel<double> model = host::to_core<double>(table2());
    double worst = 0.0;
    double commute = 0.0;
    for (int i = 0; i < 2000; ++i) {
        SolutionInput<double> in = input(from_eigen(random_attitude(rng)), static_cast<std::uint8_t>(i % 3));
        const auto both = correct_solution(in, CorrectionConfig<double>{true, &model});
        const auto ab = correct_solution(in, CorrectionConfig<double>{true, nullptr});
        SolutionInput<double> in2 = in;
        in2.q_chu_icrf = ab.q_chu_icrf;
        const auto ab_th = correct_solution(in2, CorrectionConfig<double>{false, &model});
        worst = std::max(worst, angle_arcsec(both.q_chu_icrf, ab_th.q_chu_icrf));
        const auto th = correct_solution(in, CorrectionConfig<double>{false, &model});
        SolutionInput<double> in3 = in;
        in3.q_chu_icrf = th.q_chu_icrf;
        const auto th_ab = correct_solution(in3, CorrectionConfig<double>{true, nullptr});
        commute = std::max(commute, angle_arcsec(both.q_chu_icrf, th_ab.q_chu_icrf));
    }
    EXPECT_LE(worst, 1e-9);
    EXPECT_GT(commute, 1e-6);  // the reverse order is measurably different
}

TEST(Properties, RenormalisationIsNewtonStep) {
    const Quaternion<double> q{0.5 * (1 + 4e-7), 0.5 * (1 + 4e-7), 0.5 * (1 + 4e-7), 0.5 * (1 + 4e-7)};
    const double eps = squared_norm(q) - 1.0;
    EXPECT_NEAR(squared_norm(renormalized(q)) - 1.0, -0.75 * eps * eps, 1e-15);
}

// ---- Bad input: every case gets its status and never a wrong correction.

// A bad-input case: what it is, the input that is bad, the head, and what it gives.
template <typename Input, typename Want>
struct HeadCase {
    const char* what;
    Input input;
    std::uint8_t head;
    Want want;
};

TEST(BadInput, RejectedSolutionsComeBackUnchanged) {
    const ThermalModel<double> model = host::to_core<double>(table2());
    const CorrectionConfig<double> cfg{true, &model};
    using Case = HeadCase<Quaternion<double>, Rejection>;
    const double inf = std::numeric_limits<double>::infinity();
    const Case cases[] = {
        {"NaN component", {kNaN, 0, 0, 1}, 0, Rejection::kQuaternionNotFinite},
        {"infinite component", {inf, 0, 0, 0}, 0, Rejection::kQuaternionNotFinite},
        {"zero quaternion", {0, 0, 0, 0}, 0, Rejection::kQuaternionNotUnit},
        {"norm 1.01", {1.01, 0, 0, 0}, 0, Rejection::kQuaternionNotUnit},
        {"norm^2 off by 2e-6", {std::sqrt(1 + 2e-6), 0, 0, 0}, 0, Rejection::kQuaternionNotUnit},
        {"huge components", {1e300, 1e300, 0, 0}, 0, Rejection::kQuaternionNotUnit},
        {"head 4", {1, 0, 0, 0}, 4, Rejection::kHeadOutOfRange},
        {"head 255", {1, 0, 0, 0}, 255, Rejection::kHeadOutOfRange},
    };
    for (const Case& c : cases) {
        SolutionInput<double> in = input(c.input, c.head);
        EXPECT_EQ(check_solution(in), c.want) << c.what;
        const auto out = correct_solution(in, cfg);
        EXPECT_EQ(out.status, status::kRejected) << c.what;
        EXPECT_EQ(std::memcmp(&out.q_chu_icrf, &c.input, sizeof c.input), 0)
            << c.what << ": must be returned bit for bit";
    }
}

TEST(BadInput, NearUnitQuaternionIsAcceptedAndNormalised) {
    SolutionInput<double> in = input({std::sqrt(1 + 0.9e-6), 0, 0, 0});
    const auto out = correct_solution(in, CorrectionConfig<double>{false, nullptr});
    EXPECT_EQ(out.status, 0);
    EXPECT_NEAR(squared_norm(out.q_chu_icrf), 1.0, 1e-12);
}

TEST(BadInput, VelocityCases) {
    const Quaternion<double> q{0.5, 0.5, 0.5, 0.5};
    const double inf = std::numeric_limits<double>::infinity();
    struct Case {
        const char* what;
        ObserverVelocity<double> v;
        StatusBits want;
    };
    const double c_beta = 1.0;  // |v| = c
    const Case cases[] = {
        {"missing", {{0, 0, 0}, 1.0, false}, status::kNoVelocity},
        {"NaN", {{kNaN, 0, 0}, 1.0, true}, status::kNoVelocity | status::kVelocityInvalid},
        {"infinite", {{0, inf, 0}, 1.0, true}, status::kNoVelocity | status::kVelocityInvalid},
        {"|v| = c", {{0, 0, c_beta}, 1.0, true}, status::kNoVelocity | status::kVelocityInvalid},
        {"|v| > c", {{3.0, 0, 0}, 1.0, true}, status::kNoVelocity | status::kVelocityInvalid},
        {"1001 km/s", {{1001.0 / kSpeedOfLightKmS, 0, 0}, 1.0, true}, status::kNoVelocity | status::kVelocityInvalid},
        {"components in range, norm too big",
         {{0.9 * kMaxBeta, 0.9 * kMaxBeta, 0.9 * kMaxBeta}, 1.0, true},
         status::kNoVelocity | status::kVelocityInvalid},
        {"NaN sun distance", {{1e-4, 0, 0}, kNaN, true}, status::kNoVelocity | status::kVelocityInvalid},
        {"999 km/s", {{999.0 / kSpeedOfLightKmS, 0, 0}, 1.0, true}, status::kAberrationApplied},
    };
    for (const Case& c : cases) {
        SolutionInput<double> in = input(q);
        in.velocity = c.v;
        const auto out = correct_solution(in, CorrectionConfig<double>{true, nullptr});
        EXPECT_EQ(out.status, c.want) << c.what;
        if ((c.want & status::kAberrationApplied) == 0) {
            EXPECT_LE(angle_arcsec(out.q_chu_icrf, q), 1e-12) << c.what << ": attitude must be untouched";
        }
    }
}

// 1/s outside [1/40, 1/0.6] au⁻¹ makes the velocity unusable (4|32) in every
// scalar, and leaves the attitude untouched; its edges and Swarm's range are
// accepted. Without the check, 1/s = 1e9 turns the 4e-7" solar term into 425".
template <typename T>
void expect_sun_distance_domain() {
    using Tr = ScalarTraits<T>;
    const Quaternion<T> q{Tr::from_double(0.5), Tr::from_double(0.5), Tr::from_double(0.5), Tr::from_double(0.5)};
    const Vector3<T> beta{Tr::from_double(1e-4), Tr::from_double(-2e-5), Tr::from_double(3e-5)};
    struct Case {
        double inv_s;
        bool usable;
    };
    const Case cases[] = {
        {1e9, false},  {-1.0, false},      {0.0, false},         {1.0 / 40.5, false}, {1.0 / 0.59, false},
        {kNaN, false}, {1.0 / 40.0, true}, {1.0 / 0.6001, true}, {1.0 / 1.017, true}, {1.0 / 0.983, true},
        {1.0, true},   {1.0 / 5.2, true},  {-kNaN, false},
    };
    for (const Case& c : cases) {
        SolutionInput<T> in{q, 0, {}, {beta, Tr::from_double(c.inv_s), true}};
        const auto out = correct_solution(in, CorrectionConfig<T>{true, nullptr});
        if (c.usable) {
            EXPECT_EQ(out.status, status::kAberrationApplied) << "1/s = " << c.inv_s;
        } else {
            EXPECT_EQ(out.status, status::kNoVelocity | status::kVelocityInvalid) << "1/s = " << c.inv_s;
            EXPECT_EQ(Tr::to_double(out.q_chu_icrf.w), 0.5) << "1/s = " << c.inv_s << ": attitude must be untouched";
        }
    }
}

TEST(BadInput, SunDistanceOutsideItsDomainMakesTheVelocityUnusable) {
    expect_sun_distance_domain<double>();
    expect_sun_distance_domain<float>();
    expect_sun_distance_domain<Q30>();
}

// ---- Status bits: the rule of status.hpp, on everything the core emits.
TEST(StatusBits, TheRuleRejectsEachKindOfViolation) {
    using namespace status;
    EXPECT_TRUE(status_consistent(kAberrationApplied | kThermalApplied));
    EXPECT_TRUE(status_consistent(kNoVelocity | kVelocityInvalid | kNoTemperature | kTemperatureInvalid | kStale));
    EXPECT_TRUE(status_consistent(kAberrationApplied | kThermalOutOfRange));
    EXPECT_TRUE(status_consistent(kNoVelocity | kNoModelForHead));
    EXPECT_TRUE(status_consistent(kRejected));
    EXPECT_FALSE(status_consistent(kVelocityInvalid));                               // 32 without 4
    EXPECT_FALSE(status_consistent(kAberrationApplied | kTemperatureInvalid));       // 64 without 8
    EXPECT_FALSE(status_consistent(kAberrationApplied | kThermalApplied | kStale));  // 512 without 4 or 8
    EXPECT_FALSE(status_consistent(kAberrationApplied | kNoVelocity));               // applied and skipped
    EXPECT_FALSE(status_consistent(kThermalApplied | kThermalOutOfRange));           // applied and skipped
    EXPECT_FALSE(status_consistent(kNoTemperature | kNoModelForHead));               // two reasons
    EXPECT_FALSE(status_consistent(kRejected | kNoVelocity));
    EXPECT_FALSE(status_consistent(1024U));
    // One name per bit, the last one the highest bit defined.
    static_assert(kStale == 1U << (kStatusBitCount - 1), "a name for every bit");
    EXPECT_STREQ(kStatusBitNames[9], "stale");
}

template <typename T>
void expect_core_statuses_follow_the_rule(std::uint32_t* seen) {
    using Tr = ScalarTraits<T>;
    ThermalModel<T> model = host::to_core<T>(table2());
    model.head[2].gamma.c0 = Tr::coefficient(4000.0 * kArcsecToRad);  // head C beyond 1°: 128
    model.head[3].present = false;                                    // head D: 256
    std::mt19937_64 rng(7);
    std::uniform_int_distribution<int> pick(0, 7);
    for (int i = 0; i < 20000; ++i) {
        const Eigen::Quaterniond qe = random_attitude(rng);
        SolutionInput<T> in{};
        in.q_chu_icrf = {Tr::from_double(qe.w()), Tr::from_double(qe.x()), Tr::from_double(qe.y()),
                         Tr::from_double(qe.z())};
        if (pick(rng) == 0) {
            in.q_chu_icrf.w = Tr::from_double(2.0 * qe.w() + 0.1);  // not unit
        }
        in.head = static_cast<std::uint8_t>(pick(rng) % 5);  // 4: no such head
        const double temps[] = {10.0, -5.0, -20.0, 500.0, kNaN, 150.0, -190.0, 30.0};
        in.temperatures = {{Tr::celsius(temps[pick(rng)]), pick(rng) != 0},
                           {Tr::celsius(temps[pick(rng)]), true},
                           {Tr::celsius(temps[pick(rng)]), true}};
        const double betas[] = {1e-4, -3e-4, 0.0, 1.0, kNaN, 2e-3, 5e-5, -1e-4};
        in.velocity = {{Tr::from_double(betas[pick(rng)]), Tr::from_double(betas[pick(rng)]), Tr::from_double(1e-5)},
                       Tr::from_double(pick(rng) == 0 ? 1e9 : 1.0),
                       pick(rng) != 0};
        const CorrectionConfig<T> cfg{pick(rng) != 0, pick(rng) != 0 ? &model : nullptr};
        const StatusBits st = correct_solution(in, cfg).status;
        ASSERT_TRUE(status::status_consistent(st)) << "status " << st;
        for (int b = 0; b < status::kStatusBitCount; ++b) {
            seen[b] += (st >> b) & 1U;
        }
    }
}

TEST(StatusBits, EveryStatusTheCoreEmitsFollowsTheRule) {
    std::uint32_t seen[status::kStatusBitCount] = {};
    expect_core_statuses_follow_the_rule<double>(seen);
    expect_core_statuses_follow_the_rule<float>(seen);
    expect_core_statuses_follow_the_rule<Q30>(seen);
    // Every bit the core itself sets was exercised (512 is the callers').
    for (int b = 0; b < status::kStatusBitCount - 1; ++b) {
        EXPECT_GT(seen[b], 0U) << status::kStatusBitNames[b];
    }
}

TEST(BadInput, TemperatureCases) {
    const ThermalModel<double> model = host::to_core<double>(table2());
    const Quaternion<double> q{0.5, 0.5, 0.5, 0.5};
    using Case = HeadCase<HeadTemperatures<double>, StatusBits>;
    const double inf = std::numeric_limits<double>::infinity();
    const Case cases[] = {
        {"t_chu missing", {{0, false}, {-5, true}, {-20, true}}, 0, status::kNoTemperature},
        {"t_029 missing", {{10, true}, {0, false}, {-20, true}}, 1, status::kNoTemperature},
        {"t_032 missing", {{10, true}, {-5, true}, {0, false}}, 2, status::kNoTemperature},
        {"NaN marked valid",
         {{kNaN, true}, {-5, true}, {-20, true}},
         0,
         status::kNoTemperature | status::kTemperatureInvalid},
        {"inf", {{10, true}, {inf, true}, {-20, true}}, 0, status::kNoTemperature | status::kTemperatureInvalid},
        {"open circuit reading -273",
         {{10, true}, {-5, true}, {-273.15, true}},
         0,
         status::kNoTemperature | status::kTemperatureInvalid},
        {"short circuit reading 900",
         {{900, true}, {-5, true}, {-20, true}},
         0,
         status::kNoTemperature | status::kTemperatureInvalid},
        {"head D not in model", {{10, true}, {-5, true}, {-20, true}}, 3, status::kNoModelForHead},
        {"in domain", {{10, true}, {-5, true}, {-20, true}}, 2, status::kThermalApplied},
    };
    for (const Case& c : cases) {
        SolutionInput<double> in = input(q, c.head);
        in.temperatures = c.input;
        const auto out = correct_solution(in, CorrectionConfig<double>{false, &model});
        EXPECT_EQ(out.status, c.want) << c.what;
        if ((c.want & status::kThermalApplied) == 0) {
            EXPECT_LE(angle_arcsec(out.q_chu_icrf, q), 1e-12) << c.what;
        }
    }
}

TEST(BadInput, ThermalAngleOutOfDomainIsSkipped) {
    host::ModelFile m{};
    m.present = {true, false, false, false};
    m.coefficients[0][2][0] = 3601.0;  // gamma: just over 1 degree
    const ThermalModel<double> model = host::to_core<double>(m);
    const Quaternion<double> q{0.5, 0.5, 0.5, 0.5};
    const auto out = correct_solution(input(q, 0), CorrectionConfig<double>{false, &model});
    EXPECT_EQ(out.status, status::kThermalOutOfRange);
    EXPECT_LE(angle_arcsec(out.q_chu_icrf, q), 1e-12);
    m.coefficients[0][2][0] = 3599.0;
    const ThermalModel<double> model2 = host::to_core<double>(m);
    EXPECT_EQ(correct_solution(input(q, 0), CorrectionConfig<double>{false, &model2}).status, status::kThermalApplied);
}

// abs_within_bits (float bit patterns) and abs_within_bits_at (the same read
// from memory) against fabs(x) <= lim: the core's limits and the edges of
// lim ≥ 0, over the edges of x and every 4099th of the 2³² patterns (about a
// million, every exponent of both signs).
TEST(Core, FloatBitsWithinIsTheFabsOne) {
    const float inf = std::numeric_limits<float>::infinity();
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const std::vector<float> lims{constant<float>(kMaxThermalAngleRad),
                                  static_cast<float>(kMaxAbsTemperatureC),
                                  ScalarTraits<float>::unit_norm_tolerance,
                                  0.0F,
                                  -0.0F,
                                  std::numeric_limits<float>::denorm_min(),
                                  1.0F,
                                  std::numeric_limits<float>::max(),
                                  inf};
    std::vector<float> xs{0.0F,
                          -0.0F,
                          inf,
                          -inf,
                          nan,
                          -nan,
                          std::numeric_limits<float>::signaling_NaN(),
                          std::numeric_limits<float>::denorm_min(),
                          std::numeric_limits<float>::max(),
                          -std::numeric_limits<float>::max()};
    for (const float lim : lims) {
        for (const float x : {lim, std::nextafter(lim, inf), std::nextafter(lim, 0.0F)}) {
            xs.push_back(x);
            xs.push_back(-x);
        }
    }
    constexpr std::uint64_t kStride = 4099;  // prime: every exponent, both signs
    for (std::uint64_t bits = 0; bits < (std::uint64_t{1} << 32U); bits += kStride) {
        xs.push_back(__builtin_bit_cast(float, static_cast<std::uint32_t>(bits)));
    }
    for (const float lim : lims) {
        std::size_t inside = 0;
        for (const float x : xs) {
            const bool want = std::fabs(x) <= lim;
            inside += want ? 1U : 0U;
            ASSERT_EQ(abs_within_bits(x, lim), want) << x << " against " << lim;
            ASSERT_EQ(abs_within_bits_at(x, lim), want) << x << " in memory against " << lim;
        }
        // Both verdicts occur (not a sweep that only sees one side).
        EXPECT_GT(inside, 0U) << lim;
        EXPECT_LT(inside, xs.size()) << lim;
    }
}

}  // namespace
}  // namespace ascorr::test
