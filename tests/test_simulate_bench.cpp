// `ascorr simulate`'s bench inside the orbit (--bench-lag, --orbit-term) and
// its noise-only IBAs (--noise-iba, `stats --noise-iba`), each measured
// against what the test computes itself: the floor the summary states, the
// orbit term's first-order IBA change from the heads' geometry and the Sun
// (liberfa), the lag as the test's own first-order filter of the static
// bench's deformation.
#include <erfa.h>
#include <erfam.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <complex>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "ascorr/nav/orbit_propagation.hpp"
#include "ascorr_host/analysis/simulate.hpp"
#include "ascorr_host/analysis/stats.hpp"
#include "ascorr_host/formats/solutions_csv.hpp"
#include "cli_run.hpp"
#include "test_support.hpp"

namespace ascorr::test {
namespace {

namespace fs = std::filesystem;

constexpr double kDays = 3.0;

// A 3-day mission (seed 1) of the heads `heads` with the dynamics given, its noise-only IBAs written.
std::string mission(const fs::path& dir, const std::string& name, double lag_s, double orbit_arcsec,
                    HeadMask heads = host::kPaperHeads) {
    host::SimulateOptions o;
    o.out = (dir / name).string();
    o.days = kDays;
    o.heads = heads;
    o.bench.lag_s = lag_s;
    o.bench.orbit_arcsec = orbit_arcsec;
    o.noise_iba = true;
    (void)host::simulate(o);
    return o.out;
}

// Per pair of the file's heads (stats' pairs), t (ms) → the stage's IBA minus
// the noise-only IBA (arcsec), with the truth model's thermal stage (stage 2)
// or the aberration stage alone (1).
std::array<std::map<long long, double>, host::kMaxPairs> residuals(const std::string& data, std::size_t stage,
                                                                   host::PairList* pairs = nullptr) {
    host::StatsOptions s;
    s.in = data;
    s.model = data + ".truth.csv";
    s.keep_series = true;
    std::ostringstream log;
    const host::StatsResult r = host::compute_stats(s, log);
    const auto noise = host::read_noise_iba(data + ".noise-iba.csv", r.pairs);
    std::array<std::map<long long, double>, host::kMaxPairs> out;
    for (std::size_t p = 0; p < r.pairs.count; ++p) {
        const host::PairSeries& series = r.series[p];
        for (std::size_t k = 0; k < series.t.size(); ++k) {
            const long long key = std::llround(series.t[k] * 1000.0);
            const double* n = host::noise_iba_at(noise[p], key);
            if (n == nullptr) {
                ADD_FAILURE() << host::pair_name(r.pairs.pair[p]) << ": a clean epoch without a noise-only IBA, t "
                              << series.t[k];
                continue;
            }
            out[p][key] = series.iba[stage][k] - *n;
        }
    }
    if (pairs != nullptr) {
        *pairs = r.pairs;
    }
    return out;
}

double rms_about_mean(const std::vector<double>& v) {
    double m = 0.0;
    for (double x : v) {
        m += x;
    }
    m /= static_cast<double>(v.size());
    double ss = 0.0;
    for (double x : v) {
        ss += (x - m) * (x - m);
    }
    return std::sqrt(ss / static_cast<double>(v.size()));
}

TEST(SimulateBench, NoiseIbasAreTheFloorsAndTheTruthLeavesNoSystematicResidual) {
    const fs::path dir = scratch_dir("bench-noise");
    const std::string data = mission(dir, "m.csv", 0.0, 0.0);
    const auto noise = host::read_noise_iba(data + ".noise-iba.csv");
    // The floor the summary wrote, from the test's own RMS of the noise-only IBAs.
    const std::string floor = slurp(data + ".floor.json");
    for (std::size_t p = 0; p < host::kPaperPairs.count; ++p) {
        std::vector<double> v;
        for (const auto& kv : noise[p]) {
            v.push_back(kv.second);
        }
        ASSERT_GT(v.size(), 500U);
        char rms[64];
        std::snprintf(rms, sizeof rms, "\"%s\": {\"rms\": %.6f", host::pair_name(host::kPaperPairs.pair[p]).c_str(),
                      rms_about_mean(v));
        EXPECT_NE(floor.find(rms), std::string::npos) << rms << " in " << floor;
    }
    host::StatsOptions s;
    s.in = data;
    s.model = data + ".truth.csv";
    s.noise_iba = data + ".noise-iba.csv";
    std::ostringstream log;
    const host::StatsResult r = host::compute_stats(s, log);
    ASSERT_TRUE(r.systematic);
    for (std::size_t p = 0; p < host::kPaperPairs.count; ++p) {
        EXPECT_EQ(r.systematic_n[p], r.n[p]) << p;
        EXPECT_LT(r.systematic_rms[p][2].rms, 1e-5) << p;  // the 6 decimals written
        EXPECT_GT(r.systematic_rms[p][1].rms, 0.05) << p;  // the deformation, uncorrected (A-C: 0.08")
    }
    // Without --noise-iba: the same eight files, byte for byte.
    host::SimulateOptions o;
    o.out = (dir / "plain.csv").string();
    o.days = kDays;
    (void)host::simulate(o);
    for (const char* suffix : {"", ".truth.csv", ".truth-history.csv", ".floor.json", ".floor-daily.csv",
                               ".heaters.csv", ".mountings.csv", ".attitude.csv"}) {
        EXPECT_EQ(slurp(data + suffix), slurp(o.out + suffix)) << suffix;
    }
    EXPECT_FALSE(fs::exists(o.out + ".noise-iba.csv"));
}

// Sun direction (GCRS) at t s since J2000 TT, from liberfa.
Eigen::Vector3d sun_at(double t) {
    double pvh[2][3];
    double pvb[2][3];
    eraEpv00(ERFA_DJ00, t / 86400.0, pvh, pvb);
    return -Eigen::Vector3d(pvh[0][0], pvh[0][1], pvh[0][2]).normalized();
}

// d(IBA)/dθ of pair (i, j) when each head h turns by θ about its documented
// axis a_h (head axes; q ← q(θ·a_h) ⊗ q; A x, B y, C (y − x)/√2, D −A's): a
// boresight moves by −θ·M_hᵀ·(a_h × e_z) in the body frame (docs/contract.md, simulate).
double iba_per_orbit_term(int i, int j) {
    const double r = std::sqrt(0.5);
    const Eigen::Vector3d axis[4] = {
        Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(), {-r, r, 0.0}, -Eigen::Vector3d::UnitX()};
    const auto z = [](int h) { return Eigen::Vector3d(host::head_mounting(h).row(2).transpose()); };
    const auto dz = [&](int h) {
        return Eigen::Vector3d(-host::head_mounting(h).transpose() * axis[h].cross(Eigen::Vector3d::UnitZ()));
    };
    const double c = z(i).dot(z(j));
    return -(dz(i).dot(z(j)) + z(i).dot(dz(j))) / std::sqrt(1.0 - c * c);
}

TEST(SimulateBench, OrbitTermIsTheSunAlongTheOrbitThatNoThermistorReads) {
    const fs::path dir = scratch_dir("bench-orbit");
    constexpr double kAmplitude = 0.8;
    constexpr HeadMask kAbcd = 0b1111U;
    const std::string data = mission(dir, "orbit.csv", 0.0, kAmplitude, kAbcd);
    const std::string plain = mission(dir, "plain.csv", 0.0, 0.0, kAbcd);
    EXPECT_EQ(slurp(data + ".floor.json"), slurp(plain + ".floor.json"));
    EXPECT_EQ(slurp(data + ".noise-iba.csv"), slurp(plain + ".noise-iba.csv"));
    // The recorded temperatures are those of the static bench.
    std::map<std::pair<long long, int>, std::array<double, 3>> temps;
    std::map<long long, Eigen::Vector3d> v_hat;
    host::for_each_solution(
        plain,
        [&](const host::SolutionRecord& rec) {
            temps[{std::llround(rec.t * 1000.0), rec.head}] = rec.temperature;
        },
        "plain");
    std::size_t same = 0;
    host::for_each_solution(
        data,
        [&](const host::SolutionRecord& rec) {
            same += temps.at({std::llround(rec.t * 1000.0), rec.head}) == rec.temperature ? 1U : 0U;
            const Eigen::Vector3d v(rec.v_sc_kms.x, rec.v_sc_kms.y, rec.v_sc_kms.z);
            v_hat[std::llround(rec.t * 1000.0)] = v.normalized();
        },
        "orbit");
    EXPECT_EQ(same, temps.size());
    // The truth model removes the rest: the residual is A·(v̂·ŝ)·dIBA/dθ, every pair of A, B, C and D.
    host::PairList pairs;
    const auto res = residuals(data, 2, &pairs);
    ASSERT_EQ(pairs.count, 6U);
    for (std::size_t p = 0; p < pairs.count; ++p) {
        const auto& pair = pairs.pair[p];
        const double k = iba_per_orbit_term(pair.first, pair.second);
        double sxy = 0.0;
        double sxx = 0.0;
        std::vector<double> misfit;
        for (const auto& kv : res[p]) {
            const double s = kAmplitude * v_hat.at(kv.first).dot(sun_at(static_cast<double>(kv.first) / 1000.0));
            sxy += s * kv.second;
            sxx += s * s;
            misfit.push_back(kv.second - s * k);
        }
        ASSERT_GT(misfit.size(), 300U) << host::pair_name(pair);
        std::printf("%s: slope %.4f, geometry %.4f, misfit %.2e arcsec\n", host::pair_name(pair).c_str(), sxy / sxx, k,
                    rms_about_mean(misfit));
        EXPECT_NEAR(sxy / sxx, k, 0.002 + 0.002 * std::fabs(k)) << host::pair_name(pair);
        EXPECT_LT(rms_about_mean(misfit), 0.001) << host::pair_name(pair);
    }
}

// The complex amplitude of the orbit frequency ω in v(t), by least squares on
// [1, t, cos ωt, sin ωt] over the epochs it has (gaps and blinded heads do not matter).
std::complex<double> orbit_harmonic(const std::map<long long, double>& v, double omega) {
    Eigen::Matrix4d ata = Eigen::Matrix4d::Zero();
    Eigen::Vector4d atb = Eigen::Vector4d::Zero();
    const double t0 = static_cast<double>(v.begin()->first) / 1000.0;
    for (const auto& kv : v) {
        const double t = static_cast<double>(kv.first) / 1000.0 - t0;
        const Eigen::Vector4d a(1.0, t / 86400.0, std::cos(omega * t), std::sin(omega * t));
        ata += a * a.transpose();
        atb += a * kv.second;
    }
    const Eigen::Vector4d x = ata.ldlt().solve(atb);
    return {x(2), -x(3)};  // v ≈ Re(c·e^(iωt))
}

TEST(SimulateBench, LagIsAFirstOrderFilterOfTheStaticBench) {
    const fs::path dir = scratch_dir("bench-lag");
    constexpr double kTau = 900.0;
    constexpr double kStep = 60.0;
    const std::string lagged = mission(dir, "lag.csv", kTau, 0.0);
    const std::string plain = mission(dir, "plain.csv", 0.0, 0.0);
    // The static bench's deformation D (the aberration stage's residual) at
    // the orbit frequency, and what the truth model at the recorded
    // temperatures leaves of the lagged bench, (H − 1)·D, H the response of
    // the filter sampled every step: g / (1 − (1 − g)·e^(−iωΔ)), g = 1 − e^(−Δ/τ).
    const double a = kEarthEquatorialRadiusKm + host::kSimAltitudeKm;
    const double omega = std::sqrt(kEarthGmKm3S2 / (a * a * a));
    const double g = -std::expm1(-kStep / kTau);
    const std::complex<double> h = g / (1.0 - (1.0 - g) * std::exp(std::complex<double>(0.0, -omega * kStep)));
    const auto d = residuals(plain, 1);
    const auto r = residuals(lagged, 2);
    for (std::size_t p = 0; p < host::kPaperPairs.count; ++p) {
        const std::complex<double> cd = orbit_harmonic(d[p], omega);
        const std::complex<double> cr = orbit_harmonic(r[p], omega);
        const std::complex<double> expected = (h - 1.0) * cd;
        std::printf(
            "%s: deformation %.3f arcsec at the orbit frequency; left by the lag %.3f at %.1f deg, "
            "expected %.3f at %.1f deg\n",
            host::pair_name(host::kPaperPairs.pair[p]).c_str(), std::abs(cd), std::abs(cr), std::arg(cr) * 180.0 / kPi,
            std::abs(expected), std::arg(expected) * 180.0 / kPi);
        EXPECT_GT(std::abs(cd), 0.05) << p;
        EXPECT_LT(std::abs(cr - expected), 0.05 * std::abs(expected)) << p;
    }
}

// The lag runs on through a --gap: after it, every row is the same mission's without it.
TEST(SimulateBench, LagRunsOnThroughAGap) {
    const fs::path dir = scratch_dir("bench-gap");
    host::SimulateOptions o;
    o.days = 2.0;
    o.bench.lag_s = 1800.0;
    o.out = (dir / "whole.csv").string();
    (void)host::simulate(o);
    const std::string whole = o.out;
    o.gaps = {{0.5, 1.0}};
    o.out = (dir / "gap.csv").string();
    (void)host::simulate(o);
    const auto after = [](const std::string& file) {
        std::string rows;
        for (const std::string& line : lines_of_file(file)) {
            const double t = std::strtod(line.c_str(), nullptr);
            rows += t >= host::kDefaultSimStartT + 86400.0 ? line + "\n" : std::string();
        }
        return rows;
    };
    EXPECT_GT(after(whole).size(), 100000U);
    EXPECT_EQ(after(o.out), after(whole));
}

TEST(SimulateBench, BadDynamicsAreUsageErrorsThatWriteNothing) {
    const fs::path dir = scratch_dir("bench-bad");
    const std::string data = (dir / "m.csv").string();
    const std::pair<std::string, std::string> cases[] = {
        {"--bench-lag -1", "--bench-lag: -1 is out of range"},
        {"--bench-lag 1e6", "--bench-lag: 1e6 is out of range"},
        {"--orbit-term nan", "--orbit-term: nan is out of range: the range is [0, 60]"},
        {"--orbit-term 61", "--orbit-term: 61 is out of range"},
    };
    for (const auto& c : cases) {
        EXPECT_EQ(run_cli("simulate --days 1 --noise-iba " + c.first + " --out " + data, dir), 2) << c.first;
        const std::string err = slurp(dir / "err.txt");
        EXPECT_NE(err.find(c.second), std::string::npos) << c.first << ": " << err;
    }
    for (const char* suffix : {"", ".truth.csv", ".truth-history.csv", ".floor.json", ".floor-daily.csv",
                               ".heaters.csv", ".mountings.csv", ".attitude.csv", ".noise-iba.csv"}) {
        EXPECT_FALSE(fs::exists(data + suffix)) << suffix;
    }
    // The API refuses them too, naming the option.
    host::SimulateOptions o;
    o.out = data;
    o.bench.lag_s = -5.0;
    EXPECT_NE(
        message_of<std::exception>([&] { host::refuse_bad_events(o); }, "").find("--bench-lag must be in [0, 86400] s"),
        std::string::npos);
    o.bench = {0.0, 100.0};
    EXPECT_NE(message_of<std::exception>([&] { host::refuse_bad_events(o); }, "")
                  .find("--orbit-term must be in [0, 60] arcsec"),
              std::string::npos);
}

// `stats --noise-iba` on the command line: the JSON's systematic block, and
// every malformed file refused at its line and column (exit 1, nothing on
// standard output), with --combined a usage error.
TEST(SimulateBench, StatsNoiseIbaOnTheCommandLine) {
    const fs::path dir = scratch_dir("bench-stats");
    ASSERT_EQ(run_in("simulate --days 0.2 --noise-iba --out s.csv > /dev/null", dir).exit_code, 0);
    const CliRun ok =
        run_in("stats --in s.csv --model s.csv.truth.csv --noise-iba s.csv.noise-iba.csv --json > out.txt", dir);
    ASSERT_EQ(ok.exit_code, 0) << ok.err;
    const std::string json = slurp(dir / "out.txt");
    EXPECT_NE(json.find("\"systematic\": {\"A-B\": {\"original\": "), std::string::npos) << json;
    const std::string systematic = json.substr(json.find("\"systematic\""));
    for (const char* pair : {"A-B", "A-C", "B-C"}) {
        const std::string entry = systematic.substr(systematic.find(std::string("\"") + pair + "\""));
        EXPECT_EQ(entry.find("\"thermal\": 0.000000"), entry.find("\"thermal\"")) << pair << ": " << json;
    }
    const std::string noise = slurp(dir / "s.csv.noise-iba.csv");
    const std::string first =
        noise.substr(noise.find('\n') + 1, noise.find('\n', noise.find('\n') + 1) - noise.find('\n'));
    const std::pair<std::string, std::string> cases[] = {
        {"t,pair,IBA\n", "n.csv:1:1: expected the header t,pair,iba"},
        {"", "n.csv:1:1: empty file: expected the header t,pair,iba"},
        {"t,pair,iba\n1.0,A-B\n", "n.csv:2:1: expected 3 fields (t,pair,iba), found 2"},
        {"t,pair,iba\nx,A-B,2\n", "n.csv:2:1: column 't': expected a number, got 'x'"},
        {"t,pair,iba\n1e999,A-B,2\n", "n.csv:2:1: column 't': '1e999' is out of range"},
        {"t,pair,iba\n1.0,A-X,3\n", "n.csv:2:5: pair 'A-X' is not two heads of ABCD (as A-B)"},
        {"t,pair,iba\n1.0,A-B,-3\n", "n.csv:2:9: column 'iba': -3 is no angle in [0, 648000] arcsec"},
        {"t,pair,iba\n" + first + first, "n.csv:3:1: pair A-B twice at this t (also line 2)"},
    };
    // A byte-order mark and CRLF line ends are read as every reader reads them.
    write(dir / "n.csv", "\xEF\xBB\xBFt,pair,iba\r\n" + first.substr(0, first.size() - 1) + "\r\n");
    const CliRun bom = run_in("stats --in s.csv --noise-iba n.csv --json > out.txt", dir);
    EXPECT_EQ(bom.exit_code, 0) << bom.err;
    EXPECT_NE(slurp(dir / "out.txt").find("\"systematic\""), std::string::npos);
    for (const auto& c : cases) {
        write(dir / "n.csv", c.first);
        const CliRun r = run_in("stats --in s.csv --noise-iba n.csv > out.txt", dir);
        EXPECT_EQ(r.exit_code, 1) << c.first;
        EXPECT_NE(r.err.find(c.second), std::string::npos) << c.first << ": " << r.err;
        EXPECT_EQ(slurp(dir / "out.txt"), "") << c.first;
    }
    const CliRun both = run_in("stats --combined s.csv --noise-iba s.csv.noise-iba.csv", dir);
    EXPECT_EQ(both.exit_code, 2);
    EXPECT_NE(both.err.find("excludes"), std::string::npos) << both.err;
}

}  // namespace
}  // namespace ascorr::test
