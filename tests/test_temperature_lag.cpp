// pipeline/temperature_lag.hpp against an independent reference: τ·dL/dt =
// T − L integrated by fourth-order Runge–Kutta in long double (substeps of
// at most τ/1000, the reading held at the newer value, as `simulate
// --bench-lag`), on an orbit-like reading with a jittered cadence, a gap and
// withheld readings; and every bad input's outcome.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>
#include <type_traits>
#include <vector>

#include "ascorr/pipeline/temperature_lag.hpp"

namespace {

using ascorr::HeadTemperatures;
using ascorr::pipeline::LagStep;
using ascorr::pipeline::TemperatureLag;

constexpr double kPi = 3.14159265358979323846;
constexpr double kOrbitS = 5700.0;

struct Sample {
    std::int64_t t_us;
    double temp[3];
    bool valid[3];
};

// Three channels: an orbit-periodic swing of 5, 2 and 1 °C on a slow drift.
// Times rounded to the millisecond when round_ms (22 Hz: steps of 45 and 46 ms).
std::vector<Sample> readings(double cadence_s, double days, std::uint32_t seed, double jitter_fraction = 0.3,
                             bool round_ms = false) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> jitter(-jitter_fraction, jitter_fraction);
    std::vector<Sample> out;
    const double amp[3] = {5.0, 2.0, 1.0};
    double next = 0.0;
    while (next < days * 86400.0) {
        const double t = next;
        next += cadence_s * (1.0 + jitter(rng));
        if (t > 20000.0 && t < 22000.0) {
            continue;  // a gap of 2000 s
        }
        Sample s{round_ms ? std::llround(t * 1e3) * 1000 : std::llround(t * 1e6), {}, {true, true, true}};
        for (int k = 0; k < 3; ++k) {
            s.temp[k] = 20.0 + 1e-5 * t + amp[k] * std::sin(2.0 * kPi * t / kOrbitS + k);
        }
        out.push_back(s);
    }
    return out;
}

// L after holding T over dt from l (RK4, long double): the reference.
long double rk4(long double l, long double temp, long double dt, long double tau) {
    // h ≤ τ/1000: RK4's error per substep ≤ (h/τ)⁵/120 of the deviation, below 1e-16.
    const auto n = static_cast<long>(std::max(4.0L, std::ceil(1000.0L * dt / tau)));
    const long double h = dt / static_cast<long double>(n);
    for (long i = 0; i < n; ++i) {
        const auto f = [&](long double x) { return (temp - x) / tau; };
        const long double k1 = f(l);
        const long double k2 = f(l + h / 2 * k1);
        const long double k3 = f(l + h / 2 * k2);
        const long double k4 = f(l + h * k3);
        l += h / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
    }
    return l;
}

// A reading in T's temperature format, and back in double.
template <typename T>
ascorr::Celsius<T> celsius(double x) {
    return ascorr::ScalarTraits<T>::celsius(x);
}
template <typename T>
double widened(const ascorr::Celsius<T>& x) {
    return ascorr::ScalarTraits<T>::to_double(x);
}

template <typename T>
HeadTemperatures<T> reading(const Sample& s) {
    return {
        {celsius<T>(s.temp[0]), s.valid[0]}, {celsius<T>(s.temp[1]), s.valid[1]}, {celsius<T>(s.temp[2]), s.valid[2]}};
}

// The largest |D − (L_ref − T)| over the samples, °C, per channel's valid
// readings; the reference holds each channel's newest valid reading.
template <typename T>
double worst_against_reference(const std::vector<Sample>& samples, double tau_s) {
    TemperatureLag<T> lag;
    EXPECT_TRUE(lag.configure(tau_s));
    long double l[3] = {};
    std::int64_t last[3] = {};
    bool started[3] = {};
    double worst = 0.0;
    for (const Sample& s : samples) {
        lag.step(s.t_us, reading<T>(s));
        for (std::uint8_t k = 0; k < 3; ++k) {
            if (!s.valid[k]) {
                continue;
            }
            // The reference sees the value the filter saw (float, Q30: rounded).
            const long double temp = widened<T>(celsius<T>(s.temp[k]));
            l[k] = started[k] ? rk4(l[k], temp, static_cast<long double>(s.t_us - last[k]) * 1e-6L, tau_s) : temp;
            started[k] = true;
            last[k] = s.t_us;
            const auto d = lag.deviation(k);
            EXPECT_TRUE(d.valid);
            const auto err =
                static_cast<double>(std::fabs(static_cast<long double>(widened<T>(d.value)) - (l[k] - temp)));
            worst = err <= worst ? worst : err;  // a NaN D makes worst NaN, and fails every bound
        }
    }
    return worst;
}

