// ascorr/core/rotation_vector.hpp: the rotation between two attitudes as a
// rotation vector in arcsec (double), for the analysis of attitudes on the
// ground (align's relative attitudes, the combined file against a truth).
//
// Conventions (quaternion.hpp): Hamilton, scalar first; a and b map the same
// frame (ICRF) into two frames. θ is the rotation vector of a ⊗ b* in the
// left frame's axes: a = Exp(θ) ⊗ b, R_a = R(θ) R_b. Either sign of a and b
// gives the same θ (w ≥ 0 taken), so |θ| ≤ 180°. The angle is
// 2·atan2(|v|, w), exact at every angle (2·asin(|v|) loses digits near π);
// θ = 0 for identical attitudes (no 0/0). exp_arcsec is the inverse: the
// unit quaternion Exp(θ) of a rotation vector, with no 0/0 at θ = 0 either.
// One implementation of each for the ground (align, combine, interpolate,
// the statistics and plots of a combined file).
#pragma once

#include <cmath>

#include "constants.hpp"
#include "quaternion.hpp"
#include "vector3.hpp"

namespace ascorr {

inline Vector3<double> rotation_vector_arcsec(const Quaternion<double>& a, const Quaternion<double>& b) noexcept {
    const Quaternion<double> d = canonical(a * conjugate(b));
    const double s = std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
    if (s == 0.0) {
        return {0.0, 0.0, 0.0};
    }
    const double k = 2.0 * std::atan2(s, d.w) / s * kRadToArcsec;
    return {d.x * k, d.y * k, d.z * k};
}

// Exp(θ) = [cos(x/2), r sin(x/2)/x] with r = θ in rad, x = |r|: sin(x/2)/x
// has no cancellation at any x > 0 (sin is accurate to the last bit for
// small arguments), so only x = 0 needs its own case.
inline Quaternion<double> exp_arcsec(const Vector3<double>& theta_arcsec) noexcept {
    const Vector3<double> r{theta_arcsec.x / kRadToArcsec, theta_arcsec.y / kRadToArcsec,
                            theta_arcsec.z / kRadToArcsec};
    const double x = std::sqrt(r.x * r.x + r.y * r.y + r.z * r.z);
    if (x == 0.0) {
        return {1.0, 0.0, 0.0, 0.0};
    }
    const double k = std::sin(0.5 * x) / x;
    return {std::cos(0.5 * x), r.x * k, r.y * k, r.z * k};
}

}  // namespace ascorr
