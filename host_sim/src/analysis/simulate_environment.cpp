// `ascorr simulate`'s spacecraft and surroundings: Sun and Moon, orbit, attitude, heaters, gaps, temperatures.
#include <erfa.h>
#include <erfam.h>

#include <algorithm>
#include <cmath>

#include "simulate_parts.hpp"

namespace ascorr::host::detail {

void SunMoon::at(double t, Eigen::Vector3d& sun, Eigen::Vector3d& moon) {
    const auto hour = static_cast<long long>(std::floor(t / 3600.0));
    if (hour != hour_) {
        hour_ = hour;
        const double tc = static_cast<double>(hour) * 3600.0 + 1800.0;
        double pvh[2][3];
        double pvb[2][3];
        eraEpv00(ERFA_DJ00, tc / kSecondsPerDay, pvh, pvb);
        sun_ = -Eigen::Vector3d(pvh[0][0], pvh[0][1], pvh[0][2]).normalized();
        double pv[2][3];
        eraMoon98(ERFA_DJ00, tc / kSecondsPerDay, pv);
        moon_ = Eigen::Vector3d(pv[0][0], pv[0][1], pv[0][2]).normalized();
    }
    sun = sun_;
    moon = moon_;
}

Heaters::Heaters(double t0, std::mt19937_64& rng) : rng_(rng) {
    schedule(t0);
}

void Heaters::at(double t, double& op, double& surv) {
    while (t > end_ + 5.0 * kTau) {
        schedule(end_);
    }
    double p = 0.0;
    if (t >= start_) {
        const double on = std::min(t, end_) - start_;
        p = 1.0 - std::exp(-on / kTau);
        if (t > end_) {
            p *= std::exp(-(t - end_) / kTau);
        }
    }
    op = operational_ ? p : 0.0;
    surv = operational_ ? 0.0 : p;
}

void Heaters::schedule(double after) {
    std::uniform_real_distribution<double> gap(40.0 * kSecondsPerDay, 80.0 * kSecondsPerDay);
    std::uniform_real_distribution<double> len(3.0 * kSecondsPerDay, 5.0 * kSecondsPerDay);
    start_ = after + gap(rng_);
    end_ = start_ + len(rng_);
    operational_ = !operational_;
    events_.push_back({start_, end_, operational_});
}

bool Gap::step(double p_start, std::size_t min_len, std::size_t max_len, std::mt19937_64& rng) {
    if (left > 0) {
        --left;
        return true;
    }
    std::uniform_real_distribution<double> u(0.0, 1.0);
    if (u(rng) < p_start) {
        std::uniform_int_distribution<std::size_t> len(min_len, max_len);
        left = len(rng) - 1;
        return true;
    }
    return false;
}

Orbit::Orbit(double start_t, SunMoon& sky) {
    Eigen::Vector3d sun0;
    Eigen::Vector3d moon0;
    sky.at(start_t, sun0, moon0);
    node0_ = std::atan2(sun0.y(), sun0.x()) + 30.0 * kDegToRad;
}

SpacecraftPose Orbit::at(double dt) const {
    SpacecraftPose o;
    const double u = n_ * dt;
    const double node = node0_ + node_rate_ * dt;
    o.P = Eigen::Vector3d(std::cos(node), std::sin(node), 0.0);
    o.Q = Eigen::Vector3d(-std::cos(inc_) * std::sin(node), std::cos(inc_) * std::cos(node), std::sin(inc_));
    o.r_hat = std::cos(u) * o.P + std::sin(u) * o.Q;
    const Eigen::Vector3d v_dir = -std::sin(u) * o.P + std::cos(u) * o.Q;
    o.v_sc = a_ * n_ * v_dir;
    for (int i = 0; i < 3; ++i) {
        o.v_sc[i] = std::round(o.v_sc[i] * 1e6) / 1e6;  // as written
    }
    o.body_icrf.row(0) = v_dir.transpose();
    o.body_icrf.row(2) = -o.r_hat.transpose();
    o.body_icrf.row(1) = (-o.r_hat).cross(v_dir).transpose();
    return o;
}

namespace {

// A CHU's temperature response (°C): mean, per sine of the Sun's angle to the
// orbital plane (sinb), per sinb², per cosine of the Sun from the position
// (the sunlit side), per operational heater on.
struct ChuResponse {
    double mean;
    double season;
    double season2;
    double orbit;
    double heater;
};
constexpr ChuResponse kChuResponse[kOwnHeads] = {
    {10.0, 5.0, 2.0, 0.8, 2.5},   // A
    {14.0, -7.0, 1.0, 1.2, 3.0},  // B
    {8.0, -4.0, 3.0, 0.6, 2.0},   // C
};

// The response of head h: A, B, C's above; a head beyond C (h ≥ 3) has head
// h − 3's mirrored, as mounted on the other side: the seasonal (sinb) and
// orbital terms change sign.
ChuResponse chu_response(std::size_t h) {
    if (h < kOwnHeads) {
        return kChuResponse[h];
    }
    ChuResponse r = kChuResponse[(h - kOwnHeads) % kOwnHeads];
    r.season = -r.season;
    r.orbit = -r.orbit;
    return r;
}

double chu_temperature(std::size_t h, const Exposure& x, double wander, double op) {
    const ChuResponse r = chu_response(h);
    return r.mean + r.season * x.sinb + r.season2 * (x.sinb * x.sinb) + r.orbit * x.orb + wander + r.heater * op;
}

}  // namespace

Exposure exposure(const SpacecraftPose& o, const Eigen::Vector3d& sun) {
    return {sun.dot(o.P.cross(o.Q)), o.r_hat.dot(sun)};
}

// T_CHU A, B, C, T029, T032 (°C, rounded as written): seasonal (sine of the
// Sun's angle to the orbital plane), orbital (sunlit side), independent
// wander, heater events, read noise.
std::array<double, 5> temperatures(const SpacecraftPose& o, const Eigen::Vector3d& sun, double op, double surv,
                                   std::array<Wander, 5>& wander, double step_s, Random& rnd) {
    const Exposure x = exposure(o, sun);
    const double sinb = x.sinb;
    const double orb = x.orb;
    for (auto& w : wander) {
        w.step(step_s, 3.0 * kSecondsPerDay, 0.6, rnd.engine);
    }
    const double s2 = sinb * sinb;
    std::array<double, 5> temp = {
        chu_temperature(0, x, wander[0].x, op),
        chu_temperature(1, x, wander[1].x, op),
        chu_temperature(2, x, wander[2].x, op),
        -9.0 + 3.0 * sinb - 2.0 * s2 + 0.3 * orb + wander[3].x + 3.0 * surv,
        -20.0 + 2.0 * sinb + 4.0 * s2 + 0.2 * orb + wander[4].x + 2.0 * op,
    };
    for (double& t : temp) {
        t = std::round((t + 0.02 * rnd.gauss()) * 1000.0) / 1000.0;  // as written
    }
    return temp;
}

// The recorded T_CHU of a head beyond C: its response, its own wander and
// read noise, drawn from its own stream (Mission::extra_).
double extra_chu_temperature(std::size_t h, const Exposure& x, double op, Wander& wander, double step_s, Random& rnd) {
    wander.step(step_s, 3.0 * kSecondsPerDay, 0.6, rnd.engine);
    const double t = chu_temperature(h, x, wander.x, op);
    return std::round((t + 0.02 * rnd.gauss()) * 1000.0) / 1000.0;  // as written
}

}  // namespace ascorr::host::detail