TEST(TemperatureLag, DoubleFollowsTheIntegratedLagToANanoKelvin) {
    auto samples = readings(1.0, 2.0, 7);
    for (std::size_t i = 5000; i < 9000; i += 7) {
        samples[i].valid[1] = false;  // T029 withheld now and then: held, then advanced over the interval
    }
    // A steady cadence (α formed once, then reused) and 22 Hz at millisecond
    // times (45 and 46 ms alternating: both α kept) beside the jittered one.
    const auto steady = readings(0.5, 1.0, 3, 0.0);
    const auto rounded = readings(1.0 / 22.0, 0.2, 5, 0.0, true);
    for (double tau : {300.0, 900.0, 1800.0}) {
        EXPECT_LT(worst_against_reference<double>(samples, tau), 1e-9) << tau;
        EXPECT_LT(worst_against_reference<double>(steady, tau), 1e-9) << tau;
        EXPECT_LT(worst_against_reference<double>(rounded, tau), 1e-9) << tau;
    }
}

// Float at 22 Hz (α ≈ 5e-5 at τ = 900 s): the deviation form keeps D's
// relative precision. Each step rounds u − α·u by ≤ 2⁻²⁴·|u|; forgetting at
// α, that sums to ≤ 2⁻²⁴·max|D|/α ≈ 6e-8 · 3.2 / 5e-5 ≈ 4e-3 °C if every
// rounding had one sign; they do not: measured 1.9e-5 °C (the plain form
// 1.6e-4 °C, its rounding of L ≈ 20 °C instead of D).
TEST(TemperatureLag, FloatAt22HzKeepsTheDeviationsPrecision) {
    const auto samples = readings(1.0 / 22.0, 0.5, 11);
    const double worst = worst_against_reference<float>(samples, 900.0);
    EXPECT_LT(worst, 3e-5);
    // Mutation check: the plain form L ← L + α·(T − L) in float, with the same
    // α, rounds L (20 °C) where the deviation form rounds D: it misses the bound.
    float l = static_cast<float>(samples[0].temp[0]);
    long double ref = l;
    double plain_worst = 0.0;
    for (std::size_t i = 1; i < samples.size(); ++i) {
        const double dt = static_cast<double>(samples[i].t_us - samples[i - 1].t_us) * 1e-6;
        const float temp = static_cast<float>(samples[i].temp[0]);
        const float alpha = -std::expm1(-static_cast<float>(dt) / 900.0F);
        l += alpha * (temp - l);
        ref = rk4(ref, temp, dt, 900.0L);
        plain_worst = std::max(plain_worst, static_cast<double>(std::fabs(l - ref)));
    }
    EXPECT_GT(plain_worst, 3 * 3e-5);
}

// Q30 (QCelsius readings, Q30 α, D in int64 at 2⁻⁵⁰ °C) at 22 Hz at
// millisecond times, τ = 900 s and a day (α ≈ 5e-5 and 5e-7). The error is
// α's rounding (a relative error of τ ≤ 2⁻³¹·τ/Δt: 1e-5 and 9e-4) times D,
// plus D's and T's rounding to QCelsius (≤ 2⁻²¹ °C each): measured 1.3e-5
// and 1.4e-5 °C, against a bound of 3e-5 °C, the float path's (0.15 mas of a
// 5"/°C coefficient).
TEST(TemperatureLag, Q30At22HzIsWithinItsResolution) {
    using ascorr::Q30;
    const auto samples = readings(1.0 / 22.0, 0.5, 13, 0.0, true);
    EXPECT_LT(worst_against_reference<Q30>(samples, 900.0), 3e-5);
    EXPECT_LT(worst_against_reference<Q30>(samples, 86400.0), 3e-5);
    // Mutation check: D held in QCelsius itself (int32, 2⁻²⁰ °C), with the
    // same rounded product: a step whose α·u is below half an LSB does not
    // decay, a dead band of 0.5/α LSB (0.01 °C at 900 s), far past the bound.
    std::int32_t d = 0;
    std::int32_t last = celsius<Q30>(samples[0].temp[0]).raw;
    long double ref = widened<Q30>(celsius<Q30>(samples[0].temp[0]));
    double narrow_worst = 0.0;
    for (std::size_t i = 1; i < samples.size(); ++i) {
        const double dt = static_cast<double>(samples[i].t_us - samples[i - 1].t_us) * 1e-6;
        const ascorr::QCelsius temp = celsius<Q30>(samples[i].temp[0]);
        const Q30 alpha = ascorr::ScalarTraits<Q30>::from_double(-std::expm1(-dt / 900.0));
        const std::int32_t u = d - (temp.raw - last);
        d = u - ascorr::fx::narrow<30>(0, alpha.raw, u);
        last = temp.raw;
        ref = rk4(ref, widened<Q30>(temp), dt, 900.0L);
        narrow_worst = std::max(narrow_worst, std::fabs(static_cast<double>((last + d) * 0x1p-20L - ref)));
    }
    EXPECT_GT(narrow_worst, 10 * 3e-5);
}

