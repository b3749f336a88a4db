// firmware/app/flight_data.hpp: the data the correction loop works on, in
// static storage.
//
// Conventions: the thermal model is Table 2 of Herceg et al. 2017 (heads A–C,
// linear; ascorr/core/table2.hpp, the one copy in code, checked against
// tests/data/model_table2.csv by Table2.*), converted to the core's formats in
// radians at compile time (thermal_model(), model_coefficients.hpp) and kept
// in flash. The
// observer velocity is not here: the velocity service (velocity_service.hpp,
// fed by gnss_feed.hpp) computes it for each solution's time.
#pragma once

#include "app_scalar.hpp"
#include "ascorr/core/aberration.hpp"
#include "ascorr/core/constants.hpp"
#include "ascorr/core/model_coefficients.hpp"
#include "ascorr/core/quaternion.hpp"
#include "ascorr/core/table2.hpp"
#include "ascorr/core/thermal.hpp"

namespace ascorr::app {

constexpr ThermalModel<Scalar> kThermalModel = thermal_model<Scalar>(kTable2, kArcsecToRad);

constexpr Scalar s(double x) {
    return ScalarTraits<Scalar>::from_double(x);
}

// The heads' undeformed attitudes, one per head (simulated: the worked
// examples' raw quaternions of heads A, B, C; D has no model: thermal skipped,
// status 256). The raw solutions the loop corrects are these deformed by the
// simulated bench (flight_bench.hpp).
constexpr Quaternion<double> kHeadAttitude[] = {
    {0.188173755763194, -0.642227588171342, 0.463430603055416, 0.580832539365081},
    {0.536911789185323, 0.045581161688435, 0.778137527156088, 0.322722910814147},
    {0.904730389821686, -0.114358111360624, -0.316980035977685, -0.260593171228098},
    {0.533209592857951, -0.403609172093452, -0.739738302419800, 0.074661973047649},
};
static_assert(sizeof(kHeadAttitude) / sizeof(kHeadAttitude[0]) == kMaxHeads, "one attitude per head (heads.hpp)");

}  // namespace ascorr::app
