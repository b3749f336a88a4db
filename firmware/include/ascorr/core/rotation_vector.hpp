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

// Exp(θ) = [cos(|θ|/2), θ̂ sin(|θ|/2)] for θ in arcsec. sin(x/2)/x is taken
// from its series below 1e-4 rad (truncation < x⁴/3840 < 3e-20, of 0.5).
inline Quaternion<double> exp_arcsec(const Vector3<double>& theta_arcsec) noexcept {
    const double x =
        std::sqrt(theta_arcsec.x * theta_arcsec.x + theta_arcsec.y * theta_arcsec.y + theta_arcsec.z * theta_arcsec.z) /
        kRadToArcsec;
    const double k = (x < 1e-4 ? 0.5 - x * x / 48.0 : std::sin(0.5 * x) / x) / kRadToArcsec;
    return {std::cos(0.5 * x), theta_arcsec.x * k, theta_arcsec.y * k, theta_arcsec.z * k};
}

}  // namespace ascorr