// α from its series in float and Q30 (Δt ≤ τ/256, no double on the step)
// against expm1 in long double, over every τ the lag takes and Δt from a
// microsecond to τ/256: Q30 within half an LSB plus k's rounding (2⁵¹/τ to
// an integer: 2e-5 relative at a day), float within 4 roundings of 2⁻²⁴.
TEST(TemperatureLag, AlphaSeriesIsWithinItsFormatsResolution) {
    using ascorr::Q30;
    using ascorr::pipeline::LagArithmetic;
    double worst_q30 = 0.0;
    double worst_float = 0.0;
    for (double tau_s : {1.0, 7.3, 300.0, 900.0, 1800.0, 6048.0, 86400.0}) {
        const double tau_us = tau_s * 1e6;
        const auto q30 = LagArithmetic<Q30>::AlphaSeries::of(tau_us);
        const auto f = LagArithmetic<float>::AlphaSeries::of(tau_us);
        const auto longest = static_cast<std::int32_t>(tau_us * ascorr::pipeline::kSeriesFraction);
        for (int i = 0; i <= 400; ++i) {
            const auto dt = std::max(std::int32_t{1}, static_cast<std::int32_t>(longest * std::pow(1e-7, i / 400.0)));
            const long double exact = -std::expm1l(-static_cast<long double>(dt) / tau_us);
            const double a_q30 = ascorr::ScalarTraits<Q30>::to_double(q30(dt));
            const double q30_bound = 0x1p-31 + 2.0 / (0x1p51 / tau_us) * static_cast<double>(exact);
            worst_q30 = std::max(worst_q30, static_cast<double>(std::fabs(a_q30 - exact)) / q30_bound);
            const double a_f = static_cast<double>(f(dt));
            worst_float = std::max(worst_float, static_cast<double>(std::fabs(a_f - exact) / exact) / (4 * 0x1p-24));
        }
    }
    EXPECT_LE(worst_q30, 1.0);
    EXPECT_LE(worst_float, 1.0);
}

// The lag as first written (6a379b0): every channel with its own last time,
// α formed for each channel's own Δt; the reference of the bookkeeping that
// replaced it (a time per lag, channels in step, the straight usual step),
// which in double must give the same bits for any sequence.
class ChannelwiseLag {
public:
    explicit ChannelwiseLag(double tau_s) : inv_tau_per_us_(1.0 / (tau_s * 1e6)) {}
    LagStep step(std::uint8_t k, std::int64_t t_us, double reading, bool valid) {
        Channel& c = ch_[k];
        if (!(t_us > -ascorr::pipeline::kMaxLagTimeUs && t_us < ascorr::pipeline::kMaxLagTimeUs)) {
            return LagStep::kBadTime;
        }
        if (!valid || !ascorr::temperature_in_domain<double>(reading)) {
            return LagStep::kHeld;
        }
        if (!c.started) {
            c = {0.0, reading, t_us, true};
            return LagStep::kStarted;
        }
        if (t_us <= c.t_us) {
            return LagStep::kTimeNotIncreasing;
        }
        const double alpha = -ascorr::calib::expm1_nonpositive(-static_cast<double>(t_us - c.t_us) * inv_tau_per_us_);
        const double u = c.d - (reading - c.t_reading);
        c = {u - alpha * u, reading, t_us, true};
        return LagStep::kAdvanced;
    }
    double lagged(std::uint8_t k) const { return ch_[k].t_reading + ch_[k].d; }
    bool started(std::uint8_t k) const { return ch_[k].started; }

private:
    struct Channel {
        double d = 0.0;
        double t_reading = 0.0;
        std::int64_t t_us = 0;
        bool started = false;
    };
    double inv_tau_per_us_;
    Channel ch_[3];
};

