// tests/states_recording.hpp: a recorded pass with spacecraft states, for the
// replay tests: 1 Hz ITRF states (a 460 km near-polar orbit, J2 RK4 at 0.1 s,
// to ITRF by inverting the service's own rotation: input data only) with a
// 40 s gap, and solutions of heads A–C every 0.3 s starting 2 s before the
// first state, without velocity except every 37th row (which keeps its own).
#pragma once

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>

#include "ascorr/core/heads.hpp"
#include "ascorr/nav/velocity_service.hpp"
#include "test_support.hpp"

namespace ascorr::test {

struct StatesRecording {
    std::string solutions;
    std::string states;
};

inline StatesRecording make_states_recording(const std::filesystem::path& dir, int rows) {
    constexpr double kT0 = 801964800.184;
    const double span = rows * 0.1 + 10.0;
    const double r0 = kEarthEquatorialRadiusKm + 460.0;
    OrbitState s{{r0, 0.0, 0.0}, {0.0, 0.35, std::sqrt(kEarthGmKm3S2 / r0)}};
    std::string st = "t,x,y,z,vx,vy,vz\n";
    char buf[400];
    for (int k = 0; k <= static_cast<int>(span); ++k) {
        const double t = kT0 + k;
        if (!(k >= 60 && k < 100)) {
            TtTime tt{};
            tt_from_seconds(t, tt);
            const CelestialFromTerrestrial m = celestial_from_terrestrial(tt, kDefaultTtMinusUt1Us);
            const auto& q = m.q_gcrs_cirs.row;
            const auto qt = [&](const Vector3<double>& x) {
                return Vector3<double>{q[0].x * x.x + q[1].x * x.y + q[2].x * x.z,
                                       q[0].y * x.x + q[1].y * x.y + q[2].y * x.z,
                                       q[0].z * x.x + q[1].z * x.y + q[2].z * x.z};
            };
            const auto r3 = [&](const Vector3<double>& x) {
                return Vector3<double>{m.era.c * x.x + m.era.s * x.y, -m.era.s * x.x + m.era.c * x.y, x.z};
            };
            const Vector3<double> r = r3(qt(s.r_km));
            const Vector3<double> vi = r3(qt(s.v_kms));
            const double w = kEarthRotationRateRadS;
            std::snprintf(buf, sizeof buf, "%.3f,%.9f,%.9f,%.9f,%.12f,%.12f,%.12f\n", t, r.x, r.y, r.z, vi.x + w * r.y,
                          vi.y - w * r.x, vi.z);
            st += buf;
        }
        for (int i = 0; i < 10; ++i) {
            s = rk4_step(s, gravity_j2(s.r_km, {0, 0, 1}), {0, 0, 1}, 0.1);
        }
    }
    std::mt19937_64 rng(5);
    std::string sol = "t,chu,qw,qx,qy,qz,t_chu,t_029,t_032,vx,vy,vz,flags,confidence\n";
    for (int i = 0; i < rows; ++i) {
        const Eigen::Quaterniond q = random_attitude(rng);
        const double t = kT0 - 2.0 + 0.3 * (i / 3);
        std::snprintf(buf, sizeof buf, "%.6f,%c,%.15f,%.15f,%.15f,%.15f,%.2f,%.2f,%.2f,%s,0,1\n", t,
                      ascorr::head_letter(static_cast<std::uint8_t>(i % 3)), q.w() < 0 ? -q.w() : q.w(),
                      q.w() < 0 ? -q.x() : q.x(), q.w() < 0 ? -q.y() : q.y(), q.w() < 0 ? -q.z() : q.z(),
                      20.0 + 0.001 * i, 21.5, 19.25, i % 37 == 5 ? "1.25,-6.5,3.75" : ",,");
        sol += buf;
    }
    StatesRecording out{(dir / "rec.csv").string(), (dir / "states.csv").string()};
    std::ofstream(out.solutions) << sol;
    std::ofstream(out.states) << st;
    return out;
}

}  // namespace ascorr::test
