// tests/target_vectors.cpp: the host side of the accuracy tests on the targets.
//
//   ascorr_target_vectors write DIR N SEED
//       DIR/vectors.bin: the 12 worked examples (tests/data, observer velocity
//       from ERFA as `ascorr correct` computes it), then N random solutions
//       (random attitudes, |v| ≤ 100 km/s, temperatures −40…60 °C, a random
//       model with quadratic terms, and one bad input in 16: non-finite or
//       out-of-range values, missing readings, a head without a model);
//   ascorr_target_vectors check DIR BOUND_ARCSEC
//       compares DIR/results.bin (written by the target image) with the double
//       core on the same inputs (every configuration, status bits must be
//       equal) and the worked examples also with tests/data/expected_*.csv;
//       prints the largest errors and, last, {"max_error_arcsec": x}; exit 0
//       when all are within the bound and every status matches, else 1.
#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "ascorr/ascorr.hpp"
#include "ascorr_host/correct/solution_input.hpp"
#include "ascorr_host/formats/csv.hpp"
#include "ascorr_host/formats/model_csv.hpp"
#include "ascorr_host/formats/solutions_csv.hpp"
#include "solutions_records.hpp"
#include "target/model_record.hpp"
#include "target/vector_convert.hpp"
#include "target/vector_format.hpp"

