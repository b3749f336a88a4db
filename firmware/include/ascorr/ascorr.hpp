// ascorr/ascorr.hpp: umbrella header of the ascorr correction core.
//
// Header-only, allocation-free, templated on the scalar type. One header per
// concept; each states its conventions at the top:
//   scalar_traits.hpp  per-scalar constants, tolerances, maths hooks
//   constants.hpp      physical constants and the core's validity domain
//   vector3.hpp        3-vectors
//   quaternion.hpp     Hamilton, scalar-first attitude quaternions
//   aberration.hpp     ERFA eraAb stellar aberration as an attitude rotation
//   heads.hpp          the camera heads: how many, their letters
//   thermal.hpp        the thermal model (Herceg et al. 2017, eqs. 4–10)
//   model_coefficients.hpp  a model as numbers (arcsec or rad) → ThermalModel<T>
//   status.hpp         status bits of a corrected solution
//   correct.hpp        correct_solution(): the per-solution entry point
//   fixed_point.hpp    Q30, the fixed-point scalar (with its temperature and
//                      coefficient formats and thermal_angle)
//   compiler.hpp       what the fixed-point core asks of the compiler, checked
//   earth_series.hpp   the Earth's barycentric velocity and Sun distance, a
//                      series fitted to ERFA eraEpv00 (double; coefficients in
//                      the generated earth_series_table.hpp)
// Data (not included here): table2.hpp, the paper's Table 2 as ModelCoefficients.
// The on-board observer velocity (not included here; include velocity_service.hpp):
//   tt_time.hpp        TT time tags in integer microseconds
//   earth_frame.hpp    ITRF → GCRS (Earth rotation angle, IAU 2006 precession)
//   sincos.hpp         sin/cos in double with the same bits on every platform
//   orbit_propagation.hpp  J2 RK4 propagation of a spacecraft state
//   velocity_service.hpp   states in, ObserverVelocity<T> per solution out
#pragma once

#include "aberration.hpp"
#include "compiler.hpp"
#include "constants.hpp"
#include "correct.hpp"
#include "earth_series.hpp"
#include "fixed_point.hpp"
#include "heads.hpp"
#include "model_coefficients.hpp"
#include "quaternion.hpp"
#include "scalar_traits.hpp"
#include "status.hpp"
#include "thermal.hpp"
#include "vector3.hpp"
