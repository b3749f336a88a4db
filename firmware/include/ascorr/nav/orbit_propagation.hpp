// ascorr/nav/orbit_propagation.hpp: a spacecraft state propagated with J2.
//
// Conventions: OrbitState is position (km) and velocity (km/s) in GCRS axes,
// relative to the Earth's centre; the force is the Earth's point mass and its
// J2 (EGM2008, unnormalised), about the CIP pole_gcrs (earth_frame.hpp) fixed
// at the state's epoch (the pole moves 6e-9 rad per day):
//   a = −μ/r³ · [ (1 + k(1 − 5u)) r + 2k z p ],  z = r·p, u = z²/r², k = 3/2 J2 (R/r)².
// Integrator: classical Runge–Kutta (RK4) with a fixed step of
// kPropagationStepS = 10 s anchored at the state's time, so the state at
// t_state + n·10 s is one function of the state and n, whichever way it was
// reached (on board step by step, on the host from scratch): host and target
// compute the same bits. The integrator's own error on a LEO orbit
// (n = 1.1e-3 rad/s, local ~(n·h)⁵ = 1.6e-10 relative per step) is far below
// the force model's: J3, J4 and drag are left out; both are measured in
// tests/test_velocity_service.cpp, and they set the default horizon
// (velocity_service.hpp).
// Double, software on the Cortex-M3: one step is 4 force evaluations (one
// sqrt and one division each), run only when a solution's time passes 10 s
// after the latest state (in GNSS gaps, or from an uplinked state), outside
// the per-solution path. sqrt and division are IEEE correctly rounded on every
// platform we build for, so the bits agree.
#pragma once

#include <cmath>

#include "../core/vector3.hpp"

namespace ascorr {

inline constexpr double kEarthGmKm3S2 = 398600.4418;          // km³/s² (EGM2008 / WGS 84)
inline constexpr double kEarthEquatorialRadiusKm = 6378.137;  // km
inline constexpr double kEarthJ2 = 1.08262668e-3;             // EGM2008, −C̄20·√5
inline constexpr double kPropagationStepS = 10.0;

struct OrbitState {
    Vector3<double> r_km;
    Vector3<double> v_kms;
};

inline Vector3<double> gravity_j2(const Vector3<double>& r, const Vector3<double>& pole) noexcept {
    const double rr = dot(r, r);
    const double inv_r = 1.0 / std::sqrt(rr);
    const double inv_r2 = inv_r * inv_r;
    const double inv_r3 = inv_r2 * inv_r;
    const double z = dot(r, pole);
    const double u = z * z * inv_r2;
    const double k = 1.5 * kEarthJ2 * kEarthEquatorialRadiusKm * kEarthEquatorialRadiusKm * inv_r2;
    const double m = -kEarthGmKm3S2 * inv_r3;
    return (m * (1.0 + k * (1.0 - 5.0 * u))) * r + (m * 2.0 * k * z) * pole;
}

// One RK4 step of h seconds; a_s = gravity_j2(s.r_km, pole), which the
// caller has (the velocity service keeps it for its Taylor nodes).
inline OrbitState rk4_step(const OrbitState& s, const Vector3<double>& a_s, const Vector3<double>& pole,
                           double h) noexcept {
    const double h2 = 0.5 * h;
    const Vector3<double>& k1v = a_s;
    const Vector3<double> k1r = s.v_kms;
    const Vector3<double> k2r = s.v_kms + h2 * k1v;
    const Vector3<double> k2v = gravity_j2(s.r_km + h2 * k1r, pole);
    const Vector3<double> k3r = s.v_kms + h2 * k2v;
    const Vector3<double> k3v = gravity_j2(s.r_km + h2 * k2r, pole);
    const Vector3<double> k4r = s.v_kms + h * k3v;
    const Vector3<double> k4v = gravity_j2(s.r_km + h * k3r, pole);
    const double h6 = h * (1.0 / 6.0);
    return {s.r_km + h6 * (k1r + 2.0 * k2r + 2.0 * k3r + k4r), s.v_kms + h6 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v)};
}

}  // namespace ascorr