// Random sequences: 22 Hz steps, tiny and long ones, repeats, times going
// back, readings withheld, NaN, beyond the domain, at its edge.
struct Sequence {
    std::mt19937_64 rng;
    std::int64_t t = 0;
    double temp[3] = {20.0, 21.0, 22.0};
    double u() { return std::uniform_real_distribution<double>(0.0, 1.0)(rng); }
    std::int64_t next_time() {
        const double r = u();
        if (r < 0.6) {
            t += r < 0.3 ? 45'000 : 46'000;
        } else if (r < 0.7) {
            t += 1 + static_cast<std::int64_t>(u() * 100);
        } else if (r < 0.78) {
            t -= static_cast<std::int64_t>(u() * 200'000);  // a repeat, or back
        } else if (r < 0.88) {
            t += static_cast<std::int64_t>(u() * 4e11);  // a gap, up to 4.6 days
        } else {
            t += static_cast<std::int64_t>(u() * 4e8);  // around τ/256 at a day
        }
        return t;
    }
    void next_readings(double out[3], bool valid[3]) {
        for (int k = 0; k < 3; ++k) {
            const double r = u();
            temp[k] = r < 0.85 ? temp[k] + (u() - 0.5) * 0.01 : r < 0.93 ? (u() - 0.5) * 400.0 : 200.0;
            out[k] = u() < 0.02 ? std::nan("") : u() < 0.02 ? 250.0 : temp[k];
            valid[k] = u() < 0.85;
        }
    }
};

template <typename T>
HeadTemperatures<T> of(const double v[3], const bool ok[3]) {
    return {{celsius<T>(v[0]), ok[0]}, {celsius<T>(v[1]), ok[1]}, {celsius<T>(v[2]), ok[2]}};
}

template <typename T>
bool same(const ascorr::Celsius<T>& a, const ascorr::Celsius<T>& b) {
    return std::memcmp(&a, &b, sizeof a) == 0;
}

// lag_in_place (its straight usual step, or the general one) against step()
// and lagged() of a second lag fed alike, bit for bit, in T; in double both
// also against ChannelwiseLag.
template <typename T>
std::size_t differences(std::uint64_t seed, double tau_s, int steps) {
    Sequence seq{std::mt19937_64(seed)};
    TemperatureLag<T> in_place;
    TemperatureLag<T> stepped;
    ChannelwiseLag reference(tau_s);
    EXPECT_TRUE(in_place.configure(tau_s) && stepped.configure(tau_s));
    std::size_t n = 0;
    for (int i = 0; i < steps; ++i) {
        const std::int64_t t = seq.next_time();
        double v[3];
        bool ok[3];
        seq.next_readings(v, ok);
        HeadTemperatures<T> a = of<T>(v, ok);
        const bool taken = in_place.lag_in_place(t, a);
        const bool earlier = stepped.before_last(t);
        const auto s = earlier ? ascorr::pipeline::LagSteps{} : stepped.step(t, of<T>(v, ok));
        const ascorr::TemperatureReading<T>* got[3] = {&a.t_chu, &a.t_029, &a.t_032};
        for (std::uint8_t k = 0; k < 3; ++k) {
            const bool took = !earlier && s.channel[k] != LagStep::kHeld && s.channel[k] != LagStep::kBadTime;
            n += taken != (!earlier && s.channel[0] != LagStep::kBadTime) ? 1U : 0U;
            const ascorr::Celsius<T> want = took ? stepped.lagged(k).value : celsius<T>(v[k]);
            n += same<T>(got[k]->value, want) ? 0U : 1U;
            if constexpr (std::is_same_v<T, double>) {
                if (!earlier) {
                    const LagStep r = reference.step(k, t, v[k], ok[k]);
                    n += r == s.channel[k] ? 0U : 1U;
                    n += !reference.started(k) || same<double>(reference.lagged(k), stepped.lagged(k).value) ? 0U : 1U;
                }
            }
        }
    }
    return n;
}

TEST(TemperatureLag, TheTimeOfALagAndItsStraightStepAreTheChannelwiseLagsBits) {
    for (std::uint64_t seed = 1; seed <= 60; ++seed) {
        const double tau = seed % 3 == 0 ? 1.0 : seed % 3 == 1 ? 900.0 : 86400.0;
        EXPECT_EQ(differences<double>(seed, tau, 3000), 0U) << seed;
        EXPECT_EQ(differences<float>(seed, tau, 3000), 0U) << seed;
        EXPECT_EQ(differences<ascorr::Q30>(seed, tau, 3000), 0U) << seed;
    }
}

TEST(TemperatureLag, EachBadInputLeavesItsChannelAsItWas) {
    TemperatureLag<double> lag;
    const HeadTemperatures<double> ok{{20.0, true}, {21.0, true}, {22.0, true}};
    EXPECT_EQ(lag.step(0, ok).channel[0], LagStep::kNotConfigured);
    EXPECT_FALSE(lag.deviation(0).valid);
    for (double tau : {0.0, -1.0, 1e-300, 0.999, std::nan(""), ascorr::pipeline::kMaxLagTauS * 1.000001}) {
        EXPECT_FALSE(lag.configure(tau)) << tau;
        EXPECT_EQ(lag.step(0, ok).channel[2], LagStep::kNotConfigured);
    }
    ASSERT_TRUE(lag.configure(600.0));
    EXPECT_EQ(lag.step(1'000'000, ok).channel[0], LagStep::kStarted);
    // T1 steps by 1 °C, held 60 s: L = 20 + (1 − e^(−0.1)), D = L − 21 = −e^(−0.1).
    HeadTemperatures<double> next = ok;
    next.t_chu.value = 21.0;
    next.t_029 = {std::nan(""), true};  // NaN: held
    next.t_032 = {22.0 + 1e3, true};    // beyond ±200 °C: held
    const auto s = lag.step(61'000'000, next);
    EXPECT_EQ(s.channel[0], LagStep::kAdvanced);
    EXPECT_EQ(s.channel[1], LagStep::kHeld);
    EXPECT_EQ(s.channel[2], LagStep::kHeld);
    EXPECT_NEAR(lag.deviation(0).value, -std::exp(-0.1), 1e-15);
    EXPECT_NEAR(lag.lagged(0).value, 20.0 + (1.0 - std::exp(-0.1)), 1e-13);
    EXPECT_EQ(lag.deviation(1).value, 0.0);
    // Not after the channel's last time, or no time of an epoch: unchanged.
    const double d0 = lag.deviation(0).value;
    const HeadTemperatures<double> t1_only{{25.0, true}, {0.0, false}, {0.0, false}};
    EXPECT_EQ(lag.step(61'000'000, t1_only).channel[0], LagStep::kTimeNotIncreasing);
    EXPECT_EQ(lag.step(-5, t1_only).channel[0], LagStep::kTimeNotIncreasing);
    EXPECT_EQ(lag.step(INT64_MAX, t1_only).channel[0], LagStep::kBadTime);
    EXPECT_EQ(lag.step(INT64_MIN, t1_only).channel[0], LagStep::kBadTime);
    EXPECT_EQ(lag.deviation(0).value, d0);
    // The held T2 advances over its whole interval at its next reading (121 s).
    HeadTemperatures<double> later = ok;
    later.t_029.value = 23.0;
    EXPECT_EQ(lag.step(121'000'000, later).channel[1], LagStep::kAdvanced);
    EXPECT_NEAR(lag.deviation(1).value, -2.0 * std::exp(-120.0 / 600.0), 1e-14);
    // A τ out of range changes nothing.
    EXPECT_FALSE(lag.configure(0.0));
    EXPECT_TRUE(lag.deviation(1).valid);
    EXPECT_NEAR(lag.deviation(1).value, -2.0 * std::exp(-120.0 / 600.0), 1e-14);
    // A channel out of range asks for none.
    EXPECT_FALSE(lag.deviation(3).valid);
    EXPECT_FALSE(lag.lagged(200).valid);
    // A gap of 10⁶ τ forgets: α = 1 exactly, D = 0.
    EXPECT_EQ(lag.step(121'000'000 + 600'000'000'000'000, later).channel[0], LagStep::kAdvanced);
    EXPECT_EQ(lag.deviation(0).value, 0.0);
    // An accepted τ starts every channel again.
    ASSERT_TRUE(lag.configure(300.0));
    EXPECT_FALSE(lag.deviation(0).valid);
    EXPECT_EQ(lag.step(0, ok).channel[1], LagStep::kStarted);
}

// α's e^x − 1 with + − × ÷ alone (calib/portable_math.hpp) against the
// C library's expm1l in long double: relative error ≲ (k + 2)·2⁻⁵³, k ≤ 20.
TEST(TemperatureLag, PortableExpm1IsWithinItsBoundOfLongDouble) {
    using ascorr::calib::expm1_nonpositive;
    double worst = 0.0;
    for (int i = 0; i <= 20000; ++i) {
        const double x = -std::pow(10.0, -16.0 + 18.8 * i / 20000.0);  // −1e-16 … −630
        const long double ref = std::expm1l(static_cast<long double>(x));
        const auto rel = static_cast<double>(std::fabs((static_cast<long double>(expm1_nonpositive(x)) - ref) / ref));
        worst = rel <= worst ? worst : rel;
    }
    EXPECT_LT(worst, 22 * 0x1p-53);
    EXPECT_EQ(expm1_nonpositive(0.0), 0.0);
    EXPECT_EQ(expm1_nonpositive(1.0), 0.0);  // outside its domain
    EXPECT_EQ(expm1_nonpositive(-746.0), -1.0);
    EXPECT_EQ(expm1_nonpositive(-std::numeric_limits<double>::infinity()), -1.0);
    EXPECT_TRUE(std::isnan(expm1_nonpositive(std::nan(""))));
}

TEST(TemperatureLag, TimesAtTheLimitsStepWithoutOverflow) {
    using ascorr::pipeline::kMaxLagTimeUs;
    TemperatureLag<float> lag;
    ASSERT_TRUE(lag.configure(900.0));
    const HeadTemperatures<float> ok{{20.0F, true}, {21.0F, true}, {22.0F, true}};
    EXPECT_EQ(lag.step(-kMaxLagTimeUs, ok).channel[0], LagStep::kBadTime);
    EXPECT_EQ(lag.step(-(kMaxLagTimeUs - 1), ok).channel[0], LagStep::kStarted);
    // The largest step there is (9.2e18 µs): t − t_last within int64, α = 1.
    EXPECT_EQ(lag.step(kMaxLagTimeUs - 1, ok).channel[0], LagStep::kAdvanced);
    EXPECT_EQ(lag.deviation(0).value, 0.0F);
    EXPECT_EQ(lag.step(kMaxLagTimeUs, ok).channel[0], LagStep::kBadTime);
}

// Q30 at the ends of its ranges (the sanitizers' builds trap any overflow):
// readings swinging across the whole domain, ±200 °C, at every α from a
// microsecond against a day to α = 1; D stays within ±400 °C and L within
// the readings' hull, and a step with α = 1 forgets exactly.
TEST(TemperatureLag, Q30AtTheEndsOfItsRangesNeitherOverflowsNorLeavesTheHull) {
    using ascorr::Q30;
    const double edge = ascorr::kMaxAbsTemperatureC;
    for (double tau : {1.0, 900.0, ascorr::pipeline::kMaxLagTauS}) {
        TemperatureLag<Q30> lag;
        ASSERT_TRUE(lag.configure(tau));
        std::int64_t t = 0;
        for (int i = 0; i < 2000; ++i) {
            const double v = (i % 2 == 0 ? edge : -edge);
            const HeadTemperatures<Q30> r{{celsius<Q30>(v), true}, {celsius<Q30>(-v), true}, {celsius<Q30>(v), true}};
            t += i % 3 == 0 ? 1 : 1'000'000;  // a microsecond, a second
            ASSERT_NE(lag.step(t, r).channel[0], LagStep::kHeld);
            for (std::uint8_t k = 0; k < 3; ++k) {
                const double l = widened<Q30>(lag.lagged(k).value);
                ASSERT_LE(std::fabs(l), edge + 0x1p-20) << tau << " " << i;
                ASSERT_LE(std::fabs(widened<Q30>(lag.deviation(k).value)), 2 * edge + 0x1p-20);
            }
        }
        const HeadTemperatures<Q30> last{
            {celsius<Q30>(12.5), true}, {celsius<Q30>(-3.0), true}, {celsius<Q30>(0.0), true}};
        EXPECT_EQ(lag.step(t + 1'000'000'000'000'000, last).channel[2], LagStep::kAdvanced);  // 10⁹ s: α = 1
        EXPECT_EQ(lag.deviation(0).value.raw, 0);
        EXPECT_EQ(lag.lagged(1).value.raw, celsius<Q30>(-3.0).raw);
    }
}

}  // namespace
