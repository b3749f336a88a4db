// ascorr/core/fixed_point.hpp: the fixed-point core (DPU without FPU) in one include.
//
// The fixed-point scalar Q30 and the other Q formats (temperatures,
// coefficients) with their conventions (range, scaling, rounding, saturation)
// are in q_formats.hpp, on the integer arithmetic of fx.hpp (conversions,
// saturating sums, exact products and the one family of rounding helpers).
// Each Q30 kernel of the correction is beside its generic version, followed
// by its guard (the deleted Q30 specialisation of the template, so that a
// call never falls back to it): vector3.hpp (dot, squared_norm, cross),
// quaternion.hpp (dot, squared_norm, the product, boresight, conjugate,
// norm_within, right_increment, add_left_increment, renormalized_sum),
// aberration.hpp (beta_in_domain, aberration_rotation) and thermal.hpp
// (thermal_angle, thermal_rotation). This header includes them all.
#pragma once

#include "aberration.hpp"
#include "compiler.hpp"
#include "constants.hpp"
#include "fx.hpp"
#include "q_formats.hpp"
#include "quaternion.hpp"
#include "scalar_traits.hpp"
#include "thermal.hpp"
#include "vector3.hpp"
