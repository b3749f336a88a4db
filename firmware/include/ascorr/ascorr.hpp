// ascorr/ascorr.hpp: umbrella header of the ascorr correction core.
//
// Header-only, allocation-free, templated on the scalar type. One header per
// concept; each states its conventions at the top:
//   scalar_traits.hpp  per-scalar constants, tolerances, maths hooks
//   constants.hpp      physical constants and the core's validity domain
//   vector3.hpp        3-vectors
//   quaternion.hpp     Hamilton, scalar-first attitude quaternions
//   aberration.hpp     ERFA eraAb stellar aberration as an attitude rotation
//   thermal.hpp        the thermal model (Herceg et al. 2017, eqs. 4–10)
//   status.hpp         status bits of a corrected solution
//   correct.hpp        correct_solution(): the per-solution entry point
//   fixed_point.hpp    Q30, the fixed-point scalar (with its temperature and
//                      coefficient formats and thermal_angle)
//   compiler.hpp       what the fixed-point core asks of the compiler, checked
#pragma once

#include "aberration.hpp"
#include "compiler.hpp"
#include "constants.hpp"
#include "correct.hpp"
#include "fixed_point.hpp"
#include "quaternion.hpp"
#include "scalar_traits.hpp"
#include "status.hpp"
#include "thermal.hpp"
#include "vector3.hpp"
