// ascorr/ascorr.hpp: umbrella header of the ascorr correction core.
//
// The firmware side is in parts, each in its own folder with its own rules
// (stated in the folder's README.md):
//   core/   the per-solution correction: header-only, allocation-free,
//           templated on the scalar (double, float, Q30); no loops (but over
//           the kMaxHeads heads), no division, no sqrt, no exceptions, no I/O.
//   nav/    the navigation behind the on-board observer velocity: double,
//           loops of bounded trip count, sqrt allowed; only its per-solution
//           query runs in the core's scalar.
//   calib/  the thermal model's calibration, shared by the ground fit and the
//           on-board estimator.
// One header per concept; each states its conventions at the top:
//   core/scalar_traits.hpp  per-scalar constants, tolerances, maths hooks
//   core/constants.hpp      physical constants and the core's validity domain
//   core/vector3.hpp        3-vectors
//   core/quaternion.hpp     Hamilton, scalar-first attitude quaternions
//   core/rotation_vector.hpp  the rotation between two attitudes, arcsec (ground analysis)
//   core/aberration.hpp     ERFA eraAb stellar aberration as an attitude rotation
//   core/heads.hpp          the camera heads: how many, their letters
//   core/thermal.hpp        the thermal model (Herceg et al. 2017, eqs. 4–10)
//   core/model_coefficients.hpp  a model as numbers (arcsec or rad) → ThermalModel<T>
//   core/status.hpp         status bits of a corrected solution
//   core/correct.hpp        correct_solution(): the per-solution entry point
//   core/q_formats.hpp      Q30, the fixed-point scalar, and its temperature and
//                           coefficient formats (range, scaling, rounding, saturation)
//   core/fx.hpp             the integer arithmetic under them: conversions,
//                           exact products, the rounding helpers
//   core/fixed_point.hpp    all of the fixed-point core (the Q30 kernels are
//                           beside their generic versions, each with its guard)
//   core/compiler.hpp       what the fixed-point core asks of the compiler, checked
//   nav/earth_series.hpp    the Earth's barycentric velocity and Sun distance, a
//                           series fitted to ERFA eraEpv00 (double; coefficients in
//                           the generated earth_series_table.hpp)
// Data (not included here): core/table2.hpp, the paper's Table 2 as ModelCoefficients.
// The on-board observer velocity (not included here; include nav/velocity_service.hpp):
//   nav/tt_time.hpp        TT time tags in integer microseconds
//   nav/earth_frame.hpp    ITRF → GCRS (Earth rotation angle, IAU 2006 precession)
//   nav/sincos.hpp         sin/cos in double with the same bits on every platform
//   nav/orbit_propagation.hpp  J2 RK4 propagation of a spacecraft state
//   nav/state_gate.hpp     the verdicts on incoming states, the plausible orbit
//   nav/earth_grid.hpp     the Earth series on a 60 s grid, linear between
//   nav/velocity_node.hpp  the 10 s velocity node and its per-solution query
//   nav/velocity_service.hpp   states in, ObserverVelocity<T> per solution out
// Include each part's headers by their part's path (ascorr/core/…, ascorr/nav/…).
#pragma once

#include "core/aberration.hpp"
#include "core/compiler.hpp"
#include "core/constants.hpp"
#include "core/correct.hpp"
#include "core/fixed_point.hpp"
#include "core/heads.hpp"
#include "core/model_coefficients.hpp"
#include "core/quaternion.hpp"
#include "core/rotation_vector.hpp"
#include "core/scalar_traits.hpp"
#include "core/status.hpp"
#include "core/thermal.hpp"
#include "core/vector3.hpp"
#include "nav/earth_series.hpp"
