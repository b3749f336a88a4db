// firmware/app/app_scalar.hpp: the scalar the flight application runs the core in.
//
// Conventions: ASCORR_APP_FIXED (set by the build for cores without FPU,
// toolchain/cortex-m3.cmake) selects the fixed-point Q30 core; otherwise float
// (single-precision FPU, toolchain/cortex-m4f.cmake). Everything the
// application stores for the core (model, velocity, temperatures, attitudes)
// is in this scalar's formats, converted at compile time.
#pragma once

#include "ascorr/core/fixed_point.hpp"
#include "ascorr/core/scalar_traits.hpp"

namespace ascorr::app {

#if defined(ASCORR_APP_FIXED)
using Scalar = Q30;
#else
using Scalar = float;
#endif

}  // namespace ascorr::app