namespace {

using namespace ascorr;
using namespace ascorr::target;

std::string data(const std::string& name) {
    return std::string(ASCORR_TEST_DATA) + "/" + name;
}

SolutionInput<double> to_input(const VectorRecord& r) {
    SolutionInput<double> in{};
    in.q_chu_icrf = {r.q[0], r.q[1], r.q[2], r.q[3]};
    in.head = static_cast<std::uint8_t>(r.head < 255U ? r.head : 255U);
    in.temperatures.t_chu = {r.temperature[0], (r.temperature_valid & 1U) != 0U};
    in.temperatures.t_029 = {r.temperature[1], (r.temperature_valid & 2U) != 0U};
    in.temperatures.t_032 = {r.temperature[2], (r.temperature_valid & 4U) != 0U};
    in.velocity = {{r.beta[0], r.beta[1], r.beta[2]}, r.inv_sun_distance_au, r.velocity_valid != 0U};
    return in;
}

double angle_arcsec(const Quaternion<double>& a, const Quaternion<double>& b) {
    const Eigen::Quaterniond d =
        Eigen::Quaterniond(a.w, a.x, a.y, a.z).conjugate() * Eigen::Quaterniond(b.w, b.x, b.y, b.z);
    const double s = std::min(1.0, d.vec().norm() / d.norm());
    return 2.0 * std::asin(s) * kRadToArcsec;
}

int write(const std::string& dir, std::uint32_t n, std::uint64_t seed) {
    std::string text;
    const auto rows = ascorr::test::read_records(data("solutions.csv"), text);
    host::EarthVelocity earth;
    std::mt19937_64 rng(seed);
    VectorHeader header{};
    header.magic = kVectorMagic;
    header.count = static_cast<std::uint32_t>(rows.size()) + n;
    header.model[0] = model_record(host::read_model_file(data("model_table2.csv")));
    {
        std::uniform_real_distribution<double> c0(-100.0, 100.0);
        std::uniform_real_distribution<double> c1(-5.0, 5.0);
        std::uniform_real_distribution<double> c2(-0.01, 0.01);
        host::ModelFile m;
        for (std::size_t h = 0; h < 3; ++h) {
            m.present[h] = true;
            for (auto& axis : m.coefficients[h]) {
                axis = {c0(rng), c1(rng), c1(rng), c1(rng), c2(rng), c2(rng), c2(rng)};
            }
        }
        header.model[1] = model_record(m);
    }
    std::vector<VectorRecord> out;
    for (const auto& rec : rows) {
        const SolutionInput<double> in = host::to_core_input<double>(rec, &earth);
        VectorRecord r{};
        r.q[0] = in.q_chu_icrf.w;
        r.q[1] = in.q_chu_icrf.x;
        r.q[2] = in.q_chu_icrf.y;
        r.q[3] = in.q_chu_icrf.z;
        for (int i = 0; i < 3; ++i) {
            r.temperature[i] = rec.temperature[static_cast<std::size_t>(i)];
        }
        r.temperature_valid = 7U;
        r.beta[0] = in.velocity.beta_icrf.x;
        r.beta[1] = in.velocity.beta_icrf.y;
        r.beta[2] = in.velocity.beta_icrf.z;
        r.inv_sun_distance_au = in.velocity.inv_sun_distance_au;
        r.head = in.head;
        r.velocity_valid = in.velocity.valid ? 1U : 0U;
        r.model = 0;
        out.push_back(r);
    }
    std::normal_distribution<double> normal(0.0, 1.0);
    std::uniform_real_distribution<double> speed(0.0, 100.0);
    std::uniform_real_distribution<double> temp(-40.0, 60.0);
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const double inf = std::numeric_limits<double>::infinity();
    for (std::uint32_t i = 0; i < n; ++i) {
        Eigen::Quaterniond q(normal(rng), normal(rng), normal(rng), normal(rng));
        q.normalize();
        Eigen::Vector3d v(normal(rng), normal(rng), normal(rng));
        v = v.normalized() * (speed(rng) / kSpeedOfLightKmS);
        VectorRecord r{};
        r.q[0] = q.w();
        r.q[1] = q.x();
        r.q[2] = q.y();
        r.q[3] = q.z();
        for (double& t : r.temperature) {
            t = temp(rng);
        }
        r.temperature_valid = 7U;
        r.beta[0] = v.x();
        r.beta[1] = v.y();
        r.beta[2] = v.z();
        r.inv_sun_distance_au = 1.0 / (0.983 + 0.034 * (i % 11) / 10.0);
        r.head = i % 3;
        r.velocity_valid = 1U;
        r.model = 1;
        switch (i % 16 == 15 ? (i / 16) % 8 : 8U) {  // one input in 16 is bad
            case 0:
                r.temperature[1] = nan;
                break;
            case 1:
                r.temperature[2] = 250.0;
                break;
            case 2:
                r.beta[0] = inf;
                break;
            case 3:
                r.beta[1] = 4e-3;
                break;  // 1200 km/s
            case 4:
                r.q[2] = nan;
                break;
            case 5:
                r.q[0] *= 1.001;
                break;  // not unit
            case 6:
                r.head = 3;
                break;  // no model for head D
            case 7:
                r.temperature_valid = 5U;
                r.velocity_valid = 0U;
                break;
            default:
                break;
        }
        out.push_back(r);
    }
    std::ofstream f(dir + "/vectors.bin", std::ios::binary);
    f.write(reinterpret_cast<const char*>(&header), sizeof header);
    f.write(reinterpret_cast<const char*>(out.data()), static_cast<std::streamsize>(out.size() * sizeof(VectorRecord)));
    if (!f) {
        std::cerr << dir << "/vectors.bin: cannot write\n";
        return 1;
    }
    return 0;
}

int check(const std::string& dir, double bound) {
    std::ifstream fv(dir + "/vectors.bin", std::ios::binary);
    std::ifstream fr(dir + "/results.bin", std::ios::binary);
    VectorHeader header{};
    fv.read(reinterpret_cast<char*>(&header), sizeof header);
    if (!fv || header.magic != kVectorMagic) {
        std::cerr << dir << "/vectors.bin: unreadable\n";
        return 1;
    }
    const ThermalModel<double> models[kModels] = {to_core_model<double>(header.model[0]),
                                                  to_core_model<double>(header.model[1])};
    const char* expected_files[kConfigs] = {"expected_aberration_only.csv", "expected_thermal_only.csv",
                                            "expected_both.csv"};
    std::string storage[kConfigs];
    std::vector<host::SolutionRecord> expected[kConfigs];
    for (int c = 0; c < kConfigs; ++c) {
        expected[c] = ascorr::test::read_records(data(expected_files[c]), storage[c]);
    }
    double worst_examples = 0.0;
    double worst_expected = 0.0;
    double worst_random = 0.0;
    std::uint32_t mismatches = 0;
    for (std::uint32_t i = 0; i < header.count; ++i) {
        VectorRecord r{};
        ResultRecord res{};
        fv.read(reinterpret_cast<char*>(&r), sizeof r);
        fr.read(reinterpret_cast<char*>(&res), sizeof res);
        if (!fv || !fr || r.model >= kModels) {
            std::cerr << dir << ": results.bin or vectors.bin short at record " << i << "\n";
            return 1;
        }
        const SolutionInput<double> in = to_input(r);
        const ThermalModel<double>* model = &models[r.model];
        const CorrectionConfig<double> cfgs[kConfigs] = {{true, nullptr}, {false, model}, {true, model}};
        for (int c = 0; c < kConfigs; ++c) {
            const CorrectedSolution<double> ref = correct_solution(in, cfgs[c]);
            const Quaternion<double> got{res.q[c][0], res.q[c][1], res.q[c][2], res.q[c][3]};
            if (res.status[c] != ref.status) {
                if (++mismatches <= 10) {
                    std::cerr << "record " << i << " config " << c << ": status " << res.status[c] << ", double "
                              << ref.status << "\n";
                }
                continue;
            }
            if ((ref.status & status::kRejected) != 0U) {
                continue;  // quaternion returned unchanged (in the target's scalar)
            }
            const double e = angle_arcsec(got, ref.q_chu_icrf);
            if (i < expected[c].size()) {
                worst_examples = std::max(worst_examples, e);
                worst_expected = std::max(worst_expected, angle_arcsec(got, expected[c][i].q_chu_icrf));
            } else {
                worst_random = std::max(worst_random, e);
            }
        }
    }
    const double worst = std::max({worst_examples, worst_expected, worst_random});
    std::printf("worked examples: max %.6f\" vs double core, %.6f\" vs tests/data/expected_*.csv\n", worst_examples,
                worst_expected);
    std::printf("random set (%u solutions x 3 configurations): max %.6f\"; status mismatches %u\n",
                header.count - static_cast<std::uint32_t>(expected[0].size()), worst_random, mismatches);
    std::printf("{\"max_error_arcsec\": %.6f}\n", worst);
    return (worst <= bound && mismatches == 0U) ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
    try {
        const std::string cmd = argc > 1 ? argv[1] : "";
        if (cmd == "write" && argc == 5) {
            return write(argv[2], static_cast<std::uint32_t>(std::stoul(argv[3])), std::stoull(argv[4]));
        }
        if (cmd == "check" && argc == 4) {
            return check(argv[2], std::stod(argv[3]));
        }
    } catch (const std::exception& e) {
        std::cerr << "ascorr_target_vectors: " << e.what() << "\n";
        return 1;
    }
    std::cerr << "usage: ascorr_target_vectors write DIR N SEED | check DIR BOUND_ARCSEC\n";
    return 2;
}
