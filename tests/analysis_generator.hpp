// tests/analysis_generator.hpp: a small recorded data set that `ascorr
// simulate` did not make, for the analysis tests.
//
// Independent of the project's code on purpose: other geometry (800 km,
// 98.6°, a yawed spacecraft, heads not 90° apart), another truth model (random
// coefficients), other noise, flags, outages and gaps, rows of an epoch written
// in the order C, B, A. Aberration is undone with liberfa's eraAb and Eigen's
// minimal rotation, the thermal deformation with the paper's matrices.
#pragma once

#include <erfa.h>
#include <erfam.h>

#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "ascorr/core/constants.hpp"
#include "ascorr/core/heads.hpp"
#include "ascorr/nav/orbit_propagation.hpp"
#include "ascorr_host/formats/model_csv.hpp"

namespace ascorr::test {

// R3(γ)·R2(β)·R1(α), the paper's matrices (docs/contract.md), angles in rad.
inline Eigen::Matrix3d paper_rotation(double a, double b, double g) {
    Eigen::Matrix3d r1;
    r1 << 1, 0, 0, 0, std::cos(a), std::sin(a), 0, -std::sin(a), std::cos(a);
    Eigen::Matrix3d r2;
    r2 << std::cos(b), 0, -std::sin(b), 0, 1, 0, std::sin(b), 0, std::cos(b);
    Eigen::Matrix3d r3;
    r3 << std::cos(g), std::sin(g), 0, -std::sin(g), std::cos(g), 0, 0, 0, 1;
    return r3 * r2 * r1;
}

// The model's correction matrix of head h for temperatures (T1, T2, T3).
inline Eigen::Matrix3d model_rotation(const host::ModelFile& m, std::size_t h, const std::array<double, 3>& t) {
    double ang[3];
    for (std::size_t a = 0; a < 3; ++a) {
        const auto& c = m.coefficients[h][a];
        const double d2 = t[1] - t[0];
        const double d3 = t[2] - t[0];
        ang[a] = (c[0] + c[1] * t[0] + c[2] * d2 + c[3] * d3 + c[4] * t[0] * t[0] + c[5] * d2 * d2 + c[6] * d3 * d3) *
                 kArcsecToRad;
    }
    return paper_rotation(ang[0], ang[1], ang[2]);
}

struct GeneratorOptions {
    double days = 330.0;
    double step_s = 1800.0;
    std::uint64_t seed = 7;
    bool collinear_temperatures = false;   // T029 − T_CHU and T032 − T_CHU constant: rank-deficient
    bool garbage_in_dropped_rows = false;  // rows the selection drops get random attitudes
    // Quadratic terms in the truth: c1_2, c2_2, c3_2 uniform in ±quadratic_truth
    // arcsec/°C² (drawn apart, so that the rest of the data set stays the same).
    double quadratic_truth = 0.0;
    // Factor on every temperature variation (seasons, orbit, wander, heater);
    // small values give a period whose temperatures hardly change.
    double temperature_swing = 1.0;
};

struct Generated {
    host::ModelFile truth;
    std::array<Eigen::Matrix3d, 3> mount;                     // body into head
    std::vector<std::array<std::array<double, 3>, 3>> temps;  // per epoch, per head (T1, T2, T3)
    std::vector<double> t;
    // Noise-only IBA at clean epochs, per pair (A-B, A-C, B-C): time and arcsec.
    std::array<std::vector<std::pair<double, double>>, 3> floor;
};

inline double angle_between_arcsec(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
    return std::atan2(a.cross(b).norm(), a.dot(b)) * kRadToArcsec;
}

inline Generated generate(const std::string& path, const GeneratorOptions& o) {
    std::mt19937_64 rng(o.seed);
    std::normal_distribution<double> normal(0.0, 1.0);
    std::uniform_real_distribution<double> uni(0.0, 1.0);
    std::mt19937_64 garbage_rng(o.seed + 1);  // apart, so that the rest of the data set stays the same
    Generated g;
    g.truth.present = {true, true, true, false};
    for (std::size_t h = 0; h < 3; ++h) {
        for (std::size_t a = 0; a < 3; ++a) {
            auto& c = g.truth.coefficients[h][a];
            c[0] = 20.0 * uni(rng) - 10.0;
            c[1] = uni(rng) - 0.5;
            c[2] = 2.0 * uni(rng) - 1.0;
            c[3] = 2.0 * uni(rng) - 1.0;
        }
    }
    if (o.quadratic_truth != 0.0) {
        std::mt19937_64 quad_rng(o.seed + 2);
        g.truth.quadratic = true;
        for (std::size_t h = 0; h < 3; ++h) {
            for (std::size_t a = 0; a < 3; ++a) {
                for (std::size_t j = 4; j < 7; ++j) {
                    g.truth.coefficients[h][a][j] = o.quadratic_truth * (2.0 * uni(quad_rng) - 1.0);
                }
            }
        }
    }
    // Heads: (azimuth, elevation) in the body frame (x velocity, z nadir), degrees.
    const double az[3] = {10.0, 105.0, 215.0};
    const double el[3] = {40.0, 25.0, 45.0};
    const double deg = kPi / 180.0;
    for (std::size_t h = 0; h < 3; ++h) {
        const Eigen::Vector3d z(std::cos(el[h] * deg) * std::cos(az[h] * deg),
                                std::cos(el[h] * deg) * std::sin(az[h] * deg), -std::sin(el[h] * deg));
        const Eigen::Vector3d x = Eigen::Vector3d(0.3, 1.0, 0.2).cross(z).normalized();
        g.mount[h].row(0) = x.transpose();
        g.mount[h].row(1) = z.cross(x).transpose();
        g.mount[h].row(2) = z.transpose();
    }
    const Eigen::Matrix3d yaw = Eigen::AngleAxisd(20.0 * deg, Eigen::Vector3d::UnitZ()).toRotationMatrix();

    const double mu = kEarthGmKm3S2;
    const double a = kEarthEquatorialRadiusKm + 800.0;
    const double n = std::sqrt(mu / (a * a * a));
    const double inc = 98.6 * deg;
    const double season = 180.0 * 86400.0;
    const double t0 = 480000000.0;
    std::ofstream f(path);
    f << "t,chu,qw,qx,qy,qz,t_chu,t_029,t_032,vx,vy,vz,flags,confidence\n";
    std::array<double, 5> walk{};
    const auto epochs = static_cast<std::size_t>(o.days * 86400.0 / o.step_s);
    for (std::size_t k = 0; k < epochs; ++k) {
        const double dt = static_cast<double>(k) * o.step_s;
        const double t = t0 + dt;
        const double u = n * dt + 0.3;
        const double node = 1.0 + 2.0 * kPi * dt / season;
        const Eigen::Vector3d P(std::cos(node), std::sin(node), 0.0);
        const Eigen::Vector3d Q(-std::cos(inc) * std::sin(node), std::cos(inc) * std::cos(node), std::sin(inc));
        const Eigen::Vector3d r = std::cos(u) * P + std::sin(u) * Q;
        const Eigen::Vector3d vd = -std::sin(u) * P + std::cos(u) * Q;
        Eigen::Vector3d v_sc = a * n * vd;
        for (int i = 0; i < 3; ++i) {
            v_sc[i] = std::round(v_sc[i] * 1e6) / 1e6;
        }
        Eigen::Matrix3d body;
        body.row(0) = vd.transpose();
        body.row(1) = (-r).cross(vd).transpose();
        body.row(2) = (-r).transpose();
        body = yaw * body;

        for (double& w : walk) {
            w = 0.995 * w + 0.1 * normal(rng);
        }
        const double s = std::sin(2.0 * kPi * dt / season);
        const double c = std::cos(2.0 * kPi * dt / season);
        const double orb = std::cos(u);
        const bool heater = std::fmod(dt, 50.0 * 86400.0) < 3.0 * 86400.0;
        std::array<double, 3> tchu{};
        const double sw = o.temperature_swing;
        double t029 = -10.0 + sw * (5.0 * std::sin(2.0 * kPi * dt / season + 2.2) + walk[3]);
        double t032 = -15.0 + sw * (3.0 * c + walk[4] + (heater ? 4.0 : 0.0));
        for (std::size_t h = 0; h < 3; ++h) {
            tchu[h] = 5.0 * static_cast<double>(h) +
                      sw * (8.0 * std::sin(2.0 * kPi * dt / season + static_cast<double>(h)) + orb + walk[h]);
        }
        if (o.collinear_temperatures) {
            tchu = {8.0 * s, 8.0 * s, 8.0 * s};
            t029 = 8.0 * s - 5.0;
            t032 = 8.0 * s - 12.0;
        }
        const auto r3 = [](double x) { return std::round(x * 1000.0) / 1000.0; };
        t029 = r3(t029);
        t032 = r3(t032);
        std::array<std::array<double, 3>, 3> temps{};
        for (std::size_t h = 0; h < 3; ++h) {
            tchu[h] = r3(tchu[h]);
            temps[h] = {tchu[h], t029, t032};
        }
        g.t.push_back(t);
        g.temps.push_back(temps);

        double pvh[2][3];
        double pvb[2][3];
        eraEpv00(ERFA_DJ00, dt / 86400.0 + t0 / 86400.0, pvh, pvb);
        const double au_day = kAstronomicalUnitKm / 86400.0;
        const Eigen::Vector3d v_obs = Eigen::Vector3d(pvb[1][0], pvb[1][1], pvb[1][2]) * au_day + v_sc;
        double beta[3] = {v_obs.x() / kSpeedOfLightKmS, v_obs.y() / kSpeedOfLightKmS, v_obs.z() / kSpeedOfLightKmS};
        const double sun_au = std::sqrt(pvh[0][0] * pvh[0][0] + pvh[0][1] * pvh[0][1] + pvh[0][2] * pvh[0][2]);
        const double bm1 = std::sqrt(1.0 - (beta[0] * beta[0] + beta[1] * beta[1] + beta[2] * beta[2]));
        const bool gps_gap = std::fmod(dt, 23.0 * 86400.0) < 2.0 * 3600.0;

        std::array<bool, 3> clean{};
        std::array<bool, 3> written{};
        std::array<Eigen::Vector3d, 3> z_floor;
        for (int hi = 2; hi >= 0; --hi) {
            const auto h = static_cast<std::size_t>(hi);
            if (uni(rng) < 0.05) {
                continue;  // outage
            }
            int flags = 0;
            double conf = 0.5 + 2.0 * uni(rng);
            const double x = uni(rng);
            if (x < 0.02) {
                flags = 1 << static_cast<int>(3.0 * uni(rng));
            } else if (x < 0.03) {
                conf = 8.0;
            }
            const bool temp_missing = uni(rng) < 0.01;
            const bool bad = flags != 0 || conf > 5.0;
            const double sc = bad ? 60.0 : 1.0;
            const double sa = bad ? 60.0 : 6.0;
            const Eigen::Vector3d e =
                Eigen::Vector3d(sc * normal(rng), sc * normal(rng), sa * normal(rng)) * kArcsecToRad;
            const Eigen::Matrix3d noise = Eigen::AngleAxisd(e.norm(), e.normalized()).toRotationMatrix();
            const Eigen::Matrix3d r_true = g.mount[h] * body;
            const Eigen::Matrix3d r_meas = noise * model_rotation(g.truth, h, temps[h]).transpose() * r_true;
            // Raw: the boresight z_raw with eraAb(z_raw) = z_meas, and R_raw = R_meas·Q.
            const Eigen::Vector3d z_meas = r_meas.row(2).transpose();
            Eigen::Vector3d z_raw = z_meas;
            for (int it = 0; it < 5; ++it) {
                double pn[3] = {z_raw.x(), z_raw.y(), z_raw.z()};
                double pp[3];
                eraAb(pn, beta, sun_au, bm1, pp);
                z_raw = (z_raw + z_meas - Eigen::Vector3d(pp[0], pp[1], pp[2])).normalized();
            }
            const Eigen::Matrix3d q_ab = Eigen::Quaterniond::FromTwoVectors(z_raw, z_meas).toRotationMatrix();
            Eigen::Quaterniond q_raw(r_meas * q_ab);
            const bool dropped = bad || temp_missing || gps_gap;
            if (o.garbage_in_dropped_rows && dropped) {
                std::normal_distribution<double> gn(0.0, 1.0);  // own state: normal() caches values
                q_raw = Eigen::Quaterniond(gn(garbage_rng), gn(garbage_rng), gn(garbage_rng), gn(garbage_rng));
            }
            q_raw.normalize();
            if (q_raw.w() < 0.0) {
                q_raw.coeffs() = -q_raw.coeffs();
            }
            char line[400];
            const std::string tc = temp_missing ? std::string("nan") : std::to_string(tchu[h]);
            char vel[100] = ",,";
            if (!gps_gap) {
                std::snprintf(vel, sizeof vel, "%.6f,%.6f,%.6f", v_sc.x(), v_sc.y(), v_sc.z());
            }
            std::snprintf(line, sizeof line, "%.3f,%c,%.15f,%.15f,%.15f,%.15f,%s,%.3f,%.3f,%s,%d,%.2f\n", t,
                          ascorr::head_letter(static_cast<std::uint8_t>(hi)), q_raw.w(), q_raw.x(), q_raw.y(),
                          q_raw.z(), tc.c_str(), t029, t032, vel, flags, conf);
            f << line;
            written[h] = true;
            clean[h] = !dropped;
            z_floor[h] = (noise * r_true).row(2).transpose();
        }
        const std::size_t pairs[3][2] = {{0, 1}, {0, 2}, {1, 2}};
        for (std::size_t p = 0; p < 3; ++p) {
            const auto i = pairs[p][0];
            const auto j = pairs[p][1];
            if (written[i] && written[j] && clean[i] && clean[j]) {
                g.floor[p].emplace_back(t, angle_between_arcsec(z_floor[i], z_floor[j]));
            }
        }
    }
    return g;
}

// RMS about the mean of the floor samples with t in [from, to].
inline double floor_rms(const std::vector<std::pair<double, double>>& s, double from, double to) {
    double sum = 0.0;
    std::size_t n = 0;
    for (const auto& x : s) {
        if (x.first >= from && x.first <= to) {
            sum += x.second;
            ++n;
        }
    }
    const double mean = sum / static_cast<double>(n);
    double ss = 0.0;
    for (const auto& x : s) {
        if (x.first >= from && x.first <= to) {
            ss += (x.second - mean) * (x.second - mean);
        }
    }
    return std::sqrt(ss / static_cast<double>(n));
}

// A generated data set: its folder, its file, what the generator made, and
// its span with the end of the modelling period (280 days after the start).
struct GeneratedSet {
    std::filesystem::path dir;
    std::filesystem::path data;
    Generated gen;
    double t_from = 0.0;
    double t_split = 0.0;  // end of the modelling period
    double t_end = 0.0;
};

// Generates dir/file with options o.
inline GeneratedSet generate_set(const std::filesystem::path& dir, const std::string& file, const GeneratorOptions& o) {
    GeneratedSet d;
    d.dir = dir;
    d.data = dir / file;
    d.gen = generate(d.data.string(), o);
    d.t_from = d.gen.t.front();
    d.t_split = d.t_from + 280.0 * kSecondsPerDay;
    d.t_end = d.gen.t.back();
    return d;
}

}  // namespace ascorr::test
