// bench/baseline.hpp: the benchmark's baseline, a straightforward double
// implementation of both corrections, as one would first write it.
//
// Conventions: the same as the core (README, "Conventions in one paragraph"),
// written plainly with Eigen: the boresight from the full rotation matrix,
// ERFA's eraAb formula with sqrt and divisions, the minimal rotation from
// atan2 and an AngleAxis (sin, cos), the thermal rotation as three AngleAxis
// elementary rotations (paper's R3(γ)·R2(β)·R1(α)), a full normalisation.
// Used for instruction counts only (its accuracy is also reported): on the
// host with callgrind, on the targets under QEMU (Eigen headers build with
// gcc-arm-none-eabi and picolibc given EIGEN_NO_IO; double is software there).
#pragma once

#ifndef EIGEN_NO_IO
#define EIGEN_NO_IO
#endif
#include <Eigen/Geometry>
#include <cmath>
#include <cstdint>

#include "ascorr/core/heads.hpp"

namespace ascorr::bench {

struct BaselineModel {
    bool present[kMaxHeads];
    double coefficient[kMaxHeads][3][7];  // rad, rad/°C, rad/°C²
};

struct BaselineInput {
    double q[4];
    std::uint32_t head;
    double temperature[3];
    bool temperatures_valid;
    double beta[3];
    double inv_sun_distance_au;
    bool velocity_valid;
};

struct BaselineOutput {
    double q[4];
};

inline double baseline_angle(const double* c, const double* t) {
    const double d2 = t[1] - t[0];
    const double d3 = t[2] - t[0];
    return c[0] + c[1] * t[0] + c[2] * d2 + c[3] * d3 + c[4] * t[0] * t[0] + c[5] * d2 * d2 + c[6] * d3 * d3;
}

inline BaselineOutput baseline_correct(const BaselineInput& in, const BaselineModel* model, bool aberration) {
    Eigen::Quaterniond q(in.q[0], in.q[1], in.q[2], in.q[3]);
    if (aberration && in.velocity_valid) {
        const Eigen::Matrix3d r = q.toRotationMatrix();
        const Eigen::Vector3d z = r.row(2).transpose();
        const Eigen::Vector3d v(in.beta[0], in.beta[1], in.beta[2]);
        // eraAb(pnat = z, v, s, bm1)
        const double pdv = z.dot(v);
        const double bm1 = std::sqrt(1.0 - v.squaredNorm());
        const double w1 = 1.0 + pdv / (1.0 + bm1);
        const double w2 = 1.97412574336e-8 * in.inv_sun_distance_au;  // ERFA_SRS / s
        Eigen::Vector3d p = z * bm1 + w1 * v + w2 * (v - pdv * z);
        p /= std::sqrt(p.squaredNorm());
        // Minimal rotation z → p, applied on the inertial side.
        const Eigen::Vector3d axis = z.cross(p);
        const double angle = std::atan2(axis.norm(), z.dot(p));
        const Eigen::Quaterniond q_ab(Eigen::AngleAxisd(angle, axis.normalized()));
        q = q * q_ab.conjugate();
    }
    if (model != nullptr && in.head < kMaxHeads && model->present[in.head] && in.temperatures_valid) {
        const double a = baseline_angle(model->coefficient[in.head][0], in.temperature);
        const double b = baseline_angle(model->coefficient[in.head][1], in.temperature);
        const double g = baseline_angle(model->coefficient[in.head][2], in.temperature);
        const Eigen::Quaterniond q_th = Eigen::AngleAxisd(-g, Eigen::Vector3d::UnitZ()) *
                                        Eigen::AngleAxisd(-b, Eigen::Vector3d::UnitY()) *
                                        Eigen::AngleAxisd(-a, Eigen::Vector3d::UnitX());
        q = q_th * q;
    }
    q.normalize();
    if (q.w() < 0.0) {
        q.coeffs() = -q.coeffs();
    }
    return {{q.w(), q.x(), q.y(), q.z()}};
}

}  // namespace ascorr::bench
