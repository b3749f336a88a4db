// firmware/app/app_scalar.hpp: the scalar the flight application runs the core in.
//
// Conventions: ASCORR_APP_FIXED (set by firmware/app/CMakeLists.txt for a
// target whose flight scalar is `fixed` in toolchain/targets.txt: the cores
// without FPU) selects the fixed-point Q30 core; otherwise float (a
// single-precision FPU). Everything the
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
