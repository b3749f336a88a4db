// firmware/app/flight_data.hpp: the data the correction loop works on, in
// static storage.
//
// Conventions: the thermal model is Table 2 of Herceg et al. 2017 (heads A–C,
// linear; arcsec and arcsec/°C, as in tests/data/model_table2.csv), converted
// to the core's formats in radians at compile time and kept in flash. The
// observer velocity is not here: the velocity service (velocity_service.hpp,
// fed by gnss_feed.hpp) computes it for each solution's time.
// The raw attitudes stand in for the star tracker's solutions (simulated: the
// worked examples' raw quaternions of heads A, B, C).
#pragma once

#include "app_scalar.hpp"
#include "ascorr/aberration.hpp"
#include "ascorr/constants.hpp"
#include "ascorr/model_coefficients.hpp"
#include "ascorr/quaternion.hpp"
#include "ascorr/thermal.hpp"

namespace ascorr::app {

// Herceg, Jørgensen & Jørgensen 2017, Table 2 (alpha, beta, gamma per head;
// c0, c1, c2, c3 in arcsec and arcsec/°C).
constexpr ModelCoefficients kTable2Arcsec = {
    {true, true, true},
    {
        {{-4.67067e-01, 3.58190e-03, -9.04363e-03, -1.04154e-01},
         {4.59718e-01, -3.52161e-03, 8.89788e-03, 1.02497e-01},
         {2.36543e-01, -7.31744e-01, 4.50041e-01, -1.12265e+00}},
        {{-1.19000e+00, 3.27044e-01, -2.10603e-01, 2.40148e-01},
         {2.03750e+00, -4.03134e-01, 4.04762e-02, 6.57657e-02},
         {5.51564e+00, -3.12725e-02, -7.31304e-01, 2.07894e+00}},
        {{4.08584e-02, 1.36145e-02, 1.57687e-02, 8.06663e-03},
         {2.99157e-02, 9.95873e-03, 1.15304e-02, 5.89875e-03},
         {1.17996e+01, -2.01007e-01, 4.97267e-01, 2.25162e+00}},
    },
};

constexpr ThermalModel<Scalar> kThermalModel = thermal_model<Scalar>(kTable2Arcsec, kArcsecToRad);

constexpr Scalar s(double x) {
    return ScalarTraits<Scalar>::from_double(x);
}

// Simulated raw solutions, one per head (D has no model: thermal skipped, status 256).
constexpr Quaternion<Scalar> kRawAttitude[kMaxHeads] = {
    {s(0.188173755763194), s(-0.642227588171342), s(0.463430603055416), s(0.580832539365081)},
    {s(0.536911789185323), s(0.045581161688435), s(0.778137527156088), s(0.322722910814147)},
    {s(0.904730389821686), s(-0.114358111360624), s(-0.316980035977685), s(-0.260593171228098)},
    {s(0.533209592857951), s(-0.403609172093452), s(-0.739738302419800), s(0.074661973047649)},
};

}  // namespace ascorr::app
